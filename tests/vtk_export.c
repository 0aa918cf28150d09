/* tests/vtk_export.c - writes ParaView files with sph.h for tests/check_vtk.py to read with VTK.

   Build and run (from the repository root; make check-vtk does this in double and float):

       cc -O2 -std=c99 -I. tests/vtk_export.c -o build/vtk_export -lm
       ./build/vtk_export build/vtk && /usr/bin/python3 tests/check_vtk.py build/vtk

   It writes into DIR three scenes, each as .vtu files (sph_write_vtu_series: NAME.pvd and
   NAME_0000.vtu ...) plus, per frame, NAME_0000.txt with the expected point values in C99 hex
   floating point (%a, exact) for the checker:
       first line:  time n_fluid n_boundary dim has_energy sizeof(sph_real)
       then per point (fluid first, then boundary):
                    kind id phase body x y z vx vy vz density pressure [internal_energy]
   and the last frame of the first scene also as legacy VTK (NAME_last.vtk, 9 digits).
   Scenes: a 2D dam break with walls (3 frames), a 3D two-phase tank with walls (2 frames), a
   3D ideal-gas box with internal energy (1 frame, compressible step). */
#define SPH_IMPLEMENTATION
#include "sph.h"

#include <stdio.h>
#include <string.h>

static int fail(const sph_world* w, const char* what, sph_status s) {
    fprintf(stderr, "vtk_export: %s: %s (%s)\n", what, sph_status_string(s), w->error);
    return 1;
}

static int expected(const sph_world* w, const char* path) {
    const size_t n = w->n + w->nb, d = (size_t)w->dim;
    FILE* f = fopen(path, "w");
    size_t i;
    int k;
    if (!f) return 1;
    fprintf(f, "%a %zu %zu %d %d %d\n", w->time, w->n, w->nb, w->dim, w->e != NULL,
            (int)sizeof(sph_real));
    for (i = 0; i < n; ++i) {
        const int fluid = i < w->n;
        const size_t b = fluid ? 0 : i - w->n;
        fprintf(f, "%d %u %d %d", fluid ? 0 : 1, fluid ? (unsigned)w->id[i] : (unsigned)w->b_id[b],
                fluid ? (int)w->phase[i] : -1, fluid ? -1 : (int)w->b_body[b]);
        for (k = 0; k < 3; ++k)
            fprintf(f, " %a", (size_t)k < d ? (double)(fluid ? w->x[i * d + (size_t)k] : w->b_x[b * d + (size_t)k]) : 0.0);
        for (k = 0; k < 3; ++k)
            fprintf(f, " %a", (size_t)k < d ? (double)(fluid ? w->v[i * d + (size_t)k] : w->b_v[b * d + (size_t)k]) : 0.0);
        fprintf(f, " %a %a", fluid ? (double)w->rho[i] : (double)(w->b_rho[b] * w->phases[0].rest_density),
                fluid ? (double)w->p[i] : (double)w->b_p[b]);
        if (w->e) fprintf(f, " %a", fluid ? (double)w->e[i] : 0.0);
        fputc('\n', f);
    }
    return fclose(f) != 0;
}

static int frame(const sph_world* w, const char* dir, const char* name, int k) {
    char base[512], txt[600];
    sph_status s;
    snprintf(base, sizeof base, "%s/%s", dir, name);
    snprintf(txt, sizeof txt, "%s_%04d.txt", base, k);
    s = sph_write_vtu_series(w, base, k);
    if (s != SPH_OK) return fail(w, "sph_write_vtu_series", s);
    return expected(w, txt);
}

int main(int argc, char** argv) {
    const char* dir = argc > 1 ? argv[1] : "build/vtk";
    sph_world w;
    sph_world_def def;
    sph_phase water, oil, gas;
    sph_status s;
    int ph, ph2, k, step;
    char path[512];

    /* 1. 2D dam break with walls, WCSPH */
    def = sph_world_def_default(2);
    def.spacing = 0.02;
    if ((s = sph_world_init(&w, &def)) != SPH_OK) return fail(&w, "init", s);
    memset(&water, 0, sizeof water);
    water.rest_density = 1000;
    ph = sph_world_add_phase(&w, &water);
    {
        sph_real lo[2] = {0, 0}, col[2] = {0.3, 0.6}, tank[2] = {1.2, 0.8};
        if ((s = sph_fill_box(&w, ph, lo, col)) != SPH_OK) return fail(&w, "fill", s);
        if ((s = sph_add_wall_box(&w, lo, tank, 0, 0)) != SPH_OK) return fail(&w, "walls", s);
    }
    for (k = 0; k < 3; ++k) {
        if (frame(&w, dir, "dam2d", k)) return 1;
        if ((s = sph_advance(&w, 0.05)) != SPH_OK) return fail(&w, "advance", s);
    }
    snprintf(path, sizeof path, "%s/dam2d_last.vtk", dir);
    if ((s = sph_write_vtk(&w, path)) != SPH_OK) return fail(&w, "sph_write_vtk", s);
    snprintf(path, sizeof path, "%s/dam2d_last.txt", dir);
    if (expected(&w, path)) return 1;
    printf("dam2d: %zu fluid + %zu wall particles, 3 frames, t = %.3f s\n", w.n, w.nb, w.time);
    sph_world_free(&w);

    /* 2. 3D two-phase tank (oil over water) with walls */
    def = sph_world_def_default(3);
    def.spacing = 0.04;
    def.density = SPH_DENSITY_PARTICLE;
    if ((s = sph_world_init(&w, &def)) != SPH_OK) return fail(&w, "init", s);
    memset(&oil, 0, sizeof oil);
    oil.rest_density = 800;
    ph = sph_world_add_phase(&w, &water);
    ph2 = sph_world_add_phase(&w, &oil);
    {
        sph_real lo[3] = {0, 0, 0}, mid[3] = {0.4, 0.2, 0.24}, lo2[3] = {0, 0.2, 0},
                 hi[3] = {0.4, 0.36, 0.24}, tank[3] = {0.4, 0.5, 0.24};
        if ((s = sph_fill_box(&w, ph, lo, mid)) != SPH_OK) return fail(&w, "fill", s);
        if ((s = sph_fill_box(&w, ph2, lo2, hi)) != SPH_OK) return fail(&w, "fill", s);
        if ((s = sph_add_wall_box(&w, lo, tank, 0, 0)) != SPH_OK) return fail(&w, "walls", s);
    }
    if ((s = sph_set_hydrostatic(&w)) != SPH_OK) return fail(&w, "hydrostatic", s);
    for (k = 0; k < 2; ++k) {
        if (frame(&w, dir, "tank3d", k)) return 1;
        for (step = 0; step < 5; ++step)
            if ((s = sph_step(&w, sph_stable_dt(&w, def.solver))) != SPH_OK) return fail(&w, "step", s);
    }
    printf("tank3d: %zu fluid + %zu wall particles, 2 phases, 2 frames\n", w.n, w.nb);
    sph_world_free(&w);

    /* 3. 3D ideal gas with a pressure jump: internal energy written */
    def = sph_world_def_default(3);
    def.spacing = 0.05;
    def.gravity[1] = 0;
    def.solver = SPH_SOLVER_COMPRESSIBLE;
    def.periodic[0] = def.periodic[1] = def.periodic[2] = 1;
    def.domain_lo[0] = def.domain_lo[1] = def.domain_lo[2] = 0;
    def.domain_hi[0] = def.domain_hi[1] = def.domain_hi[2] = 0.5;
    if ((s = sph_world_init(&w, &def)) != SPH_OK) return fail(&w, "init", s);
    memset(&gas, 0, sizeof gas);
    gas.rest_density = 1;
    gas.eos = SPH_EOS_IDEAL_GAS;
    gas.back_pressure = 1e5;
    ph = sph_world_add_phase(&w, &gas);
    {
        sph_real lo[3] = {0, 0, 0}, hi[3] = {0.5, 0.5, 0.5};
        size_t i;
        if ((s = sph_fill_box(&w, ph, lo, hi)) != SPH_OK) return fail(&w, "fill", s);
        for (i = 0; i < w.n; ++i)
            if (w.x[3 * i] < 0.25) w.e[i] *= 2; /* hot half */
    }
    if ((s = sph_step(&w, sph_stable_dt(&w, def.solver))) != SPH_OK) return fail(&w, "step", s);
    if (frame(&w, dir, "gas3d", 0)) return 1;
    printf("gas3d: %zu particles with internal energy\n", w.n);
    sph_world_free(&w);
    return 0;
}
