/* tests/fuzz_api.c - libFuzzer harness for sequences of sph.h's API calls in any order, with the
   invariants of tests/fuzz_common.h checked after each call: adding particles and walls
   (positions may be NaN, huge or far from the origin), phases, steps, sph_advance, the host
   writing state between steps, save/load and copies mid-run, a force callback that writes NaN.

   Build and run: make fuzz (tests/fuzz.mk), or by hand
       clang -g -O1 -fsanitize=fuzzer,address,undefined -I. tests/fuzz_api.c -lm -o build/fuzz_api
       build/fuzz_api tests/fuzz_corpus/api tests/fuzz_corpus/regressions/api
   Replay without libFuzzer: tests/fuzz_replay.c linked with this file (make fuzz-replay).

   Beyond fuzz_common.h's invariants:
     - every world the API built loads back from its saved bytes, equal to the original (the
       loader accepts what the API accepts), and so does sph_world_copy;
     - when the force callback writes NaN for a particle that exists, the next step fails
       (SPH_ERR_UNSTABLE) naming that particle and the callback;
     - sph_stable_dt returns a finite value >= 0 (0 with a message).
   Work is bounded: at most 1500 fluid and 3000 wall particles, 12 steps or sph_advance calls of at
   most 48 sub-steps each (def.max_substeps; retries and restarts included: a scene whose flow
   itself passes the speed limit fails every retry, and the default budget of 100000 sub-steps
   is minutes under the sanitizers), 30 solver iterations.

   INPUT LAYOUT (bytes beyond the end read as 0)
     def      dim byte, solver byte, integrator byte, spacing real (3 bytes)
     calls    up to 24, each an opcode byte and its fields (see fza_call) */
#define SPH_IMPLEMENTATION
#include "../sph.h"
#include "fuzz_common.h"

#define FZA_MAX_FLUID 1500
#define FZA_MAX_WALL 3000
#define FZA_MAX_STEPS 12

typedef struct fza_force {
    uint32_t bad_id; /* the id whose acceleration becomes NaN while armed */
    int armed;
} fza_force;

static void fza_force_fn(const sph_world* w, size_t begin, size_t end, sph_real* acc, void* user) {
    const fza_force* f = (const fza_force*)user;
    size_t i;
    for (i = begin; f->armed && i < end; ++i)
        if (w->id[i] == f->bad_id) acc[i * (size_t)w->dim] = (sph_real)NAN;
}

typedef struct fza_ctx {
    fzc_reader r;
    sph_world w;
    fza_force force;
    int steps;
    int dirty; /* the host wrote state, or a step failed midway: the world may hold values the
                  loader refuses (NaN, far positions), so a round trip may fail (with a message) */
} fza_ctx;

/* Particles a box holds with `pad` layers around it: NAN for a box the library refuses as
   invalid, INFINITY for one it must refuse as too large before allocating. */
static double fza_box_count(const sph_world* w, const sph_real* lo, const sph_real* hi, int pad,
                            unsigned open, double* walls) {
    double all = 1, inner = 1;
    int k;
    for (k = 0; k < w->dim; ++k) {
        double e;
        if (!isfinite((double)lo[k]) || !isfinite((double)hi[k]) || !(hi[k] > lo[k])) return NAN;
        e = (double)((hi[k] - lo[k]) / w->dx);
        /* the library's rule: round(e) spacings, more than 1e7 refused */
        if (!(floor(e + 0.5) <= 1e7)) return INFINITY;
        e = floor(e + 0.5);
        inner *= e < 1 ? 1 : e;
        all *= (e < 1 ? 1 : e) + (open & (1u << (2 * k)) ? 0 : pad) +
               (open & (1u << (2 * k + 1)) ? 0 : pad);
    }
    *walls = all - inner;
    return inner;
}

static void fza_box(fza_ctx* c, sph_real* lo, sph_real* hi) {
    const double dx = (double)c->w.dx;
    int k;
    for (k = 0; k < 3; ++k) {
        const double l = fzc_real(&c->r, 0, -20 * dx, 20 * dx);
        const double e = fzc_real(&c->r, 8 * dx, 0, 30 * dx);
        lo[k] = (sph_real)l;
        hi[k] = (sph_real)(l + e);
    }
}

/* n points of a lattice at the spacing from `base` (which may be far away or not finite) */
static void fza_points(fza_ctx* c, size_t n, sph_real* x) {
    const int dim = c->w.dim;
    const double dx = (double)c->w.dx;
    double base[3];
    size_t side = 1, i;
    int k;
    for (k = 0; k < 3; ++k)
        base[k] = fzc_real(&c->r, 0, -20 * dx, 20 * dx);
    while (dim == 1 ? side < n : dim == 2 ? side * side < n : side * side * side < n)
        ++side;
    for (i = 0; i < n; ++i) {
        size_t rem = i;
        for (k = 0; k < dim; ++k) {
            x[i * (size_t)dim + (size_t)k] =
                (sph_real)(base[k] + ((double)(rem % side) + 0.5) * dx);
            rem /= side;
        }
    }
    if (n && (fzc_u8(&c->r) & 1u)) /* one poked value */
        x[(fzc_u8(&c->r) % n) * (size_t)dim] = (sph_real)fzc_real(&c->r, 0, -1, 1);
}

/* Saves the world, loads it into a second one (or copies it), checks they are equal and goes
   on with the copy. */
static void fza_roundtrip(fza_ctx* c, int copy) {
    sph_world l;
    sph_status s;
    fzc_state a, b;
    if (copy) {
        s = sph_world_copy(&l, &c->w);
    } else {
        const size_t n = sph_world_save_mem(&c->w, NULL, 0);
        unsigned char* buf = (unsigned char*)malloc(n);
        FZC_ASSERT(buf && sph_world_save_mem(&c->w, buf, n) == n, "save_mem");
        s = sph_world_load_mem(&l, buf, n, &c->w.def);
        free(buf);
    }
    FZC_LOG("  %-22s -> %s %s\n", copy ? "sph_world_copy" : "save/load", sph_status_string(s),
            l.error);
    if (c->dirty && s != SPH_OK) {
        FZC_ASSERT(l.error[0] != 0 && l.n == 0 && l.x == NULL, "a failed load without a message");
        sph_world_free(&l);
        return;
    }
    FZC_ASSERT(s == SPH_OK, "a world the API built does not %s: %s", copy ? "copy" : "load back",
               l.error);
    a = fzc_take(&c->w);
    b = fzc_take(&l);
    FZC_ASSERT(a.n == b.n && a.nb == b.nb && a.sum == b.sum && a.steps == b.steps,
               "the loaded world differs");
    sph_world_free(&c->w);
    c->w = l;
    c->w.def.force_user = &c->force; /* the def's user pointer is the caller's (unchanged) */
}

static void fza_step(fza_ctx* c, unsigned op) {
    sph_world* w = &c->w;
    fzc_state before;
    sph_status s;
    const char* what = op == 9 ? "sph_advance" : "sph_step";
    double f = fzc_real(&c->r, 1, 0, 2);
    sph_real dt;
    size_t armed_index = w->n;
    if (c->steps >= FZA_MAX_STEPS) return;
    ++c->steps;
    before = fzc_begin(w);
    dt = sph_stable_dt(w, w->def.solver);
    FZC_ASSERT(isfinite((double)dt) && dt >= 0, "sph_stable_dt returned %g", (double)dt);
    if (dt == 0) FZC_ASSERT(w->error[0] != 0, "sph_stable_dt returned 0 with an empty error");
    before = fzc_begin(w);
    if (c->force.armed) {
        size_t i;
        for (i = 0; i < w->n; ++i)
            if (w->id[i] == c->force.bad_id) armed_index = i;
    }
    if (op == 9) {
        /* a few stable steps, or a bad duration (0, negative, NaN, infinite); a huge finite one
           would only spend the sub-step budget (def.max_substeps, SPH_ERR_BUDGET) */
        double dur = isfinite(f) && f > 0 ? (f < 3 ? 2 * f : 4) * (double)dt : f;
        s = sph_advance(w, (sph_real)dur);
    } else {
        if (!(isfinite(f) && f > 0 && f <= 2))
            dt = (sph_real)f; /* 0, negative, NaN, huge ... */
        else
            dt = (sph_real)((double)dt * f);
        s = sph_step(w, dt);
    }
    fzc_after(what, w, s, &before, 0);
    if (s == SPH_OK && w->steps > before.steps) fzc_check_finite(what, w);
    if (s != SPH_OK && s != SPH_ERR_ARG) c->dirty = 1;
    if (armed_index < before.n && w->steps > before.steps) /* a step ran its forces */
        FZC_ASSERT(0, "%s took a step although the force callback wrote NaN for id %u", what,
                   (unsigned)c->force.bad_id);
    if (armed_index < before.n && s == SPH_ERR_UNSTABLE) {
        FZC_ASSERT(strstr(w->error, "force callback") != NULL && w->error_index >= 0 &&
                       (size_t)w->error_index < w->n && w->id[w->error_index] == c->force.bad_id,
                   "the force callback's NaN for id %u was reported as: %s",
                   (unsigned)c->force.bad_id, w->error);
    }
    c->force.armed = 0;
}

static void fza_call(fza_ctx* c) {
    sph_world* w = &c->w;
    fzc_reader* r = &c->r;
    const unsigned op = fzc_u8(r) % 14u;
    const int dim = w->dim;
    fzc_state before = fzc_begin(w);
    sph_real lo[3], hi[3];
    sph_status s;
    if (op == 0) { /* a phase */
        sph_phase ph;
        int idx, np = w->nphase;
        memset(&ph, 0, sizeof ph);
        ph.eos = (sph_eos)(fzc_u8(r) % 5u);
        ph.rest_density = (sph_real)fzc_real(r, 1000, 1, 3000);
        ph.viscosity = (sph_real)fzc_real(r, 0, 0, 0.01);
        ph.sound_speed = (sph_real)fzc_real(r, ph.eos == SPH_EOS_STIFFENED_GAS ? 50 : 20, 0, 100);
        if (ph.eos == SPH_EOS_IDEAL_GAS) ph.sound_speed = 0;
        ph.gamma = (sph_real)fzc_real(r, 0, 1, 20);
        ph.back_pressure = (sph_real)fzc_real(r, ph.eos == SPH_EOS_IDEAL_GAS ? 1e5 : 0, 0, 1e5);
        ph.mass = (sph_real)fzc_real(r, 0, 0, 1);
        idx = sph_world_add_phase(w, &ph);
        FZC_LOG("  sph_world_add_phase     -> %d %s\n", idx, idx < 0 ? w->error : "");
        FZC_ASSERT(idx < 0 ? w->error[0] != 0 && w->nphase == np : idx == np && w->nphase == np + 1,
                   "add_phase returned %d with %d phases", idx, w->nphase);
    } else if (op == 1) { /* sph_fill_box */
        const int ph = (int)(fzc_u8(r) % (unsigned)(w->nphase + 2)) - 1;
        double walls, cnt;
        fza_box(c, lo, hi);
        cnt = fza_box_count(w, lo, hi, 0, 0, &walls);
        if (cnt + (double)w->n > FZA_MAX_FLUID && cnt < 5e9) return;
        s = sph_fill_box(w, ph, lo, hi);
        fzc_after("sph_fill_box", w, s, &before, 0);
        if (s != SPH_OK) FZC_ASSERT(w->n == before.n, "fill_box failed but added particles");
    } else if (op == 2 || op == 3 || op == 4) { /* sph_add_fluid(_ex), sph_add_boundary */
        const unsigned nb = fzc_u8(r), flags = fzc_u8(r);
        const size_t n = nb % 65u;
        const int ph = (int)(fzc_u8(r) % (unsigned)(w->nphase + 2)) - 1;
        sph_real* x = (sph_real*)malloc(n * (size_t)dim * sizeof(sph_real) + 1);
        sph_real* a = (sph_real*)malloc(n * (size_t)dim * sizeof(sph_real) + 1);
        sph_real* m = (sph_real*)malloc(n * sizeof(sph_real) + 1);
        double vv, mm, rr;
        size_t i;
        fza_points(c, n, x);
        vv = fzc_real(r, 0, -2, 2);
        mm = fzc_real(r, 1, 0.1, 3);
        rr = fzc_real(r, 1000, 1, 3000);
        for (i = 0; i < n * (size_t)dim; ++i)
            a[i] = (sph_real)vv;
        for (i = 0; i < n; ++i)
            m[i] = (sph_real)(op == 4 ? mm * pow((double)w->dx, dim) : mm);
        if (op == 4) {
            if ((double)(w->nb + n) > FZA_MAX_WALL) goto skip;
            s = sph_add_boundary(w, n, (flags & 8u) ? NULL : x, (flags & 1u) ? m : NULL,
                                 (int)(flags >> 4) - 1);
            fzc_after("sph_add_boundary", w, s, &before, n);
            FZC_ASSERT(w->nb == before.nb + (s == SPH_OK ? n : 0), "add_boundary count");
        } else {
            if ((double)(w->n + n) > FZA_MAX_FLUID) goto skip;
            if (op == 2)
                s = sph_add_fluid(w, ph, n, (flags & 8u) ? NULL : x, (flags & 1u) ? a : NULL);
            else
                s = sph_add_fluid_ex(w, ph, n, (flags & 8u) ? NULL : x, (flags & 1u) ? a : NULL,
                                     (flags & 2u) ? m : NULL, NULL);
            (void)rr;
            fzc_after(op == 2 ? "sph_add_fluid" : "sph_add_fluid_ex", w, s, &before, n);
            FZC_ASSERT(w->n == before.n + (s == SPH_OK ? n : 0), "add_fluid count");
        }
    skip:
        free(x);
        free(a);
        free(m);
    } else if (op == 5) { /* sph_add_wall_box */
        const unsigned lb = fzc_u8(r), open = fzc_u8(r) % 66u;
        const int layers = (int)(lb % 6u) - (lb == 255 ? 70 : 0);
        double walls = 0, cnt;
        fza_box(c, lo, hi);
        cnt = fza_box_count(w, lo, hi, layers > 0 ? layers : 3, open, &walls);
        if (cnt == cnt && isfinite(cnt) && walls + (double)w->nb > FZA_MAX_WALL && walls < 5e9)
            return;
        FZC_LOG("  wall box [%g %g %g] - [%g %g %g] layers %d open %u (estimate %g walls)\n",
                (double)lo[0], (double)lo[1], (double)lo[2], (double)hi[0], (double)hi[1],
                (double)hi[2], layers, open, walls);
        s = sph_add_wall_box(w, lo, hi, layers, open);
        fzc_after("sph_add_wall_box", w, s, &before, 0);
        if (s != SPH_OK) FZC_ASSERT(w->nb == before.nb, "wall_box failed but added particles");
    } else if (op == 6) {
        s = sph_set_hydrostatic(w);
        fzc_after("sph_set_hydrostatic", w, s, &before, 0);
    } else if (op == 7) {
        const sph_real dt = sph_stable_dt(w, (sph_solver)(fzc_u8(r) % 5u));
        FZC_ASSERT(isfinite((double)dt) && dt >= 0, "sph_stable_dt returned %g", (double)dt);
        if (dt == 0) FZC_ASSERT(w->error[0] != 0, "sph_stable_dt returned 0 with an empty error");
    } else if (op == 8 || op == 9) {
        fza_step(c, op);
    } else if (op == 10) { /* the host writes a position, velocity, density or energy */
        const unsigned which = fzc_u8(r) % 4u, idx = fzc_u16(r), comp = fzc_u8(r);
        const double v = fzc_real(r, 0, -1, 1);
        if (w->n == 0) return;
        if (which == 0)
            w->x[(idx % w->n) * (size_t)dim + comp % (unsigned)dim] = (sph_real)v;
        else if (which == 1)
            w->v[(idx % w->n) * (size_t)dim + comp % (unsigned)dim] = (sph_real)v;
        else if (which == 2)
            w->rho[idx % w->n] = (sph_real)v;
        else if (w->e)
            w->e[idx % w->n] = (sph_real)v;
        FZC_LOG("  host writes %u[%u] = %g\n", which, idx % (unsigned)w->n, v);
        c->dirty = 1;
        /* what the host wrote must not hide from the loader: a loaded copy of it either loads
           or is refused with a message; the world keeps the written value */
        {
            const size_t n = sph_world_save_mem(w, NULL, 0);
            unsigned char* buf = (unsigned char*)malloc(n);
            sph_world l;
            FZC_ASSERT(buf && sph_world_save_mem(w, buf, n) == n, "save_mem");
            s = sph_world_load_mem(&l, buf, n, NULL);
            FZC_ASSERT(s == SPH_OK || (l.error[0] != 0 && l.n == 0), "load after a host write");
            sph_world_free(&l);
            free(buf);
        }
    } else if (op == 11 || op == 12) {
        fza_roundtrip(c, op == 12);
    } else { /* arm the force callback for an id */
        c->force.bad_id = fzc_u16(r) % (w->next_id + 1u);
        c->force.armed = w->def.force != NULL;
    }
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    fza_ctx* c = (fza_ctx*)calloc(1, sizeof(fza_ctx));
    sph_world_def d;
    unsigned b, q, calls;
    if (!c) return 0;
    if (fzc_verbose < 0) fzc_verbose = getenv("FUZZ_VERBOSE") != NULL;
    c->r.p = data;
    c->r.n = size;
    b = fzc_u8(&c->r);
    d = sph_world_def_default(1 + (int)((b + 1u) % 3u));
    b = fzc_u8(&c->r);
    if (b & 128u) sph_world_def_pcisph(&d, (int)(b & 1u));
    d.solver = (sph_solver)((b >> 1) % 4u);
    b = fzc_u8(&c->r);
    d.integrator = (sph_integrator)(b & 1u);
    if (b & 2u) {
        d.force = fza_force_fn;
        d.force_user = &c->force;
    }
    if (b & 4u) d.density = SPH_DENSITY_SUMMATION;
    d.spacing = (sph_real)fzc_real(&c->r, 0.02, 0.005, 0.1);
    d.max_iterations = 30;
    d.max_substeps = 48;
    if (d.min_iterations > 30) d.min_iterations = 30;
    if (sph_world_init(&c->w, &d) != SPH_OK) {
        FZC_ASSERT(c->w.error[0] != 0 && c->w.n == 0, "init failed without a message");
        sph_world_free(&c->w);
        free(c);
        return 0;
    }
    calls = 1 + fzc_u8(&c->r) % 24u;
    for (q = 0; q < calls; ++q)
        fza_call(c);
    sph_world_free(&c->w);
    FZC_ASSERT(c->w.n == 0 && c->w.x == NULL, "sph_world_free left particles");
    free(c);
    return 0;
}
