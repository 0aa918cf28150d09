# tests/fuzz.mk - fuzzing targets; the Makefile includes it (uses its B and CC).
#   make fuzz          builds the libFuzzer harnesses (below) with clang (ASan + UBSan)
#                      and fuzzes for FUZZ_TIME seconds in all from tests/fuzz_corpus (start
#                      and regressions); new inputs go to $(B)/fuzz_corpus, crashes, leaks and
#                      timeouts to $(B)/fuzz_artifacts/. Skipped, with a message, when clang
#                      cannot link -fsanitize=fuzzer (Debian: apt-get install clang libclang-rt-14-dev).
#                      FUZZ_DEFS=-DSPH_FLOAT fuzzes the float build; FUZZ_ARGS passes libFuzzer flags.
#   make fuzz-replay   runs the regression inputs and the seeds through the same harness without
#                      libFuzzer (tests/fuzz_replay.c), built with $(CC) and ASan + UBSan, in
#                      double and in float (SPH_FLOAT), and with clang when there is one.
# Three harnesses share FUZZ_TIME (half to fuzz_world, a quarter to each of the others):
#   tests/fuzz_world.c  bytes -> def, phases, particles, walls, steps (inputs: tests/fuzz_corpus/,
#                       read recursively: the other harnesses' inputs are valid inputs too)
#   tests/fuzz_load.c   a small world saved, its bytes edited, the checksum recomputed, loaded
#                       and stepped (inputs: tests/fuzz_corpus/load/, regressions/load/)
#   tests/fuzz_api.c    API calls in any order with invariants after each (inputs:
#                       tests/fuzz_corpus/api/, regressions/api/)
# A crash found by make fuzz: fix it, then keep the input as a regression of its harness:
#   cp $(B)/fuzz_artifacts/crash-... tests/fuzz_corpus/regressions/<what-it-was>.bin
#   cp $(B)/fuzz_artifacts/load-crash-... tests/fuzz_corpus/regressions/load/<what-it-was>.bin
# and FUZZ_VERBOSE=1 $(B)/fuzz_replay <file> (fuzz_replay_load, fuzz_replay_api) prints what an
# input does.

FUZZ_CC      ?= clang
FUZZ_TIME    ?= 60
FUZZ_TIMEOUT ?= 25
FUZZ_RSS     ?= 2048
FUZZ_ARGS    ?=
FUZZ_DEFS    ?=
# float-cast-overflow: gcc's -fsanitize=undefined leaves it out (clang's includes it)
FUZZ_SAN      = -fsanitize=address,undefined,float-cast-overflow -fno-sanitize-recover=all \
                -fno-omit-frame-pointer
# malloc_fill_byte=255: every allocation starts as NaN in both precisions (ASan's default fill,
# 0xbe, reads as a finite number), so state a call leaves unset cannot pass as a value
FUZZ_RUN      = ASAN_OPTIONS=detect_leaks=1:malloc_fill_byte=255:max_malloc_fill_size=1000000000 \
                UBSAN_OPTIONS=print_stacktrace=1
FUZZ_INPUTS   = $(wildcard tests/fuzz_corpus/regressions/*.bin) $(wildcard tests/fuzz_corpus/seed-*.bin)
FUZZ_INPUTS_LOAD = $(wildcard tests/fuzz_corpus/regressions/load/*.bin) $(wildcard tests/fuzz_corpus/load/*.bin)
FUZZ_INPUTS_API  = $(wildcard tests/fuzz_corpus/regressions/api/*.bin) $(wildcard tests/fuzz_corpus/api/*.bin)
FUZZ_DEP      = sph.h tests/fuzz_world.c tests/fuzz_load.c tests/fuzz_api.c tests/fuzz_common.h
FUZZ_FLAGS    = -timeout=$(FUZZ_TIMEOUT) -rss_limit_mb=$(FUZZ_RSS) -print_final_stats=1 $(FUZZ_ARGS)

.PHONY: fuzz fuzz-replay

fuzz: | $(B)
	@if printf 'int LLVMFuzzerTestOneInput(const char* d, unsigned long n) { (void)d; (void)n; return 0; }\n' | \
	    $(FUZZ_CC) -fsanitize=fuzzer -x c - -o $(B)/fuzz_probe >/dev/null 2>&1; then \
	    rm -f $(B)/fuzz_probe; \
	else \
	    echo "make fuzz: skipped: '$(FUZZ_CC) -fsanitize=fuzzer' does not link (libFuzzer missing;"; \
	    echo "           Debian: apt-get install clang libclang-rt-14-dev, or FUZZ_CC=clang-NN)"; \
	    exit 0; \
	fi; \
	set -e; \
	pids=; for h in world load api; do \
	    echo "$(FUZZ_CC) -g -O1 -fsanitize=fuzzer,address,undefined ... tests/fuzz_$$h.c -o $(B)/fuzz_$$h"; \
	    $(FUZZ_CC) -g -O1 -fsanitize=fuzzer $(FUZZ_SAN) $(FUZZ_DEFS) -I. tests/fuzz_$$h.c -lm -o $(B)/fuzz_$$h & \
	    pids="$$pids $$!"; \
	done; \
	for p in $$pids; do wait $$p; done; \
	mkdir -p $(B)/fuzz_corpus $(B)/fuzz_corpus_load $(B)/fuzz_corpus_api $(B)/fuzz_artifacts; \
	./$(B)/fuzz_world $(B)/fuzz_corpus tests/fuzz_corpus \
	    -max_total_time=$$(( $(FUZZ_TIME) / 2 )) -artifact_prefix=$(B)/fuzz_artifacts/ $(FUZZ_FLAGS); \
	./$(B)/fuzz_load $(B)/fuzz_corpus_load tests/fuzz_corpus/load tests/fuzz_corpus/regressions/load \
	    -max_total_time=$$(( $(FUZZ_TIME) / 4 )) -artifact_prefix=$(B)/fuzz_artifacts/load- $(FUZZ_FLAGS); \
	./$(B)/fuzz_api $(B)/fuzz_corpus_api tests/fuzz_corpus/api tests/fuzz_corpus/regressions/api \
	    -max_total_time=$$(( $(FUZZ_TIME) / 4 )) -artifact_prefix=$(B)/fuzz_artifacts/api- $(FUZZ_FLAGS)

# With clang available the inputs also run under clang's UBSan, which checks what gcc's does not
# (e.g. NULL + 0, one of the regressions).
fuzz-replay: $(FUZZ_DEP) tests/fuzz_replay.c | $(B)
	$(CC) -g -O1 -std=c99 $(WARN) $(FUZZ_SAN) -I. tests/fuzz_world.c tests/fuzz_replay.c -o $(B)/fuzz_replay -lm
	$(CC) -g -O1 -std=c99 $(WARN) $(FUZZ_SAN) -DSPH_FLOAT -I. tests/fuzz_world.c tests/fuzz_replay.c -o $(B)/fuzz_replay_f -lm
	$(FUZZ_RUN) ./$(B)/fuzz_replay $(FUZZ_INPUTS)
	$(FUZZ_RUN) ./$(B)/fuzz_replay_f $(FUZZ_INPUTS)
	for h in load api; do \
	    $(CC) -g -O1 -std=c99 $(WARN) $(FUZZ_SAN) -I. tests/fuzz_$$h.c tests/fuzz_replay.c -o $(B)/fuzz_replay_$$h -lm && \
	    $(CC) -g -O1 -std=c99 $(WARN) $(FUZZ_SAN) -DSPH_FLOAT -I. tests/fuzz_$$h.c tests/fuzz_replay.c -o $(B)/fuzz_replay_$${h}_f -lm || exit 1; \
	done
	$(FUZZ_RUN) ./$(B)/fuzz_replay_load $(FUZZ_INPUTS_LOAD)
	$(FUZZ_RUN) ./$(B)/fuzz_replay_load_f $(FUZZ_INPUTS_LOAD)
	$(FUZZ_RUN) ./$(B)/fuzz_replay_api $(FUZZ_INPUTS_API)
	$(FUZZ_RUN) ./$(B)/fuzz_replay_api_f $(FUZZ_INPUTS_API)
	@if command -v $(FUZZ_CC) >/dev/null 2>&1; then \
	    echo "$(FUZZ_CC) ... -o $(B)/fuzz_replay_clang"; \
	    $(FUZZ_CC) -g -O1 -std=c99 $(WARN) $(FUZZ_SAN) -I. tests/fuzz_world.c tests/fuzz_replay.c \
	        -o $(B)/fuzz_replay_clang -lm && $(FUZZ_RUN) ./$(B)/fuzz_replay_clang $(FUZZ_INPUTS); \
	else echo "fuzz-replay: $(FUZZ_CC) not found, the clang replay is skipped"; fi
