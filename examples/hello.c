/* hello.c - quick start: a water column collapses in a closed 2D tank.
   Build: cc -O2 -I. examples/hello.c -o hello -lm */
#define SPH_IMPLEMENTATION
#include "sph.h"
#include <stdio.h>

int main(void) {
    sph_world_def def = sph_world_def_default(2); /* 2D, y up, gravity -9.81 m/s^2 */
    def.spacing = 0.02;                           /* particle spacing [m]          */
    sph_world w;
    if (sph_world_init(&w, &def) != SPH_OK) { printf("%s\n", w.error); return 1; }
    int water = sph_world_add_phase(&w, &(sph_phase){.rest_density = 1000});
    sph_real lo[2] = {0, 0}, column[2] = {0.4, 0.8}, tank[2] = {2.0, 1.0};
    sph_fill_box(&w, water, lo, column);   /* 0.4 m x 0.8 m of water              */
    sph_add_wall_box(&w, lo, tank, 0, 0);  /* closed tank, walls as deep as needed */
    for (int frame = 1; frame <= 20; ++frame) {
        if (sph_advance(&w, 0.05) != SPH_OK) { printf("error: %s\n", w.error); break; }
        double front = 0;
        for (size_t i = 0; i < w.n; ++i)
            if (w.x[i * 2] > front) front = w.x[i * 2];
        printf("t = %.2f s  steps %5llu  front at x = %.3f m  max speed %.2f m/s\n", w.time,
               (unsigned long long)w.steps, front, w.stats.v_max);
    }
    sph_world_free(&w);
    return 0;
}
