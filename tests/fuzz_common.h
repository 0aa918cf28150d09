/* tests/fuzz_common.h - the byte reader and the invariant checks of the harnesses
   tests/fuzz_load.c and tests/fuzz_api.c (each includes it once, after sph.h's implementation).

   The invariants checked after every call (FZC_AFTER):
     - the status is a sph_status; a failing call leaves a non-empty, terminated w.error and
       w.status equal to the status, and w.error_index is -1 or names a particle that exists
       (fluid or boundary) or an index of the caller's array;
     - SPH_ERR_ARG changes nothing: the fluid (n, x, v, rho, p, e, id, phase), the walls (nb,
       b_x, b_vol), the time and the step count (the documented exception: a boundary-motion
       callback that wrote a non-finite value, which these harnesses never do);
     - the particle counts never drop;
     - a step that returns SPH_OK leaves positions, velocities, densities and pressures finite. */
#ifndef SPH_FUZZ_COMMON_H
#define SPH_FUZZ_COMMON_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct fzc_reader {
    const uint8_t* p;
    size_t n, i;
} fzc_reader;

static unsigned fzc_u8(fzc_reader* r) { return r->i < r->n ? r->p[r->i++] : 0u; }

static unsigned fzc_u16(fzc_reader* r) {
    const unsigned a = fzc_u8(r);
    return (a << 8) | fzc_u8(r);
}

/* A real: [mode, hi, lo]; mode < 128 the default, 128..223 (hi, lo) mapped onto [lo, hi],
   224..255 a special value: the hostile ones (NaN, infinities, huge, denormal, negative) and
   coordinates far from the origin (1e4 .. 2e12, where float can no longer resolve a spacing). */
static double fzc_real(fzc_reader* r, double def, double lo, double hi) {
    const unsigned mode = fzc_u8(r), a = fzc_u8(r), b = fzc_u8(r);
    static const double special[32] = {
        0,        -1,   NAN,   INFINITY, -INFINITY,    1e300, -1e300, 1e-300,
        4.9e-324, 1e30, -1e30, 1e4,      -1e4,         1e5,   3e11,   0.55 + 2e12,
        3.5e38,   -0.0, 1e-7,  1e6,      2147483648.0, 1e-45, 1e-40,  -5,
        -3,       -1e9, 1e15,  0.5,      1e-3,         100,   170,    336};
    if (mode < 128) return def;
    if (mode < 224) return lo + (hi - lo) * (double)((a << 8) | b) / 65535.0;
    return special[(mode - 224) & 31u];
}

#define FZC_ASSERT(cond, ...)                                                                      \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            fprintf(stderr, "%s: invariant violated at line %d: %s\n  ", __FILE__, __LINE__,       \
                    #cond);                                                                        \
            fprintf(stderr, __VA_ARGS__);                                                          \
            fputc('\n', stderr);                                                                   \
            abort();                                                                               \
        }                                                                                          \
    } while (0)

static int fzc_verbose = -1;
#define FZC_LOG(...)                                                                               \
    do {                                                                                           \
        if (fzc_verbose > 0) fprintf(stderr, __VA_ARGS__);                                         \
    } while (0)

static uint64_t fzc_hash(uint64_t h, const void* data, size_t bytes) {
    const unsigned char* c = (const unsigned char*)data;
    size_t i;
    if (!data) return h ^ 0x9e3779b97f4a7c15ULL;
    for (i = 0; i < bytes; ++i) {
        h ^= c[i];
        h *= 1099511628211ULL;
    }
    return h;
}

/* What "the world is unchanged" compares. */
typedef struct fzc_state {
    size_t n, nb;
    double time;
    uint64_t steps, sum;
} fzc_state;

static fzc_state fzc_take(const sph_world* w) {
    fzc_state s;
    const size_t nd = w->n * (size_t)w->dim, nbd = w->nb * (size_t)w->dim;
    uint64_t h = 1469598103934665603ULL;
    s.n = w->n;
    s.nb = w->nb;
    s.time = w->time;
    s.steps = w->steps;
    if (w->n) {
        h = fzc_hash(h, w->x, nd * sizeof(sph_real));
        h = fzc_hash(h, w->v, nd * sizeof(sph_real));
        h = fzc_hash(h, w->rho, w->n * sizeof(sph_real));
        h = fzc_hash(h, w->p, w->n * sizeof(sph_real));
        h = fzc_hash(h, w->id, w->n * sizeof(uint32_t));
        h = fzc_hash(h, w->phase, w->n * sizeof(uint8_t));
        if (w->e) h = fzc_hash(h, w->e, w->n * sizeof(sph_real));
    }
    if (w->nb) {
        h = fzc_hash(h, w->b_x, nbd * sizeof(sph_real));
        h = fzc_hash(h, w->b_vol, w->nb * sizeof(sph_real));
    }
    s.sum = h;
    return s;
}

/* Before a checked call: clears w.error and w.status (the library only writes them), so that a
   failure which sets neither is caught rather than hidden by an older one. */
static fzc_state fzc_begin(sph_world* w) {
    w->error[0] = 0;
    w->status = SPH_OK;
    w->error_index = -1;
    return fzc_take(w);
}

static int fzc_all_finite(const sph_real* a, size_t count) {
    size_t i;
    for (i = 0; i < count; ++i)
        if (!isfinite((double)a[i])) return 0;
    return 1;
}

/* caller_count: the length of the caller's array an error index may name (0 if none). */
static void fzc_after(const char* what, sph_world* w, sph_status s, const fzc_state* before,
                      size_t caller_count) {
    FZC_LOG("  %-22s -> %s  n=%zu nb=%zu t=%g%s%s\n", what, sph_status_string(s), w->n, w->nb,
            w->time, s != SPH_OK ? "  : " : "", s != SPH_OK ? w->error : "");
    FZC_ASSERT((int)s >= 0 && s < SPH_STATUS_COUNT, "%s returned %d", what, (int)s);
    FZC_ASSERT(w->n >= before->n && w->nb >= before->nb, "%s: n %zu -> %zu, nb %zu -> %zu", what,
               before->n, w->n, before->nb, w->nb);
    if (s != SPH_OK) {
        size_t most = w->n > w->nb ? w->n : w->nb;
        if (caller_count > most) most = caller_count;
        FZC_ASSERT(memchr(w->error, 0, SPH_ERROR_SIZE) != NULL, "%s: error not terminated", what);
        FZC_ASSERT(w->error[0] != 0, "%s returned %s with an empty error", what,
                   sph_status_string(s));
        FZC_ASSERT(w->status == s, "%s returned %s but w.status is %s", what, sph_status_string(s),
                   sph_status_string(w->status));
        FZC_ASSERT(w->error_index >= -1 && (w->error_index < 0 || (size_t)w->error_index < most),
                   "%s: error_index %ld names no particle (n %zu, nb %zu): %s", what,
                   w->error_index, w->n, w->nb, w->error);
    }
    if (s == SPH_ERR_ARG) {
        const fzc_state after = fzc_take(w);
        FZC_ASSERT(after.n == before->n && after.nb == before->nb && after.sum == before->sum &&
                       after.steps == before->steps &&
                       memcmp(&after.time, &before->time, sizeof(double)) == 0,
                   "%s returned SPH_ERR_ARG (%s) but changed the world", what, w->error);
    }
}

/* After a call that stepped and returned SPH_OK. */
static void fzc_check_finite(const char* what, const sph_world* w) {
    const size_t nd = w->n * (size_t)w->dim;
    FZC_ASSERT(fzc_all_finite(w->x, nd), "%s returned SPH_OK with a non-finite position", what);
    FZC_ASSERT(fzc_all_finite(w->v, nd), "%s returned SPH_OK with a non-finite velocity", what);
    FZC_ASSERT(fzc_all_finite(w->rho, w->n), "%s returned SPH_OK with a non-finite density", what);
    FZC_ASSERT(fzc_all_finite(w->p, w->n), "%s returned SPH_OK with a non-finite pressure", what);
}

#endif
