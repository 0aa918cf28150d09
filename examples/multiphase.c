/* multiphase.c - two fluids: the Rayleigh-Taylor instability, a heavy fluid (density 1.8) over a
   light one (1.0) in a closed 1 x 2 box under gravity g = 1, with a wavy interface, Re = 420
   (scene_rayleigh_taylor in examples/scenes.h; Enhanced PCISPH 2018 sec. 5.4). WCSPH.

   Two phases are two sph_world_add_phase calls; each particle carries its phase (w.phase[i]) and,
   since the two rest densities differ at equal spacing, its own mass (w.m[i]). Across a density
   jump sph.h's notes recommend Ott & Schnetter's particle-density continuity
   (def.density = SPH_DENSITY_PARTICLE: d rho_i/dt = m_i sum_j v_ij . grad W_ij, so a particle
   never takes its heavier neighbours' masses) and their multiphase pressure gradient
   (def.pressure_grad = SPH_PGRAD_MULTIPHASE). The same settings work with the enhanced PCISPH
   (sph_world_def_pcisph(&def, 1); tests/test_pcisph.c runs this scene with it), whose larger
   steps cost more here: about twice WCSPH's run time. A PNG frame every 0.25 s (light fluid
   blue, heavy fluid orange, walls grey) and the heavy fluid's centre of mass over time (CSV) go
   to the output directory.

   Build: cc -O2 -std=c99 -fopenmp -I. examples/multiphase.c -o build/multiphase -lm
   Run:   mkdir -p out && ./build/multiphase [output dir = out]
   Checks (exit status 1 if one fails): each phase's mass is exactly what it was; the heavy
   fluid sank: its centre of mass went down by more than 0.1 m by t = 5; the potential energy
   released pays for the kinetic energy gained (0 < KE <= -dPE; viscosity dissipated the rest);
   no particle left the box. */
#define SPH_IMPLEMENTATION
#include "sph.h"
#include "examples/scenes.h"
#include "examples/draw.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#define LIGHT 0 /* scene_rayleigh_taylor adds the light phase first, then the heavy one */
#define HEAVY 1

static double particle_mass(const sph_world* w, size_t i) {
    return (double)(w->m ? w->m[i] : w->mass); /* w.m exists when masses differ */
}

/* Mass of each phase, the heavy phase's centre of mass height, and the potential energy of all
   the fluid relative to y = 0 (gravity g along -y). */
typedef struct budget {
    double mass[2], y_heavy, pe;
} budget;

static budget measure(const sph_world* w, double g) {
    budget b;
    double my = 0;
    size_t i;
    b.mass[0] = b.mass[1] = 0;
    b.pe = 0;
    for (i = 0; i < w->n; ++i) {
        const double m = particle_mass(w, i), y = (double)w->x[2 * i + 1];
        b.mass[w->phase[i]] += m;
        b.pe += m * g * y;
        if (w->phase[i] == HEAVY) my += m * y;
    }
    b.y_heavy = my / b.mass[HEAVY];
    return b;
}

/* Fluid particles whose centre lies beyond the walls' first layer (half a spacing outside the
   box [0, 1] x [0, 2]). */
static size_t count_escaped(const sph_world* w) {
    const double h = 0.5 * (double)w->dx;
    size_t i, out = 0;
    for (i = 0; i < w->n; ++i) {
        const double x = (double)w->x[2 * i], y = (double)w->x[2 * i + 1];
        if (x < -h || x > 1 + h || y < -h || y > 2 + h) ++out;
    }
    return out;
}

/* Particles as discs in a 400 x 800 px picture of the box, coloured by phase. */
static void render(const sph_world* w, const char* path, const char* label) {
    const double margin = 4 * (double)w->dx;
    draw pic;
    size_t i;
    if (!draw_begin(&pic, w, -margin, -margin, 1 + margin, 2 + margin, 400)) return;
    draw_walls(&pic, w, -1, 140, 140, 140);
    for (i = 0; i < w->n; ++i) {
        const int heavy = w->phase[i] == HEAVY;
        draw_disc(&pic, (double)w->x[2 * i], (double)w->x[2 * i + 1], heavy ? 225 : 60,
                  heavy ? 110 : 120, heavy ? 40 : 210);
    }
    draw_swatch(&pic, "heavy, rho 1.8", 225, 110, 40);
    draw_swatch(&pic, "light, rho 1.0", 60, 120, 210);
    draw_finish(&pic, path, label);
}

int main(int argc, char** argv) {
    const char* dir = argc > 1 ? argv[1] : "out";
    const int res = 24; /* particles per unit length: 24 x 48 in the box */
    const double g = 1, t_end = 5, frame_dt = 0.25;
    sph_world_def def = sph_world_def_default(2);
    sph_world w;
    budget b0, b;
    double ylow = 0;
    size_t i, escaped = 0;
    int frame = 0, failed = 0, samples = 0;
    char path[512], label[160];
    FILE* csv;

    def.density = SPH_DENSITY_PARTICLE;       /* particle-density continuity (Ott & Schnetter) */
    def.pressure_grad = SPH_PGRAD_MULTIPHASE; /* (p_i + p_j) / (rho_i rho_j) across the interface */
    if (scene_rayleigh_taylor(&w, def, res) != SPH_OK) { /* sets g = 1 and no-slip walls */
        fprintf(stderr, "scene: %s\n", scene_error);
        return 1;
    }
    csv = draw_fopen(dir, "multiphase_heavy.csv");
    if (!csv) {
        sph_world_free(&w);
        return 1;
    }
    fprintf(csv, "t,y_heavy,lowest_heavy,potential_energy,kinetic_energy\n");
    b0 = measure(&w, g);
    printf("Rayleigh-Taylor: heavy (%.1f) over light (%.1f) in a 1 x 2 box, g = %.0f, %zu fluid + "
           "%zu wall particles, particle masses %.3g and %.3g\nWCSPH with particle-density "
           "continuity and the multiphase pressure gradient; a frame every %.2f s in %s/\n",
           (double)w.phases[HEAVY].rest_density, (double)w.phases[LIGHT].rest_density, g, w.n, w.nb,
           (double)w.phases[HEAVY].rest_density * (double)(w.dx * w.dx),
           (double)w.phases[LIGHT].rest_density * (double)(w.dx * w.dx), frame_dt, dir);
    printf("%5s %6s %9s %9s %10s %7s %8s %8s\n", "frame", "t [s]", "y heavy", "lowest", "KE",
           "steps", "ms/step", "rho err");
    for (;;) {
        b = measure(&w, g);
        ylow = 2;
        for (i = 0; i < w.n; ++i)
            if (w.phase[i] == HEAVY) ylow = fmin(ylow, (double)w.x[2 * i + 1]);
        escaped += count_escaped(&w);
        ++samples;
        fprintf(csv, "%.3f,%.5f,%.5f,%.6f,%.6f\n", w.time, b.y_heavy, ylow, b.pe,
                w.steps ? w.stats.kinetic_energy : 0.0);
        snprintf(label, sizeof(label), "t = %.2f s  heavy CoM y = %.3f", w.time, b.y_heavy);
        draw_frame_path(path, sizeof(path), dir, "multiphase", frame);
        render(&w, path, label);
        printf("%5d %6.2f %9.4f %9.3f %10.3e %7llu %8.3f %8.4f\n", frame, w.time, b.y_heavy, ylow,
               w.steps ? w.stats.kinetic_energy : 0.0, (unsigned long long)w.steps,
               w.steps ? 1e3 * w.step_time_total / (double)w.steps : 0.0,
               w.steps ? w.stats.density_error_max : 0.0);
        fflush(stdout);
        if (w.time >= t_end - 1e-9) break;
        if (sph_advance(&w, (sph_real)frame_dt) != SPH_OK) {
            fprintf(stderr, "stopped at t = %.3f s: %s\n", w.time, w.error);
            failed = 1;
            break;
        }
        ++frame;
    }
    fclose(csv);
    printf("%llu steps in %.2f s; frames %s/multiphase_0000.png .. %04d.png, history "
           "%s/multiphase_heavy.csv\n",
           (unsigned long long)w.steps, w.step_time_total, dir, frame, dir);

    /* the checks */
    {
        const double ke = w.stats.kinetic_energy, dpe = b.pe - b0.pe;
        printf("phase masses: light %.9g -> %.9g, heavy %.9g -> %.9g (expected unchanged)\n",
               b0.mass[LIGHT], b.mass[LIGHT], b0.mass[HEAVY], b.mass[HEAVY]);
        printf("heavy centre of mass: y = %.4f -> %.4f (expected a drop > 0.1); lowest heavy "
               "particle y = %.3f (the interface started at 0.85 or above)\n",
               b0.y_heavy, b.y_heavy, ylow);
        printf("energy: potential %.5f -> %.5f (change %.5f), kinetic %.5f (expected 0 < KE <= "
               "%.5f)\n", b0.pe, b.pe, dpe, ke, -dpe);
        printf("particles outside the box (summed over %d samples): %zu (expected 0)\n", samples,
               escaped);
        if (failed) printf("FAIL: the run stopped early\n");
        if (b.mass[LIGHT] != b0.mass[LIGHT] || b.mass[HEAVY] != b0.mass[HEAVY]) {
            printf("FAIL: a phase's mass changed\n");
            failed = 1;
        }
        if (!(b.y_heavy < b0.y_heavy - 0.1)) { printf("FAIL: the heavy fluid did not sink\n"); failed = 1; }
        if (!(ke > 0 && ke <= -dpe)) { printf("FAIL: energy budget violated\n"); failed = 1; }
        if (escaped) { printf("FAIL: particles left the box\n"); failed = 1; }
    }
    sph_world_free(&w);
    printf(failed ? "multiphase: FAILED\n" : "multiphase: all checks passed\n");
    return failed ? 1 : 0;
}
