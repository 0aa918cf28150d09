// The header included from C++ (declarations with C linkage, linked to the C implementation
// in tests/impl.c): a kernel value and a short simulation driven from C++.
#include "../sph.h"

extern "C" double compile_cpp_kernel_w(void);
extern "C" int compile_cpp_run(void);

extern "C" double compile_cpp_kernel_w(void) {
    sph_kernel k;
    if (sph_kernel_init(&k, SPH_KERNEL_QUINTIC, 3, static_cast<sph_real>(0.1)) != SPH_OK) return -1;
    return static_cast<double>(sph_kernel_w(&k, static_cast<sph_real>(0.05)));
}

// Returns the number of fluid particles after 10 steps of a small tank, or -1.
extern "C" int compile_cpp_run(void) {
    sph_world_def def = sph_world_def_default(2);
    def.spacing = static_cast<sph_real>(0.05);
    sph_world w;
    if (sph_world_init(&w, &def) != SPH_OK) return -1;
    sph_phase water = sph_phase();
    water.rest_density = 1000;
    const int ph = sph_world_add_phase(&w, &water);
    const sph_real lo[2] = {0, 0}, hi[2] = {0.5, 0.25}, tank[2] = {0.5, 0.5};
    int n = -1;
    if (ph >= 0 && sph_fill_box(&w, ph, lo, hi) == SPH_OK &&
        sph_add_wall_box(&w, lo, tank, 0, SPH_FACE_YMAX) == SPH_OK) {
        n = static_cast<int>(w.n);
        for (int s = 0; s < 10; ++s)
            if (sph_step(&w, static_cast<sph_real>(1e-4)) != SPH_OK) n = -1;
    }
    sph_world_free(&w);
    return n;
}
