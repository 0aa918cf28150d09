/* tests/main.c - runs the registered tests: build/tests [substring ...] */
#include "harness.h"

#include <stdarg.h>
#include <string.h>
#include <time.h>
#ifdef _OPENMP
#include <omp.h>
#endif

static int th_nc;
int th_taken(int status, int not_converged) {
    if (status != not_converged) return status;
    ++th_nc;
    return 0;
}
int th_not_converged(void) { return th_nc; }

static const th_test* const th_tables[] = {tests_kernels, tests_grid, tests_operators, tests_world, tests_io, tests_save, tests_reliability, tests_wcsph,
                                           tests_pcisph, tests_iisph, tests_dfsph, tests_compressible, tests_soc,
                                           tests_compile, tests_oom, tests_validation, tests_scenes,
                                           tests_hostile, tests_viscous, tests_layers, tests_rt};
static const th_test* const th_long_tables[] = {tests_pcisph_long, tests_iisph_long,
                                                tests_compressible_long, tests_soc_long,
                                                tests_reliability_long, tests_scenes_long,
                                                tests_viscous_long, tests_layers_long,
                                                tests_rt_long};

static int th_failed_checks;
static int th_skip_flag;
static const char* th_current;

void th_fail(const char* file, int line, const char* fmt, ...) {
    va_list ap;
    if (th_failed_checks < 10) { /* the first few failures of a test in full */
        fprintf(stdout, "    %s:%d: ", file, line);
        va_start(ap, fmt);
        vfprintf(stdout, fmt, ap);
        va_end(ap);
        fputc('\n', stdout);
    }
    ++th_failed_checks;
}

void th_note(const char* fmt, ...) {
    va_list ap;
    fprintf(stdout, "    note: ");
    va_start(ap, fmt);
    vfprintf(stdout, fmt, ap);
    va_end(ap);
    fputc('\n', stdout);
    fflush(stdout);
}

void th_skip(const char* reason) {
    th_skip_flag = 1;
    fprintf(stdout, "    skip: %s\n", reason);
}

int th_skipped(void) { return th_skip_flag; }

static double th_now(void) {
#ifdef _OPENMP
    return omp_get_wtime();
#else
    return (double)clock() / CLOCKS_PER_SEC;
#endif
}

static void th_run_table(const th_test* table, int argc, char** argv, int* passed, int* failed,
                         int* skipped) {
    const th_test* test;
    for (test = table; test->name; ++test) {
        double t0;
        int a, selected = 1, filters = 0;
        for (a = 1; a < argc; ++a) {
            if (strcmp(argv[a], "--long") == 0) continue;
            if (!filters) selected = 0;
            ++filters;
            if (strstr(test->name, argv[a])) selected = 1;
        }
        if (!selected) continue;
        th_current = test->name;
        th_failed_checks = 0;
        th_skip_flag = 0;
        fprintf(stdout, "%-48s\n", test->name);
        fflush(stdout);
        t0 = th_now();
        test->fn();
        if (th_failed_checks) {
            ++*failed;
            fprintf(stdout, "  FAIL %s (%d failed checks, %.2f s)\n", test->name, th_failed_checks,
                    th_now() - t0);
        } else if (th_skip_flag) {
            ++*skipped;
        } else {
            ++*passed;
            fprintf(stdout, "  ok   %s (%.2f s)\n", test->name, th_now() - t0);
        }
        fflush(stdout);
    }
}

int main(int argc, char** argv) {
    int passed = 0, failed = 0, skipped = 0, a, with_long = 0;
    size_t t;
    for (a = 1; a < argc; ++a)
        if (strcmp(argv[a], "--long") == 0) with_long = 1;
    for (t = 0; t < sizeof(th_tables) / sizeof(th_tables[0]); ++t)
        th_run_table(th_tables[t], argc, argv, &passed, &failed, &skipped);
    if (with_long)
        for (t = 0; t < sizeof(th_long_tables) / sizeof(th_long_tables[0]); ++t)
            th_run_table(th_long_tables[t], argc, argv, &passed, &failed, &skipped);
    (void)th_current;
    if (skipped) fprintf(stdout, "%d skipped\n", skipped);
    fprintf(stdout, "%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}
