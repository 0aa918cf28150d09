/* tests/fuzz_load.c - libFuzzer harness for sph.h's loader: a small world saved to bytes, the
   bytes edited, the checksum recomputed (so that edits reach the loader's field checks instead
   of stopping at the checksum), loaded, and the result stepped.

   Build and run: make fuzz (tests/fuzz.mk), or by hand
       clang -g -O1 -fsanitize=fuzzer,address,undefined -I. tests/fuzz_load.c -lm -o build/fuzz_load
       build/fuzz_load tests/fuzz_corpus/load tests/fuzz_corpus/regressions/load
   Replay without libFuzzer: tests/fuzz_replay.c linked with this file (make fuzz-replay).

   Invariants, besides no crash, sanitizer report, leak or hang:
     - a failed load leaves a message and an empty world (n = nb = 0, no arrays), safe to free;
     - a world that loads is one the API could have built: its def, phases, fluid and walls
       rebuilt through sph_world_init, sph_world_add_phase, sph_add_fluid_ex and
       sph_add_boundary are accepted, its time and pressures are finite and its ids unique;
       saved and loaded again it loads, and its second save equals its first;
     - its steps keep the invariants of tests/fuzz_common.h (SPH_ERR_ARG changes nothing, an
       SPH_OK step leaves everything finite, errors have messages).

   INPUT LAYOUT (bytes beyond the end read as 0)
     scene    1 byte: which small world (see fzl_scene), 1 byte: steps taken before the save
     edits    1 byte count (up to 15), then per edit [kind, offset: 3 bytes, value: 3 bytes]
              kinds: a real (sph_real) at the offset, the same real at up to 64 consecutive
              reals, a double, a u32, a byte, a truncation; offsets wrap around the file
     flags    1 byte: bit 0 keeps the old checksum (tests that a changed byte is refused) */
#define SPH_IMPLEMENTATION
#include "../sph.h"
#include "fuzz_common.h"

/* The small worlds: each exercises other saved arrays (walls, the energy array, the mass array,
   the second-order scheme's lists, Akinci volumes). */
static sph_status fzl_scene(sph_world* w, unsigned which, unsigned steps) {
    sph_world_def d = sph_world_def_default(2);
    sph_phase a, b;
    sph_real lo[3] = {0, 0, 0}, hi[3] = {0.2f, 0.16f, 0.1f}, whi[3] = {0.2f, 0.24f, 0.1f};
    sph_status s;
    unsigned q;
    int walls = 1;
    memset(&a, 0, sizeof a);
    memset(&b, 0, sizeof b);
    a.rest_density = 1000;
    b.rest_density = 500;
    d.spacing = (sph_real)0.02;
    switch (which % 6u) {
    case 1:
        d = sph_world_def_default(3);
        d.spacing = (sph_real)0.025;
        break;
    case 2: /* 1D gas: the energy array */
        d = sph_world_def_default(1);
        d.solver = SPH_SOLVER_COMPRESSIBLE;
        d.spacing = (sph_real)0.01;
        a.eos = SPH_EOS_IDEAL_GAS;
        a.rest_density = 1;
        a.back_pressure = 1e5;
        walls = 0;
        break;
    case 3:
        sph_world_def_pcisph(&d, 1);
        b.mass = (sph_real)0.3;
        break; /* two masses: w.m */
    case 4:    /* the second-order scheme: its lists are saved */
        d.scheme = SPH_SCHEME_SECOND_ORDER;
        d.kernel = SPH_KERNEL_QUINTIC;
        d.h_factor = (sph_real)1.2;
        d.gravity[1] = 0;
        d.periodic[0] = d.periodic[1] = 1;
        d.domain_hi[0] = d.domain_hi[1] = (sph_real)0.2;
        hi[1] = (sph_real)0.2;
        a.sound_speed = 10;
        walls = 0;
        break;
    case 5:
        d.solver = SPH_SOLVER_IISPH;
        d.boundary_volume = SPH_BVOL_AKINCI;
        break;
    default:
        break;
    }
    d.max_iterations = 20;
    if ((s = sph_world_init(w, &d)) != SPH_OK) return s;
    if (sph_world_add_phase(w, &a) < 0) return w->status;
    if (which % 6u == 3 && sph_world_add_phase(w, &b) < 0) return w->status;
    if (d.dim == 1) hi[0] = (sph_real)0.3;
    if ((s = sph_fill_box(w, 0, lo, hi)) != SPH_OK) return s;
    if (which % 6u == 3) {
        sph_real x[4] = {0.05f, 0.2f, 0.1f, 0.2f};
        if ((s = sph_add_fluid(w, 1, 2, x, NULL)) != SPH_OK) return s;
    }
    if (walls && (s = sph_add_wall_box(w, lo, whi, 0, SPH_FACE_YMAX)) != SPH_OK) return s;
    if (d.gravity[1] != 0 && (s = sph_set_hydrostatic(w)) != SPH_OK) return s;
    for (q = 0; q < steps % 4u; ++q) {
        s = sph_step(w, sph_stable_dt(w, d.solver));
        /* a solve that stopped at max_iterations (20 here) still took its step */
        if (s != SPH_OK && s != SPH_ERR_NOT_CONVERGED) return s;
    }
    return SPH_OK;
}

/* The loaded world rebuilt through the API: its def, each phase (an ideal gas's sound speed back
   to 0, as given), every fluid particle with its mass and density, every wall particle with its
   volume. The API must accept all of it, and the rest must be what a run leaves: a finite time,
   finite pressures, unique ids below the next id. */
static void fzl_rebuild(const sph_world* l) {
    sph_world r;
    sph_status s;
    size_t i, j;
    int k;
    FZC_ASSERT(isfinite(l->time), "the loader accepted time = %g", l->time);
    s = sph_world_init(&r, &l->def);
    FZC_ASSERT(s == SPH_OK, "the loader accepted a def the API refuses: %s", r.error);
    for (k = 0; k < l->nphase; ++k) {
        sph_phase ph = l->phases[k];
        if (ph.eos == SPH_EOS_IDEAL_GAS) ph.sound_speed = 0;
        FZC_ASSERT(sph_world_add_phase(&r, &ph) == k,
                   "the loader accepted phase %d, which "
                   "sph_world_add_phase refuses: %s",
                   k, r.error);
    }
    for (i = 0; i < l->n; ++i) {
        const sph_real m = l->m ? l->m[i] : l->mass;
        s = sph_add_fluid_ex(&r, l->phase[i], 1, l->x + i * (size_t)l->dim,
                             l->v + i * (size_t)l->dim, &m, &l->rho[i]);
        /* the API refuses fluid added onto fluid (within 1e-3 spacings), which a run may still
           bring together and save: the loader accepts it. Checked here independently. */
        if (s == SPH_ERR_ARG && strstr(r.error, "never separate")) {
            int close = 0;
            for (j = 0; j < i && !close; ++j) {
                double d2 = 0;
                for (k = 0; k < l->dim; ++k) {
                    const double d = ((double)l->x[i * (size_t)l->dim + (size_t)k] -
                                      (double)l->x[j * (size_t)l->dim + (size_t)k]) / (double)l->dx;
                    d2 += d * d;
                }
                close = d2 < 1e-6 * 1.0001;
            }
            FZC_ASSERT(close, "sph_add_fluid_ex called fluid particle %zu coincident, but no "
                              "earlier particle lies within 1e-3 spacings: %s", i, r.error);
            s = SPH_OK;
        }
        FZC_ASSERT(s == SPH_OK,
                   "the loader accepted fluid particle %zu, which sph_add_fluid_ex "
                   "refuses: %s",
                   i, r.error);
        FZC_ASSERT(isfinite((double)l->p[i]), "the loader accepted p[%zu] = %g", i,
                   (double)l->p[i]);
        FZC_ASSERT(l->id[i] < l->next_id, "the loader accepted id %u >= next id %u",
                   (unsigned)l->id[i], (unsigned)l->next_id);
    }
    s = sph_add_boundary(&r, l->nb, l->b_x, l->b_vol, 0);
    FZC_ASSERT(s == SPH_OK, "the loader accepted walls sph_add_boundary refuses: %s", r.error);
    for (i = 0; i < l->n; ++i) /* quadratic, but the scenes are small */
        for (j = i + 1; j < l->n; ++j)
            FZC_ASSERT(l->id[i] != l->id[j], "the loader accepted two particles with id %u",
                       (unsigned)l->id[i]);
    sph_world_free(&r);
}

static void fzl_rehash(unsigned char* b, size_t n) {
    uint64_t h = 14695981039346656037ull;
    size_t i;
    if (n < 8) return;
    for (i = 0; i + 8 < n; ++i)
        h = (h ^ b[i]) * 1099511628211ull;
    memcpy(b + n - 8, &h, 8);
}

static void fzl_edit(fzc_reader* r, unsigned char* b, size_t* size) {
    const unsigned kind = fzc_u8(r) % 6u;
    const size_t off = ((size_t)fzc_u8(r) << 16 | (size_t)fzc_u16(r)) % (*size > 8 ? *size - 8 : 1);
    const double v = fzc_real(r, -1, -1e3, 1e3);
    const size_t room = *size - 8 - off; /* bytes before the checksum */
    if (kind == 0 && room >= sizeof(sph_real)) {
        const sph_real x = (sph_real)v;
        memcpy(b + off, &x, sizeof x);
    } else if (kind == 1) { /* a run of reals: "every wall volume" */
        const sph_real x = (sph_real)v;
        size_t k;
        for (k = 0; k < 64 && (k + 1) * sizeof x <= room; ++k)
            memcpy(b + off + k * sizeof x, &x, sizeof x);
    } else if (kind == 2 && room >= 8) {
        memcpy(b + off, &v, 8);
    } else if (kind == 3 && room >= 4) {
        const uint32_t u = isfinite(v) && fabs(v) < 4e9 ? (uint32_t)(int64_t)v : 0xffffffffu;
        memcpy(b + off, &u, 4);
    } else if (kind == 4) {
        /* a finite v beyond int64_t's range would make the conversion undefined */
        b[off] = (unsigned char)((int64_t)(isfinite(v) && fabs(v) < 9e18 ? v : 255) & 255);
    } else if (kind == 5) {
        *size = off + 8; /* truncated (the checksum is recomputed over what is left) */
    }
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    fzc_reader r;
    sph_world w, l, l2;
    unsigned char *bytes = NULL, *again = NULL;
    size_t n, n2, q;
    unsigned scene, pre, edits, e, flags;
    sph_status s;
    if (fzc_verbose < 0) fzc_verbose = getenv("FUZZ_VERBOSE") != NULL;
    r.p = data;
    r.n = size;
    r.i = 0;
    scene = fzc_u8(&r);
    pre = fzc_u8(&r);
    s = fzl_scene(&w, scene, pre);
    FZC_ASSERT(s == SPH_OK, "scene %u: %s", scene % 6u, w.error);
    n = sph_world_save_mem(&w, NULL, 0);
    bytes = (unsigned char*)malloc(n);
    FZC_ASSERT(bytes && sph_world_save_mem(&w, bytes, n) == n, "save_mem");
    sph_world_free(&w);
    edits = fzc_u8(&r) % 16u;
    for (e = 0; e < edits; ++e)
        fzl_edit(&r, bytes, &n);
    flags = fzc_u8(&r);
    if (!(flags & 1u)) fzl_rehash(bytes, n);
    s = sph_world_load_mem(&l, bytes, n, NULL);
    FZC_LOG("scene %u, %u edits, %zu bytes: load -> %s %s\n", scene % 6u, edits, n,
            sph_status_string(s), l.error);
    if (s != SPH_OK) {
        FZC_ASSERT(l.error[0] != 0 && l.status == s, "a failed load without a message");
        FZC_ASSERT(l.n == 0 && l.nb == 0 && l.x == NULL && l.b_x == NULL && l.nphase == 0,
                   "a failed load left particles (%s)", l.error);
        sph_world_free(&l);
        sph_world_free(&l);
        free(bytes);
        return 0;
    }
    fzl_rebuild(&l);
    /* a world the loader accepted saves and loads again, to the same bytes */
    n2 = sph_world_save_mem(&l, NULL, 0);
    again = (unsigned char*)malloc(n2);
    FZC_ASSERT(again && sph_world_save_mem(&l, again, n2) == n2, "save of a loaded world");
    s = sph_world_load_mem(&l2, again, n2, NULL);
    FZC_ASSERT(s == SPH_OK, "a loaded world, saved, does not load: %s", l2.error);
    {
        const size_t n3 = sph_world_save_mem(&l2, NULL, 0);
        unsigned char* third = (unsigned char*)malloc(n3);
        FZC_ASSERT(third && sph_world_save_mem(&l2, third, n3) == n3, "save");
        FZC_ASSERT(n3 == n2 && memcmp(third, again, n2) == 0, "save(load(save)) differs");
        free(third);
    }
    sph_world_free(&l2);
    /* and steps keeping the invariants (iterative solvers bounded: a def may ask 1e5 iterations) */
    for (q = 0; q < 2 && l.def.max_iterations <= 100 && l.n + l.nb < 4000; ++q) {
        fzc_state before;
        sph_real dt = sph_stable_dt(&l, l.def.solver);
        FZC_ASSERT(isfinite((double)dt) && dt >= 0, "stable_dt %g", (double)dt);
        if (dt == 0) {
            FZC_ASSERT(l.error[0] != 0, "stable_dt 0 without a message");
            break;
        }
        before = fzc_begin(&l);
        s = sph_step(&l, dt);
        fzc_after("sph_step", &l, s, &before, 0);
        if (s != SPH_OK) break;
        fzc_check_finite("sph_step", &l);
    }
    sph_world_free(&l);
    free(bytes);
    free(again);
    return 0;
}
