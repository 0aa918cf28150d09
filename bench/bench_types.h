/* bench/bench_types.h - what the two precisions of the benchmark share: the scene and solver
   tables and the result record (plain double, so the float copy can report to the driver). */
#ifndef SPH_BENCH_TYPES_H
#define SPH_BENCH_TYPES_H

#include <stdint.h>
#include <time.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#if defined(__GNUC__) || defined(__clang__)
#define BENCH_FN static __attribute__((unused)) /* each precision's copy uses only some */
#else
#define BENCH_FN static
#endif

enum { BENCH_DAMBREAK2D, BENCH_DAMBREAK3D, BENCH_HYDROSTATIC2D, BENCH_NSCENE };
enum { BENCH_WCSPH, BENCH_PCISPH, BENCH_PCISPH_ENH, BENCH_IISPH, BENCH_NSOLVER };

typedef struct bench_scene {
    const char* name;
    int dim;
    const char* what;
} bench_scene;

static const bench_scene bench_scenes[BENCH_NSCENE] = {
    {"dambreak2d", 2, "Martin & Moyce column a x 2a in a 5a x 3a tank, a = 0.5 m"},
    {"dambreak3d", 3, "the same column a deep, in a tank a deep"},
    {"hydrostatic2d", 2, "water 0.5 m deep in a 1 m tank, at rest"},
};

typedef struct bench_solver {
    const char* name;
    int sph_solver; /* sph_solver value */
} bench_solver;

static const bench_solver bench_solvers[BENCH_NSOLVER] = {
    {"wcsph", 0}, {"pcisph", 2}, {"pcisph-enh", 2}, {"iisph", 1}};

typedef struct bench_result {
    double n, nb, dt;
    double step_s;          /* wall-clock seconds per step                              */
    double stage_s[8];      /* per sph_stage                                            */
    double iterations;      /* mean solver iterations per step (0 for WCSPH)            */
    double pairs;           /* fluid neighbour pairs per fluid particle                 */
    double bytes;           /* sph_world_memory / fluid particles (or the baseline's)   */
    double grid_s, lists_s; /* neighbour search parts (search suite, baseline)       */
    double agree;           /* baseline: max position difference to sph.h [spacings]   */
    uint64_t hash;          /* state after the timed steps                              */
} bench_result;

static double bench_now(void) {
#ifdef _OPENMP
    return omp_get_wtime();
#else
    return (double)clock() / CLOCKS_PER_SEC;
#endif
}

#endif
