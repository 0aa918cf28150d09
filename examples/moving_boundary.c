/* moving_boundary.c - a piston wave-maker: a paddle moved by def.boundary_motion makes waves in a
   2D tank of water (WCSPH).

   The tank is 2 m long with 0.24 m of water. Its left end is a paddle: three layers of boundary
   particles added with sph_add_boundary under their own body tag (1). The motion callback moves
   only those particles, x = x0 + (S/2) sin(2 pi t / T) with a soft start, and sets their position
   (b_x, from the reference position b_x0), velocity (b_v) and acceleration (b_a, which enters the
   wall pressure). The other walls (body 0) stay where sph_add_wall_box put them. A PNG frame every
   0.1 s (fluid coloured by speed, walls grey, paddle orange) and the water level at the far wall
   over time (CSV) go to the output directory.

   Build: cc -O2 -std=c99 -fopenmp -I. examples/moving_boundary.c -o build/moving_boundary -lm
   Run:   mkdir -p out && ./build/moving_boundary [output dir = out]
   Checks (exit status 1 if one fails): no fluid particle got behind the paddle, under the floor
   or past the far wall; the fluid mass is unchanged; the waves reached the far wall: the water
   there rose by more than half the height H of linear wave-maker theory (at a reflecting wall
   a fully developed crest rises by H; the first crest, made during the soft start, comes close),
   and it first rose (by 1 cm) no sooner than the fastest linear water wave, of speed sqrt(g d),
   could have got there. */
#define SPH_IMPLEMENTATION
#include "sph.h"
#include "examples/draw.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PADDLE 1 /* body tag of the paddle's particles (sph_add_wall_box uses 0) */

static const double PI = 3.14159265358979323846;

typedef struct paddle {
    double stroke; /* peak-to-peak travel S [m]                 */
    double period; /* T [s]                                     */
    double ramp;   /* soft start: the amplitude grows over [s]  */
} paddle;

/* Paddle displacement x(t) = (S/2) sin(w t) r(t), where r = (1 - cos(pi t / ramp)) / 2 grows
   from 0 to 1 during the ramp (so the paddle starts at rest), with its velocity and acceleration. */
static void paddle_state(const paddle* p, double t, double* x, double* v, double* a) {
    const double A = 0.5 * p->stroke, w = 2 * PI / p->period, q = PI / p->ramp;
    double r = 1, r1 = 0, r2 = 0; /* r and its first two time derivatives */
    if (t < p->ramp) {
        r = 0.5 * (1 - cos(q * t));
        r1 = 0.5 * q * sin(q * t);
        r2 = 0.5 * q * q * cos(q * t);
    }
    *x = A * sin(w * t) * r;
    *v = A * (w * cos(w * t) * r + sin(w * t) * r1);
    *a = A * (-w * w * sin(w * t) * r + 2 * w * cos(w * t) * r1 + sin(w * t) * r2);
}

/* def.boundary_motion: called once per step before the neighbour search. Moves the paddle's
   particles only; the fixed walls keep their positions and zero velocity. */
static void paddle_motion(sph_world* w, double t, void* user) {
    double x, v, a;
    size_t b;
    paddle_state((const paddle*)user, t, &x, &v, &a);
    for (b = 0; b < w->nb; ++b) {
        if (w->b_body[b] != PADDLE) continue;
        w->b_x[2 * b] = w->b_x0[2 * b] + (sph_real)x;
        w->b_v[2 * b] = (sph_real)v;
        w->b_a[2 * b] = (sph_real)a;
    }
}

/* Linear wave-maker theory (Biesel 1951): the wave number k of period T in depth d solves
   w^2 = g k tanh(k d) (bisection), and a piston of stroke S makes waves of height
   H = S 2 (cosh 2kd - 1) / (sinh 2kd + 2kd). */
static double piston_wave_height(const paddle* p, double d, double g) {
    const double w = 2 * PI / p->period;
    double lo = 1e-9, hi = 1e3, k = 1, kd;
    int it;
    for (it = 0; it < 100; ++it) {
        k = 0.5 * (lo + hi);
        if (g * k * tanh(k * d) > w * w) hi = k; else lo = k;
    }
    kd = k * d;
    return p->stroke * 2 * (cosh(2 * kd) - 1) / (sinh(2 * kd) + 2 * kd);
}

/* Height of the water at the far wall: the top of the highest fluid particle within two
   spacings of the wall at x = L. */
static double far_level(const sph_world* w, double L) {
    double top = 0;
    size_t i;
    for (i = 0; i < w->n; ++i)
        if ((double)w->x[2 * i] > L - 2 * (double)w->dx)
            top = fmax(top, (double)w->x[2 * i + 1] + 0.5 * (double)w->dx);
    return top;
}

/* Fluid particles whose centre lies beyond the first layer of the paddle, the floor or the far
   wall (the walls' first layers sit half a spacing outside the water). */
static size_t count_escaped(const sph_world* w, double L, double x_paddle) {
    const double h = 0.5 * (double)w->dx;
    size_t i, out = 0;
    for (i = 0; i < w->n; ++i) {
        const double x = (double)w->x[2 * i], y = (double)w->x[2 * i + 1];
        if (x < x_paddle - h || x > L + h || y < -h) ++out;
    }
    return out;
}

/* Particles as discs in a 1000 px wide picture of the tank; fluid coloured by speed (0 .. umax),
   walls grey, the paddle orange. */
static void render(const sph_world* w, const double* view, double umax, const char* path,
                   const char* label) {
    draw pic;
    if (!draw_begin(&pic, w, view[0], view[1], view[2], view[3], 1000)) return;
    draw_walls(&pic, w, -1, 140, 140, 140);
    draw_walls(&pic, w, PADDLE, 230, 120, 30);
    draw_fluid_speed(&pic, w, umax);
    draw_swatch(&pic, "paddle", 230, 120, 30);
    draw_finish(&pic, path, label);
}

int main(int argc, char** argv) {
    const char* dir = argc > 1 ? argv[1] : "out";
    const double L = 2.0, depth = 0.24, wall = 0.6, dx = 0.02, g = 9.81;
    const double t_end = 3.0, sample_dt = 0.02, umax = 0.3;
    const int frame_every = 5; /* samples per PNG frame: one every 0.1 s */
    const double view[4] = {-0.2, -0.08, 2.08, 0.44}; /* picture: x0, y0, x1, y1 [m] */
    sph_world_def def = sph_world_def_default(2);
    sph_world w;
    sph_phase water;
    paddle pad;
    sph_real lo[2], hi[2], wlo[2], whi[2], *px;
    double m0, level0, level_max = 0, t_rise = -1, x_p, v_p, a_p;
    const int rows = (int)(wall / dx + 0.5);
    size_t np = 0, escaped = 0;
    int sample = 0, frame = 0, j, k, failed = 0;
    char path[512], label[200];
    FILE* csv;

    pad.stroke = 0.08;
    pad.period = 1.2;
    pad.ramp = 1.2;
    def.spacing = (sph_real)dx;
    def.boundary_motion = paddle_motion; /* the library calls it before every step */
    def.boundary_user = &pad;
    memset(&water, 0, sizeof(water)); /* zero fields take their defaults (c0 automatic) */
    water.rest_density = 1000;
    if (sph_world_init(&w, &def) != SPH_OK || sph_world_add_phase(&w, &water) < 0) {
        fprintf(stderr, "setup: %s\n", w.error);
        sph_world_free(&w);
        return 1;
    }
    /* water from the paddle's rest position x = 0 to the far wall x = L */
    lo[0] = 0;
    lo[1] = 0;
    hi[0] = (sph_real)L;
    hi[1] = (sph_real)depth;
    /* the fixed walls: floor and far wall, open at the top and at the left, where the floor
       runs on under the paddle's whole travel (it moves up to S/2 to the left of x = 0) */
    wlo[0] = (sph_real)view[0];
    wlo[1] = 0;
    whi[0] = (sph_real)L;
    whi[1] = (sph_real)wall;
    /* the paddle: 3 layers (enough for the kernel support of 2.6 dx) just left of x = 0, from the
       floor's top layer up to the walls' height, body tag PADDLE */
    px = (sph_real*)malloc((size_t)(3 * rows) * 2 * sizeof(sph_real));
    if (!px) {
        fprintf(stderr, "out of memory\n");
        sph_world_free(&w);
        return 1;
    }
    for (k = 0; k < 3; ++k)
        for (j = 0; j < rows; ++j, ++np) {
            px[2 * np] = (sph_real)(-(k + 0.5) * dx);
            px[2 * np + 1] = (sph_real)((j + 0.5) * dx);
        }
    if (sph_fill_box(&w, 0, lo, hi) != SPH_OK ||
        sph_add_wall_box(&w, wlo, whi, 0, SPH_FACE_XMIN | SPH_FACE_YMAX) != SPH_OK ||
        sph_add_boundary(&w, np, px, NULL, PADDLE) != SPH_OK || sph_set_hydrostatic(&w) != SPH_OK) {
        fprintf(stderr, "setup: %s\n", w.error);
        free(px);
        sph_world_free(&w);
        return 1;
    }
    free(px);

    csv = draw_fopen(dir, "moving_boundary_level.csv");
    if (!csv) {
        sph_world_free(&w);
        return 1;
    }
    fprintf(csv, "t,paddle_x,far_level\n");
    m0 = sph_world_mass(&w);
    level0 = far_level(&w, L);
    printf("wave tank: %.1f m long, water %.2f m deep, %zu fluid + %zu wall particles (%zu on the "
           "paddle)\npaddle: stroke %.2f m, period %.1f s, soft start over %.1f s; a frame every "
           "0.1 s in %s/\n",
           L, depth, w.n, w.nb, np, pad.stroke, pad.period, pad.ramp, dir);
    printf("%5s %6s %9s %12s %9s %7s %8s\n", "frame", "t [s]", "paddle x", "far level", "max |v|",
           "steps", "ms/step");
    for (;;) {
        const double level = far_level(&w, L);
        paddle_state(&pad, w.time, &x_p, &v_p, &a_p);
        escaped += count_escaped(&w, L, x_p);
        level_max = fmax(level_max, level);
        if (t_rise < 0 && level > level0 + 0.01) t_rise = w.time;
        fprintf(csv, "%.3f,%.5f,%.5f\n", w.time, x_p, level);
        if (sample % frame_every == 0) {
            snprintf(label, sizeof(label), "t = %.1f s   paddle x = %+.3f m   far wall level %+.3f m",
                     w.time, x_p, level - level0);
            draw_frame_path(path, sizeof(path), dir, "moving_boundary", frame++);
            render(&w, view, umax, path, label);
            printf("%5d %6.2f %+9.3f %+12.4f %9.3f %7llu %8.3f\n", frame - 1, w.time, x_p,
                   level - level0, w.stats.v_max, (unsigned long long)w.steps,
                   w.steps ? 1e3 * w.step_time_total / (double)w.steps : 0.0);
            fflush(stdout);
        }
        if (w.time >= t_end - 1e-9) break;
        if (sph_advance(&w, (sph_real)sample_dt) != SPH_OK) {
            fprintf(stderr, "stopped at t = %.3f s: %s\n", w.time, w.error);
            failed = 1;
            break;
        }
        ++sample;
    }
    fclose(csv);
    printf("%llu steps in %.2f s (c0 = %.1f m/s); frames %s/moving_boundary_0000.png .. %04d.png, "
           "level history %s/moving_boundary_level.csv\n",
           (unsigned long long)w.steps, w.step_time_total, (double)w.phases[0].sound_speed, dir,
           frame - 1, dir);

    /* the checks */
    {
        const double t_linear = L / sqrt(g * depth), dm = sph_world_mass(&w) - m0;
        const double H = piston_wave_height(&pad, depth, g);
        printf("particles outside the tank (summed over %d samples): %zu (expected 0)\n", sample + 1,
               escaped);
        printf("fluid mass: %.6f kg, change %.3g kg (expected 0)\n", m0, dm);
        printf("far wall: level rose by up to %.4f m; linear theory: waves of height H = %.4f m, "
               "a crest at the wall rises by H (expected > H/2)\n", level_max - level0, H);
        printf("far wall: first rose by 1 cm at t = %.2f s (expected no sooner than the fastest "
               "linear wave, sqrt(g d) = %.2f m/s, arrives: %.2f s)\n", t_rise, sqrt(g * depth),
               t_linear);
        if (failed) printf("FAIL: the run stopped early\n");
        if (escaped) { printf("FAIL: fluid particles left the tank\n"); failed = 1; }
        if (dm != 0) { printf("FAIL: the fluid mass changed\n"); failed = 1; }
        if (!(level_max - level0 > 0.5 * H)) { printf("FAIL: no wave reached the far wall\n"); failed = 1; }
        if (t_rise >= 0 && t_rise < t_linear) {
            printf("FAIL: the level rose before a wave could arrive\n");
            failed = 1;
        }
    }
    sph_world_free(&w);
    printf(failed ? "moving_boundary: FAILED\n" : "moving_boundary: all checks passed\n");
    return failed ? 1 : 0;
}
