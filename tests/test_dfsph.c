/* tests/test_dfsph.c - divergence-free SPH (Bender & Koschier 2015, 2017): a tank at rest in 2D
   and 3D with every boundary pressure scheme, the Martin & Moyce dam break (also against IISPH
   at the same step), the divergence-free solve checked from outside, an enclosed vortex that
   must not gain energy, a paddle moved by the boundary callback, and thread determinism.

   Time steps are fixed, from the velocity CFL with a force limit: dt = min(0.4 dx / U,
   0.1 sqrt(h / |g|)) with U the scene's largest expected speed, so the tests do not depend on
   the step control. The force factor is 0.1, not sph_stable_dt's cfl_force 0.25: at 0.25 (14 ms
   in the 2D tank) neither IISPH nor DFSPH converges within 100 iterations there (measured:
   IISPH 98 iterations per step, blowing up with mirrored walls). */
#include "harness.h"
#include "../sph.h"
#include "../examples/scenes.h"
#include "tank_profile.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

/* The fixed step: velocity CFL 0.4 dx / U with the force limit 0.1 sqrt(h / g) (g > 0). */
static double df_dt(const sph_world* w, double U, double g) {
    double dt = 1e300;
    if (U > 0) dt = 0.4 * (double)w->dx / U;
    if (g > 0) dt = fmin(dt, 0.1 * sqrt((double)w->h / g));
    return dt;
}

/* ---- a tank at rest ------------------------------------------------------------------------ */

typedef struct df_tank {
    double layer_err;    /* mean |layer-averaged p - rho g (H - y)| / (rho g H), interior      */
    double particle_err; /* mean |p - rho g (H - y)| / (rho g H) over interior particles         */
    double v_max;        /* largest fluid speed over the last half of the run [m/s]             */
    double v_rms;        /* largest RMS fluid speed of a step over the last half [m/s]          */
    double comp_max;     /* largest mean compression of a step                                  */
    double iterations;   /* mean iterations per step (both solves)                              */
    double divergence;   /* mean divergence-solve iterations per step                           */
    double step_ms;
    size_t outside;
    int steps, failed, unconverged; /* steps that returned SPH_ERR_NOT_CONVERGED (and went on) */
    double unconverged_until;       /* the time of the last of them [s]                        */
} df_tank;

/* scene_hydrostatic's tank (width W, depth H, res particles over H) in dim dimensions with the
   boundary scheme bp, run for T seconds; pressures averaged per particle over the last 0.3 s and
   compared with rho g (H - y) a support away from walls and surface. */
static df_tank run_df_tank(sph_solver solver, int dim, sph_boundary_pressure bp, double W,
                           double H, int res, double T) {
    sph_world_def def = sph_world_def_default(dim);
    sph_world w;
    df_tank r;
    tank_profile tp;
    double *ps, dt, its = 0, itv = 0;
    int* cn;
    size_t i;
    memset(&r, 0, sizeof(r));
    def.solver = solver;
    def.boundary_pressure = bp;
    def.domain_lo[0] = def.domain_lo[1] = def.domain_lo[2] = (sph_real)(-0.5 * H / res);
    def.domain_hi[0] = def.domain_hi[2] = (sph_real)(W + 0.5 * H / res);
    def.domain_hi[1] = 10;
    if (scene_hydrostatic(&w, def, W, H, res) != SPH_OK) {
        CHECK_MSG(0, "tank: %s", scene_error);
        r.failed = 1;
        return r;
    }
    dt = df_dt(&w, 0, 9.81);
    ps = (double*)calloc(w.n, sizeof(double));
    cn = (int*)calloc(w.n, sizeof(int));
    while (w.time < T - 1e-9) {
        sph_status s = th_step(&w, (sph_real)dt);
        if (s == SPH_ERR_NOT_CONVERGED) { /* the step is complete: count it and go on */
            ++r.unconverged;
            r.unconverged_until = w.time;
            s = SPH_OK;
        }
        if (s != SPH_OK) {
            CHECK_MSG(0, "tank dim %d scheme %d step %d: %s", dim, (int)bp, r.steps, w.error);
            r.failed = 1;
            break;
        }
        ++r.steps;
        its += w.stats.iterations;
        itv += w.stats.iterations_divergence;
        if (w.stats.compression_avg > r.comp_max) r.comp_max = w.stats.compression_avg;
        if (w.stats.n_outside > r.outside) r.outside = w.stats.n_outside;
        if (w.time > T / 2) {
            const double rms = sqrt(2 * w.stats.kinetic_energy / sph_world_mass(&w));
            if (w.stats.v_max > r.v_max) r.v_max = w.stats.v_max;
            if (rms > r.v_rms) r.v_rms = rms;
        }
        if (w.time > T - 0.3)
            for (i = 0; i < w.n; ++i) { ps[w.id[i]] += (double)w.p[i]; cn[w.id[i]]++; }
    }
    tp = tank_profile_error(&w, ps, cn, W, H, 1000, 9.81);
    r.layer_err = tp.layer_err;
    r.particle_err = tp.particle_err;
    r.iterations = r.steps ? its / r.steps : 0;
    r.divergence = r.steps ? itv / r.steps : 0;
    r.step_ms = r.steps ? 1e3 * w.step_time_total / r.steps : 0;
    free(ps);
    free(cn);
    sph_world_free(&w);
    return r;
}

/* The checks of a settled tank: layer-averaged pressure within 2 % of rho g H of rho g (H - y), single
   particles within 5 % (IISPH's bound: each particle's summation density is corrected by its own
   pressure), an RMS speed below 2 % of sqrt(g H) over the second half, the measured mean
   compression at most 0.15 % (the solver's 0.1 % on the linear prediction; the summation density
   after the move runs a little above it), no particle out, and steps above tolerance only during
   the first 0.3 s (the hydrostatic start is warm started at half its pressure, and Jacobi's slowest,
   smooth modes take more than max_iterations to rebuild it). */
static void df_check_tank(const char* what, const df_tank* r, double H, double layer_tol,
                          double v_tol) {
    TH_NOTE("%s: pressure error layers %.4f, particles %.4f of rho g H; v_rms %.2e, v_max %.2e m/s; "
            "max compression %.5f; %.2f iterations/step (%.2f divergence), %.2f ms/step; %d steps "
            "not converged, the last at t = %.3f s; outside %zu", what, r->layer_err,
            r->particle_err, r->v_rms, r->v_max, r->comp_max, r->iterations, r->divergence,
            r->step_ms, r->unconverged, r->unconverged_until, r->outside);
    CHECK(!r->failed);
    CHECK_LT(r->layer_err, layer_tol);
    CHECK_LT(r->particle_err, 2.5 * layer_tol);
    CHECK_LT(r->v_rms, v_tol * sqrt(9.81 * H));
    CHECK_LE(r->comp_max, 0.0015);
    CHECK_EQ_INT(r->outside, 0);
    CHECK_LT(r->unconverged_until, 0.3);
}

/* 2D tank 1 m wide, 0.5 m deep (20 particles), for 3 s at 5.8 ms, each boundary scheme; IISPH on
   the same tank and step for reference (reported, not checked). Mirrored walls (p_b = p_i) are
   refused by sph_world_init: here they threw the wall-adjacent particles at the free surface off
   the side walls (v_max about 2 m/s, with IISPH too: 2.25 m/s on this tank) and needed looser
   bounds (layers 4 %, RMS speed 15 % of sqrt(g H)); see SPH_BP_MIRROR. */
static void test_df_tank_2d(void) {
    static const char* names[3] = {"DFSPH 2D tank, extrapolation", "DFSPH 2D tank, mirroring",
                                   "DFSPH 2D tank, zero pressure"};
    df_tank r;
    int bp;
    for (bp = 0; bp < 3; ++bp) {
        if (bp == SPH_BP_MIRROR) continue;
        r = run_df_tank(SPH_SOLVER_DFSPH, 2, (sph_boundary_pressure)bp, 1.0, 0.5, 20, 3.0);
        df_check_tank(names[bp], &r, 0.5, 0.02, 0.02);
    }
    r = run_df_tank(SPH_SOLVER_IISPH, 2, SPH_BP_EXTRAPOLATE, 1.0, 0.5, 20, 3.0);
    TH_NOTE("IISPH, same tank and step, extrapolation: pressure error layers %.4f, particles %.4f; "
            "v_rms %.2e, v_max %.2e m/s; %.2f iterations/step, %.2f ms/step", r.layer_err,
            r.particle_err, r.v_rms, r.v_max, r.iterations, r.step_ms);
}

/* 3D tank 0.2 m wide and deep (10 particles) for 1.5 s at 5.1 ms, extrapolated walls: the same
   checks. With def.omega = 0.5 both DFSPH and IISPH blew up on this tank within 0.05 s with
   Wendland C2 (measured: the relaxed Jacobi diverges; in 3D a particle has about 4 times the
   neighbours of 2D), so the automatic weight is 0.3 for that kernel (extrapolated walls keep it);
   zero-pressure walls get the cubic at h = dx and 0.5. Zero-pressure walls are reported: they
   hold the fluid, but their interior layers are off hydrostatic. */
static void test_df_tank_3d(void) {
    df_tank r = run_df_tank(SPH_SOLVER_DFSPH, 3, SPH_BP_EXTRAPOLATE, 0.2, 0.2, 10, 1.5);
    df_check_tank("DFSPH 3D tank, extrapolation", &r, 0.2, 0.02, 0.02);
    r = run_df_tank(SPH_SOLVER_DFSPH, 3, SPH_BP_ZERO, 0.2, 0.2, 10, 1.5);
    TH_NOTE("DFSPH 3D tank, zero pressure: pressure error layers %.4f, particles %.4f; v_rms %.2e, "
            "v_max %.2e m/s; max compression %.5f; %.2f iterations/step; outside %zu",
            r.layer_err, r.particle_err, r.v_rms, r.v_max, r.comp_max, r.iterations, r.outside);
    CHECK(!r.failed);
    CHECK_EQ_INT(r.outside, 0);
}

/* ---- dam break ----------------------------------------------------------------------------- */

typedef struct df_dam {
    double front_rms, comp_mean, comp_max, ke_max, pe_released, iterations, divergence, step_ms;
    size_t escaped; /* most fluid particles outside the tank at any step */
    int steps, failed;
} df_dam;

/* Martin & Moyce's dam break (a = 0.1 m, res particles per a) to T = 3.33 at the fixed step of
   the front speed 2 sqrt(2 g a) (Ritter's dam-break wave), with the solver of def. */
static df_dam run_df_dam(sph_world_def def, int res) {
    sph_world w;
    scene_dam d;
    df_dam r;
    double sq = 0, dt, pe0 = 0, m;
    int k;
    size_t i;
    memset(&r, 0, sizeof(r));
    memset(&d, 0, sizeof(d)); /* set by scene_dam_break; gcc -O2 without OpenMP cannot tell */
    if (scene_dam_break(&w, def, 0.1, res, &d) != SPH_OK) {
        CHECK_MSG(0, "scene: %s", scene_error);
        r.failed = 1;
        return r;
    }
    dt = df_dt(&w, 2 * sqrt(2 * 9.81 * d.a), 9.81);
    m = (double)w.mass;
    for (i = 0; i < w.n; ++i) pe0 += m * 9.81 * (double)w.x[2 * i + 1];
    for (k = 0; k < SCENE_MM_N && !r.failed; ++k) {
        const double t = scene_mm_time(scene_mm_T[k], d.a);
        double e;
        while (w.time < t - 1e-12) {
            const int last = dt >= t - w.time;
            const sph_status s = th_step(&w, (sph_real)(last ? t - w.time : dt));
            size_t out = 0;
            if (s != SPH_OK) {
                TH_NOTE("dam break step %d: %s", r.steps, w.error); /* the caller checks */
                r.failed = 1;
                break;
            }
            ++r.steps;
            r.iterations += w.stats.iterations;
            r.divergence += w.stats.iterations_divergence;
            r.comp_mean += w.stats.compression_avg;
            if (w.stats.compression_avg > r.comp_max) r.comp_max = w.stats.compression_avg;
            if (w.stats.kinetic_energy > r.ke_max) r.ke_max = w.stats.kinetic_energy;
            for (i = 0; i < w.n; ++i) {
                const double x = (double)w.x[2 * i], y = (double)w.x[2 * i + 1];
                if (x < 0 || x > d.length || y < 0 || y > d.height) ++out;
            }
            if (out > r.escaped) r.escaped = out;
            if (last) break;
        }
        e = (scene_dam_front(&w, &d) - scene_mm_Z[k]) / scene_mm_Z[k];
        sq += e * e;
    }
    {
        double pe = 0;
        for (i = 0; i < w.n; ++i) pe += m * 9.81 * (double)w.x[2 * i + 1];
        r.pe_released = pe0 - pe;
    }
    if (r.steps) {
        r.iterations /= r.steps;
        r.divergence /= r.steps;
        r.comp_mean /= r.steps;
        r.step_ms = 1e3 * w.step_time_total / r.steps;
    }
    r.front_rms = sqrt(sq / SCENE_MM_N);
    sph_world_free(&w);
    return r;
}

/* 20 particles per a: no particle outside the tank at any step, the mean compression per step at
   the 0.1 % tolerance on average (and 0.3 % at most: the measured compression of the summation
   density runs a little above the solver's linear prediction during the impact), the kinetic
   energy never above the potential energy the column has released by the end, and the surge
   front within 15 % RMS of Martin & Moyce (the tolerance of the other solvers' dam breaks). */
static void test_df_dam_break(void) {
    sph_world_def def = sph_world_def_default(2);
    def.boundary_pressure = SPH_BP_EXTRAPOLATE; /* the wall scheme this test was written for (the
                                               default before SPH_BP_AUTO) */
    df_dam r;
    def.solver = SPH_SOLVER_DFSPH;
    r = run_df_dam(def, 20);
    TH_NOTE("DFSPH dam break, 20 per a, %d steps: front RMS error %.3f; compression mean %.5f, "
            "max %.5f; kinetic energy max %.3f J of %.3f J released; %.2f iterations/step (%.2f "
            "divergence), %.2f ms/step; escaped %zu", r.steps, r.front_rms, r.comp_mean,
            r.comp_max, r.ke_max, r.pe_released, r.iterations, r.divergence, r.step_ms, r.escaped);
#ifdef SPH_FLOAT
    /* in float both DFSPH and IISPH blow up at this fixed step (step 42, the corner particle
       accelerating to kilometres per second; measured): reported, left to the step control */
    if (r.failed) TH_SKIP("float: blows up at this fixed step, as IISPH does");
#endif
    CHECK(!r.failed);
    CHECK_EQ_INT(r.escaped, 0);
    CHECK_LE(r.comp_mean, 0.001);
    CHECK_LE(r.comp_max, 0.003);
    CHECK_LT(r.ke_max, r.pe_released);
    CHECK_LT(r.front_rms, 0.15);
}

/* The same dam break, same fixed step, one thread: DFSPH against IISPH (iterations and time per
   step reported; the comparison the manual quotes). Both must finish. */
static void test_df_vs_iisph(void) {
    sph_world_def dd = sph_world_def_default(2), di = dd;
    dd.boundary_pressure = SPH_BP_EXTRAPOLATE; /* the wall scheme this test was written for (the
                                               default before SPH_BP_AUTO) */
    di = dd;
    df_dam a, b;
#ifdef _OPENMP
    const int threads = omp_get_max_threads();
    omp_set_num_threads(1);
#endif
    dd.solver = SPH_SOLVER_DFSPH;
    di.solver = SPH_SOLVER_IISPH;
    a = run_df_dam(dd, 20);
    b = run_df_dam(di, 20);
#ifdef _OPENMP
    omp_set_num_threads(threads);
#endif
    TH_NOTE("dam break 20 per a, same dt, 1 thread: DFSPH %.2f iterations/step (%.2f divergence), "
            "%.3f ms/step, compression mean %.5f, front RMS %.3f; IISPH %.2f iterations/step, "
            "%.3f ms/step, compression mean %.5f, front RMS %.3f", a.iterations, a.divergence,
            a.step_ms, a.comp_mean, a.front_rms, b.iterations, b.step_ms, b.comp_mean,
            b.front_rms);
#ifdef SPH_FLOAT
    if (a.failed && b.failed) TH_SKIP("float: both blow up at this fixed step");
#endif
    CHECK(!a.failed && !b.failed);
}

/* ---- the divergence-free solve from outside -------------------------------------------------- */

/* A periodic 0.4 m box of fluid at rest density with the compressive field u = U sin(2 pi x / L),
   no gravity and no viscosity; the constant-density solve is switched off (tolerance 0.99, no
   minimum), so after one step the velocities are exactly those of the divergence-free solve.
   D rho_i/Dt = sum_j m_j (v_i - v_j) . grad W_ij / S is recomputed here by brute force at the
   positions before the step (particles are followed by id): its mean compressive part times
   dt / rho0 is at most def.divergence_tolerance and equals stats.divergence_error; before the
   solve it was more than 5 times the tolerance. */
static double df_divergence(const sph_world* w, const sph_real* x0, const sph_real* vel,
                            const uint32_t* id, double S, double dt) {
    const double L = 0.4, m = (double)w->mass;
    double sum = 0;
    size_t i, j;
    for (i = 0; i < w->n; ++i) {
        const sph_real* xi = x0 + 2 * (size_t)id[i];
        double R = 0;
        for (j = 0; j < w->n; ++j) {
            const sph_real* xj = x0 + 2 * (size_t)id[j];
            sph_real d[2], g[2];
            int k;
            if (j == i) continue;
            for (k = 0; k < 2; ++k) {
                double dk = (double)xi[k] - (double)xj[k];
                dk -= L * floor(dk / L + 0.5); /* minimum image */
                d[k] = (sph_real)dk;
            }
            if ((double)(d[0] * d[0] + d[1] * d[1]) >= (double)(w->kernel.radius * w->kernel.radius))
                continue;
            sph_kernel_grad(&w->kernel, d, g);
            for (k = 0; k < 2; ++k)
                R += m * ((double)vel[2 * i + (size_t)k] - (double)vel[2 * j + (size_t)k]) * (double)g[k];
        }
        R /= S;
        if (R > 0) sum += R * dt / 1000;
    }
    return sum / (double)w->n;
}

static void test_df_divergence_solve(void) {
    const double L = 0.4, U = 0.1, dt = 0.02, pi = 3.14159265358979323846;
    sph_world_def def = sph_world_def_default(2);
    def.boundary_pressure = SPH_BP_EXTRAPOLATE; /* the wall scheme this test was written for (the
                                               default before SPH_BP_AUTO) */
    sph_world w;
    sph_phase water;
    sph_real lo[2] = {0, 0}, hi[2] = {(sph_real)L, (sph_real)L}, *x0, *v0;
    uint32_t* id0;
    double S = 0, before, after;
    size_t i;
    int a, b;
    def.solver = SPH_SOLVER_DFSPH;
    def.spacing = (sph_real)0.02;
    def.gravity[1] = 0;
    def.alpha = 0;
    def.tolerance = (sph_real)0.99;
    def.min_iterations = 0;
    def.periodic[0] = def.periodic[1] = 1;
    def.domain_hi[0] = def.domain_hi[1] = (sph_real)L;
    memset(&water, 0, sizeof(water));
    water.rest_density = 1000;
    CHECK_EQ_INT(sph_world_init(&w, &def), SPH_OK);
    CHECK_EQ_INT(sph_world_add_phase(&w, &water), 0);
    CHECK_EQ_INT(sph_fill_box(&w, 0, lo, hi), SPH_OK);
    for (i = 0; i < w.n; ++i) w.v[2 * i] = (sph_real)(U * sin(2 * pi * (double)w.x[2 * i] / L));
    for (a = -4; a <= 4; ++a) /* the lattice sum dx^2 sum W over the lattice */
        for (b = -4; b <= 4; ++b)
            S += (double)sph_kernel_w(&w.kernel, w.dx * (sph_real)sqrt((double)(a * a + b * b))) *
                 (double)(w.dx * w.dx);
    x0 = (sph_real*)malloc(w.n * 2 * sizeof(sph_real));
    v0 = (sph_real*)malloc(w.n * 2 * sizeof(sph_real));
    id0 = (uint32_t*)malloc(w.n * sizeof(uint32_t));
    for (i = 0; i < w.n; ++i) { /* positions and velocities by id (ids are 0 .. n-1 here) */
        x0[2 * w.id[i]] = w.x[2 * i];
        x0[2 * w.id[i] + 1] = w.x[2 * i + 1];
        v0[2 * i] = w.v[2 * i];
        v0[2 * i + 1] = w.v[2 * i + 1];
        id0[i] = w.id[i];
    }
    before = df_divergence(&w, x0, v0, id0, S, dt);
    CHECK_EQ_INT(th_step(&w, (sph_real)dt), SPH_OK);
    after = df_divergence(&w, x0, w.v, w.id, S, dt);
    TH_NOTE("divergence solve: mean compressive D rho/Dt dt / rho0 %.3e before, %.3e after "
            "(stats %.3e, tolerance %.0e) in %d iterations; density solve iterations %d",
            before, after, w.stats.divergence_error, (double)def.divergence_tolerance,
            w.stats.iterations_divergence, w.stats.iterations - w.stats.iterations_divergence);
    CHECK_LT(5 * (double)def.divergence_tolerance, before);
    CHECK_LE(after, (double)def.divergence_tolerance);
    CHECK_NEAR(after, w.stats.divergence_error, 1e-3 * (double)def.divergence_tolerance);
    CHECK(w.stats.iterations_divergence >= 1);
    CHECK_EQ_INT(w.stats.iterations, w.stats.iterations_divergence); /* no density updates */
    free(x0);
    free(v0);
    free(id0);
    sph_world_free(&w);
}

/* ---- an enclosed fluid ---------------------------------------------------------------------- */

/* A closed unit box completely filled (30 x 30 particles, free-slip walls), no gravity, the
   vortex u = sin(pi x) cos(pi y), v = -cos(pi x) sin(pi y), nu = 0.01 m^2/s, no artificial
   viscosity, for 1 s at 0.4 dx / |v|max, zero-pressure walls: the kinetic energy never grows
   from one step to the next (an enclosed fluid has no pressure level of its own, and the
   pressures, clamped at 0, must build one; the solves must not pump energy into the flow), and
   it decays by less than 2.5 times the viscous rate of the Stokes mode (exp(-4 pi^2 nu t)^2.5:
   the flow keeps its vortex; measured 0.45 at t = 1 against the Stokes mode's 0.67). The pressure level is Jacobi's slowest mode, so max_iterations is
   raised to 300 here and steps that still end above tolerance (SPH_ERR_NOT_CONVERGED, complete)
   are counted and reported. With mirrored or extrapolated walls (p_b from the fluid's p) the
   enclosed system has no pressure level at all, and DFSPH blows up within 0.15 s (measured:
   kinetic energy +66 % in one step, after steps at max_iterations); see the manual. */
static void test_df_enclosed_vortex(void) {
    const double pi = 3.14159265358979323846, nu = 0.01;
    const int bp = SPH_BP_ZERO;
    {
        sph_world_def def = sph_world_def_default(2);
        sph_world w;
        sph_phase fluid;
        sph_real lo[2] = {0, 0}, hi[2] = {1, 1};
        double ke0 = 0, ke_prev, grow = 0, dt;
        size_t i;
        int steps = 0, failed = 0, unconverged = 0, its = 0;
        def.solver = SPH_SOLVER_DFSPH;
        def.boundary_pressure = (sph_boundary_pressure)bp;
        def.max_iterations = 300;
        def.spacing = (sph_real)(1.0 / 30);
        def.gravity[1] = 0;
        def.alpha = 0;
        memset(&fluid, 0, sizeof(fluid));
        fluid.rest_density = 1000;
        fluid.viscosity = (sph_real)nu;
        CHECK_EQ_INT(sph_world_init(&w, &def), SPH_OK);
        CHECK_EQ_INT(sph_world_add_phase(&w, &fluid), 0);
        CHECK_EQ_INT(sph_fill_box(&w, 0, lo, hi), SPH_OK);
        CHECK_EQ_INT(sph_add_wall_box(&w, lo, hi, 0, 0), SPH_OK);
        for (i = 0; i < w.n; ++i) {
            const double x = (double)w.x[2 * i], y = (double)w.x[2 * i + 1];
            w.v[2 * i] = (sph_real)(sin(pi * x) * cos(pi * y));
            w.v[2 * i + 1] = (sph_real)(-cos(pi * x) * sin(pi * y));
            ke0 += 0.5 * (double)w.mass * ((double)(w.v[2 * i] * w.v[2 * i]) +
                                           (double)(w.v[2 * i + 1] * w.v[2 * i + 1]));
        }
        dt = df_dt(&w, 1.0, 0);
        ke_prev = ke0;
        while (w.time < 1.0 - 1e-9) {
            const sph_status s = th_step(&w, (sph_real)dt);
            if (s == SPH_ERR_NOT_CONVERGED) ++unconverged; /* complete: go on */
            else if (s != SPH_OK) { CHECK_MSG(0, "vortex scheme %d: %s", bp, w.error); failed = 1; break; }
            ++steps;
            its += w.stats.iterations;
            grow = fmax(grow, w.stats.kinetic_energy / ke_prev - 1);
            ke_prev = w.stats.kinetic_energy;
        }
        TH_NOTE("enclosed vortex, scheme %d, %d steps: kinetic energy %.4f of the start (Stokes "
                "decay %.4f), largest growth in a step %.2e, mean compression %.5f; %.1f "
                "iterations/step, %d steps at max_iterations 300", bp, steps, ke_prev / ke0,
                exp(-4 * pi * pi * nu * w.time), grow, w.stats.compression_avg,
                steps ? (double)its / steps : 0.0, unconverged);
        CHECK(!failed);
        CHECK_LE(grow, 0.0);
        CHECK_LT(pow(exp(-4 * pi * pi * nu * w.time), 2.5), ke_prev / ke0);
        sph_world_free(&w);
    }
}

/* ---- a paddle ------------------------------------------------------------------------------- */

typedef struct df_paddle {
    double x0, A, omega; /* rest position of the face [m], stroke [m], angular frequency [1/s] */
} df_paddle;

static double df_paddle_x(const df_paddle* p, double t) { return p->x0 + p->A * (1 - cos(p->omega * t)); }

static void df_paddle_motion(sph_world* w, double t, void* user) {
    const df_paddle* p = (const df_paddle*)user;
    const double dx = df_paddle_x(p, t) - p->x0, v = p->A * p->omega * sin(p->omega * t);
    const double a = p->A * p->omega * p->omega * cos(p->omega * t);
    size_t b;
    for (b = 0; b < w->nb; ++b) {
        if (w->b_body[b] != 1) continue;
        w->b_x[2 * b] = w->b_x0[2 * b] + (sph_real)dx;
        w->b_v[2 * b] = (sph_real)v;
        w->b_a[2 * b] = (sph_real)a;
    }
}

/* A 1 m tank with water 0.3 m deep right of a paddle (body 1, three layers spanning the depth
   and more) that moves 0.15 m into the water and back in one second (0.47 m/s at most), each
   boundary scheme: at every step no fluid particle is beyond the first layer of the paddle or of
   a tank wall, and the mean compression stays at 0.2 % (the wall velocity enters the source terms:
   without it the paddle would compress the water it pushes). */
static void test_df_paddle(void) {
    int bp;
    for (bp = 0; bp < 3; bp += 2) { /* extrapolated and zero (mirrored walls are refused) */
        const double W = 1.0, H = 0.3, dx = 0.02;
        sph_world_def def = sph_world_def_default(2);
        def.boundary_pressure = SPH_BP_EXTRAPOLATE; /* the wall scheme this test was written for (the
                                                   default before SPH_BP_AUTO) */
        sph_world w;
        df_paddle pd;
        sph_phase water;
        sph_real lo[2] = {0, 0}, hi[2], whi[2] = {(sph_real)W, (sph_real)(2 * H)}, *px;
        double comp = 0, dt, behind = 1e9;
        size_t i, n = 0, escaped = 0;
        int k, j, steps = 0, failed = 0;
        pd.x0 = 0.2;
        pd.A = 0.075;
        pd.omega = 2 * 3.14159265358979323846;
        def.solver = SPH_SOLVER_DFSPH;
        def.boundary_pressure = (sph_boundary_pressure)bp;
        def.spacing = (sph_real)dx;
        def.boundary_motion = df_paddle_motion;
        def.boundary_user = &pd;
        memset(&water, 0, sizeof(water));
        water.rest_density = 1000;
        CHECK_EQ_INT(sph_world_init(&w, &def), SPH_OK);
        CHECK_EQ_INT(sph_world_add_phase(&w, &water), 0);
        lo[0] = (sph_real)pd.x0;
        hi[0] = (sph_real)W;
        hi[1] = (sph_real)H;
        CHECK_EQ_INT(sph_fill_box(&w, 0, lo, hi), SPH_OK);
        lo[0] = 0;
        CHECK_EQ_INT(sph_add_wall_box(&w, lo, whi, 0, SPH_FACE_YMAX), SPH_OK);
        px = (sph_real*)malloc(3 * 30 * 2 * sizeof(sph_real));
        for (k = 0; k < 3; ++k)
            for (j = 0; j < 30; ++j, ++n) {
                px[2 * n] = (sph_real)(pd.x0 - (k + 0.5) * dx);
                px[2 * n + 1] = (sph_real)((j + 0.5) * dx);
            }
        CHECK_EQ_INT(sph_add_boundary(&w, n, px, NULL, 1), SPH_OK);
        free(px);
        CHECK_EQ_INT(sph_set_hydrostatic(&w), SPH_OK);
        dt = df_dt(&w, 2 * sqrt(9.81 * H), 9.81);
        while (w.time < 1.0 - 1e-9) {
            const sph_status s = th_step(&w, (sph_real)dt);
            const double face = df_paddle_x(&pd, w.time - dt); /* the walls of the step */
            size_t out = 0;
            if (s != SPH_OK) { CHECK_MSG(0, "paddle scheme %d: %s", bp, w.error); failed = 1; break; }
            ++steps;
            comp = fmax(comp, w.stats.compression_avg);
            for (i = 0; i < w.n; ++i) {
                const double x = (double)w.x[2 * i], y = (double)w.x[2 * i + 1];
                behind = fmin(behind, (x - face) / dx);
                /* through a wall: beyond the centre line of its first layer */
                if (x < face - 0.5 * dx || x > W + 0.5 * dx || y < -0.5 * dx) ++out;
            }
            if (out > escaped) escaped = out;
        }
        TH_NOTE("paddle, scheme %d, %d steps: closest particle %.2f dx ahead of the face, escaped "
                "%zu, max compression %.5f", bp, steps, behind, escaped, comp);
        CHECK(!failed);
        CHECK_EQ_INT(escaped, 0);
        CHECK_LE(comp, 0.002);
        sph_world_free(&w);
    }
}

/* ---- determinism ---------------------------------------------------------------------------- */

/* The dam break at 40 particles per a (3200 particles, above the parallel threshold), 40 steps
   with 1 and with 2 threads: bitwise identical positions, velocities, pressures, warm starts
   and iteration counts. */
static void test_df_determinism(void) {
#ifndef _OPENMP
    TH_SKIP("built without OpenMP");
#else
    sph_world a, b;
    const int threads = omp_get_max_threads();
    int t, s, ita = 0, itb = 0;
    for (t = 1; t <= 2; ++t) {
        sph_world* w = t == 1 ? &a : &b;
        sph_world_def def = sph_world_def_default(2);
        def.boundary_pressure = SPH_BP_EXTRAPOLATE; /* the wall scheme this test was written for (the
                                                   default before SPH_BP_AUTO) */
        omp_set_num_threads(t);
        def.solver = SPH_SOLVER_DFSPH;
        CHECK_EQ_INT(scene_dam_break(w, def, 0.1, 40, NULL), SPH_OK);
        for (s = 0; s < 40; ++s) {
            CHECK_EQ_INT(th_step(w, (sph_real)5e-4), SPH_OK);
            *(t == 1 ? &ita : &itb) += w->stats.iterations;
        }
    }
    omp_set_num_threads(threads);
    CHECK(a.n == b.n && a.n > 2048);
    CHECK(memcmp(a.x, b.x, a.n * 2 * sizeof(sph_real)) == 0);
    CHECK(memcmp(a.v, b.v, a.n * 2 * sizeof(sph_real)) == 0);
    CHECK(memcmp(a.p, b.p, a.n * sizeof(sph_real)) == 0);
    CHECK(memcmp(a.drho, b.drho, a.n * sizeof(sph_real)) == 0);
    CHECK_EQ_INT(ita, itb);
    TH_NOTE("determinism: %d iterations in 40 steps with 1 and 2 threads", ita);
    sph_world_free(&a);
    sph_world_free(&b);
#endif
}

/* ---- a retried step ------------------------------------------------------------------------ */

/* sph_advance retries a failed step at half the size; the retry must not remove the whole
   compression standing at the step's start within the shorter step (a kick of about
   delta dx / dt, see sph__standing_keep). The 2D tank at rest (1 x 0.8 m of water in a 1 m box,
   dx = 0.02, started by sph_set_hydrostatic) runs into such retries within its first 0.05 s;
   when DFSPH's density solve corrected all of the standing compression in the retried steps,
   the water jumped: the total energy rose by 0.34 rho g H^2 W within 0.3 s (kinetic energy
   1718 J after the first 0.05 s, particles at 4 m/s; 0 rise and 1.7 J with the fix). Held to:
   the total energy (kinetic plus potential) does not rise by more than 0.5 % of rho g H^2 W in any frame, through sph_advance
   with the defaults. */
static void test_df_retry(void) {
    sph_world_def def = sph_world_def_default(2);
    sph_world w;
    sph_phase water;
    const sph_real lo[2] = {0, 0}, fhi[2] = {1, (sph_real)0.8}, thi[2] = {1, 1};
    const double H = 0.8, scale = 1000 * 9.81 * H * H;
    double e0 = 0, rise = 0;
    int f, retries = 0;
    size_t i;
    memset(&water, 0, sizeof water);
    water.rest_density = 1000;
    def.solver = SPH_SOLVER_DFSPH;
    def.spacing = (sph_real)0.02;
    CHECK_EQ_INT(sph_world_init(&w, &def), SPH_OK);
    CHECK(sph_world_add_phase(&w, &water) == 0);
    CHECK_EQ_INT(sph_fill_box(&w, 0, lo, fhi), SPH_OK);
    CHECK_EQ_INT(sph_add_wall_box(&w, lo, thi, 0, 0), SPH_OK);
    CHECK_EQ_INT(sph_set_hydrostatic(&w), SPH_OK);
    for (i = 0; i < w.n; ++i) e0 += (double)w.mass * 9.81 * (double)w.x[2 * i + 1];
    for (f = 1; f <= 6; ++f) {
        double e = 0;
        CHECK_EQ_INT(sph_advance(&w, (sph_real)0.05), SPH_OK);
        retries += w.stats.retries;
        for (i = 0; i < w.n; ++i) e += (double)w.mass * 9.81 * (double)w.x[2 * i + 1];
        e += w.stats.kinetic_energy;
        if ((e - e0) / scale > rise) rise = (e - e0) / scale;
    }
    TH_NOTE("2D tank at rest, DFSPH through sph_advance, 0.3 s: %d retries, largest energy rise "
            "%.2e of rho g H^2 W, kinetic energy at the end %.3g J", retries, rise,
            w.stats.kinetic_energy);
    CHECK_LE(rise, 5e-3);
    sph_world_free(&w);
}

const th_test tests_dfsph[] = {
    {"dfsph/tank_2d_every_boundary_scheme", test_df_tank_2d},
    {"dfsph/tank_3d", test_df_tank_3d},
    {"dfsph/dam_break_martin_moyce", test_df_dam_break},
    {"dfsph/dam_break_against_iisph", test_df_vs_iisph},
    {"dfsph/divergence_solve", test_df_divergence_solve},
    {"dfsph/enclosed_vortex_gains_no_energy", test_df_enclosed_vortex},
    {"dfsph/paddle", test_df_paddle},
    {"dfsph/determinism_1_2_threads", test_df_determinism},
    {"dfsph/retry_keeps_standing_compression", test_df_retry},
    {0, 0},
};
