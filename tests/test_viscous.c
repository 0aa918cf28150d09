/* tests/test_viscous.c - viscous accuracy through sph_advance with the defaults (issue 18):
   - plane Poiseuille flow between no-slip walls, periodic in x, driven by a body force g: the
     steady profile u(y) = g y (H - y) / (2 nu) (Morris, Fox & Zhu 1997 validate their viscous term on it), centre speed
     and RMS over the profile at 20 particles across (and 40 in the long set: the error must not
     grow with resolution), WCSPH, IISPH and DFSPH;
   - a Taylor-Green vortex cell filling a closed free-slip box: its kinetic energy decays as
     exp(-4 pi^2 nu t / L^2) (see run_box_decay); the measured decay rate per solver, with the
     default artificial viscosity and without, and with particle shifting (2D and 3D). (The
     periodic Taylor-Green box of scene_taylor_green, wavelength L, decays as
     exp(-16 pi^2 nu t / L^2); with the standard options and c0 = 10 U, IISPH and DFSPH blow up
     in it by t = 0.1 s and WCSPH and PCISPH decay 4.1 and 3.6 times too fast at 40 x 40, so it
     is the second-order scheme's test, tests/test_soc.c.) */
#include "harness.h"
#include "../sph.h"
#include "../examples/scenes.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#ifdef _OPENMP
#include <omp.h>
#include "state_hash.h"
#endif

/* ---- plane Poiseuille flow ------------------------------------------------------------------ */

typedef struct poiseuille_result {
    sph_status status;
    double centre;  /* (u - u_exact)/u_max, mean of the two rows beside y = H/2 [-]            */
    double rms;     /* RMS over the rows of (u_row - u_exact(y_row)) / u_max [-]                */
    double v_max;   /* largest |v_y| / u_max [-]                                                */
    double ms_step; /* wall-clock milliseconds per sub-step                                     */
    unsigned long long steps;
} poiseuille_result;

/* Fluid of rest density 1 between walls at y = 0 and y = H = 1 (the walls' particles start half
   a spacing outside, so the no-slip plane is at 0 and H), N particles across, 0.5 m long and
   periodic in x, nu = 0.5 m^2/s, g = 1 m/s^2 along x: u_max = g H^2 / (8 nu) = 0.25 m/s, Re =
   u_max H / nu = 0.5. Sound speed 10 u_max. The slowest mode of the start-up decays as
   exp(-pi^2 nu t / H^2) (the first term of the series solution), 0.2 s: at t = 2.5 s it is e^-12 of its start,
   far below 1e-3, so the profile is the steady one. */
static poiseuille_result run_poiseuille(sph_solver solver, int N, double t_end) {
    const double H = 1.0, L = 0.5, nu = 0.5, g = 1.0, umax = g * H * H / (8 * nu);
    sph_world_def def = sph_world_def_default(2);
    sph_world w;
    sph_phase fluid;
    sph_real lo[2] = {0, 0}, hi[2] = {(sph_real)L, (sph_real)H};
    poiseuille_result r;
    double sum[80], cnt[80], t0;
    size_t i;
    int b;
    memset(&r, 0, sizeof r);
    def.spacing = (sph_real)(H / N);
    def.solver = solver;
    def.gravity[0] = (sph_real)g;
    def.gravity[1] = 0;
    def.wall = SPH_WALL_NO_SLIP;
    def.periodic[0] = 1;
    def.domain_lo[0] = 0;
    def.domain_hi[0] = (sph_real)L;
    memset(&fluid, 0, sizeof fluid);
    fluid.rest_density = 1;
    fluid.viscosity = (sph_real)nu;
    fluid.sound_speed = (sph_real)(10 * umax);
    if (sph_world_init(&w, &def) != SPH_OK || sph_world_add_phase(&w, &fluid) != 0 ||
        sph_fill_box(&w, 0, lo, hi) != SPH_OK ||
        sph_add_wall_box(&w, lo, hi, 0, SPH_FACE_XMIN | SPH_FACE_XMAX) != SPH_OK) {
        th_fail(__FILE__, __LINE__, "channel setup: %s", w.error);
        r.status = w.status;
        return r;
    }
    t0 = (double)clock() / CLOCKS_PER_SEC;
    r.status = sph_advance(&w, (sph_real)t_end);
    r.steps = (unsigned long long)w.steps;
    r.ms_step = 1e3 * ((double)clock() / CLOCKS_PER_SEC - t0) / (double)(w.steps ? w.steps : 1);
    for (b = 0; b < N; ++b) sum[b] = cnt[b] = 0;
    for (i = 0; i < w.n; ++i) {
        b = (int)floor((double)w.x[2 * i + 1] / H * N);
        if (b >= 0 && b < N) { sum[b] += (double)w.v[2 * i]; cnt[b] += 1; }
        r.v_max = fmax(r.v_max, fabs((double)w.v[2 * i + 1]) / umax);
    }
    for (b = 0; b < N; ++b) {
        const double y = (b + 0.5) * H / N, ue = g * y * (H - y) / (2 * nu);
        const double e = cnt[b] > 0 ? (sum[b] / cnt[b] - ue) / umax : 1;
        r.rms += e * e;
        if (b == N / 2 - 1 || b == N / 2) r.centre += 0.5 * e;
    }
    r.rms = sqrt(r.rms / N);
    sph_world_free(&w);
    return r;
}

static const char* solver_label(sph_solver s) {
    return s == SPH_SOLVER_WCSPH ? "WCSPH" : s == SPH_SOLVER_IISPH ? "IISPH"
           : s == SPH_SOLVER_DFSPH ? "DFSPH" : s == SPH_SOLVER_PCISPH ? "PCISPH" : "other";
}

static void check_poiseuille(sph_solver solver, int N) {
    const poiseuille_result r = run_poiseuille(solver, N, 2.5);
    CHECK_MSG(r.status == SPH_OK, "%s Poiseuille: status %d", solver_label(solver), (int)r.status);
    TH_NOTE("%s Poiseuille, %d across, t = 2.5 s: centre error %+.4f u_max, RMS %.4f u_max, "
            "|v_y| <= %.1e u_max, %llu steps, %.3f ms per step", solver_label(solver), N,
            r.centre, r.rms, r.v_max, r.steps, r.ms_step);
    CHECK_LT(fabs(r.centre), 0.01);
    CHECK_LT(r.rms, 0.01);
    CHECK_LT(r.v_max, 0.01);
}

static void test_poiseuille_wcsph_20(void) { check_poiseuille(SPH_SOLVER_WCSPH, 20); }
static void test_poiseuille_iisph_20(void) { check_poiseuille(SPH_SOLVER_IISPH, 20); }
static void test_poiseuille_dfsph_20(void) { check_poiseuille(SPH_SOLVER_DFSPH, 20); }
static void test_poiseuille_wcsph_40(void) { check_poiseuille(SPH_SOLVER_WCSPH, 40); }

/* ---- a decaying vortex in a closed box ----------------------------------------------------- */

typedef struct decay_result {
    sph_status status;
    double ratio; /* measured decay rate of the kinetic energy / exact rate 4 pi^2 nu / L^2 [-] */
    double ke;    /* KE(t_end) / KE(0) [-]                                                     */
    double rise;  /* largest rise of the kinetic energy from one frame to the next / KE(0) [-] */
    size_t out;   /* fluid particles past the first wall layer's plane at a frame end (most)   */
} decay_result;

/* Fluid particles of w farther than 0.5 dx outside the box [0, hi] (the first wall layer's
   plane of sph_add_wall_box). */
static size_t box_outside(const sph_world* w, const double* hi) {
    const double e = 0.5 * (double)w->dx;
    size_t i, n = 0;
    int k;
    for (i = 0; i < w->n; ++i)
        for (k = 0; k < w->dim; ++k) {
            const double x = (double)w->x[i * (size_t)w->dim + (size_t)k];
            if (x < -e || x > hi[k] + e) { ++n; break; }
        }
    return n;
}

/* A unit box of water (rest density 1000, nu = 0.01 m^2/s, no gravity) completely filled, walls
   with the defaults (free slip), u = U sin(pi x) cos(pi y), v = -U cos(pi x) sin(pi y), U = 1 m/s:
   a Taylor-Green cell of wavelength 2 L. The walls carry no normal velocity and no shear stress
   (dv/dx = 0 at x = 0, L), so the free-slip box holds the periodic solution exactly: nu Lap u =
   -2 pi^2 nu / L^2 u, and the kinetic energy decays as exp(-4 pi^2 nu t / L^2) (0.395 /s; the
   nonlinear term is a gradient the pressure balances). The scene of tests/test_scenes.c's box.
   Through sph_advance with the defaults; the rate is the least-squares slope of ln KE over
   samples every 0.05 s. alpha: def.alpha (artificial viscosity; default 0.02); shifting:
   def.shifting (default 0). */
static decay_result run_box_decay(sph_solver solver, int N, double alpha, double shifting,
                                  double t_end, double frame) {
    const double nu = 0.01, L = 1, exact = 4 * SCENE_TG_PI * SCENE_TG_PI * nu / (L * L);
    const double box[2] = {L, L};
    sph_world_def def = sph_world_def_default(2);
    sph_world w;
    decay_result r;
    double st = 0, sy = 0, stt = 0, sty = 0, ns = 0, ke0 = 0, ke = 0;
    int f, frames = (int)(t_end / frame + 0.5);
    size_t i;
    memset(&r, 0, sizeof r);
    if (solver == SPH_SOLVER_PCISPH) sph_world_def_pcisph(&def, 0);
    def.solver = solver;
    def.alpha = (sph_real)alpha;
    def.shifting = (sph_real)shifting;
    r.status = scene_vortex_box(&w, def, L, N, nu, 0);
    if (r.status != SPH_OK) {
        th_fail(__FILE__, __LINE__, "box setup: %s", scene_error);
        return r;
    }
    for (i = 0; i < 2 * w.n; ++i) ke0 += 0.5 * (double)w.v[i] * (double)w.v[i];
    st = 0; sy = log(ke0); stt = 0; sty = 0; ns = 1;
    for (f = 1; f <= frames && r.status == SPH_OK; ++f) {
        const double ke_prev = f > 1 ? ke : ke0;
        r.status = sph_advance(&w, (sph_real)frame);
        ke = 0;
        for (i = 0; i < 2 * w.n; ++i) ke += 0.5 * (double)w.v[i] * (double)w.v[i];
        if ((ke - ke_prev) / ke0 > r.rise) r.rise = (ke - ke_prev) / ke0;
        if (box_outside(&w, box) > r.out) r.out = box_outside(&w, box);
        st += w.time; sy += log(ke); stt += w.time * w.time; sty += w.time * log(ke); ns += 1;
    }
    if (r.status != SPH_OK) th_fail(__FILE__, __LINE__, "box decay: %s", w.error);
    r.ratio = -(ns * sty - st * sy) / (ns * stt - st * st) / exact;
    r.ke = ke / ke0;
    sph_world_free(&w);
    return r;
}

/* Per solver with the defaults, over 0.5 s at 25 x 25: the kinetic energy decays at least at the
   physical rate (ratio >= 0.9: a viscous term that lost part of its Laplacian, or walls that
   added energy, would show), and the default artificial viscosity (alpha = 0.02) accounts for
   less than a quarter of the excess over the physical rate (it is not what makes the decay too
   fast). The upper bounds are the known excess (measured 4.3 WCSPH, 3.1 IISPH and DFSPH, 2.4
   PCISPH): the lattice breaks up along the stretching directions after t = 0.2 s and the
   disordered particles dissipate; they hold it from growing unnoticed, they do not call it
   right. How it breaks up is chaotic: the frame length alone (where sph_advance's steps land)
   moved IISPH's rate between 2.77 and 3.31 (0.025, 0.05, 0.1 and 0.5 s frames) and the
   difference alpha makes between 0.03 and 0.34, so each rate is the mean of a run in 0.05 s and
   one in 0.1 s frames. */
static void test_box_decay(void) {
    static const sph_solver solvers[] = {SPH_SOLVER_WCSPH, SPH_SOLVER_IISPH, SPH_SOLVER_DFSPH,
                                         SPH_SOLVER_PCISPH};
    static const double known_excess[] = {4.6, 3.3, 3.4, 3.4};
    int s, k;
    for (s = 0; s < 4; ++s) {
        double on = 0, off = 0, ke_on = 0, ke_off = 0;
        for (k = 0; k < 2; ++k) {
            const double frame = k ? 0.1 : 0.05;
            const decay_result a = run_box_decay(solvers[s], 25, 0.02, 0, 0.5, frame);
            const decay_result b = run_box_decay(solvers[s], 25, 0, 0, 0.5, frame);
            CHECK_EQ_INT(a.status, SPH_OK);
            CHECK_EQ_INT(b.status, SPH_OK);
            on += 0.5 * a.ratio;
            off += 0.5 * b.ratio;
            ke_on += 0.5 * a.ke;
            ke_off += 0.5 * b.ke;
        }
        TH_NOTE("%s vortex box 25^2, t <= 0.5 s: decay rate / exact %.3f (alpha 0.02, KE %.3f), "
                "%.3f (alpha 0, KE %.3f); exact KE %.3f", solver_label(solvers[s]), on, ke_on,
                off, ke_off, exp(-4 * SCENE_TG_PI * SCENE_TG_PI * 0.01 * 0.5));
        CHECK_LE(0.9, on);
        CHECK_LE(0.9, off);
        CHECK_LT(fabs(on - off), 0.25 * (on - 1));
        CHECK_LT(on, known_excess[s]);
    }
}

/* The same cell in a box built here: 1 x 1 m at dx 0.04 (2D) or 1 x 1 x 0.3 m at dx 0.05 (3D),
   walls of sph_add_wall_box on every side, u = sin(pi x) cos(pi y), v = -cos(pi x) sin(pi y)
   (w = 0), nu 0.01, 0.5 s in frames of `frame` seconds. With gravity g > 0 (along -y) the
   pressure starts hydrostatic (sph_set_hydrostatic, velocities kept). ke: KE(0.5 s) / KE(0)
   (exact without gravity 0.821); rise: the largest rise of the mechanical energy (kinetic plus
   m g y) from one frame to the next, over KE(0). */
static decay_result run_box_cell(sph_solver solver, int dim, double shifting, double g,
                                 double frame) {
    sph_world_def def = sph_world_def_default(dim);
    sph_world w;
    sph_phase water;
    decay_result r;
    sph_real lo[3] = {0, 0, 0}, hi[3] = {1, 1, (sph_real)0.3};
    const double box[3] = {1, 1, (double)hi[2]};
    const int frames = (int)(0.5 / frame + 0.5);
    double ke0 = 0, ke = 0, e = 0, e_prev, m;
    size_t i;
    int f, k;
    memset(&r, 0, sizeof r);
    memset(&water, 0, sizeof water);
    def.spacing = (sph_real)(dim == 2 ? 0.04 : 0.05);
    def.gravity[1] = (sph_real)-g;
    def.solver = solver;
    def.shifting = (sph_real)shifting;
    water.rest_density = 1000;
    water.viscosity = (sph_real)0.01;
    r.status = sph_world_init(&w, &def);
    if (r.status != SPH_OK) return r;
    if (sph_world_add_phase(&w, &water) < 0 || sph_fill_box(&w, 0, lo, hi) != SPH_OK ||
        sph_add_wall_box(&w, lo, hi, 0, 0) != SPH_OK) {
        r.status = SPH_ERR_ARG;
        sph_world_free(&w);
        return r;
    }
    for (i = 0; i < w.n; ++i) {
        const double x = (double)w.x[(size_t)dim * i], y = (double)w.x[(size_t)dim * i + 1];
        w.v[(size_t)dim * i] = (sph_real)(sin(SCENE_TG_PI * x) * cos(SCENE_TG_PI * y));
        w.v[(size_t)dim * i + 1] = (sph_real)(-cos(SCENE_TG_PI * x) * sin(SCENE_TG_PI * y));
        if (dim == 3) w.v[3 * i + 2] = 0;
    }
    if (g > 0 && sph_set_hydrostatic(&w) != SPH_OK) {
        r.status = SPH_ERR_ARG;
        sph_world_free(&w);
        return r;
    }
    m = sph_world_mass(&w) / (double)w.n;
    for (f = 0; f <= frames && r.status == SPH_OK; ++f) {
        if (f > 0) r.status = sph_advance(&w, (sph_real)frame);
        e_prev = e;
        ke = e = 0;
        for (i = 0; i < w.n; ++i) {
            for (k = 0; k < dim; ++k)
                ke += 0.5 * m * (double)w.v[(size_t)dim * i + (size_t)k] *
                      (double)w.v[(size_t)dim * i + (size_t)k];
            e += m * g * (double)w.x[(size_t)dim * i + 1];
        }
        e += ke;
        if (f == 0) ke0 = ke;
        else if ((e - e_prev) / ke0 > r.rise) r.rise = (e - e_prev) / ke0;
        if (box_outside(&w, box) > r.out) r.out = box_outside(&w, box);
    }
    if (r.status != SPH_OK) th_fail(__FILE__, __LINE__, "%dD box: %s", dim, w.error);
    r.ke = ke / ke0;
    sph_world_free(&w);
    return r;
}

/* The same box with particle shifting (def.shifting = 4, Sun et al. 2017; sph__stage_shift),
   which keeps the particles ordered where the lattice broke up: the excess decay is the
   disorder's, so the shifted box decays closer to exp(-4 pi^2 nu t). Measured at 25 x 25 over
   0.5 s in 0.05 s frames, decay rate over the exact one (unshifted in brackets): WCSPH 1.13
   (4.17), IISPH 1.99 (3.32), DFSPH 2.10 (3.17). IISPH and DFSPH shift less per simulated second
   (D = A h U dt is bounded by 0.1 h^2 / dim per step for them, half WCSPH's bound, and they take
   7 times fewer steps; see test_box_gravity_shifting for why), so they keep more of the excess.
   Asserted: the rate at least 0.9 of the exact one, at most 1.3 times it (WCSPH) or 2.4 (IISPH,
   DFSPH), at most 0.7 of the unshifted rate, and the kinetic energy never above the last
   frame's, no fluid particle past the first wall layer's plane (0.5 dx outside the box); in the
   3D box (run_box_cell) IISPH and DFSPH keep at least 0.05 of the start's kinetic energy more
   than unshifted, never more than the exact decay leaves, and never rising. */
static void test_box_decay_shifting(void) {
    static const sph_solver solvers[] = {SPH_SOLVER_WCSPH, SPH_SOLVER_IISPH, SPH_SOLVER_DFSPH};
    static const double bound[] = {1.3, 2.4, 2.4};
    int s;
    for (s = 0; s < 3; ++s) {
        const decay_result a = run_box_decay(solvers[s], 25, 0.02, 4, 0.5, 0.05);
        const decay_result b = run_box_decay(solvers[s], 25, 0.02, 0, 0.5, 0.05);
        CHECK_EQ_INT(a.status, SPH_OK);
        CHECK_EQ_INT(b.status, SPH_OK);
        TH_NOTE("%s vortex box 25^2, t <= 0.5 s: decay rate / exact %.3f with shifting 4 (KE "
                "%.3f, largest rise %.2e), %.3f without (KE %.3f); exact KE %.3f",
                solver_label(solvers[s]), a.ratio, a.ke, a.rise, b.ratio, b.ke,
                exp(-4 * SCENE_TG_PI * SCENE_TG_PI * 0.01 * 0.5));
        CHECK_LE(0.9, a.ratio);
        CHECK_LE(a.ratio, bound[s]);
        CHECK_LE(a.ratio, 0.7 * b.ratio);
        CHECK_LE(a.rise, 0);
        CHECK_EQ_INT(a.out, 0);
    }
    /* 3D (IISPH, DFSPH): measured KE(0.5 s) 0.537 and 0.538 shifted, 0.483 unshifted (exact
       0.821); no rise */
    for (s = 1; s < 3; ++s) {
        const decay_result a = run_box_cell(solvers[s], 3, 4, 0, 0.05);
        const decay_result b = run_box_cell(solvers[s], 3, 0, 0, 0.05);
        CHECK_EQ_INT(a.status, SPH_OK);
        CHECK_EQ_INT(b.status, SPH_OK);
        TH_NOTE("%s 3D vortex box 20 x 20 x 6, 0.5 s: KE %.3f with shifting 4 (largest rise "
                "%.2e), %.3f without; exact %.3f", solver_label(solvers[s]), a.ke, a.rise, b.ke,
                exp(-4 * SCENE_TG_PI * SCENE_TG_PI * 0.01 * 0.5));
        CHECK_LE(b.ke + 0.05, a.ke);
        CHECK_LE(a.ke, exp(-4 * SCENE_TG_PI * SCENE_TG_PI * 0.01 * 0.5));
        CHECK_LE(a.rise, 0);
        CHECK_EQ_INT(a.out, 0);
    }
}

/* The shifted box under gravity (g = 9.81 m/s^2, the pressure starting hydrostatic): IISPH and
   DFSPH sum their density again at the next step, so what a shift compresses the next pressure
   solve pushes apart, and against the hydrostatic pressure that push is work the shift never
   paid: with D bounded by 0.2 h^2 / dim (WCSPH's bound, theirs before) the mechanical energy
   rose from one frame to the next in 8 of 16 runs (2D and 3D, frames of 0.04-0.125 s), by up to
   8.6 % (2D) and 20 % (3D) of the start's kinetic energy; at 0.1 h^2 / dim in none of them.
   WCSPH carries its density: a shift moves a particle with its density and pressure, and puts
   no energy in. Asserted: the mechanical energy (kinetic plus m g y) never rises by more than
   1e-3 of the start's kinetic energy from one frame to the next, every frame succeeds, nothing
   passes the first wall layer, in the runs that rose before: 2D IISPH and DFSPH with 0.04 and
   0.05 s frames (3.9, 4.1 and 8.6, 2.9 % before), 3D IISPH with 0.04 s frames (20 %) and DFSPH
   with 0.1 s (4.8 %). */
static void test_box_gravity_shifting(void) {
    static const struct {
        sph_solver solver;
        int dim;
        double frame;
    } runs[] = {{SPH_SOLVER_IISPH, 2, 0.04}, {SPH_SOLVER_IISPH, 2, 0.05},
                {SPH_SOLVER_DFSPH, 2, 0.04}, {SPH_SOLVER_DFSPH, 2, 0.05},
                {SPH_SOLVER_IISPH, 3, 0.04}, {SPH_SOLVER_DFSPH, 3, 0.1}};
    size_t q;
    for (q = 0; q < sizeof runs / sizeof runs[0]; ++q) {
        const decay_result a = run_box_cell(runs[q].solver, runs[q].dim, 4, 9.81, runs[q].frame);
        CHECK_EQ_INT(a.status, SPH_OK);
        TH_NOTE("%s %dD vortex box under gravity, shifting 4, %.2f s frames: largest rise of the "
                "mechanical energy %.2e of KE(0), KE(0.5 s) %.3f", solver_label(runs[q].solver),
                runs[q].dim, runs[q].frame, a.rise, a.ke);
        CHECK_LE(a.rise, 1e-3);
        CHECK_EQ_INT(a.out, 0);
    }
}

/* ---- conservation and determinism of the normalised term ------------------------------------ */

/* A periodic box of viscous fluid (nu = 0.05 m^2/s, no walls, no gravity) on a lattice shaken by
   up to 0.025 dx, so every particle's moment m_i differs, with a sheared velocity field: the pair
   factor (1/m_i + 1/m_j)/2 is symmetric, so the forces are pairwise antisymmetric and the total
   momentum stays at its start to round-off (relative to sum m |v|) over 20 steps, per solver
   (1/m_i alone in place of the pair factor leaves 3e-7 ... 7e-6 of it). */
static void test_momentum_conserved(void) {
    static const sph_solver solvers[] = {SPH_SOLVER_WCSPH, SPH_SOLVER_IISPH, SPH_SOLVER_DFSPH};
    int s;
    for (s = 0; s < 3; ++s) {
        sph_world_def def = sph_world_def_default(2);
        sph_world w;
        sph_phase fluid;
        sph_real lo[2] = {0, 0}, hi[2] = {1, 1};
        double p0[2] = {0, 0}, p1[2] = {0, 0}, scale = 0, lcg = 1;
        size_t i;
        int k;
        memset(&fluid, 0, sizeof fluid);
        fluid.rest_density = 1;
        fluid.viscosity = (sph_real)0.05;
        fluid.sound_speed = 10;
        def.solver = solvers[s];
        def.spacing = (sph_real)(1.0 / 30);
        def.gravity[1] = 0;
        for (k = 0; k < 2; ++k) {
            def.periodic[k] = 1;
            def.domain_lo[k] = 0;
            def.domain_hi[k] = 1;
        }
        CHECK_EQ_INT(sph_world_init(&w, &def), SPH_OK);
        CHECK(sph_world_add_phase(&w, &fluid) == 0);
        CHECK_EQ_INT(sph_fill_box(&w, 0, lo, hi), SPH_OK);
        for (i = 0; i < w.n; ++i) {
            for (k = 0; k < 2; ++k) { /* a linear congruential sequence: the same in every build */
                lcg = fmod(lcg * 16807.0, 2147483647.0);
                w.x[2 * i + (size_t)k] += (sph_real)(0.05 * (lcg / 2147483647.0 - 0.5) * (double)w.dx);
            }
            w.v[2 * i] = (sph_real)(0.3 + sin(2 * SCENE_TG_PI * (double)w.x[2 * i + 1]));
            w.v[2 * i + 1] = (sph_real)(0.5 * cos(2 * SCENE_TG_PI * (double)w.x[2 * i]));
        }
        for (i = 0; i < w.n; ++i)
            for (k = 0; k < 2; ++k) p0[k] += (double)w.mass * (double)w.v[2 * i + (size_t)k];
        for (k = 0; k < 20; ++k) {
            sph_status st = th_step(&w, (sph_real)2e-4);
            CHECK_MSG(st == SPH_OK, "%s: %s", solver_label(solvers[s]), w.error);
            if (st != SPH_OK) break;
        }
        for (i = 0; i < w.n; ++i)
            for (k = 0; k < 2; ++k) {
                p1[k] += (double)w.mass * (double)w.v[2 * i + (size_t)k];
                scale += (double)w.mass * fabs((double)w.v[2 * i + (size_t)k]);
            }
        TH_NOTE("%s periodic shaken box, nu = 0.05, 20 steps: |P - P0| / sum m|v| = %.2g, %.2g",
                solver_label(solvers[s]), fabs(p1[0] - p0[0]) / scale, fabs(p1[1] - p0[1]) / scale);
        CHECK_LT(fabs(p1[0] - p0[0]) / scale, 100 * TH_EPS);
        CHECK_LT(fabs(p1[1] - p0[1]) / scale, 100 * TH_EPS);
        sph_world_free(&w);
    }
}

/* The normalisation pass is a gather like every other: 1 and 2 threads give bitwise the same
   state (the no-slip vortex box at 60 x 60, above the 2048 particles of the serial cutoff, 10
   steps, WCSPH and IISPH). */
#ifdef _OPENMP
static uint64_t viscous_box_hash(sph_solver solver, int threads) {
    sph_world_def def = sph_world_def_default(2);
    sph_world w;
    uint64_t hash;
    int k;
    omp_set_num_threads(threads);
    def.solver = solver;
    def.wall = SPH_WALL_NO_SLIP;
    CHECK_EQ_INT(scene_vortex_box(&w, def, 1, 60, 0.01, 10), SPH_OK);
    for (k = 0; k < 10; ++k) CHECK_EQ_INT(th_step(&w, sph_stable_dt(&w, solver)), SPH_OK);
    CHECK(w.n > 2048);
    hash = th_state_hash(&w);
    sph_world_free(&w);
    return hash;
}

#endif

static void test_threads_bitwise(void) {
#ifdef _OPENMP
    static const sph_solver solvers[] = {SPH_SOLVER_WCSPH, SPH_SOLVER_IISPH};
    int s;
    for (s = 0; s < 2; ++s) {
        const uint64_t h1 = viscous_box_hash(solvers[s], 1), h2 = viscous_box_hash(solvers[s], 2);
        CHECK_MSG(h1 == h2, "%s: 1 and 2 threads differ", solver_label(solvers[s]));
    }
    omp_set_num_threads(omp_get_num_procs());
#else
    TH_SKIP("built without OpenMP");
#endif
}

const th_test tests_viscous[] = {
    {"viscous/poiseuille_wcsph_20", test_poiseuille_wcsph_20},
    {"viscous/poiseuille_iisph_20", test_poiseuille_iisph_20},
    {"viscous/poiseuille_dfsph_20", test_poiseuille_dfsph_20},
    {"viscous/box_decay", test_box_decay},
    {"viscous/box_decay_shifting", test_box_decay_shifting},
    {"viscous/box_gravity_shifting", test_box_gravity_shifting},
    {"viscous/momentum_conserved", test_momentum_conserved},
    {"viscous/threads_bitwise", test_threads_bitwise},
    {0, 0},
};

const th_test tests_viscous_long[] = {
    {"viscous-long/poiseuille_wcsph_40", test_poiseuille_wcsph_40},
    {0, 0},
};
