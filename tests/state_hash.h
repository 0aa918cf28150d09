/* tests/state_hash.h - an FNV-1a hash of the state a user sees (fluid x, v, rho, p, id, e;
   boundary x, v, p; time): equal hashes mean bitwise equal states. Header-only, static inline
   (no warning where a build leaves it unused, e.g. without OpenMP). */
#ifndef SPH_TESTS_STATE_HASH_H
#define SPH_TESTS_STATE_HASH_H
#include "../sph.h"

static inline uint64_t th_fnv(uint64_t h, const void* data, size_t n) {
    const unsigned char* p = (const unsigned char*)data;
    size_t i;
    for (i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

static inline uint64_t th_state_hash(const sph_world* w) {
    const size_t d = (size_t)w->dim, r = sizeof(sph_real);
    uint64_t h = 14695981039346656037ull;
    h = th_fnv(h, w->x, w->n * d * r);
    h = th_fnv(h, w->v, w->n * d * r);
    h = th_fnv(h, w->rho, w->n * r);
    h = th_fnv(h, w->p, w->n * r);
    h = th_fnv(h, w->id, w->n * sizeof(uint32_t));
    if (w->e) h = th_fnv(h, w->e, w->n * r);
    h = th_fnv(h, w->b_x, w->nb * d * r);
    h = th_fnv(h, w->b_v, w->nb * d * r);
    h = th_fnv(h, w->b_p, w->nb * r);
    h = th_fnv(h, &w->time, sizeof w->time);
    return h;
}
#endif
