/* tests/fuzz_replay.c - runs the fuzz harness (tests/fuzz_world.c) over the files given on the
   command line, without libFuzzer: the regression inputs and seeds under any compiler, e.g.
       gcc -g -O1 -fsanitize=address,undefined -fno-sanitize-recover=all -I. \
           tests/fuzz_world.c tests/fuzz_replay.c -lm -o build/fuzz_replay
       build/fuzz_replay tests/fuzz_corpus/regressions/crash-... tests/fuzz_corpus/seed-...
   (make fuzz-replay). An invariant violation or a sanitizer report aborts; otherwise it prints
   the number of inputs run. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

int main(int argc, char** argv) {
    int i, runs = 0;
    for (i = 1; i < argc; ++i) {
        FILE* f = fopen(argv[i], "rb");
        unsigned char* buf;
        long len;
        if (!f) { fprintf(stderr, "fuzz_replay: cannot open %s\n", argv[i]); return 1; }
        if (fseek(f, 0, SEEK_END) != 0 || (len = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0) {
            fprintf(stderr, "fuzz_replay: cannot size %s\n", argv[i]);
            fclose(f);
            return 1;
        }
        buf = (unsigned char*)malloc((size_t)len + 1);
        if (!buf || fread(buf, 1, (size_t)len, f) != (size_t)len) {
            fprintf(stderr, "fuzz_replay: cannot read %s\n", argv[i]);
            free(buf);
            fclose(f);
            return 1;
        }
        fclose(f);
        if (getenv("FUZZ_VERBOSE")) fprintf(stderr, "== %s (%ld bytes)\n", argv[i], len);
        LLVMFuzzerTestOneInput(buf, (size_t)len);
        free(buf);
        ++runs;
    }
    printf("fuzz_replay: %d inputs, no failures\n", runs);
    return 0;
}
