/* bench/bench.c - throughput of the WCSPH step on the shared scenes, and IISPH's time-step sweep.
   Build: cc -O2 -fopenmp -I. bench/bench.c -o bench -lm
   Run:   ./bench [scene = dambreak2d] [particles per column width = 100] [steps = 200]
                  [repeats = 3] [csv file]
          ./bench iisph-sweep [particles over the 0.5 m depth = 40] [csv file]
   The sweep runs a hydrostatic tank (1 m wide, 0.5 m deep) with IISPH for one simulated second at
   several time steps and reports, like seed 003's Table 2, the mean iterations, the time spent in
   the pressure solve and in the neighbour search, and the overall time per simulated second.
   For each thread count from 1 to the number of processors it runs the scene's first `steps`
   steps (after 20 warm-up steps) `repeats` times and reports the median: fluid particle-steps
   per second, time per step and per stage, neighbour pairs per particle and bytes per particle
   (sph_world_memory / fluid particles, neighbour lists included). */
#define SPH_IMPLEMENTATION
#include "sph.h"
#include "examples/scenes.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

typedef struct bench_run {
    double step_s, stage_s[SPH_STAGE_COUNT], pairs, bytes;
    size_t n, nb;
} bench_run;

static int cmp_double(const void* a, const void* b) {
    const double x = *(const double*)a, y = *(const double*)b;
    return x < y ? -1 : x > y;
}

static int build(sph_world* w, const char* scene, int res) {
    sph_world_def def = sph_world_def_default(strstr(scene, "3d") ? 3 : 2);
    if (strncmp(scene, "dambreak", 8) == 0) return scene_dam_break(w, def, 0.5, res, NULL) == SPH_OK;
    if (strncmp(scene, "hydrostatic", 11) == 0)
        return scene_hydrostatic(w, def, 1.0, 0.5, res) == SPH_OK;
    fprintf(stderr, "unknown scene %s (dambreak2d, dambreak3d, hydrostatic2d, hydrostatic3d)\n", scene);
    return 0;
}

static int run_once(const char* scene, int res, int steps, bench_run* r) {
    sph_world w;
    double dt;
    int s, k;
    if (!build(&w, scene, res)) return 0;
    dt = (double)sph_stable_dt(&w, SPH_SOLVER_WCSPH);
    for (s = 0; s < 20; ++s)
        if (sph_step(&w, (sph_real)dt) != SPH_OK) { fprintf(stderr, "%s\n", w.error); return 0; }
    memset(r, 0, sizeof(*r));
    w.step_time_total = 0;
    for (k = 0; k < SPH_STAGE_COUNT; ++k) w.stage_time_total[k] = 0;
    for (s = 0; s < steps; ++s)
        if (sph_step(&w, (sph_real)dt) != SPH_OK) { fprintf(stderr, "%s\n", w.error); return 0; }
    r->step_s = w.step_time_total / steps;
    for (k = 0; k < SPH_STAGE_COUNT; ++k) r->stage_s[k] = w.stage_time_total[k] / steps;
    r->pairs = (double)w.stats.pairs / (double)w.n;
    r->bytes = (double)sph_world_memory(&w) / (double)w.n;
    r->n = w.n;
    r->nb = w.nb;
    sph_world_free(&w);
    return 1;
}

/* Seed 003 Table 2 for our solver: the time step against iterations and time to solution. */
static int iisph_sweep(int res, const char* csv) {
    /* in units of sqrt(dx / g); seed 003's Table 2 spans 0.0087-0.013 of its sqrt(h / g) */
    static const double fs[] = {0.005, 0.0075, 0.01, 0.015, 0.02, 0.03, 0.05, 0.08};
    const double dx = 0.5 / res, unit = sqrt(dx / 9.81);
    FILE* f = csv ? fopen(csv, "w") : NULL;
    size_t k;
    if (f) fprintf(f, "dt,dt_units,steps,iterations,pressure_s,neighbors_s,overall_s\n");
    printf("IISPH hydrostatic tank, %d particles deep, 1 s simulated, %d thread(s)\n", res,
#ifdef _OPENMP
           omp_get_max_threads()
#else
           1
#endif
    );
    printf("%9s %15s %7s %10s %12s %13s %11s\n", "dt [s]", "dt/sqrt(dx/g)", "steps", "iterations",
           "pressure [s]", "neighbors [s]", "overall [s]");
    for (k = 0; k < sizeof(fs) / sizeof(fs[0]); ++k) {
        const double dt = fs[k] * unit;
        sph_world_def def = sph_world_def_default(2);
        sph_world w;
        double its = 0;
        int steps = 0;
        def.solver = SPH_SOLVER_IISPH;
        if (scene_hydrostatic(&w, def, 1.0, 0.5, res) != SPH_OK) { fprintf(stderr, "%s\n", scene_error); return 1; }
        while (w.time < 1.0 - 1e-9) {
            if (sph_step(&w, (sph_real)dt) != SPH_OK) { fprintf(stderr, "%s\n", w.error); return 1; }
            its += w.stats.iterations;
            ++steps;
        }
        printf("%9.6f %15.4f %7d %10.1f %12.3f %13.3f %11.3f\n", dt, fs[k], steps, its / steps,
               w.stage_time_total[SPH_STAGE_PRESSURE], w.stage_time_total[SPH_STAGE_NEIGHBORS],
               w.step_time_total);
        if (f) fprintf(f, "%.6f,%.4f,%d,%.2f,%.4f,%.4f,%.4f\n", dt, fs[k], steps, its / steps,
                       w.stage_time_total[SPH_STAGE_PRESSURE], w.stage_time_total[SPH_STAGE_NEIGHBORS],
                       w.step_time_total);
        sph_world_free(&w);
    }
    if (f) fclose(f);
    return 0;
}

int main(int argc, char** argv) {
    const char* scene = argc > 1 ? argv[1] : "dambreak2d";
    const int res = argc > 2 ? atoi(argv[2]) : 100, steps = argc > 3 ? atoi(argv[3]) : 200;
    const int repeats = argc > 4 ? atoi(argv[4]) : 3;
    const char* csv = argc > 5 ? argv[5] : NULL;
    static const char* stage_names[SPH_STAGE_COUNT] = {"boundary", "neighbors", "density",
                                                       "pressure", "forces", "integrate"};
    int maxthreads = 1, t, k, rep;
    double base = 0;
    FILE* f = NULL;
    if (strcmp(scene, "iisph-sweep") == 0)
        return iisph_sweep(argc > 2 ? atoi(argv[2]) : 40, argc > 3 ? argv[3] : NULL);
#ifdef _OPENMP
    maxthreads = omp_get_num_procs();
#endif
    if (csv) {
        f = fopen(csv, "w");
        if (f) fprintf(f, "scene,res,threads,n,nb,step_ms,particle_steps_per_s,pairs_per_particle,"
                          "bytes_per_particle\n");
    }
    printf("scene %s, %d particles per width, %d steps, median of %d, precision %s\n", scene, res,
           steps, repeats, sizeof(sph_real) == 8 ? "double" : "float");
    for (t = 1; t <= maxthreads; ++t) {
        bench_run runs[16];
        double times[16];
        bench_run* med;
#ifdef _OPENMP
        omp_set_num_threads(t);
#endif
        for (rep = 0; rep < repeats && rep < 16; ++rep) {
            if (!run_once(scene, res, steps, &runs[rep])) return 1;
            times[rep] = runs[rep].step_s;
        }
        qsort(times, (size_t)rep, sizeof(double), cmp_double);
        med = &runs[0];
        for (k = 0; k < rep; ++k)
            if (runs[k].step_s == times[rep / 2]) med = &runs[k];
        if (t == 1) base = med->step_s;
        printf("threads %d: n %zu (+%zu wall), %.3f ms/step, %.3g particle-steps/s, speedup %.2f, "
               "%.1f pairs/particle, %.0f bytes/particle\n  stages (ms):",
               t, med->n, med->nb, 1e3 * med->step_s, (double)med->n / med->step_s,
               base / med->step_s, med->pairs, med->bytes);
        for (k = 0; k < SPH_STAGE_COUNT; ++k) printf(" %s %.3f", stage_names[k], 1e3 * med->stage_s[k]);
        printf("\n");
        if (f)
            fprintf(f, "%s,%d,%d,%zu,%zu,%.6f,%.6g,%.2f,%.1f\n", scene, res, t, med->n, med->nb,
                    1e3 * med->step_s, (double)med->n / med->step_s, med->pairs, med->bytes);
    }
    if (f) fclose(f);
    return 0;
}
