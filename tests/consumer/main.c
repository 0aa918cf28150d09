/* tests/consumer/main.c - a program that takes sph.h through CMake or pkg-config: a 2D water
   column at hydrostatic rest for 0.2 s. It passes when the column stays at rest (speeds under
   1 % of sqrt(g H)) and the bottom pressure is rho g H within 5 %. */
#define SPH_IMPLEMENTATION
#include "sph.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

void consumer_report(const sph_world* w); /* report.cpp: the API used from C++ */

int main(void) {
    sph_world_def def = sph_world_def_default(2);
    sph_world w;
    sph_phase water;
    sph_real lo[2] = {0, 0}, hi[2] = {0.2, 0.4};
    double p_bottom = 0, y_min = 1e9;
    size_t i;
    int nb = 0;
    memset(&water, 0, sizeof water);
    water.rest_density = 1000;
    def.spacing = 0.02;
    if (sph_world_init(&w, &def) != SPH_OK || sph_world_add_phase(&w, &water) < 0 ||
        sph_fill_box(&w, 0, lo, hi) != SPH_OK || sph_add_wall_box(&w, lo, hi, 0, SPH_FACE_YMAX) != SPH_OK ||
        sph_set_hydrostatic(&w) != SPH_OK || sph_advance(&w, 0.2) != SPH_OK) {
        printf("consumer: FAILED: %s\n", w.error);
        return 1;
    }
    for (i = 0; i < w.n; ++i) y_min = fmin(y_min, (double)w.x[2 * i + 1]);
    for (i = 0; i < w.n; ++i)
        if ((double)w.x[2 * i + 1] < y_min + 1e-6) { p_bottom += (double)w.p[i]; ++nb; }
    p_bottom /= nb;
    consumer_report(&w);
    {
        const double H = 0.4, expect = 1000 * 9.81 * (H - y_min);
        const int ok = w.stats.v_max < 0.01 * sqrt(9.81 * H) && fabs(p_bottom / expect - 1) < 0.05;
        printf("consumer: sph %d.%d.%d, bottom row pressure %.0f Pa (rho g depth = %.0f Pa), max "
               "speed %.2g m/s: %s\n",
               SPH_VERSION_MAJOR, SPH_VERSION_MINOR, SPH_VERSION_PATCH, p_bottom, expect,
               (double)w.stats.v_max, ok ? "ok" : "FAILED");
        sph_world_free(&w);
        return ok ? 0 : 1;
    }
}
