/* A second C translation unit: the declarations only (linked to tests/impl.c), then a private
   copy of the whole library under SPH_STATIC in tests/compile_static.c. */
#include "../sph.h"

#ifdef __cplusplus
extern "C"
#endif
double compile_second_kernel_w(void);

double compile_second_kernel_w(void) {
    sph_kernel k;
    if (sph_kernel_init(&k, SPH_KERNEL_QUINTIC, 3, (sph_real)0.1) != SPH_OK) return -1;
    return (double)sph_kernel_w(&k, (sph_real)0.05);
}
