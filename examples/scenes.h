/* examples/scenes.h - scene constructors shared by examples, tests and bench, so all three run
   the same setups. Include after sph.h (with or without SPH_IMPLEMENTATION). Every constructor
   takes a def prepared by the caller (kernel, solver, integrator ... as the caller wants), sets
   the scene's geometry fields, and builds the world; on failure the world is freed and the
   status returned (w->error is kept in scene_error). */
#ifndef SPH_SCENES_H
#define SPH_SCENES_H

#include <math.h>
#include <stdio.h>
#include <string.h>

#if defined(__GNUC__) || defined(__clang__)
#define SCENE_FN static __attribute__((unused)) /* a program uses only some scenes */
#else
#define SCENE_FN static
#endif

static char scene_error[SPH_ERROR_SIZE];

SCENE_FN sph_status scene__fail(sph_world* w, sph_status s) {
    memcpy(scene_error, w->error, sizeof(scene_error));
    sph_world_free(w);
    return s;
}

#define SCENE__TRY(expr)                                                                           \
    do { sph_status scene_s_ = (expr); if (scene_s_ != SPH_OK) return scene__fail(w, scene_s_); } \
    while (0)

/* Hydrostatic tank (Adami, Hu & Adams 2012 sec. 6, validation-data.md sec. 4): water of depth
   `depth` [m] in a tank `width` [m] wide (and deep in 3D), walls `wall_height` = 1.4 depth high
   with an open top, `res` particles over the depth, initialised in hydrostatic equilibrium. */
SCENE_FN sph_status scene_hydrostatic(sph_world* w, sph_world_def def, double width, double depth,
                                    int res) {
    sph_real lo[3] = {0, 0, 0}, hi[3], whi[3];
    sph_phase water;
    int k, ph;
    memset(&water, 0, sizeof(water));
    water.rest_density = 1000;
    def.spacing = (sph_real)(depth / res);
    for (k = 0; k < 3; ++k) hi[k] = whi[k] = (sph_real)width;
    hi[1] = (sph_real)depth;
    whi[1] = (sph_real)(1.4 * depth);
    if (def.dim == 1) { hi[0] = (sph_real)depth; whi[0] = (sph_real)(1.4 * depth); }
    SCENE__TRY(sph_world_init(w, &def));
    ph = sph_world_add_phase(w, &water);
    if (ph < 0) return scene__fail(w, w->status);
    SCENE__TRY(sph_fill_box(w, ph, lo, hi));
    SCENE__TRY(sph_add_wall_box(w, lo, whi, 0, def.dim == 1 ? SPH_FACE_XMAX : SPH_FACE_YMAX));
    SCENE__TRY(sph_set_hydrostatic(w));
    return SPH_OK;
}

/* Dam break after Martin & Moyce 1952 (validation-data.md sec. 1): a water column a wide and
   2a high (n^2 = 2) at the left end of a closed tank 5a long and 3a high (a deep in 3D), `res`
   particles over a. Gravity -9.81 along y. */
typedef struct scene_dam {
    double a;      /* column width [m]    */
    double length; /* tank length [m]     */
    double height; /* tank height [m]     */
} scene_dam;

SCENE_FN sph_status scene_dam_break(sph_world* w, sph_world_def def, double a, int res,
                                  scene_dam* out) {
    sph_real lo[3] = {0, 0, 0}, hi[3], thi[3];
    sph_phase water;
    int ph;
    memset(&water, 0, sizeof(water));
    water.rest_density = 1000;
    def.spacing = (sph_real)(a / res);
    hi[0] = (sph_real)a; hi[1] = (sph_real)(2 * a); hi[2] = (sph_real)a;
    thi[0] = (sph_real)(5 * a); thi[1] = (sph_real)(3 * a); thi[2] = (sph_real)a;
    SCENE__TRY(sph_world_init(w, &def));
    ph = sph_world_add_phase(w, &water);
    if (ph < 0) return scene__fail(w, w->status);
    SCENE__TRY(sph_fill_box(w, ph, lo, hi));
    SCENE__TRY(sph_add_wall_box(w, lo, thi, 0, 0));
    SCENE__TRY(sph_set_hydrostatic(w));
    if (out) { out->a = a; out->length = 5 * a; out->height = 3 * a; }
    return SPH_OK;
}

/* Surge front: the largest x of fluid particles within 0.1 a of the floor, plus half a spacing
   (a particle stands for a cell), in units of a (Martin & Moyce's Z). */
SCENE_FN double scene_dam_front(const sph_world* w, const scene_dam* d) {
    double xmax = 0;
    size_t i;
    for (i = 0; i < w->n; ++i) {
        const sph_real* x = w->x + i * (size_t)w->dim;
        if (x[1] < 0.1 * d->a && x[0] > xmax) xmax = x[0];
    }
    return (xmax + 0.5 * w->dx) / d->a;
}

/* Martin & Moyce 1952, Table 2 (n^2 = 2, a = 2.25 in): surge front Z = x/a against
   T = t sqrt(2 g / a) (validation-data.md sec. 1 A). */
static const double scene_mm_T[] = {0.41, 0.84, 1.19, 1.43, 1.63, 1.83, 1.98, 2.20,
                                     2.32, 2.51, 2.65, 2.83, 2.98, 3.11, 3.33};
static const double scene_mm_Z[] = {1.11, 1.22, 1.44, 1.67, 1.89, 2.11, 2.33, 2.56,
                                     2.78, 3.00, 3.22, 3.44, 3.67, 3.89, 4.11};
#define SCENE_MM_N 15

/* Time [s] of Martin & Moyce's nondimensional time T for column width a [m]. */
SCENE_FN double scene_mm_time(double T, double a) { return T / sqrt(2 * 9.81 / a); }

#endif
