/* first_scene.c - the README's tutorial scene: a 2D wave tank with a paddle and an obstacle.
   Water 0.5 m deep in a 2 m x 1 m tank; on the floor a block made of boundary particles placed
   by the program; at the left a paddle (boundary particles moved by a callback) makes waves; a
   force callback damps the waves near the far wall (a "beach"); every 0.05 s a frame goes to
   ParaView files. WCSPH (the default) with sph_advance's automatic time step.
   Build: cc -O2 -fopenmp -I. examples/first_scene.c -o build/first_scene -lm
   Run:   mkdir -p out/first_scene && ./build/first_scene [output dir = out/first_scene]
   Then open out/first_scene/scene.pvd in ParaView. */
#define SPH_IMPLEMENTATION
#include "sph.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { PADDLE = 1, BLOCK = 2 };             /* body tags of the boundary particles */
static const double A = 0.04, PERIOD = 1.0; /* paddle stroke amplitude [m] and period [s] */

/* boundary callback: x = x0 + A sin(omega t) for the paddle's particles */
static void move_paddle(sph_world* w, double t, void* user) {
    const double om = 2 * 3.14159265358979 / PERIOD;
    size_t b;
    (void)user;
    for (b = 0; b < w->nb; ++b)
        if (w->b_body[b] == PADDLE) {
            w->b_x[2 * b] = w->b_x0[2 * b] + (sph_real)(A * sin(om * t));
            w->b_v[2 * b] = (sph_real)(A * om * cos(om * t));
            w->b_a[2 * b] = (sph_real)(-A * om * om * sin(om * t));
        }
}

/* force callback (runs on worker threads, each with its own range): beyond x = 1.6 m the
   velocity relaxes to zero within 0.5 s, so waves die out instead of reflecting */
static void beach(const sph_world* w, size_t begin, size_t end, sph_real* acc, void* user) {
    size_t i;
    (void)user;
    for (i = begin; i < end; ++i)
        if (w->x[2 * i] > 1.6) {
            acc[2 * i] -= w->v[2 * i] / (sph_real)0.5;
            acc[2 * i + 1] -= w->v[2 * i + 1] / (sph_real)0.5;
        }
}

int main(int argc, char** argv) {
    const char* dir = argc > 1 ? argv[1] : "out/first_scene";
    const double dx = 0.02;
    sph_world_def def = sph_world_def_default(2);
    sph_phase water;
    sph_world w;
    sph_real lo[2] = {0, 0}, tank[2] = {2.0, 1.0}, block[2 * 150], paddle[2 * 3 * 30];
    sph_real a0[2] = {0.2, 0}, a1[2] = {1.1, 0.5}, b0[2] = {1.1, 0.2}, b1[2] = {1.4, 0.5};
    sph_real c0[2] = {1.4, 0}, c1[2] = {2.0, 0.5};
    char base[512];
    int i, j, n = 0, frame = 0;

    def.spacing = (sph_real)dx;
    def.force = beach;
    def.boundary_motion = move_paddle;
    memset(&water, 0, sizeof water);
    water.rest_density = 1000;
    if (sph_world_init(&w, &def) != SPH_OK) { printf("%s\n", w.error); return 1; }
    /* water around the block: three boxes, each a whole number of spacings wide and high */
    if (sph_world_add_phase(&w, &water) < 0 || sph_fill_box(&w, 0, a0, a1) != SPH_OK ||
        sph_fill_box(&w, 0, b0, b1) != SPH_OK || sph_fill_box(&w, 0, c0, c1) != SPH_OK ||
        sph_add_wall_box(&w, lo, tank, 0, 0) != SPH_OK) {
        printf("setup: %s\n", w.error);
        return 1;
    }
    /* the block, 0.3 m x 0.2 m, filled with boundary particles on the fluid's lattice */
    for (j = 0; j < 10; ++j)
        for (i = 0; i < 15; ++i, ++n) {
            block[2 * n] = (sph_real)(1.1 + (i + 0.5) * dx);
            block[2 * n + 1] = (sph_real)((j + 0.5) * dx);
        }
    /* the paddle: three columns of particles 0.6 m high, left of the water (x < 0.2 m) */
    for (n = 0, i = 0; i < 3; ++i)
        for (j = 0; j < 30; ++j, ++n) {
            paddle[2 * n] = (sph_real)(0.2 - (i + 0.5) * dx);
            paddle[2 * n + 1] = (sph_real)((j + 0.5) * dx);
        }
    if (sph_add_boundary(&w, 150, block, NULL, BLOCK) != SPH_OK ||
        sph_add_boundary(&w, 90, paddle, NULL, PADDLE) != SPH_OK) {
        printf("boundary: %s\n", w.error);
        return 1;
    }
    printf("%zu fluid particles, %zu boundary particles\n", w.n, w.nb);
    snprintf(base, sizeof base, "%s/scene", dir);
    for (;;) {
        if (sph_write_vtu_series(&w, base, frame) != SPH_OK) {
            printf("cannot write %s_%04d.vtu (does %s/ exist?)\n", base, frame, dir);
            break;
        }
        if (frame % 10 == 0) {
            double crest = 0;
            size_t k;
            for (k = 0; k < w.n; ++k)
                if (w.x[2 * k + 1] > crest) crest = w.x[2 * k + 1];
            printf("t = %.2f s  steps %5llu  dt %.2e s  max speed %.3f m/s  highest water %.3f m\n",
                   w.time, (unsigned long long)w.steps, (double)w.stats.dt, (double)w.stats.v_max,
                   crest);
        }
        if (frame == 60) break; /* 3 s */
        if (sph_advance(&w, 0.05) != SPH_OK) { printf("error: %s\n", w.error); break; }
        ++frame;
    }
    printf("wrote %s.pvd (%d frames); open it in ParaView\n", base, frame + 1);
    sph_world_free(&w);
    return 0;
}
