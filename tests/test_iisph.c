/* tests/test_iisph.c - implicit incompressible SPH (Meiers 2025): a hydrostatic column held to
   0.1 % compression, iteration counts against depth and time step, the three boundary pressure
   schemes, single-layer walls, a rotating non-uniformly sampled stirrer, a lifting piston, the
   time-step sweet spot, and thread determinism. */
#include "harness.h"
#include "../sph.h"
#include "../examples/scenes.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

/* ---- a tank of water at rest --------------------------------------------------------------- */

typedef struct tank_result {
    double comp_max;      /* largest mean compression after the first `skip` steps */
    double layer_err;     /* mean |layer-averaged p - rho g (H - y)| / (rho g H), interior */
    double particle_err;  /* mean |p - rho g (H - y)| / (rho g H) over interior particles */
    double near_floor;    /* mean signed error of particles within a support of the floor */
    double iterations;    /* mean solver iterations */
    double lowest;        /* lowest fluid particle above the floor plane [dx] */
    size_t outside;       /* most particles beyond a wall's first layer at any step */
    int steps, at_max;    /* steps, steps that hit max_iterations */
    double step_ms;
} tank_result;

/* A tank W = 1 m wide with water H deep (res particles over 0.5 m), walls of `layers` layers
   (0: enough for the kernel), `closed` or open at the top, run for T seconds at time step dt.
   Pressures are time-averaged over the last 0.5 s per particle. */
static tank_result run_tank(sph_world_def def, double H, int layers, int closed, double dt, double T,
                            int skip) {
    const double W = 1.0, dx = 0.5 / 20;
    sph_world w;
    sph_phase water;
    sph_real lo[2] = {0, 0}, hi[2] = {(sph_real)W, (sph_real)H}, whi[2] = {(sph_real)W, (sph_real)(H + 0.2)};
    tank_result r;
    double *ps, its = 0, bins[128] = {0};
    int *cn, bc[128] = {0}, b, nl = 0, np = 0, nf = 0;
    size_t i;
    memset(&r, 0, sizeof(r));
    memset(&water, 0, sizeof(water));
    water.rest_density = 1000;
    def.solver = SPH_SOLVER_IISPH;
    def.spacing = (sph_real)dx;
    def.domain_lo[0] = (sph_real)(-dx / 2);
    def.domain_hi[0] = (sph_real)(W + dx / 2);
    def.domain_lo[1] = (sph_real)(-dx / 2);
    def.domain_hi[1] = (sph_real)(closed ? H + 0.2 + dx / 2 : 10);
    if (sph_world_init(&w, &def) != SPH_OK || sph_world_add_phase(&w, &water) != 0 ||
        sph_fill_box(&w, 0, lo, hi) != SPH_OK ||
        sph_add_wall_box(&w, lo, whi, layers, closed ? 0 : SPH_FACE_YMAX) != SPH_OK ||
        sph_set_hydrostatic(&w) != SPH_OK) {
        CHECK_MSG(0, "tank: %s", w.error);
        r.comp_max = 1;
        return r;
    }
    ps = (double*)calloc(w.n, sizeof(double));
    cn = (int*)calloc(w.n, sizeof(int));
    r.lowest = 1e9;
    while (w.time < T - 1e-9) {
        /* dt = 0: what a user gets, sph_advance (frames of 0.01 s) with the library's step control */
        if ((dt > 0 ? th_step(&w, (sph_real)dt) : sph_advance(&w, (sph_real)0.01)) != SPH_OK) {
            CHECK_MSG(0, "step %d: %s", r.steps, w.error);
            break;
        }
        ++r.steps;
        its += w.stats.iterations;
        if (w.stats.iterations >= def.max_iterations) ++r.at_max;
        if (r.steps > skip && w.stats.compression_avg > r.comp_max) r.comp_max = w.stats.compression_avg;
        if (w.stats.n_outside > r.outside) r.outside = w.stats.n_outside;
        if (w.time > T - 0.5)
            for (i = 0; i < w.n; ++i) { ps[w.id[i]] += (double)w.p[i]; cn[w.id[i]]++; }
    }
    for (i = 0; i < w.n; ++i) {
        const double x = (double)w.x[2 * i], y = (double)w.x[2 * i + 1], m = (double)w.kernel.radius;
        double p, e;
        r.lowest = fmin(r.lowest, y / dx);
        if (x < m || x > W - m || y > H - m || !cn[w.id[i]]) continue;
        p = ps[w.id[i]] / cn[w.id[i]];
        e = (p - 1000 * 9.81 * (H - y)) / (1000 * 9.81 * H);
        if (y < m) { r.near_floor += e; ++nf; continue; }
        r.particle_err += fabs(e);
        ++np;
        b = (int)((y - m) / (2 * dx)); /* whole layers two spacings thick, from the exclusion edge */
        if (b < 128) { bins[b] += e; bc[b]++; }
    }
    for (b = 0; b < 128; ++b)
        if (bc[b]) { r.layer_err += fabs(bins[b] / bc[b]); ++nl; }
    r.layer_err = nl ? r.layer_err / nl : 1;
    r.particle_err = np ? r.particle_err / np : 1;
    r.near_floor = nf ? r.near_floor / nf : 1;
    r.iterations = r.steps ? its / r.steps : 0;
    r.step_ms = r.steps ? 1e3 * w.step_time_total / r.steps : 0;
    free(ps);
    free(cn);
    sph_world_free(&w);
    return r;
}

/* Hydrostatic column, 20 particles deep, dt = 0.005 s: the measured mean compression stays at or
   below 0.1 % at every step (the hydrostatic start is a lattice at exactly rest density), no
   step needs the iteration cap, no particle passes a wall; the layer-averaged pressure follows
   rho g (H - y) to 1.5 % (the discrete gradient's lattice normalisation bounds it); particle
   pressures scatter more (IISPH corrects each particle's summation density with its own
   pressure), bounded at 5 %. */
static void test_hydrostatic_column(void) {
    sph_world_def def = sph_world_def_default(2);
    def.boundary_pressure = SPH_BP_EXTRAPOLATE; /* the wall scheme this test was written for (the
                                               default before SPH_BP_AUTO) */
    const tank_result r = run_tank(def, 0.5, 0, 0, 0.005, 2.0, 0);
    TH_NOTE("IISPH tank 20 deep, dt 5 ms: max mean compression %.5f, %.1f iterations, %.2f ms/step; "
            "pressure error layer-averaged %.4f, per particle %.4f of rho g H; outside %zu",
            r.comp_max, r.iterations, r.step_ms, r.layer_err, r.particle_err, r.outside);
    CHECK_LE(r.comp_max, 0.001 * 1.0001);
    CHECK_EQ_INT(r.at_max, 0);
    CHECK_LT(r.layer_err, 0.015);
    CHECK_LT(r.particle_err, 0.05);
    CHECK_EQ_INT(r.outside, 0);
}

/* Meiers 2025 Fig. 6: mean iterations grow with the fluid's depth (fixed dt) and with dt (fixed
   depth); asserted as strictly increasing over three points each. */
static void test_iterations_grow(void) {
    sph_world_def def = sph_world_def_default(2);
    def.boundary_pressure = SPH_BP_EXTRAPOLATE; /* the wall scheme this test was written for (the
                                               default before SPH_BP_AUTO) */
    const double depth[3] = {0.25, 0.5, 1.0}, dts[3] = {0.0025, 0.005, 0.01};
    double itd[3], itt[3];
    int k;
    for (k = 0; k < 3; ++k) itd[k] = run_tank(def, depth[k], 0, 0, 0.005, 0.5, 0).iterations;
    for (k = 0; k < 3; ++k) itt[k] = run_tank(def, 0.5, 0, 0, dts[k], 0.5, 0).iterations;
    TH_NOTE("mean iterations at depth 0.25/0.5/1.0 m (dt 5 ms): %.1f %.1f %.1f; at dt 2.5/5/10 ms "
            "(0.5 m): %.1f %.1f %.1f", itd[0], itd[1], itd[2], itt[0], itt[1], itt[2]);
    CHECK(itd[0] < itd[1] && itd[1] < itd[2]);
    CHECK(itt[0] < itt[1] && itt[1] < itt[2]);
}

/* The boundary pressure schemes hold a tank at rest: no particle passes a wall in 4 s and the
   compression stays at 0.1 % (extrapolation) or within 0.2 %. Meiers 2025 sec. 5.3: zero
   pressure puts the weight on the wall-adjacent layer (its pressure runs well above hydrostatic),
   extrapolation does not. The wall-adjacent pressure errors are reported. Mirroring (p_b = p_i,
   +1.4 % next to the floor here when it was offered) is refused: it put energy into tanks at rest
   (see SPH_BP_MIRROR). */
static void test_boundary_schemes(void) {
    static const char* names[3] = {"extrapolation", "mirroring", "zero pressure"};
    tank_result r[3];
    int bp;
    for (bp = 0; bp < 3; ++bp) {
        sph_world_def def = sph_world_def_default(2);
        if (bp == SPH_BP_MIRROR) continue;
        def.boundary_pressure = (sph_boundary_pressure)bp;
        r[bp] = run_tank(def, 0.5, 0, 0, 0.005, 4.0, 3);
        TH_NOTE("%-13s: near-floor pressure error %+.4f, interior layers %.4f of rho g H, "
                "%.1f iterations, max compression %.5f, lowest particle %.2f dx above the floor, "
                "outside %zu", names[bp], r[bp].near_floor, r[bp].layer_err, r[bp].iterations,
                r[bp].comp_max, r[bp].lowest, r[bp].outside);
        CHECK_EQ_INT(r[bp].outside, 0);
        CHECK(r[bp].lowest > 0);
        CHECK_LE(r[bp].comp_max, bp == 0 ? 0.0010001 : 0.002);
    }
    CHECK_LT(0.1, r[2].near_floor);                  /* zero pressure overloads the wall layer */
    CHECK_LT(fabs(r[0].near_floor), 0.05);
}

/* Single-layer walls with Akinci volumes, closed box, the library's defaults (gamma_1 calibrated
   by sph__akinci_gamma; with gamma_1 = 1 the start was 24 % compressed next to the layer and
   this test had to raise max_compression to 0.5): no particle passes the layer in 4 s, for each
   scheme, and the fluid settles to 0.2 % compression. */
static void test_single_layer_walls(void) {
    int bp;
    for (bp = 0; bp < 3; ++bp) {
        sph_world_def def = sph_world_def_default(2);
        tank_result r;
        if (bp == SPH_BP_MIRROR) continue; /* refused (see SPH_BP_MIRROR) */
        /* through sph_advance: at a fixed 5 ms a particle reached 5.5 m/s at t = 0.37 s with
           zero wall pressure, which the step now reports (1.09 spacings per step) */
        def.boundary_pressure = (sph_boundary_pressure)bp;
        def.boundary_volume = SPH_BVOL_AKINCI;
        r = run_tank(def, 0.5, 1, 1, 0, 4.0, 200); /* 200 frames: after 2 s */
        TH_NOTE("single layer, scheme %d: outside %zu, lowest particle %.2f dx above the floor, "
                "compression after 2 s %.5f", bp, r.outside, r.lowest, r.comp_max);
        CHECK_EQ_INT(r.outside, 0);
        CHECK(r.lowest > 0);
        /* the most compressed particle within 2.5 times the solve's mean tolerance (0.1 %):
           0.12 % (extrapolated), 0.24 % (zero: the row at the layer carries the load, against a
           layer of 0.585 times gamma = 1's volume; 0.2 % and less with gamma = 1) */
        CHECK_LE(r.comp_max, 2.5 * (double)def.tolerance);
    }
}

/* ---- moving boundaries --------------------------------------------------------------------- */

/* Meiers 2025 sec. 5.1.2: the stirrer (oval single-layer container, three-blade rotor sampled from
   0.5 dx to dx) turning at half a revolution per second: no particle leaves the oval, no blow-up,
   and after the first three steps (the lattice start next to the curved walls is 0.2 %
   compressed) the measured mean compression stays at or below 0.1 %. The actual compression
   runs about 0.05 % above the solver's linear prediction here, so the tolerance is 0.05 % and
   the step 0.3 dx / |v|max. make validate runs ten revolutions. */
static void run_stirrer(double revolutions, int check) {
    sph_world_def def = sph_world_def_default(2);
    def.boundary_pressure = SPH_BP_EXTRAPOLATE; /* the wall scheme this test was written for (the
                                               default before SPH_BP_AUTO) */
    sph_world w;
    scene_stirrer st;
    double comp = 0, extent = 0, its = 0;
    int steps = 0;
    def.solver = SPH_SOLVER_IISPH;
    def.tolerance = (sph_real)0.0005;
    def.cfl_velocity = (sph_real)0.3;
    st.omega = 3.14159265358979323846;
    if (scene_stirrer_build(&w, def, 0.02, 0.6, &st) != SPH_OK) {
        CHECK_MSG(0, "stirrer: %s", scene_error);
        return;
    }
    while (w.time < revolutions * 2 - 1e-9) {
        sph_real dt = sph_stable_dt(&w, SPH_SOLVER_IISPH);
        if (dt > (sph_real)0.005) dt = (sph_real)0.005;
        if (th_step(&w, dt) != SPH_OK) {
            CHECK_MSG(0, "stirrer step %d: %s", steps, w.error);
            break;
        }
        ++steps;
        its += w.stats.iterations;
        if (steps > 3) comp = fmax(comp, w.stats.compression_avg);
        extent = fmax(extent, scene_stirrer_extent(&w, &st));
    }
    TH_NOTE("stirrer, %.0f revolutions, %zu particles, %zu wall particles: %d steps, %.1f "
            "iterations, max compression %.5f, largest (x/a)^2 + (y/b)^2 = %.4f, %.2f ms/step",
            revolutions, w.n, w.nb, steps, its / steps, comp, extent,
            1e3 * w.step_time_total / steps);
    if (check) {
        CHECK_LT(extent, 1);
        CHECK_LE(comp, 0.001);
    }
    sph_world_free(&w);
}

static void test_stirrer(void) { run_stirrer(2, 1); }
static void test_stirrer_long(void) { run_stirrer(10, 1); }

typedef struct lift_piston {
    double U, ramp; /* final speed [m/s], smooth start [s] */
} lift_piston;

static void piston_kinematics(const lift_piston* p, double t, double* y, double* v, double* a) {
    const double pi = 3.14159265358979323846;
    if (t < p->ramp) {
        *v = p->U * 0.5 * (1 - cos(pi * t / p->ramp));
        *a = p->U * 0.5 * pi / p->ramp * sin(pi * t / p->ramp);
        *y = p->U * 0.5 * (t - p->ramp / pi * sin(pi * t / p->ramp));
    } else {
        *v = p->U;
        *a = 0;
        *y = p->U * (t - 0.5 * p->ramp);
    }
}

static void lift_motion(sph_world* w, double t, void* user) {
    double y, v, a;
    size_t b;
    piston_kinematics((const lift_piston*)user, t, &y, &v, &a);
    for (b = 0; b < w->nb; ++b) {
        if (w->b_body[b] != 1) continue;
        w->b_x[2 * b + 1] = w->b_x0[2 * b + 1] + (sph_real)y;
        w->b_v[2 * b + 1] = (sph_real)v;
        w->b_a[2 * b + 1] = (sph_real)a;
    }
}

/* A piston (the tube's floor, body 1) lifts a 0.4 m column at a prescribed speed (smooth start
   to 0.5 m/s in 0.2 s). The piston's pressure (its first layer, extrapolated) carries the
   hydrostatic plus acceleration load rho (g + a) (H + dx/2): averaged over the accelerating
   window 0.05-0.15 s and over the constant-speed window 0.3-0.6 s it matches to 3 % (single
   steps scatter by about 5 %). The fluid stays incompressible (mean compression at the 0.1 %
   tolerance at every step) and moves with the piston: its centre of mass stays at the same
   height above it to 0.2 dx (the wall stand-off adjusting). The wall velocity enters the
   source term: without it the piston would run into the fluid. */
static void test_lifting_piston(void) {
    const double H = 0.4, Wd = 0.2, dx = 0.02, dt = 0.004;
    sph_world_def def = sph_world_def_default(2);
    def.boundary_pressure = SPH_BP_EXTRAPOLATE; /* the wall scheme this test was written for (the
                                               default before SPH_BP_AUTO) */
    sph_world w;
    lift_piston lp;
    sph_phase water;
    sph_real lo[2] = {0, 0}, hi[2] = {(sph_real)Wd, (sph_real)H}, whi[2] = {(sph_real)Wd, 1.2};
    sph_real* px;
    double load_acc = 0, load_const = 0, cm0 = 0, drift = 0, comp = 0, solve = 0;
    size_t i, n = 0;
    int k, n_acc = 0, n_const = 0;
    lp.U = 0.5;
    lp.ramp = 0.2;
    def.solver = SPH_SOLVER_IISPH;
    def.spacing = (sph_real)dx;
    def.boundary_motion = lift_motion;
    def.boundary_user = &lp;
    memset(&water, 0, sizeof(water));
    water.rest_density = 1000;
    CHECK_EQ_INT(sph_world_init(&w, &def), SPH_OK);
    CHECK_EQ_INT(sph_world_add_phase(&w, &water), 0);
    CHECK_EQ_INT(sph_fill_box(&w, 0, lo, hi), SPH_OK);
    CHECK_EQ_INT(sph_add_wall_box(&w, lo, whi, 3, SPH_FACE_YMIN | SPH_FACE_YMAX), SPH_OK); /* tube */
    px = (sph_real*)malloc(3 * 16 * 2 * sizeof(sph_real));
    for (k = 0; k < 3; ++k) /* the piston spans the tube and its walls */
        for (i = 0; i < 16; ++i, ++n) {
            px[2 * n] = (sph_real)((i - 2.5) * dx);
            px[2 * n + 1] = (sph_real)(-(k + 0.5) * dx);
        }
    CHECK_EQ_INT(sph_add_boundary(&w, n, px, NULL, 1), SPH_OK);
    free(px);
    CHECK_EQ_INT(sph_set_hydrostatic(&w), SPH_OK);
    for (i = 0; i < w.n; ++i) cm0 += (double)w.x[2 * i + 1] / (double)w.n;
    while (w.time < 0.6 - 1e-9) {
        double y, v, a, pb = 0, cm = 0;
        const double t0 = w.time; /* the walls of this step are at its start time */
        size_t b, nb = 0;
        if (th_step(&w, (sph_real)dt) != SPH_OK) { CHECK_MSG(0, "piston: %s", w.error); break; }
        comp = fmax(comp, w.stats.compression_avg);
        solve = fmax(solve, w.stats.solver_error);
        piston_kinematics(&lp, t0, &y, &v, &a);
        for (b = 0; b < w.nb; ++b) {
            const double bx = (double)w.b_x[2 * b], by = (double)w.b_x[2 * b + 1] - y;
            if (w.b_body[b] == 1 && fabs(by + 0.5 * dx) < 0.1 * dx && bx > 0.05 && bx < Wd - 0.05) {
                pb += (double)w.b_p[b];
                ++nb;
            }
        }
        if (!nb) continue;
        pb /= (double)nb * 1000 * (9.81 + a) * (H + 0.5 * dx);
        if (t0 >= 0.05 && t0 <= 0.15) { load_acc += pb; ++n_acc; }
        if (t0 >= 0.3) { load_const += pb; ++n_const; }
        piston_kinematics(&lp, w.time, &y, &v, &a);
        for (i = 0; i < w.n; ++i) cm += (double)w.x[2 * i + 1] / (double)w.n;
        drift = fmax(drift, fabs(cm - y - cm0));
    }
    load_acc = n_acc ? load_acc / n_acc : 0;
    load_const = n_const ? load_const / n_const : 0;
    TH_NOTE("lifting piston: mean load while accelerating %.4f, at constant speed %.4f of "
            "rho (g + a)(H + dx/2); centre of mass drift relative to the piston %.3f dx; max "
            "compression %.5f", load_acc, load_const, drift / dx, comp);
    CHECK_NEAR(load_acc, 1, 0.03);
    CHECK_NEAR(load_const, 1, 0.03);
    CHECK_LT(drift, 0.2 * dx);
    /* the solver's 0.1 % on predicted compression; measured after the move it is 0.102 %, and
       0.111 % at the steps where the wall contact (def.wall_contact) moves the two particles in
       the piston's corners back out after the solve (measured; 0.0001 of the mean from 2 of 200
       particles) */
    CHECK_LE(solve, 0.001 * (1 + 1e-9));
    CHECK_LE(comp, 0.0012);
    sph_world_free(&w);
}

/* ---- the time-step sweet spot (Meiers 2025 Table 2) ------------------------------------------ */

/* One column for 0.5 s at four time steps: larger steps need more iterations but fewer steps
   (both monotone); the table of iterations, steps and solver work is reported. make bench
   times it. */
static void test_dt_sweep(void) {
    sph_world_def def = sph_world_def_default(2);
    def.boundary_pressure = SPH_BP_EXTRAPOLATE; /* the wall scheme this test was written for (the
                                               default before SPH_BP_AUTO) */
    const double dts[4] = {0.003, 0.005, 0.008, 0.012};
    double it[4];
    int st[4], k;
    for (k = 0; k < 4; ++k) {
        const tank_result r = run_tank(def, 0.5, 0, 0, dts[k], 0.6, 0);
        it[k] = r.iterations;
        st[k] = r.steps;
        TH_NOTE("dt %.3f s: %d steps, %.1f iterations per step, %.0f iterations in all, %.2f ms/step",
                dts[k], r.steps, r.iterations, r.iterations * r.steps, r.step_ms);
    }
    for (k = 0; k < 3; ++k) {
        CHECK_LT(it[k], it[k + 1]);
        CHECK_LT(st[k + 1], st[k]);
    }
}

/* ---- determinism --------------------------------------------------------------------------- */

/* The dam break of scene_dam_break (a = 0.1 m at res particles per a) with def, `steps` steps of
   dt on 1 and on 2 threads: bitwise the same state and iteration count. */
static void iisph_same_on_1_and_2_threads(sph_world_def def, int res, int steps, double dt) {
#ifndef _OPENMP
    (void)def; (void)res; (void)steps; (void)dt;
    TH_SKIP("built without OpenMP");
#else
    sph_world a, b;
    int t, s;
    def.solver = SPH_SOLVER_IISPH;
    for (t = 1; t <= 2; ++t) {
        sph_world* w = t == 1 ? &a : &b;
        omp_set_num_threads(t);
        CHECK_EQ_INT(scene_dam_break(w, def, 0.1, res, NULL), SPH_OK);
        for (s = 0; s < steps; ++s) CHECK_EQ_INT(th_step(w, (sph_real)dt), SPH_OK);
    }
    CHECK(a.n == b.n && memcmp(a.x, b.x, a.n * 2 * sizeof(sph_real)) == 0);
    CHECK(memcmp(a.v, b.v, a.n * 2 * sizeof(sph_real)) == 0);
    CHECK(memcmp(a.p, b.p, a.n * sizeof(sph_real)) == 0);
    CHECK(a.stats.iterations == b.stats.iterations);
    sph_world_free(&a);
    sph_world_free(&b);
    omp_set_num_threads(omp_get_num_procs());
#endif
}

static void test_iisph_determinism(void) {
    sph_world_def def = sph_world_def_default(2);
    def.boundary_pressure = SPH_BP_EXTRAPOLATE; /* the wall scheme this test was written for (the
                                                   default before SPH_BP_AUTO) */
    iisph_same_on_1_and_2_threads(def, 24, 60, 1e-3);
}

/* A step whose solve ends with a particle still predicted beyond def.max_compression fails at
   that step (SPH_ERR_UNSTABLE) naming the particle, so sph_advance can retry it smaller. The
   density check on the step's own start would only see it one step later, when no smaller step
   can undo it. Water hitting a floor at 5 m/s, one step of 6 ms (1.2 spacings) with at most two
   Jacobi sweeps (IISPH) or one sweep per solve (DFSPH's constant-density solve): the predicted
   compression at the floor stays far above 20 %. */
static void test_overcompressed_step_fails(void) {
    static const sph_solver solvers[2] = {SPH_SOLVER_IISPH, SPH_SOLVER_DFSPH};
    int si;
    for (si = 0; si < 2; ++si) {
        sph_world_def def = sph_world_def_default(2);
        sph_world w;
        sph_phase water;
        const sph_real lo[2] = {0, 0}, hi[2] = {(sph_real)0.5, (sph_real)0.3},
                       thi[2] = {(sph_real)0.5, (sph_real)0.5};
        sph_status s;
        size_t i;
        memset(&water, 0, sizeof water);
        water.rest_density = 1000;
        def.solver = solvers[si];
        def.spacing = (sph_real)0.025;
        def.max_iterations = si == 0 ? 2 : 1;
        def.min_iterations = 1;
        def.max_speed = 100;      /* neither the speed bound nor the displacement bound */
        def.max_displacement = 3; /* is what this test is about */
        CHECK_EQ_INT(sph_world_init(&w, &def), SPH_OK);
        CHECK(sph_world_add_phase(&w, &water) == 0);
        CHECK_EQ_INT(sph_fill_box(&w, 0, lo, hi), SPH_OK);
        CHECK_EQ_INT(sph_add_wall_box(&w, lo, thi, 0, 0), SPH_OK);
        for (i = 0; i < w.n; ++i) w.v[2 * i + 1] = -5;
        s = sph_step(&w, (sph_real)0.006);
        TH_NOTE("%s, 5 m/s into the floor, dt 6 ms, %d sweep(s): status %d: %s",
                si == 0 ? "IISPH" : "DFSPH", def.max_iterations, (int)s, w.error);
        CHECK_EQ_INT(s, SPH_ERR_UNSTABLE);
        CHECK(strstr(w.error, "max_compression") != NULL);
        CHECK(w.error_index >= 0 && (double)w.x[2 * (size_t)w.error_index + 1] < 0.1);
        sph_world_free(&w);
    }
}

/* ---- conjugate gradients (def.pressure_solve = SPH_PSOLVE_CG) ------------------------------- */

/* A closed tank W wide (and deep in 3D) with 0.8 W of water at spacing dx, from
   sph_set_hydrostatic, then `steps` IISPH steps of dt. */
static void cg_tank(sph_world* w, int dim, double W, double dx, double tol, sph_pressure_solve ps,
                    int steps, double dt) {
    sph_world_def def = sph_world_def_default(dim);
    sph_phase water;
    sph_real lo[3] = {0, 0, 0}, hi[3], whi[3];
    int k;
    memset(&water, 0, sizeof water);
    water.rest_density = 1000;
    def.solver = SPH_SOLVER_IISPH;
    def.spacing = (sph_real)dx;
    def.tolerance = (sph_real)tol;
    def.max_iterations = 100000;
    def.pressure_solve = ps;
    for (k = 0; k < 3; ++k) { hi[k] = (sph_real)W; whi[k] = (sph_real)W; }
    hi[1] = (sph_real)(0.8 * W);
    CHECK_EQ_INT(sph_world_init(w, &def), SPH_OK);
    CHECK_EQ_INT(sph_fill_box(w, sph_world_add_phase(w, &water), lo, hi), SPH_OK);
    CHECK_EQ_INT(sph_add_wall_box(w, lo, whi, 0, 0), SPH_OK);
    CHECK_EQ_INT(sph_set_hydrostatic(w), SPH_OK);
    for (k = 0; k < steps; ++k) CHECK_EQ_INT(sph_step_iisph(w, (sph_real)dt), SPH_OK);
}

/* Both solvers solve the same system: from the same state, solved to a mean compression of 1e-8,
   their pressures agree (measured: 1 Pa of 30 kPa in 2D, 3 Pa of 25 kPa in 3D; Jacobi's own
   spread between 1e-6 and 1e-8 is 75 Pa), and conjugate gradients need a fraction of Jacobi's
   products with A (measured 128 against 1027 in 2D, 85 against 499 in 3D). With extrapolated
   wall pressure (no constraint force, A not self-adjoint) SPH_PSOLVE_CG is Jacobi, bit for bit. */
static void test_cg_matches_jacobi(void) {
    int dim;
    for (dim = 2; dim <= 3; ++dim) {
        sph_world a, b;
        double dmax = 0, pmax = 0;
        size_t i;
        cg_tank(&a, dim, dim == 2 ? 1.0 : 0.4, 0.04, 1e-8, SPH_PSOLVE_JACOBI, 5, 0.005);
        memset(&b, 0, sizeof b);
        CHECK_EQ_INT(sph_world_copy(&b, &a), SPH_OK);
        b.def.pressure_solve = SPH_PSOLVE_CG;
        CHECK_EQ_INT(sph_step_iisph(&a, (sph_real)0.005), SPH_OK);
        CHECK_EQ_INT(sph_step_iisph(&b, (sph_real)0.005), SPH_OK);
        for (i = 0; i < a.n; ++i) {
            const double d = fabs((double)a.p[i] - (double)b.p[i]);
            if (d > dmax) dmax = d;
            if ((double)a.p[i] > pmax) pmax = (double)a.p[i];
        }
        TH_NOTE("%dD: Jacobi %d sweeps, CG %d products; |p_J - p_CG| <= %.3g Pa of %.4g Pa", dim,
                a.stats.iterations, b.stats.iterations, dmax, pmax);
        CHECK_LE(dmax, 1e-3 * pmax);
        CHECK_LE(b.stats.solver_error, 1e-8);
        CHECK_LE(3 * b.stats.iterations, a.stats.iterations);
        sph_world_free(&a);
        sph_world_free(&b);
    }
    {
        sph_world a, b;
        int t, k;
        for (t = 0; t < 2; ++t) {
            sph_world* w = t ? &b : &a;
            sph_world_def def = sph_world_def_default(2);
            def.solver = SPH_SOLVER_IISPH;
            def.boundary_pressure = SPH_BP_EXTRAPOLATE;
            def.pressure_solve = t ? SPH_PSOLVE_CG : SPH_PSOLVE_JACOBI;
            CHECK_EQ_INT(scene_dam_break(w, def, 0.1, 16, NULL), SPH_OK);
            for (k = 0; k < 20; ++k) CHECK_EQ_INT(th_step(w, 2e-3), SPH_OK);
        }
        CHECK(a.n == b.n && memcmp(a.x, b.x, a.n * 2 * sizeof(sph_real)) == 0);
        CHECK(memcmp(a.p, b.p, a.n * sizeof(sph_real)) == 0);
        sph_world_free(&a);
        sph_world_free(&b);
    }
}

/* Conjugate gradients in a user's scene: the 2D tank at rest (1 m box, 0.8 m of water, dx 0.04)
   through sph_advance for 1.5 s: Jacobi at the default tolerance 1e-3 and at 1e-4, CG at 1e-4.
   Nothing passes a wall and the energy never rises above its start; CG reaches the tenfold
   tighter tolerance for at most 1.25 times the work of Jacobi at the default (measured 0.9) and
   at under a third of Jacobi's at the same tolerance (measured 1/7; Jacobi's solves stop at
   max_iterations and are retried smaller). How still the tank gets is in the README ("Choosing a
   solver"); 1.5 s is too short to tell the solvers apart. */
static void test_cg_tank_at_rest(void) {
    const double vref = sqrt(9.81 * 0.8);
    double late[3] = {0, 0, 0}, work[3] = {0, 0, 0};
    int v;
    for (v = 0; v < 3; ++v) { /* Jacobi 1e-3 (default), Jacobi 1e-4, CG 1e-4 */
        sph_world w;
        double e0 = 0, rise = 0;
        int f;
        size_t i;
        cg_tank(&w, 2, 1.0, 0.04, v ? 1e-4 : 1e-3, v == 2 ? SPH_PSOLVE_CG : SPH_PSOLVE_JACOBI, 0, 0);
        w.def.max_iterations = 100;
        for (i = 0; i < w.n; ++i) e0 += (double)w.mass * 9.81 * (double)w.x[2 * i + 1];
        for (f = 1; f <= 30; ++f) {
            double e = 0;
            CHECK_EQ_INT(sph_advance(&w, (sph_real)0.05), SPH_OK);
            for (i = 0; i < w.n; ++i) {
                e += (double)w.mass * 9.81 * (double)w.x[2 * i + 1];
                CHECK((double)w.x[2 * i] > 0 && (double)w.x[2 * i] < 1 && (double)w.x[2 * i + 1] > 0);
            }
            e += w.stats.kinetic_energy;
            if (e - e0 > rise) rise = e - e0;
            work[v] += w.stats.iterations_sum;
            if (f > 20 && w.stats.v_max > late[v]) late[v] = w.stats.v_max;
        }
        late[v] /= vref;
        TH_NOTE("%s, tolerance %g: late max speed %.3f sqrt(g H), %.0f products, %llu steps, "
                "energy rise %.3g J", v == 2 ? "CG" : "Jacobi", v ? 1e-4 : 1e-3, late[v], work[v],
                (unsigned long long)w.steps, rise);
        CHECK_LE(rise, 0);
        sph_world_free(&w);
    }
    CHECK_LE(work[2], 1.25 * work[0]);
    CHECK_LT(3 * work[2], work[1]);
}

/* Bitwise the same on 1 and 2 threads (a dam break above the 2048 particles where the parallel
   loops start). */
static void test_cg_determinism(void) {
    sph_world_def def = sph_world_def_default(2);
    def.pressure_solve = SPH_PSOLVE_CG;
    iisph_same_on_1_and_2_threads(def, 48, 20, 1e-3);
}

const th_test tests_iisph[] = {
    {"iisph/hydrostatic_column", test_hydrostatic_column},
    {"iisph/overcompressed_step_fails_at_its_step", test_overcompressed_step_fails}, /* and DFSPH */
    {"iisph/iterations_grow_with_depth_and_dt", test_iterations_grow},
    {"iisph/boundary_schemes", test_boundary_schemes},
    {"iisph/single_layer_walls", test_single_layer_walls},
    {"iisph/stirrer", test_stirrer},
    {"iisph/lifting_piston", test_lifting_piston},
    {"iisph/dt_sweep", test_dt_sweep},
    {"iisph/determinism_1_vs_2_threads", test_iisph_determinism},
    {"iisph/cg_matches_jacobi", test_cg_matches_jacobi},
    {"iisph/cg_tank_at_rest", test_cg_tank_at_rest},
    {"iisph/cg_determinism_1_vs_2_threads", test_cg_determinism},
    {0, 0},
};

/* Long runs for make validate. */
const th_test tests_iisph_long[] = {
    {"iisph-long/stirrer_10_revolutions", test_stirrer_long},
    {0, 0},
};
