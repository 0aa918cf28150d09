/* bench/bench_float.c - the float copy of the benchmark's measuring code (bench/bench_core.h),
   linked into the same program as the double copy, so one run measures both precisions. */
#define SPH_FLOAT
#define SPH_STATIC
#define SPH_IMPLEMENTATION
#include "sph.h"
#include "examples/scenes.h"
#include "bench/bench_types.h"
#include "bench/baseline.h"
#define BX(name) name##_f
#include "bench/bench_core.h"

/* the entry points the driver calls */
int bench_run_f(int scene, int solver, double target, int warm, int steps, bench_result* r) {
    return run_f(scene, solver, target, warm, steps, r);
}
int bench_tts_f(int scene, int solver, int quick, double t_end, double max_wall, double progress,
                tts_result* r) {
    return tts_f(scene, solver, quick, t_end, max_wall, progress, r);
}
