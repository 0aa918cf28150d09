/* examples/scenes.h - scene constructors shared by examples, tests and bench, so all three run
   the same setups. Include after sph.h (with or without SPH_IMPLEMENTATION). Every constructor
   takes a def prepared by the caller (kernel, solver, integrator ... as the caller wants), sets
   the scene's geometry fields, and builds the world; on failure the world is freed and the
   status returned (w->error is kept in scene_error). */
#ifndef SPH_SCENES_H
#define SPH_SCENES_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
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

/* Hydrostatic tank (Adami, Hu & Adams 2012 sec. 6): water of depth
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

/* Dam break after Martin & Moyce 1952: a water column a wide and
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

/* Stirrer after Meiers 2025 sec. 5.1.2: an oval container (semi-axes 0.5 m x 0.35 m, one layer of
   wall particles at spacing dx) holds water up to `fill` of its height, stirred by a rotor at the
   centre: a hub of radius 0.06 m and three blades 0.2 m long whose particles are spaced
   non-uniformly (from 0.5 dx at the hub to 1.0 dx at the tip), rotating at omega [rad/s].
   Boundary volumes come from the particle density (SPH_BVOL_AKINCI). Body 0 is the container,
   body 1 the rotor; the motion callback is scene_stirrer_motion with a scene_stirrer as user. */
typedef struct scene_stirrer {
    double omega;      /* rotor angular velocity [rad/s], counter-clockwise */
    double cx, cy;     /* centre [m] */
} scene_stirrer;

SCENE_FN void scene_stirrer_motion(sph_world* w, double t, void* user) {
    const scene_stirrer* s = (const scene_stirrer*)user;
    const double c = cos(s->omega * t), sn = sin(s->omega * t), om = s->omega;
    size_t b;
    for (b = 0; b < w->nb; ++b) {
        double rx, ry, x, y;
        if (w->b_body[b] != 1) continue;
        rx = (double)w->b_x0[2 * b] - s->cx;
        ry = (double)w->b_x0[2 * b + 1] - s->cy;
        x = c * rx - sn * ry;
        y = sn * rx + c * ry;
        w->b_x[2 * b] = (sph_real)(s->cx + x);
        w->b_x[2 * b + 1] = (sph_real)(s->cy + y);
        w->b_v[2 * b] = (sph_real)(-om * y); /* omega x r */
        w->b_v[2 * b + 1] = (sph_real)(om * x);
        w->b_a[2 * b] = (sph_real)(-om * om * x); /* centripetal */
        w->b_a[2 * b + 1] = (sph_real)(-om * om * y);
    }
}

SCENE_FN sph_status scene_stirrer_build(sph_world* w, sph_world_def def, double dx, double fill,
                                        scene_stirrer* st) {
    const double A = 0.5, B = 0.35, pi = 3.14159265358979323846, hub = 0.06, blade = 0.2;
    sph_phase water;
    sph_real* pts = NULL;
    size_t n = 0, cap, k;
    int ph, i, j, blade_i;
    memset(&water, 0, sizeof(water));
    water.rest_density = 1000;
    def.spacing = (sph_real)dx;
    def.boundary_volume = SPH_BVOL_AKINCI;
    def.boundary_motion = scene_stirrer_motion;
    def.boundary_user = st;
    st->cx = A;
    st->cy = B;
    SCENE__TRY(sph_world_init(w, &def));
    ph = sph_world_add_phase(w, &water);
    if (ph < 0) return scene__fail(w, w->status);
    cap = (size_t)(4 * pi * A / dx) + (size_t)(4 * (A / dx) * (B / dx)) + 4096;
    pts = (sph_real*)malloc(cap * 2 * sizeof(sph_real));
    if (!pts) return scene__fail(w, SPH_ERR_NOMEM);
    { /* container: one layer, equal arc length along the ellipse (Ramanujan perimeter) */
        const double h = (A - B) * (A - B) / ((A + B) * (A + B));
        const double per = pi * (A + B) * (1 + 3 * h / (10 + sqrt(4 - 3 * h)));
        const int m = (int)(per / dx + 0.5);
        double th = 0;
        for (i = 0; i < m; ++i) {
            /* step the parameter so the arc length advances by per / m */
            double ds = per / m, sp = sqrt(A * A * sin(th) * sin(th) + B * B * cos(th) * cos(th));
            pts[2 * n] = (sph_real)(st->cx + A * cos(th));
            pts[2 * n + 1] = (sph_real)(st->cy + B * sin(th));
            ++n;
            th += ds / sp;
        }
        if (sph_add_boundary(w, n, pts, NULL, 0) != SPH_OK) { free(pts); return scene__fail(w, w->status); }
    }
    n = 0;
    { /* rotor: hub circle and three blades, spacing growing from 0.5 dx to dx */
        const int m = (int)(2 * pi * hub / (0.5 * dx));
        for (i = 0; i < m; ++i) {
            pts[2 * n] = (sph_real)(st->cx + hub * cos(2 * pi * i / m));
            pts[2 * n + 1] = (sph_real)(st->cy + hub * sin(2 * pi * i / m));
            ++n;
        }
        for (blade_i = 0; blade_i < 3; ++blade_i) {
            const double ang = 2 * pi * blade_i / 3;
            double r = hub + 0.5 * dx;
            while (r <= hub + blade) {
                pts[2 * n] = (sph_real)(st->cx + r * cos(ang));
                pts[2 * n + 1] = (sph_real)(st->cy + r * sin(ang));
                ++n;
                r += dx * (0.5 + 0.5 * (r - hub) / blade);
            }
        }
        if (sph_add_boundary(w, n, pts, NULL, 1) != SPH_OK) { free(pts); return scene__fail(w, w->status); }
    }
    n = 0;
    { /* water: lattice points inside the ellipse (a spacing from it), below the fill level,
         a spacing away from the rotor's hub and blades */
        for (i = 0; i < (int)(2 * A / dx); ++i)
            for (j = 0; j < (int)(2 * B / dx); ++j) {
                const double x = (i + 0.5) * dx, y = (j + 0.5) * dx;
                const double ex = (x - st->cx) / (A - dx), ey = (y - st->cy) / (B - dx);
                const double rx = x - st->cx, ry = y - st->cy, r = sqrt(rx * rx + ry * ry);
                int near = r < hub + dx;
                for (blade_i = 0; blade_i < 3 && !near; ++blade_i) {
                    const double ang = 2 * pi * blade_i / 3, ux = cos(ang), uy = sin(ang);
                    const double along = rx * ux + ry * uy, across = fabs(-rx * uy + ry * ux);
                    if (along > 0 && along < hub + blade + dx && across < dx) near = 1;
                }
                if (ex * ex + ey * ey < 1 && y < 2 * B * fill && !near && n < cap) {
                    pts[2 * n] = (sph_real)x;
                    pts[2 * n + 1] = (sph_real)y;
                    ++n;
                }
            }
        if (sph_add_fluid(w, ph, n, pts, NULL) != SPH_OK) { free(pts); return scene__fail(w, w->status); }
    }
    free(pts);
    (void)k;
    return SPH_OK;
}

/* The largest value of (x/a)^2 + (y/b)^2 over fluid particles relative to the container's centre:
   below 1 means every particle is inside the oval. */
SCENE_FN double scene_stirrer_extent(const sph_world* w, const scene_stirrer* st) {
    double worst = 0;
    size_t i;
    for (i = 0; i < w->n; ++i) {
        const double ex = ((double)w->x[2 * i] - st->cx) / 0.5, ey = ((double)w->x[2 * i + 1] - st->cy) / 0.35;
        if (ex * ex + ey * ey > worst) worst = ex * ex + ey * ey;
    }
    return worst;
}

/* Rayleigh-Taylor instability (Cummins & Rudman 1999; Enhanced PCISPH 2018 sec. 5.4): a closed 1 x
   2 box, heavy fluid (1.8) above light (1.0), interface y = 1 - 0.15 sin(2 pi x), g = -1, kinematic
   viscosity 1/420 for both (Re = 420), no-slip walls, `res` particles per unit length. Phase 0
   is the light fluid, phase 1 the heavy one. */
SCENE_FN sph_status scene_rayleigh_taylor(sph_world* w, sph_world_def def, int res) {
    const double dx = 1.0 / res, pi = 3.14159265358979323846;
    sph_phase light, heavy;
    sph_real *pl = NULL, *ph = NULL, lo[2] = {0, 0}, hi[2] = {1, 2};
    size_t nl = 0, nh = 0;
    int i, j, a, b;
    memset(&light, 0, sizeof(light));
    memset(&heavy, 0, sizeof(heavy));
    light.rest_density = 1;
    heavy.rest_density = (sph_real)1.8;
    light.viscosity = heavy.viscosity = (sph_real)(1.0 / 420);
    def.spacing = (sph_real)dx;
    def.gravity[0] = 0;
    def.gravity[1] = -1;
    def.wall = SPH_WALL_NO_SLIP;
    SCENE__TRY(sph_world_init(w, &def));
    a = sph_world_add_phase(w, &light);
    b = sph_world_add_phase(w, &heavy);
    if (a < 0 || b < 0) return scene__fail(w, w->status);
    pl = (sph_real*)malloc((size_t)(2 * res * res) * 2 * sizeof(sph_real));
    ph = (sph_real*)malloc((size_t)(2 * res * res) * 2 * sizeof(sph_real));
    if (!pl || !ph) { free(pl); free(ph); return scene__fail(w, SPH_ERR_NOMEM); }
    for (j = 0; j < 2 * res; ++j)
        for (i = 0; i < res; ++i) {
            const double x = (i + 0.5) * dx, y = (j + 0.5) * dx;
            sph_real* q = y > 1 - 0.15 * sin(2 * pi * x) ? ph + 2 * nh++ : pl + 2 * nl++;
            q[0] = (sph_real)x;
            q[1] = (sph_real)y;
        }
    if (sph_add_fluid(w, a, nl, pl, NULL) != SPH_OK || sph_add_fluid(w, b, nh, ph, NULL) != SPH_OK) {
        free(pl);
        free(ph);
        return scene__fail(w, w->status);
    }
    free(pl);
    free(ph);
    SCENE__TRY(sph_add_wall_box(w, lo, hi, 0, 0));
    SCENE__TRY(sph_set_hydrostatic(w));
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

/* Taylor-Green vortex (Negi & Ramachandran 2022 sec. III B): unit periodic box, U = 1 m/s,
   rho0 = 1, Re = 100 (nu = 0.01 m^2/s), N x N particles on the lattice, quintic spline with
   h = 1.2 dx unless def says otherwise, no gravity; velocity and pressure of the exact solution
   at t = 0, the fluid density from the Tait law's inverse (Negi & Ramachandran 2022: "rho by
   inverting the EOS"). The exact field at time t: scene_tg_exact. */
#define SCENE_TG_PI 3.14159265358979323846
SCENE_FN void scene_tg_exact(double x, double y, double t, double* u, double* v, double* p) {
    const double b = -8 * SCENE_TG_PI * SCENE_TG_PI / 100, e = exp(b * t);
    *u = -e * cos(2 * SCENE_TG_PI * x) * sin(2 * SCENE_TG_PI * y);
    *v = e * sin(2 * SCENE_TG_PI * x) * cos(2 * SCENE_TG_PI * y);
    *p = -0.25 * e * e * (cos(4 * SCENE_TG_PI * x) + cos(4 * SCENE_TG_PI * y));
}

SCENE_FN sph_status scene_taylor_green(sph_world* w, sph_world_def def, int N, double c0) {
    sph_real lo[2] = {0, 0}, hi[2] = {1, 1};
    sph_phase fluid;
    size_t i;
    int ph, k;
    def.dim = 2;
    def.spacing = (sph_real)(1.0 / N);
    for (k = 0; k < 2; ++k) {
        def.gravity[k] = 0;
        def.periodic[k] = 1;
        def.domain_lo[k] = 0;
        def.domain_hi[k] = 1;
    }
    memset(&fluid, 0, sizeof(fluid));
    fluid.rest_density = 1;
    fluid.sound_speed = (sph_real)c0;
    fluid.viscosity = (sph_real)0.01;
    SCENE__TRY(sph_world_init(w, &def));
    ph = sph_world_add_phase(w, &fluid);
    if (ph < 0) return scene__fail(w, w->status);
    SCENE__TRY(sph_fill_box(w, ph, lo, hi));
    for (i = 0; i < w->n; ++i) {
        double u, v, p;
        scene_tg_exact((double)w->x[2 * i], (double)w->x[2 * i + 1], 0, &u, &v, &p);
        w->v[2 * i] = (sph_real)u;
        w->v[2 * i + 1] = (sph_real)v;
        w->rho[i] = (sph_real)pow(7 * p / (c0 * c0) + 1, 1.0 / 7); /* Tait, gamma 7, rho0 1 */
    }
    return SPH_OK;
}

/* A closed box of water without gravity (a square of side L, N particles across, walls on all
   sides by sph_add_wall_box), set turning as one cell of the vortex u = sin(pi x/L) cos(pi y/L),
   v = -cos(pi x/L) sin(pi y/L) (zero normal velocity on the walls; with free-slip walls its
   kinetic energy decays as exp(-4 pi^2 nu t / L^2), the Stokes decay of the mode). Water:
   rho0 1000, kinematic viscosity nu, sound speed c0 (0: automatic). */
SCENE_FN sph_status scene_vortex_box(sph_world* w, sph_world_def def, double L, int N, double nu,
                                     double c0) {
    sph_real lo[2] = {0, 0}, hi[2];
    sph_phase water;
    size_t i;
    hi[0] = hi[1] = (sph_real)L;
    def.dim = 2;
    def.spacing = (sph_real)(L / N);
    def.gravity[0] = def.gravity[1] = 0;
    memset(&water, 0, sizeof(water));
    water.rest_density = 1000;
    water.viscosity = (sph_real)nu;
    water.sound_speed = (sph_real)c0;
    SCENE__TRY(sph_world_init(w, &def));
    if (sph_world_add_phase(w, &water) < 0) return scene__fail(w, w->status);
    SCENE__TRY(sph_fill_box(w, 0, lo, hi));
    SCENE__TRY(sph_add_wall_box(w, lo, hi, 0, 0));
    for (i = 0; i < w->n; ++i) {
        const double x = (double)w->x[2 * i] / L, y = (double)w->x[2 * i + 1] / L;
        w->v[2 * i] = (sph_real)(sin(SCENE_TG_PI * x) * cos(SCENE_TG_PI * y));
        w->v[2 * i + 1] = (sph_real)(-cos(SCENE_TG_PI * x) * sin(SCENE_TG_PI * y));
    }
    return SPH_OK;
}

/* Errors against the exact solution at w->time: mean |(|u| - |u_exact|)| and mean |p - p_exact|
   with the mean pressure removed (a weakly compressible run carries a constant offset), both
   over the particles (Negi & Ramachandran 2022 eq. 36 at one instant); ke_ratio = kinetic energy /
   exact. */
SCENE_FN void scene_tg_errors(const sph_world* w, double* l1_u, double* l1_p, double* ke_ratio) {
    double eu = 0, ep = 0, pm = 0, ke = 0, ke_ex = 0;
    size_t i;
    for (i = 0; i < w->n; ++i) pm += (double)w->p[i] / (double)w->n;
    for (i = 0; i < w->n; ++i) {
        double u, v, p;
        const double su = (double)w->v[2 * i], sv = (double)w->v[2 * i + 1];
        scene_tg_exact((double)w->x[2 * i], (double)w->x[2 * i + 1], w->time, &u, &v, &p);
        eu += fabs(sqrt(su * su + sv * sv) - sqrt(u * u + v * v));
        ep += fabs((double)w->p[i] - pm - p);
        ke += su * su + sv * sv;
        ke_ex += u * u + v * v;
    }
    *l1_u = eu / (double)w->n;
    *l1_p = ep / (double)w->n;
    *ke_ratio = ke / ke_ex;
}

/* Martin & Moyce 1952, Table 2 (n^2 = 2, a = 2.25 in): surge front Z = x/a against
   T = t sqrt(2 g / a). */
static const double scene_mm_T[] = {0.41, 0.84, 1.19, 1.43, 1.63, 1.83, 1.98, 2.20,
                                     2.32, 2.51, 2.65, 2.83, 2.98, 3.11, 3.33};
static const double scene_mm_Z[] = {1.11, 1.22, 1.44, 1.67, 1.89, 2.11, 2.33, 2.56,
                                     2.78, 3.00, 3.22, 3.44, 3.67, 3.89, 4.11};
#define SCENE_MM_N 15

/* Time [s] of Martin & Moyce's nondimensional time T for column width a [m]. */
SCENE_FN double scene_mm_time(double T, double a) { return T / sqrt(2 * 9.81 / a); }

/* Lid-driven cavity (Ghia, Ghia & Shin 1982): fluid of rest density
   1 kg/m^3 filling the unit square, no gravity, kinematic viscosity nu = U L / Re [m^2/s] with
   U = SCENE_CAVITY_U = 1 m/s and L = 1 m, sound speed 10 U (PySPH's cavity.py), no-slip walls
   (Adami's extrapolated wall velocity). Body 0 is the fixed box (bottom and sides), body 1 the
   lid above y = 1, spanning the side walls' layers so the top corners are closed; the lid keeps
   its position and moves tangentially at u = U through scene_cavity_lid, the motion callback
   (a moving wall enters the no-slip viscous terms and IISPH's source only through b_v).
   `res` particles over the side. */
#define SCENE_CAVITY_U 1.0

SCENE_FN void scene_cavity_lid(sph_world* w, double t, void* user) {
    size_t b;
    int k;
    (void)t;
    (void)user;
    for (b = 0; b < w->nb; ++b) {
        if (w->b_body[b] != 1) continue;
        for (k = 0; k < w->dim; ++k) {
            w->b_x[b * (size_t)w->dim + (size_t)k] = w->b_x0[b * (size_t)w->dim + (size_t)k];
            w->b_v[b * (size_t)w->dim + (size_t)k] = (sph_real)(k == 0 ? SCENE_CAVITY_U : 0);
            w->b_a[b * (size_t)w->dim + (size_t)k] = 0;
        }
    }
}

SCENE_FN sph_status scene_cavity(sph_world* w, sph_world_def def, int res, double Re) {
    sph_real lo[2] = {0, 0}, hi[2] = {1, 1}, *pts;
    sph_phase fluid;
    int ph, layers, i, j, m;
    size_t n = 0;
    def.dim = 2;
    def.spacing = (sph_real)(1.0 / res);
    def.gravity[0] = def.gravity[1] = def.gravity[2] = 0;
    def.wall = SPH_WALL_NO_SLIP;
    def.boundary_motion = scene_cavity_lid;
    def.boundary_user = NULL;
    memset(&fluid, 0, sizeof(fluid));
    fluid.rest_density = 1;
    fluid.sound_speed = (sph_real)(10 * SCENE_CAVITY_U);
    fluid.viscosity = (sph_real)(SCENE_CAVITY_U * 1.0 / Re);
    SCENE__TRY(sph_world_init(w, &def));
    ph = sph_world_add_phase(w, &fluid);
    if (ph < 0) return scene__fail(w, w->status);
    SCENE__TRY(sph_fill_box(w, ph, lo, hi));
    SCENE__TRY(sph_add_wall_box(w, lo, hi, 0, SPH_FACE_YMAX));
    layers = (int)ceil((double)(w->kernel.radius / w->dx) - 1e-9); /* as sph_add_wall_box */
    m = res + 2 * layers;
    pts = (sph_real*)malloc((size_t)(m * layers) * 2 * sizeof(sph_real));
    if (!pts) return scene__fail(w, SPH_ERR_NOMEM);
    for (j = 0; j < layers; ++j)
        for (i = 0; i < m; ++i) {
            pts[2 * n] = (sph_real)((i - layers + 0.5) * (double)w->dx);
            pts[2 * n + 1] = (sph_real)(1 + (j + 0.5) * (double)w->dx);
            ++n;
        }
    if (sph_add_boundary(w, n, pts, NULL, 1) != SPH_OK) { free(pts); return scene__fail(w, w->status); }
    free(pts);
    scene_cavity_lid(w, 0, NULL); /* so that sph_stable_dt sees the lid speed before step 1 */
    return SPH_OK;
}

/* Ghia, Ghia & Shin 1982, J. Comput. Phys. 48, 387-411, Re = 100: Table I, u along the vertical
   centre line x = 0.5 (at y = scene_ghia_y), and Table II, v along the horizontal centre line
   y = 0.5 (at x = scene_ghia_x); unit cavity, lid u = 1 at y = 1 (Ghia, Ghia & Shin 1982). */
#define SCENE_GHIA_N 17
static const double scene_ghia_y[] = {1.0000, 0.9766, 0.9688, 0.9609, 0.9531, 0.8516,
                                       0.7344, 0.6172, 0.5000, 0.4531, 0.2813, 0.1719,
                                       0.1016, 0.0703, 0.0625, 0.0547, 0.0000};
static const double scene_ghia_u100[] = {1.0000,   0.84123,  0.78871,  0.73722,  0.68717,
                                          0.23151,  0.00332,  -0.13641, -0.20581, -0.21090,
                                          -0.15662, -0.10150, -0.06434, -0.04775, -0.04192,
                                          -0.03717, 0.00000};
static const double scene_ghia_x[] = {1.0000, 0.9688, 0.9609, 0.9531, 0.9453, 0.9063,
                                       0.8594, 0.8047, 0.5000, 0.2344, 0.2266, 0.1563,
                                       0.0938, 0.0781, 0.0703, 0.0625, 0.0000};
static const double scene_ghia_v100[] = {0.00000,  -0.05906, -0.07391, -0.08864, -0.10313,
                                          -0.16914, -0.22445, -0.24533, 0.05454,  0.17527,
                                          0.17507,  0.16077,  0.12317,  0.10890,  0.10091,
                                          0.09233,  0.00000};

/* Two-layer tank (Enhanced PCISPH 2018 sec. 5.3): scene_hydrostatic's tank with
   water (rho0 = 1000 kg/m^3) below depth/2 and a phase of rest density ratio * rho0 above, up
   to `depth` [m], `res` particles over the depth, both at the same spacing (so the particle
   masses differ by the ratio), initialised in hydrostatic equilibrium. Phase 0 is the water.
   scene_two_layer_p gives the exact pressure [Pa] at height y [m] for gravity g [m/s^2]. */
SCENE_FN sph_status scene_two_layer(sph_world* w, sph_world_def def, double width, double depth,
                                    int res, double ratio) {
    sph_real lo[2] = {0, 0}, hi[2], whi[2];
    sph_phase heavy, light;
    int a, b;
    def.dim = 2;
    def.spacing = (sph_real)(depth / res);
    hi[0] = whi[0] = (sph_real)width;
    hi[1] = (sph_real)(depth / 2);
    whi[1] = (sph_real)(1.4 * depth);
    memset(&heavy, 0, sizeof(heavy));
    memset(&light, 0, sizeof(light));
    heavy.rest_density = 1000;
    light.rest_density = (sph_real)(1000 * ratio);
    SCENE__TRY(sph_world_init(w, &def));
    a = sph_world_add_phase(w, &heavy);
    b = sph_world_add_phase(w, &light);
    if (a < 0 || b < 0) return scene__fail(w, w->status);
    SCENE__TRY(sph_fill_box(w, a, lo, hi));
    lo[1] = hi[1];
    hi[1] = (sph_real)depth;
    SCENE__TRY(sph_fill_box(w, b, lo, hi));
    lo[1] = 0;
    SCENE__TRY(sph_add_wall_box(w, lo, whi, 0, SPH_FACE_YMAX));
    SCENE__TRY(sph_set_hydrostatic(w));
    return SPH_OK;
}

/* p = rho1 g (H - y) above the interface H/2, rho1 g H/2 + rho0 g (H/2 - y) below it
   (hydrostatics), rho0 = 1000, rho1 = ratio rho0. */
SCENE_FN double scene_two_layer_p(double y, double depth, double ratio, double g) {
    const double r0 = 1000, r1 = 1000 * ratio, H = depth;
    return y > H / 2 ? r1 * g * (H - y) : r1 * g * H / 2 + r0 * g * (H / 2 - y);
}

#endif
