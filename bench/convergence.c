/* bench/convergence.c - Negi & Ramachandran 2022's Taylor-Green convergence study (Re = 100, unit
   periodic box, t = 0.5 s): L1 errors of |u| and p against the exact solution for the second-order
   scheme (def.scheme = SPH_SCHEME_SECOND_ORDER, L-IPST-C) at c0 = 20, 40, 80 m/s and for the plain
   WCSPH step at c0 = 20 and 80, over N^2 particles, N = 20, 28, 40, 56, 80 (a factor sqrt 2 apart;
   up to the first argument, at most 160), with the order fitted by least squares.
   dt = 0.3 h / (U + c0) per resolution (the paper fixes it by the finest resolution; with RK2 the
   time error is second order too). Quintic spline, h = 1.2 dx.
   Build: cc -O2 -fopenmp -I. bench/convergence.c -o convergence -lm
   Run:   ./convergence [max N = 80] [output directory = bench/results]
   (about 20 minutes on 2 cores at the default; the paper went to 500^2)
   Writes taylor_green.csv, taylor_green_u.svg, taylor_green_p.svg. */
#define SPH_IMPLEMENTATION
#include "sph.h"
#include "examples/scenes.h"
#include "bench/svg.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct tg_run {
    double l1_u, l1_p, ke, seconds;
    int ok;
} tg_run;

static tg_run run(int N, double c0, int second_order) {
    sph_world_def def = sph_world_def_default(2);
    sph_world w;
    tg_run r;
    double dt;
    int s, steps;
    memset(&r, 0, sizeof r);
    def.kernel = SPH_KERNEL_QUINTIC;
    def.h_factor = (sph_real)1.2;
    if (second_order) {
        def.scheme = SPH_SCHEME_SECOND_ORDER;
        def.alpha = 0;
        def.delta = 0;
    }
    if (scene_taylor_green(&w, def, N, c0) != SPH_OK) {
        fprintf(stderr, "scene: %s\n", scene_error);
        return r;
    }
    dt = 0.3 * (double)w.h / (1 + c0);
    steps = (int)ceil(0.5 / dt - 1e-9);
    dt = 0.5 / steps;
    r.ok = 1;
    for (s = 0; s < steps; ++s)
        if (sph_step_wcsph(&w, (sph_real)dt) != SPH_OK) {
            fprintf(stderr, "N %d c0 %g: %s\n", N, c0, w.error);
            r.ok = 0;
            break;
        }
    r.seconds = w.step_time_total;
    if (r.ok) scene_tg_errors(&w, &r.l1_u, &r.l1_p, &r.ke);
    sph_world_free(&w);
    return r;
}

static double order(const int* N, const double* e, int m) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int q, k = 0;
    for (q = 0; q < m; ++q) {
        if (!(e[q] > 0)) continue;
        sx += log(1.0 / N[q]), sy += log(e[q]), sxx += log(1.0 / N[q]) * log(1.0 / N[q]);
        sxy += log(1.0 / N[q]) * log(e[q]);
        ++k;
    }
    return k < 2 ? NAN : (k * sxy - sx * sy) / (k * sxx - sx * sx);
}

int main(int argc, char** argv) {
    static const int Ns[] = {20, 28, 40, 56, 80, 113, 160};
    static const struct { double c0; int soc; const char* name; } series[] = {
        {20, 1, "L-IPST-C, c0 = 20"}, {40, 1, "L-IPST-C, c0 = 40"}, {80, 1, "L-IPST-C, c0 = 80"},
        {20, 0, "plain WCSPH, c0 = 20"}, {80, 0, "plain WCSPH, c0 = 80"}};
    const int maxN = argc > 1 ? atoi(argv[1]) : 80;
    const char* dir = argc > 2 ? argv[2] : "bench/results";
    char path[512];
    double eu[5][7], ep[5][7], Nd[7];
    int m = 0, q, k;
    FILE* csv;
    svg_chart cu, cp;
    while (m < 7 && Ns[m] <= maxN) Nd[m] = Ns[m], ++m;
    snprintf(path, sizeof path, "%s/taylor_green.csv", dir);
    csv = fopen(path, "w");
    if (!csv) {
        fprintf(stderr, "cannot write %s\n", path);
        return 1;
    }
    fprintf(csv, "scheme,c0,N,l1_u,l1_p,ke_ratio,seconds\n");
    printf("Taylor-Green Re 100, t = 0.5 s (L1 = mean absolute error over the particles)\n");
    printf("%-22s %5s %11s %11s %9s %9s\n", "scheme", "N", "L1(|u|)", "L1(p)", "KE/exact", "seconds");
    for (k = 0; k < 5; ++k) {
        for (q = 0; q < m; ++q) {
            const tg_run r = run(Ns[q], series[k].c0, series[k].soc);
            eu[k][q] = r.ok ? r.l1_u : NAN;
            ep[k][q] = r.ok ? r.l1_p : NAN;
            printf("%-22s %5d %11.3e %11.3e %9.4f %9.2f\n", series[k].name, Ns[q], eu[k][q], ep[k][q],
                   r.ke, r.seconds);
            fprintf(csv, "%s,%g,%d,%.6e,%.6e,%.6f,%.3f\n", series[k].soc ? "L-IPST-C" : "WCSPH",
                    series[k].c0, Ns[q], eu[k][q], ep[k][q], r.ke, r.seconds);
            fflush(stdout);
        }
        printf("%-22s order: |u| %.2f, p %.2f\n", series[k].name, order(Ns, eu[k], m), order(Ns, ep[k], m));
    }
    fclose(csv);
    svg_begin(&cu, "Taylor-Green, Re 100, t = 0.5: velocity error", "N (particles per side)", "L1(|u|) [m/s]");
    svg_begin(&cp, "Taylor-Green, Re 100, t = 0.5: pressure error", "N (particles per side)", "L1(p) [Pa]");
    svg_log(&cu, 0), svg_log(&cu, 1), svg_log(&cp, 0), svg_log(&cp, 1);
    for (k = 0; k < 5; ++k) {
        svg_series(&cu, Nd, eu[k], (size_t)m, SVG_LINE_MARKS, series[k].name);
        svg_series(&cp, Nd, ep[k], (size_t)m, SVG_LINE_MARKS, series[k].name);
    }
    { /* slope -2 reference through the first L-IPST-C point */
        double ref[7];
        for (q = 0; q < m; ++q) ref[q] = eu[0][0] * (Nd[0] / Nd[q]) * (Nd[0] / Nd[q]);
        svg_series(&cu, Nd, ref, (size_t)m, SVG_DASHED, "second order");
        for (q = 0; q < m; ++q) ref[q] = ep[2][0] * (Nd[0] / Nd[q]) * (Nd[0] / Nd[q]);
        svg_series(&cp, Nd, ref, (size_t)m, SVG_DASHED, "second order");
    }
    snprintf(path, sizeof path, "%s/taylor_green_u.svg", dir);
    svg_write(&cu, path);
    snprintf(path, sizeof path, "%s/taylor_green_p.svg", dir);
    svg_write(&cp, path);
    svg_free(&cu);
    svg_free(&cp);
    printf("wrote %s/taylor_green.csv and the two charts\n", dir);
    return 0;
}
