/* bench/bench_core.h - the measuring half of the benchmark driver, compiled once per precision.

   bench/bench.c includes it with sph_real = double, bench/bench_float.c with SPH_FLOAT (and
   SPH_STATIC, so the two copies of the library do not clash); BX(name) gives each copy its own
   function names (name_d, name_f). Everything crossing between the two is plain double, in the
   structs of bench/bench_types.h. */
#ifndef BX
#error "define BX(name) before including bench_core.h"
#endif

/* Builds scene s with about `target` fluid particles for solver `solver`. */
BENCH_FN int BX(build)(sph_world* w, int scene, int solver, double target) {
    const int dim = bench_scenes[scene].dim;
    sph_world_def def = sph_world_def_default(dim);
    int res;
    switch (solver) {
    case BENCH_PCISPH:
        sph_world_def_pcisph(&def, 0);
        break;
    case BENCH_PCISPH_ENH:
        sph_world_def_pcisph(&def, 1);
        break;
    case BENCH_IISPH:
        def.solver = SPH_SOLVER_IISPH;
        break;
    default:
        break;
    }
    switch (scene) {
    case BENCH_DAMBREAK2D: /* n = a/dx * 2a/dx */
        res = (int)floor(sqrt(target / 2) + 0.5);
        return scene_dam_break(w, def, 0.5, res < 2 ? 2 : res, NULL) == SPH_OK;
    case BENCH_DAMBREAK3D: /* n = 2 (a/dx)^3 */
        res = (int)floor(cbrt(target / 2) + 0.5);
        return scene_dam_break(w, def, 0.5, res < 2 ? 2 : res, NULL) == SPH_OK;
    case BENCH_HYDROSTATIC2D: /* 1 m x 0.5 m: n = 2 res^2 */
        res = (int)floor(sqrt(target / 2) + 0.5);
        return scene_hydrostatic(w, def, 1.0, 0.5, res < 2 ? 2 : res) == SPH_OK;
    default:
        return 0;
    }
}

BENCH_FN uint64_t BX(fnv)(uint64_t h, const void* data, size_t n) {
    const unsigned char* p = (const unsigned char*)data;
    size_t i;
    for (i = 0; i < n; ++i)
        h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

BENCH_FN uint64_t BX(hash)(const sph_world* w) {
    uint64_t h = 14695981039346656037ull;
    h = BX(fnv)(h, w->x, w->n * (size_t)w->dim * sizeof(sph_real));
    h = BX(fnv)(h, w->v, w->n * (size_t)w->dim * sizeof(sph_real));
    h = BX(fnv)(h, w->rho, w->n * sizeof(sph_real));
    h = BX(fnv)(h, w->id, w->n * sizeof(uint32_t));
    return h;
}

/* The time step of a timed run. WCSPH: sph_stable_dt (acoustic CFL). The incompressible solvers'
   limit is Meiers 2025 eq. 14, cfl_velocity dx / |v|max, and |v|max is 0 at the start, so they get
   it with the speed the flow will reach, U = c0 / 10 (the automatic sound speed is 10 U with
   U = sqrt(2 |g| H), sph.h's rule): one fixed step for the whole run, as a user would pick. */
BENCH_FN double BX(bench_dt)(sph_world* w, int solver) {
    const double dtw = (double)sph_stable_dt(w, SPH_SOLVER_WCSPH); /* also fixes c0 */
    double dt;
    if (solver == BENCH_WCSPH) return dtw;
    dt = (double)w->def.cfl_velocity * (double)w->dx / ((double)w->phases[0].sound_speed / 10);
    if (dt > (double)sph_stable_dt(w, (sph_solver)bench_solvers[solver].sph_solver))
        dt = (double)sph_stable_dt(w, (sph_solver)bench_solvers[solver].sph_solver);
    return dt;
}

/* Times `steps` steps of the scene after `warm` warm-up steps, at the solver's stable dt. */
BENCH_FN int BX(run)(int scene, int solver, double target, int warm, int steps, bench_result* r) {
    sph_world w;
    double dt, its = 0;
    int s, k;
    memset(r, 0, sizeof(*r));
    if (!BX(build)(&w, scene, solver, target)) {
        fprintf(stderr, "bench: %s\n", scene_error);
        return 0;
    }
    dt = BX(bench_dt)(&w, solver);
    for (s = 0; s < warm; ++s)
        if (sph_step(&w, (sph_real)dt) != SPH_OK) goto fail;
    w.step_time_total = 0;
    for (k = 0; k < SPH_STAGE_COUNT; ++k)
        w.stage_time_total[k] = 0;
    for (s = 0; s < steps; ++s) {
        if (sph_step(&w, (sph_real)dt) != SPH_OK) goto fail;
        its += w.stats.iterations;
    }
    r->n = (double)w.n;
    r->nb = (double)w.nb;
    r->dt = dt;
    r->step_s = w.step_time_total / steps;
    for (k = 0; k < SPH_STAGE_COUNT && k < 8; ++k)
        r->stage_s[k] = w.stage_time_total[k] / steps;
    r->iterations = solver == BENCH_WCSPH ? 0 : its / steps; /* WCSPH reports 1 */
    r->pairs = (double)w.stats.pairs / (double)w.n;
    r->bytes = (double)sph_world_memory(&w) / (double)w.n;
    r->hash = BX(hash)(&w);
    sph_world_free(&w);
    return 1;
fail:
    fprintf(stderr, "bench: step failed: %s\n", w.error);
    sph_world_free(&w);
    return 0;
}

/* The baseline (bench/baseline.h) on the same scene and steps; its agreement with sph.h after
   the timed steps goes to r->agree (largest position difference, in particle spacings). */
BENCH_FN int BX(run_baseline)(int scene, double target, int warm, int steps, bench_result* r) {
    sph_world w;
    base_world b;
    double dt, t0, dmax = 0;
    int s;
    size_t i;
    memset(r, 0, sizeof(*r));
    if (!BX(build)(&w, scene, BENCH_WCSPH, target)) return 0;
    dt = (double)sph_stable_dt(&w, SPH_SOLVER_WCSPH);
    if (!base_init(&b, &w) || b.c0 <= 0) {
        sph_world_free(&w);
        return 0;
    }
    for (s = 0; s < warm; ++s)
        if (!base_step(&b, (sph_real)dt)) goto fail;
    b.t_grid = b.t_lists = b.t_density = b.t_forces = b.t_other = 0;
    t0 = bench_now();
    for (s = 0; s < steps; ++s)
        if (!base_step(&b, (sph_real)dt)) goto fail;
    r->step_s = (bench_now() - t0) / steps;
    r->grid_s = b.t_grid / steps;
    r->lists_s = b.t_lists / steps;
    r->stage_s[SPH_STAGE_NEIGHBORS] = (b.t_grid + b.t_lists) / steps;
    r->stage_s[SPH_STAGE_DENSITY] = b.t_density / steps;
    r->stage_s[SPH_STAGE_FORCES] = b.t_forces / steps;
    r->stage_s[SPH_STAGE_INTEGRATE] = b.t_other / steps;
    r->n = (double)b.n;
    r->nb = (double)b.nb;
    r->dt = dt;
    r->bytes = base_bytes_per_particle(&b);
    /* the same steps with sph.h (untimed): positions by particle id */
    for (s = 0; s < warm + steps; ++s)
        if (sph_step(&w, (sph_real)dt) != SPH_OK) goto fail;
    {
        size_t* at = (size_t*)malloc((b.n + 1) * sizeof(size_t));
        if (!at) goto fail;
        for (i = 0; i < b.n; ++i)
            at[b.id[i]] = i;
        for (i = 0; i < w.n; ++i) {
            const size_t j = at[w.id[i]];
            int k;
            for (k = 0; k < w.dim; ++k) {
                const double d = fabs((double)w.x[i * (size_t)w.dim + (size_t)k] -
                                      (double)b.x[j * (size_t)w.dim + (size_t)k]);
                if (d > dmax) dmax = d;
            }
        }
        free(at);
    }
    r->agree = dmax / (double)w.dx;
    base_free(&b);
    sph_world_free(&w);
    return 1;
fail:
    base_free(&b);
    sph_world_free(&w);
    return 0;
}

/* Neighbour search alone, fluid-fluid, ns per particle: sph.h's grid build (counting sort into
   cells) and list build through the public API on the particles as a step leaves them (in cell
   order), and the baseline's on the same particles in the order they were added. r: sph.h,
   rb: baseline. */
BENCH_FN int BX(run_search)(int scene, double target, int reps, bench_result* r, bench_result* rb) {
    sph_world w;
    base_world b;
    sph_grid g;
    sph_neighbors nl;
    double t0;
    int s, ok = 1;
    memset(r, 0, sizeof(*r));
    memset(rb, 0, sizeof(*rb));
    memset(&nl, 0, sizeof(nl));
    if (!BX(build)(&w, scene, BENCH_WCSPH, target)) return 0;
    if (!base_init(&b, &w)) {
        sph_world_free(&w);
        return 0;
    }
    if (sph_step(&w, sph_stable_dt(&w, SPH_SOLVER_WCSPH)) != SPH_OK ||
        sph_grid_init(&g, w.dim, w.kernel.radius, NULL, NULL, NULL) != SPH_OK) {
        base_free(&b);
        sph_world_free(&w);
        return 0;
    }
    for (s = 0; s <= reps && ok; ++s) { /* the first round allocates: not timed */
        t0 = bench_now();
        ok = sph_grid_build(&g, w.x, w.n) == SPH_OK;
        if (s) r->grid_s += bench_now() - t0;
        t0 = bench_now();
        ok = ok && sph_neighbors_build(&nl, &g, w.x, w.x, w.n, w.kernel.radius, 1) == SPH_OK;
        if (s) r->lists_s += bench_now() - t0;
        t0 = bench_now();
        ok = ok && base__grid_build(&b.gf, b.dim, b.x, b.n, b.R);
        if (s) rb->grid_s += bench_now() - t0;
        t0 = bench_now();
        base__lists(&b, &b.gf, b.x, b.x, b.n, 1, b.ff, b.ffn);
        if (s) rb->lists_s += bench_now() - t0;
    }
    r->n = rb->n = (double)w.n;
    r->grid_s /= reps;
    r->lists_s /= reps;
    rb->grid_s /= reps;
    rb->lists_s /= reps;
    r->pairs = (double)nl.total / (double)w.n;
    {
        size_t i, tot = 0;
        for (i = 0; i < b.n; ++i)
            tot += b.ffn[i];
        rb->pairs = (double)tot / (double)b.n;
    }
    ok = ok && !b.overflow;
    sph_neighbors_free(&nl);
    sph_grid_free(&g);
    base_free(&b);
    sph_world_free(&w);
    return ok;
}

/* "Model no more than a scene needs": the 2D dam break with one optional piece of physics on. */
enum {
    BENCH_M_BASE,
    BENCH_M_NODELTA,
    BENCH_M_VERLET,
    BENCH_M_SUMMATION,
    BENCH_M_VISCOUS,
    BENCH_M_AKINCI,
    BENCH_M_TWOPHASE,
    BENCH_M_ENERGY,
    BENCH_M_PCISPH,
    BENCH_M_IISPH,
    BENCH_NMODEL
};
static const char* const bench_model_names[BENCH_NMODEL] = {
    "defaults (continuity, delta-SPH, extrapolated walls)",
    "delta-SPH off",
    "Stormer-Verlet",
    "summation density",
    "laminar viscosity + no-slip walls",
    "Akinci wall volumes",
    "two phases (upper half 800 kg/m^3)",
    "energy equation (compressible step)",
    "PCISPH enhanced (for scale)",
    "IISPH (for scale)"};

BENCH_FN int BX(build_model)(sph_world* w, int model, double target) {
    sph_world_def def = sph_world_def_default(2);
    sph_phase water, oil;
    const double a = 0.5;
    const int res = (int)floor(sqrt(target / 2) + 0.5);
    sph_real lo[3] = {0, 0, 0}, mid[3], hi[3], thi[3];
    int p0, p1;
    memset(&water, 0, sizeof(water));
    water.rest_density = 1000;
    oil = water;
    oil.rest_density = 800;
    def.spacing = (sph_real)(a / res);
    switch (model) {
    case BENCH_M_NODELTA:
        def.delta = 0;
        break;
    case BENCH_M_VERLET:
        def.integrator = SPH_INTEGRATOR_VERLET;
        break;
    case BENCH_M_SUMMATION:
        def.density = SPH_DENSITY_SUMMATION;
        break;
    case BENCH_M_VISCOUS:
        water.viscosity = (sph_real)1e-6;
        def.wall = SPH_WALL_NO_SLIP;
        break;
    case BENCH_M_AKINCI:
        def.boundary_volume = SPH_BVOL_AKINCI;
        break;
    case BENCH_M_ENERGY:
        def.solver = SPH_SOLVER_COMPRESSIBLE;
        break;
    case BENCH_M_PCISPH:
        sph_world_def_pcisph(&def, 1);
        break;
    case BENCH_M_IISPH:
        def.solver = SPH_SOLVER_IISPH;
        break;
    default:
        break;
    }
    hi[0] = (sph_real)a;
    hi[1] = (sph_real)(2 * a);
    mid[0] = (sph_real)a;
    mid[1] = (sph_real)a;
    thi[0] = (sph_real)(5 * a);
    thi[1] = (sph_real)(3 * a);
    if (sph_world_init(w, &def) != SPH_OK) return 0;
    p0 = sph_world_add_phase(w, &water);
    p1 = model == BENCH_M_TWOPHASE ? sph_world_add_phase(w, &oil) : p0;
    if (p0 < 0 || p1 < 0) goto fail;
    if (model == BENCH_M_TWOPHASE) {
        sph_real lo1[3] = {0, 0, 0};
        lo1[1] = (sph_real)a;
        if (sph_fill_box(w, p0, lo, mid) != SPH_OK || sph_fill_box(w, p1, lo1, hi) != SPH_OK)
            goto fail;
    } else if (sph_fill_box(w, p0, lo, hi) != SPH_OK) {
        goto fail;
    }
    if (sph_add_wall_box(w, lo, thi, 0, 0) != SPH_OK || sph_set_hydrostatic(w) != SPH_OK) goto fail;
    return 1;
fail:
    snprintf(scene_error, sizeof scene_error, "%s", w->error);
    sph_world_free(w);
    return 0;
}

BENCH_FN int BX(run_model)(int model, double target, int warm, int steps, bench_result* r) {
    sph_world w;
    double dt;
    int s;
    memset(r, 0, sizeof(*r));
    if (!BX(build_model)(&w, model, target)) {
        fprintf(stderr, "bench: %s\n", scene_error);
        return 0;
    }
    dt = BX(bench_dt)(&w, model == BENCH_M_PCISPH  ? BENCH_PCISPH_ENH
                          : model == BENCH_M_IISPH ? BENCH_IISPH
                                                   : BENCH_WCSPH);
    for (s = 0; s < warm; ++s)
        if (sph_step(&w, (sph_real)dt) != SPH_OK) goto fail;
    w.step_time_total = 0;
    for (s = 0; s < steps; ++s) {
        if (sph_step(&w, (sph_real)dt) != SPH_OK) goto fail;
        r->iterations += w.stats.iterations;
    }
    r->iterations /= steps;
    r->n = (double)w.n;
    r->nb = (double)w.nb;
    r->dt = dt;
    r->step_s = w.step_time_total / steps;
    r->bytes = (double)sph_world_memory(&w) / (double)w.n;
    sph_world_free(&w);
    return 1;
fail:
    fprintf(stderr, "bench: model %d: %s\n", model, w.error);
    sph_world_free(&w);
    return 0;
}

/* 3D multiphase memory: the 3D dam break column split in two phases (water under oil). */
BENCH_FN double BX(bytes_3d_multiphase)(double target) {
    sph_world_def def = sph_world_def_default(3);
    sph_world w;
    sph_phase water, oil;
    const double a = 0.5;
    const int res = (int)floor(cbrt(target / 2) + 0.5);
    sph_real lo[3] = {0, 0, 0}, lo1[3] = {0, 0, 0}, mid[3], hi[3], thi[3];
    double bytes = 0;
    int p0, p1, k;
    memset(&water, 0, sizeof(water));
    water.rest_density = 1000;
    oil = water;
    oil.rest_density = 800;
    def.spacing = (sph_real)(a / res);
    for (k = 0; k < 3; ++k) {
        hi[k] = mid[k] = (sph_real)a;
        thi[k] = (sph_real)a;
    }
    hi[1] = (sph_real)(2 * a);
    lo1[1] = (sph_real)a;
    thi[0] = (sph_real)(5 * a);
    thi[1] = (sph_real)(3 * a);
    if (sph_world_init(&w, &def) != SPH_OK) return 0;
    p0 = sph_world_add_phase(&w, &water);
    p1 = sph_world_add_phase(&w, &oil);
    if (p0 >= 0 && p1 >= 0 && sph_fill_box(&w, p0, lo, mid) == SPH_OK &&
        sph_fill_box(&w, p1, lo1, hi) == SPH_OK && sph_add_wall_box(&w, lo, thi, 0, 0) == SPH_OK &&
        sph_set_hydrostatic(&w) == SPH_OK &&
        sph_step(&w, sph_stable_dt(&w, SPH_SOLVER_WCSPH)) == SPH_OK)
        bytes = (double)sph_world_memory(&w) / (double)w.n;
    sph_world_free(&w);
    return bytes;
}

/* ---- time to solution (the tts suite) -------------------------------------------------------- */

/* Builds a tts scene for a solver with the library's defaults (only the scene's geometry,
   material and the solver's preset are set), the domain box set to the container's interior so
   that w.stats.n_outside counts fluid that left it. 3D: SPlisHSPlasH's DamBreakModel, a cube of
   (1/dx - 1)^3 particles (39^3 = 59319 at dx 0.025 m, 19^3 = 6859 at 0.05 m) in the corner of a
   closed 4 x 3 x 1.5 m box of wall particles, nu = 0.01 m^2/s, gravity -9.81 m/s^2 in y. */
BENCH_FN int BX(tts_build)(sph_world* w, int scene, int solver, int quick) {
    const int dim = scene == TTS_DAM2D ? 2 : 3;
    sph_world_def def = sph_world_def_default(dim);
    switch (solver) {
    case TTS_PCISPH_ENH:
        sph_world_def_pcisph(&def, 1);
        break;
    case TTS_PCISPH:
        sph_world_def_pcisph(&def, 0);
        break;
    case TTS_IISPH:
        def.solver = SPH_SOLVER_IISPH;
        break;
    case TTS_DFSPH:
        def.solver = SPH_SOLVER_DFSPH;
        break;
    case TTS_PBF:
        def.solver = SPH_SOLVER_PBF;
        break;
    default:
        break;
    }
    if (bench_tts_skin >= -1) def.neighbor_skin = (sph_real)bench_tts_skin; /* --skin */
    if (bench_tts_kernel == 1) { /* --kernel cubic: the peer's support, 2 dx */
        def.kernel = SPH_KERNEL_CUBIC;
        def.h_factor = 1;
        def.omega = (sph_real)0.5;
    } else if (bench_tts_kernel == 2) { /* --kernel wendland: Wendland C2 at h = 1.3 dx */
        def.kernel = SPH_KERNEL_WENDLAND_C2;
    }
    if (scene == TTS_DAM2D) { /* examples/dambreak.c's scene: a = 0.5 m, 40 particles per a */
        const double a = 0.5;
        def.domain_hi[0] = (sph_real)(5 * a);
        def.domain_hi[1] = (sph_real)(3 * a);
        if (scene_dam_break(w, def, a, quick ? 10 : 40, NULL) != SPH_OK) return 0;
        return 1;
    }
    {
        const double dx = scene == TTS_DAM3D_FINE ? 0.025 : 0.05;
        const int m = (int)floor(1 / dx + 0.5) - 1;
        sph_real lo[3] = {0, 0, 0}, hi[3], box[3];
        sph_phase water;
        int ph, k;
        memset(&water, 0, sizeof(water));
        water.rest_density = 1000;
        water.viscosity = (sph_real)0.01;
        def.spacing = (sph_real)dx;
        box[0] = 4;
        box[1] = 3;
        box[2] = (sph_real)1.5;
        for (k = 0; k < 3; ++k) {
            hi[k] = (sph_real)(m * dx);
            def.domain_hi[k] = box[k];
        }
        if (sph_world_init(w, &def) != SPH_OK) goto fail;
        ph = sph_world_add_phase(w, &water);
        if (ph < 0 || sph_fill_box(w, ph, lo, hi) != SPH_OK ||
            sph_add_wall_box(w, lo, box, 0, 0) != SPH_OK || sph_set_hydrostatic(w) != SPH_OK)
            goto fail;
        return 1;
    fail:
        snprintf(scene_error, sizeof scene_error, "%s", w->error);
        sph_world_free(w);
        return 0;
    }
}

/* Runs a tts scene to t_end through sph_advance in frames of TTS_FRAME, stopping at the first
   error (the world is then as at the end of the last good frame: r->time is the time reached)
   or once more than max_wall wall-clock seconds (0: no limit) were spent. progress > 0: a line on
   stderr every `progress` wall-clock seconds. Returns 1 if the scene was built. */
BENCH_FN int BX(tts)(int scene, int solver, int quick, double t_end, double max_wall,
                     double progress, tts_result* r) {
    sph_world w;
    double rho0, next_report = progress, sum_err = 0, sum_comp = 0, sum_its = 0;
    int f, frames;
    memset(r, 0, sizeof(*r));
    if (!BX(tts_build)(&w, scene, solver, quick)) {
        r->status = -1;
        snprintf(r->error, sizeof r->error, "%s", scene_error);
        return 0;
    }
    r->n = (double)w.n;
    r->nb = (double)w.nb;
    rho0 = (double)w.phases[0].rest_density;
    frames = (int)ceil(t_end / TTS_FRAME - 1e-9);
    for (f = 0; f < frames; ++f) {
        const double target = f + 1 == frames ? t_end : (f + 1) * TTS_FRAME;
        double t0, e_sum = 0, c_sum = 0, c_max = -1;
        sph_status s;
        size_t i;
        w.stats.substeps = w.stats.retries = 0; /* set by the call (not by every failure path) */
        t0 = bench_now();
        s = sph_advance(&w, (sph_real)(target - w.time));
        r->wall_s += bench_now() - t0;
        r->substeps += s == SPH_ERR_BUDGET ? w.def.max_substeps : w.stats.substeps;
        r->retries += w.stats.retries;
        if (w.stats.dt_min > 0 && (r->dt_min == 0 || w.stats.dt_min < r->dt_min))
            r->dt_min = w.stats.dt_min;
        if (s != SPH_OK) {
            r->status = (int)s;
            snprintf(r->error, sizeof r->error, "%s", w.error);
            break;
        }
        for (i = 0; i < w.n; ++i) {
            const double e = (double)w.rho[i] / rho0 - 1;
            int k;
            e_sum += fabs(e);
            c_sum += e > 0 ? e : 0;
            if (e > c_max) c_max = e;
            for (k = 0; k < w.dim; ++k) { /* depth outside the container (w.def.domain) */
                const double x = (double)w.x[i * (size_t)w.dim + (size_t)k];
                const double d = fmax((double)w.def.domain_lo[k] - x,
                                      x - (double)w.def.domain_hi[k]) / (double)w.dx;
                if (d > r->outside_depth) r->outside_depth = d;
            }
        }
        sum_err += w.n ? e_sum / (double)w.n : 0;
        sum_comp += w.n ? c_sum / (double)w.n : 0;
        sum_its += w.stats.iterations;
        if (c_max > r->comp_max) r->comp_max = c_max;
        if ((double)w.stats.n_outside > r->outside_max) r->outside_max = (double)w.stats.n_outside;
        r->frames = f + 1;
        if (progress > 0 && r->wall_s >= next_report) {
            fprintf(stderr, "  [%s %s %s] t = %.3f s after %.0f s wall, %.0f sub-steps, %.0f "
                            "retries\n",
                    tts_scene_names[scene], tts_solver_names[solver],
                    sizeof(sph_real) == sizeof(float) ? "float" : "double", w.time, r->wall_s,
                    r->substeps, r->retries);
            next_report += progress;
        }
        if (max_wall > 0 && r->wall_s > max_wall && f + 1 < frames) {
            r->capped = 1;
            break;
        }
    }
    r->time = w.time;
    for (f = 0; f < SPH_STAGE_COUNT; ++f)
        r->stage_s[f] = (double)w.stage_time_total[f];
    if (r->frames > 0) {
        r->err_mean = sum_err / r->frames;
        r->comp_mean = sum_comp / r->frames;
        r->its_mean = sum_its / r->frames;
    }
    sph_world_free(&w);
    return 1;
}
