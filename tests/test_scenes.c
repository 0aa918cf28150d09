/* tests/test_scenes.c - what a user gets: ordinary scenes run only through sph_advance with the
   library's defaults (no hand-set max_dt, tolerance or iteration count), for every solver and
   every wall pressure scheme, in 2D and 3D:
     tank   water at rest in a closed box, started by sph_set_hydrostatic;
     dam    a water column collapsing in a closed tank (Martin & Moyce 1952's proportions);
     slosh  a half-full tank moved sideways by the boundary-motion callback;
     box    a closed box completely filled, no gravity, a decaying vortex u = sin(pi x) cos(pi y),
            v = -cos(pi x) sin(pi y) (nu = 0.01): an enclosed fluid without forcing;
     ring   the tank with walls the host places itself (a circle of boundary particles, 3 layers),
            not sph_add_wall_box;
     ring1  the same with a single layer of boundary particles and Akinci volumes
            (SPH_BVOL_AKINCI, the library's recipe for single-layer walls);
     shell  the dam break in a box whose walls are one layer of boundary particles the host
            places on the box's faces (the default volumes, SPH_BVOL_AUTO), in 2D and 3D;
     jet    the shell's column thrown at 10 m/s against the far wall (a violent impact on
            single-layer walls: corner jets three to four times as fast);
     drum   a drum turning at 2 rad/s about its axis (the boundary-motion callback), a third
            full, its wall one layer of the lattice points a host keeps in the band
            R <= r < R + dx (a staircase with diagonal gaps of 1.41 dx; in 3D a cylinder with
            single-layer end caps), Akinci volumes (with the default volumes PBF let a particle
            out of the 3D drum at 0.4 s in float, see README, Limits);
     drop   a disc (2D) or ball (3D) of water, radius 0.15 of the box's width, let fall from
            rest with its centre 0.7 m above the floor of a closed box 1 m tall: the impact of a
            round body throws jets several times its speed along the floor;
     film   a film of water one spacing thick at rest on the tank's floor (what a splash leaves),
            started by sph_set_hydrostatic: every particle's only support is the wall below.
   Every run checks, frame by frame, that a failure is reported (a status with a message, the
   world as before the failing call), never silent. With each solver's default wall scheme
   (make test: short 2D and 3D variants; make validate: longer and finer) the run must get
   through, no fluid particle may go through a wall (more than half a spacing past the first
   layer), the mass is exact, and without forcing the energy (kinetic + potential) must not rise
   by more than 0.5 % of the scale rho g H^2 (tank, dam, ring) or 0.1 % of the kinetic energy per
   frame (box). Every other wall scheme runs in make validate, where it must report what it
   cannot do (no particle through a wall in a frame that returned SPH_OK); mirrored wall
   pressure must be refused by sph_world_init with its reason. How close to rest the
   tank stays (largest speed of its last half second against sqrt(g H)) is printed. */
#include "harness.h"
#include "../sph.h"
#include "../examples/scenes.h"
#include "tank_profile.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

typedef enum { SC_TANK, SC_DAM, SC_SLOSH, SC_BOX, SC_RING, SC_RING1, SC_SHELL, SC_JET, SC_DRUM, SC_DROP, SC_FILM } sc_scene;
static const char* const sc_names[] = {"tank", "dam",   "slosh", "box", "ring",
                                       "ring1", "shell", "jet",  "drum", "drop", "film"};

typedef struct sc_solver {
    const char* name;
    sph_solver solver;
    int pcisph; /* -1: not PCISPH; 0 original; 1 enhanced */
} sc_solver;

static const sc_solver sc_solvers[] = {{"WCSPH", SPH_SOLVER_WCSPH, -1},
                                       {"PCISPH orig", SPH_SOLVER_PCISPH, 0},
                                       {"PCISPH enh", SPH_SOLVER_PCISPH, 1},
                                       {"IISPH", SPH_SOLVER_IISPH, -1},
                                       {"DFSPH", SPH_SOLVER_DFSPH, -1},
                                       {"PBF", SPH_SOLVER_PBF, -1}};
static const char* const sc_bp_names[] = {"extrapolate", "mirror", "zero"}; /* mirror: refused */
static const char* sc_bp_name(int bp) { return bp < 0 ? "default" : sc_bp_names[bp]; }

typedef struct sc_result {
    sph_status status;   /* first failure (SPH_OK if none)                           */
    double t_end;        /* time reached                                             */
    double v_late;       /* largest speed over the last half second [m/s]            */
    double v_ref;        /* sqrt(g H) (tank), 1 m/s (box)                             */
    double e_rise;       /* largest rise of the energy above its start, / scale      */
    size_t escaped;      /* fluid particles past the first wall layer, at most       */
    size_t in_layer;     /* ... past the first layer's centres by less than that     */
    int silent_escape;   /* a frame returned SPH_OK with a particle through a wall   */
    double mass_err;     /* |M - M0| / M0                                            */
    double ke_ratio;     /* box: KE(end) / KE(0)                                     */
    unsigned long long steps;
    int retries;
} sc_result;

static double sc_slosh_amp = 0.03, sc_slosh_freq = 1.0;

static void sc_slosh_motion(sph_world* w, double t, void* user) {
    const double om = 2 * M_PI * sc_slosh_freq, a = sc_slosh_amp;
    size_t b;
    (void)user;
    for (b = 0; b < w->nb; ++b) {
        const size_t o = b * (size_t)w->dim;
        w->b_x[o] = w->b_x0[o] + (sph_real)(a * sin(om * t));
        w->b_v[o] = (sph_real)(a * om * cos(om * t));
        w->b_a[o] = (sph_real)(-a * om * om * sin(om * t));
    }
}

/* The drum: its axis through (R, R) along z, turning at sc_drum_omega [rad/s]. */
static const double sc_drum_omega = 2.0;

static void sc_drum_motion(sph_world* w, double t, void* user) {
    const int D = w->dim;
    const double R = *(const double*)user, c = cos(sc_drum_omega * t), s = sin(sc_drum_omega * t);
    size_t b;
    for (b = 0; b < w->nb; ++b) {
        const size_t o = b * (size_t)D;
        const double rx = (double)w->b_x0[o] - R, ry = (double)w->b_x0[o + 1] - R;
        const double x = c * rx - s * ry, y = s * rx + c * ry;
        w->b_x[o] = (sph_real)(R + x);
        w->b_x[o + 1] = (sph_real)(R + y);
        w->b_v[o] = (sph_real)(-sc_drum_omega * y);
        w->b_v[o + 1] = (sph_real)(sc_drum_omega * x);
        w->b_a[o] = (sph_real)(-sc_drum_omega * sc_drum_omega * x);
        w->b_a[o + 1] = (sph_real)(-sc_drum_omega * sc_drum_omega * y);
    }
}

/* Potential energy of the fluid in gravity [J]. */
static double sc_potential(const sph_world* w) {
    double e = 0;
    size_t i;
    int k;
    for (i = 0; i < w->n; ++i)
        for (k = 0; k < w->dim; ++k)
            e -= (double)(w->m ? w->m[i] : w->mass) * (double)w->def.gravity[k] *
                 (double)w->x[i * (size_t)w->dim + (size_t)k];
    return e;
}

/* Particles outside the container by more than tol: with tol = dx, through the first wall layer
   (half a spacing past the first layer's line; the library's check_walls reports the same);
   with tol = dx / 2, past the first layer's line (printed: a known defect of 3D impacts). */
static size_t sc_escaped(const sph_world* w, sc_scene sc, const double* lo, const double* hi,
                         double R, double tol) {
    const int D = w->dim;
    size_t i, out = 0;
    int k;
    for (i = 0; i < w->n; ++i) {
        const sph_real* x = w->x + i * (size_t)D;
        int bad = 0;
        if (sc == SC_RING || sc == SC_RING1) {
            const double dx0 = (double)x[0] - 0.5 * (lo[0] + hi[0]), dy = (double)x[1] - R;
            bad = sqrt(dx0 * dx0 + dy * dy) > R + tol;
        } else if (sc == SC_DRUM) { /* past the band of the wall's centres, R + dx */
            const double dx0 = (double)x[0] - R, dy = (double)x[1] - R;
            bad = sqrt(dx0 * dx0 + dy * dy) > R + (double)w->dx + tol - 0.5 * (double)w->dx ||
                  (D == 3 && ((double)x[2] < lo[2] - tol || (double)x[2] > hi[2] + tol));
        } else {
            for (k = 0; k < D; ++k)
                if ((double)x[k] < lo[k] - tol || (double)x[k] > hi[k] + tol) bad = 1;
        }
        out += bad != 0;
    }
    return out;
}

/* A ring of boundary particles placed by the host: `layers` circles outside radius R about
   (R, R), spacing dx along each, volume dx^2 (or Akinci's, as def says); the fluid fills the
   disc's lower 0.6 2R. */
static sph_status sc_build_ring(sph_world* w, const sph_world_def* def, int ph, double R,
                                int layers) {
    const double dx = (double)def->spacing;
    sph_real* xs = NULL;
    size_t n = 0, cap = 0;
    int l;
    sph_status s;
    for (l = 0; l < layers; ++l) {
        const double r = R + (l + 0.5) * dx;
        const int m = (int)ceil(2 * M_PI * r / dx);
        int q;
        if (n + (size_t)m > cap) {
            cap = 2 * (n + (size_t)m);
            xs = (sph_real*)realloc(xs, cap * 2 * sizeof(sph_real));
        }
        for (q = 0; q < m; ++q) {
            xs[2 * n] = (sph_real)(R + r * cos(2 * M_PI * q / m));
            xs[2 * n + 1] = (sph_real)(R + r * sin(2 * M_PI * q / m));
            ++n;
        }
    }
    s = sph_add_boundary(w, n, xs, NULL, 0);
    free(xs);
    if (s != SPH_OK) return s;
    { /* fluid: lattice points of the disc below 0.6 of its height */
        sph_real* xf = (sph_real*)malloc(sizeof(sph_real) * 2 * (size_t)(4 * R * R / (dx * dx) + 8));
        size_t nf = 0;
        int i, j;
        const int N = (int)(2 * R / dx);
        for (i = 0; i < N; ++i)
            for (j = 0; j < N; ++j) {
                const double x = (i + 0.5) * dx, y = (j + 0.5) * dx;
                if (hypot(x - R, y - R) < R - 0.5 * dx && y < 1.2 * R) {
                    xf[2 * nf] = (sph_real)x;
                    xf[2 * nf + 1] = (sph_real)y;
                    ++nf;
                }
            }
        s = sph_add_fluid(w, ph, nf, xf, NULL);
        free(xf);
    }
    return s;
}

/* The drum: the lattice points (spacing dx, offset half a spacing from the axis) in the band
   R <= r < R + dx about (R, R), over the depth (0, depth) in 3D, and the lattice points of its
   two end caps (one layer, half a spacing outside); the fluid on the same lattice inside
   r < R - dx/2, below y = R - R/6. */
static sph_status sc_build_drum(sph_world* w, int dim, int ph, double dx, double R, double depth) {
    const int M = (int)(R / dx) + 2, nz = dim == 3 ? (int)(depth / dx + 0.5) : 1;
    size_t cap = (size_t)(2 * M) * (size_t)(2 * M) * (size_t)(nz + 2), nb = 0, nf = 0;
    sph_real* xb = (sph_real*)malloc(sizeof(sph_real) * 3 * cap);
    sph_real* xf = (sph_real*)malloc(sizeof(sph_real) * 3 * cap);
    sph_status s = SPH_ERR_NOMEM;
    int i, j, k, q;
    if (xb && xf) {
        for (i = -M; i < M; ++i)
            for (j = -M; j < M; ++j)
                for (k = (dim == 3 ? -1 : 0); k <= (dim == 3 ? nz : 0); ++k) {
                    const double x = (i + 0.5) * dx, y = (j + 0.5) * dx, r = hypot(x, y);
                    const double p[3] = {R + x, R + y, (k + 0.5) * dx};
                    const int cap_layer = dim == 3 && (k == -1 || k == nz);
                    if (cap_layer ? r < R + dx : r >= R && r < R + dx) {
                        for (q = 0; q < dim; ++q) xb[nb * (size_t)dim + (size_t)q] = (sph_real)p[q];
                        ++nb;
                    } else if (!cap_layer && r < R - 0.5 * dx && y < -R / 6) {
                        for (q = 0; q < dim; ++q) xf[nf * (size_t)dim + (size_t)q] = (sph_real)p[q];
                        ++nf;
                    }
                }
        s = sph_add_boundary(w, nb, xb, NULL, 0);
        if (s == SPH_OK) s = sph_add_fluid(w, ph, nf, xf, NULL);
    }
    free(xb);
    free(xf);
    return s;
}

/* The drop: the lattice points (spacing dx, offset half a spacing) within radius r of c. */
static sph_status sc_fill_ball(sph_world* w, int dim, int ph, double dx, const double* c, double r) {
    const int N = (int)(r / dx) + 1;
    size_t nf = 0;
    sph_real* xf = (sph_real*)malloc(sizeof(sph_real) * 3 * (size_t)(2 * N + 1) * (size_t)(2 * N + 1) *
                                     (size_t)(dim == 3 ? 2 * N + 1 : 1));
    sph_status s;
    int i, j, k, q;
    if (!xf) return SPH_ERR_NOMEM;
    for (i = -N; i <= N; ++i)
        for (j = -N; j <= N; ++j)
            for (k = (dim == 3 ? -N : 0); k <= (dim == 3 ? N : 0); ++k) {
                const double d[3] = {(i + 0.5) * dx, (j + 0.5) * dx, dim == 3 ? (k + 0.5) * dx : 0};
                if (d[0] * d[0] + d[1] * d[1] + d[2] * d[2] >= r * r) continue;
                for (q = 0; q < dim; ++q) xf[nf * (size_t)dim + (size_t)q] = (sph_real)(c[q] + d[q]);
                ++nf;
            }
    s = sph_add_fluid(w, ph, nf, xf, NULL);
    free(xf);
    return s;
}

/* One layer of boundary particles on the faces of the box [0, hi] (dim 2 or 3), half a spacing
   outside, edges and corners included: walls a host samples from a shape. */
static sph_status sc_build_shell(sph_world* w, int dim, double dx, const double* hi) {
    int n[3] = {1, 1, 1}, i, j, k;
    size_t cap, nb = 0;
    sph_real* xs;
    sph_status s;
    for (k = 0; k < dim; ++k) n[k] = (int)(hi[k] / dx + 0.5);
    cap = (size_t)(n[0] + 2) * (size_t)(n[1] + 2) * (size_t)(dim == 3 ? n[2] + 2 : 1);
    xs = (sph_real*)malloc(sizeof(sph_real) * 3 * cap);
    if (!xs) return SPH_ERR_NOMEM;
    for (i = -1; i <= n[0]; ++i)
        for (j = -1; j <= n[1]; ++j)
            for (k = (dim == 3 ? -1 : 0); k <= (dim == 3 ? n[2] : 0); ++k) {
                if (!(i == -1 || i == n[0] || j == -1 || j == n[1] ||
                      (dim == 3 && (k == -1 || k == n[2]))))
                    continue;
                xs[nb * (size_t)dim] = (sph_real)((i + 0.5) * dx);
                xs[nb * (size_t)dim + 1] = (sph_real)((j + 0.5) * dx);
                if (dim == 3) xs[nb * (size_t)dim + 2] = (sph_real)((k + 0.5) * dx);
                ++nb;
            }
    s = sph_add_boundary(w, nb, xs, NULL, 0);
    free(xs);
    return s;
}

static sc_result sc_run(sc_scene sc, const sc_solver* so, int bp, int dim,
                        double dx, double duration) {
    sc_result r;
    sph_world_def def = sph_world_def_default(dim);
    sph_world w;
    sph_phase water;
    double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, R = 0.5, H = 0.8, m0, e0 = 0, escale, ke_prev;
    double t_prev = 0;
    const double frame = 0.05;
    int ph, k, f, frames = (int)(duration / frame + 0.5);
    sph_real flo[3] = {0, 0, 0}, fhi[3], thi[3];
    memset(&r, 0, sizeof r);
    memset(&water, 0, sizeof water);
    water.rest_density = 1000;
    if (so->pcisph >= 0) sph_world_def_pcisph(&def, so->pcisph);
    def.solver = so->solver;
    if (bp >= 0) def.boundary_pressure = (sph_boundary_pressure)bp;
    def.spacing = (sph_real)dx;
    if (sc == SC_SLOSH) def.boundary_motion = sc_slosh_motion;
    if (sc == SC_DRUM) {
        def.boundary_motion = sc_drum_motion;
        def.boundary_user = &R;
    }
    if (sc == SC_RING1 || sc == SC_DRUM) def.boundary_volume = SPH_BVOL_AKINCI;
    if (sc == SC_BOX) {
        for (k = 0; k < 3; ++k) def.gravity[k] = 0;
        water.viscosity = (sph_real)0.01;
    }
    CHECK_EQ_INT(sph_world_init(&w, &def), SPH_OK);
    ph = sph_world_add_phase(&w, &water);
    /* geometry: a 1 m box (0.4 m in 3D) */
    for (k = 0; k < 3; ++k) { hi[k] = dim == 3 ? 0.4 : 1.0; thi[k] = (sph_real)hi[k]; fhi[k] = (sph_real)hi[k]; }
    switch (sc) {
    case SC_TANK: H = 0.8 * hi[1]; fhi[1] = (sph_real)H; break;
    case SC_SLOSH: H = 0.5 * hi[1]; fhi[1] = (sph_real)H; break;
    case SC_DAM:
    case SC_SHELL:
    case SC_JET: H = 0.5 * hi[1]; fhi[0] = (sph_real)(0.25 * hi[0]); fhi[1] = (sph_real)H; break;
    case SC_BOX: H = hi[1]; break;
    case SC_RING:
    case SC_RING1: R = 0.5 * hi[0]; H = 1.2 * R; break;
    case SC_DRUM: R = 0.3; H = 0.5 * R; hi[2] = 0.2; break;
    case SC_DROP: hi[1] = 1.0; thi[1] = 1; H = 0.7; break; /* in 3D a tall box, 0.4 x 1 x 0.4 m */
    case SC_FILM: H = dx; fhi[1] = (sph_real)H; break;
    }
    if (sc == SC_RING || sc == SC_RING1) {
        CHECK_EQ_INT(sc_build_ring(&w, &def, ph, R, sc == SC_RING ? 3 : 1), SPH_OK);
    } else if (sc == SC_DRUM) {
        CHECK_EQ_INT(sc_build_drum(&w, dim, ph, dx, R, hi[2]), SPH_OK);
    } else if (sc == SC_DROP) {
        const double c[3] = {0.5 * hi[0], H, 0.5 * hi[2]};
        CHECK_EQ_INT(sc_fill_ball(&w, dim, ph, dx, c, 0.15 * hi[0]), SPH_OK); /* r 0.15 | 0.06 m */
        CHECK_EQ_INT(sph_add_wall_box(&w, flo, thi, 0, 0), SPH_OK);
    } else if (sc == SC_SHELL || sc == SC_JET) {
        CHECK_EQ_INT(sph_fill_box(&w, ph, flo, fhi), SPH_OK);
        CHECK_EQ_INT(sc_build_shell(&w, dim, dx, hi), SPH_OK);
    } else {
        CHECK_EQ_INT(sph_fill_box(&w, ph, flo, fhi), SPH_OK);
        CHECK_EQ_INT(sph_add_wall_box(&w, flo, thi, 0, 0), SPH_OK);
    }
    if (sc == SC_BOX) {
        size_t i;
        for (i = 0; i < w.n; ++i) {
            const double x = (double)w.x[i * (size_t)dim] / hi[0], y = (double)w.x[i * (size_t)dim + 1] / hi[1];
            w.v[i * (size_t)dim] = (sph_real)(sin(M_PI * x) * cos(M_PI * y));
            w.v[i * (size_t)dim + 1] = (sph_real)(-cos(M_PI * x) * sin(M_PI * y));
        }
    } else {
        /* the jet's speed first: the automatic sound speed (resolved here) follows the
           fastest particle it sees (10 |v|max), see sph_phase.sound_speed */
        if (sc == SC_JET) {
            size_t i;
            for (i = 0; i < w.n; ++i) w.v[i * (size_t)dim] = 10;
        }
        if (sc != SC_DROP) CHECK_EQ_INT(sph_set_hydrostatic(&w), SPH_OK);
    }
    m0 = sph_world_mass(&w);
    r.v_ref = sc == SC_BOX ? 1.0 : sqrt(9.81 * H);
    /* energy scale: rho g H^2 times the width (and depth) for gravity scenes; KE(0) for the box */
    {
        double ke = 0;
        size_t i;
        for (i = 0; i < w.n * (size_t)dim; ++i) ke += 0.5 * (double)w.mass * (double)w.v[i] * (double)w.v[i];
        escale = sc == SC_BOX ? ke : 1000 * 9.81 * H * H * hi[0] * (dim == 3 ? hi[2] : 1);
        e0 = ke + sc_potential(&w);
        ke_prev = ke;
        r.ke_ratio = 1;
    }
    for (f = 1; f <= frames; ++f) {
        const double ta = w.time;
        double e;
        sph_status s = sph_advance(&w, (sph_real)frame);
        if (s != SPH_OK) {
            /* reported, with a message, and the world as before the call */
            CHECK_MSG(w.error[0] != 0, "%s: status %d without a message", so->name, (int)s);
            CHECK_NEAR(w.time, ta, 0);
            r.status = s;
            TH_NOTE("%-11s %-11s %dD %-5s: %s", so->name, sc_bp_name(bp), dim, sc_names[sc], w.error);
            break;
        }
        t_prev = w.time;
        e = w.stats.kinetic_energy + (sc == SC_BOX ? 0 : sc_potential(&w));
        if (sc != SC_SLOSH && sc != SC_DRUM) { /* no forcing: the energy must not rise */
            const double rise = sc == SC_BOX ? (w.stats.kinetic_energy - ke_prev) / escale
                                             : (e - e0) / escale;
            if (rise > r.e_rise) r.e_rise = rise;
        }
        ke_prev = w.stats.kinetic_energy;
        if (w.time > duration - 0.5 + 1e-9 && w.stats.v_max > r.v_late) r.v_late = w.stats.v_max;
        {
            /* the sloshing tank's walls are where the callback put them */
            const double off = sc == SC_SLOSH ? sc_slosh_amp * sin(2 * M_PI * sc_slosh_freq * w.time) : 0;
            double lo1[3], hi1[3];
            size_t out;
            for (k = 0; k < 3; ++k) { lo1[k] = lo[k] + (k == 0 ? off : 0); hi1[k] = hi[k] + (k == 0 ? off : 0); }
            out = sc_escaped(&w, sc, lo1, hi1, R, (double)w.dx);
            if (out > r.escaped) r.escaped = out;
            {
                const size_t shallow = sc_escaped(&w, sc, lo1, hi1, R, 0.5 * (double)w.dx) - out;
                if (shallow > r.in_layer) r.in_layer = shallow;
            }
            if (out) r.silent_escape = 1;
        }
        r.retries += w.stats.retries;
    }
    r.t_end = t_prev;
    r.steps = (unsigned long long)w.steps;
    r.mass_err = fabs(sph_world_mass(&w) - m0) / m0;
    if (sc == SC_BOX && escale > 0) r.ke_ratio = w.stats.kinetic_energy / escale;
    TH_NOTE("%-11s %-11s %dD %-5s: t = %.2f s, %6llu steps, %3d retries, late max speed %.3g "
            "sqrt(gH) , energy rise %.2g, escaped %zu (%zu in the first layer), KE/KE0 %.3f%s",
            so->name, sc_bp_name(bp), dim, sc_names[sc], r.t_end, r.steps, r.retries,
            r.v_late / r.v_ref, r.e_rise, r.escaped, r.in_layer, r.ke_ratio,
            r.status ? " (reported failure)" : "");
    sph_world_free(&w);
    return r;
}

/* The defaults (each solver with its default wall scheme: def.boundary_pressure = SPH_BP_AUTO,
   or the PCISPH presets): the run gets through, nothing crosses a wall, the mass is exact and,
   without forcing, the energy does not rise. */
static void sc_defaults(sc_scene sc, int dim, double dx, double duration) {
    int si;
    for (si = 0; si < (int)(sizeof sc_solvers / sizeof sc_solvers[0]); ++si) {
        const sc_solver* so = &sc_solvers[si];
        const sc_result r = sc_run(sc, so, -1, dim, dx, duration);
#ifdef SPH_FLOAT
        /* in float, enhanced PCISPH's dam break fails (its frame at t = 0.95 s ran into
           def.max_substeps, reported). Held to what every run must do: report the failure
           (sc_run), keep the mass, and let nothing through a wall unreported. */
        if (so->pcisph == 1 && sc == SC_DAM) {
            CHECK(!r.silent_escape);
            CHECK_LE(r.mass_err, 1e-12);
            continue;
        }
#endif
        /* the closed box (no forcing): the kinetic energy never rises between frames by more
           than 1e-3 of its start, for every solver, enhanced PCISPH included (its correction runs
           with the density constraint's own wall term in an enclosed fluid, see
           sph__step_pcisph; before, it failed at t = 0.05 s in 3D and rose 1.7 % in 2D) */
        CHECK_MSG(r.status == SPH_OK, "%s %dD %s: failed at t = %.2f s", so->name, dim,
                  sc_names[sc], r.t_end);
        CHECK_EQ_INT(r.escaped, 0);
        CHECK_LE(r.mass_err, 1e-12);
        if (sc == SC_BOX) CHECK_LE(r.e_rise, 1e-3);
        else if (sc == SC_FILM && so->pcisph == 1) continue; /* creeps up: see test_film_2d */
        else if (sc != SC_SLOSH && sc != SC_DRUM) CHECK_LE(r.e_rise, 5e-3);
    }
}

/* What every run of sc_schemes must do. REPORTED (make validate's matrix): whatever a run
   reaches, a failure is reported with the world as before the call (checked in sc_run), no
   particle goes through a wall in a frame that returned SPH_OK, and the mass is exact; the
   outcomes are printed (the README's table of schemes comes from them). HOLDS (the closed box,
   make test): besides, the run gets through, no particle passes a wall and, without forcing, the
   kinetic energy never rises between frames by more than 1e-3 of its start. */
typedef enum sc_expect { SC_REPORTED, SC_HOLDS } sc_expect;

/* Mirrored wall pressure is refused with a reason, for every solver (not conservative: every
   solver's tank at rest gained energy with it, see SPH_BP_MIRROR in sph.h). */
static void sc_mirror_refused(const sc_solver* so, int dim) {
    sph_world_def def = sph_world_def_default(dim);
    sph_world w;
    if (so->pcisph >= 0) sph_world_def_pcisph(&def, so->pcisph);
    def.solver = so->solver;
    def.boundary_pressure = SPH_BP_MIRROR;
    CHECK_EQ_INT(sph_world_init(&w, &def), SPH_ERR_ARG);
    CHECK_MSG(strstr(w.error, "SPH_BP_MIRROR") != NULL, "%s: '%s'", so->name, w.error);
    sph_world_free(&w);
}

/* Every solver with every wall scheme, the ones not recommended included. */
static void sc_schemes(sc_scene sc, int dim, double dx, double duration, sc_expect expect) {
    int si, bp;
    for (si = 0; si < (int)(sizeof sc_solvers / sizeof sc_solvers[0]); ++si)
        for (bp = 0; bp < 3; ++bp) {
            const sc_solver* so = &sc_solvers[si];
            sc_result r;
            if (bp == SPH_BP_MIRROR) {
                sc_mirror_refused(so, dim);
                continue;
            }
            /* PBF's walls carry no multiplier (zero wall pressure) whatever the scheme */
            if (so->solver == SPH_SOLVER_PBF && bp != SPH_BP_ZERO) continue;
            r = sc_run(sc, so, bp, dim, dx, duration);
            CHECK_MSG(!r.silent_escape, "%s %s %dD %s: a particle crossed a wall unreported",
                      so->name, sc_bp_names[bp], dim, sc_names[sc]);
            CHECK_LE(r.mass_err, 1e-12);
            if (expect != SC_HOLDS) continue;
            CHECK_MSG(r.status == SPH_OK, "%s %s %dD %s: failed at t = %.2f s", so->name,
                      sc_bp_names[bp], dim, sc_names[sc], r.t_end);
            CHECK_MSG(r.e_rise <= 1e-3, "%s %s %dD %s: kinetic energy rose by %.3g of its start",
                      so->name, sc_bp_names[bp], dim, sc_names[sc], r.e_rise);
            CHECK_EQ_INT(r.escaped, 0);
        }
}

/* A film one spacing thick on the floor (2D: 1 m long, dx 0.02, 2 s; 3D: 0.4 m square, dx 0.04,
   1 s), every solver: the run gets through, nothing leaves, and the energy is never above its
   start by more than 0.5 % of rho g H^2 W with H = dx. WCSPH's delta-SPH diffused the hydrostatic
   density gradient the wall's extrapolated density carries into the film (sph__delta_hydro): its
   density climbed, lifting it, and the energy rose by 0.38 of that scale within 1 s in 2D (1.35
   by 8 s), every frame SPH_OK; now 0 in 2D and 0.0015 in 3D. Not asserted, printed: enhanced
   PCISPH's film creeps up at a steady 0.011 of the scale per second (2D, its pressure 106 ->
   110 Pa over 4 s while its density stays put), 0.0057 by 2 s. The solvers with zero wall
   pressure and summation density (IISPH, DFSPH, PBF, original PCISPH) lose energy but do not
   rest: a film's summation density is short of rho0, its pressure clamped at zero, and its
   particles jostle in the hollows of the wall at 0.45-0.75 sqrt(g dx). */
static void test_film_2d(void) { sc_defaults(SC_FILM, 2, 0.02, 2.0); }
static void test_film_3d(void) { sc_defaults(SC_FILM, 3, 0.04, 1.0); }

/* A fluid filling a closed box, without gravity, stirred by a vortex (nu = 0.01 m^2/s): every
   solver with every wall scheme holds (PCISPH, IISPH and DFSPH solve it with zero wall
   pressure, see sph__enclosed). */
static void test_box_schemes_2d(void) { sc_schemes(SC_BOX, 2, 0.04, 0.5, SC_HOLDS); }
static void test_box_schemes_3d(void) { sc_schemes(SC_BOX, 3, 0.05, 0.3, SC_HOLDS); }

static void test_tank_2d(void) { sc_defaults(SC_TANK, 2, 0.04, 1.5); }
static void test_dam_2d(void) { sc_defaults(SC_DAM, 2, 0.04, 1.0); }
static void test_slosh_2d(void) { sc_defaults(SC_SLOSH, 2, 0.04, 1.0); }
static void test_box_2d(void) { sc_defaults(SC_BOX, 2, 0.04, 0.5); }
static void test_ring_2d(void) { sc_defaults(SC_RING, 2, 0.04, 1.0); }
/* Single-layer walls with Akinci volumes (the calibrated gamma of sph__akinci_gamma): with
   gamma = 1 the fluid beside the layer started 15-30 % compressed, and IISPH, DFSPH and the
   original PCISPH refused the first step (max_compression) */
static void test_ring1_2d(void) { sc_defaults(SC_RING1, 2, 0.04, 1.0); }
static void test_shell_2d(void) { sc_defaults(SC_SHELL, 2, 0.04, 1.0); }
static void test_shell_3d(void) { sc_defaults(SC_SHELL, 3, 0.04, 0.5); }
/* a column thrown at 10 m/s into single-layer walls: IISPH shot a particle through the corner
   at 37 m/s, unreported, before sph__wall_cross_guard (2D, dx 0.02) */
static void test_jet_2d(void) { sc_defaults(SC_JET, 2, 0.02, 0.5); }
static void test_jet_3d(void) { sc_defaults(SC_JET, 3, 0.04, 0.3); }
/* a turning drum of one host-sampled layer: IISPH, DFSPH and PBF put a particle through a
   diagonal gap of its staircase within 0.08 s in 2D (dx 0.02) and within 0.2-0.5 s in 3D (dx
   0.04), unreported: the contact took the walls where the step began, not where it ends, pushed
   along the wall's normal at the particle's end, which has no side in the line of a single
   layer, and in 3D its ramp to 0.6 dx left the hollows and gaps of the layer open
   (sph__wall_contact) */
static void test_drum_2d(void) { sc_defaults(SC_DRUM, 2, 0.02, 0.5); }
static void test_drum_3d(void) { sc_defaults(SC_DRUM, 3, 0.04, 1.0); }
/* a disc or ball of water dropped onto the floor: while the automatic sound speed came from the
   fluid's own height only (24.3 m/s for the disc), the jets of the impact (12.2-14.0 m/s in 2D at
   dx 0.01, 3.7-4.3 times the impact speed) passed the incompressible solvers' speed bound, then
   half of it, and every solver failed at 0.34 s; here WCSPH failed after 0.35 s in 2D, WCSPH and
   enhanced PCISPH after 0.45 and 0.35 s in 3D. The automatic sound speed now counts the fall to the
   floor (sph_phase.sound_speed) and the bound is c0 (def.max_speed) */
static void test_drop_2d(void) { sc_defaults(SC_DROP, 2, 0.02, 1.0); }
static void test_drop_3d(void) { sc_defaults(SC_DROP, 3, 0.015, 0.5); }
static void test_tank_3d(void) { sc_defaults(SC_TANK, 3, 0.04, 0.5); }
static void test_box_3d(void) { sc_defaults(SC_BOX, 3, 0.05, 0.3); }
static void test_dam_3d(void) { sc_defaults(SC_DAM, 3, 0.025, 0.3); }
static void test_slosh_3d(void) { sc_defaults(SC_SLOSH, 3, 0.04, 0.3); }

static void test_tank_2d_long(void) { sc_defaults(SC_TANK, 2, 0.02, 3.0); }
static void test_dam_2d_long(void) { sc_defaults(SC_DAM, 2, 0.02, 2.0); }
/* A 0.4 x 0.6 m column in a closed 1.6 x 0.8 m tank, nu 1e-6, sph_advance in frames of 0.02 s
   for 3 s: in 2D at dx 0.01 with walls of Akinci volumes, in 3D 0.2 m deep at dx 0.04 with the
   default walls. The front runs along the floor as a sheet one or two particles thick, which the
   wall contact keeps lifting off the floor, and splashes. In 2D, WCSPH failed at t = 2.22 s and
   enhanced PCISPH at 1.18 s (reported) before two changes: the contact's move joins a carried
   density (sph__contact_density; before, the sheet's particles paired up within 0.001 dx with
   their continuity density at rest density), and WCSPH clamps negative pressure (sph__clamps;
   before, a splash's carried density fell towards zero and its Tait tension, down to -B, pulled
   clusters of ten particles onto one point). Every solver must reach 3 s.
   (pcisph/contact_keeps_carried_density and wcsph/free_expansion_ballistic check the two
   mechanisms in make test.) Held to what every run must do: a failure reported with the world
   as before the call (sc_run checks that for its scenes; here the same), the mass exact, no
   particle more than dx outside the tank at a frame end, no rise of the energy. */
static void sheet_run(int dim) {
    int si;
    for (si = 0; si < (int)(sizeof sc_solvers / sizeof sc_solvers[0]); ++si) {
        const sc_solver* so = &sc_solvers[si];
        sph_world_def def = sph_world_def_default(dim);
        sph_world w;
        sph_phase water;
        const sph_real lo[3] = {0, 0, 0}, hi[3] = {(sph_real)1.6, (sph_real)0.8, (sph_real)0.2};
        const sph_real fhi[3] = {(sph_real)0.4, (sph_real)0.6, (sph_real)0.2};
        const double lo_d[3] = {0, 0, 0}, hi_d[3] = {1.6, 0.8, 0.2};
        double m0, e0, escale = 1000 * 9.81 * 0.6 * 0.6 * 1.6 * (dim == 3 ? 0.2 : 1), rise = 0;
        double t_fail = -1;
        size_t out = 0;
        int f;
        memset(&water, 0, sizeof water);
        water.rest_density = 1000;
        water.viscosity = (sph_real)1e-6;
        if (so->pcisph >= 0) sph_world_def_pcisph(&def, so->pcisph);
        def.solver = so->solver;
        def.spacing = (sph_real)(dim == 2 ? 0.01 : 0.04);
        if (dim == 2) def.boundary_volume = SPH_BVOL_AKINCI;
        CHECK(sph_world_init(&w, &def) == SPH_OK && sph_world_add_phase(&w, &water) == 0 &&
              sph_add_wall_box(&w, lo, hi, 0, 0) == SPH_OK && sph_fill_box(&w, 0, lo, fhi) == SPH_OK &&
              sph_set_hydrostatic(&w) == SPH_OK);
        m0 = sph_world_mass(&w);
        e0 = sc_potential(&w); /* at rest */
        for (f = 1; f <= 150; ++f) {
            const double ta = w.time;
            size_t o;
            if (sph_advance(&w, (sph_real)0.02) != SPH_OK) {
                CHECK_MSG(w.error[0] != 0, "%s: a failure without a message", so->name);
                CHECK_NEAR(w.time, ta, 0);
                t_fail = w.time;
                TH_NOTE("%-11s %dD sheet: %s", so->name, dim, w.error);
                break;
            }
            o = sc_escaped(&w, SC_DAM, lo_d, hi_d, 0, (double)w.dx);
            if (o > out) out = o;
            if ((w.stats.kinetic_energy + sc_potential(&w) - e0) / escale > rise)
                rise = (w.stats.kinetic_energy + sc_potential(&w) - e0) / escale;
        }
        CHECK_EQ_INT(out, 0);
        CHECK_MSG(t_fail < 0, "%s %dD: failed at t = %.2f s", so->name, dim, t_fail);
        CHECK_LE(rise, 5e-3); /* no forcing: the energy does not rise (scale rho g H^2 W) */
        CHECK_LE(fabs(sph_world_mass(&w) - m0) / m0, 1e-12);
        if (t_fail >= 0)
            TH_NOTE("%-11s %dD sheet: failed (reported) at t = %.2f s after %llu steps, energy rise "
                    "%.2g", so->name, dim, t_fail, (unsigned long long)w.steps, rise);
        else
            TH_NOTE("%-11s %dD sheet: t = 3 s, %llu steps, energy rise %.2g", so->name, dim,
                    (unsigned long long)w.steps, rise);
        sph_world_free(&w);
    }
}
static void test_sheet_2d_long(void) { sheet_run(2); }
static void test_sheet_3d_long(void) { sheet_run(3); }
static void test_slosh_2d_long(void) { sc_defaults(SC_SLOSH, 2, 0.02, 3.0); }
static void test_box_2d_long(void) { sc_defaults(SC_BOX, 2, 0.02, 1.0); }
static void test_tank_3d_long(void) { sc_defaults(SC_TANK, 3, 0.025, 1.0); }
static void test_dam_3d_long(void) { sc_defaults(SC_DAM, 3, 0.025, 1.0); }
/* A 3D tank at rest comes to rest (make validate): the incompressible solvers with their default
   walls (zero wall pressure; enhanced PCISPH extrapolated), 10 s, the largest speed over the
   last half second. Zero wall pressure settles its floor rows up to 0.35 dx closer to the wall
   than the lattice sph_set_hydrostatic starts from; while the wall contact fought that (it moved
   about 200 of the 800 particles each step, see sph__wall_contact), the tank kept moving at
   0.19-0.25 sqrt(g H) for good. Left to the pressure (the contact shrinks for particles with a
   full neighbourhood) it settles. Measured after 4 s with Wendland C2: 0.043 (IISPH), 0.041
   (DFSPH), 0.054 (enhanced PCISPH) sqrt(g H), and IISPH still 0.042 after 10 s, kept up by a few
   surface particles at the side walls (p = 0: the wall, which pushes with p_i alone, does not
   push them, the fluid behind them does). With the automatic 3D kernel (the cubic at h = dx)
   after 10 s: IISPH 0.0084, DFSPH 0.028, enhanced PCISPH (still Wendland C2) 0.0125. Asserted:
   IISPH below the 0.01, the others below 0.04, no particle through a wall, the energy
   never more than 0.5 % of rho g H^2 above its start (measured: 0 for IISPH and DFSPH, 1.4e-4
   for enhanced PCISPH). */
static void test_tank_3d_settles(void) {
    int si;
    for (si = 0; si < (int)(sizeof sc_solvers / sizeof sc_solvers[0]); ++si) {
        const sc_solver* so = &sc_solvers[si];
        sc_result r;
        if (so->solver != SPH_SOLVER_IISPH && so->solver != SPH_SOLVER_DFSPH && so->pcisph != 1)
            continue;
        r = sc_run(SC_TANK, so, -1, 3, 0.04, 10.0);
        CHECK_MSG(r.status == SPH_OK, "%s: failed at t = %.2f s", so->name, r.t_end);
        CHECK_EQ_INT(r.escaped, 0);
        CHECK_LE(r.e_rise, 0.005); /* no forcing: the energy stays at its start (the scale as above) */
        CHECK_LE(r.v_late / r.v_ref, so->solver == SPH_SOLVER_IISPH ? 0.01 : 0.04);
    }
}

/* A 2D tank at rest through sph_advance in 0.05 s frames (IISPH and DFSPH, their defaults),
   3 s: the largest speed over the last half second. A step that only lands on the end of a
   frame used to correct part of the standing compression and leave the rest to the next frame's
   first step, which then stopped at max_iterations and was retried from p = 0: a sag of the
   whole column about once a frame. Measured at dx 0.04 before: 0.049 (IISPH) and 0.059 (DFSPH)
   sqrt(g H); after: 0.022 and 0.028 (at dx 0.02: 0.17 and 0.13 before, 0.028 and 0.023
   after, kinetic energy 20-50 times lower). The target is 0.01. */
static void test_tank_2d_rests(void) {
    int si;
    for (si = 0; si < (int)(sizeof sc_solvers / sizeof sc_solvers[0]); ++si) {
        const sc_solver* so = &sc_solvers[si];
        sc_result r;
        if (so->solver != SPH_SOLVER_IISPH && so->solver != SPH_SOLVER_DFSPH) continue;
        r = sc_run(SC_TANK, so, -1, 2, 0.04, 3.0);
        CHECK_MSG(r.status == SPH_OK, "%s: failed at t = %.2f s", so->name, r.t_end);
        CHECK_EQ_INT(r.escaped, 0);
        CHECK_LE(r.v_late / r.v_ref, 0.035);
    }
}

/* The same 2D tank for 10 s (make validate): the incompressible solvers come to rest, below
   the 1 % of sqrt(g H) over the last half second. Measured: IISPH 0.0013, DFSPH 0.0039,
   original PCISPH 0.0090 (before the frame-landing change: IISPH 0.054, DFSPH 0.051, still
   sloshing). Not asserted, printed: enhanced PCISPH 0.0073 (240 retries), WCSPH 0.019 and PBF
   0.011 (a jitter of 1-2 %; WCSPH: acoustic waves of its equation of state). */
static void test_tank_2d_comes_to_rest(void) {
    int si;
    for (si = 0; si < (int)(sizeof sc_solvers / sizeof sc_solvers[0]); ++si) {
        const sc_solver* so = &sc_solvers[si];
        const int held = so->solver == SPH_SOLVER_IISPH || so->solver == SPH_SOLVER_DFSPH ||
                         (so->solver == SPH_SOLVER_PCISPH && so->pcisph == 0);
        const sc_result r = sc_run(SC_TANK, so, -1, 2, 0.04, 10.0);
        CHECK_MSG(r.status == SPH_OK, "%s: failed at t = %.2f s", so->name, r.t_end);
        CHECK_EQ_INT(r.escaped, 0);
        if (held) CHECK_LE(r.v_late / r.v_ref, 0.01);
    }
}

/* The pressure of a 3D tank at rest through sph_advance (scene_hydrostatic: 0.4 m square, water
   0.32 m deep, 16 particles over the depth, 3 s in 0.05 s frames), averaged per particle over
   the last 0.5 s and compared with rho g (H - y) a support away from the walls, the floor and
   the surface (tests/tank_profile.h); every frame must succeed and leave no fluid particle past
   the first wall layer. bp -1: the solver's default walls. */
static tank_profile sc_tank_pressure(const sc_solver* so, int bp) {
    const double W = 0.4, H = 0.32, T = 3.0;
    sph_world_def def = sph_world_def_default(3);
    sph_world w;
    tank_profile tp;
    double* ps;
    int *cn, f;
    const int frames = (int)(T / 0.05 + 0.5);
    size_t i, out = 0;
    memset(&tp, 0, sizeof tp);
    tp.layer_err = tp.particle_err = 1;
    if (so->pcisph >= 0) sph_world_def_pcisph(&def, so->pcisph);
    def.solver = so->solver;
    if (bp >= 0) def.boundary_pressure = (sph_boundary_pressure)bp;
    if (scene_hydrostatic(&w, def, W, H, 16) != SPH_OK) {
        CHECK_MSG(0, "%s: %s", so->name, scene_error);
        return tp;
    }
    ps = (double*)calloc(w.n, sizeof(double));
    cn = (int*)calloc(w.n, sizeof(int));
    for (f = 1; f <= frames; ++f) {
        const sph_status s = sph_advance(&w, (sph_real)0.05);
        CHECK_MSG(s == SPH_OK, "%s %s: %s", so->name, sc_bp_name(bp), w.error);
        if (s != SPH_OK) break;
        if (w.time > T - 0.5 + 1e-9)
            for (i = 0; i < w.n; ++i) { ps[w.id[i]] += (double)w.p[i]; cn[w.id[i]]++; }
        /* nothing past the first wall layer (half a spacing outside the tank's inner faces) */
        for (i = 0; i < w.n * 3; ++i)
            out += (double)w.x[i] < -0.5 * (double)w.dx ||
                   ((i % 3) != 1 && (double)w.x[i] > W + 0.5 * (double)w.dx);
    }
    CHECK_EQ_INT(out, 0);
    if (f > frames) tp = tank_profile_error(&w, ps, cn, W, H, 1000, 9.81);
    TH_NOTE("%-11s %-11s 3D tank at rest, 16 particles deep: pressure error layers %.4f, "
            "particles %.4f of rho g H", so->name, sc_bp_name(bp), tp.layer_err, tp.particle_err);
    free(ps);
    free(cn);
    sph_world_free(&w);
    return tp;
}

/* Issue: the pressure of a 3D tank at rest within 1 % of rho g H away from walls (make
   validate). Asserted where it holds: WCSPH with its defaults (extrapolated walls; measured
   0.0034) and DFSPH with extrapolated walls (0.0036; Wendland C2, as the automatic kernel gives
   every scheme but zero wall pressure). Printed: the others, as measured on 2 cores at commit
   time (README, "Pressure in a 3D tank at rest"): the original PCISPH with extrapolated walls
   0.0096, enhanced PCISPH (its default, extrapolated) 0.0101, IISPH with extrapolated walls
   0.0114 (its solve stops at the mean compression 0.1 % with the pressure 0.17 rho g dx short
   throughout: at a tolerance of 1e-4 it is 0.06-0.15 short), and with the defaults' zero wall
   pressure IISPH 0.0156, DFSPH 0.0159, the original PCISPH 0.0207: the wall then pushes with
   the particle's own pressure alone, the floor row carries about 1.8 times the hydrostatic
   pressure and settles into the hollows of the wall lattice, 0.2 dx above the floor instead of
   0.5, and the interior pressure sits 0.2-0.3 rho g dx below rho g (H - y). */
static void test_tank_3d_pressure(void) {
    int si;
    for (si = 0; si < (int)(sizeof sc_solvers / sizeof sc_solvers[0]); ++si) {
        const sc_solver* so = &sc_solvers[si];
        tank_profile tp;
        if (so->solver == SPH_SOLVER_PBF) continue; /* compressible by design (its 1 % target) */
        tp = sc_tank_pressure(so, -1);
        if (so->solver == SPH_SOLVER_WCSPH) CHECK_LT(tp.layer_err, 0.01);
        if (so->solver == SPH_SOLVER_WCSPH || so->pcisph == 1) continue; /* extrapolated already */
        tp = sc_tank_pressure(so, SPH_BP_EXTRAPOLATE);
        if (so->solver == SPH_SOLVER_DFSPH) CHECK_LT(tp.layer_err, 0.01);
    }
}

static void test_schemes_2d_long(void) {
    sc_schemes(SC_TANK, 2, 0.04, 1.5, SC_REPORTED);
    sc_schemes(SC_DAM, 2, 0.04, 1.0, SC_REPORTED);
    sc_schemes(SC_SLOSH, 2, 0.04, 1.0, SC_REPORTED);
    sc_schemes(SC_BOX, 2, 0.04, 0.5, SC_HOLDS);
    sc_schemes(SC_RING, 2, 0.04, 1.0, SC_REPORTED);
}
static void test_schemes_3d_long(void) {
    sc_schemes(SC_TANK, 3, 0.04, 0.5, SC_REPORTED);
    sc_schemes(SC_BOX, 3, 0.05, 0.3, SC_HOLDS);
}

const th_test tests_scenes[] = {{"scenes/tank_2d", test_tank_2d}, {"scenes/tank_2d_rests", test_tank_2d_rests},   {"scenes/dam_2d", test_dam_2d},
                                {"scenes/slosh_2d", test_slosh_2d}, {"scenes/box_2d", test_box_2d},
                                {"scenes/ring_2d", test_ring_2d},   {"scenes/tank_3d", test_tank_3d},
                                {"scenes/box_3d", test_box_3d},     {"scenes/dam_3d", test_dam_3d},
                                {"scenes/slosh_3d", test_slosh_3d},
                                {"scenes/ring1_2d", test_ring1_2d},
                                {"scenes/shell_2d", test_shell_2d},
                                {"scenes/shell_3d", test_shell_3d},
                                {"scenes/jet_2d", test_jet_2d},
                                {"scenes/jet_3d", test_jet_3d},
                                {"scenes/drum_2d", test_drum_2d},
                                {"scenes/drum_3d", test_drum_3d},
                                {"scenes/drop_2d", test_drop_2d},
                                {"scenes/drop_3d", test_drop_3d},
                                {"scenes/film_2d", test_film_2d},
                                {"scenes/film_3d", test_film_3d},
                                {"scenes/box_schemes_2d", test_box_schemes_2d},
                                {"scenes/box_schemes_3d", test_box_schemes_3d}, {0, 0}};
const th_test tests_scenes_long[] = {{"long/scenes/tank_2d", test_tank_2d_long},
                                     {"long/scenes/dam_2d", test_dam_2d_long},
                                     {"long/scenes/sheet_2d", test_sheet_2d_long},
                                     {"long/scenes/sheet_3d", test_sheet_3d_long},
                                     {"long/scenes/slosh_2d", test_slosh_2d_long},
                                     {"long/scenes/box_2d", test_box_2d_long},
                                     {"long/scenes/tank_3d", test_tank_3d_long},
                                     {"long/scenes/dam_3d", test_dam_3d_long},
                                     {"long/scenes/tank_3d_settles", test_tank_3d_settles},
                                     {"long/scenes/tank_3d_pressure", test_tank_3d_pressure},
                                     {"long/scenes/tank_2d_comes_to_rest", test_tank_2d_comes_to_rest},
                                     {"long/scenes/schemes_2d", test_schemes_2d_long},
                                     {"long/scenes/schemes_3d", test_schemes_3d_long},
                                     {0, 0}};
