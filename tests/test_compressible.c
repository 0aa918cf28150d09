/* tests/test_compressible.c - the compressible multiphase step and the Ott-Schnetter particle-
   density continuity (Ott & Schnetter 2003), against exact solutions: Toro's Riemann problems, Ott
   & Schnetter 2003's advection, sound wave and air | Diesel shock tube, an interface at rest at
   1000:1 (periodic, and touching side walls) and a 1000:1 dam break against the column alone. */
#include "../sph.h"
#include "harness.h"
#include "riemann.h"
#include "../bench/svg.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

/* ---- helpers ------------------------------------------------------------------------------- */

/* Adds a phase (C++-compatible: no compound literals in the tests). */
static int add_phase(sph_world* w, double rho0, sph_eos eos, double gamma, double c0, double pb,
                     double nu) {
    sph_phase ph;
    memset(&ph, 0, sizeof ph);
    ph.rest_density = (sph_real)rho0;
    ph.eos = eos;
    ph.gamma = (sph_real)gamma;
    ph.sound_speed = (sph_real)c0;
    ph.back_pressure = (sph_real)pb;
    ph.viscosity = (sph_real)nu;
    return sph_world_add_phase(w, &ph);
}

/* Adds the particles of [x0, x1) at spacing dx (centred in their cells), density rho, mass
   rho dx: a 1D line of one phase. */
static int line(sph_world* w, int phase, double x0, double x1, double dx, double rho) {
    const size_t n = (size_t)floor((x1 - x0) / dx + 0.5);
    sph_real* x = (sph_real*)malloc(n * sizeof(sph_real));
    sph_real* m = (sph_real*)malloc(n * sizeof(sph_real));
    sph_real* r = (sph_real*)malloc(n * sizeof(sph_real));
    size_t i;
    sph_status s;
    for (i = 0; i < n; ++i) {
        x[i] = (sph_real)(x0 + ((double)i + 0.5) * dx);
        m[i] = (sph_real)(rho * dx);
        r[i] = (sph_real)rho;
    }
    s = sph_add_fluid_ex(w, phase, n, x, NULL, m, r);
    free(x);
    free(m);
    free(r);
    return s == SPH_OK;
}

static double particle_mass(const sph_world* w, size_t i) {
    return (double)(w->m ? w->m[i] : w->mass);
}

/* Total energy sum m (e + |v|^2 / 2) [J]. */
static double total_energy(const sph_world* w) {
    double E = 0;
    size_t i;
    int k;
    for (i = 0; i < w->n; ++i) {
        double v2 = 0;
        for (k = 0; k < w->dim; ++k) v2 += (double)w->v[i * (size_t)w->dim + (size_t)k] * (double)w->v[i * (size_t)w->dim + (size_t)k];
        E += particle_mass(w, i) * ((w->e ? (double)w->e[i] : 0) + 0.5 * v2);
    }
    return E;
}

/* Sorts particle indices by x (1D worlds are sorted by cell, not exactly by x). */
static const sph_world* g_sort_world;
static int by_x(const void* a, const void* b) {
    const double xa = (double)g_sort_world->x[*(const size_t*)a * (size_t)g_sort_world->dim];
    const double xb = (double)g_sort_world->x[*(const size_t*)b * (size_t)g_sort_world->dim];
    return xa < xb ? -1 : xa > xb ? 1 : 0;
}
static size_t* sorted_by_x(const sph_world* w) {
    size_t* o = (size_t*)malloc(w->n * sizeof(size_t));
    size_t i;
    for (i = 0; i < w->n; ++i) o[i] = i;
    g_sort_world = w;
    qsort(o, w->n, sizeof(size_t), by_x);
    return o;
}

/* Writes a chart to out/NAME.svg when the directory out/ exists (make creates it). */
static void save_chart(svg_chart* ch, const char* name) {
    char path[256];
    snprintf(path, sizeof path, "out/%s.svg", name);
    if (svg_write(ch, path) == 0) TH_NOTE("plot: %s", path);
    svg_free(ch);
}

/* ---- the exact Riemann solver (reference code) --------------------------------------------- */

/* Toro (2009) Table 4.3: the star region of his five ideal-gas tests (gamma = 1.4). */
static void test_riemann_toro(void) {
    static const double T[5][10] = {
        /* rhoL uL pL rhoR uR pR | p* u* rho*L rho*R */
        {1, 0, 1, 0.125, 0, 0.1, 0.30313, 0.92745, 0.42632, 0.26557},
        {1, -2, 0.4, 1, 2, 0.4, 0.00189, 0.00000, 0.02185, 0.02185},
        {1, 0, 1000, 1, 0, 0.01, 460.894, 19.5975, 0.57506, 5.99924},
        {1, 0, 0.01, 1, 0, 100, 46.0950, -6.19633, 5.99242, 0.57511},
        {5.99924, 19.5975, 460.894, 5.99242, -6.19633, 46.0950, 1691.64, 8.68975, 14.2823, 31.0426}};
    int t;
    for (t = 0; t < 5; ++t) {
        rm_state L = {T[t][0], T[t][1], T[t][2], 1.4, 0}, R = {T[t][3], T[t][4], T[t][5], 1.4, 0};
        rm_solution s;
        CHECK(rm_solve(&L, &R, &s) == 0);
        /* the table's five significant digits */
        CHECK_NEAR(s.p_star, T[t][6], 6e-5 * fabs(T[t][6]) + 1e-5);
        CHECK_NEAR(s.u_star, T[t][7], 6e-5 * fabs(T[t][7]) + 1e-5);
        CHECK_NEAR(s.rho_star_L, T[t][8], 6e-5 * T[t][8] + 5e-6);
        CHECK_NEAR(s.rho_star_R, T[t][9], 6e-5 * T[t][9] + 5e-6);
    }
    { /* a sampled Sod profile conserves mass, momentum and energy: integrate over [-0.5, 0.5]
         at t = 0.2 and compare with the initial content minus the boundary fluxes (zero flux
         at both ends while the waves are inside) */
        rm_state L = {1, 0, 1, 1.4, 0}, R = {0.125, 0, 0.1, 1.4, 0};
        rm_solution s;
        double M = 0, P = 0, E = 0;
        const int N = 200000;
        int i;
        rm_solve(&L, &R, &s);
        for (i = 0; i < N; ++i) {
            const double x = -0.5 + (i + 0.5) / N;
            double rho, u, p;
            int side;
            rm_sample(&s, x / 0.2, &rho, &u, &p, &side);
            M += rho / N;
            P += rho * u / N;
            E += (p / 0.4 + 0.5 * rho * u * u) / N;
        }
        CHECK_NEAR(M, 0.5 * (1 + 0.125), 2e-5);
        /* momentum: the pressure difference pushes for 0.2 time units */
        CHECK_NEAR(P, 0.2 * (1 - 0.1), 2e-5);
        CHECK_NEAR(E, 0.5 * (1 / 0.4 + 0.1 / 0.4), 2e-5);
    }
}

/* Ott & Schnetter 2003's air | Diesel problem with Diesel as a stiffened gas (gamma = 11, p_inf
   from c = 1059.6 m/s): the exact shock relations of its Table 2. */
static rm_solution diesel_exact(void) {
    const double rhoD = 772.546, pD = 5e6, cD = 1059.6, gD = 11;
    rm_state L = {88.1, 0, 1e7, 1.4, 0};
    rm_state R = {rhoD, 0, pD, gD, rhoD * cD * cD / gD - pD};
    rm_solution s;
    rm_solve(&L, &R, &s);
    return s;
}

static void test_riemann_diesel(void) {
    rm_solution s = diesel_exact();
    CHECK(s.shock_R && !s.shock_L); /* a shock into the Diesel, a rarefaction into the air */
    CHECK_NEAR(s.cR, 1059.6, 1e-9);
    TH_NOTE("exact air | Diesel: shock %.2f m/s, post-shock Diesel %.4f m/s, drho %.4f kg/m^3, "
            "dp %.4f MPa", s.S_R, s.u_star, s.rho_star_R - 772.546, (s.p_star - 5e6) / 1e6);
    CHECK_NEAR(s.S_R, 1077.0, 0.5);
    CHECK_NEAR(s.u_star, 5.768, 0.001);
    CHECK_NEAR(s.rho_star_R - 772.546, 4.159, 0.001);
    CHECK_NEAR((s.p_star - 5e6) / 1e6, 4.799, 0.001);
}

/* ---- the shock tube ------------------------------------------------------------------------- */

typedef struct tube_result {
    sph_status status;
    unsigned long long steps; /* steps taken (the failing one if status != SPH_OK)             */
    double t;                 /* time reached [s]                                               */
    double shock_half;        /* shock speed from where the Diesel velocity is u_post/2 [m/s]   */
    double shock_area;        /* shock speed from the equal-area position (Whitham) [m/s]       */
    double u_post, drho, dp;  /* plateau means behind the shock, in the Diesel                  */
    double rho_air;           /* mean air density within 3h of the contact [kg/m^3]            */
    double rho_air_max;       /* the largest there                                              */
    double energy_drift;      /* relative change of the total energy                            */
    char error[SPH_ERROR_SIZE];
} tube_result;

/* Ott & Schnetter 2003 sec. 3.3: air (ideal gas, gamma 1.4) on [-0.8, 0), Diesel (stiffened gas
   fitted to c = 1059.6 m/s) on [0, 2.2), periodic (the second interface at 2.2 = -0.8 stays more
   than 0.5 m from everything measured), cubic spline with h = 5 dx (0.05 m at the paper's 100
   particles per metre), alpha = 0.5, beta = 0, to t = 5e-4 s. The plateau is measured between
   the contact's spike (2h) and the shock's foot (3h before the half point). */
static tube_result shock_tube(double dx, sph_density density, sph_pressure_grad pgrad,
                              svg_chart* ch, const char* label) {
    const double t_end = 5e-4, h = 5 * dx;
    sph_world_def def = sph_world_def_default(1);
    sph_world w;
    tube_result r;
    int air, diesel;
    memset(&r, 0, sizeof r);
    def.spacing = (sph_real)dx;
    def.kernel = SPH_KERNEL_CUBIC;
    def.h_factor = 5;
    def.solver = SPH_SOLVER_COMPRESSIBLE;
    def.density = density;
    def.pressure_grad = pgrad;
    def.alpha = (sph_real)0.5;
    def.beta = 0;
    def.delta = 0;
    def.periodic[0] = 1;
    def.domain_lo[0] = (sph_real)-0.8;
    def.domain_hi[0] = (sph_real)2.2;
    CHECK(sph_world_init(&w, &def) == SPH_OK);
    air = add_phase(&w, (sph_real)88.1, SPH_EOS_IDEAL_GAS, 0, 0, (sph_real)1e7, 0);
    diesel = add_phase(&w, (sph_real)772.546, SPH_EOS_STIFFENED_GAS, 11, (sph_real)1059.6, (sph_real)5e6, 0);
    CHECK(air >= 0 && diesel >= 0);
    CHECK(line(&w, air, -0.8, 0, dx, 88.1));
    CHECK(line(&w, diesel, 0, 2.2, dx, 772.546));
    {
        const double E0 = total_energy(&w);
        r.status = sph_advance(&w, (sph_real)t_end);
        r.steps = (unsigned long long)w.steps;
        r.t = w.time;
        snprintf(r.error, sizeof r.error, "%s", w.error);
        r.energy_drift = (total_energy(&w) - E0) / E0;
    }
    if (r.status == SPH_OK) {
        size_t* o = sorted_by_x(&w);
        double xc = -1, xa, xb, su = 0, sr = 0, sp = 0, sa = 0, xs = 0, area = 0, x0 = 1e9;
        int cnt = 0, na = 0;
        size_t q;
        for (q = 0; q < w.n; ++q) /* the contact: the rightmost air particle left of 1 m */
            if (w.phase[o[q]] == air && (double)w.x[o[q]] < 1) xc = (double)w.x[o[q]];
        /* the shock: the last crossing of a rough plateau value / 2, refined below */
        for (q = 0; q < w.n; ++q) {
            const double x = (double)w.x[o[q]];
            if (x > xc + 2 * h && x < xc + 2 * h + 0.15) su += (double)w.v[o[q]], ++cnt;
        }
        r.u_post = su / cnt;
        for (q = 1; q < w.n; ++q) {
            const double xq = (double)w.x[o[q - 1]], xr = (double)w.x[o[q]];
            const double va = (double)w.v[o[q - 1]], vb = (double)w.v[o[q]];
            if (xq > xc && xq < 1.5 && va >= 0.5 * r.u_post && vb < 0.5 * r.u_post)
                xs = xq + (0.5 * r.u_post - va) / (vb - va) * (xr - xq);
        }
        xa = xc + 2 * h;
        xb = xs - 3 * h;
        su = 0;
        cnt = 0;
        for (q = 0; q < w.n; ++q) {
            const size_t i = o[q];
            const double x = (double)w.x[i];
            if (x > xa && x < xb) {
                su += (double)w.v[i];
                sr += (double)w.rho[i] - 772.546;
                sp += (double)w.p[i] - 5e6;
                ++cnt;
            }
            if (x > xa && x < xs + 0.3) { /* particle i stands for [x - V/2, x + V/2] */
                const double V = particle_mass(&w, i) / (double)w.rho[i];
                if (x0 > x - 0.5 * V) x0 = x - 0.5 * V;
                area += (double)w.v[i] * V;
            }
            if (w.phase[i] == air && x > xc - 3 * h && x <= xc) {
                sa += (double)w.rho[i], ++na;
                r.rho_air_max = fmax(r.rho_air_max, (double)w.rho[i]);
            }
        }
        r.u_post = su / cnt;
        r.drho = sr / cnt;
        r.dp = sp / cnt / 1e6;
        r.rho_air = sa / na;
        r.shock_half = xs / r.t;
        /* equal area: the sharp jump of height u_post that has the same momentum content */
        r.shock_area = (x0 + area / r.u_post) / r.t;
        if (ch) {
            double* xv = (double*)malloc(w.n * sizeof(double));
            double* pv = (double*)malloc(w.n * sizeof(double));
            for (q = 0; q < w.n; ++q) {
                xv[q] = (double)w.x[o[q]];
                pv[q] = (double)w.p[o[q]] / 1e6;
            }
            svg_series(ch, xv, pv, w.n, SVG_DOTS, label);
            free(xv);
            free(pv);
        }
        free(o);
    }
    sph_world_free(&w);
    return r;
}

static void test_shock_tube(void) {
    const rm_solution ex = diesel_exact();
    const double drho_ex = ex.rho_star_R - 772.546, dp_ex = (ex.p_star - 5e6) / 1e6;
    svg_chart ch;
    tube_result r, r2, std_mp, std_sym, part_sym;
    double xs[801], ps[801];
    int k;
    svg_begin(&ch, "Air | Diesel shock tube (Ott & Schnetter 2003), t = 0.5 ms, 100 particles/m", "x [m]", "p [MPa]");
    for (k = 0; k <= 800; ++k) {
        double rho, u, p;
        int side;
        xs[k] = -0.5 + 1.6 * k / 800.0;
        rm_sample(&ex, xs[k] / 5e-4, &rho, &u, &p, &side);
        ps[k] = p / 1e6;
    }
    svg_series(&ch, xs, ps, 801, SVG_LINE, "exact");
    svg_range(&ch, 0, -0.5, 1.1);

    /* particle density (eq. 11) with eq. 12: the paper's method */
    r = shock_tube(0.01, SPH_DENSITY_PARTICLE, SPH_PGRAD_MULTIPHASE, &ch, "particle density");
    CHECK_MSG(r.status == SPH_OK, "particle density: %s", r.error);
    TH_NOTE("100/m, particle density: shock %.1f m/s equal-area, %.1f m/s half point (exact %.1f, "
            "paper 1070 +- 10); u %.4f m/s (exact %.4f, paper 5.8 +- 0.05); drho %.4f kg/m^3 (%.4f, "
            "paper 4.17 +- 0.02); dp %.4f MPa (%.4f, paper 4.81 +- 0.03); air at the contact %.2f "
            "kg/m^3 (exact %.2f); energy drift %.1e",
            r.shock_area, r.shock_half, ex.S_R, r.u_post, ex.u_star, r.drho, drho_ex, r.dp, dp_ex,
            r.rho_air, ex.rho_star_L, r.energy_drift);
    /* the paper's error bars, around the exact values; the shock speed within the paper's own
       SPH result (1070 +- 10: 11.6 m/s below the exact 1077 at this resolution, 5.6 at 200/m) */
    CHECK_NEAR(r.shock_area, 1070, 10);
    CHECK_NEAR(r.u_post, ex.u_star, 0.05);
    CHECK_NEAR(r.dp, dp_ex, 0.03);
    /* the density plateau is 0.027 low at this resolution (outside the paper's 0.02); it is
       inside at 200/m, below. Total energy is conserved to round-off. */
    CHECK_NEAR(r.drho, drho_ex, 0.04);
    CHECK(fabs(r.energy_drift) < (sizeof(sph_real) == 4 ? 1e-6 : 1e-12));
    CHECK_NEAR(r.rho_air, ex.rho_star_L, 0.03 * ex.rho_star_L);

    /* 200/m: every Table 2 quantity within the paper's bars */
    r2 = shock_tube(0.005, SPH_DENSITY_PARTICLE, SPH_PGRAD_MULTIPHASE, NULL, NULL);
    CHECK_MSG(r2.status == SPH_OK, "particle density, 200/m: %s", r2.error);
    TH_NOTE("200/m, particle density: shock %.1f m/s equal-area, %.1f half point; u %.4f; drho %.4f; dp %.4f",
            r2.shock_area, r2.shock_half, r2.u_post, r2.drho, r2.dp);
    CHECK_NEAR(r2.shock_area, ex.S_R, 10);
    CHECK_NEAR(r2.u_post, ex.u_star, 0.05);
    CHECK_NEAR(r2.drho, drho_ex, 0.02);
    CHECK_NEAR(r2.dp, dp_ex, 0.03);
    /* the half-amplitude point lags behind the exact shock (dispersive ringing spreads the
       front); the lag shrinks with resolution */
    CHECK(r.shock_half < r2.shock_half && r2.shock_half < ex.S_R);
    CHECK(fabs(r2.shock_area - ex.S_R) < fabs(r.shock_area - ex.S_R));

    /* standard continuity (eq. 8) with the same eq. 12 runs, but the air next to the contact
       sees the Diesel's masses and is compressed far beyond the exact star state */
    std_mp = shock_tube(0.01, SPH_DENSITY_CONTINUITY, SPH_PGRAD_MULTIPHASE, &ch, "standard");
    CHECK_MSG(std_mp.status == SPH_OK, "standard density: %s", std_mp.error);
    TH_NOTE("100/m, standard continuity + eq. 12: runs; air at the contact %.2f kg/m^3 mean, %.2f "
            "max (exact %.2f, %+.1f %%; particle density %.2f max); shock %.1f m/s, u %.4f, drho "
            "%.4f, dp %.4f",
            std_mp.rho_air, std_mp.rho_air_max, ex.rho_star_L,
            100 * (std_mp.rho_air_max / ex.rho_star_L - 1), r.rho_air_max,
            std_mp.shock_area, std_mp.u_post, std_mp.drho, std_mp.dp);
    CHECK(std_mp.rho_air_max > 1.08 * ex.rho_star_L);
    CHECK(fabs(std_mp.rho_air_max - ex.rho_star_L) > 3 * fabs(r.rho_air_max - ex.rho_star_L));
    /* with the usual p/rho^2 momentum form both densities fail in the first steps, and the
       step says so */
    std_sym = shock_tube(0.01, SPH_DENSITY_CONTINUITY, SPH_PGRAD_SYMMETRIC, NULL, NULL);
    part_sym = shock_tube(0.01, SPH_DENSITY_PARTICLE, SPH_PGRAD_SYMMETRIC, NULL, NULL);
    TH_NOTE("p/rho^2 form: standard density stops at step %llu (%s); particle density at step %llu (%s)",
            std_sym.steps, std_sym.error, part_sym.steps, part_sym.error);
    CHECK(std_sym.status == SPH_ERR_UNSTABLE && std_sym.steps < 20);
    CHECK(part_sym.status == SPH_ERR_UNSTABLE && part_sym.steps < 20);
    save_chart(&ch, "ott_schnetter_shock_tube");
}

/* ---- advection (Ott & Schnetter 2003 sec. 3.1) ----------------------------------------------- */

/* A pressureless gas moves with the prescribed v(x) = x / (1 + q x^2); its exact density follows
   the characteristics: the label X of the particle at x at time t solves
   ln X + q X^2/2 = ln x + q x^2/2 - t, and rho(x, t) = rho0(X) v(X) / v(x). */
static const double ADV_A = 1.5, ADV_X0 = 1, ADV_W = 0.4, ADV_Q = 0.2;
static double adv_v(double x) { return x / (1 + ADV_Q * x * x); }
static double adv_rho0(double x) {
    return ADV_A * x * x * exp(-((x - ADV_X0) / ADV_W) * ((x - ADV_X0) / ADV_W));
}
static double adv_exact(double x, double t) {
    const double c = log(x) + 0.5 * ADV_Q * x * x - t;
    double X = x;
    int it;
    for (it = 0; it < 100; ++it) { /* Newton on the monotone ln X + q X^2/2 */
        const double f = log(X) + 0.5 * ADV_Q * X * X - c, df = 1 / X + ADV_Q * X;
        double Xn = X - f / df;
        if (Xn <= 0) Xn = 0.5 * X;
        if (fabs(Xn - X) < 1e-15 * X) { X = Xn; break; }
        X = Xn;
    }
    return adv_rho0(X) * adv_v(X) / adv_v(x);
}

/* 10 particles per unit length on (xmin, 4), cubic spline h = 0.25, no viscosity, dt = 0.005;
   the host sets v each step (the step keeps the position update). err[s] is the largest
   |rho - exact| at t = 2s (but for the five particles at the left end), peak[s] the largest
   SPH density. Returns the status. */
static sph_status advection(sph_density density, double xmin, double err[5], double peak[5],
                            double exact_peak[5], svg_chart* ch, const char* label) {
    sph_world_def def = sph_world_def_default(1);
    sph_world w;
    sph_real x[64], m[64], r[64];
    const int n = (int)floor((4 - xmin) / 0.1 + 0.5);
    int i, snap, ph;
    sph_status s = SPH_OK;
    def.spacing = (sph_real)0.1;
    def.kernel = SPH_KERNEL_CUBIC;
    def.h_factor = (sph_real)2.5;
    def.solver = SPH_SOLVER_COMPRESSIBLE;
    def.density = density;
    def.alpha = 0;
    def.beta = 0;
    def.delta = 0;
    CHECK(sph_world_init(&w, &def) == SPH_OK);
    ph = add_phase(&w, 1, SPH_EOS_IDEAL_GAS, 0, 0, 0, 0);
    for (i = 0; i < n; ++i) {
        x[i] = (sph_real)(xmin + (i + 0.5) * 0.1);
        r[i] = (sph_real)adv_rho0((double)x[i]);
        m[i] = (sph_real)0.1 * r[i];
    }
    CHECK(sph_add_fluid_ex(&w, ph, (size_t)n, x, NULL, m, r) == SPH_OK);
    for (snap = 0; snap < 5 && s == SPH_OK; ++snap) {
        const double T = 2.0 * snap;
        size_t q;
        while (s == SPH_OK && w.time < T - 1e-9) {
            for (q = 0; q < w.n; ++q) w.v[q] = (sph_real)adv_v((double)w.x[q]);
            s = sph_step_compressible(&w, (sph_real)fmin(0.005, T - w.time));
        }
        if (s != SPH_OK) break;
        err[snap] = peak[snap] = exact_peak[snap] = 0;
        for (q = 0; q < w.n; ++q) {
            const double ex = adv_exact((double)w.x[q], w.time);
            /* the five leftmost particles (started within 2h of the line's end) miss half
               their neighbourhood: excluded from the error */
            if (w.id[q] >= 5) err[snap] = fmax(err[snap], fabs((double)w.rho[q] - ex));
            peak[snap] = fmax(peak[snap], (double)w.rho[q]);
            exact_peak[snap] = fmax(exact_peak[snap], ex);
        }
        if (ch && (snap == 2 || snap == 4)) {
            size_t* o = sorted_by_x(&w);
            double xv[64], rv[64];
            char name[96];
            for (q = 0; q < w.n; ++q) {
                xv[q] = (double)w.x[o[q]];
                rv[q] = (double)w.rho[o[q]];
            }
            snprintf(name, sizeof name, "%s, t = %d", label, (int)T);
            svg_series(ch, xv, rv, w.n, SVG_DOTS, name);
            free(o);
        }
    }
    sph_world_free(&w);
    return s;
}

static void test_advection(void) {
    double ep[5], pp[5], xp[5], es[5], ps[5], xs2[5], ep6[5], pp6[5], xp6[5];
    svg_chart ch;
    sph_status s;
    int k;
    svg_begin(&ch, "Advection (Ott & Schnetter 2003 sec. 3.1): density", "x", "rho");
    for (k = 4; k <= 8; k += 4) { /* exact curves at t = 4 and 8 */
        double xv[1000], rv[1000];
        int q;
        char name[32];
        for (q = 0; q < 1000; ++q) {
            xv[q] = 0.01 + q * 0.01;
            rv[q] = adv_exact(xv[q], k);
        }
        snprintf(name, sizeof name, "exact, t = %d", k);
        svg_series(&ch, xv, rv, 1000, SVG_LINE, name);
    }
    /* the particle density on (0, 4) */
    s = advection(SPH_DENSITY_PARTICLE, 0, ep, pp, xp, &ch, "particle");
    CHECK_MSG(s == SPH_OK, "particle density: status %d", (int)s);
    for (k = 0; k < 5 && s == SPH_OK; ++k) {
        TH_NOTE("particle density, t = %d: max |rho - exact| %.4f, peak %.4f (exact %.4f)", 2 * k,
                ep[k], pp[k], xp[k]);
        /* tracks the exact solution within 2 % of its peak at every snapshot */
        CHECK(ep[k] < 0.02 * xp[k]);
    }
    /* the standard form on the same particles: the thin left tail (rho ~ 1e-3 next to a peak of
       1.5) gets a negative density in the first step, and the step reports it */
    s = advection(SPH_DENSITY_CONTINUITY, 0, es, ps, xs2, NULL, NULL);
    TH_NOTE("standard continuity on (0, 4): status %d", (int)s);
    CHECK(s == SPH_ERR_UNSTABLE);
    /* on (0.6, 4), without the thin tail, both run; the standard form loses the peak */
    s = advection(SPH_DENSITY_CONTINUITY, 0.6, es, ps, xs2, &ch, "standard");
    CHECK_MSG(s == SPH_OK, "standard continuity on (0.6, 4): status %d", (int)s);
    CHECK(advection(SPH_DENSITY_PARTICLE, 0.6, ep6, pp6, xp6, NULL, NULL) == SPH_OK);
    for (k = 1; k < 5 && s == SPH_OK; ++k) {
        TH_NOTE("on (0.6, 4), t = %d: max error standard %.4f, particle %.4f; peak standard %.4f, "
                "particle %.4f, exact %.4f",
                2 * k, es[k], ep6[k], ps[k], pp6[k], xs2[k]);
        CHECK(es[k] > 3 * ep6[k]);
    }
    if (s == SPH_OK) CHECK(ps[4] < 0.9 * xs2[4] && fabs(pp6[4] - xp6[4]) < 0.02 * xp6[4]);
    save_chart(&ch, "ott_schnetter_advection");
}

/* ---- sound wave through a 10:1 interface (Ott & Schnetter 2003 sec. 3.2) --------------------- */

typedef struct wave_result {
    sph_status status;
    double R, T; /* reflected and transmitted pressure amplitudes over the incident one */
} wave_result;

/* One ideal gas (gamma 1.4, p = 1) at density 10 for x < 0 and 1 for x > 0, periodic on
   [-2, 3), 200 particles per unit length, cubic spline with h = 0.1 (20 dx), no viscosity.
   A left-going Gaussian pulse p' = A exp(-((x - 1)/sigma)^2), A = 0.01, sigma = 0.3
   (u' = -p'/(rho c), rho' = p'/c^2, isentropic e) reaches the interface at t = 1/c1 and is
   measured 1.0 later, when both pulses are clear of it: amplitudes from the pulse areas
   sum p' V (the transmitted pulse is shorter by c2/c1), |x| < 0.1 excluded. */
static wave_result sound_wave(sph_density density, svg_chart* ch, const char* label) {
    const double dx = 0.005, g = 1.4, A = 0.01, sig = 0.3, xc = 1, lo = -2, hi = 3;
    const double c1 = sqrt(g / 1.0), c2 = sqrt(g / 10.0);
    const size_t n = (size_t)floor((hi - lo) / dx + 0.5);
    sph_world_def def = sph_world_def_default(1);
    sph_world w;
    wave_result res;
    sph_real *x = (sph_real*)malloc(n * sizeof(sph_real)), *v = (sph_real*)malloc(n * sizeof(sph_real));
    sph_real *m = (sph_real*)malloc(n * sizeof(sph_real)), *r = (sph_real*)malloc(n * sizeof(sph_real));
    double* p0 = (double*)malloc(n * sizeof(double));
    size_t i;
    int gas;
    memset(&res, 0, sizeof res);
    def.spacing = (sph_real)dx;
    def.kernel = SPH_KERNEL_CUBIC;
    def.h_factor = 20;
    def.solver = SPH_SOLVER_COMPRESSIBLE;
    def.density = density;
    def.pressure_grad = SPH_PGRAD_MULTIPHASE;
    def.alpha = 0;
    def.beta = 0;
    def.delta = 0;
    def.periodic[0] = 1;
    def.domain_lo[0] = (sph_real)lo;
    def.domain_hi[0] = (sph_real)hi;
    CHECK(sph_world_init(&w, &def) == SPH_OK);
    gas = add_phase(&w, 1, SPH_EOS_IDEAL_GAS, 0, 0, 1, 0);
    for (i = 0; i < n; ++i) {
        const double xi = lo + ((double)i + 0.5) * dx, rb = xi < 0 ? 10 : 1, cb = sqrt(g / rb);
        const double pp = xi > 0 ? A * exp(-((xi - xc) / sig) * ((xi - xc) / sig)) : 0;
        x[i] = (sph_real)xi;
        r[i] = (sph_real)(rb + pp / (cb * cb));
        m[i] = (sph_real)(dx * (double)r[i]);
        v[i] = (sph_real)(-pp / (rb * cb));
        p0[i] = 1 + pp;
    }
    CHECK(sph_add_fluid_ex(&w, gas, n, x, v, m, r) == SPH_OK);
    for (i = 0; i < n; ++i) w.e[i] = (sph_real)(p0[i] / ((g - 1) * (double)w.rho[i]));
    res.status = sph_advance(&w, (sph_real)(xc / c1 + 1.0));
    if (res.status == SPH_OK) {
        double aL = 0, aR = 0;
        const double area0 = A * sig * sqrt(acos(-1.0));
        for (i = 0; i < w.n; ++i) {
            const double xi = (double)w.x[i], pp = (double)w.p[i] - 1;
            if (fabs(xi) < 0.1) continue;
            if (xi < 0) aL += pp * particle_mass(&w, i) / (double)w.rho[i];
            else aR += pp * particle_mass(&w, i) / (double)w.rho[i];
        }
        res.R = aR / area0;
        res.T = aL / area0 * c1 / c2;
        if (ch) {
            size_t* o = sorted_by_x(&w);
            double* xv = (double*)malloc(w.n * sizeof(double));
            double* pv = (double*)malloc(w.n * sizeof(double));
            for (i = 0; i < w.n; ++i) {
                xv[i] = (double)w.x[o[i]];
                pv[i] = ((double)w.p[o[i]] - 1) / A;
            }
            svg_series(ch, xv, pv, w.n, SVG_DOTS, label);
            free(xv);
            free(pv);
            free(o);
        }
    }
    sph_world_free(&w);
    free(x);
    free(v);
    free(m);
    free(r);
    free(p0);
    return res;
}

static void test_sound_wave(void) {
    const double z = sqrt(10.0); /* Z2/Z1 = rho2 c2 / (rho1 c1) = sqrt(10) at equal pressure */
    const double R = (z - 1) / (z + 1), T = 2 * z / (z + 1);
    const double c1 = sqrt(1.4), c2 = sqrt(0.14);
    svg_chart ch;
    wave_result p, s;
    double xv[1001], pv[1001];
    int k;
    svg_begin(&ch, "Sound pulse through a 10:1 interface (Ott & Schnetter 2003 sec. 3.2), 1.0 after impact",
              "x", "p' / A");
    for (k = 0; k <= 1000; ++k) { /* the acoustic solution: two Gaussians */
        const double x = -2 + 5.0 * k / 1000;
        const double ur = (x - c1 * 1.0) / 0.3, ut = (x + c2 * 1.0) / (0.3 * c2 / c1);
        xv[k] = x;
        pv[k] = x > 0 ? R * exp(-ur * ur) : T * exp(-ut * ut);
    }
    svg_series(&ch, xv, pv, 1001, SVG_LINE, "acoustic (R, T)");
    p = sound_wave(SPH_DENSITY_PARTICLE, &ch, "SPH, particle density");
    s = sound_wave(SPH_DENSITY_CONTINUITY, &ch, "SPH, standard");
    CHECK(p.status == SPH_OK && s.status == SPH_OK);
    TH_NOTE("reflected R: particle %.4f, standard %.4f, acoustic %.4f; transmitted T: particle "
            "%.4f, standard %.4f, acoustic %.4f",
            p.R, s.R, R, p.T, s.T, T);
    /* within a few percent (3 %) with the particle density; standard SPH much further off */
    CHECK_NEAR(p.R, R, 0.03 * R);
    CHECK_NEAR(p.T, T, 0.03 * T);
    CHECK(fabs(s.R - R) > 5 * fabs(p.R - R) && fabs(s.T - T) > 5 * fabs(p.T - T));
    save_chart(&ch, "ott_schnetter_sound_wave");
}

/* ---- Sod's shock tube in 1D, 2D and 3D -------------------------------------------------------- */

/* Sod's problem (Toro test 1: rho 1, p 1 | rho 0.125, p 0.1, gamma 1.4) on a lattice of equal
   spacing dx = 0.01 with the density jump carried by the masses (8:1), which is what the
   particle density is for: x in [-1, 1) periodic (the second jump at +-1 is 0.65 away from
   anything measured at t = 0.2), slabs 8 dx thick in y and z, Wendland C2 with h = 2 dx,
   alpha 1, beta 2.
   The L1 error of the density against the exact solution on [-0.5, 0.5] is the same in every
   dimension (the flow is planar), total energy and momentum are conserved. */
static double sod(int dim, double* energy_drift, double* momentum, sph_status* status) {
    const double dx = 0.01, t_end = 0.2;
    const int nx = 200, ny = dim > 1 ? 8 : 1, nz = dim > 2 ? 8 : 1;
    const size_t n = (size_t)nx * (size_t)ny * (size_t)nz;
    sph_world_def def = sph_world_def_default(dim);
    sph_world w;
    rm_state L = {1, 0, 1, 1.4, 0}, R = {0.125, 0, 0.1, 1.4, 0};
    rm_solution ex;
    sph_real* x = (sph_real*)malloc(n * (size_t)dim * sizeof(sph_real));
    sph_real* m = (sph_real*)malloc(n * sizeof(sph_real));
    sph_real* r = (sph_real*)malloc(n * sizeof(sph_real));
    double E0, P = 0, l1 = 0;
    size_t i = 0;
    int k, gas, ix, iy, iz;
    rm_solve(&L, &R, &ex);
    def.spacing = (sph_real)dx;
    def.solver = SPH_SOLVER_COMPRESSIBLE;
    def.density = SPH_DENSITY_PARTICLE;
    def.pressure_grad = SPH_PGRAD_MULTIPHASE;
    def.kernel = SPH_KERNEL_WENDLAND_C2;
    def.h_factor = 2; /* h = 1.3 dx: L1 0.033 in 1D, and 2D 50 % worse (transverse noise) */
    def.alpha = 1;
    def.beta = 2;
    def.delta = 0;
    for (k = 0; k < dim; ++k) {
        def.gravity[k] = 0;
        def.periodic[k] = 1;
        def.domain_lo[k] = (sph_real)(k == 0 ? -1 : 0);
        def.domain_hi[k] = (sph_real)(k == 0 ? 1 : 8 * dx);
    }
    if (sph_world_init(&w, &def) != SPH_OK) {
        *status = w.status;
        TH_NOTE("%s", w.error);
        free(x);
        free(m);
        free(r);
        return 1;
    }
    gas = add_phase(&w, 1, SPH_EOS_IDEAL_GAS, 0, 0, 1, 0);
    for (iz = 0; iz < nz; ++iz)
        for (iy = 0; iy < ny; ++iy)
            for (ix = 0; ix < nx; ++ix, ++i) {
                const double xi = -1 + (ix + 0.5) * dx;
                x[i * (size_t)dim] = (sph_real)xi;
                if (dim > 1) x[i * (size_t)dim + 1] = (sph_real)((iy + 0.5) * dx);
                if (dim > 2) x[i * (size_t)dim + 2] = (sph_real)((iz + 0.5) * dx);
                r[i] = (sph_real)(xi < 0 ? 1 : 0.125);
                m[i] = (sph_real)((double)r[i] * pow(dx, dim));
            }
    CHECK(sph_add_fluid_ex(&w, gas, n, x, NULL, m, r) == SPH_OK);
    for (i = 0; i < w.n; ++i) /* e = p / ((gamma - 1) rho) */
        w.e[i] = (sph_real)(((double)w.x[i * (size_t)dim] < 0 ? 1 : 0.1) / (0.4 * (double)w.rho[i]));
    E0 = total_energy(&w);
    *status = sph_advance(&w, (sph_real)t_end);
    if (*status != SPH_OK) TH_NOTE("%s", w.error);
    *energy_drift = (total_energy(&w) - E0) / E0;
    for (i = 0; i < w.n; ++i) {
        const double xi = (double)w.x[i * (size_t)dim];
        P += particle_mass(&w, i) * (double)w.v[i * (size_t)dim];
        if (fabs(xi) < 0.5) {
            double rho, u, p;
            int side;
            rm_sample(&ex, xi / w.time, &rho, &u, &p, &side);
            l1 += fabs((double)w.rho[i] - rho) * dx / (double)(ny * nz);
        }
    }
    /* the exact momentum: the pressure difference pushed for t (the two jumps cancel in a
       periodic box, so the total stays 0) */
    *momentum = P / (0.9 * t_end * pow(8 * dx, dim - 1));
    sph_world_free(&w);
    free(x);
    free(m);
    free(r);
    return l1;
}

static double sod_check(int dim) {
    double l1, drift, mom;
    sph_status s;
    l1 = sod(dim, &drift, &mom, &s);
    CHECK_MSG(s == SPH_OK, "%dD Sod: status %d", dim, (int)s);
    TH_NOTE("%dD Sod: L1(rho) on [-0.5, 0.5] = %.5f; energy drift %.1e; total x-momentum %.1e "
            "of the pressure impulse", dim, l1, drift, mom);
    CHECK(fabs(drift) < (sizeof(sph_real) == 4 ? 1e-5 : 1e-12));
    CHECK(fabs(mom) < (sizeof(sph_real) == 4 ? 1e-4 : 1e-10));
    /* a regression bound: 1.75 % of the unit density jump in 1D is what this resolution gives */
    CHECK(l1 < 0.025);
    return l1;
}

static void test_sod_1d_2d(void) {
    const double a = sod_check(1), b = sod_check(2);
    CHECK(fabs(b - a) < 0.25 * a); /* planar: the dimension must not matter */
}

static void test_sod_3d(void) {
    const double a = sod_check(1), c = sod_check(3);
    CHECK(fabs(c - a) < 0.25 * a);
}

/* ---- equations of state: validation and the other solvers ----------------------------------- */

static void test_gas_phase_rules(void) {
    sph_world_def def = sph_world_def_default(1);
    sph_world w;
    const sph_real lo[1] = {0}, hi[1] = {1};
    sph_real x0;
    int gas;
    def.spacing = (sph_real)0.05;
    CHECK(sph_world_init(&w, &def) == SPH_OK);
    /* an ideal gas's sound speed follows from its state */
    CHECK(add_phase(&w, 1, SPH_EOS_IDEAL_GAS, 0, 3, 1, 0) < 0);
    CHECK(w.status == SPH_ERR_ARG && strstr(w.error, "sound_speed"));
    CHECK(add_phase(&w, 1, SPH_EOS_IDEAL_GAS, 0, 0, -1, 0) < 0);
    CHECK(strstr(w.error, "back_pressure") != NULL);
    CHECK(add_phase(&w, 1, SPH_EOS_IDEAL_GAS, 1, 0, 0, 0) < 0);
    CHECK(strstr(w.error, "gamma") != NULL);
    /* a stiffened gas needs c0, and p_inf = rho0 c0^2/gamma - p_b must not be negative */
    CHECK(add_phase(&w, 1000, SPH_EOS_STIFFENED_GAS, 0, 0, 0, 0) < 0);
    CHECK(strstr(w.error, "sound_speed") != NULL);
    CHECK(add_phase(&w, 1, SPH_EOS_STIFFENED_GAS, 0, 1, 10, 0) < 0);
    CHECK(strstr(w.error, "p_inf") != NULL);
    CHECK(w.nphase == 0 && w.e == NULL);
    gas = add_phase(&w, 1, SPH_EOS_IDEAL_GAS, 0, 0, 1, 0);
    CHECK(gas == 0 && w.e != NULL);
    CHECK_NEAR((double)w.phases[gas].sound_speed, sqrt(1.4), 1e-6);
    CHECK(sph_fill_box(&w, gas, lo, hi) == SPH_OK);
    { /* per-particle masses and densities are checked, and a rejection adds nothing */
        const sph_real px[1] = {(sph_real)0.5}, bad_m[1] = {-1}, bad_r[1] = {0};
        const size_t n0 = w.n;
        CHECK(sph_add_fluid_ex(&w, gas, 1, px, NULL, bad_m, NULL) == SPH_ERR_ARG);
        CHECK(strstr(w.error, "sph_add_fluid_ex: mass") != NULL);
        CHECK(sph_add_fluid_ex(&w, gas, 1, px, NULL, NULL, bad_r) == SPH_ERR_ARG);
        CHECK(strstr(w.error, "density") != NULL && w.n == n0);
    }
    /* particles start at the back pressure: e = p / ((gamma - 1) rho) */
    CHECK_NEAR((double)w.e[3], 1 / 0.4, 1e-6);
    /* the other solvers refuse a gas phase and leave the world as it was */
    x0 = w.x[3];
    CHECK(sph_step_wcsph(&w, (sph_real)1e-3) == SPH_ERR_ARG);
    CHECK(strstr(w.error, "sph_step_compressible") != NULL);
    CHECK(sph_step_iisph(&w, (sph_real)1e-3) == SPH_ERR_ARG);
    CHECK(sph_step_pcisph(&w, (sph_real)1e-3) == SPH_ERR_ARG);
    CHECK(w.time == 0 && w.steps == 0 && w.x[3] == x0);
    /* a non-finite energy is bad input; an energy below -p_inf after a step is a blow-up */
    w.e[3] = (sph_real)NAN;
    CHECK(sph_step_compressible(&w, (sph_real)1e-3) == SPH_ERR_ARG && w.steps == 0);
    w.e[3] = (sph_real)-1;
    CHECK(sph_step_compressible(&w, (sph_real)1e-3) == SPH_ERR_UNSTABLE);
    CHECK(strstr(w.error, "internal energy") != NULL && w.error_index >= 0);
    sph_world_free(&w);
}

/* ---- a 2D interface at rest, 1000:1 ------------------------------------------------------------ */

typedef struct rest_result {
    sph_status status;
    unsigned long long steps;
    double t;
    double vmax[2];   /* largest speed seen in water and air over the run [m/s]             */
    double vlate[2];  /* the same from t = 0.25 s on, after the start-up transient          */
    double t_break;   /* first sample at which it is no longer at rest (check_rest's bounds),
                         or the end time [s]; the run stops there                          */
    double rise;      /* highest water particle minus its start [m]                          */
    double sink;      /* start minus the lowest air particle [m]                             */
    char error[SPH_ERROR_SIZE];
} rest_result;

/* Adds one particle's sample to r: its speed v (to the late maximum too when late), and how far
   a water particle rose above, or an air particle sank below, the interface rows' start (the
   interface at height Hw, rows half a spacing dy either side). */
/* The end of a run: steps, time and message of w into r, and w freed. */
static void rest_finish(rest_result* r, sph_world* w) {
    r->steps = (unsigned long long)w->steps;
    r->t = w->time;
    snprintf(r->error, sizeof r->error, "%s", w->error);
    sph_world_free(w);
}

static void rest_sample(rest_result* r, int air, double y, double v, int late, double Hw, double dy) {
    if (v > r->vmax[air]) r->vmax[air] = v;
    if (late && v > r->vlate[air]) r->vlate[air] = v;
    if (!air && y - (Hw - 0.5 * dy) > r->rise) r->rise = y - (Hw - 0.5 * dy);
    if (air && (Hw + 0.5 * dy) - y > r->sink) r->sink = (Hw + 0.5 * dy) - y;
}

/* Water (1000 kg/m^3) on [0, 0.5), air (1 kg/m^3) on [0.5, 1) in a tank 1 m wide, periodic in x,
   with walls at the floor and the lid, gravity 9.81 m/s^2, dx = 0.025 m, particles on a
   hexagonal lattice (rows dx sqrt(3)/2 apart, stretched to fit). Decisions, measured:
   - Both phases are Tait fluids (air with gamma 1.4, Colagrossi & Landrini 2003) with a common
     background pressure of 2000 Pa: without it the water's top row goes into tension (its
     pressure fluctuates by rho c^2 drho/rho = 200 Pa per 1e-4, the air carries 5 Pa) and the
     interface breaks up after 0.2 s.
   - With a background pressure every pair repels, and a square lattice is then shear-unstable
     (it collapses towards the hexagonal packing in 0.1 s, even without gravity); the hexagonal
     lattice is the stable one.
   - The air's stiffness rho c^2 must exceed the background pressure by about 10: c_air = 150
     m/s (rho c^2 = 22500 Pa); water c = 10 sqrt(2 g H) = 44.3 m/s.
   - alpha = 0.2: with 0.05 a slow shear mode of the air grows over a second and breaks the
     interface at t = 1.2 s. With 0.2 it holds for about 2 s and then breaks up the same way
     (speeds grow from 0.005 m/s at 1.3 s to 0.02 at 2.0 s, then the water sprays into the air
     at 2.2 s): a limitation, measured by the long test.
   Sampled every 0.025 s. */
/* At rest: once the start-up transient (the air's acoustic ringing after the hydrostatic
   initialisation, up to 0.4 m/s in the first 0.03 s) has decayed, spurious speeds stay below 5 %
   of sqrt(g H), the free-fall speed over the water depth; the interface rows stay within half a
   spacing of their start. */
static int rest_holds(const rest_result* r) {
    const double U = sqrt(9.81 * 0.5);
    return r->status == SPH_OK && r->vlate[0] < 0.05 * U && r->vlate[1] < 0.05 * U &&
           r->rise < 0.0125 && r->sink < 0.0125;
}

/* The step of the 1000:1 water/air scenes below (Ott & Schnetter 2003's compressible step):
   spacing dx, the density form and pressure gradient given, artificial viscosity 0.2,
   delta-SPH 0.1, gravity g downwards. */
static sph_world_def water_air_def(double dx, sph_density density, sph_pressure_grad pgrad,
                                   double g) {
    sph_world_def def = sph_world_def_default(2);
    def.spacing = (sph_real)dx;
    def.solver = SPH_SOLVER_COMPRESSIBLE;
    def.density = density;
    def.pressure_grad = pgrad;
    def.alpha = (sph_real)0.2;
    def.delta = (sph_real)0.1;
    def.gravity[1] = (sph_real)-g;
    return def;
}

static rest_result interface_at_rest(sph_density density, double t_end) {
    const double dx = 0.025, Hw = 0.5, g = 9.81, cw = 10 * sqrt(2 * g * 1.0), pb = 2000;
    const int nx = 40, ny = (int)floor(Hw / (dx * 0.8660254) + 0.5); /* rows per phase */
    const double dy = Hw / ny;
    sph_world_def def = water_air_def(dx, density, SPH_PGRAD_INTERFACE, g);
    sph_world w;
    rest_result r;
    sph_real lo[2] = {0, 0}, top[2] = {1, 1};
    sph_real* x = (sph_real*)malloc((size_t)(nx * ny) * 2 * sizeof(sph_real));
    sph_real* m = (sph_real*)malloc((size_t)(nx * ny) * sizeof(sph_real));
    sph_real* rho = (sph_real*)malloc((size_t)(nx * ny) * sizeof(sph_real));
    int ph, idx[2], k;
    memset(&r, 0, sizeof r);
    def.periodic[0] = 1;
    def.domain_lo[0] = 0;
    def.domain_hi[0] = 1;
    def.domain_lo[1] = -1;
    def.domain_hi[1] = 2;
    CHECK(sph_world_init(&w, &def) == SPH_OK);
    idx[0] = add_phase(&w, 1000, SPH_EOS_TAIT, 0, (sph_real)cw, (sph_real)pb, 0);
    idx[1] = add_phase(&w, 1, SPH_EOS_TAIT, (sph_real)1.4, 150, (sph_real)pb, 0);
    for (ph = 0; ph < 2; ++ph) {
        const double rho0 = ph ? 1 : 1000;
        size_t q = 0;
        int ix, jy;
        for (jy = 0; jy < ny; ++jy)
            for (ix = 0; ix < nx; ++ix, ++q) {
                const int row = jy + ph * ny;
                x[2 * q] = (sph_real)((ix + 0.25 + 0.5 * (row & 1)) * dx);
                x[2 * q + 1] = (sph_real)(ph * Hw + (jy + 0.5) * dy);
                m[q] = (sph_real)(rho0 * dx * dy);
                rho[q] = (sph_real)rho0;
            }
        CHECK(sph_add_fluid_ex(&w, idx[ph], q, x, NULL, m, rho) == SPH_OK);
    }
    CHECK(sph_add_wall_box(&w, lo, top, 0, SPH_FACE_XMIN | SPH_FACE_XMAX) == SPH_OK);
    CHECK(sph_set_hydrostatic(&w) == SPH_OK);
    r.status = SPH_OK;
    r.t_break = t_end;
    for (k = 1; k <= (int)floor(t_end / 0.025 + 0.5) && r.status == SPH_OK; ++k) {
        size_t i;
        r.status = sph_advance(&w, (sph_real)0.025);
        for (i = 0; i < w.n; ++i) {
            const double y = (double)w.x[2 * i + 1];
            const double v = hypot((double)w.v[2 * i], (double)w.v[2 * i + 1]);
            rest_sample(&r, w.phase[i] == idx[1], y, v, k > 10, Hw, dy);
        }
        if (!rest_holds(&r)) {
            r.t_break = w.time;
            break;
        }
    }
    rest_finish(&r, &w);
    free(x);
    free(m);
    free(rho);
    return r;
}

static void report_rest(const char* name, const rest_result* r) {
    TH_NOTE("%s: status %d after %llu steps, t = %.3f s; max speed water %.4f m/s, air %.4f m/s "
            "(from 0.25 s: %.4f, %.4f); water rose %.4f m, air sank %.4f m; at rest until %.3f s%s%s",
            name, (int)r->status, r->steps, r->t, r->vmax[0], r->vmax[1], r->vlate[0],
            r->vlate[1], r->rise, r->sink, r->t_break,
            r->status ? ": " : "", r->error);
}

static void check_rest(const rest_result* r) {
    const double U = sqrt(9.81 * 0.5);
    CHECK(r->status == SPH_OK);
    CHECK(r->vlate[0] < 0.05 * U && r->vlate[1] < 0.05 * U);
    CHECK(r->rise < 0.0125 && r->sink < 0.0125);
}

static void test_interface_at_rest(void) {
    rest_result p = interface_at_rest(SPH_DENSITY_PARTICLE, 0.5);
    rest_result s = interface_at_rest(SPH_DENSITY_CONTINUITY, 0.5);
    report_rest("particle density, 0.5 s", &p);
    report_rest("standard continuity", &s);
    check_rest(&p);
    /* the standard form sees 1000 times the air's mass across the interface: the air there is
       compressed eightfold in a few steps, and the step reports it */
    CHECK(s.status == SPH_ERR_UNSTABLE && s.steps < 20);
}

/* Up to 3 s: at rest for 1.5 s at least (it breaks up near 2.2 s, reported). */
static void test_interface_at_rest_long(void) {
    rest_result p = interface_at_rest(SPH_DENSITY_PARTICLE, 3.0);
    report_rest("particle density, up to 3 s", &p);
    CHECK(p.t_break >= 1.5);
}

/* ---- a 1000:1 interface touching side walls (contact line) ------------------------------------ */

/* The interface above in a closed box, built as a user would: sph_fill_box puts water
   (1000 kg/m^3) on [0, 1] x [0, 0.5] and air (1 kg/m^3) on [0, 1] x [0.5, 1] on the square
   lattice at dx = 0.025 m, and sph_add_wall_box closes the box with wall particles on the same
   lattice; the phases, the background pressure and the step's settings as above. (The
   hexagonal lattice of the periodic test does not fit a square wall lattice: its rows sit 0.75
   and 1.25 dx from the first wall layer, and the air, whose background pressure is 2000 times
   its rho g per metre, is thrown about within 0.05 s.) Every wall particle stands for the phase
   of its nearest fluid particle (sph__phase_walls in sph.h). */
static sph_status contact_line_scene(sph_world* w, int* air, sph_pressure_grad pgrad) {
    const double dx = 0.025, g = 9.81, cw = 10 * sqrt(2 * g * 1.0), pb = 2000;
    sph_world_def def = water_air_def(dx, SPH_DENSITY_PARTICLE, pgrad, g);
    sph_real lo[2] = {0, 0}, mid[2] = {1, (sph_real)0.5}, mid0[2] = {0, (sph_real)0.5},
             top[2] = {1, 1};
    int water;
    if (sph_world_init(w, &def) != SPH_OK) return w->status;
    water = add_phase(w, 1000, SPH_EOS_TAIT, 0, (sph_real)cw, (sph_real)pb, 0);
    *air = add_phase(w, 1, SPH_EOS_TAIT, (sph_real)1.4, 150, (sph_real)pb, 0);
    if (water < 0 || *air < 0) return w->status;
    if (sph_fill_box(w, water, lo, mid) != SPH_OK || sph_fill_box(w, *air, mid0, top) != SPH_OK ||
        sph_add_wall_box(w, lo, top, 0, 0) != SPH_OK)
        return w->status;
    return sph_set_hydrostatic(w);
}

/* The rows next to the contact line at the start, where sph_set_hydrostatic leaves every row in
   the same state across the box: a flat wall that acts as the fluid beside it would (Adami, Hu &
   Adams 2012: walls as a continuation of the fluid) gives the particles in the wall column the
   accelerations of their rows in the middle of the box. Returns the largest difference over
   the three rows either side of the interface, both walls, from one step of 1e-6 s, relative to
   the row's acceleration or g, whichever is larger (sph_set_hydrostatic's rows are not the
   discrete equilibrium: with SPH_PGRAD_VOLUME the air's bottom row starts at 2633 m/s^2, as its
   kernel reaches the water's rows, 122 Pa higher). With
   one wall pressure per phase extrapolated from that phase alone, the water's extrapolation
   reaches up the wall beside the air (rho_w g per metre where the air has rho_a g) and the air's
   down the wall beside the water: measured (SPH_PGRAD_INTERFACE) 3.66 m/s^2, 0.37 of the row's
   acceleration, on the air at the corner, which pulled it into the wall. */
static double contact_line_force_defect(sph_pressure_grad pgrad) {
    sph_world w;
    int air;
    double dev = -1;
    size_t i, j;
    const double dt = 1e-6, dx = 0.025;
    if (contact_line_scene(&w, &air, pgrad) != SPH_OK || sph_step(&w, (sph_real)dt) != SPH_OK) {
        TH_NOTE("contact line: %s", w.error);
        sph_world_free(&w);
        return dev;
    }
    dev = 0;
    for (i = 0; i < w.n; ++i) {
        const double x = (double)w.x[2 * i], y = (double)w.x[2 * i + 1];
        if (fabs(y - 0.5) > 3 * dx || (x > dx && x < 1 - dx)) continue;
        for (j = 0; j < w.n; ++j) /* the same row in the middle of the box */
            if (fabs((double)w.x[2 * j + 1] - y) < 0.1 * dx && fabs((double)w.x[2 * j] - 0.5125) < 0.1 * dx) {
                const double ax = (double)w.v[2 * i] / dt, ay = (double)w.v[2 * i + 1] / dt;
                const double bx = (double)w.v[2 * j] / dt, by = (double)w.v[2 * j + 1] / dt;
                dev = fmax(dev, hypot(fabs(ax) - fabs(bx), ay - by) / fmax(9.81, hypot(bx, by)));
            }
    }
    sph_world_free(&w);
    return dev;
}

/* Runs the scene until t_end in frames of 0.025 s through sph_advance; the quantities of
   rest_result, the late speeds from t_late on. Also counts frames that returned SPH_OK with a
   fluid particle outside the box (more than half a spacing past a wall's face): escapes. */
static rest_result contact_line_run(sph_pressure_grad pgrad, double t_end, double t_late,
                                    int* escapes) {
    const double dx = 0.025, Hw = 0.5, U = sqrt(9.81 * 0.5);
    sph_world w;
    rest_result r;
    int air, k;
    memset(&r, 0, sizeof r);
    *escapes = 0;
    r.status = contact_line_scene(&w, &air, pgrad);
    r.t_break = t_end;
    for (k = 1; k <= (int)floor(t_end / 0.025 + 0.5) && r.status == SPH_OK; ++k) {
        size_t i;
        double out = 0;
        r.status = sph_advance(&w, (sph_real)0.025);
        for (i = 0; i < w.n; ++i) {
            const double x = (double)w.x[2 * i], y = (double)w.x[2 * i + 1];
            const double v = hypot((double)w.v[2 * i], (double)w.v[2 * i + 1]);
            rest_sample(&r, w.phase[i] == air, y, v, w.time > t_late - 1e-9, Hw, dx);
            out = fmax(out, fmax(fmax(-x, x - 1), fmax(-y, y - 1)));
        }
        if (r.status == SPH_OK && out > 0.5 * dx) ++*escapes;
        /* at rest: the water below 5 % of sqrt(g H), the interface rows within 1 dx (the
           air's own speed is reported: see test_contact_line) */
        if (r.status != SPH_OK || r.vlate[0] >= 0.05 * U || r.rise >= dx || r.sink >= dx) {
            r.t_break = w.time;
            break;
        }
    }
    rest_finish(&r, &w);
    return r;
}

/* The scene with the momentum equation of the particle density (SPH_PGRAD_VOLUME, see sph.h):
   the force balance at the contact line at the start (contact_line_force_defect: measured
   2.8e-5 of the row's acceleration m/s^2; with the interface form 2.4e-4, float 0.16, and 3.66 m/s^2 before each wall
   particle stood for one phase), then 0.5 s through sph_advance: no frame returns SPH_OK with a
   particle outside, no interface row moves by 1 dx, and from 0.3 s on the water stays below
   5 % of sqrt(g H). Measured: water 0.014 sqrt(g H) from 0.3 s on, rise 0.11 dx, sink 0.26 dx. The air's speed is
   reported, not asserted: 0.64 sqrt(g H) from 0.3 s on (its rows rearrange: see the long test). */
static void test_contact_line(void) {
    const double dev = contact_line_force_defect(SPH_PGRAD_VOLUME);
    const double U = sqrt(9.81 * 0.5);
    int escapes;
    rest_result r;
    TH_NOTE("contact line, first step: largest difference from the row's acceleration in the "
            "middle %.3g of it", dev);
    /* the air's pair terms are each about p_b / (rho_a dx) = 8e4 m/s^2 and cancel to the row's
       acceleration: float's round-off alone leaves 0.0085 of it */
    CHECK(dev >= 0 && dev < (sizeof(sph_real) == 8 ? 1e-3 : 0.05));
    r = contact_line_run(SPH_PGRAD_VOLUME, 0.5, 0.3, &escapes);
    TH_NOTE("contact line, side walls: status %d, t = %.3f s; from 0.3 s water %.4f, air %.4f of "
            "sqrt(g H) (air %.4f over the run); water rose %.2f dx, air sank %.2f dx%s%s",
            (int)r.status, r.t, r.vlate[0] / U, r.vlate[1] / U, r.vmax[1] / U, r.rise / 0.025,
            r.sink / 0.025, r.status ? ": " : "", r.error);
    CHECK_EQ_INT(escapes, 0);
    CHECK_EQ_INT(r.status, SPH_OK);
    CHECK(r.t_break >= 0.5 - 1e-9);
}

/* 10 s at rest (make validate), the criteria above from 0.5 s on. Measured: at rest for the 10 s, water at most 0.018 sqrt(g H) from 0.5 s on,
   rise 0.62 dx, sink 0.34 dx, no particle outside (473 s on a loaded host). The air reaches 0.28
   sqrt(g H), reported, not asserted: the square lattice of sph_fill_box under a background
   pressure 0.09 of the air's rho c^2 rearranges now and then, walls or not. With the interface form (SPH_PGRAD_INTERFACE) the
   interface breaks up after 1.5 s (1.575 s before each wall particle stood for one phase), as
   the periodic test above does after about 2 s (a zig-zag of the water's top row). */
static void test_contact_line_long(void) {
    const double U = sqrt(9.81 * 0.5);
    int escapes;
    rest_result r = contact_line_run(SPH_PGRAD_VOLUME, 10.0, 0.5, &escapes);
    TH_NOTE("contact line, side walls, 10 s: status %d, at rest until %.3f s; from 0.5 s water "
            "%.4f, air %.4f of sqrt(g H); water rose %.2f dx, air sank %.2f dx%s%s",
            (int)r.status, r.t_break, r.vlate[0] / U, r.vlate[1] / U, r.rise / 0.025,
            r.sink / 0.025, r.status ? ": " : "", r.error);
    CHECK_EQ_INT(escapes, 0);
    CHECK(r.t_break >= 10.0 - 1e-9);
}

/* ---- a 1000:1 dam break ---------------------------------------------------------------------- */

typedef struct dam_result {
    sph_status status;
    double t;          /* reached, in units of sqrt(a / (2 g))                                */
    double front[31];  /* Martin & Moyce's Z = (front + dx/2) / a at T = 0, 0.1, ... 3         */
    double vw, va;     /* largest water and air speeds over the run / sqrt(2 g a)              */
    double far;        /* largest distance of a water particle from its nearest water
                          neighbour over the run [dx]                                          */
    int escapes;       /* frames that returned SPH_OK with a particle outside the tank         */
} dam_result;

/* Martin & Moyce's column (a wide, 2a high, a = 0.2 m, 10 particles per a) at the left of a
   closed tank 5a x 3a, in the compressible step with the settings of the interface at rest
   above (water c = 10 sqrt(2 g 2a), background pressure 2000 Pa): with air (1 kg/m^3, Tait
   gamma 1.4, c 150 m/s) filling the rest of the tank, or alone (then without background
   pressure). Frames of 0.1 sqrt(a / (2 g)) through sph_advance up to T = 3. */
static dam_result dam_1000_to_1(int with_air, sph_pressure_grad pgrad) {
    const double a = 0.2, g = 9.81, dx = a / 10, ts = sqrt(a / (2 * g)), U = sqrt(2 * g * a);
    const double pb = with_air ? 2000 : 0;
    sph_world_def def = water_air_def(dx, SPH_DENSITY_PARTICLE, pgrad, g);
    sph_world w;
    dam_result r;
    sph_real lo[2] = {0, 0}, col[2], tank[2], alo[2], ahi[2];
    int k, air = -1;
    memset(&r, 0, sizeof r);
    col[0] = (sph_real)a; col[1] = (sph_real)(2 * a);
    tank[0] = (sph_real)(5 * a); tank[1] = (sph_real)(3 * a);
    r.status = sph_world_init(&w, &def);
    if (r.status != SPH_OK) return r;
    add_phase(&w, 1000, SPH_EOS_TAIT, 0, 10 * sqrt(2 * g * 2 * a), pb, 0);
    if (with_air) air = add_phase(&w, 1, SPH_EOS_TAIT, 1.4, 150, pb, 0);
    r.status = sph_fill_box(&w, 0, lo, col);
    if (with_air && r.status == SPH_OK) {
        alo[0] = (sph_real)a; alo[1] = 0; ahi[0] = tank[0]; ahi[1] = (sph_real)(2 * a);
        r.status = sph_fill_box(&w, air, alo, ahi);
        alo[0] = 0; alo[1] = (sph_real)(2 * a); ahi[1] = tank[1];
        if (r.status == SPH_OK) r.status = sph_fill_box(&w, air, alo, ahi);
    }
    if (r.status == SPH_OK) r.status = sph_add_wall_box(&w, lo, tank, 0, 0);
    if (r.status == SPH_OK) r.status = sph_set_hydrostatic(&w);
    r.front[0] = 1 + 0.5 * dx / a;
    for (k = 1; k <= 30 && r.status == SPH_OK; ++k) {
        size_t i, j;
        double front = 0, out = 0;
        r.status = sph_advance(&w, (sph_real)(0.1 * ts));
        for (i = 0; i < w.n; ++i) {
            const double x = (double)w.x[2 * i], y = (double)w.x[2 * i + 1];
            const double v = hypot((double)w.v[2 * i], (double)w.v[2 * i + 1]) / U;
            out = fmax(out, fmax(fmax(-x, x - 5 * a), fmax(-y, y - 3 * a)));
            if (w.phase[i] == air) {
                r.va = fmax(r.va, v);
                continue;
            }
            r.vw = fmax(r.vw, v);
            if (y < 0.1 * a && x > front) front = x;
            {
                double near = 1e30;
                for (j = 0; j < w.n; ++j)
                    if (j != i && w.phase[j] != air)
                        near = fmin(near, hypot((double)w.x[2 * j] - x, (double)w.x[2 * j + 1] - y));
                r.far = fmax(r.far, near / dx);
            }
        }
        if (r.status == SPH_OK && out > 0.5 * dx) ++r.escapes;
        r.front[k] = (front + 0.5 * dx) / a;
        r.t = w.time / ts;
    }
    sph_world_free(&w);
    return r;
}

/* The dam break of water in air against the same column alone (make validate). At 1000:1 the
   air's drag and buoyancy change the water's motion by about rho_air/rho_water = 0.1 %, so
   the fronts must agree to the front's own resolution, one spacing (0.1 a), at every sample up
   to T = 3. No breakup: no water particle ever farther than 2 dx from its nearest water
   neighbour (the column alone: 1.16 dx), no particle outside. No air jets: the air never faster
   than twice the largest water speed of the column alone (potential flow around a moving body
   reaches twice its speed, at a cylinder's flanks). Measured: front within 0.041 a (RMS 0.023 a); farthest water particle 1.16 dx;
   air 2.21, water 1.36 (alone 1.40) sqrt(2 g a). With the interface form
   the front ran 0.2-0.3 a behind, then (after each wall particle stood for one phase) a film
   0.32 a ahead at T = 3, the air reached 2.5-3.3 sqrt(2 g a) and water particles separated by
   2.6-3.8 dx. */
static void test_dam_break_1000_to_1(void) {
    const dam_result one = dam_1000_to_1(0, SPH_PGRAD_VOLUME);
    const dam_result two = dam_1000_to_1(1, SPH_PGRAD_VOLUME);
    double dev = 0, rms = 0;
    int k;
    for (k = 0; k <= 30; ++k) {
        const double d = two.front[k] - one.front[k];
        dev = fmax(dev, fabs(d));
        rms += d * d;
    }
    rms = sqrt(rms / 31);
    TH_NOTE("1000:1 dam break to T = %.2f (alone %.2f): front Z %.3f / %.3f at T = 1, %.3f / %.3f "
            "at T = 2, %.3f / %.3f at T = 3 (with air / alone), largest difference %.3f a, RMS "
            "%.3f a; largest speeds / sqrt(2 g a): water %.2f (alone %.2f), air %.2f; farthest "
            "water particle from the water %.2f dx (alone %.2f); escapes %d, %d",
            two.t, one.t, two.front[10], one.front[10], two.front[20], one.front[20],
            two.front[30], one.front[30], dev, rms, two.vw, one.vw, two.va, two.far, one.far,
            two.escapes, one.escapes);
    CHECK_EQ_INT(one.status, SPH_OK);
    CHECK_EQ_INT(two.status, SPH_OK);
    CHECK_EQ_INT(one.escapes + two.escapes, 0);
    CHECK_LT(dev, 0.1);
    CHECK_LT(two.far, 2.0);
    CHECK_LT(two.va, 2 * one.vw);
}

/* ---- determinism --------------------------------------------------------------------------- */

/* A 2D blast in a periodic box of ideal gas over a water-like stiffened gas (100:1), with the
   particle density, energy and per-particle sound speeds: 1 and 2 threads give the same bits. */
static void test_compressible_determinism(void) {
#ifndef _OPENMP
    TH_SKIP("built without OpenMP");
#else
    sph_world a, b;
    int t, s;
    for (t = 1; t <= 2; ++t) {
        sph_world* w = t == 1 ? &a : &b;
        sph_world_def def = sph_world_def_default(2);
        const sph_real lo[2] = {0, 0}, mid[2] = {1, (sph_real)0.5}, mid0[2] = {0, (sph_real)0.5}, hi[2] = {1, 1};
        int gas, liq, k;
        size_t i;
        omp_set_num_threads(t);
        def.spacing = (sph_real)0.02;
        def.solver = SPH_SOLVER_COMPRESSIBLE;
        def.density = SPH_DENSITY_PARTICLE;
        def.pressure_grad = SPH_PGRAD_MULTIPHASE;
        def.alpha = 1;
        def.beta = 2;
        def.gravity[1] = 0;
        for (k = 0; k < 2; ++k) {
            def.periodic[k] = 1;
            def.domain_lo[k] = 0;
            def.domain_hi[k] = 1;
        }
        CHECK_EQ_INT(sph_world_init(w, &def), SPH_OK);
        liq = add_phase(w, 100, SPH_EOS_STIFFENED_GAS, 0, 10, 1, 0);
        gas = add_phase(w, 1, SPH_EOS_IDEAL_GAS, 0, 0, 1, 0);
        CHECK_EQ_INT(sph_fill_box(w, liq, lo, mid), SPH_OK);
        CHECK_EQ_INT(sph_fill_box(w, gas, mid0, hi), SPH_OK);
        for (i = 0; i < w->n; ++i) { /* ten times the pressure in a disc in the gas */
            const double dx = (double)w->x[2 * i] - 0.5, dy = (double)w->x[2 * i + 1] - 0.75;
            if (w->phase[i] == gas && dx * dx + dy * dy < 0.01) w->e[i] *= 10;
        }
        for (s = 0; s < 40; ++s) CHECK_EQ_INT(sph_step(w, sph_stable_dt(w, SPH_SOLVER_COMPRESSIBLE)), SPH_OK);
    }
    CHECK(a.n == b.n && memcmp(a.x, b.x, a.n * 2 * sizeof(sph_real)) == 0);
    CHECK(memcmp(a.v, b.v, a.n * 2 * sizeof(sph_real)) == 0);
    CHECK(memcmp(a.rho, b.rho, a.n * sizeof(sph_real)) == 0);
    CHECK(memcmp(a.e, b.e, a.n * sizeof(sph_real)) == 0);
    CHECK(a.time == b.time);
    sph_world_free(&a);
    sph_world_free(&b);
    omp_set_num_threads(omp_get_num_procs());
#endif
}

const th_test tests_compressible[] = {
    {"compressible/riemann_toro", test_riemann_toro},
    {"compressible/riemann_air_diesel", test_riemann_diesel},
    {"compressible/gas_phase_rules", test_gas_phase_rules},
    {"compressible/sod_1d_2d", test_sod_1d_2d},
    {"compressible/advection", test_advection},
    {"compressible/sound_wave_10_to_1", test_sound_wave},
    {"compressible/shock_tube_air_diesel", test_shock_tube},
    {"compressible/interface_at_rest_1000_to_1", test_interface_at_rest},
    {"compressible/contact_line_1000_to_1", test_contact_line},
    {"compressible/determinism_1_vs_2_threads", test_compressible_determinism},
    {0, 0}};

const th_test tests_compressible_long[] = {
    {"compressible/sod_3d", test_sod_3d},
    {"compressible/interface_at_rest_how_long", test_interface_at_rest_long},
    {"compressible-long/contact_line_10s", test_contact_line_long},
    {"compressible-long/dam_break_1000_to_1", test_dam_break_1000_to_1},
    {0, 0}};
