#!/usr/bin/env bash
# tests/check_integration.sh - takes sph.h into a tiny consumer project (tests/consumer) the ways
# a user would, builds it and runs it (make check-integration):
#   1. CMake add_subdirectory(<repo>) + target_link_libraries(... sph::sph)
#   2. cmake --install to a prefix, then find_package(sph CONFIG REQUIRED)
#   3. pkg-config (the installed sph.pc): cc $(pkg-config --cflags --libs sph)
#   4. make install PREFIX=... (no CMake), then pkg-config again
# Each consumer is a C file with the implementation and a C++ file using the API; it runs a
# hydrostatic column and fails unless it stays at rest with the right bottom pressure.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
work=${1:-$root/build/integration}
rm -rf "$work"
mkdir -p "$work"
version=$(sed -n 's/^#define SPH_VERSION_\(MAJOR\|MINOR\|PATCH\) \([0-9]*\)$/\2/p' "$root/sph.h" | paste -sd.)
q() { "$@" > "$work/log.txt" 2>&1 || { cat "$work/log.txt"; echo "FAILED: $*"; exit 1; }; }

echo "-- 1. add_subdirectory"
q cmake -S "$root/tests/consumer" -B "$work/sub" -DSPH_SOURCE_DIR="$root"
q cmake --build "$work/sub"
"$work/sub/consumer"

echo "-- 2. cmake --install + find_package"
q cmake -S "$root" -B "$work/lib" -DCMAKE_INSTALL_PREFIX="$work/prefix"
q cmake --install "$work/lib"
test -f "$work/prefix/include/sph.h"
q cmake -S "$root/tests/consumer" -B "$work/pkg" -DCMAKE_PREFIX_PATH="$work/prefix"
grep -q "$work/prefix/include" "$work/pkg/CMakeFiles/consumer.dir/flags.make" ||
    { echo "FAILED: the installed package does not point at $work/prefix/include"; exit 1; }
q cmake --build "$work/pkg"
"$work/pkg/consumer"

echo "-- 3. pkg-config from the CMake install"
export PKG_CONFIG_PATH="$work/prefix/share/pkgconfig"
got=$(pkg-config --modversion sph)
[ "$got" = "$version" ] || { echo "FAILED: pkg-config says version $got, sph.h says $version"; exit 1; }
cc -O2 -std=c99 $(pkg-config --cflags sph) -c "$root/tests/consumer/main.c" -o "$work/main.o"
c++ -O2 $(pkg-config --cflags sph) -c "$root/tests/consumer/report.cpp" -o "$work/report.o"
c++ "$work/main.o" "$work/report.o" $(pkg-config --libs sph) -o "$work/consumer_pc"
"$work/consumer_pc"

echo "-- 4. make install + pkg-config"
q make -C "$root" install PREFIX="$work/mkprefix"
export PKG_CONFIG_PATH="$work/mkprefix/share/pkgconfig"
[ "$(pkg-config --modversion sph)" = "$version" ]
cflags=$(pkg-config --cflags sph)
[ "${cflags% }" = "-I$work/mkprefix/include" ] ||
    { echo "FAILED: make install's sph.pc gives '$cflags'"; exit 1; }
cc -O2 -std=c99 $(pkg-config --cflags sph) -c "$root/tests/consumer/main.c" -o "$work/main2.o"
c++ "$work/main2.o" "$work/report.o" $(pkg-config --libs sph) -o "$work/consumer_mk"
"$work/consumer_mk"
echo "integration ok: add_subdirectory, find_package, pkg-config (CMake and make install), sph $version"
