/* tests/main.c - runs the registered tests: build/tests [substring ...] */
#include "harness.h"

#include <stdarg.h>
#include <string.h>
#include <time.h>
#ifdef _OPENMP
#include <omp.h>
#endif

static const th_test* const th_tables[] = {tests_kernels, tests_grid, tests_world, tests_wcsph,
                                           tests_compile};

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

int main(int argc, char** argv) {
    int passed = 0, failed = 0, skipped = 0;
    size_t t;
    for (t = 0; t < sizeof(th_tables) / sizeof(th_tables[0]); ++t) {
        const th_test* test;
        for (test = th_tables[t]; test->name; ++test) {
            double t0;
            int a, selected = argc < 2;
            for (a = 1; a < argc; ++a)
                if (strstr(test->name, argv[a])) selected = 1;
            if (!selected) continue;
            th_current = test->name;
            th_failed_checks = 0;
            th_skip_flag = 0;
            fprintf(stdout, "%-48s\n", test->name);
            fflush(stdout);
            t0 = th_now();
            test->fn();
            if (th_failed_checks) {
                ++failed;
                fprintf(stdout, "  FAIL %s (%d failed checks, %.2f s)\n", test->name,
                        th_failed_checks, th_now() - t0);
            } else if (th_skip_flag) {
                ++skipped;
            } else {
                ++passed;
                fprintf(stdout, "  ok   %s (%.2f s)\n", test->name, th_now() - t0);
            }
            fflush(stdout);
        }
    }
    (void)th_current;
    if (skipped) fprintf(stdout, "%d skipped\n", skipped);
    fprintf(stdout, "%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}
