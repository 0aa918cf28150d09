/* dambreak.c - the collapse of a water column (Martin & Moyce 1952) in 2D with WCSPH.
   Prints progress with the surge front against the experiment and writes a PNG frame every
   0.05 s, coloured by speed, to out/ (or the directory given).
   Build: cc -O2 -fopenmp -I. examples/dambreak.c -o dambreak -lm
   Run:   ./dambreak [particles per column width = 40] [end time s = 1.5] [output dir = out] */
#define SPH_IMPLEMENTATION
#include "sph.h"
#include "examples/scenes.h"
#include "examples/draw.h"

#include <stdio.h>
#include <stdlib.h>

/* Martin & Moyce's front Z at nondimensional time T (linear interpolation of their table). */
static double mm_front(double T) {
    int k;
    if (T <= scene_mm_T[0]) return 1 + (scene_mm_Z[0] - 1) * T / scene_mm_T[0];
    for (k = 1; k < SCENE_MM_N; ++k)
        if (T <= scene_mm_T[k])
            return scene_mm_Z[k - 1] + (scene_mm_Z[k] - scene_mm_Z[k - 1]) *
                                           (T - scene_mm_T[k - 1]) / (scene_mm_T[k] - scene_mm_T[k - 1]);
    return -1; /* beyond the table */
}

/* Particles as discs in a 1000 px wide picture of the tank and its walls; fluid coloured by
   speed from 0 to sqrt(2 g 2a), the free-fall speed from the column's top. */
static void render(const sph_world* w, const scene_dam* d, const char* path, const char* label) {
    const double margin = 4 * (double)w->dx;
    draw pic;
    if (!draw_begin(&pic, w, -margin, -margin, d->length + margin, d->height + margin, 1000)) return;
    draw_walls(&pic, w, -1, 140, 140, 140);
    draw_fluid_speed(&pic, w, sqrt(2 * 9.81 * 2 * d->a));
    draw_finish(&pic, path, label);
}

int main(int argc, char** argv) {
    const int res = argc > 1 ? atoi(argv[1]) : 40;
    const double t_end = argc > 2 ? atof(argv[2]) : 1.5, a = 0.5, frame_dt = 0.05;
    const char* dir = argc > 3 ? argv[3] : "out";
    sph_world_def def = sph_world_def_default(2);
    sph_world w;
    scene_dam d;
    double sq = 0;
    unsigned long long psteps = 0;
    int frame = 0, nmm = 0;
    char path[512], label[160], mm[32];
    FILE* csv;
    if (res < 4 || !(t_end > 0)) {
        fprintf(stderr, "usage: %s [res >= 4] [t_end > 0] [dir]\n", argv[0]);
        return 2;
    }
    if (scene_dam_break(&w, def, a, res, &d) != SPH_OK) {
        fprintf(stderr, "scene: %s\n", scene_error);
        return 1;
    }
    csv = draw_fopen(dir, "dambreak_front.csv");
    if (!csv) {
        sph_world_free(&w);
        return 1;
    }
    printf("dam break: column %.2f m x %.2f m in a %.2f m x %.2f m tank, %zu fluid + %zu wall "
           "particles\nc0 = %.1f m/s, h = %.4f m, a frame every %.2f s in %s/\n",
           a, 2 * a, d.length, d.height, w.n, w.nb, (double)w.phases[0].sound_speed, (double)w.h,
           frame_dt, dir);
    fprintf(csv, "t,T,Z_sph,Z_martin_moyce\n");
    printf("%5s %7s %6s %7s %7s %8s %8s %9s\n", "frame", "t [s]", "T", "Z", "Z(M&M)", "steps",
           "ms/step", "rho err");
    for (;;) {
        const double T = w.time * sqrt(2 * 9.81 / a), Z = scene_dam_front(&w, &d), Zmm = mm_front(T);
        snprintf(mm, sizeof(mm), Zmm > 0 ? "%.3f" : "-", Zmm);
        snprintf(label, sizeof(label), "t = %.2f s   T = %.2f   front Z = %.2f   Martin & Moyce %s",
                 w.time, T, Z, mm);
        if (Zmm > 0 && frame > 0) {
            sq += (Z - Zmm) * (Z - Zmm) / (Zmm * Zmm);
            ++nmm;
        }
        draw_frame_path(path, sizeof(path), dir, "dambreak", frame);
        render(&w, &d, path, label);
        fprintf(csv, "%.5f,%.4f,%.4f,%s\n", w.time, T, Z, Zmm > 0 ? mm : "");
        printf("%5d %7.3f %6.2f %7.3f %7s %8llu %8.3f %9.5f\n", frame, w.time, T, Z, mm,
               (unsigned long long)w.steps, w.steps ? 1e3 * w.step_time_total / (double)w.steps : 0.0,
               w.stats.density_error_max);
        fflush(stdout);
        if (w.time >= t_end - 1e-9) break;
        {
            const unsigned long long s0 = w.steps;
            const sph_status s = sph_advance(&w, (sph_real)frame_dt);
            psteps += (w.steps - s0) * (unsigned long long)w.n;
            if (s != SPH_OK) {
                fprintf(stderr, "stopped: %s\n", w.error);
                break;
            }
        }
        ++frame;
    }
    fclose(csv);
    printf("%llu steps in %.2f s: %.3g fluid particle-steps/s; front RMS deviation from Martin & "
           "Moyce %.1f %% over %d frames (T <= 3.33)\n",
           (unsigned long long)w.steps, w.step_time_total,
           w.step_time_total > 0 ? (double)psteps / w.step_time_total : 0.0,
           nmm ? 100 * sqrt(sq / nmm) : 0.0, nmm);
    printf("frames %s/dambreak_0000.png .. dambreak_%04d.png, front history %s/dambreak_front.csv\n",
           dir, frame, dir);
    sph_world_free(&w);
    return 0;
}
