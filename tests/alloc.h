/* tests/alloc.h - the counting allocator of the test binary.

   tests/impl.c routes SPH_MALLOC / SPH_REALLOC / SPH_FREE of the library through these
   functions (defined in tests/test_oom.c), so every test runs on them. Disarmed (the default)
   they only count: each malloc and each realloc is one allocation (a realloc that only moves or
   resizes a block can fail too), and live blocks are tracked so that a test can show that a world
   freed everything. Armed with th_alloc_fail_at(k), the k-th allocation after the call returns
   NULL (realloc then leaves its block untouched, as C's does) and every other one succeeds.
   free(NULL) is a no-op that is not counted; realloc(NULL, n) is a malloc; a size of 0 is served
   as 1 byte (the library never asks for 0, and C leaves the result of 0 to the implementation).

   sph.h allocates only on the calling thread, outside OpenMP parallel regions (checked:
   th_alloc_in_parallel counts violations); the counters are still updated in a critical section,
   so the allocator stays correct if a host ever runs worlds on several threads. */
#ifndef SPH_TEST_ALLOC_H
#define SPH_TEST_ALLOC_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

void* th_malloc(size_t size);
void* th_realloc(void* ptr, size_t size);
void th_free(void* ptr);

/* Zeroes the allocation count and arms: the k-th allocation from now fails (k = 0: none). */
void th_alloc_fail_at(unsigned long k);
/* Disarms without touching the count. */
void th_alloc_disarm(void);
unsigned long th_alloc_count(void);    /* allocations since the last th_alloc_fail_at          */
unsigned long th_alloc_injected(void); /* allocations failed on purpose since then             */
long th_alloc_live(void);              /* blocks allocated and not yet freed (whole run)       */
unsigned long th_alloc_in_parallel(void); /* allocations inside an active parallel region   */

#ifdef __cplusplus
}
#endif

#endif
