/* tests/harness.h - the tiny test harness of sph.h's tests.

   A test is a void function registered in its file's table:

       static void test_something(void) { CHECK(1 + 1 == 2); CHECK_NEAR(x, 1.0, 1e-6); }
       const th_test tests_area[] = { {"area/something", test_something}, {0, 0} };

   tests/main.c lists every table; `build/tests [filter...]` runs the tests whose name contains
   any filter and ends with the line "N passed, N failed"; tables of long runs (make validate)
   run only with --long. TH_NOTE prints a measured number
   (shown in the output so closing notes can quote it). TH_SKIP ends a test that cannot run in
   this build (e.g. determinism without OpenMP); skips are counted separately. */
#ifndef SPH_TEST_HARNESS_H
#define SPH_TEST_HARNESS_H

#include <stdio.h>

typedef struct th_test {
    const char* name;
    void (*fn)(void);
} th_test;

/* Every test file's table (declared here so that `const` keeps external linkage in C++). */
extern const th_test tests_kernels[];
extern const th_test tests_grid[];
extern const th_test tests_world[];
extern const th_test tests_wcsph[];
extern const th_test tests_compile[];
extern const th_test tests_iisph[];
extern const th_test tests_iisph_long[]; /* long runs: only with --long (make validate) */
extern const th_test tests_dfsph[];
extern const th_test tests_pbf[]; /* position based fluids (issue 17, item 6) */
extern const th_test tests_pcisph[];
extern const th_test tests_pcisph_long[];
extern const th_test tests_operators[];
extern const th_test tests_compressible[];
extern const th_test tests_compressible_long[];
extern const th_test tests_soc[];
extern const th_test tests_soc_long[];
extern const th_test tests_io[];
extern const th_test tests_save[];
extern const th_test tests_reliability[];
extern const th_test tests_reliability_long[];
extern const th_test tests_oom[]; /* out of memory: every allocation failing once */
extern const th_test tests_validation[]; /* methods failing are detected (issue 7) */
extern const th_test tests_scenes[]; /* user scenes through sph_advance with the defaults */
extern const th_test tests_scenes_long[];
extern const th_test tests_hostile[]; /* hostile input (issue 19) */
extern const th_test tests_viscous[]; /* viscous accuracy and dissipation (issue 18) */
extern const th_test tests_viscous_long[];
extern const th_test tests_layers[]; /* layered columns at rest (issue 18, item 1) */
extern const th_test tests_layers_long[];
extern const th_test tests_rt[]; /* Rayleigh-Taylor linear growth (issue 18, item 2) */
extern const th_test tests_rt_long[];
extern const th_test tests_verlet[]; /* neighbour lists kept with a skin (issue 17, item 3) */

void th_fail(const char* file, int line, const char* fmt, ...);
void th_note(const char* fmt, ...);
void th_skip(const char* reason);
int th_skipped(void); /* nonzero after TH_SKIP in the running test */

/* Precision-aware tolerances: TH_EPS is the machine epsilon of sph_real; TH_ROUNDOFF a loose
   round-off level for results of many operations. */
#ifdef SPH_FLOAT
#define TH_EPS 1.1920929e-07
#define TH_ROUNDOFF 1e-5
#else
#define TH_EPS 2.220446049250313e-16
#define TH_ROUNDOFF 1e-12
#endif

#define CHECK(cond)                                                                                \
    do { if (!(cond)) th_fail(__FILE__, __LINE__, "CHECK(%s)", #cond); } while (0)
#define CHECK_MSG(cond, ...)                                                                       \
    do { if (!(cond)) th_fail(__FILE__, __LINE__, __VA_ARGS__); } while (0)
#define CHECK_NEAR(a, b, tol)                                                                      \
    do {                                                                                           \
        double th_a_ = (double)(a), th_b_ = (double)(b), th_t_ = (double)(tol);                    \
        if (!(th_a_ - th_b_ <= th_t_ && th_b_ - th_a_ <= th_t_))                                   \
            th_fail(__FILE__, __LINE__, "CHECK_NEAR(%s, %s, %s): %.10g vs %.10g (diff %.3g)", #a,  \
                    #b, #tol, th_a_, th_b_, th_a_ - th_b_);                                        \
    } while (0)
#define CHECK_LT(a, b)                                                                             \
    do {                                                                                           \
        double th_a_ = (double)(a), th_b_ = (double)(b);                                           \
        if (!(th_a_ < th_b_))                                                                      \
            th_fail(__FILE__, __LINE__, "CHECK_LT(%s, %s): %.10g >= %.10g", #a, #b, th_a_, th_b_); \
    } while (0)
#define CHECK_LE(a, b)                                                                             \
    do {                                                                                           \
        double th_a_ = (double)(a), th_b_ = (double)(b);                                           \
        if (!(th_a_ <= th_b_))                                                                     \
            th_fail(__FILE__, __LINE__, "CHECK_LE(%s, %s): %.10g > %.10g", #a, #b, th_a_, th_b_);  \
    } while (0)
#define CHECK_EQ_INT(a, b)                                                                         \
    do {                                                                                           \
        long long th_a_ = (long long)(a), th_b_ = (long long)(b);                                  \
        if (th_a_ != th_b_)                                                                        \
            th_fail(__FILE__, __LINE__, "CHECK_EQ_INT(%s, %s): %lld vs %lld", #a, #b, th_a_,      \
                    th_b_);                                                                        \
    } while (0)
#define TH_NOTE(...) th_note(__VA_ARGS__)

/* A step at a dt the test chose itself, in the unit and validation tests written before the
   iterative solvers reported non-convergence: SPH_ERR_NOT_CONVERGED (the step was taken with
   the solve's last pressure) counts as taken, and th_not_converged() says how often it
   happened. Scenes of what users get run through sph_advance instead (tests/test_scenes.c). */
int th_taken(int status, int not_converged);
int th_not_converged(void);
#define th_step(w, dt) ((sph_status)th_taken((int)sph_step((w), (dt)), (int)SPH_ERR_NOT_CONVERGED))
#define TH_SKIP(reason) do { th_skip(reason); return; } while (0)

#endif
