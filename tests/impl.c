/* The one translation unit of the test binary that compiles the implementation. The tests run
   with the library's expensive self-checks on, and on the counting allocator of tests/alloc.h
   (disarmed unless a test of tests/test_oom.c arms it). */
#include "alloc.h"
#define SPH_VALIDATE
#define SPH_MALLOC(size) th_malloc(size)
#define SPH_REALLOC(ptr, size) th_realloc(ptr, size)
#define SPH_FREE(ptr) th_free(ptr)
#define SPH_IMPLEMENTATION
#include "../sph.h"
