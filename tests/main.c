/* tests/main.c - runs the registered tests: build/tests [-j N] [--long] [substring ...]

   -j N runs up to N tests at once, each in its own forked process (POSIX; default: the number
   of online processors, at most 4, or the environment variable SPH_TEST_JOBS). A test's output
   is printed whole when it ends, so the order of tests in the log can differ from their order
   in the tables; the summary line is the same. A test that crashes is reported as failed with
   its signal instead of ending the run. -j 1 (and any platform without fork) runs the tests one
   after another in this process, as before. The parent process itself never runs OpenMP code,
   so every child starts its own OpenMP runtime. */
#if !defined(_POSIX_C_SOURCE) && !defined(_WIN32)
#define _POSIX_C_SOURCE 200809L /* fileno, fork, sysconf */
#endif
#include "harness.h"

#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#if defined(__unix__) || defined(__APPLE__)
#include <sys/wait.h>
#include <unistd.h>
#define TH_FORK 1
#else
#define TH_FORK 0
#endif
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
                                           tests_pcisph, tests_iisph, tests_dfsph, tests_pbf, tests_compressible, tests_soc,
                                           tests_compile, tests_oom, tests_validation, tests_scenes,
                                           tests_hostile, tests_viscous, tests_layers, tests_rt,
                                           tests_verlet};
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

/* Is the test selected by the command line's substrings (none: every test)? */
static int th_selected(const th_test* test, int argc, char** argv) {
    int a, selected = 1, filters = 0;
    for (a = 1; a < argc; ++a) {
        if (strcmp(argv[a], "--long") == 0) continue;
        if (strcmp(argv[a], "-j") == 0) { ++a; continue; }
        if (!filters) selected = 0;
        ++filters;
        if (strstr(test->name, argv[a])) selected = 1;
    }
    return selected;
}

enum { TH_PASSED = 0, TH_FAILED = 1, TH_SKIPPED = 2 };

/* Runs one test in this process, prints its lines, returns TH_PASSED/FAILED/SKIPPED. */
static int th_run_one(const th_test* test) {
    double t0;
    th_current = test->name;
    th_failed_checks = 0;
    th_skip_flag = 0;
    fprintf(stdout, "%-48s\n", test->name);
    fflush(stdout);
    t0 = th_now();
    test->fn();
    if (th_failed_checks) {
        fprintf(stdout, "  FAIL %s (%d failed checks, %.2f s)\n", test->name, th_failed_checks,
                th_now() - t0);
        fflush(stdout);
        return TH_FAILED;
    }
    if (th_skip_flag) { fflush(stdout); return TH_SKIPPED; }
    fprintf(stdout, "  ok   %s (%.2f s)\n", test->name, th_now() - t0);
    fflush(stdout);
    return TH_PASSED;
}

static void th_count(int result, int* passed, int* failed, int* skipped) {
    if (result == TH_PASSED) ++*passed;
    else if (result == TH_SKIPPED) ++*skipped;
    else ++*failed;
}

#if TH_FORK
/* One running child: its test, process id and the temporary file holding its output. */
typedef struct th_job {
    const th_test* test;
    pid_t pid;
    FILE* out;
} th_job;

/* Waits for one child of jobs[0..*n), prints its output, counts its result, removes it. */
static void th_reap(th_job* jobs, int* n, int* passed, int* failed, int* skipped) {
    int status = 0, k, ch, result = TH_FAILED;
    const pid_t pid = wait(&status);
    for (k = 0; k < *n; ++k)
        if (jobs[k].pid == pid) break;
    if (k == *n) return; /* not ours (cannot happen: the parent has no other children) */
    rewind(jobs[k].out);
    while ((ch = fgetc(jobs[k].out)) != EOF) fputc(ch, stdout);
    fclose(jobs[k].out);
    if (WIFEXITED(status) && WEXITSTATUS(status) <= TH_SKIPPED) result = WEXITSTATUS(status);
    else if (WIFSIGNALED(status))
        fprintf(stdout, "  FAIL %s (killed by signal %d)\n", jobs[k].test->name, WTERMSIG(status));
    else
        fprintf(stdout, "  FAIL %s (exit status %d)\n", jobs[k].test->name, WEXITSTATUS(status));
    fflush(stdout);
    th_count(result, passed, failed, skipped);
    jobs[k] = jobs[--*n];
}
#endif

/* Runs the selected tests of the given tables, up to `jobs` at a time. */
static void th_run_tables(const th_test* const* tables, size_t ntables, int argc, char** argv,
                          int jobs, int* passed, int* failed, int* skipped) {
    size_t t;
    const th_test* test;
#if TH_FORK
    th_job running[16];
    int n = 0;
    if (jobs > 16) jobs = 16;
    if (jobs > 1) {
        for (t = 0; t < ntables; ++t)
            for (test = tables[t]; test->name; ++test) {
                FILE* out;
                pid_t pid;
                if (!th_selected(test, argc, argv)) continue;
                while (n >= jobs) th_reap(running, &n, passed, failed, skipped);
                fflush(stdout);
                out = tmpfile();
                pid = out ? fork() : -1;
                if (pid == 0) { /* the child: run the test with stdout into the file */
                    dup2(fileno(out), 1);
                    exit(th_run_one(test));
                }
                if (pid < 0) { /* no file or no process: run it here */
                    if (out) fclose(out);
                    th_count(th_run_one(test), passed, failed, skipped);
                    continue;
                }
                running[n].test = test;
                running[n].pid = pid;
                running[n].out = out;
                ++n;
            }
        while (n > 0) th_reap(running, &n, passed, failed, skipped);
        return;
    }
#endif
    (void)jobs;
    for (t = 0; t < ntables; ++t)
        for (test = tables[t]; test->name; ++test)
            if (th_selected(test, argc, argv))
                th_count(th_run_one(test), passed, failed, skipped);
}

static int th_default_jobs(void) {
    const char* env = getenv("SPH_TEST_JOBS");
    long n = 1;
    if (env && *env) return atoi(env) > 0 ? atoi(env) : 1;
#if TH_FORK && defined(_SC_NPROCESSORS_ONLN)
    n = sysconf(_SC_NPROCESSORS_ONLN);
#endif
    return n < 1 ? 1 : n > 4 ? 4 : (int)n;
}

int main(int argc, char** argv) {
    int passed = 0, failed = 0, skipped = 0, a, with_long = 0, jobs = th_default_jobs();
    for (a = 1; a < argc; ++a) {
        if (strcmp(argv[a], "--long") == 0) with_long = 1;
        if (strcmp(argv[a], "-j") == 0 && a + 1 < argc) jobs = atoi(argv[a + 1]) > 0 ? atoi(argv[a + 1]) : 1;
    }
    th_run_tables(th_tables, sizeof(th_tables) / sizeof(th_tables[0]), argc, argv, jobs, &passed,
                  &failed, &skipped);
    if (with_long)
        th_run_tables(th_long_tables, sizeof(th_long_tables) / sizeof(th_long_tables[0]), argc,
                      argv, jobs, &passed, &failed, &skipped);
    (void)th_current;
    if (skipped) fprintf(stdout, "%d skipped\n", skipped);
    fprintf(stdout, "%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}
