/* tests/tank_profile.h - how far a tank at rest is from hydrostatic: the pressure of each fluid
   particle (averaged by the caller over a window, by particle id) against rho0 g (H - y), with H
   the depth the tank was filled to, at least a kernel support away from the side walls, the
   floor and the filled surface. Two measures, both relative to rho0 g H:
     layer_err     the mean over layers two spacings thick of |layer-averaged error| (a profile
                   shifted or tilted as a whole shows here);
     particle_err  the mean over the particles of |error| (noise from particle to particle too).
   The tank is scene_hydrostatic's: x (and z) in [0, W], the floor at y = 0. */
#ifndef SPH_TESTS_TANK_PROFILE_H
#define SPH_TESTS_TANK_PROFILE_H

#include <math.h>
#include <stddef.h>

typedef struct tank_profile {
    double layer_err, particle_err;
    size_t particles; /* interior particles compared */
} tank_profile;

/* p_sum[id] / count[id]: particle id's averaged pressure [Pa] (count 0: left out); rho0 [kg/m^3],
   g [m/s^2] > 0. */
static tank_profile tank_profile_error(const sph_world* w, const double* p_sum, const int* count,
                                       double W, double H, double rho0, double g) {
    tank_profile r;
    double bins[128] = {0}, m = (double)w->kernel.radius, scale = rho0 * g * H;
    int bc[128] = {0}, b, nl = 0;
    size_t i, k;
    const size_t D = (size_t)w->dim;
    r.layer_err = r.particle_err = 0;
    r.particles = 0;
    for (i = 0; i < w->n; ++i) {
        const sph_real* x = w->x + i * D;
        const double y = (double)x[1];
        double e;
        int inner = count[w->id[i]] > 0;
        for (k = 0; k < D; ++k)
            if (k != 1 && ((double)x[k] < m || (double)x[k] > W - m)) inner = 0;
        if (!inner || y < m || y > H - m) continue;
        e = (p_sum[w->id[i]] / count[w->id[i]] - rho0 * g * (H - y)) / scale;
        r.particle_err += fabs(e);
        ++r.particles;
        b = (int)((y - m) / (2 * (double)w->dx));
        if (b < 128) { bins[b] += e; bc[b]++; }
    }
    for (b = 0; b < 128; ++b)
        if (bc[b]) { r.layer_err += fabs(bins[b] / bc[b]); ++nl; }
    r.layer_err = nl ? r.layer_err / nl : 1;
    r.particle_err = r.particles ? r.particle_err / (double)r.particles : 1;
    return r;
}

#endif
