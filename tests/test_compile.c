/* tests/test_compile.c - the header as a library: included in several translation units (the
   implementation in one), privately under SPH_STATIC, from C++, and the quick start in the
   header's documentation is exactly examples/hello.c. */
#include "harness.h"
#include "../sph.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef __cplusplus /* the whole suite also builds as C++ (make check-cpp) */
extern "C" {
#endif
double compile_second_kernel_w(void);
double compile_static_kernel_w(void);
double compile_cpp_kernel_w(void);
int compile_cpp_run(void);
#ifdef __cplusplus
}
#endif

static double here_kernel_w(void) {
    sph_kernel k;
    if (sph_kernel_init(&k, SPH_KERNEL_QUINTIC, 3, (sph_real)0.1) != SPH_OK) return -2;
    return (double)sph_kernel_w(&k, (sph_real)0.05);
}

/* The same function reached from three translation units gives the same value. */
static void test_translation_units(void) {
    double a = here_kernel_w();
    CHECK(a > 0);
    CHECK(compile_second_kernel_w() == a);
    CHECK(compile_static_kernel_w() == a);
    CHECK(compile_cpp_kernel_w() == a);
}

static void test_cpp_world(void) { CHECK_EQ_INT(compile_cpp_run(), 50); }

static char* read_file(const char* path) {
    FILE* f = fopen(path, "rb");
    long n;
    char* s;
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    n = ftell(f);
    fseek(f, 0, SEEK_SET);
    s = (char*)malloc((size_t)n + 1);
    if (s && fread(s, 1, (size_t)n, f) != (size_t)n) { free(s); s = NULL; }
    if (s) s[n] = 0;
    fclose(f);
    return s;
}

/* The quick start in the header (between the QUICKSTART markers) is examples/hello.c from its
   #define line on, so the documented program is the one the examples build and run. */
static void test_quickstart_in_docs(void) {
    char* hdr = read_file("sph.h");
    char* ex = read_file("examples/hello.c");
    const char *a, *b, *e;
    CHECK(hdr != NULL && ex != NULL);
    if (hdr && ex) {
        a = strstr(hdr, "QUICKSTART-BEGIN");
        b = strstr(hdr, "QUICKSTART-END");
        e = strstr(ex, "#define SPH_IMPLEMENTATION");
        CHECK(a && b && e && b > a);
        if (a && b && e && b > a) {
            const char* body = strchr(a, '\n') + 1;
            size_t len = (size_t)(b - body);
            while (len > 0 && body[len - 1] != '\n') --len; /* up to the marker's line */
            CHECK_MSG(len == strlen(e) && memcmp(body, e, len) == 0,
                      "the quick start in sph.h differs from examples/hello.c");
        }
    }
    free(hdr);
    free(ex);
}

const th_test tests_compile[] = {
    {"compile/translation_units_static_cpp", test_translation_units},
    {"compile/cpp_world", test_cpp_world},
    {"compile/quickstart_in_docs_is_hello_c", test_quickstart_in_docs},
    {0, 0},
};
