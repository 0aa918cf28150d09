/* bench/bench.c - the benchmark driver: sph.h's speed against its own baseline, in one run.

   Build: make build/bench   (bench.c + bench_float.c: the double and float copies in one program)
   Run:   ./build/bench [suite ...] [options]
   Suites (default: all but iisph-sweep and run):
     throughput  2D and 3D dam break at --n particles, 1 thread: every solver's time per step (and
                 per iteration), WCSPH's ratio to the baseline (bench/baseline.h) and the
                 baseline's agreement with sph.h after the same steps
     scaling     the same scenes on 1..P threads: speed-up, and whether the states are bitwise equal
     search      neighbour search alone: grid build and list build, ns per particle, vs baseline
     float       WCSPH in float against double, same scene, interleaved repeats (step, and
                 its neighbour search, density-rate and force passes)
     memory      bytes per particle: 2D single phase, 3D two phases, the baseline
     growth      time per step against N (10^3 .. 10^6 in 2D) per solver; fitted exponent
     model       the 2D dam break with one optional piece of physics on at a time: bytes, time
     run         one measurement: --scene, --n, --solver, --threads, --repeats, --steps
     iisph-sweep Meiers 2025's Table 2 for our IISPH (time step against iterations and cost)
     tts         time to solution: the dam break through sph_advance with the library's defaults
                 (frames of 1/50 s) to --t-end, per solver (wcsph, pcisph-enh, pcisph, iisph,
                 dfsph), double and float, 1 and 2 threads: wall-clock seconds per simulated
                 second, time reached (a run stops at its first error and reports it), sub-steps,
                 retries, density error, particles outside the container. Scenes: 2d (examples/
                 dambreak.c's), 3d-6k and 3d-59k (SPlisHSPlasH's DamBreakModel at dx 0.05 and
                 0.025 m); default 2d only (make bench-tts runs all), --quick: 2d at 10
                 particles per a to 0.1 s, wcsph and dfsph; among the default suites of a full
                 run (make bench) double and 2 threads only. Select cells with --scene, --solver
                 (comma lists or all), --precision, --threads; --max-wall S stops a run after S
                 wall-clock seconds (it reports the time it reached)
   Options: --quick (small sizes, < 1 minute), --out DIR (CSV and SVG; default bench/results),
            --n N, --scene S, --solver S, --threads T, --repeats R, --steps K, --t-end T (tts:
            simulated seconds, default 1), --max-wall S, --precision double|float|all,
            --kernel default|cubic|wendland (tts: instead of the automatic kernel, the cubic
            B-spline at h = dx and omega 0.5, the peer's support, or Wendland C2 at h = 1.3 dx,
            the automatic kernel everywhere but 3D IISPH, DFSPH and PBF), --skin S (tts: def.neighbor_skin = S, the
            Verlet skin of the neighbour lists in support radii; 0 = search every step)
   Every timing is the median over the repeats of a wall-clock time per step; runs that are
   compared (ours against the baseline, double against float) alternate inside one repeat loop,
   so a slow minute on a shared machine hits both. tts is the exception: one run per cell (each
   is thousands of steps), printed with the host's load average. */
#define SPH_IMPLEMENTATION
#include "sph.h"
#include "examples/scenes.h"
#include "bench/bench_types.h"
#include "bench/baseline.h"
#define BX(name) name##_d
#include "bench/bench_core.h"
#include "bench/svg.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int bench_run_f(int scene, int solver, double target, int warm, int steps, bench_result* r);
int bench_tts_f(int scene, int solver, int quick, double t_end, double max_wall, double progress,
                tts_result* r);

int bench_tts_kernel = 0;
double bench_tts_skin = -2; /* --skin S: def.neighbor_skin of the tts scenes; -2: the default */

typedef struct opts {
    int quick, repeats, steps, threads, threads_set, scene, solver;
    int suites_default; /* no suite named: tts runs a smaller default set (see suite_tts) */
    unsigned tts_scenes, tts_solvers, precisions; /* bit masks (tts); 0 = the suite's default */
    double n, t_end, max_wall;
    const char* out;
} opts;

static int max_threads(void) {
#ifdef _OPENMP
    return omp_get_num_procs();
#else
    return 1;
#endif
}

static void set_threads(int t) {
#ifdef _OPENMP
    omp_set_num_threads(t);
#else
    (void)t;
#endif
}

static int cmp_double(const void* a, const void* b) {
    const double x = *(const double*)a, y = *(const double*)b;
    return x < y ? -1 : x > y;
}

static double median(double* v, int n) {
    qsort(v, (size_t)n, sizeof(double), cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static FILE* csv_open(const opts* o, const char* name, const char* header) {
    char path[512];
    FILE* f;
    snprintf(path, sizeof path, "%s/%s", o->out, name);
    f = fopen(path, "w");
    if (!f) {
        fprintf(stderr, "bench: cannot write %s\n", path);
        return NULL;
    }
    fprintf(f, "%s\n", header);
    return f;
}

static void out_path(const opts* o, const char* name, char* path, size_t cap) {
    snprintf(path, cap, "%s/%s", o->out, name);
}

/* rough cost per particle-step [ns] of each solver on this kind of machine, 2D (3D: x4), only to
   choose step counts that take about the intended time */
static const double solver_cost[BENCH_NSOLVER] = {400, 20000, 8000, 2000};

/* steps that take about `budget` seconds at an estimated cost of c ns per particle-step */
static int steps_for(double n, double ns_per_particle, double budget, int lo, int hi) {
    double s = budget / (n * ns_per_particle * 1e-9);
    return s < lo ? lo : s > hi ? hi : (int)s;
}

/* A measurement repeated: the record of the median time (a repeat's other fields come along). */
typedef struct med_run {
    bench_result r[16];
    int n;
} med_run;

static bench_result med_pick(med_run* m) {
    double t[16];
    int k;
    for (k = 0; k < m->n; ++k)
        t[k] = m->r[k].step_s;
    {
        const double md = median(t, m->n);
        int best = 0;
        for (k = 0; k < m->n; ++k)
            if (fabs(m->r[k].step_s - md) < fabs(m->r[best].step_s - md)) best = k;
        {
            bench_result r = m->r[best];
            r.step_s = md;
            return r;
        }
    }
}

/* ---------------------------------------------------------------------------------------------- */

static int suite_throughput(const opts* o) {
    static const int scenes[2] = {BENCH_DAMBREAK2D, BENCH_DAMBREAK3D};
    FILE* f = csv_open(o, "perf_throughput.csv",
                       "scene,solver,threads,n,nb,step_ms,particle_steps_per_s,iterations,"
                       "ms_per_iteration,ratio_to_baseline,neighbors_ms,density_ms,pressure_ms,"
                       "forces_ms,integrate_ms,pairs_per_particle,bytes_per_particle,agree_dx");
    int si, k, rep;
    if (!f) return 0;
    set_threads(1);
    printf("\n== throughput: 1 thread, double, median of %d\n", o->repeats);
    for (si = 0; si < 2; ++si) {
        const int sc = scenes[si], dim = bench_scenes[sc].dim;
        const double n = o->n, budget = o->quick ? 0.25 : 2.0;
        med_run base, runs[BENCH_NSOLVER];
        bench_result b, r[BENCH_NSOLVER];
        int failed[BENCH_NSOLVER] = {0};
        memset(&base, 0, sizeof base);
        memset(runs, 0, sizeof runs);
        for (rep = 0; rep < o->repeats; ++rep) {
            const int steps =
                o->steps ? o->steps
                         : steps_for(n, solver_cost[0] * (dim == 3 ? 4 : 1), budget, 5, 200);
            if (!run_baseline_d(sc, n, 5, steps, &base.r[base.n++])) return 0;
            for (k = 0; k < BENCH_NSOLVER; ++k) {
                const int sk =
                    o->steps ? o->steps
                             : steps_for(n, solver_cost[k] * (dim == 3 ? 4 : 1), budget, 3, 200);
                if (failed[k]) continue;
                if (!run_d(sc, k, n, 5, sk, &runs[k].r[runs[k].n]))
                    failed[k] = 1; /* reported below */
                else
                    runs[k].n++;
            }
        }
        b = med_pick(&base);
        printf("%s (%s): %.0f fluid + %.0f wall particles, %.1f pairs/particle\n",
               bench_scenes[sc].name, bench_scenes[sc].what, b.n, b.nb, runs[0].r[0].pairs);
        printf("  %-12s %10s %14s %8s %10s %9s %11s\n", "solver", "ms/step", "particle-st/s",
               "iters", "ms/iter", "vs base", "search ms");
        printf("  %-12s %10.3f %14.3g %8s %10s %9s %11.3f   (agrees with sph.h to %.1e dx)\n",
               "baseline", 1e3 * b.step_s, b.n / b.step_s, "-", "-", "1.00",
               1e3 * b.stage_s[SPH_STAGE_NEIGHBORS], b.agree);
        fprintf(f, "%s,baseline,1,%.0f,%.0f,%.6f,%.6g,0,0,1,%.6f,%.6f,0,%.6f,%.6f,0,%.1f,%.3g\n",
                bench_scenes[sc].name, b.n, b.nb, 1e3 * b.step_s, b.n / b.step_s,
                1e3 * b.stage_s[SPH_STAGE_NEIGHBORS], 1e3 * b.stage_s[SPH_STAGE_DENSITY],
                1e3 * b.stage_s[SPH_STAGE_FORCES], 1e3 * b.stage_s[SPH_STAGE_INTEGRATE], b.bytes,
                b.agree);
        for (k = 0; k < BENCH_NSOLVER; ++k) {
            const double* st;
            if (failed[k]) {
                printf("  %-12s failed (the step error is printed above)\n", bench_solvers[k].name);
                fprintf(f, "%s,%s,1,,,,,,,,,,,,,,,\n", bench_scenes[sc].name,
                        bench_solvers[k].name);
                continue;
            }
            r[k] = med_pick(&runs[k]);
            st = r[k].stage_s;
            printf("  %-12s %10.3f %14.3g %8.1f %10.3f %9.2f %11.3f\n", bench_solvers[k].name,
                   1e3 * r[k].step_s, r[k].n / r[k].step_s, r[k].iterations,
                   r[k].iterations > 0 ? 1e3 * r[k].step_s / r[k].iterations : 0,
                   b.step_s / r[k].step_s, 1e3 * st[SPH_STAGE_NEIGHBORS]);
            fprintf(
                f,
                "%s,%s,1,%.0f,%.0f,%.6f,%.6g,%.2f,%.6f,%.3f,%.6f,%.6f,%.6f,%.6f,%.6f,%.2f,%.1f,\n",
                bench_scenes[sc].name, bench_solvers[k].name, r[k].n, r[k].nb, 1e3 * r[k].step_s,
                r[k].n / r[k].step_s, r[k].iterations,
                r[k].iterations > 0 ? 1e3 * r[k].step_s / r[k].iterations : 0,
                b.step_s / r[k].step_s, 1e3 * st[SPH_STAGE_NEIGHBORS], 1e3 * st[SPH_STAGE_DENSITY],
                1e3 * st[SPH_STAGE_PRESSURE], 1e3 * st[SPH_STAGE_FORCES],
                1e3 * st[SPH_STAGE_INTEGRATE], r[k].pairs, r[k].bytes);
        }
        if (failed[0]) continue;
        printf("  WCSPH stages (ms): neighbours %.3f, density %.3f, pressure %.3f, forces %.3f, "
               "integrate %.3f; baseline: search %.3f, density %.3f, forces %.3f, rest %.3f\n",
               1e3 * r[0].stage_s[SPH_STAGE_NEIGHBORS], 1e3 * r[0].stage_s[SPH_STAGE_DENSITY],
               1e3 * r[0].stage_s[SPH_STAGE_PRESSURE], 1e3 * r[0].stage_s[SPH_STAGE_FORCES],
               1e3 * r[0].stage_s[SPH_STAGE_INTEGRATE], 1e3 * b.stage_s[SPH_STAGE_NEIGHBORS],
               1e3 * b.stage_s[SPH_STAGE_DENSITY], 1e3 * b.stage_s[SPH_STAGE_FORCES],
               1e3 * b.stage_s[SPH_STAGE_INTEGRATE]);
    }
    fclose(f);
    return 1;
}

static int suite_scaling(const opts* o) {
    static const int scenes[2] = {BENCH_DAMBREAK2D, BENCH_DAMBREAK3D};
    static const int solvers[2] = {BENCH_WCSPH, BENCH_IISPH};
    const int P = max_threads();
    FILE* f =
        csv_open(o, "perf_scaling.csv", "scene,solver,threads,n,step_ms,speedup,bitwise_equal");
    double xs[4][8], ys[4][8];
    char labels[4][64], path[512];
    int si, so, t, rep, all_equal = 1;
    svg_chart ch;
    if (!f) return 0;
    printf("\n== scaling: 1..%d threads, double, median of %d\n", P, o->repeats);
    for (si = 0; si < 2; ++si)
        for (so = 0; so < 2; ++so) {
            const int sc = scenes[si], sv = solvers[so], dim = bench_scenes[sc].dim;
            const int steps = o->steps ? o->steps
                                       : steps_for(o->n, solver_cost[sv] * (dim == 3 ? 4 : 1),
                                                   o->quick ? 0.25 : 2.0, 3, 200);
            med_run m[8];
            double t1 = 0;
            uint64_t h1 = 0;
            memset(m, 0, sizeof m);
            for (rep = 0; rep < o->repeats; ++rep)
                for (t = 1; t <= P && t <= 8; ++t) {
                    set_threads(t);
                    if (!run_d(sc, sv, o->n, 5, steps, &m[t - 1].r[m[t - 1].n++])) return 0;
                }
            printf("%s %s:", bench_scenes[sc].name, bench_solvers[sv].name);
            snprintf(labels[si * 2 + so], 64, "%s %s", bench_scenes[sc].name,
                     bench_solvers[sv].name);
            for (t = 1; t <= P && t <= 8; ++t) {
                const bench_result r = med_pick(&m[t - 1]);
                int equal = 1, k;
                if (t == 1) {
                    t1 = r.step_s;
                    h1 = r.hash;
                }
                for (k = 0; k < m[t - 1].n; ++k)
                    equal &= m[t - 1].r[k].hash == h1;
                all_equal &= equal;
                xs[si * 2 + so][t - 1] = t;
                ys[si * 2 + so][t - 1] = t1 / r.step_s;
                printf("  %d thread%s %.3f ms (x%.2f)%s", t, t > 1 ? "s" : "", 1e3 * r.step_s,
                       t1 / r.step_s, equal ? "" : " STATE DIFFERS");
                fprintf(f, "%s,%s,%d,%.0f,%.6f,%.3f,%d\n", bench_scenes[sc].name,
                        bench_solvers[sv].name, t, r.n, 1e3 * r.step_s, t1 / r.step_s, equal);
            }
            printf("\n");
        }
    printf("states after the timed steps bitwise equal for every thread count: %s\n",
           all_equal ? "yes" : "NO");
    fclose(f);
    set_threads(1);
    svg_begin(&ch, "Thread scaling (100k-particle dam break)", "threads", "speed-up over 1 thread");
    {
        double ix[8], iy[8];
        int n = P < 8 ? P : 8;
        for (t = 0; t < n; ++t)
            ix[t] = iy[t] = t + 1;
        svg_series(&ch, ix, iy, (size_t)n, SVG_DASHED, "ideal");
        for (si = 0; si < 4; ++si)
            svg_series(&ch, xs[si], ys[si], (size_t)n, SVG_LINE_MARKS, labels[si]);
    }
    out_path(o, "perf_scaling.svg", path, sizeof path);
    svg_write(&ch, path);
    svg_free(&ch);
    return all_equal;
}

static int suite_search(const opts* o) {
    static const int scenes[2] = {BENCH_DAMBREAK2D, BENCH_DAMBREAK3D};
    FILE* f =
        csv_open(o, "perf_search.csv",
                 "scene,n,code,grid_ns_per_particle,lists_ns_per_particle,pairs_per_particle");
    int si, rep;
    if (!f) return 0;
    set_threads(1);
    printf("\n== neighbour search (fluid-fluid), 1 thread, double, median of %d\n", o->repeats);
    for (si = 0; si < 2; ++si) {
        double g[16], l[16], gb[16], lb[16];
        bench_result r, rb;
        const int reps = o->quick ? 3 : 10;
        memset(&r, 0, sizeof r);
        memset(&rb, 0, sizeof rb);
        for (rep = 0; rep < o->repeats && rep < 16; ++rep) {
            if (!run_search_d(scenes[si], o->n, reps, &r, &rb)) return 0;
            g[rep] = r.grid_s;
            l[rep] = r.lists_s;
            gb[rep] = rb.grid_s;
            lb[rep] = rb.lists_s;
        }
        r.grid_s = median(g, rep);
        r.lists_s = median(l, rep);
        rb.grid_s = median(gb, rep);
        rb.lists_s = median(lb, rep);
        printf("%s, %.0f particles: grid build %.1f ns/particle (baseline %.1f, x%.2f), list build "
               "%.1f ns/particle (baseline %.1f, x%.2f), %.1f pairs/particle (baseline %.1f)\n",
               bench_scenes[scenes[si]].name, r.n, 1e9 * r.grid_s / r.n, 1e9 * rb.grid_s / r.n,
               rb.grid_s / r.grid_s, 1e9 * r.lists_s / r.n, 1e9 * rb.lists_s / r.n,
               rb.lists_s / r.lists_s, r.pairs, rb.pairs);
        fprintf(f, "%s,%.0f,sph.h,%.2f,%.2f,%.2f\n%s,%.0f,baseline,%.2f,%.2f,%.2f\n",
                bench_scenes[scenes[si]].name, r.n, 1e9 * r.grid_s / r.n, 1e9 * r.lists_s / r.n,
                r.pairs, bench_scenes[scenes[si]].name, r.n, 1e9 * rb.grid_s / r.n,
                1e9 * rb.lists_s / r.n, rb.pairs);
    }
    fclose(f);
    return 1;
}

static int suite_float(const opts* o) {
    static const int scenes[2] = {BENCH_DAMBREAK2D, BENCH_DAMBREAK3D};
    FILE* f = csv_open(o, "perf_float.csv", "scene,n,double_ms,float_ms,float_speedup");
    int si, rep;
    if (!f) return 0;
    set_threads(1);
    printf("\n== float against double: WCSPH, 1 thread, median of %d\n", o->repeats);
    for (si = 0; si < 2; ++si) {
        const int sc = scenes[si], dim = bench_scenes[sc].dim;
        const int steps = o->steps ? o->steps
                                   : steps_for(o->n, solver_cost[0] * (dim == 3 ? 4 : 1),
                                               o->quick ? 0.25 : 2.0, 5, 200);
        /* the stages a step's time is mostly in, each the median over the repeats */
        static const int stages[3] = {SPH_STAGE_NEIGHBORS, SPH_STAGE_DENSITY, SPH_STAGE_FORCES};
        static const char* stage_names[3] = {"neighbours", "density rate", "forces"};
        double td[16], tf[16], sd[3][16], sf[3][16], n = 0, md, mf;
        bench_result r;
        int k;
        for (rep = 0; rep < o->repeats && rep < 16; ++rep) {
            if (!run_d(sc, BENCH_WCSPH, o->n, 5, steps, &r)) return 0;
            td[rep] = r.step_s;
            for (k = 0; k < 3; ++k) sd[k][rep] = r.stage_s[stages[k]];
            n = r.n;
            if (!bench_run_f(sc, BENCH_WCSPH, o->n, 5, steps, &r)) return 0;
            tf[rep] = r.step_s;
            for (k = 0; k < 3; ++k) sf[k][rep] = r.stage_s[stages[k]];
        }
        md = median(td, rep);
        mf = median(tf, rep);
        printf("%s, %.0f particles: double %.3f ms/step, float %.3f ms/step: float x%.2f\n",
               bench_scenes[sc].name, n, 1e3 * md, 1e3 * mf, md / mf);
        for (k = 0; k < 3; ++k) {
            const double a = median(sd[k], rep), b = median(sf[k], rep);
            printf("    %-12s double %.3f ms, float %.3f ms: float x%.2f\n", stage_names[k],
                   1e3 * a, 1e3 * b, b > 0 ? a / b : 0);
        }
        fprintf(f, "%s,%.0f,%.6f,%.6f,%.3f\n", bench_scenes[sc].name, n, 1e3 * md, 1e3 * mf,
                md / mf);
    }
    fclose(f);
    return 1;
}

static int suite_memory(const opts* o) {
    FILE* f = csv_open(o, "perf_memory.csv", "world,n,bytes_per_particle");
    bench_result r, b;
    double b3;
    if (!f) return 0;
    set_threads(1);
    printf("\n== memory (sph_world_memory / fluid particles: every array, neighbour lists "
           "included)\n");
    if (!run_d(BENCH_DAMBREAK2D, BENCH_WCSPH, o->n, 0, 2, &r)) return 0;
    if (!run_baseline_d(BENCH_DAMBREAK2D, o->n, 0, 2, &b)) return 0;
    b3 = bytes_3d_multiphase_d(o->n);
    printf("2D WCSPH single phase, %.0f particles: %.0f bytes/particle (baseline %.0f)\n", r.n,
           r.bytes, b.bytes);
    printf("3D WCSPH two phases, ~%.0f particles: %.0f bytes/particle\n", o->n, b3);
    fprintf(
        f,
        "dambreak2d wcsph,%.0f,%.1f\nbaseline dambreak2d,%.0f,%.1f\n3d two-phase wcsph,%.0f,%.1f\n",
        r.n, r.bytes, b.n, b.bytes, o->n, b3);
    fclose(f);
    return 1;
}

static int suite_growth(const opts* o) {
    static const double full[] = {1e3, 3e3, 1e4, 3e4, 1e5, 3e5, 1e6};
    static const double quick[] = {1e3, 3e3, 1e4, 3e4};
    const double* ns = o->quick ? quick : full;
    const int nn = o->quick ? 4 : 7;
    FILE* f = csv_open(o, "perf_growth.csv", "solver,n,step_ms,particle_steps_per_s,iterations");
    double X[BENCH_NSOLVER + 1][8], Y[BENCH_NSOLVER + 1][8];
    int cnt[BENCH_NSOLVER + 1], k, i, rep;
    char path[512];
    svg_chart ch;
    if (!f) return 0;
    set_threads(1);
    printf("\n== cost growth: 2D dam break, 1 thread, double, median of %d\n", o->repeats);
    for (k = 0; k <= BENCH_NSOLVER; ++k) { /* k = BENCH_NSOLVER: the baseline */
        cnt[k] = 0;
        for (i = 0; i < nn; ++i) {
            const double per = k == BENCH_NSOLVER ? solver_cost[0] : solver_cost[k];
            const int steps = steps_for(ns[i], per, o->quick ? 0.15 : 1.5, 3, 400);
            med_run m;
            bench_result r;
            if (k != BENCH_WCSPH && k != BENCH_NSOLVER && ns[i] > 3.1e5) continue;
            memset(&m, 0, sizeof m);
            for (rep = 0; rep < o->repeats; ++rep) {
                const int ok = k == BENCH_NSOLVER
                                   ? run_baseline_d(BENCH_DAMBREAK2D, ns[i], 3, steps, &m.r[m.n])
                                   : run_d(BENCH_DAMBREAK2D, k, ns[i], 3, steps, &m.r[m.n]);
                if (!ok) return 0;
                ++m.n;
            }
            r = med_pick(&m);
            X[k][cnt[k]] = r.n;
            Y[k][cnt[k]] = r.n / r.step_s;
            cnt[k]++;
            fprintf(f, "%s,%.0f,%.6f,%.6g,%.2f\n",
                    k == BENCH_NSOLVER ? "baseline" : bench_solvers[k].name, r.n, 1e3 * r.step_s,
                    r.n / r.step_s, r.iterations);
        }
        { /* least-squares slope of log(time per step) against log N, from 10^4 up */
            double sx = 0, sy = 0, sxx = 0, sxy = 0, m = 0, slope;
            printf("%-12s", k == BENCH_NSOLVER ? "baseline" : bench_solvers[k].name);
            for (i = 0; i < cnt[k]; ++i) {
                printf(" %7.0f:%.3gms", X[k][i], 1e3 * X[k][i] / Y[k][i]);
                if (X[k][i] < 0.9e4 && !o->quick) continue;
                sx += log(X[k][i]);
                sy += log(X[k][i] / Y[k][i]);
                sxx += log(X[k][i]) * log(X[k][i]);
                sxy += log(X[k][i]) * log(X[k][i] / Y[k][i]);
                m += 1;
            }
            slope = (m * sxy - sx * sy) / (m * sxx - sx * sx);
            printf("\n             time per step ~ N^%.3f (fit over N >= %s)\n", slope,
                   o->quick ? "10^3" : "10^4");
            fprintf(f, "%s,fit_exponent,%.4f,,\n",
                    k == BENCH_NSOLVER ? "baseline" : bench_solvers[k].name, slope);
        }
    }
    fclose(f);
    svg_begin(&ch, "Throughput against size (2D dam break, 1 thread, double)", "fluid particles N",
              "particle-steps per second");
    svg_log(&ch, 0);
    svg_log(&ch, 1);
    for (k = 0; k <= BENCH_NSOLVER; ++k)
        svg_series(&ch, X[k], Y[k], (size_t)cnt[k],
                   k == BENCH_NSOLVER ? SVG_DASHED : SVG_LINE_MARKS,
                   k == BENCH_NSOLVER ? "baseline WCSPH" : bench_solvers[k].name);
    out_path(o, "perf_growth.svg", path, sizeof path);
    svg_write(&ch, path);
    svg_free(&ch);
    return 1;
}

static int suite_model(const opts* o) {
    FILE* f = csv_open(o, "perf_model.csv",
                       "variant,n,step_ms,ratio_to_defaults,bytes_per_particle,"
                       "iterations");
    double t0 = 0;
    int m, rep;
    if (!f) return 0;
    set_threads(1);
    printf("\n== model no more than a scene needs: 2D dam break, %.0f particles, 1 thread, median "
           "of %d\n",
           o->n, o->repeats);
    printf("  %-52s %9s %9s %11s\n", "variant", "ms/step", "x default", "bytes/part");
    for (m = 0; m < BENCH_NMODEL; ++m) {
        const int steps = o->steps ? o->steps
                                   : steps_for(o->n, m >= BENCH_M_PCISPH ? 8000 : 500,
                                               o->quick ? 0.15 : 1.0, 3, 100);
        med_run mr;
        bench_result r;
        memset(&mr, 0, sizeof mr);
        for (rep = 0; rep < o->repeats; ++rep)
            if (!run_model_d(m, o->n, 5, steps, &mr.r[mr.n++])) return 0;
        r = med_pick(&mr);
        if (m == 0) t0 = r.step_s;
        printf("  %-52s %9.3f %9.2f %11.0f\n", bench_model_names[m], 1e3 * r.step_s, r.step_s / t0,
               r.bytes);
        fprintf(f, "\"%s\",%.0f,%.6f,%.3f,%.1f,%.2f\n", bench_model_names[m], r.n, 1e3 * r.step_s,
                r.step_s / t0, r.bytes, r.iterations);
    }
    fclose(f);
    return 1;
}

/* Names of w.stats.stage_time's stages (enum sph_stage), for the suites that print them. */
static const char* const stage_label[SPH_STAGE_COUNT] = {"boundary", "neighbors", "density",
                                                        "pressure", "forces",    "integrate"};

static int suite_run(const opts* o) {
    med_run m;
    bench_result r;
    int rep, k;
    memset(&m, 0, sizeof m);
    set_threads(o->threads);
    for (rep = 0; rep < o->repeats; ++rep)
        if (!run_d(o->scene, o->solver, o->n, 10, o->steps ? o->steps : 50, &m.r[m.n++])) return 0;
    r = med_pick(&m);
    printf("%s %s, %d thread(s): n %.0f (+%.0f wall), %.3f ms/step, %.3g particle-steps/s, "
           "%.1f iterations, %.1f pairs/particle, %.0f bytes/particle\n  stages (ms):",
           bench_scenes[o->scene].name, bench_solvers[o->solver].name, o->threads, r.n, r.nb,
           1e3 * r.step_s, r.n / r.step_s, r.iterations, r.pairs, r.bytes);
    for (k = 0; k < SPH_STAGE_COUNT; ++k)
        printf(" %s %.3f", stage_label[k], 1e3 * r.stage_s[k]);
    printf("\n");
    return 1;
}

/* Meiers 2025's Table 2 for our solver: the time step against iterations and time to solution. */
static int suite_iisph_sweep(const opts* o) {
    static const double fs[] = {0.005, 0.0075, 0.01, 0.015, 0.02, 0.03, 0.05, 0.08};
    const int res = o->quick ? 20 : 40;
    const double dx = 0.5 / res, unit = sqrt(dx / 9.81);
    FILE* f = csv_open(o, "iisph_sweep.csv",
                       "dt,dt_units,steps,iterations,pressure_s,neighbors_s,overall_s");
    size_t k;
    if (!f) return 0;
    set_threads(o->threads);
    printf("\n== IISPH hydrostatic tank, %d particles deep, 1 s simulated, %d thread(s)\n", res,
           o->threads);
    printf("%9s %15s %7s %10s %12s %13s %11s\n", "dt [s]", "dt/sqrt(dx/g)", "steps", "iterations",
           "pressure [s]", "neighbors [s]", "overall [s]");
    for (k = 0; k < sizeof(fs) / sizeof(fs[0]); ++k) {
        const double dt = fs[k] * unit;
        sph_world_def def = sph_world_def_default(2);
        sph_world w;
        double its = 0;
        int steps = 0;
        def.solver = SPH_SOLVER_IISPH;
        if (scene_hydrostatic(&w, def, 1.0, 0.5, res) != SPH_OK) {
            fprintf(stderr, "%s\n", scene_error);
            return 0;
        }
        while (w.time < 1.0 - 1e-9) {
            if (sph_step(&w, (sph_real)dt) != SPH_OK) {
                fprintf(stderr, "%s\n", w.error);
                return 0;
            }
            its += w.stats.iterations;
            ++steps;
        }
        printf("%9.6f %15.4f %7d %10.1f %12.3f %13.3f %11.3f\n", dt, fs[k], steps, its / steps,
               w.stage_time_total[SPH_STAGE_PRESSURE], w.stage_time_total[SPH_STAGE_NEIGHBORS],
               w.step_time_total);
        fprintf(f, "%.6f,%.4f,%d,%.2f,%.4f,%.4f,%.4f\n", dt, fs[k], steps, its / steps,
                w.stage_time_total[SPH_STAGE_PRESSURE], w.stage_time_total[SPH_STAGE_NEIGHBORS],
                w.step_time_total);
        sph_world_free(&w);
    }
    fclose(f);
    return 1;
}

/* The host's 1-minute load average (Linux; 0 elsewhere): other work on a shared machine. */
static double load_average(void) {
    double l = 0;
    FILE* f = fopen("/proc/loadavg", "r");
    if (!f) return 0;
    if (fscanf(f, "%lf", &l) != 1) l = 0;
    fclose(f);
    return l;
}

/* Time to solution: each scene run to --t-end through sph_advance with the library's defaults
   (no max_dt, no tuned tolerance: what a user gets), one frame (1/50 s) per call. A run stops
   at its first error, reported with the time it reached. */
static int suite_tts(const opts* o) {
    static const int quick_solvers = (1 << TTS_WCSPH) | (1 << TTS_DFSPH);
    const unsigned scenes = o->tts_scenes ? o->tts_scenes : 1u << TTS_DAM2D; /* 3D: --scene */
    const unsigned solvers = o->tts_solvers ? o->tts_solvers
                                            : o->quick ? (unsigned)quick_solvers
                                                       : (1u << TTS_NSOLVER) - 1;
    /* 1 double, 2 float; make bench (tts among the default suites, full mode): double only */
    const unsigned precs = o->precisions               ? o->precisions
                           : o->suites_default && !o->quick ? 1u
                                                            : 3u;
    const double t_end = o->t_end > 0 ? o->t_end : o->quick ? 0.1 : 1.0;
    const int P = max_threads();
    int threads[2], nthreads = 0, sc, sv, pr, ti, ncell = 0, ok = 1;
    /* chart: one series per scene x precision x thread count (at most 3 x 2 x 2 = 12) */
    double X[TTS_NSCENE * 4][TTS_NSOLVER], Y[TTS_NSCENE * 4][TTS_NSOLVER];
    int used[TTS_NSCENE * 4] = {0};
    char path[512];
    FILE* f = csv_open(o, "tts.csv",
                       "scene,solver,precision,threads,fluid,walls,t_end,time_reached,status,"
                       "wall_s,s_per_sim_s,frames,substeps,retries,dt_mean,dt_min,iters_mean,"
                       "err_mean,comp_mean,comp_max,outside_max,outside_depth_dx,capped,load1,kernel,error");
    if (!f) return 0;
    if (o->threads_set)
        threads[nthreads++] = o->threads;
    else if (o->suites_default && !o->quick) /* make bench: 2 threads only */
        threads[nthreads++] = P >= 2 ? 2 : 1;
    else {
        threads[nthreads++] = 1;
        if (P >= 2) threads[nthreads++] = 2;
    }
    for (sc = 0; sc < TTS_NSCENE * 4; ++sc)
        for (sv = 0; sv < TTS_NSOLVER; ++sv) {
            X[sc][sv] = sv + 1;
            Y[sc][sv] = NAN;
        }
    printf("\n== time to solution: sph_advance with the library's defaults, frames of %.2f s, to "
           "t = %.2f s; %d processor(s)%s\n",
           TTS_FRAME, t_end, P,
           bench_tts_kernel == 1   ? "; --kernel cubic: cubic B-spline, h = dx, omega 0.5"
           : bench_tts_kernel == 2 ? "; --kernel wendland: Wendland C2, h = 1.3 dx"
                                   : "");
    for (sc = 0; sc < TTS_NSCENE; ++sc)
        if (scenes >> sc & 1) printf("  %-7s %s\n", tts_scene_names[sc], tts_scene_what[sc]);
    printf("  s/sim-s: wall-clock seconds per simulated second (inside sph_advance); comp: mean "
           "over frames of the mean max(rho/rho0-1, 0) and its max; |err|: mean |rho/rho0-1|; "
           "out: most fluid particles outside the container at a frame end, depth: the farthest "
           "one [dx]; load: 1-minute load average after the run (the host is shared)\n");
    printf("  %-7s %-10s %-6s %3s %7s %6s %9s %8s %8s %7s %6s %7s %7s %7s %5s %6s %5s  %s\n",
           "scene", "solver", "prec", "thr", "fluid", "walls", "s/sim-s", "t [s]", "substeps",
           "retries", "iters", "|err|%", "comp %", "cmax %", "out", "depth", "load", "status");
    fflush(stdout);
    for (sc = 0; sc < TTS_NSCENE; ++sc) {
        if (!(scenes >> sc & 1)) continue;
        for (sv = 0; sv < TTS_NSOLVER; ++sv) {
            if (!(solvers >> sv & 1)) continue;
            for (pr = 0; pr < 2; ++pr) {
                if (!(precs >> pr & 1)) continue;
                for (ti = 0; ti < nthreads; ++ti) {
                    tts_result run, *r = &run;
                    const int series = sc * 4 + pr * 2 + ti;
                    const char* c;
                    double rt;
                    set_threads(threads[ti]);
                    if (pr == 0)
                        tts_d(sc, sv, o->quick, t_end, o->max_wall, o->quick ? 0 : 60, r);
                    else
                        bench_tts_f(sc, sv, o->quick, t_end, o->max_wall, o->quick ? 0 : 60, r);
                    ++ncell;
                    rt = r->time > 0 ? r->wall_s / r->time : NAN;
                    printf("  %-7s %-10s %-6s %3d %7.0f %6.0f %9.3g %8.3f %8.0f %7.0f %6.1f %7.3f "
                           "%7.3f %7.2f %5.0f %6.2f %5.1f  %s\n",
                           tts_scene_names[sc], tts_solver_names[sv], pr ? "float" : "double",
                           threads[ti], r->n, r->nb, rt, r->time, r->substeps, r->retries,
                           r->its_mean, 100 * r->err_mean, 100 * r->comp_mean, 100 * r->comp_max,
                           r->outside_max, r->outside_depth, load_average(),
                           r->status > 0   ? sph_status_string((sph_status)r->status)
                           : r->status < 0 ? "scene not built"
                           : r->capped     ? "stopped at --max-wall"
                                           : "ok");
                    if (r->status) printf("          %s\n", r->error);
                    if (r->time > 0) { /* where the time goes, per simulated second */
                        int k;
                        printf("          s/sim-s by stage:");
                        for (k = 0; k < SPH_STAGE_COUNT; ++k)
                            printf(" %s %.3g", stage_label[k], r->stage_s[k] / r->time);
                        printf("\n");
                    }
                    fflush(stdout);
                    fprintf(f,
                            "%s,%s,%s,%d,%.0f,%.0f,%.4f,%.6f,%s,%.3f,%.6g,%d,%.0f,%.0f,%.6g,%.6g,"
                            "%.2f,%.6g,%.6g,%.6g,%.0f,%.3f,%d,%.2f,%s,\"",
                            tts_scene_names[sc], tts_solver_names[sv], pr ? "float" : "double",
                            threads[ti], r->n, r->nb, t_end, r->time,
                            r->status > 0   ? sph_status_string((sph_status)r->status)
                            : r->status < 0 ? "scene not built"
                                            : "ok",
                            r->wall_s, rt, r->frames, r->substeps, r->retries,
                            r->substeps > r->retries ? r->time / (r->substeps - r->retries) : 0,
                            r->dt_min, r->its_mean, r->err_mean, r->comp_mean, r->comp_max,
                            r->outside_max, r->outside_depth, r->capped, load_average(),
                            bench_tts_kernel == 1   ? "cubic"
                            : bench_tts_kernel == 2 ? "wendland"
                                                    : "default");
                    for (c = r->error; *c; ++c) /* the message, CSV-quoted */
                        if (*c == '"')
                            fputs("\"\"", f);
                        else
                            fputc(*c, f);
                    fputs("\"\n", f);
                    fflush(f);
                    if (r->status == 0 && !r->capped) Y[series][sv] = rt;
                    used[series] = 1;
                    if (r->status < 0) ok = 0;
                }
            }
        }
    }
    fclose(f);
    set_threads(1);
    {
        svg_chart ch;
        char label[64];
        svg_begin(&ch, "Time to solution, dam break, sph_advance with defaults",
                  "1 WCSPH, 2 PCISPH enh., 3 PCISPH orig., 4 IISPH, 5 DFSPH, 6 PBF",
                  "wall s per simulated s (runs that finished)");
        svg_log(&ch, 1);
        svg_range(&ch, 0, 0.5, TTS_NSOLVER + 0.5);
        for (sc = 0; sc < TTS_NSCENE * 4; ++sc) {
            if (!used[sc]) continue;
            snprintf(label, sizeof label, "%s %s %dt", tts_scene_names[sc / 4],
                     sc % 4 >= 2 ? "float" : "double", threads[sc % 2]);
            svg_series(&ch, X[sc], Y[sc], TTS_NSOLVER, SVG_LINE_MARKS, label);
        }
        out_path(o, "tts.svg", path, sizeof path);
        svg_write(&ch, path);
        svg_free(&ch);
    }
    printf("%d run(s); CSV %s/tts.csv, chart %s/tts.svg\n", ncell, o->out, o->out);
    return ok;
}

static int find_name(const char* s, const char* const* names, int n) {
    int k;
    for (k = 0; k < n; ++k)
        if (strcmp(s, names[k]) == 0) return k;
    return -1;
}

/* A comma-separated list of names ("all": every one) as a bit mask; 0 if a name is unknown. */
static unsigned name_mask(const char* s, const char* const* names, int n) {
    unsigned m = 0;
    char buf[64];
    if (strcmp(s, "all") == 0) return (1u << n) - 1;
    while (*s) {
        size_t len = strcspn(s, ",");
        int k;
        if (len == 0 || len >= sizeof buf) return 0;
        memcpy(buf, s, len);
        buf[len] = 0;
        if ((k = find_name(buf, names, n)) < 0) return 0;
        m |= 1u << k;
        s += len;
        if (*s == ',') ++s;
    }
    return m;
}

int main(int argc, char** argv) {
    static const char* const suites[] = {"throughput", "scaling", "search", "float", "memory",
                                         "growth",     "model",   "tts",    "run",   "iisph-sweep"};
    static const char* const precisions[] = {"double", "float"};
    enum { NSUITE = 10, NDEFAULT = 8 };
    int (*const fns[NSUITE])(const opts*) = {
        suite_throughput, suite_scaling, suite_search, suite_float,     suite_memory,
        suite_growth,     suite_model,   suite_tts,    suite_run,       suite_iisph_sweep};
    const char *scene_arg = NULL, *solver_arg = NULL;
    const char* scene_names[BENCH_NSCENE];
    const char* solver_names[BENCH_NSOLVER];
    int want[NSUITE] = {0}, any = 0, k, ok = 1;
    double t0 = bench_now();
    opts o;
    memset(&o, 0, sizeof o);
    o.repeats = 3;
    o.threads = 1;
    o.out = "bench/results";
    for (k = 0; k < BENCH_NSCENE; ++k)
        scene_names[k] = bench_scenes[k].name;
    for (k = 0; k < BENCH_NSOLVER; ++k)
        solver_names[k] = bench_solvers[k].name;
    for (k = 1; k < argc; ++k) {
        const char* a = argv[k];
        const char* v = k + 1 < argc ? argv[k + 1] : NULL;
        int s;
        if (strcmp(a, "--quick") == 0) {
            o.quick = 1;
            continue;
        }
        if (a[0] == '-' && a[1] == '-' && !v) {
            fprintf(stderr, "bench: %s needs a value\n", a);
            return 2;
        }
        if (strcmp(a, "--out") == 0)
            o.out = v;
        else if (strcmp(a, "--n") == 0)
            o.n = atof(v);
        else if (strcmp(a, "--repeats") == 0)
            o.repeats = atoi(v);
        else if (strcmp(a, "--steps") == 0)
            o.steps = atoi(v);
        else if (strcmp(a, "--threads") == 0) {
            o.threads = atoi(v);
            o.threads_set = 1;
        } else if (strcmp(a, "--t-end") == 0)
            o.t_end = atof(v);
        else if (strcmp(a, "--max-wall") == 0)
            o.max_wall = atof(v);
        else if (strcmp(a, "--kernel") == 0) {
            if (strcmp(v, "default") == 0)
                bench_tts_kernel = 0;
            else if (strcmp(v, "cubic") == 0)
                bench_tts_kernel = 1;
            else if (strcmp(v, "wendland") == 0)
                bench_tts_kernel = 2;
            else {
                fprintf(stderr, "bench: unknown --kernel %s (default, cubic, wendland)\n", v);
                return 2;
            }
        }
        else if (strcmp(a, "--skin") == 0) {
            bench_tts_skin = atof(v);
            if (!(bench_tts_skin == -1 || (bench_tts_skin >= 0 && bench_tts_skin <= 1))) {
                fprintf(stderr, "bench: --skin %s: -1 (automatic) or in [0, 1]\n", v);
                return 2;
            }
        }
        else if (strcmp(a, "--precision") == 0) {
            if (!(o.precisions = name_mask(v, precisions, 2))) {
                fprintf(stderr, "bench: unknown precision %s (double, float, double,float, all)\n",
                        v);
                return 2;
            }
        } else if (strcmp(a, "--scene") == 0)
            scene_arg = v;
        else if (strcmp(a, "--solver") == 0)
            solver_arg = v;
        else if ((s = find_name(a, suites, NSUITE)) >= 0) {
            want[s] = any = 1;
            continue;
        } else {
            fprintf(stderr,
                    "bench: unknown argument %s (see the comment at the top of bench/bench.c)\n",
                    a);
            return 2;
        }
        ++k;
    }
    if (o.repeats < 1 || o.repeats > 16 || o.threads < 1 || o.t_end < 0 || o.max_wall < 0) {
        fprintf(stderr, "bench: bad --repeats/--threads/--t-end/--max-wall\n");
        return 2;
    }
    /* --scene and --solver: the run suite's names, or for tts a list of its own */
    if (scene_arg && (o.scene = find_name(scene_arg, scene_names, BENCH_NSCENE)) < 0 &&
        !(o.tts_scenes = name_mask(scene_arg, tts_scene_names, TTS_NSCENE))) {
        fprintf(stderr,
                "bench: unknown scene %s (run: dambreak2d, dambreak3d, hydrostatic2d; tts: a "
                "list of 2d, 3d-6k, 3d-59k, or all)\n",
                scene_arg);
        return 2;
    }
    if (solver_arg) o.solver = find_name(solver_arg, solver_names, BENCH_NSOLVER);
    if (want[8] && (o.scene < 0 || o.solver < 0)) {
        fprintf(stderr, "bench: run needs a scene and solver of its own (see --scene, --solver)\n");
        return 2;
    }
    if (solver_arg && !(o.tts_solvers = name_mask(solver_arg, tts_solver_names, TTS_NSOLVER))) {
        fprintf(stderr,
                "bench: unknown solver %s (run: wcsph, pcisph, pcisph-enh, iisph; tts: a list "
                "of those, dfsph and pbf, or all)\n",
                solver_arg);
        return 2;
    }
    if (o.n <= 0) o.n = o.quick ? 2e4 : 1e5;
    if (!any) {
        for (k = 0; k < NDEFAULT; ++k)
            want[k] = 1;
        o.suites_default = 1;
    }
    printf("sph.h %d.%d.%d bench: %s mode, %d processor(s), target %.0f fluid particles, median of "
           "%d%s\n",
           SPH_VERSION_MAJOR, SPH_VERSION_MINOR, SPH_VERSION_PATCH, o.quick ? "quick" : "full",
           max_threads(), o.n, o.repeats,
#ifdef _OPENMP
           ", OpenMP"
#else
           ", no OpenMP"
#endif
    );
    for (k = 0; k < NSUITE && ok; ++k) {
        if (!want[k]) continue;
        ok = fns[k](&o);
        fflush(stdout);
        if (!ok) fprintf(stderr, "bench: suite %s failed\n", suites[k]);
    }
    printf("\nbench: %.0f s\n", bench_now() - t0);
    return ok ? 0 : 1;
}
