# sph.h - build targets. Nothing here is needed to use the library: it is one header.
#   make test      fast test suite (what CI runs; under 5 minutes on 2 cores)
#   make demo      the 2D dam break: progress on stdout, PNG frames in out/
#   make examples  every example, each built with one cc command
#   make run-examples  runs the checked examples (moving boundary, external force, multiphase,
#                  float build, ParaView output); each exits non-zero if its physics check fails
#   make check     warnings (gcc, clang, C, C++), sanitizers, float, no-OpenMP and C++ test runs
#   make validate  the long validation runs (tests marked long)
#   make bench     the benchmark driver (bench/bench.c: speed against a baseline, scaling, memory,
#                  cost growth) and the Taylor-Green convergence study, results in bench/results/
#   make bench-quick  the driver at small sizes (under a minute), into out/bench-quick/
#   make bench-tts time to solution per solver on the 2D and 3D dam breaks (59k particles
#                  included: hours), into bench/results/tts.*
#   make pareto    error against CPU time per solver and scene, stability maps (bench/pareto.c,
#                  about 11 minutes), into bench/results/; make pareto-quick: small, out/pareto-quick/
#   make paraview  the dam break as a ParaView time series: out/paraview/dambreak.pvd
#   make realtime  the interactive SDL2 demo (optional; needs libsdl2-dev)
#   make install   sph.h and sph.pc (pkg-config) under PREFIX (default /usr/local); CMake users
#                  can instead add_subdirectory() this directory (CMakeLists.txt) or install it

CC      ?= cc
CXX     ?= c++
CLANG   ?= clang
CLANGXX ?= clang++
OPT     ?= -O2
OMP     ?= -fopenmp
WARN     = -Wall -Wextra -Wpedantic -Wshadow
CFLAGS  ?= $(OPT) -std=c99 $(WARN)
B        = build
# OpenMP's default wait policy may spin idle threads (GNU libgomp spins for a while after each
# parallel loop); on a shared or loaded host that slows the demo and the tests several times.
# Passive waiting costs nothing measurable on an idle machine. Override: make OMP_WAIT_POLICY=active
OMP_WAIT_POLICY ?= passive
export OMP_WAIT_POLICY

TEST_SRC = tests/main.c tests/impl.c tests/test_kernels.c tests/test_grid.c tests/test_operators.c \
           tests/test_world.c tests/test_wcsph.c tests/test_pcisph.c tests/test_iisph.c \
           tests/test_dfsph.c tests/test_pbf.c \
           tests/test_compressible.c tests/test_soc.c tests/test_io.c tests/test_save.c \
           tests/test_reliability.c tests/test_oom.c tests/test_validation.c tests/test_scenes.c \
           tests/test_hostile.c tests/test_viscous.c tests/test_layers.c tests/test_rt.c \
           tests/test_verlet.c \
           tests/test_compile.c \
           tests/compile_second.c \
           tests/compile_static.c
TEST_CXX = tests/compile_cpp.cpp
TEST_DEP = sph.h tests/harness.h tests/alloc.h tests/state_hash.h tests/riemann.h tests/tank_profile.h bench/svg.h examples/scenes.h $(TEST_SRC) $(TEST_CXX)
EXAMPLES = hello first_scene dambreak paraview moving_boundary external_force multiphase float_build
PREFIX  ?= /usr/local
VTK_PYTHON ?= /usr/bin/python3

.PHONY: test validate bench bench-quick demo paraview realtime examples run-examples install check-tsan \
        check-realtime check check-warnings check-sanitize \
        check-float check-noomp check-cpp check-png check-vtk check-integration clean

test: $(B)/tests
	./$(B)/tests

# The tests are C; one C++ translation unit checks that the header compiles and links as C++.
$(B)/tests: $(TEST_DEP) | $(B)
	$(CXX) $(OPT) -std=c++11 $(WARN) $(OMP) -c $(TEST_CXX) -o $(B)/compile_cpp.o
	$(CC) $(CFLAGS) $(OMP) $(TEST_SRC) $(B)/compile_cpp.o -o $@ -lm

validate: $(B)/tests
	./$(B)/tests --long -long/

BENCH_N ?= 80
# make bench: every suite of the benchmark driver (sph.h against its baseline, scaling, search,
# float, memory, cost growth, optional physics, time to solution on the 2D dam break in double
# on 2 threads) and the Taylor-Green convergence study, CSV and SVG into bench/results/ (about
# 15 minutes on 2 cores; the 3D time-to-solution runs are behind make bench-tts). make bench-quick: the same suites at
# small sizes into out/bench-quick/ (under a minute; CI runs it so the log shows a regression).
bench: $(B)/bench $(B)/convergence
	mkdir -p bench/results
	./$(B)/bench --out bench/results > bench/results/perf.txt; st=$$?; cat bench/results/perf.txt; exit $$st
	./$(B)/convergence $(BENCH_N) bench/results

bench-quick: $(B)/bench
	mkdir -p out/bench-quick
	./$(B)/bench --quick --repeats 1 --out out/bench-quick

# make bench-tts: the tts suite (time to solution through sph_advance with the library's
# defaults) for every scene, solver, precision and 1 and 2 threads, SPlisHSPlasH's 59k-particle
# DamBreakModel included: 60 runs, several hours on 2 cores (a 59k run takes minutes to hours;
# each run stops after TTS_MAX_WALL wall-clock seconds and then reports the time it reached).
# One cell: ./build/bench tts --scene 3d-59k --solver dfsph --precision double --threads 2
TTS_MAX_WALL ?= 1500
.PHONY: bench-tts
bench-tts: $(B)/bench
	mkdir -p bench/results
	./$(B)/bench tts --scene all --max-wall $(TTS_MAX_WALL) --out bench/results > bench/results/tts.txt; st=$$?; cat bench/results/tts.txt; exit $$st

BENCH_SRC = bench/bench.c bench/bench_float.c
$(B)/bench: $(BENCH_SRC) bench/bench_core.h bench/bench_types.h bench/baseline.h bench/svg.h sph.h examples/scenes.h | $(B)
	$(CC) $(CFLAGS) $(OMP) -I. $(BENCH_SRC) -o $@ -lm

$(B)/convergence: bench/convergence.c sph.h examples/scenes.h bench/svg.h | $(B)
	$(CC) $(CFLAGS) $(OMP) -I. bench/convergence.c -o $@ -lm

# make pareto: speed against accuracy per solver on the dam break, hydrostatic tank and Re 100
# cavity, and the stability maps (bench/pareto.c), CSV and SVG into bench/results/. One thread
# (CPU seconds are compared); the log (kinetic energy of the cavity runs, the messages of runs
# that failed) in bench/results/pareto.txt. make pareto-quick: fewer runs into out/pareto-quick/
# (about 30 s on 2 cores).
.PHONY: pareto pareto-quick
pareto: $(B)/pareto
	mkdir -p bench/results
	OMP_NUM_THREADS=1 ./$(B)/pareto bench/results > bench/results/pareto.txt 2>&1; st=$$?; cat bench/results/pareto.txt; exit $$st

pareto-quick: $(B)/pareto
	mkdir -p out/pareto-quick
	OMP_NUM_THREADS=1 ./$(B)/pareto --quick out/pareto-quick

$(B)/pareto: bench/pareto.c sph.h examples/scenes.h bench/svg.h | $(B)
	$(CC) $(CFLAGS) $(OMP) -I. bench/pareto.c -o $@ -lm

demo: $(B)/dambreak
	./$(B)/dambreak

# The interactive SDL2 demo (optional: needs libsdl2-dev; nothing else depends on it).
# Without a display it stops at once (the window would be invisible) and names the headless
# check, which needs none: xvfb-run -a ./build/realtime --frames 150 --screenshot out/realtime.png
realtime:
	@if [ -z "$$DISPLAY$$WAYLAND_DISPLAY$$SDL_VIDEODRIVER" ]; then \
	    echo "make realtime: no display (neither DISPLAY nor WAYLAND_DISPLAY is set)." >&2; \
	    echo "  Headless: make $(B)/realtime && xvfb-run -a ./$(B)/realtime --frames 150 --screenshot out/realtime.png" >&2; \
	    echo "  (or SDL_VIDEODRIVER=offscreen ./$(B)/realtime --frames 150; see tests/check_realtime.sh)" >&2; \
	    exit 1; fi
	@$(MAKE) --no-print-directory $(B)/realtime
	./$(B)/realtime

$(B)/realtime: examples/realtime.c examples/image.h sph.h | $(B)
	@command -v sdl2-config >/dev/null 2>&1 || { echo "make realtime needs SDL2: apt-get install libsdl2-dev"; exit 1; }
	$(CC) $(CFLAGS) $(OMP) -I. examples/realtime.c $$(sdl2-config --cflags --libs) -lm -o $@

paraview: $(B)/paraview
	mkdir -p out/paraview
	./$(B)/paraview out/paraview 2d 1.0

examples: $(addprefix $(B)/,$(EXAMPLES))

# Builds and runs the checked examples (each checks a physical property and exits non-zero if
# it fails); frames and CSVs in out/examples/NAME/.
run-examples:
	examples/run_examples.sh moving_boundary external_force multiphase float_build paraview

# The header and a pkg-config file (the same sph.pc.in as CMake's install uses).
install:
	install -d $(DESTDIR)$(PREFIX)/include $(DESTDIR)$(PREFIX)/share/pkgconfig
	install -m 644 sph.h $(DESTDIR)$(PREFIX)/include/sph.h
	v=$$(sed -n 's/^#define SPH_VERSION_[A-Z]* \([0-9]*\)$$/\1/p' sph.h | paste -sd.); \
	sed -e 's|@SPH_PC_PREFIX@|$(PREFIX)|' -e 's|@SPH_PC_INCLUDEDIR@|$(PREFIX)/include|' \
	    -e "s|@SPH_PC_VERSION@|$$v|" sph.pc.in > $(DESTDIR)$(PREFIX)/share/pkgconfig/sph.pc

$(B)/%: examples/%.c sph.h examples/scenes.h examples/image.h examples/draw.h | $(B)
	$(CC) $(CFLAGS) $(OMP) -I. $< -o $@ -lm

$(B):
	mkdir -p $(B) out

# ---- check: the quality bar --------------------------------------------------------------------
check: check-warnings check-sanitize check-float check-noomp check-cpp check-png check-vtk \
       check-integration check-tsan check-realtime

IMPL_C = printf '\#define SPH_IMPLEMENTATION\n\#include "sph.h"\nint main(void){return 0;}\n'

check-warnings: | $(B)
	$(IMPL_C) > $(B)/impl_check.c
	$(CC) -std=c99 $(WARN) -Wconversion -Werror -fsyntax-only -I. $(B)/impl_check.c
	$(CC) -std=c99 $(WARN) -Wconversion -Werror -fsyntax-only -DSPH_FLOAT -I. $(B)/impl_check.c
	$(CC) -std=c99 $(WARN) -Werror -fsyntax-only $(OMP) -DSPH_STATIC -I. $(B)/impl_check.c
	$(CXX) -std=c++11 $(WARN) -Werror -fsyntax-only -x c++ -I. $(B)/impl_check.c
	$(CLANG) -std=c99 $(WARN) -Wconversion -Werror -fsyntax-only -I. $(B)/impl_check.c
	$(CLANG) -std=c99 $(WARN) -Werror -fsyntax-only -DSPH_FLOAT -I. $(B)/impl_check.c
	$(CLANGXX) -std=c++11 $(WARN) -Werror -fsyntax-only -x c++ -I. $(B)/impl_check.c
	for e in $(filter-out hello,$(EXAMPLES)); do \
	    $(CC) $(CFLAGS) -Werror -fsyntax-only -I. examples/$$e.c && \
	    $(CLANG) $(CFLAGS) -Werror -fsyntax-only -I. examples/$$e.c && \
	    $(CXX) -std=c++11 $(WARN) -Werror -fsyntax-only -x c++ -I. examples/$$e.c || exit 1; \
	done
	$(CC) $(CFLAGS) -Werror -fsyntax-only -I. examples/hello.c

# AddressSanitizer + UndefinedBehaviorSanitizer over the whole fast suite (OpenMP off: the
# sanitizers do not know libgomp's threads).
check-sanitize: | $(B)
	$(CXX) -O1 -g -std=c++11 $(WARN) -fsanitize=address,undefined -c $(TEST_CXX) -o $(B)/compile_cpp_san.o
	$(CC) -O1 -g -std=c99 $(WARN) -fsanitize=address,undefined -fno-omit-frame-pointer \
	      -fno-sanitize-recover=all $(TEST_SRC) $(B)/compile_cpp_san.o -o $(B)/tests_san -lm -lstdc++
	ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 ./$(B)/tests_san

check-float: | $(B)
	$(CXX) $(OPT) -std=c++11 $(WARN) -DSPH_FLOAT $(OMP) -c $(TEST_CXX) -o $(B)/compile_cpp_f.o
	$(CC) $(CFLAGS) -DSPH_FLOAT $(OMP) $(TEST_SRC) $(B)/compile_cpp_f.o -o $(B)/tests_float -lm
	./$(B)/tests_float

# Also the scalar path of the packed pair arithmetic (SPH_NO_SIMD): the golden hashes hold for both.
check-noomp: | $(B)
	$(CXX) $(OPT) -std=c++11 $(WARN) -DSPH_NO_SIMD -c $(TEST_CXX) -o $(B)/compile_cpp_noomp.o
	$(CC) $(CFLAGS) -DSPH_NO_SIMD $(TEST_SRC) $(B)/compile_cpp_noomp.o -o $(B)/tests_noomp -lm
	./$(B)/tests_noomp

# The same suite compiled as C++ (every test file and the implementation).
check-cpp: | $(B)
	$(CXX) $(OPT) -std=c++11 $(WARN) $(OMP) -x c++ $(TEST_SRC) -x none $(TEST_CXX) -o $(B)/tests_cpp -lm
	./$(B)/tests_cpp

check-png: | $(B)
	$(CC) $(CFLAGS) tests/png_check.c -o $(B)/png_check -lm
	./$(B)/png_check $(B)
	python3 tests/check_png.py $(B)

# The ParaView writer read back by VTK itself (python3-vtk9; Debian's /usr/bin/python3), double
# and float builds.
check-vtk: | $(B)
	$(CC) $(CFLAGS) -I. tests/vtk_export.c -o $(B)/vtk_export -lm
	$(CC) $(CFLAGS) -DSPH_FLOAT -I. tests/vtk_export.c -o $(B)/vtk_export_f -lm
	rm -rf $(B)/vtk $(B)/vtk_f && mkdir -p $(B)/vtk $(B)/vtk_f
	./$(B)/vtk_export $(B)/vtk && ./$(B)/vtk_export_f $(B)/vtk_f
	$(VTK_PYTHON) tests/check_vtk.py $(B)/vtk
	$(VTK_PYTHON) tests/check_vtk.py $(B)/vtk_f

print-test-src:
	@echo $(TEST_SRC)

# ThreadSanitizer over the OpenMP loops (clang + libomp + Archer; prints SKIP without them).
check-tsan:
	tests/check_tsan.sh $(B)/tsan

# The SDL2 demo headless under Xvfb, a screenshot per solver (prints SKIP without SDL2/Xvfb).
check-realtime:
	tests/check_realtime.sh

# CMake add_subdirectory / find_package, pkg-config and make install, each with a tiny consumer.
check-integration:
	tests/check_integration.sh $(CURDIR)/$(B)/integration

# Fuzzing (libFuzzer; make fuzz, make fuzz-replay)
include tests/fuzz.mk

clean:
	rm -rf $(B) out
