/* tests/fuzz_world.c - libFuzzer harness for sph.h: bytes -> world def, phases, particles, walls,
   callbacks and a few steps of each solver.

   Build and run (make fuzz, tests/fuzz.mk):
       clang -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all -I. \
             tests/fuzz_world.c -lm -o build/fuzz_world
       build/fuzz_world -max_total_time=60 -timeout=10 -rss_limit_mb=2048 tests/fuzz_corpus
   Replay without libFuzzer (any compiler): tests/fuzz_replay.c (make fuzz-replay).
   FUZZ_VERBOSE=1 in the environment prints what an input does (for writing seeds).

   Every call may fail, but the library must not crash, trip a sanitizer, leak or hang, and:
     - a call that returns an error leaves a non-empty w.error and w.status equal to the status;
     - SPH_ERR_ARG from sph_add_* / sph_fill_box / a step leaves the fluid (n, x, v, rho, p, e, id,
       phase), the walls' count, the time and the step count unchanged (the documented exception:
       a boundary-motion callback that wrote a non-finite value);
     - w.n and w.nb never decrease; sph_stable_dt returns a finite value >= 0 (0 with an error);
     - a step or sph_advance that returns SPH_OK after stepping leaves finite positions,
       velocities, densities and pressures (blow-ups are SPH_ERR_UNSTABLE).
   The work is bounded: at most FZ_MAX_FLUID fluid and FZ_MAX_WALL wall particles (fewer with a
   large h_factor or the second-order scheme), at most 10 steps, iteration limits of at most 40,
   sph_advance over at most a few stable steps in at most 48 sub-steps (def.max_substeps).

   INPUT LAYOUT (bytes beyond the end read as 0; a 0 byte always means "the default")
     def      20 one-byte fields, then 29 reals of 3 bytes (see fz_def)
     phases   1 byte count, then 3 slots of 1 + 6 x 3 bytes (see fz_phases)
     ops      1 byte count, then per op a type byte and its fields (see fz_op)
     steps    1 byte count, then per step an action byte and its fields (see fz_steps)
   A real is [mode, hi, lo]: mode < 128 keeps the default, 128..223 maps (hi, lo) onto a range,
   224..255 picks a special value (0, -1, NaN, +-inf, 1e300, 1e6, denormals, just out of range ...). */
#define SPH_IMPLEMENTATION
#include "../sph.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define FZ_MAX_FLUID 2000
#define FZ_MAX_WALL 3000
#define FZ_PAIR_BUDGET 1.0e6 /* particles x neighbours per particle (a cube of the support); an
                               input at 1.1e6 (800 particles, h = 2.5 dx in 3D, IISPH) took 13 s
                               under libFuzzer on a loaded machine, against its 25 s timeout */

/* ---- the byte reader -------------------------------------------------------------------------- */

typedef struct fz_reader {
    const uint8_t* p;
    size_t n, i;
} fz_reader;

static unsigned fz_u8(fz_reader* r) { return r->i < r->n ? r->p[r->i++] : 0u; }

static double fz_special(unsigned s, double lo, double hi) {
    switch (s & 31u) {
    case 0: return 0;
    case 1: return -1;
    case 2: return NAN;
    case 3: return INFINITY;
    case 4: return -INFINITY;
    case 5: return 1e300;
    case 6: return -1e300;
    case 7: return 1e-300;
    case 8: return 4.9e-324;
    case 9: return 1e30;
    case 10: return -1e30;
    case 11: return lo - (hi - lo);
    case 12: return hi + (hi - lo);
    case 13: return 3.5e38; /* beyond FLT_MAX */
    case 14: return -0.0;
    case 15: return 1e-7;
    case 16: return 1e6;
    case 17: return -1e6;
    case 18: return 1e4;
    case 19: return 2147483648.0;
    case 20: return 4294967297.0;
    case 21: return 1e15;
    case 22: return 1e-15;
    case 23: return 1e10;
    case 24: return 1e-3;
    case 25: return 1e-320;
    case 26: return 0.5 * (lo + hi);
    case 27: return lo + 1e-12 * (hi - lo);
    case 28: return hi - 1e-12 * (hi - lo);
    case 29: return 1e-40; /* a float denormal */
    case 30: return 1e-45;
    default: return -1e-300;
    }
}

/* A real field: three bytes always consumed. */
static double fz_real(fz_reader* r, double def, double lo, double hi) {
    unsigned mode = fz_u8(r), a = fz_u8(r), b = fz_u8(r);
    if (mode < 128) return def;
    if (mode < 224) return lo + (hi - lo) * (double)((a << 8) | b) / 65535.0;
    return fz_special(mode - 224, lo, hi);
}

/* An enum field of `count` values: one byte; 128 + v gives v, v == count is out of range and
   v == count + 1 gives -1. */
static int fz_enum(fz_reader* r, int def, int count) {
    unsigned b = fz_u8(r);
    int v;
    if (b < 128) return def;
    v = (int)((b - 128) % (unsigned)(count + 2));
    return v == count + 1 ? -1 : v;
}

/* A small integer field: 128 + v gives v in 0..40; 250.. give bad values. */
static int fz_int(fz_reader* r, int def) {
    unsigned b = fz_u8(r);
    if (b < 128) return def;
    switch (b) {
    case 250: return -1;
    case 251: return 100001;
    case 252: return 2147483647;
    case 253: return -2147483647 - 1;
    default: return (int)((b - 128) % 41);
    }
}

/* ---- invariant checks ------------------------------------------------------------------------- */

static int fz_verbose = -1;

#define FZ_LOG(...) do { if (fz_verbose > 0) fprintf(stderr, __VA_ARGS__); } while (0)

#define FZ_ASSERT(cond, ...)                                                                       \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            fprintf(stderr, "fuzz_world: invariant violated at line %d: %s\n  ", __LINE__, #cond);\
            fprintf(stderr, __VA_ARGS__);                                                          \
            fputc('\n', stderr);                                                               \
            abort();                                                                               \
        }                                                                                          \
    } while (0)

static uint64_t fz_hash(uint64_t h, const void* data, size_t bytes) {
    const unsigned char* c = (const unsigned char*)data;
    size_t i;
    if (!data) return h ^ 0x9e3779b97f4a7c15ULL;
    for (i = 0; i < bytes; ++i) { h ^= c[i]; h *= 1099511628211ULL; }
    return h;
}

/* What "the world is unchanged" compares. */
typedef struct fz_state {
    size_t n, nb;
    double time;
    uint64_t steps, sum;
} fz_state;

static fz_state fz_take(const sph_world* w) {
    fz_state s;
    const size_t nd = w->n * (size_t)w->dim;
    uint64_t h = 1469598103934665603ULL;
    s.n = w->n;
    s.nb = w->nb;
    s.time = w->time;
    s.steps = w->steps;
    if (w->n) {
        h = fz_hash(h, w->x, nd * sizeof(sph_real));
        h = fz_hash(h, w->v, nd * sizeof(sph_real));
        h = fz_hash(h, w->rho, w->n * sizeof(sph_real));
        h = fz_hash(h, w->p, w->n * sizeof(sph_real));
        h = fz_hash(h, w->id, w->n * sizeof(uint32_t));
        h = fz_hash(h, w->phase, w->n * sizeof(uint8_t));
        if (w->e) h = fz_hash(h, w->e, w->n * sizeof(sph_real));
    }
    s.sum = h;
    return s;
}

/* Before a checked call: clears w.error and w.status (the library only writes them), so that a
   failure which sets no message or status is caught rather than hidden by an older one. */
static fz_state fz_begin(sph_world* w) {
    w->error[0] = 0;
    w->status = SPH_OK;
    return fz_take(w);
}

static int fz_same(const fz_state* a, const fz_state* b) {
    return a->n == b->n && a->nb == b->nb && a->steps == b->steps && a->sum == b->sum &&
           memcmp(&a->time, &b->time, sizeof(double)) == 0;
}

static int fz_all_finite(const sph_real* a, size_t count) {
    size_t i;
    for (i = 0; i < count; ++i)
        if (!isfinite((double)a[i])) return 0;
    return 1;
}

/* Set when the boundary-motion callback wrote a non-finite value: from then on a step may change
   the world and still return SPH_ERR_ARG (documented in sph_boundary_fn). */
static int fz_bad_motion;

static void fz_after(const char* what, sph_world* w, sph_status s, const fz_state* before,
                     int unchanged_on_arg) {
    FZ_LOG("  %-22s -> %s  n=%zu nb=%zu t=%g it=%d (%.3f s)%s%s\n", what, sph_status_string(s),
           w->n, w->nb, w->time, w->stats.iterations, w->stats.step_time,
           s != SPH_OK ? "  : " : "", s != SPH_OK ? w->error : "");
    FZ_ASSERT((int)s >= 0 && s < SPH_STATUS_COUNT, "%s returned %d", what, (int)s);
    FZ_ASSERT(w->n >= before->n && w->nb >= before->nb, "%s: n %zu -> %zu, nb %zu -> %zu", what,
              before->n, w->n, before->nb, w->nb);
    if (s != SPH_OK) {
        FZ_ASSERT(w->error[0] != 0, "%s returned %s with an empty error", what,
                  sph_status_string(s));
        FZ_ASSERT(w->status == s, "%s returned %s but w.status is %s", what, sph_status_string(s),
                  sph_status_string(w->status));
        FZ_ASSERT(memchr(w->error, 0, SPH_ERROR_SIZE) != NULL, "%s: error not terminated", what);
    }
    if (s == SPH_ERR_ARG && unchanged_on_arg && !fz_bad_motion) {
        fz_state after = fz_take(w);
        FZ_ASSERT(fz_same(before, &after), "%s returned SPH_ERR_ARG (%s) but changed the world",
                  what, w->error);
    }
}

/* After a step that succeeded: nothing non-finite is left (blow-ups are SPH_ERR_UNSTABLE). */
static void fz_check_finite(const char* what, const sph_world* w) {
    const size_t nd = w->n * (size_t)w->dim;
    FZ_ASSERT(fz_all_finite(w->x, nd), "%s returned SPH_OK with a non-finite position", what);
    FZ_ASSERT(fz_all_finite(w->v, nd), "%s returned SPH_OK with a non-finite velocity", what);
    FZ_ASSERT(fz_all_finite(w->rho, w->n), "%s returned SPH_OK with a non-finite density", what);
    FZ_ASSERT(fz_all_finite(w->p, w->n), "%s returned SPH_OK with a non-finite pressure", what);
}

/* ---- callbacks -------------------------------------------------------------------------------- */

typedef struct fz_force {
    int mode;          /* 0 none, 1 constant, 2 spring to a centre, 3 oscillating in time */
    double a[3], k, c[3], omega;
} fz_force;

static void fz_force_fn(const sph_world* w, size_t begin, size_t end, sph_real* acc, void* user) {
    const fz_force* f = (const fz_force*)user;
    const size_t dim = (size_t)w->dim;
    size_t i, k;
    for (i = begin; i < end; ++i)
        for (k = 0; k < dim; ++k) {
            double a = 0;
            switch (f->mode) {
            case 1: a = f->a[k]; break;
            case 2: a = -f->k * ((double)w->x[i * dim + k] - f->c[k]); break;
            default: a = f->a[k] * sin(f->omega * w->time); break;
            }
            acc[i * dim + k] += (sph_real)a;
        }
}

typedef struct fz_motion {
    int mode;          /* 0 none, 1 oscillate, 2 constant velocity, 3 oscillate and write a NaN */
    double amp[3], omega;
    int body;          /* the body that moves (-1 all) */
    unsigned calls, bad_call;
} fz_motion;

static void fz_motion_fn(sph_world* w, double time, void* user) {
    fz_motion* m = (fz_motion*)user;
    const size_t dim = (size_t)w->dim;
    size_t b, k;
    ++m->calls;
    for (b = 0; b < w->nb; ++b) {
        if (m->body >= 0 && w->b_body[b] != m->body) continue;
        for (k = 0; k < dim; ++k) {
            double x, v, a;
            if (m->mode == 2) {
                x = m->amp[k] * time;
                v = m->amp[k];
                a = 0;
            } else {
                x = m->amp[k] * sin(m->omega * time);
                v = m->amp[k] * m->omega * cos(m->omega * time);
                a = -m->amp[k] * m->omega * m->omega * sin(m->omega * time);
            }
            w->b_x[b * dim + k] = w->b_x0[b * dim + k] + (sph_real)x;
            w->b_v[b * dim + k] = (sph_real)v;
            w->b_a[b * dim + k] = (sph_real)a;
        }
    }
    if (m->mode == 3 && m->calls == m->bad_call && w->nb > 0) {
        const size_t b0 = (size_t)(m->calls * 7919u) % w->nb;
        const unsigned which = m->calls % 3u;
        sph_real* arr = which == 0 ? w->b_x : which == 1 ? w->b_v : w->b_a;
        arr[b0 * dim] = (sph_real)(m->calls & 1u ? NAN : INFINITY);
    }
    /* a non-finite value, or a position past the library's far limit (amp * time of a huge
       amp): the step fails with SPH_ERR_ARG after the callback changed the world */
    if (!fz_all_finite(w->b_x, w->nb * dim) || !fz_all_finite(w->b_v, w->nb * dim) ||
        !fz_all_finite(w->b_a, w->nb * dim) ||
        sph__first_far(w->b_x, w->nb * dim, sph__far_limit(w->dx)) < w->nb * dim)
        fz_bad_motion = 1;
}

/* ---- decoding the input ----------------------------------------------------------------------- */

typedef struct fz_ctx {
    fz_reader r;
    sph_world w;
    sph_world_def def;
    fz_force force;
    fz_motion motion;
    double budget_fluid, budget_wall; /* particles the work bound still allows */
} fz_ctx;

static void fz_def(fz_ctx* c) {
    fz_reader* r = &c->r;
    sph_world_def* d = &c->def;
    unsigned b = fz_u8(r), pre, per;
    int dim = 1 + (int)((b + 1u) % 3u); /* 0 -> 2D */
    if (b == 255) dim = 0;
    if (b == 254) dim = 4;
    *d = sph_world_def_default(dim);
    pre = fz_u8(r);
    if (pre >= 128) sph_world_def_pcisph(d, (int)(pre & 1u));
    d->solver = (sph_solver)fz_enum(r, (int)d->solver, 4);
    d->scheme = (sph_wcsph_scheme)fz_enum(r, (int)d->scheme, 2);
    d->integrator = (sph_integrator)fz_enum(r, (int)d->integrator, 2);
    d->density = (sph_density)fz_enum(r, (int)d->density, 3);
    d->pressure_grad = (sph_pressure_grad)fz_enum(r, (int)d->pressure_grad, 3);
    d->boundary_pressure = (sph_boundary_pressure)fz_enum(r, (int)d->boundary_pressure, 3);
    d->boundary_volume = (sph_boundary_volume)fz_enum(r, (int)d->boundary_volume, 2);
    d->kernel = (sph_kernel_type)fz_enum(r, (int)d->kernel, SPH_KERNEL_COUNT);
    d->clamp = (sph_pressure_clamp)fz_enum(r, (int)d->clamp, 3);
    d->viscosity_form = (sph_viscosity_form)fz_enum(r, (int)d->viscosity_form, 2);
    d->wall = (sph_wall)fz_enum(r, (int)d->wall, 2);
    d->pcisph_factor = (sph_pcisph_factor)fz_enum(r, (int)d->pcisph_factor, 2);
    per = fz_u8(r);
    d->periodic[0] = (int)(per & 1u);
    d->periodic[1] = (int)((per >> 1) & 1u);
    d->periodic[2] = (int)((per >> 2) & 1u);
    if (per & 8u) d->periodic[0] = -7; /* any nonzero int means periodic */
    c->force.mode = fz_enum(r, 0, 4);
    c->motion.mode = fz_enum(r, 0, 4);
    if (c->force.mode < 0 || c->force.mode > 3) c->force.mode = 0;
    if (c->motion.mode < 0 || c->motion.mode > 3) c->motion.mode = 0;
    d->min_iterations = fz_int(r, d->min_iterations);
    d->max_iterations = fz_int(r, d->max_iterations > 40 ? 40 : d->max_iterations);
    d->max_substeps = 48; /* not from the input: bounds each sph_advance (retries included) */
    d->shift_every = fz_int(r, d->shift_every);
    /* 29 reals */
    d->spacing = (sph_real)fz_real(r, (double)d->spacing, 1e-3, 0.5);
    d->h_factor = (sph_real)fz_real(r, (double)d->h_factor, 0.5, 4);
    d->gravity[0] = (sph_real)fz_real(r, (double)d->gravity[0], -20, 20);
    d->gravity[1] = (sph_real)fz_real(r, (double)d->gravity[1], -20, 20);
    d->gravity[2] = (sph_real)fz_real(r, (double)d->gravity[2], -20, 20);
    d->delta = (sph_real)fz_real(r, (double)d->delta, 0, 1);
    d->alpha = (sph_real)fz_real(r, (double)d->alpha, 0, 10);
    d->beta = (sph_real)fz_real(r, (double)d->beta, 0, 10);
    d->boundary_gamma = (sph_real)fz_real(r, (double)d->boundary_gamma, 0, 10);
    d->cfl = (sph_real)fz_real(r, (double)d->cfl, 0, 1);
    d->cfl_viscous = (sph_real)fz_real(r, (double)d->cfl_viscous, 0, 1);
    d->cfl_force = (sph_real)fz_real(r, (double)d->cfl_force, 0, 1);
    d->cfl_velocity = (sph_real)fz_real(r, (double)d->cfl_velocity, 0, 1);
    d->max_dt = (sph_real)fz_real(r, (double)d->max_dt, 0, 0.01);
    d->tolerance = (sph_real)fz_real(r, (double)d->tolerance, 0, 0.1);
    d->omega = (sph_real)fz_real(r, (double)d->omega, 0, 1);
    d->warm_start = (sph_real)fz_real(r, (double)d->warm_start, 0, 1);
    d->tolerance_max = (sph_real)fz_real(r, (double)d->tolerance_max, 0, 0.5);
    d->pcisph_gain = (sph_real)fz_real(r, (double)d->pcisph_gain, 0, 4);
    d->pressure_smoothing = (sph_real)fz_real(r, (double)d->pressure_smoothing, 0, 1);
    d->max_compression = (sph_real)fz_real(r, (double)d->max_compression, 0, 2);
    d->max_speed = (sph_real)fz_real(r, (double)d->max_speed, 0, 100);
    {   /* the domain in spacings (periodic boxes need >= 2 support radii) */
        double dx = (double)d->spacing;
        int k;
        for (k = 0; k < 3; ++k) {
            double lo = fz_real(r, 0, -30, 10), len = fz_real(r, 0, 0, 60);
            d->domain_lo[k] = (sph_real)(lo * dx);
            d->domain_hi[k] = (sph_real)((lo + len) * dx);
        }
    }
    /* callback parameters */
    {
        int k;
        for (k = 0; k < 3; ++k) {
            c->force.a[k] = fz_real(r, k == 0 ? 1 : 0, -50, 50);
            c->motion.amp[k] = fz_real(r, k == 0 ? 0.01 : 0, -0.05, 0.05);
        }
        c->force.k = fz_real(r, 10, -100, 100);
        c->force.omega = c->motion.omega = fz_real(r, 20, 0, 200);
        c->motion.body = fz_enum(r, -1, 3);
        c->motion.bad_call = fz_u8(r) % 8u + 1u;
        for (k = 0; k < 3; ++k) c->force.c[k] = 5 * (double)d->spacing;
    }
    if (c->force.mode) { d->force = fz_force_fn; d->force_user = &c->force; }
    if (c->motion.mode) { d->boundary_motion = fz_motion_fn; d->boundary_user = &c->motion; }
}

static void fz_phases(fz_ctx* c) {
    fz_reader* r = &c->r;
    unsigned count = fz_u8(r) % 4u, slot; /* 0 -> 1 phase; 3 -> none */
    count = count == 0 ? 1 : count == 3 ? 0 : count + 1;
    for (slot = 0; slot < 3; ++slot) {
        sph_phase ph;
        int idx, before = c->w.nphase;
        memset(&ph, 0, sizeof(ph));
        ph.eos = (sph_eos)fz_enum(r, SPH_EOS_TAIT, 4);
        ph.rest_density = (sph_real)fz_real(r, slot == 0 ? 1000 : slot == 1 ? 1 : 500, 0, 3000);
        ph.viscosity = (sph_real)fz_real(r, 0, 0, 0.01);
        ph.sound_speed = (sph_real)fz_real(r, ph.eos == SPH_EOS_STIFFENED_GAS ? 50 : 0, 0, 100);
        ph.gamma = (sph_real)fz_real(r, 0, 1, 20);
        ph.back_pressure = (sph_real)fz_real(r, ph.eos == SPH_EOS_IDEAL_GAS ? 1e5 : 0, -100, 1e5);
        ph.mass = (sph_real)fz_real(r, 0, 0, 10);
        if (slot >= count) continue;
        (void)fz_begin(&c->w);
        idx = sph_world_add_phase(&c->w, &ph);
        FZ_LOG("  add_phase eos %d rho0 %g c0 %g gamma %g pb %g m %g -> %d %s\n", (int)ph.eos,
               (double)ph.rest_density, (double)ph.sound_speed, (double)ph.gamma,
               (double)ph.back_pressure, (double)ph.mass, idx, idx < 0 ? c->w.error : "");
        if (idx < 0) {
            FZ_ASSERT(c->w.error[0] != 0, "add_phase failed with an empty error");
            FZ_ASSERT(c->w.nphase == before, "add_phase failed but added a phase");
        } else {
            FZ_ASSERT(idx == before && c->w.nphase == before + 1, "add_phase index %d", idx);
        }
    }
}

static int fz_phase_index(fz_ctx* c) {
    const unsigned b = fz_u8(&c->r), np = (unsigned)c->w.nphase;
    const unsigned v = b % (np + 2u);
    return v == np ? -1 : (int)v; /* np + 1 is out of range too */
}

/* Reads lo[dim] and hi[dim] of a box in spacings: lo default 0, extent default `ext`. */
static void fz_box(fz_ctx* c, double ext, sph_real* lo, sph_real* hi) {
    const double dx = (double)c->w.dx;
    int k;
    for (k = 0; k < 3; ++k) {
        double l = fz_real(&c->r, 0, -20, 20), e = fz_real(&c->r, ext, 0, 40);
        lo[k] = (sph_real)(l * dx);
        hi[k] = (sph_real)((l + e) * dx);
    }
}

/* Particles in a box (with pad layers around it): NAN if the box is invalid (the library rejects
   it), INFINITY or above 1e10 if it is so large that the library must refuse it before
   allocating (more than 2^32 particles), else an estimate (at least the count). */
static double fz_box_count(const sph_world* w, const sph_real* lo, const sph_real* hi, int pad) {
    double total = 1;
    int k;
    for (k = 0; k < w->dim; ++k) {
        double e;
        if (!isfinite((double)lo[k]) || !isfinite((double)hi[k]) || !(hi[k] > lo[k])) return NAN;
        e = (double)((hi[k] - lo[k]) / w->dx);
        /* the library's rule: round(e) spacings, more than 1e7 refused */
        if (!(floor(e + 0.5) <= 1e7)) return INFINITY;
        total *= floor(e + 0.5) + 1 + 2 * pad;
    }
    return total;
}

/* A lattice of n points from `base` (spacings) at `scale` spacings, plus per-point pokes. */
static void fz_points(fz_ctx* c, size_t n, sph_real* x) {
    const int dim = c->w.dim;
    const double dx = (double)c->w.dx;
    double base[3], scale;
    size_t side = 1, i;
    int k;
    for (k = 0; k < 3; ++k) base[k] = fz_real(&c->r, 0, -20, 20);
    scale = fz_real(&c->r, 1, 0, 2);
    while (dim == 1 ? side < n : dim == 2 ? side * side < n : side * side * side < n) ++side;
    for (i = 0; i < n; ++i) {
        size_t rem = i;
        for (k = 0; k < dim; ++k) {
            x[i * (size_t)dim + (size_t)k] =
                (sph_real)((base[k] + scale * (double)(rem % side) + 0.5) * dx);
            rem /= side;
        }
    }
}

/* Up to 3 pokes into an array of `count` values: [index, value]. */
static void fz_pokes(fz_ctx* c, sph_real* a, size_t count) {
    unsigned np = fz_u8(&c->r) % 4u, q;
    for (q = 0; q < np; ++q) {
        unsigned idx = fz_u8(&c->r);
        double v = fz_real(&c->r, NAN, -10, 10);
        if (count) a[idx % count] = (sph_real)v;
    }
}

static double fz_neighbour_estimate(const sph_world* w) {
    const double R = (double)(w->kernel.radius / w->dx);
    return pow(2 * R + 1, w->dim);
}

static void fz_op(fz_ctx* c) {
    fz_reader* r = &c->r;
    sph_world* w = &c->w;
    const int dim = w->dim;
    const unsigned type = fz_u8(r) % 6u;
    fz_state before = fz_begin(w);
    sph_status s;
    sph_real lo[3], hi[3];
    if (type == 0) { /* sph_fill_box */
        int ph = fz_phase_index(c);
        double cnt;
        fz_box(c, 10, lo, hi);
        cnt = fz_box_count(w, lo, hi, 0);
        if (cnt > c->budget_fluid && cnt < 1e10) { FZ_LOG("  fill_box skipped (%g)\n", cnt); return; }
        s = sph_fill_box(w, ph, lo, hi);
        fz_after("sph_fill_box", w, s, &before, 1);
        if (s == SPH_OK) c->budget_fluid -= (double)(w->n - before.n);
        else FZ_ASSERT(w->n == before.n, "sph_fill_box failed but added particles");
    } else if (type == 1 || type == 2) { /* sph_add_fluid(_ex) */
        int ph = fz_phase_index(c);
        unsigned b = fz_u8(r), flags = fz_u8(r);
        size_t n = b % 65u, i, k;
        sph_real *x, *v = NULL, *m = NULL, *rho = NULL;
        double v0[3], mf, rf;
        if (b >= 250) n = (size_t)(b - 250) * 100 + 100; /* 100 .. 600 */
        x = (sph_real*)malloc(n * (size_t)dim * sizeof(sph_real) + 1);
        fz_points(c, n, x);
        fz_pokes(c, x, n * (size_t)dim);
        for (k = 0; k < 3; ++k) v0[k] = fz_real(r, 0, -5, 5);
        mf = fz_real(r, 1, 0, 3);
        rf = fz_real(r, 1, 0, 3);
        if (!(flags & 1u)) {
            v = (sph_real*)malloc(n * (size_t)dim * sizeof(sph_real) + 1);
            for (i = 0; i < n; ++i)
                for (k = 0; k < (size_t)dim; ++k) v[i * (size_t)dim + k] = (sph_real)v0[k];
            fz_pokes(c, v, n * (size_t)dim);
        }
        if (type == 2 && !(flags & 2u)) {
            double m0 = ph >= 0 && ph < w->nphase ? (double)w->phases[ph].mass : 1;
            m = (sph_real*)malloc(n * sizeof(sph_real) + 1);
            for (i = 0; i < n; ++i) m[i] = (sph_real)(m0 * mf);
            fz_pokes(c, m, n);
        }
        if (type == 2 && !(flags & 4u)) {
            double r0 = ph >= 0 && ph < w->nphase ? (double)w->phases[ph].rest_density : 1;
            rho = (sph_real*)malloc(n * sizeof(sph_real) + 1);
            for (i = 0; i < n; ++i) rho[i] = (sph_real)(r0 * rf * (1 + 0.01 * (double)(i % 3)));
            fz_pokes(c, rho, n);
        }
        if ((double)n <= c->budget_fluid) {
            if (type == 1) s = sph_add_fluid(w, ph, n, (flags & 8u) ? NULL : x, v);
            else s = sph_add_fluid_ex(w, ph, n, (flags & 8u) ? NULL : x, v, m, rho);
            fz_after(type == 1 ? "sph_add_fluid" : "sph_add_fluid_ex", w, s, &before, 1);
            if (s == SPH_OK) {
                FZ_ASSERT(w->n == before.n + n, "add_fluid OK but n %zu -> %zu", before.n, w->n);
                c->budget_fluid -= (double)n;
            } else {
                FZ_ASSERT(w->n == before.n, "add_fluid failed but added particles");
            }
        }
        free(x);
        free(v);
        free(m);
        free(rho);
    } else if (type == 3) { /* sph_add_wall_box */
        unsigned lb = fz_u8(r), fb = fz_u8(r);
        int layers = lb < 128 ? 0 : (int)((lb - 128) % 68u) - 1;
        unsigned open = fb < 128 ? (dim >= 2 ? (unsigned)SPH_FACE_YMAX : 0u) : (fb - 128) % 66u;
        double cnt;
        int pad;
        fz_box(c, 10, lo, hi);
        pad = layers > 0 ? layers : (int)ceil((double)(w->kernel.radius / w->dx));
        /* the library enumerates only the shell (the box with its layers minus the box), so a
           box of 1e6 x 1e6 spacings gives it 9e6 wall particles, not 1e12: its own refusals are
           a side over 1e7 spacings (INFINITY here) or more than 2^32 - 2 particles */
        cnt = fz_box_count(w, lo, hi, pad) - fz_box_count(w, lo, hi, 0);
        /* this count is an upper bound (open faces take slabs out, and it counts a point more
           along each side), so a box above the library's limit here may be below it there and
           be built: 116 million wall particles, 2.8 GB, past libFuzzer's malloc limit. Only a
           side over 1e7 spacings is left to the library's refusal, which allocates nothing */
        if (cnt > c->budget_wall && isfinite(cnt)) {
            FZ_LOG("  wall_box skipped (%g)\n", cnt);
            return;
        }
        s = sph_add_wall_box(w, lo, hi, layers, open);
        fz_after("sph_add_wall_box", w, s, &before, 1);
        if (s == SPH_OK) c->budget_wall -= (double)(w->nb - before.nb);
        else FZ_ASSERT(w->nb == before.nb, "sph_add_wall_box failed but added particles");
    } else if (type == 4) { /* sph_add_boundary */
        unsigned b = fz_u8(r), flags = fz_u8(r), bb = fz_u8(r);
        size_t n = b % 65u, i;
        int body = bb < 128 ? 0 : bb == 255 ? -1 : bb == 254 ? 65536 : (int)(bb - 128) % 3;
        sph_real *x, *vol = NULL;
        double vf;
        x = (sph_real*)malloc(n * (size_t)dim * sizeof(sph_real) + 1);
        fz_points(c, n, x);
        fz_pokes(c, x, n * (size_t)dim);
        vf = fz_real(r, 1, 0, 3);
        if (flags & 1u) {
            double v0 = pow((double)w->dx, dim) * vf;
            vol = (sph_real*)malloc(n * sizeof(sph_real) + 1);
            for (i = 0; i < n; ++i) vol[i] = (sph_real)v0;
            fz_pokes(c, vol, n);
        }
        if ((double)n <= c->budget_wall) {
            s = sph_add_boundary(w, n, (flags & 8u) ? NULL : x, vol, body);
            fz_after("sph_add_boundary", w, s, &before, 1);
            if (s == SPH_OK) {
                FZ_ASSERT(w->nb == before.nb + n, "add_boundary OK but nb %zu -> %zu", before.nb, w->nb);
                c->budget_wall -= (double)n;
            } else {
                FZ_ASSERT(w->nb == before.nb, "add_boundary failed but added particles");
            }
        }
        free(x);
        free(vol);
    } else if (type == 5) { /* sph_set_hydrostatic */
        s = sph_set_hydrostatic(w);
        fz_after("sph_set_hydrostatic", w, s, &before, 0);
    }
}

/* NULL arguments are rejected and change nothing (run once per input, after the ops; no bytes
   read, so the decoding of stored inputs stays the same). */
static void fz_null_args(fz_ctx* c) {
    sph_world* w = &c->w;
    sph_real box[3] = {0, 0, 0};
    unsigned which;
    for (which = 0; which < 5; ++which) {
        fz_state before = fz_begin(w);
        sph_status s;
        if (which == 0) s = sph_fill_box(w, 0, NULL, box);
        else if (which == 1) s = sph_fill_box(w, 0, box, NULL);
        else if (which == 2) s = sph_add_wall_box(w, NULL, box, 0, 0);
        else if (which == 3) s = sph_add_boundary(w, 3, NULL, NULL, 0);
        else s = sph_add_fluid_ex(w, 0, 2, NULL, NULL, NULL, NULL);
        FZ_ASSERT(s != SPH_OK, "a NULL argument was accepted (%u)", which);
        fz_after("NULL argument", w, s, &before, 1);
    }
    {
        const int np = w->nphase;
        FZ_ASSERT(sph_world_add_phase(w, NULL) == -1 && w->error[0] != 0 && w->nphase == np,
                  "add_phase(NULL)");
    }
    FZ_ASSERT(sph_fill_box(NULL, 0, box, box) == SPH_ERR_ARG, "fill_box(NULL world)");
    FZ_ASSERT(sph_step(NULL, 1) == SPH_ERR_ARG, "step(NULL)");
    FZ_ASSERT(sph_advance(NULL, 1) == SPH_ERR_ARG, "advance(NULL)");
    FZ_ASSERT(sph_stable_dt(NULL, SPH_SOLVER_WCSPH) == 0, "stable_dt(NULL)");
    FZ_ASSERT(sph_set_hydrostatic(NULL) == SPH_ERR_ARG, "set_hydrostatic(NULL)");
    FZ_ASSERT(sph_world_add_phase(NULL, NULL) == -1, "add_phase(NULL, NULL)");
    sph_world_free(NULL);
    sph_world_def_pcisph(NULL, 1);
}

/* The default scene when the op count byte is 0: a column of fluid in an open tank. */
static void fz_default_scene(fz_ctx* c) {
    sph_world* w = &c->w;
    const double dx = (double)w->dx;
    sph_real lo[3] = {0, 0, 0}, hi[3], whi[3];
    fz_state before;
    sph_status s;
    int k;
    if (w->nphase < 1) return;
    for (k = 0; k < 3; ++k) {
        hi[k] = (sph_real)((k == 0 ? 8 : 10) * dx);
        whi[k] = (sph_real)((k == 0 ? 16 : 12) * dx);
    }
    if (w->dim == 1) { hi[0] = (sph_real)(20 * dx); whi[0] = hi[0]; }
    if (fz_box_count(w, lo, hi, 0) > c->budget_fluid) return;
    before = fz_begin(w);
    s = sph_fill_box(w, 0, lo, hi);
    fz_after("sph_fill_box (default)", w, s, &before, 1);
    if (w->def.periodic[0] || w->def.periodic[1] || w->def.periodic[2]) return;
    if (fz_box_count(w, lo, whi, (int)ceil((double)(w->kernel.radius / w->dx))) > c->budget_wall)
        return; /* walls as deep as a huge support: skip */
    before = fz_begin(w);
    s = sph_add_wall_box(w, lo, whi, 0, w->dim >= 2 ? SPH_FACE_YMAX : 0);
    fz_after("sph_add_wall_box (default)", w, s, &before, 1);
}

static sph_status fz_step_with(sph_world* w, unsigned which, sph_real dt) {
    switch (which % 5u) {
    case 0: return sph_step_wcsph(w, dt);
    case 1: return sph_step_iisph(w, dt);
    case 2: return sph_step_pcisph(w, dt);
    case 3: return sph_step_compressible(w, dt);
    default: return sph_step(w, dt);
    }
}

static sph_real fz_stable(sph_world* w, sph_solver solver) {
    fz_state before = fz_begin(w);
    sph_real dt = sph_stable_dt(w, solver);
    FZ_LOG("  sph_stable_dt(%d)       -> %g %s\n", (int)solver, (double)dt,
           dt == 0 ? w->error : "");
    FZ_ASSERT(isfinite((double)dt) && dt >= 0, "sph_stable_dt returned %g", (double)dt);
    if (dt == 0) FZ_ASSERT(w->error[0] != 0, "sph_stable_dt returned 0 with an empty error");
    {
        fz_state after = fz_take(w);
        FZ_ASSERT(fz_same(&before, &after), "sph_stable_dt changed the particles");
    }
    return dt;
}

static void fz_steps(fz_ctx* c) {
    fz_reader* r = &c->r;
    sph_world* w = &c->w;
    unsigned b = fz_u8(r), nsteps = b == 0 ? 3 : 1 + b % 10u, q;
    for (q = 0; q < nsteps; ++q) {
        const unsigned act = fz_u8(r) % 8u, arg = fz_u8(r);
        const double f = fz_real(r, 1, 0, 2);
        fz_state before;
        sph_status s;
        sph_real dt;
        const char* what = "sph_step";
        if (act <= 3) { /* the stable step of def.solver, times f */
            dt = fz_stable(w, w->def.solver);
            if (dt == 0 && (arg & 1u)) continue;
            dt = (sph_real)((double)dt * f);
            before = fz_begin(w);
            s = sph_step(w, dt);
        } else if (act == 4) { /* dt straight from the bytes (0, negative, NaN, huge ...) */
            dt = (sph_real)fz_real(r, 1e-4, 0, 1e-2);
            before = fz_begin(w);
            s = sph_step(w, dt);
        } else if (act == 5) { /* sph_advance over a few stable steps, or a bad duration */
            double dur;
            dt = fz_stable(w, w->def.solver);
            dur = (double)dt * 2 * f;
            if (isfinite(f) && f > 2 && f < 1e13) dur = (double)dt * 4;
            if (!isfinite(f) || f <= 0) dur = f;
            before = fz_begin(w);
            s = sph_advance(w, (sph_real)dur);
            what = "sph_advance";
            if (s == SPH_OK) FZ_ASSERT(w->steps - before.steps <= 1000, "advance took %llu steps",
                                       (unsigned long long)(w->steps - before.steps));
        } else if (act == 6) { /* the host writes a position, velocity or energy */
            const unsigned idx = fz_u8(r), comp = fz_u8(r);
            const double v = fz_real(r, NAN, -20, 20);
            if (w->n == 0) continue;
            if (arg % 3u == 0) w->x[(idx % w->n) * (size_t)w->dim + comp % (unsigned)w->dim] = (sph_real)v;
            else if (arg % 3u == 1) w->v[(idx % w->n) * (size_t)w->dim + comp % (unsigned)w->dim] = (sph_real)v;
            else if (w->e) w->e[idx % w->n] = (sph_real)v;
            FZ_LOG("  poke %u[%u] = %g\n", arg % 3u, idx, v);
            continue;
        } else { /* a solver's step called directly, at that solver's stable step */
            const unsigned which = arg % 5u;
            sph_solver sv = which < 4 ? (sph_solver)which : w->def.solver;
            dt = fz_stable(w, sv);
            dt = (sph_real)((double)dt * f);
            before = fz_begin(w);
            s = fz_step_with(w, which, dt);
            what = which == 0 ? "sph_step_wcsph" : which == 1 ? "sph_step_iisph"
                 : which == 2 ? "sph_step_pcisph" : which == 3 ? "sph_step_compressible" : "sph_step";
        }
        fz_after(what, w, s, &before, 1);
        if (s == SPH_OK && w->steps > before.steps) { /* sph_advance may take no step */
            fz_check_finite(what, w);
            /* a step that passes its input checks resets w.status (sph_advance over no step
               leaves the status of an earlier failing call) */
            FZ_ASSERT(w->status == SPH_OK, "%s returned SPH_OK but w.status is %s", what,
                      sph_status_string(w->status));
        }
        /* the read-only queries */
        {
            double mom[3];
            size_t mem = sph_world_memory(w);
            (void)sph_world_mass(w);
            sph_world_momentum(w, mom);
            (void)mem;
        }
    }
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    fz_ctx* c = (fz_ctx*)calloc(1, sizeof(fz_ctx));
    sph_status s;
    unsigned nops, q;
    double allowed;
    if (!c) return 0;
    if (fz_verbose < 0) fz_verbose = getenv("FUZZ_VERBOSE") != NULL;
    fz_bad_motion = 0;
    c->r.p = data;
    c->r.n = size;
    fz_def(c);
    FZ_ASSERT(sph_world_init(NULL, &c->def) == SPH_ERR_ARG, "sph_world_init(NULL, def)");
    s = sph_world_init(&c->w, NULL);
    FZ_ASSERT(s == SPH_ERR_ARG && c->w.error[0] != 0, "sph_world_init(w, NULL)");
    sph_world_free(&c->w);
    s = sph_world_init(&c->w, &c->def);
    FZ_LOG("dim %d solver %d scheme %d integrator %d density %d kernel %d dx %g h_factor %g "
           "periodic %d%d%d force %d motion %d -> %s %s\n",
           c->def.dim, (int)c->def.solver, (int)c->def.scheme, (int)c->def.integrator,
           (int)c->def.density, (int)c->def.kernel, (double)c->def.spacing,
           (double)c->def.h_factor, c->def.periodic[0], c->def.periodic[1], c->def.periodic[2],
           c->force.mode, c->motion.mode, sph_status_string(s), c->w.error);
    if (s != SPH_OK) {
        FZ_ASSERT(c->w.error[0] != 0, "sph_world_init failed with an empty error");
        FZ_ASSERT(c->w.n == 0 && c->w.x == NULL, "sph_world_init failed but left particles");
        sph_world_free(&c->w);
        sph_world_free(&c->w); /* twice: a freed world is a zeroed world */
        free(c);
        return 0;
    }
    /* the work bound: particles x neighbours */
    allowed = FZ_PAIR_BUDGET / fz_neighbour_estimate(&c->w);
    c->budget_fluid = allowed < FZ_MAX_FLUID ? allowed : FZ_MAX_FLUID;
    /* the second-order scheme costs ~10 times a standard step when it shifts (10 iterations) */
    if (c->w.def.scheme == SPH_SCHEME_SECOND_ORDER) c->budget_fluid /= 4;
    c->budget_wall = allowed < FZ_MAX_WALL ? allowed : FZ_MAX_WALL;
    fz_phases(c);
    nops = fz_u8(&c->r) % 7u;
    if (nops == 0) fz_default_scene(c);
    for (q = 0; q < nops; ++q) fz_op(c);
    fz_null_args(c);
    fz_steps(c);
    sph_world_free(&c->w);
    FZ_ASSERT(c->w.n == 0 && c->w.x == NULL && c->w.nb == 0, "sph_world_free left particles");
    free(c);
    return 0;
}
