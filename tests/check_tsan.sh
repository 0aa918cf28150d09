#!/usr/bin/env bash
# tests/check_tsan.sh - ThreadSanitizer over sph.h's OpenMP parallel loops.
#
#   tests/check_tsan.sh [BUILD_DIR]      (default build/tsan; run from anywhere)
#
# How: clang with LLVM's OpenMP runtime (libomp) and -fsanitize=thread, run with the Archer
# OMPT tool (libarcher.so, shipped in libomp-14-dev), which tells TSan about OpenMP's
# synchronisation (fork/join, barriers, reductions). libomp itself is not instrumented, so TSan
# is also told to ignore non-instrumented modules (the runtime's own memory accesses); without
# this, a report from pthread_mutex_init/lock inside libomp's team set-up appears.
# gcc's libgomp is not used: TSan cannot see its futex-based barriers and reports false races.
#
# What runs (OMP_NUM_THREADS=2): the tests whose worlds exceed the 2048-particle threshold of
# SPH__OMP_FOR (the */determinism_1_vs_2_threads tests and reliability/golden_hash_threads) and
# a small driver for the public operators (sph_op_*) on 3000 points, which no test runs in
# parallel. Any ThreadSanitizer report fails the run (exit 66).
#
# Debian packages needed: clang (clang-14), libomp-14-dev (libomp + libarcher.so),
# libclang-rt-14-dev (the TSan runtime). Missing ones: prints SKIP and exits 0.
set -u
cd "$(dirname "$0")/.." || exit 1
B=${1:-build/tsan}
CLANG=${CLANG_TSAN:-clang}
CLANGXX=${CLANGXX_TSAN:-clang++}
LIMIT=${TSAN_TIME_LIMIT:-600}   # seconds for each run (normally ~1 min on 2 cores)

skip() { echo "SKIP: check_tsan: $*"; exit 0; }
command -v "$CLANG" >/dev/null 2>&1 || skip "$CLANG not found (apt-get install clang)"
command -v "$CLANGXX" >/dev/null 2>&1 || skip "$CLANGXX not found (apt-get install clang)"
RESDIR=$("$CLANG" -print-resource-dir 2>/dev/null)
LLVMLIB=$(dirname "$(dirname "$(dirname "$RESDIR")")")   # /usr/lib/llvm-14/lib/clang/14.x -> /usr/lib/llvm-14/lib
ARCHER=${ARCHER_LIB:-}
if [ -z "$ARCHER" ]; then
    for f in "$LLVMLIB/libarcher.so" /usr/lib/llvm-*/lib/libarcher.so; do
        [ -f "$f" ] && { ARCHER=$f; break; }
    done
fi
[ -n "$ARCHER" ] && [ -f "$ARCHER" ] || skip "libarcher.so not found (apt-get install libomp-14-dev)"
mkdir -p "$B" || exit 1
printf 'int main(void){return 0;}\n' > "$B/probe.c"
"$CLANG" -fsanitize=thread -fopenmp=libomp "$B/probe.c" -o "$B/probe" >/dev/null 2>&1 \
    || skip "clang cannot link -fsanitize=thread -fopenmp=libomp (apt-get install libomp-14-dev libclang-rt-14-dev)"

# the test sources are the Makefile's TEST_SRC (one list to keep up to date)
TEST_SRC=$(make -s --no-print-directory print-test-src) || skip "cannot read TEST_SRC from the Makefile"
FLAGS="-fsanitize=thread -fopenmp=libomp -g -O1 -fno-omit-frame-pointer -Wall -Wextra -Wpedantic -Wshadow"

echo "check_tsan: building into $B ($("$CLANG" --version | head -1); Archer: $ARCHER)"
set -e
"$CLANGXX" $FLAGS -std=c++11 -c tests/compile_cpp.cpp -o "$B/compile_cpp.o"
# shellcheck disable=SC2086
"$CLANG" $FLAGS -std=c99 $TEST_SRC "$B/compile_cpp.o" -o "$B/tests" -lm -lstdc++

# The operators on a jittered 2D lattice of 3000 points (> 2048: the loops run in parallel).
cat > "$B/ops_driver.c" <<'EOF'
#define SPH_IMPLEMENTATION
#include "sph.h"
#include <stdio.h>
int main(void) {
    enum { NX = 60, NY = 50, N = NX * NY };
    static sph_real x[N * 2], vol[N], B[N * 4], f[N], grad[N * 2], div[N], dx[N * 2], lap[N];
    const sph_real ds = 0.01, lo[2] = {0, 0}, hi[2] = {NX * 0.01, NY * 0.01};
    const int periodic[2] = {1, 1};
    sph_kernel k; sph_grid g; sph_neighbors nl;
    size_t i, singular;
    unsigned s = 12345u;
    memset(&g, 0, sizeof g); memset(&nl, 0, sizeof nl);
    for (i = 0; i < N; ++i) {
        s = s * 1664525u + 1013904223u;
        x[2 * i] = ((sph_real)(i % NX) + 0.5 + 0.2 * ((sph_real)(s >> 8) / 16777216.0 - 0.5)) * ds;
        x[2 * i + 1] = ((sph_real)(i / NX) + 0.5) * ds;
        f[i] = x[2 * i] * 3 + x[2 * i + 1];
    }
    if (sph_kernel_init(&k, SPH_KERNEL_WENDLAND_C2, 2, 1.3 * ds) != SPH_OK) return 2;
    if (sph_grid_init(&g, 2, k.radius, periodic, lo, hi) != SPH_OK) return 2;
    if (sph_grid_build(&g, x, N) != SPH_OK) return 2;
    if (sph_neighbors_build(&nl, &g, x, x, N, k.radius, 1) != SPH_OK) return 2;
    sph_op_volume(&g, &nl, &k, x, N, vol);
    singular = sph_op_correction(&g, &nl, &k, x, vol, N, B);
    sph_op_gradient(&g, &nl, &k, x, vol, B, f, 1, N, grad);
    sph_op_divergence(&g, &nl, &k, x, vol, B, grad, N, div);
    sph_op_shift(&g, &nl, &k, x, vol, N, dx);
    sph_op_laplacian(&g, &nl, &k, x, vol, B, f, 1, N, grad, lap);
    printf("ops_driver: %d points, %lu singular, grad[0] = (%g, %g), lap[0] = %g\n", N,
           (unsigned long)singular, (double)grad[0], (double)grad[1], (double)lap[0]);
    sph_neighbors_free(&nl); sph_grid_free(&g);
    return 0;
}
EOF
"$CLANG" $FLAGS -std=c99 -I. "$B/ops_driver.c" -o "$B/ops_driver" -lm
set +e

export OMP_NUM_THREADS=2
export OMP_TOOL_LIBRARIES="$ARCHER"
export TSAN_OPTIONS="ignore_noninstrumented_modules=1 exitcode=66 halt_on_error=0 second_deadlock_stack=1${TSAN_EXTRA_OPTIONS:+ $TSAN_EXTRA_OPTIONS}"
[ -f tests/tsan.supp ] && TSAN_OPTIONS="$TSAN_OPTIONS suppressions=$PWD/tests/tsan.supp"

status=0
run() { # name log cmd...
    local name=$1 log=$2; shift 2
    local t0=$SECONDS rc
    timeout "$LIMIT" "$@" > "$log" 2>&1
    rc=$?
    local races
    races=$(grep -c '^WARNING: ThreadSanitizer' "$log")
    echo "check_tsan: $name: exit $rc, $races ThreadSanitizer report(s), $((SECONDS - t0)) s (log $log)"
    if [ "$rc" -ne 0 ] || [ "$races" -ne 0 ]; then
        status=1
        grep -A40 '^WARNING: ThreadSanitizer' "$log" | head -200
        tail -5 "$log"
    fi
}
export ARCHER_OPTIONS="verbose=1"
run "tests (determinism, golden_hash_threads)" "$B/tests.log" \
    "./$B/tests" -j 1 determinism golden_hash_threads
run "operators driver" "$B/ops_driver.log" "./$B/ops_driver"
if ! grep -q 'Archer detected OpenMP application with TSan' "$B/tests.log"; then
    echo "check_tsan: Archer did not load ($ARCHER): OpenMP synchronisation unknown to TSan"
    status=1
fi
if [ $status -eq 0 ]; then echo "check_tsan: OK, no data races"; else echo "check_tsan: FAILED"; fi
exit $status
