/* bench/pareto.c - speed against accuracy (issue 7): for every solver (WCSPH, PCISPH original,
   PCISPH enhanced, IISPH) on the validation scenes, the error against reference data and the
   CPU seconds it took, over resolutions and time-step factors; the Pareto front per solver; and
   stability maps (the largest stable time-step factor per solver and scene, the density-ratio
   limit per density formulation).

   Scenes and metrics (reference data from the works named):
     dam break    Martin & Moyce 1952 (scene_dam_break, a = 0.1 m): RMS over the table's points
                  with T <= 3 of (Z_sph - Z) / Z, Z = front / a at T = t sqrt(2 g / a).
     hydrostatic  Adami, Hu & Adams 2012 sec. 6 (scene_hydrostatic, 1 m wide, H = 0.5 m deep):
                  mean |p - rho0 g (H - y)| / (rho0 g H) with p averaged per particle over
                  t in [HS_SETTLE, HS_END], over particles at least one kernel support (2.6 dx)
                  from the walls and the surface (tests/test_wcsph.c's "pressure error mean").
     cavity       lid-driven cavity, Re = 100 (scene_cavity), Ghia, Ghia & Shin 1982: RMS of
                  (u - u_Ghia) on x = 0.5 and (v - v_Ghia) on y = 0.5 over the 15 interior
                  points of each table, [m/s] with U = 1 m/s, velocities sampled by a Shepard
                  kernel average of the fluid particles and averaged over the last CAV_AVG s
                  of a run to t = 10 s (6 s in the quick mode).
   Resolutions: dam break 10, 14, 20, 28 particles per a; tank 10, 14, 20, 28 over the depth;
   cavity 20, 30, 40 over the side (quick: the first two, the first one). Factors: 0.5, 1, 2, 4
   (cavity 1, 2, 4; quick 1, 4).
   Time step: dt = factor * sph_stable_dt(w, solver) at every step (the library's own stable
   step: the acoustic CFL for WCSPH, cfl_velocity dx / |v| for the incompressible solvers, and the
   viscous and force limits), cut to land on the sampling times. CPU seconds are process CPU
   time (clock()) from building the scene to the metric; runs are single-threaded.
   A run whose step returns an error is recorded with status "unstable" (SPH_ERR_UNSTABLE) or the
   status name, and no error value.

   Build: make build/pareto     Run: ./build/pareto [--quick] [output directory]
   (default bench/results; make pareto-quick writes out/pareto-quick in under 3 minutes)
   Writes pareto_<scene>.csv / .svg for dam_break, hydrostatic, cavity, and stability.csv,
   stability.svg, density_ratio.csv, density_ratio.svg. */
#define SPH_IMPLEMENTATION
#include "sph.h"
#include "examples/scenes.h"
#include "bench/svg.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#define NSOLVER 4
static const char* const solver_name[NSOLVER] = {"WCSPH", "PCISPH original", "PCISPH enhanced",
                                                  "IISPH"};
static const char* const solver_key[NSOLVER] = {"wcsph", "pcisph_original", "pcisph_enhanced",
                                                 "iisph"};

enum { SC_DAM = 0, SC_TANK, SC_CAVITY, NSCENE };
static const char* const scene_key[NSCENE] = {"dam_break", "hydrostatic", "cavity"};

#define HS_DEPTH 0.5  /* [m] */
#define HS_WIDTH 1.0  /* [m] */
#define HS_SETTLE 1.0 /* [s] start of the pressure average: about 30 acoustic periods 2H/c0 */
#define HS_END 1.5    /* [s] */
#define DAM_A 0.1     /* [m] column width */
#define CAV_AVG 1.0   /* [s] the cavity's profiles are averaged over the last second */

static int quick;
static double cav_end = 10; /* [s] cavity end time: at Re 100, 40 per side, the kinetic energy
                               changes by under 1 % per second from t = 7 s on (logged each
                               second in pareto.txt) */

/* The def of solver s. With gravity, the incompressible solvers' step is capped at
   0.05 sqrt(dx / g) (def.max_dt): from rest nothing but the force limit 0.25 sqrt(h / g) bounds
   their step, and sph.h's PCISPH notes say large first steps from rest need def.max_dt (without
   the cap the original PCISPH fails its first dam-break step at every factor). */
static sph_world_def solver_def(int s, double dx) {
    sph_world_def def = sph_world_def_default(2);
    if (s == 1) sph_world_def_pcisph(&def, 0);
    if (s == 2) sph_world_def_pcisph(&def, 1);
    if (s == 3) def.solver = SPH_SOLVER_IISPH;
    if (s != 0 && dx > 0) def.max_dt = (sph_real)(0.05 * sqrt(dx / 9.81));
    return def;
}

typedef struct result {
    double cpu;     /* [s] */
    double err;     /* the scene's metric; NAN unless ok */
    double dt_mean; /* [s] simulated time / steps */
    long steps;
    int ok;
    sph_status status;
} result;

/* The end of every run: the failure's message, mean step, the world freed, CPU seconds since c0. */
static void run_end(result* r, sph_world* w, clock_t c0) {
    if (r->status != SPH_OK) fprintf(stderr, "  t = %.4f s: %s\n", w->time, w->error);
    r->dt_mean = r->steps ? w->time / (double)r->steps : 0;
    sph_world_free(w);
    r->cpu = (double)(clock() - c0) / CLOCKS_PER_SEC;
}

static const char* status_text(const result* r) {
    if (r->ok) return "ok";
    if (r->status == SPH_ERR_UNSTABLE) return "unstable";
    if (r->status == SPH_OK) return "error-bound"; /* finished, metric not finite */
    return sph_status_string(r->status);
}

/* One step of factor * sph_stable_dt; with t_end > 0 it lands on t_end as sph_advance does (a
   remainder under two steps is split in halves: a sliver of a step would give the incompressible
   solvers, whose pressure scales as 1 / dt^2, a meaningless pressure). */
static sph_status step_once(sph_world* w, double t_end, double factor) {
    double dt = factor * (double)sph_stable_dt(w, w->def.solver);
    if (!(dt > 0)) return w->status != SPH_OK ? w->status : SPH_ERR_UNSTABLE;
    if (t_end > 0) {
        const double rem = t_end - w->time;
        if (rem <= dt) dt = rem;
        else if (rem < 2 * dt) dt = rem / 2;
    }
    return sph_step(w, (sph_real)dt);
}

/* Steps to time t_end with dt = factor * sph_stable_dt (step_once). */
static sph_status advance_to(sph_world* w, double t_end, double factor, long* steps) {
    while (w->time < t_end - 1e-12) {
        sph_status s;
        s = step_once(w, t_end, factor);
        if (s != SPH_OK) return s;
        ++*steps;
    }
    return SPH_OK;
}

/* ---- dam break ----------------------------------------------------------------------------- */

static result run_dam(int solver, int res, double factor) {
    sph_world w;
    scene_dam d;
    result r;
    const clock_t c0 = clock();
    double sq = 0;
    int k, m = 0;
    memset(&r, 0, sizeof r);
    r.err = NAN;
    r.status = scene_dam_break(&w, solver_def(solver, DAM_A / res), DAM_A, res, &d);
    if (r.status != SPH_OK) {
        fprintf(stderr, "dam break: %s\n", scene_error);
        return r;
    }
    for (k = 0; k < SCENE_MM_N && scene_mm_T[k] <= 3; ++k, ++m) {
        double Z, e;
        r.status = advance_to(&w, scene_mm_time(scene_mm_T[k], d.a), factor, &r.steps);
        if (r.status != SPH_OK) break;
        Z = scene_dam_front(&w, &d);
        e = (Z - scene_mm_Z[k]) / scene_mm_Z[k]; /* Martin & Moyce 1952, Table 2 */
        sq += e * e;
    }
    if (r.status == SPH_OK) {
        r.err = sqrt(sq / m);
        r.ok = isfinite(r.err);
    }
    run_end(&r, &w, c0);
    return r;
}

/* ---- hydrostatic tanks ---------------------------------------------------------------------- */

/* The tank of scene_hydrostatic (ratio 0) or scene_two_layer (ratio > 0), and its exact
   hydrostatic pressure [Pa] at height y [m]: rho0 g (H - y), or scene_two_layer_p. */
static sph_status two_layer(sph_world* w, sph_world_def def, int res, double ratio) {
    if (ratio <= 0) return scene_hydrostatic(w, def, HS_WIDTH, HS_DEPTH, res);
    return scene_two_layer(w, def, HS_WIDTH, HS_DEPTH, res, ratio);
}

static double p_exact(double y, double ratio) {
    if (ratio <= 0) return 1000 * 9.81 * (HS_DEPTH - y);
    return scene_two_layer_p(y, HS_DEPTH, ratio, 9.81);
}

static result run_tank(sph_world_def def, int res, double factor, double ratio) {
    sph_world w;
    result r;
    const clock_t c0 = clock();
    double *psum = NULL, sum = 0;
    int* cnt = NULL;
    size_t i, used = 0;
    memset(&r, 0, sizeof r);
    r.err = NAN;
    r.status = two_layer(&w, def, res, ratio);
    if (r.status != SPH_OK) {
        fprintf(stderr, "tank: %s\n", scene_error);
        return r;
    }
    psum = (double*)calloc(w.n, sizeof(double));
    cnt = (int*)calloc(w.n, sizeof(int));
    while (w.time < HS_END) { /* every step of the window is sampled; no landing steps */
        r.status = step_once(&w, 0, factor);
        if (r.status != SPH_OK) break;
        ++r.steps;
        if (w.time >= HS_SETTLE)
            for (i = 0; i < w.n; ++i) { psum[w.id[i]] += (double)w.p[i]; cnt[w.id[i]]++; }
    }
    if (r.status == SPH_OK) {
        const double m = (double)w.kernel.radius, rgh = 1000 * 9.81 * HS_DEPTH;
        for (i = 0; i < w.n; ++i) {
            const double x = (double)w.x[2 * i], y = (double)w.x[2 * i + 1];
            if (x < m || x > HS_WIDTH - m || y < m || y > HS_DEPTH - m || !cnt[w.id[i]]) continue;
            sum += fabs(psum[w.id[i]] / cnt[w.id[i]] - p_exact(y, ratio)) / rgh;
            ++used;
        }
        r.err = used ? sum / (double)used : NAN;
        r.ok = isfinite(r.err);
    }
    free(psum);
    free(cnt);
    run_end(&r, &w, c0);
    return r;
}

/* ---- cavity --------------------------------------------------------------------------------- */

/* Shepard kernel average of the fluid velocity component k at (px, py); 0 without neighbours. */
static double shepard(const sph_world* w, double px, double py, int k) {
    double sw = 0, su = 0;
    size_t i;
    for (i = 0; i < w->n; ++i) {
        const double dx = (double)w->x[2 * i] - px, dy = (double)w->x[2 * i + 1] - py;
        const double r = sqrt(dx * dx + dy * dy);
        double W;
        if (r >= (double)w->kernel.radius) continue;
        W = (double)sph_kernel_w(&w->kernel, (sph_real)r);
        sw += W;
        su += W * (double)w->v[2 * i + (size_t)k];
    }
    return sw > 0 ? su / sw : 0;
}

static result run_cavity(int solver, int res, double factor, FILE* log) {
    sph_world w;
    result r;
    const clock_t c0 = clock();
    double us[SCENE_GHIA_N], vs[SCENE_GHIA_N], sq = 0, ke_prev = 0;
    int k, m = 0, samples = 0;
    memset(&r, 0, sizeof r);
    memset(us, 0, sizeof us);
    memset(vs, 0, sizeof vs);
    r.err = NAN;
    r.status = scene_cavity(&w, solver_def(solver, 0), res, 100);
    if (r.status != SPH_OK) {
        fprintf(stderr, "cavity: %s\n", scene_error);
        return r;
    }
    while (w.time < cav_end - 1e-9) {
        const double t = w.time + 0.1;
        r.status = advance_to(&w, t, factor, &r.steps);
        if (r.status != SPH_OK) break;
        if (log && fmod(w.time + 1e-6, 1.0) < 0.05) { /* kinetic energy each second: steadiness */
            fprintf(log, "cavity %s res %d f %g: t %.1f KE %.6e (change %.2e)\n", solver_key[solver],
                    res, factor, w.time, w.stats.kinetic_energy,
                    ke_prev > 0 ? w.stats.kinetic_energy / ke_prev - 1 : 0.0);
            ke_prev = w.stats.kinetic_energy;
        }
        if (w.time > cav_end - CAV_AVG - 1e-6) {
            for (k = 0; k < SCENE_GHIA_N; ++k) {
                us[k] += shepard(&w, 0.5, scene_ghia_y[k], 0);
                vs[k] += shepard(&w, scene_ghia_x[k], 0.5, 1);
            }
            ++samples;
        }
    }
    if (r.status == SPH_OK && samples) {
        for (k = 1; k + 1 < SCENE_GHIA_N; ++k) { /* interior points: the ends lie on walls */
            const double eu = us[k] / samples - scene_ghia_u100[k];
            const double ev = vs[k] / samples - scene_ghia_v100[k];
            sq += eu * eu + ev * ev;
            m += 2;
        }
        r.err = sqrt(sq / m);
        r.ok = isfinite(r.err);
    }
    run_end(&r, &w, c0);
    return r;
}

/* ---- Pareto study --------------------------------------------------------------------------- */

#define MAXRUN 64

static int pareto_scene(int sc, const char* dir) {
    static const int dam_res[] = {10, 14, 20, 28}, tank_res[] = {10, 14, 20, 28},
                     cav_res[] = {20, 30, 40};
    /* dt factors of sph_stable_dt; the cavity (the longest runs) skips 0.5 */
    static const double factors[] = {0.5, 1, 2, 4}, quick_factors[] = {1, 4};
    const int* resl = sc == SC_DAM ? dam_res : sc == SC_TANK ? tank_res : cav_res;
    const int nres = quick ? (sc == SC_CAVITY ? 1 : 2) : (sc == SC_CAVITY ? 3 : 4);
    const double* fl = quick ? quick_factors : sc == SC_CAVITY ? factors + 1 : factors;
    const int nf = quick ? 2 : sc == SC_CAVITY ? 3 : 4;
    char path[512];
    FILE* csv;
    svg_chart ch;
    int s, q, f;
    snprintf(path, sizeof path, "%s/pareto_%s.csv", dir, scene_key[sc]);
    csv = fopen(path, "w");
    if (!csv) {
        fprintf(stderr, "cannot write %s\n", path);
        return 1;
    }
    fprintf(csv, "scene,solver,res,dt_factor,dt,steps,cpu_s,error,status\n");
    svg_begin(&ch,
              sc == SC_DAM ? "Dam break (Martin & Moyce): front error against CPU time"
              : sc == SC_TANK ? "Hydrostatic tank: pressure error against CPU time"
                              : "Lid-driven cavity Re 100 (Ghia): velocity error against CPU time",
              "CPU seconds (one thread)",
              sc == SC_DAM ? "RMS relative front error" : sc == SC_TANK ? "mean |p - p_exact| / (rho0 g H)"
                                                                         : "RMS velocity error [U]");
    svg_log(&ch, 0);
    svg_log(&ch, 1);
    for (s = 0; s < NSOLVER; ++s) {
        double cx[MAXRUN], ey[MAXRUN], fx[MAXRUN], fy[MAXRUN];
        int n = 0, nfront = 0, a, b;
        char label[64];
        for (q = 0; q < nres; ++q)
            for (f = 0; f < nf; ++f) {
                result r;
                if (sc == SC_DAM) r = run_dam(s, resl[q], fl[f]);
                else if (sc == SC_TANK) r = run_tank(solver_def(s, HS_DEPTH / resl[q]), resl[q], fl[f], 0);
                else r = run_cavity(s, resl[q], fl[f], stdout);
                printf("%-12s %-16s res %3d f %4.2f: dt %.3e steps %7ld cpu %8.2f s error %.4f %s\n",
                       scene_key[sc], solver_name[s], resl[q], fl[f], r.dt_mean, r.steps, r.cpu,
                       r.err, status_text(&r));
                fflush(stdout);
                fprintf(csv, "%s,%s,%d,%g,%.4e,%ld,%.3f,", scene_key[sc], solver_key[s], resl[q],
                        fl[f], r.dt_mean, r.steps, r.cpu);
                if (r.ok) fprintf(csv, "%.5e,ok\n", r.err);
                else fprintf(csv, ",%s\n", status_text(&r));
                if (r.ok && r.err > 0) {
                    cx[n] = r.cpu > 1e-3 ? r.cpu : 1e-3;
                    ey[n++] = r.err;
                }
            }
        /* Pareto front: by increasing CPU time, each point more accurate than all before it */
        for (a = 0; a < n; ++a)
            for (b = a + 1; b < n; ++b)
                if (cx[b] < cx[a]) {
                    double t = cx[a]; cx[a] = cx[b]; cx[b] = t;
                    t = ey[a]; ey[a] = ey[b]; ey[b] = t;
                }
        for (a = 0; a < n; ++a)
            if (!nfront || ey[a] < fy[nfront - 1]) {
                fx[nfront] = cx[a];
                fy[nfront++] = ey[a];
            }
        svg_series(&ch, cx, ey, (size_t)n, SVG_DOTS, solver_name[s]);
        snprintf(label, sizeof label, "%s front", solver_name[s]);
        if (nfront > 1) svg_series(&ch, fx, fy, (size_t)nfront, SVG_LINE, label);
    }
    fclose(csv);
    snprintf(path, sizeof path, "%s/pareto_%s.svg", dir, scene_key[sc]);
    svg_write(&ch, path);
    svg_free(&ch);
    return 0;
}

/* ---- stability maps ------------------------------------------------------------------------- */

/* Largest dt factor (of sph_stable_dt) at which the run finishes without an error from the
   library and its metric stays below 3x the metric at the reference factor 0.5: bisection in
   log(factor) between 0.5 (must pass) and 64, `iters` times. Returns 0 if 0.5 itself fails. */
static double largest_factor(int sc, int s, int res, int iters, double* ref_err, FILE* csv) {
    double lo = 0.5, hi = 64, bound;
    int it;
    result r = sc == SC_DAM ? run_dam(s, res, lo) : run_tank(solver_def(s, HS_DEPTH / res), res, lo, 0);
    *ref_err = r.err;
    fprintf(csv, "%s,%s,%d,%g,%.5e,%.3f,%s,reference\n", scene_key[sc], solver_key[s], res, lo,
            r.err, r.cpu, status_text(&r));
    if (!r.ok) return 0;
    bound = 3 * r.err;
    for (it = 0; it < iters; ++it) {
        const double mid = sqrt(lo * hi);
        int pass;
        r = sc == SC_DAM ? run_dam(s, res, mid) : run_tank(solver_def(s, HS_DEPTH / res), res, mid, 0);
        pass = r.ok && r.err < bound;
        fprintf(csv, "%s,%s,%d,%g,%.5e,%.3f,%s,%s\n", scene_key[sc], solver_key[s], res, mid, r.err,
                r.cpu, status_text(&r), pass ? "pass" : "fail");
        printf("stability %-11s %-16s f %7.3f: error %.4f (bound %.4f) %s %s\n", scene_key[sc],
               solver_name[s], mid, r.err, bound, status_text(&r), pass ? "pass" : "fail");
        fflush(stdout);
        if (pass) lo = mid;
        else hi = mid;
    }
    return lo;
}

static int stability(const char* dir) {
    static const double ratios[] = {1, 0.8, 0.4, 0.2, 0.1, 0.05, 0.01, 0.001};
    static const sph_density forms[] = {SPH_DENSITY_CONTINUITY, SPH_DENSITY_SUMMATION,
                                        SPH_DENSITY_PARTICLE};
    static const char* const form_name[] = {"continuity", "summation", "particle (Ott-Schnetter)"};
    const int iters = quick ? 3 : 7, res = 10, nratio = quick ? 5 : 8, tank_res = quick ? 10 : 14;
    double fmax[2][NSOLVER], xs[NSOLVER], ref;
    char path[512];
    FILE *csv, *dcsv;
    svg_chart ch, dh;
    int sc, s, k, j;
    snprintf(path, sizeof path, "%s/stability.csv", dir);
    csv = fopen(path, "w");
    snprintf(path, sizeof path, "%s/density_ratio.csv", dir);
    dcsv = fopen(path, "w");
    if (!csv || !dcsv) {
        fprintf(stderr, "cannot write into %s\n", dir);
        if (csv) fclose(csv);
        if (dcsv) fclose(dcsv);
        return 1;
    }
    fprintf(csv, "scene,solver,res,dt_factor,error,cpu_s,status,verdict\n");
    for (sc = 0; sc < 2; ++sc)
        for (s = 0; s < NSOLVER; ++s) {
            fmax[sc][s] = largest_factor(sc, s, res, iters, &ref, csv);
            fprintf(csv, "%s,%s,%d,%g,,,largest_stable,bound 3x %.5e\n", scene_key[sc], solver_key[s],
                    res, fmax[sc][s], ref);
            printf("stability %-11s %-16s: largest stable factor %.3f of sph_stable_dt\n",
                   scene_key[sc], solver_name[s], fmax[sc][s]);
        }
    fclose(csv);
    svg_begin(&ch, "Largest stable dt / sph_stable_dt (error < 3x that at 0.5)",
              "solver: 0 WCSPH, 1 PCISPH orig., 2 PCISPH enh., 3 IISPH", "dt factor");
    svg_log(&ch, 1);
    for (s = 0; s < NSOLVER; ++s) xs[s] = s;
    svg_series(&ch, xs, fmax[0], NSOLVER, SVG_LINE_MARKS, "dam break, 10 per a");
    svg_series(&ch, xs, fmax[1], NSOLVER, SVG_LINE_MARKS, "hydrostatic tank, 10 deep");
    snprintf(path, sizeof path, "%s/stability.svg", dir);
    svg_write(&ch, path);
    svg_free(&ch);

    /* density-ratio limits: WCSPH, multiphase pressure gradient (Ott & Schnetter eq. 12), the
       library's stable step; the limit is the smallest ratio at which the run finishes and its
       pressure error stays below 3x that of the same formulation at ratio 1 */
    fprintf(dcsv, "formulation,ratio,res,error,cpu_s,status,verdict\n");
    svg_begin(&dh, "Two-layer tank: pressure error against density ratio", "rho1 / rho0",
              "mean |p - p_exact| / (rho0 g H)");
    svg_log(&dh, 0);
    svg_log(&dh, 1);
    for (j = 0; j < 3; ++j) {
        double rx[8], ry[8], bound = 0, limit = 0;
        int n = 0, failed = 0;
        for (k = 0; k < nratio; ++k) {
            sph_world_def def = sph_world_def_default(2);
            result r;
            int pass;
            def.density = forms[j];
            def.pressure_grad = SPH_PGRAD_MULTIPHASE;
            r = run_tank(def, tank_res, 1, ratios[k]);
            if (k == 0) bound = 3 * r.err;
            pass = r.ok && r.err < bound;
            if (pass && !failed) limit = ratios[k];
            if (!pass) failed = 1;
            fprintf(dcsv, "%s,%g,%d,%.5e,%.3f,%s,%s\n", form_name[j], ratios[k], tank_res, r.err, r.cpu,
                    status_text(&r), pass ? "pass" : "fail");
            printf("density ratio %-26s %6.3f: error %.4f (bound %.4f) %s %s\n", form_name[j],
                   ratios[k], r.err, bound, status_text(&r), pass ? "pass" : "fail");
            fflush(stdout);
            if (r.ok && r.err > 0) {
                rx[n] = ratios[k];
                ry[n++] = r.err;
            }
        }
        fprintf(dcsv, "%s,%g,%d,,,limit,bound %.5e\n", form_name[j], limit, tank_res, bound);
        printf("density ratio %-26s: limit %g\n", form_name[j], limit);
        svg_series(&dh, rx, ry, (size_t)n, SVG_LINE_MARKS, form_name[j]);
    }
    fclose(dcsv);
    snprintf(path, sizeof path, "%s/density_ratio.svg", dir);
    svg_write(&dh, path);
    svg_free(&dh);
    return 0;
}

int main(int argc, char** argv) {
    const char* dir = NULL;
    const char* only = NULL;
    int a, rc = 0, sc;
    const clock_t c0 = clock();
#ifdef _OPENMP
    omp_set_num_threads(1);
#endif
    for (a = 1; a < argc; ++a) {
        if (strcmp(argv[a], "--quick") == 0) quick = 1;
        else if (strcmp(argv[a], "--only") == 0 && a + 1 < argc) only = argv[++a];
        else dir = argv[a];
    }
    if (!dir) dir = quick ? "out/pareto-quick" : "bench/results";
    if (quick) cav_end = 6;
    for (sc = 0; sc < NSCENE; ++sc)
        if (!only || strcmp(only, scene_key[sc]) == 0) rc |= pareto_scene(sc, dir);
    if (!only || strcmp(only, "stability") == 0) rc |= stability(dir);
    printf("total CPU %.1f s; results in %s\n", (double)(clock() - c0) / CLOCKS_PER_SEC, dir);
    return rc;
}
