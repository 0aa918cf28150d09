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

/* Time to solution (the tts suite): scenes and solvers as a user sets them up, library defaults. */
enum { TTS_DAM2D, TTS_DAM3D_COARSE, TTS_DAM3D_FINE, TTS_NSCENE };
enum { TTS_WCSPH, TTS_PCISPH_ENH, TTS_PCISPH, TTS_IISPH, TTS_DFSPH, TTS_PBF, TTS_NSOLVER };

static const char* const tts_scene_names[TTS_NSCENE] = {"2d", "3d-6k", "3d-59k"};
static const char* const tts_scene_what[TTS_NSCENE] = {
    "scene_dam_break: column 0.5 x 1 m in a 2.5 x 1.5 m tank, dx = a/40 (a/10 --quick)",
    "DamBreakModel: 19^3 cube, dx 0.05 m, in a 4 x 3 x 1.5 m box, nu 0.01",
    "DamBreakModel: 39^3 cube, dx 0.025 m, in a 4 x 3 x 1.5 m box, nu 0.01"};
static const char* const tts_solver_names[TTS_NSOLVER] = {"wcsph", "pcisph-enh", "pcisph",
                                                          "iisph", "dfsph", "pbf"};

#define TTS_FRAME 0.02 /* one frame, 1/50 s: the duration of each sph_advance call */

/* tts --kernel: 0 the library's default (Wendland C2, h = 1.3 dx), 1 the cubic B-spline at
   h = dx with the Jacobi weight 0.5 in 3D (support 2 dx: 33 neighbours in 3D against 74, the
   peer's kernel; see README "Time to solution"). Defined in bench.c, read by both precisions. */
extern int bench_tts_kernel;
extern double bench_tts_skin;

typedef struct tts_result {
    double n, nb;          /* fluid and wall particles                                          */
    double time;           /* simulated time reached [s]                                        */
    double wall_s;         /* wall-clock seconds inside sph_advance, the failed call included   */
    double substeps;       /* sub-steps over all calls, retries included (a failed call's too)  */
    double retries;        /* sub-steps rolled back                                             */
    double dt_min;         /* smallest successful sub-step [s]                                  */
    double err_mean;       /* mean over frame ends of the mean |rho/rho0 - 1|                   */
    double comp_mean;      /* mean over frame ends of the mean max(rho/rho0 - 1, 0)             */
    double comp_max;       /* max over frame ends and particles of rho/rho0 - 1                 */
    double its_mean;       /* mean over frame ends of the last sub-step's solver iterations     */
    double outside_max;    /* max over frame ends of the fluid particles outside the container  */
    double outside_depth;  /* the farthest any was outside it [particle spacings]               */
    double stage_s[SPH_STAGE_COUNT]; /* wall-clock seconds per stage (w.stage_time_total)   */
    int frames;            /* frames completed                                                  */
    int status;            /* sph_status of the call that failed (0: none), -1: scene not built */
    int capped;            /* stopped by --max-wall                                             */
    char error[SPH_ERROR_SIZE]; /* w.error of the failed call                                  */
} tts_result;

static double bench_now(void) {
#ifdef _OPENMP
    return omp_get_wtime();
#else
    return (double)clock() / CLOCKS_PER_SEC;
#endif
}

#endif
