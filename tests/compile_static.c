/* A translation unit with its own private (static) copy of the implementation: links next to
   the extern one in tests/impl.c without clashing symbols. */
#define SPH_STATIC
#define SPH_IMPLEMENTATION
#include "../sph.h"

#ifdef __cplusplus
extern "C"
#endif
double compile_static_kernel_w(void);

double compile_static_kernel_w(void) {
    sph_kernel k;
    if (sph_kernel_init(&k, SPH_KERNEL_QUINTIC, 3, (sph_real)0.1) != SPH_OK) return -1;
    return (double)sph_kernel_w(&k, (sph_real)0.05);
}
