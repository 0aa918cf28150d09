#!/usr/bin/env bash
# examples/run_examples.sh - builds example programs into build/ and runs each one with its own
# output directory out/examples/NAME/, as a smoke test: it stops at the first example that does
# not build or whose checks fail (non-zero exit), and prints each example's run time.
#
#   examples/run_examples.sh                  the four checked examples (list below)
#   examples/run_examples.sh multiphase ...   only the ones named
#   CC=clang examples/run_examples.sh         another compiler (CFLAGS overrides the flags too)
#
# Works from any directory (it changes to the repository root). Each build is the one command
# given in the example's header: cc -O2 -std=c99 -fopenmp -I. examples/NAME.c -o build/NAME -lm
set -u
export LC_ALL=C # a decimal point in the timings
cd "$(dirname "$0")/.." || exit 1

CC=${CC:-cc}
CFLAGS=${CFLAGS:--O2 -std=c99 -fopenmp}
if [ $# -gt 0 ]; then names=("$@"); else names=(moving_boundary external_force multiphase float_build); fi

now() { # seconds, with a fraction where bash has EPOCHREALTIME (bash 5)
    if [ -n "${EPOCHREALTIME:-}" ]; then echo "$EPOCHREALTIME"; else date +%s; fi
}

mkdir -p build
summary=""
for name in "${names[@]}"; do
    out="out/examples/$name"
    mkdir -p "$out"
    echo "=== $name: $CC $CFLAGS -I. examples/$name.c -o build/$name -lm"
    # shellcheck disable=SC2086 # CFLAGS is a list of flags
    if ! $CC $CFLAGS -I. "examples/$name.c" -o "build/$name" -lm; then
        echo "run_examples: $name does not build"
        exit 1
    fi
    echo "=== $name: build/$name $out"
    start=$(now)
    "./build/$name" "$out"
    status=$?
    secs=$(awk -v a="$start" -v b="$(now)" 'BEGIN { printf "%.1f", b - a }')
    if [ $status -ne 0 ]; then
        echo "run_examples: $name FAILED (exit status $status after $secs s)"
        exit 1
    fi
    echo "=== $name: passed in $secs s"
    summary="$summary$(printf '  %-18s %6s s' "$name" "$secs")"$'\n'
done
echo "all examples passed; run times:"
printf '%s' "$summary"
