/* tests/test_oom.c - out of memory. The counting allocator of the test binary (tests/alloc.h) and,
   for every path that allocates, a scenario run once cleanly to count its N allocations and then,
   for k = 1 .. N, with the k-th allocation failing, in two modes:
     retry: the failing call must return SPH_ERR_NOMEM with w.status set and a w.error that says
       "memory"; it must have changed nothing that matters (oom_invariant: every particle's state
       by id, counts, time, steps; a step may only have sorted the particles) and left objects
       that can be read (grids queried, lists walked); then the allocator is disarmed, the same
       call is repeated and must succeed, the scenario runs to its end, and the final state (every
       particle array, time, steps, statistics; the grids and lists of the standalone scenario)
       must be the clean run's bit for bit (to round-off where a scenario says so);
     free: the scenario stops at the failure and everything is freed at once;
   in both, sph_world_free (sph_grid_free, sph_neighbors_free) must leave no block allocated, and
   no allocation may happen inside a parallel region. Each scenario's note gives its N. */
#include "harness.h"
#include "alloc.h"
#include "../sph.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

/* ---- the counting allocator ------------------------------------------------------------------ */

static unsigned long th_count_, th_fail_at_, th_injected_, th_parallel_;
static long th_live_;

#ifdef _OPENMP
#define TH_LOCKED(stmt) do { _Pragma("omp critical(th_alloc)") { stmt; } } while (0)
#else
#define TH_LOCKED(stmt) do { stmt; } while (0)
#endif

/* Counts one allocation; nonzero if it is the one that must fail. */
static int th_alloc_next(void) {
    int fail = 0;
#ifdef _OPENMP
    if (omp_in_parallel()) TH_LOCKED(++th_parallel_);
#endif
    TH_LOCKED(++th_count_; fail = th_fail_at_ != 0 && th_count_ == th_fail_at_;
              if (fail) ++th_injected_);
    return fail;
}

void* th_malloc(size_t size) {
    void* p;
    if (th_alloc_next()) return NULL;
    p = malloc(size ? size : 1);
    if (p) TH_LOCKED(++th_live_);
    return p;
}

void* th_realloc(void* ptr, size_t size) {
    void* q;
    if (th_alloc_next()) return NULL; /* ptr stays valid and allocated */
    q = realloc(ptr, size ? size : 1);
    if (q && !ptr) TH_LOCKED(++th_live_);
    return q;
}

void th_free(void* ptr) {
    if (!ptr) return;
    free(ptr);
    TH_LOCKED(--th_live_);
}

void th_alloc_fail_at(unsigned long k) {
    TH_LOCKED(th_count_ = 0; th_injected_ = 0; th_fail_at_ = k);
}
void th_alloc_disarm(void) { TH_LOCKED(th_fail_at_ = 0); }
unsigned long th_alloc_count(void) { return th_count_; }
unsigned long th_alloc_injected(void) { return th_injected_; }
long th_alloc_live(void) { return th_live_; }
unsigned long th_alloc_in_parallel(void) { return th_parallel_; }

/* ---- scenario machinery ---------------------------------------------------------------------- */

typedef struct oom_ctx {
    sph_world w;
    sph_grid g, g2;
    sph_neighbors nl, nl2;
    int mode;            /* 0 clean, 1 retry after the failure, 2 stop at the failure           */
    unsigned long k;     /* the allocation that fails (0: none)                                 */
    const char* name;
    unsigned long seen;  /* injected failures accounted for                                     */
    int failed;          /* SPH_ERR_NOMEM returned                                              */
    int stopped;         /* the scenario ended at the failure (free mode)                       */
    int bad;             /* a call went wrong otherwise (reported)                              */
    const char* where;   /* the call that ran out of memory                                     */
} oom_ctx;

/* Judges the status of one call; 1 if it ran out of memory (the allocator is then disarmed). */
static int oom_judge(oom_ctx* C, const sph_world* w, sph_status s, const char* what, int line) {
    const unsigned long inj = th_alloc_injected();
    if (s == SPH_ERR_NOMEM) {
        CHECK_MSG(inj > C->seen, "%s, allocation %lu: line %d: %s returned SPH_ERR_NOMEM but no "
                  "allocation failed", C->name, C->k, line, what);
        if (w) {
            CHECK_MSG(w->status == SPH_ERR_NOMEM, "%s, allocation %lu: line %d: %s: w.status %d",
                      C->name, C->k, line, what, (int)w->status);
            CHECK_MSG(strstr(w->error, "memory") != NULL,
                      "%s, allocation %lu: line %d: %s: w.error '%s' does not say memory",
                      C->name, C->k, line, what, w->error);
        }
        C->seen = inj;
        C->failed = 1;
        C->where = what;
        th_alloc_disarm();
        return 1;
    }
    if (inj != C->seen) {
        C->bad = 1;
        C->seen = inj;
        th_alloc_disarm();
        CHECK_MSG(0, "%s, allocation %lu: line %d: %s returned '%s' although an allocation failed",
                  C->name, C->k, line, what, sph_status_string(s));
    } else if (s != SPH_OK) {
        C->bad = 1;
        CHECK_MSG(0, "%s, allocation %lu: line %d: %s returned '%s': %s", C->name, C->k, line, what,
                  sph_status_string(s), w ? w->error : "");
    }
    return 0;
}

static uint64_t oom_invariant(const oom_ctx* C);
static sph_real oom_pts[3 * 600]; /* the points of the standalone grid scenario */
static void oom_after_failure(oom_ctx* C, uint64_t before, const char* what, int line);

/* Runs a call that returns sph_status; out of memory: check that the call changed nothing and
   left usable objects, then stop (free mode) or repeat the call once. */
#define OOM(C, W, EXPR)                                                                            \
    do {                                                                                           \
        const uint64_t oom_before_ = oom_invariant(C);                                             \
        sph_status oom_s_ = (EXPR);                                                                \
        if (oom_judge((C), (W), oom_s_, #EXPR, __LINE__)) {                                       \
            oom_after_failure((C), oom_before_, #EXPR, __LINE__);                                  \
            if ((C)->mode == 2) { (C)->stopped = 1; return; }                                     \
            oom_s_ = (EXPR);                                                                       \
            if (oom_judge((C), (W), oom_s_, #EXPR " (repeated)", __LINE__)) (C)->bad = 1;         \
        }                                                                                          \
        if (oom_s_ != SPH_OK || (C)->bad) { (C)->bad = 1; return; }                               \
    } while (0)
/* A helper scenario part, then stop if it stopped. */
#define OOM_PART(C, CALL)                                                                          \
    do { CALL; if ((C)->stopped || (C)->bad) return; } while (0)

static sph_status oom_add_phase(sph_world* w, const sph_phase* ph, int* index) {
    *index = sph_world_add_phase(w, ph);
    return *index >= 0 ? SPH_OK : w->status;
}

static uint64_t oom_fnv(uint64_t h, const void* p, size_t n) {
    const unsigned char* b = (const unsigned char*)p;
    size_t i;
    for (i = 0; i < n; ++i) {
        h ^= b[i];
        h *= 1099511628211ULL;
    }
    return h;
}
#define OOM_H(h, field) ((h) = oom_fnv((h), &(field), sizeof(field)))

/* Every array and counter of the state that a later step reads or a host sees. */
static uint64_t oom_hash_world(const sph_world* w) {
    const size_t D = (size_t)w->dim, r = sizeof(sph_real), n = w->n, nb = w->nb;
    uint64_t h = 14695981039346656037ULL;
    int q;
    OOM_H(h, w->n);
    OOM_H(h, w->nb);
    OOM_H(h, w->time);
    OOM_H(h, w->steps);
    OOM_H(h, w->next_id);
    OOM_H(h, w->b_next_id);
    OOM_H(h, w->nphase);
    OOM_H(h, w->mass);
    for (q = 0; q < w->nphase; ++q) OOM_H(h, w->phases[q].sound_speed);
    if (n) {
        h = oom_fnv(h, w->x, n * D * r);
        h = oom_fnv(h, w->v, n * D * r);
        h = oom_fnv(h, w->a, n * D * r);
        h = oom_fnv(h, w->rho, n * r);
        h = oom_fnv(h, w->p, n * r);
        h = oom_fnv(h, w->drho, n * r);
        h = oom_fnv(h, w->id, n * sizeof(uint32_t));
        h = oom_fnv(h, w->phase, n);
        if (w->m) h = oom_fnv(h, w->m, n * r);
        if (w->e) h = oom_fnv(h, w->e, n * r);
    }
    if (nb) {
        h = oom_fnv(h, w->b_x, nb * D * r);
        h = oom_fnv(h, w->b_v, nb * D * r);
        h = oom_fnv(h, w->b_x0, nb * D * r);
        h = oom_fnv(h, w->b_vol, nb * r);
        h = oom_fnv(h, w->b_p, nb * r);
        h = oom_fnv(h, w->b_rho, nb * r);
        h = oom_fnv(h, w->b_id, nb * sizeof(uint32_t));
        h = oom_fnv(h, w->b_body, nb * sizeof(uint16_t));
    }
    OOM_H(h, w->stats.iterations);
    OOM_H(h, w->stats.solver_error);
    OOM_H(h, w->stats.density_error_max);
    OOM_H(h, w->stats.v_max);
    OOM_H(h, w->stats.a_max);
    OOM_H(h, w->stats.kinetic_energy);
    OOM_H(h, w->stats.pairs);
    return h;
}

static uint64_t oom_hash_grid(uint64_t h, const sph_grid* g) {
    OOM_H(h, g->n);
    OOM_H(h, g->nbucket);
    OOM_H(h, g->hashed);
    OOM_H(h, g->cmin);
    OOM_H(h, g->ext);
    if (g->n) h = oom_fnv(h, g->order, g->n * sizeof(uint32_t));
    if (g->n) h = oom_fnv(h, g->start, (g->nbucket + 1) * sizeof(uint32_t));
    if (g->n && g->hashed) h = oom_fnv(h, g->key, g->n * sizeof(uint64_t));
    return h;
}

static uint64_t oom_hash_lists(uint64_t h, const sph_neighbors* nl) {
    size_t i;
    OOM_H(h, nl->n);
    OOM_H(h, nl->total);
    for (i = 0; i < nl->n; ++i) {
        OOM_H(h, nl->count[i]);
        h = oom_fnv(h, nl->idx + nl->begin[i], nl->count[i] * sizeof(uint32_t));
    }
    return h;
}

static uint64_t oom_hash(const oom_ctx* C) {
    uint64_t h = oom_hash_world(&C->w);
    h = oom_hash_grid(h, &C->g);
    h = oom_hash_grid(h, &C->g2);
    h = oom_hash_lists(h, &C->nl);
    return oom_hash_lists(h, &C->nl2);
}

/* Where each id sits (ids are dense: 0 .. next-1); SIZE_MAX for none. */
static size_t* oom_where(const uint32_t* id, size_t n, uint32_t next) {
    size_t* at = (size_t*)malloc((size_t)next * sizeof(size_t) + 1);
    size_t i;
    if (!at) return NULL;
    for (i = 0; i < next; ++i) at[i] = (size_t)-1;
    for (i = 0; i < n; ++i) at[id[i]] = i;
    return at;
}

/* What a call that ran out of memory must leave as it was, whatever the particle order (a step
   may sort the particles before it runs out): per fluid id x, v, rho, p, drho (not with the
   second-order scheme, whose stages recompute them from x, v, rho), phase, m, e; per
   wall id (of walls without a motion callback) x, v, x0, body and the volume (unless Akinci's,
   which a step recomputes); counts, ids, time, steps, phase masses; the standalone grids whole.
   Not the phases' sound speeds: a step (and sph_set_hydrostatic) chooses automatic ones from the
   state before it allocates, the same in the repeated call (the final comparison sees them). */
static uint64_t oom_invariant(const oom_ctx* C) {
    const sph_world* w = &C->w;
    const size_t D = (size_t)w->dim, r = sizeof(sph_real);
    uint64_t h = 14695981039346656037ULL;
    size_t* at;
    uint32_t q;
    int k;
    OOM_H(h, w->n);
    OOM_H(h, w->nb);
    OOM_H(h, w->time);
    OOM_H(h, w->steps);
    OOM_H(h, w->next_id);
    OOM_H(h, w->b_next_id);
    OOM_H(h, w->nphase);
    OOM_H(h, w->mass);
    for (k = 0; k < w->nphase; ++k) OOM_H(h, w->phases[k].mass);
    k = (w->m != NULL) + 2 * (w->e != NULL);
    OOM_H(h, k);
    at = w->n ? oom_where(w->id, w->n, w->next_id) : NULL;
    for (q = 0; at && q < w->next_id; ++q) {
        const size_t i = at[q];
        if (i == (size_t)-1) continue;
        OOM_H(h, q);
        h = oom_fnv(h, w->x + i * D, D * r);
        h = oom_fnv(h, w->v + i * D, D * r);
        h = oom_fnv(h, w->rho + i, r);
        if (w->def.scheme != SPH_SCHEME_SECOND_ORDER) { /* which recomputes both per stage */
            h = oom_fnv(h, w->p + i, r);
            h = oom_fnv(h, w->drho + i, r);
        }
        h = oom_fnv(h, w->phase + i, 1);
        if (w->m) h = oom_fnv(h, w->m + i, r);
        if (w->e) h = oom_fnv(h, w->e + i, r);
    }
    free(at);
    at = w->nb ? oom_where(w->b_id, w->nb, w->b_next_id) : NULL;
    for (q = 0; at && q < w->b_next_id; ++q) {
        const size_t b = at[q];
        if (b == (size_t)-1) continue;
        OOM_H(h, q);
        h = oom_fnv(h, w->b_x0 + b * D, D * r);
        h = oom_fnv(h, w->b_body + b, sizeof(uint16_t));
        if (w->def.boundary_motion) continue;
        h = oom_fnv(h, w->b_x + b * D, D * r);
        h = oom_fnv(h, w->b_v + b * D, D * r);
        if (w->def.boundary_volume != SPH_BVOL_AKINCI) h = oom_fnv(h, w->b_vol + b, r);
    }
    free(at);
    h = oom_hash_grid(h, &C->g);
    return oom_hash_grid(h, &C->g2);
}

/* After SPH_ERR_NOMEM: nothing that matters changed, and what is left can be read: the
   standalone grids answer queries and the lists (empty or not) stay within their arrays (ASan
   in make check-sanitize watches the reads). */
static void oom_after_failure(oom_ctx* C, uint64_t before, const char* what, int line) {
    const sph_grid* grids[2];
    const sph_neighbors* lists[2];
    uint32_t out[64];
    size_t i, kk, sum = 0;
    int t;
    CHECK_MSG(oom_invariant(C) == before,
              "%s, allocation %lu: line %d: %s ran out of memory but changed the world (or grid)",
              C->name, C->k, line, what);
    grids[0] = &C->g;
    grids[1] = &C->g2;
    lists[0] = &C->nl;
    lists[1] = &C->nl2;
    for (t = 0; t < 2; ++t) {
        const sph_grid* g = grids[t];
        const sph_neighbors* nl = lists[t];
        if (g->n) /* the grid was built on oom_pts (which may have moved since: any answer will do) */
            for (i = 0; i < 20; ++i)
                sum += sph_grid_query(g, oom_pts, oom_pts + (i * 37 % g->n) * (size_t)g->dim,
                                      g->cell, out, 64);
        for (i = 0; i < nl->n; ++i)
            for (kk = nl->begin[i]; kk < nl->begin[i] + nl->count[i]; ++kk) sum += nl->idx[kk];
    }
    (void)sum;
    (void)sph_world_memory(&C->w);
    (void)sph_world_mass(&C->w);
}

static void oom_release(oom_ctx* C) {
    sph_world_free(&C->w);
    sph_grid_free(&C->g);
    sph_grid_free(&C->g2);
    sph_neighbors_free(&C->nl);
    sph_neighbors_free(&C->nl2);
}


/* x, v, rho of the fluid by id, with time and steps: for the scenarios compared to round-off. */
typedef struct oom_snap {
    size_t n, dim;
    double time;
    uint64_t steps;
    double* val; /* per id: x, v, rho */
} oom_snap;

static void oom_snap_take(oom_snap* S, const sph_world* w) {
    const size_t D = (size_t)w->dim, per = 2 * D + 1;
    size_t i, k;
    S->n = w->n;
    S->dim = D;
    S->time = w->time;
    S->steps = w->steps;
    S->val = (double*)calloc(w->n * per + 1, sizeof(double));
    if (!S->val) return;
    for (i = 0; i < w->n; ++i) {
        double* o = S->val + (size_t)w->id[i] * per;
        if (w->id[i] >= w->n) continue;
        for (k = 0; k < D; ++k) {
            o[k] = (double)w->x[i * D + k];
            o[D + k] = (double)w->v[i * D + k];
        }
        o[2 * D] = (double)w->rho[i];
    }
}

/* The largest difference relative to the reference's scale (1 for positions and speeds); 1e300
   if time, steps or counts differ. */
static double oom_snap_diff(const oom_snap* ref, const sph_world* w) {
    oom_snap S;
    double worst = 0;
    size_t i;
    if (w->n != ref->n || w->time != ref->time || w->steps != ref->steps || !ref->val) return 1e300;
    oom_snap_take(&S, w);
    if (!S.val) return 1e300;
    for (i = 0; i < ref->n * (2 * ref->dim + 1); ++i) {
        const double a = ref->val[i], b = S.val[i], scale = fabs(a) > 1 ? fabs(a) : 1;
        if (!(fabs(a - b) / scale <= worst)) worst = fabs(a - b) / scale;
    }
    free(S.val);
    return worst;
}

/* The clean run, then every allocation failing once in each mode. tol = 0: the repeated call
   must give the clean run's state bit for bit; tol > 0: x, v, rho to tol (for the second-order
   scheme, whose neighbour lists a repeated step may rebuild in a different particle order).
   serial: the failing runs on one thread (a world large enough for parallel loops; the clean run
   keeps the default threads, and the results are the same for any number of threads). */
static void oom_run_tol(const char* name, void (*scenario)(oom_ctx*), double tol, int serial) {
    static oom_ctx C; /* static: a world is a few kB */
    const long live0 = th_alloc_live();
    unsigned long n, k;
    uint64_t ref;
    oom_snap snap;
    double worst = 0;
    int mode, exact = 0;
#ifdef _OPENMP
    const int threads = omp_get_max_threads();
#endif
    memset(&C, 0, sizeof(C));
    C.name = name;
    th_alloc_fail_at(0);
    scenario(&C);
    n = th_alloc_count();
    CHECK_MSG(!C.bad && !C.failed, "%s: the clean run failed", name);
    if (C.bad || C.failed) { oom_release(&C); return; }
    ref = oom_hash(&C);
    oom_snap_take(&snap, &C.w);
    oom_release(&C);
    CHECK_MSG(th_alloc_live() == live0, "%s: the clean run leaks %ld blocks", name,
              th_alloc_live() - live0);
#ifdef _OPENMP
    if (serial) omp_set_num_threads(1);
#else
    (void)serial;
#endif
    for (k = 1; k <= n; ++k) {
        for (mode = 1; mode <= 2; ++mode) {
            memset(&C, 0, sizeof(C));
            C.name = name;
            C.mode = mode;
            C.k = k;
            th_alloc_fail_at(k);
            scenario(&C);
            th_alloc_disarm();
            CHECK_MSG(C.failed || C.bad, "%s: allocation %lu of %lu failed unnoticed (no call "
                      "returned SPH_ERR_NOMEM)", name, k, n);
            if (mode == 1 && C.failed && !C.bad) {
                if (oom_hash(&C) == ref) {
                    ++exact;
                } else if (tol > 0) {
                    const double d = oom_snap_diff(&snap, &C.w);
                    if (d > worst) worst = d;
                    CHECK_MSG(d <= tol, "%s: allocation %lu of %lu failed in %s; after the "
                              "repeated call x, v, rho differ from the clean run's by %g", name,
                              k, n, C.where, d);
                } else {
                    CHECK_MSG(0, "%s: allocation %lu of %lu failed in %s; after the repeated "
                              "call the final state differs from the clean run's", name, k, n,
                              C.where);
                }
            }
            oom_release(&C);
            CHECK_MSG(th_alloc_live() == live0, "%s: allocation %lu of %lu failed in %s (%s mode): "
                      "%ld blocks leaked", name, k, n, C.where ? C.where : "?",
                      mode == 1 ? "retry" : "free", th_alloc_live() - live0);
            if (th_alloc_live() != live0) break; /* one leak report per scenario */
        }
        if (th_alloc_live() != live0) break;
    }
#ifdef _OPENMP
    omp_set_num_threads(threads);
#endif
    free(snap.val);
    CHECK_EQ_INT(th_alloc_in_parallel(), 0);
    CHECK_MSG(n > 0, "%s: the clean run allocated nothing, so nothing was tested", name);
    if (exact < (int)n)
        TH_NOTE("%s: %lu allocation points, each failed once (then repeated: %d bit for bit, "
                "the others within %.2g; and freed at once)", name, n, exact, worst);
    else
        TH_NOTE("%s: %lu allocation points, each failed once (then repeated: the clean run's "
                "state bit for bit; and freed at once)", name, n);
}

static void oom_run(const char* name, void (*scenario)(oom_ctx*)) {
    oom_run_tol(name, scenario, 0, 0);
}

/* ---- scenarios ----------------------------------------------------------------------------- */

static sph_phase oom_phase(double rest_density) {
    sph_phase ph;
    memset(&ph, 0, sizeof(ph));
    ph.rest_density = (sph_real)rest_density;
    return ph;
}

/* A 2D tank: 20 x 10 particles of water (dx = 0.02) in walls around 0.4 x 0.3 m, open top. The
   water moves (a swirl of 0.2 m/s), so that a step that ran out of memory after moving particles
   and moved them again when repeated would show. */
static void oom_tank(oom_ctx* C, const sph_world_def* def, int layers) {
    sph_world* w = &C->w;
    sph_phase water = oom_phase(1000);
    sph_real lo[2] = {0, 0}, hi[2] = {(sph_real)0.4, (sph_real)0.2};
    sph_real whi[2] = {(sph_real)0.4, (sph_real)0.3};
    size_t i;
    int ph;
    OOM(C, w, sph_world_init(w, def));
    OOM(C, w, oom_add_phase(w, &water, &ph));
    OOM(C, w, sph_fill_box(w, ph, lo, hi));
    OOM(C, w, sph_add_wall_box(w, lo, whi, layers, SPH_FACE_YMAX));
    for (i = 0; i < w->n; ++i) {
        w->v[2 * i] = (sph_real)(0.2 * sin(7.85 * (double)w->x[2 * i + 1]));
        w->v[2 * i + 1] = (sph_real)(-0.2 * sin(7.85 * (double)w->x[2 * i]));
    }
}

static sph_world_def oom_def2(void) {
    sph_world_def def = sph_world_def_default(2);
    def.spacing = (sph_real)0.02;
    return def;
}

/* Every way of adding phases and particles, growing the arrays several times, with a mass
   array appearing midway, and the hydrostatic initialisation. */
static void scen_setup(oom_ctx* C) {
    sph_world* w = &C->w;
    sph_world_def def = oom_def2();
    sph_phase water = oom_phase(1000), oil = oom_phase(800);
    sph_real lo[2] = {0, 0}, hi[2] = {(sph_real)0.3, (sph_real)0.2};
    sph_real lo2[2] = {0, (sph_real)0.3}, hi2[2] = {(sph_real)0.3, (sph_real)0.36};
    sph_real whi[2] = {(sph_real)0.4, (sph_real)0.5};
    sph_real x[80], v[80], m[40], rho[40], bx[60], bvol[30];
    int ph0, ph1, i;
    for (i = 0; i < 40; ++i) {
        x[2 * i] = (sph_real)(0.01 + 0.02 * (i % 20));
        x[2 * i + 1] = (sph_real)(0.21 + 0.02 * (i / 20));
        v[2 * i] = (sph_real)0.1;
        v[2 * i + 1] = 0;
        m[i] = (sph_real)(0.32 + 0.001 * i);
        rho[i] = (sph_real)(800 + i);
    }
    for (i = 0; i < 30; ++i) {
        bx[2 * i] = (sph_real)(0.6 + 0.02 * i);
        bx[2 * i + 1] = (sph_real)-0.01;
        bvol[i] = (sph_real)(0.0004 * (1 + 0.01 * i));
    }
    OOM(C, w, sph_world_init(w, &def));
    OOM(C, w, oom_add_phase(w, &water, &ph0));
    OOM(C, w, sph_fill_box(w, ph0, lo, hi));
    OOM(C, w, sph_add_fluid(w, ph0, 40, x, v));
    OOM(C, w, oom_add_phase(w, &oil, &ph1));
    for (i = 0; i < 40; ++i) x[2 * i + 1] += (sph_real)0.04;
    OOM(C, w, sph_add_fluid_ex(w, ph1, 40, x, NULL, m, rho)); /* the mass array appears */
    OOM(C, w, sph_fill_box(w, ph1, lo2, hi2));                /* and grows with the others */
    OOM(C, w, sph_add_wall_box(w, lo, whi, 0, SPH_FACE_YMAX));
    OOM(C, w, sph_add_boundary(w, 30, bx, NULL, 1));
    for (i = 0; i < 30; ++i) bx[2 * i + 1] -= (sph_real)0.02;
    OOM(C, w, sph_add_boundary(w, 30, bx, bvol, 2));
    OOM(C, w, sph_set_hydrostatic(w));
}

/* WCSPH, symplectic Euler, continuity: two steps, fluid added, a third step (arrays, grids,
   lists and scratch grow mid-run). */
static void scen_wcsph(oom_ctx* C) {
    sph_world* w = &C->w;
    sph_world_def def = oom_def2();
    sph_real x[40];
    int i;
    OOM_PART(C, oom_tank(C, &def, 0));
    OOM(C, w, th_step(w, (sph_real)2e-4));
    OOM(C, w, th_step(w, (sph_real)2e-4));
    for (i = 0; i < 20; ++i) {
        x[2 * i] = (sph_real)(0.01 + 0.02 * i);
        x[2 * i + 1] = (sph_real)0.23;
    }
    OOM(C, w, sph_add_fluid(w, 0, 20, x, NULL));
    OOM(C, w, th_step(w, (sph_real)2e-4));
}

static void scen_wcsph_summation(oom_ctx* C) {
    sph_world* w = &C->w;
    sph_world_def def = oom_def2();
    def.density = SPH_DENSITY_SUMMATION;
    OOM_PART(C, oom_tank(C, &def, 0));
    OOM(C, w, th_step(w, (sph_real)2e-4));
    OOM(C, w, th_step(w, (sph_real)2e-4));
}

static void scen_wcsph_verlet(oom_ctx* C) {
    sph_world* w = &C->w;
    sph_world_def def = oom_def2();
    def.integrator = SPH_INTEGRATOR_VERLET;
    OOM_PART(C, oom_tank(C, &def, 0));
    OOM(C, w, th_step(w, (sph_real)2e-4));
    OOM(C, w, th_step(w, (sph_real)2e-4));
    OOM(C, w, th_step(w, (sph_real)2e-4));
}

static void scen_pcisph(oom_ctx* C, int enhanced) {
    sph_world* w = &C->w;
    sph_world_def def = oom_def2();
    sph_world_def_pcisph(&def, enhanced);
    OOM_PART(C, oom_tank(C, &def, 0));
    OOM(C, w, th_step(w, (sph_real)1e-3));
    OOM(C, w, th_step(w, (sph_real)1e-3));
}
static void scen_pcisph_original(oom_ctx* C) { scen_pcisph(C, 0); }
static void scen_pcisph_enhanced(oom_ctx* C) { scen_pcisph(C, 1); }

/* More than ten reduction blocks of 256 particles: a 1D column of 2600 particles, at rest
   without gravity but moving by a uniform velocity, original PCISPH. */
static void scen_pcisph_blocks(oom_ctx* C) {
    sph_world* w = &C->w;
    sph_world_def def = sph_world_def_default(1);
    sph_phase water = oom_phase(1000);
    sph_real lo[1] = {0}, hi[1] = {(sph_real)2.6};
    size_t i;
    int ph;
    def.spacing = (sph_real)0.001;
    sph_world_def_pcisph(&def, 0);
    water.sound_speed = 10;
    OOM(C, w, sph_world_init(w, &def));
    OOM(C, w, oom_add_phase(w, &water, &ph));
    OOM(C, w, sph_fill_box(w, ph, lo, hi));
    for (i = 0; i < w->n; ++i) w->v[i] = (sph_real)0.1;
    OOM(C, w, th_step(w, (sph_real)1e-3));
}

static void scen_iisph(oom_ctx* C) {
    sph_world* w = &C->w;
    sph_world_def def = oom_def2();
    def.solver = SPH_SOLVER_IISPH;
    OOM_PART(C, oom_tank(C, &def, 0));
    OOM(C, w, th_step(w, (sph_real)2e-3));
    OOM(C, w, th_step(w, (sph_real)2e-3));
}

/* Position based fluids: its step predicts the positions before the neighbour search, and must
   put them back when the search runs out of memory. */
static void scen_pbf(oom_ctx* C) {
    sph_world* w = &C->w;
    sph_world_def def = oom_def2();
    def.solver = SPH_SOLVER_PBF;
    OOM_PART(C, oom_tank(C, &def, 0));
    OOM(C, w, th_step(w, (sph_real)2e-3));
    OOM(C, w, th_step(w, (sph_real)2e-3));
}

/* Compressible, 1D: Tait water, then two ideal gases (the internal energy array appears with
   particles present), unequal masses, closed by walls (multiphase walls: a wall pressure per
   phase). */
static void scen_compressible(oom_ctx* C) {
    sph_world* w = &C->w;
    sph_world_def def = sph_world_def_default(1);
    sph_phase water = oom_phase(1000), gas_a = oom_phase(1), gas_b = oom_phase(0.125);
    sph_real l0[1] = {0}, l1[1] = {(sph_real)0.3}, l2[1] = {(sph_real)0.8}, l3[1] = {(sph_real)1.3};
    sph_real dt;
    int pw, pa, pb;
    def.spacing = (sph_real)0.01;
    def.solver = SPH_SOLVER_COMPRESSIBLE;
    def.density = SPH_DENSITY_PARTICLE;
    def.pressure_grad = SPH_PGRAD_MULTIPHASE;
    water.sound_speed = 50;
    water.back_pressure = (sph_real)1e5;
    gas_a.eos = gas_b.eos = SPH_EOS_IDEAL_GAS;
    gas_a.back_pressure = (sph_real)1e5;
    gas_b.back_pressure = (sph_real)1e4;
    OOM(C, w, sph_world_init(w, &def));
    OOM(C, w, oom_add_phase(w, &water, &pw));
    OOM(C, w, sph_fill_box(w, pw, l0, l1));
    OOM(C, w, oom_add_phase(w, &gas_a, &pa)); /* w.e appears */
    OOM(C, w, oom_add_phase(w, &gas_b, &pb));
    OOM(C, w, sph_fill_box(w, pa, l1, l2));
    OOM(C, w, sph_fill_box(w, pb, l2, l3));
    OOM(C, w, sph_add_wall_box(w, l0, l3, 0, 0));
    dt = (sph_real)0.5 * sph_stable_dt(w, SPH_SOLVER_COMPRESSIBLE);
    CHECK(dt > 0);
    OOM(C, w, th_step(w, dt));
    OOM(C, w, th_step(w, dt));
}

/* The second-order scheme: a periodic Taylor-Green box of 16 x 16, shifting every step. */
static void scen_second_order(oom_ctx* C) {
    sph_world* w = &C->w;
    sph_world_def def = sph_world_def_default(2);
    sph_phase fluid = oom_phase(1);
    sph_real lo[2] = {0, 0}, hi[2] = {1, 1}, dt;
    const double pi = 3.14159265358979323846;
    size_t i;
    int ph, k;
    def.spacing = (sph_real)(1.0 / 16);
    def.kernel = SPH_KERNEL_QUINTIC;
    def.h_factor = (sph_real)1.2;
    def.scheme = SPH_SCHEME_SECOND_ORDER;
    def.alpha = 0;
    def.delta = 0;
    def.shift_every = 1;
    for (k = 0; k < 2; ++k) {
        def.gravity[k] = 0;
        def.periodic[k] = 1;
        def.domain_lo[k] = 0;
        def.domain_hi[k] = 1;
    }
    fluid.sound_speed = 20;
    fluid.viscosity = (sph_real)0.01;
    OOM(C, w, sph_world_init(w, &def));
    OOM(C, w, oom_add_phase(w, &fluid, &ph));
    OOM(C, w, sph_fill_box(w, ph, lo, hi));
    for (i = 0; i < w->n; ++i) {
        const double x = (double)w->x[2 * i], y = (double)w->x[2 * i + 1];
        w->v[2 * i] = (sph_real)(-cos(2 * pi * x) * sin(2 * pi * y));
        w->v[2 * i + 1] = (sph_real)(sin(2 * pi * x) * cos(2 * pi * y));
    }
    dt = (sph_real)(0.3 * (double)w->h / 21);
    OOM(C, w, th_step(w, dt));
    OOM(C, w, th_step(w, dt));
}

/* Fault injection for the second-order scheme, whose first stage moves the particles before its
   second stage and the shifting may rebuild the lists: from the force callback (called once per
   stage, after the stage's pair scratch is set up), the lists' and the pair scratch's recorded
   capacities are zeroed, so that the next rebuild and the next pair scratch allocate again (the
   same sizes) -- allocation points in mid-step, after the particles moved. Test-only: it writes
   the world's private state through the callback's const pointer. */
static void oom_regrow(const sph_world* cw, size_t begin, size_t end, sph_real* acc, void* user) {
    sph_world* w = (sph_world*)user;
    (void)cw;
    (void)end;
    (void)acc;
    if (begin != 0) return;
    w->priv.snl.cap_idx = 0;
    w->priv.socw_cap = 0;
}

/* The second-order scheme with lists that must be rebuilt (and grow, see oom_regrow) at the
   midpoint and in the shifting: a 16 x 16 periodic box flowing at 1 m/s (plus a weak
   Taylor-Green vortex), dt = 0.02 s, so a particle moves 0.16 dx per half step, beyond half the
   lists' skin of 0.2 dx. Failures there are undone to the step's start state; the repeated step
   may sort and list the particles differently, hence the comparison to round-off. */
static void scen_second_order_midstep(oom_ctx* C) {
    sph_world* w = &C->w;
    sph_world_def def = sph_world_def_default(2);
    sph_phase fluid = oom_phase(1);
    sph_real lo[2] = {0, 0}, hi[2] = {1, 1};
    const double pi = 3.14159265358979323846;
    size_t i;
    int ph, k;
    def.spacing = (sph_real)(1.0 / 16);
    def.kernel = SPH_KERNEL_QUINTIC;
    def.h_factor = (sph_real)1.2;
    def.scheme = SPH_SCHEME_SECOND_ORDER;
    def.alpha = 0;
    def.delta = 0;
    def.shift_every = 1;
    def.force = oom_regrow;
    def.force_user = w;
    for (k = 0; k < 2; ++k) {
        def.gravity[k] = 0;
        def.periodic[k] = 1;
        def.domain_lo[k] = 0;
        def.domain_hi[k] = 1;
    }
    fluid.sound_speed = 20;
    fluid.viscosity = (sph_real)0.01;
    OOM(C, w, sph_world_init(w, &def));
    OOM(C, w, oom_add_phase(w, &fluid, &ph));
    OOM(C, w, sph_fill_box(w, ph, lo, hi));
    for (i = 0; i < w->n; ++i) {
        const double x = (double)w->x[2 * i], y = (double)w->x[2 * i + 1];
        w->v[2 * i] = (sph_real)(1 - 0.01 * cos(2 * pi * x) * sin(2 * pi * y));
        w->v[2 * i + 1] = (sph_real)(0.01 * sin(2 * pi * x) * cos(2 * pi * y));
        /* off the lattice by up to 0.05 dx, so that the shifting moves particles */
        w->x[2 * i] += (sph_real)(0.003 * sin(12.9898 * (double)i));
        w->x[2 * i + 1] += (sph_real)(0.003 * sin(78.233 * (double)i));
    }
    OOM(C, w, th_step(w, (sph_real)0.02));
    CHECK(w->stats.iterations >= 2); /* shifted */
    OOM(C, w, th_step(w, (sph_real)0.02));
}

/* Water under oil in a tank: the multiphase wall pressure (one per phase and wall particle). */
static void scen_multiphase_walls(oom_ctx* C) {
    sph_world* w = &C->w;
    sph_world_def def = oom_def2();
    sph_phase oil = oom_phase(800);
    sph_real lo[2] = {0, (sph_real)0.2}, hi[2] = {(sph_real)0.4, (sph_real)0.26};
    int ph;
    OOM_PART(C, oom_tank(C, &def, 0));
    OOM(C, w, oom_add_phase(w, &oil, &ph));
    OOM(C, w, sph_fill_box(w, ph, lo, hi));
    OOM(C, w, th_step(w, (sph_real)2e-4));
    OOM(C, w, th_step(w, (sph_real)2e-4));
}

/* Walls that move sideways, so they are re-sorted every step. */
static void oom_slide(sph_world* w, double t, void* user) {
    size_t b;
    (void)user;
    for (b = 0; b < w->nb; ++b) {
        w->b_x[b * 2] = w->b_x0[b * 2] + (sph_real)(0.05 * t);
        w->b_x[b * 2 + 1] = w->b_x0[b * 2 + 1];
        w->b_v[b * 2] = (sph_real)0.05;
        w->b_v[b * 2 + 1] = 0;
    }
}

/* Akinci wall volumes of a single wall layer, walls moving (boundary-boundary lists each step). */
static void scen_akinci(oom_ctx* C) {
    sph_world* w = &C->w;
    sph_world_def def = oom_def2();
    def.boundary_volume = SPH_BVOL_AKINCI;
    def.boundary_motion = oom_slide;
    OOM_PART(C, oom_tank(C, &def, 1));
    OOM(C, w, th_step(w, (sph_real)2e-4));
    OOM(C, w, th_step(w, (sph_real)2e-4));
}

/* Akinci volumes of static walls with IISPH: volumes computed once, at the first step. */
static void scen_akinci_static(oom_ctx* C) {
    sph_world* w = &C->w;
    sph_world_def def = oom_def2();
    def.boundary_volume = SPH_BVOL_AKINCI;
    def.solver = SPH_SOLVER_IISPH;
    def.max_compression = 0; /* a single layer of gamma 1 weighs about three: dense at first */
    OOM_PART(C, oom_tank(C, &def, 1));
    OOM(C, w, th_step(w, (sph_real)2e-3));
    OOM(C, w, th_step(w, (sph_real)2e-3));
}

/* sph_grid_build / sph_neighbors_build on their own: a dense 2D grid that grows, a hashed grid
   (one point far away), a periodic 3D grid, lists with and without exclude_self. */
static void scen_grid(oom_ctx* C) {
    const int per[3] = {1, 1, 1};
    const sph_real lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    unsigned long s = 12345;
    size_t i;
    for (i = 0; i < 3 * 600; ++i) {
        s = (s * 1103515245UL + 12345UL) & 0x7fffffffUL;
        oom_pts[i] = (sph_real)((double)s / 2147483648.0);
    }
    if (sph_grid_init(&C->g, 2, (sph_real)0.1, NULL, NULL, NULL) != SPH_OK ||
        sph_grid_init(&C->g2, 3, (sph_real)0.25, per, lo, hi) != SPH_OK) {
        C->bad = 1;
        CHECK(0);
        return;
    }
    OOM(C, NULL, sph_grid_build(&C->g, oom_pts, 200));
    OOM(C, NULL, sph_neighbors_build(&C->nl, &C->g, oom_pts, oom_pts, 200, (sph_real)0.1, 1));
    OOM(C, NULL, sph_grid_build(&C->g, oom_pts, 900)); /* grows */
    OOM(C, NULL, sph_neighbors_build(&C->nl, &C->g, oom_pts, oom_pts, 900, (sph_real)0.1, 1));
    oom_pts[2 * 899] = 1000; /* one point far away: the hash table */
    OOM(C, NULL, sph_grid_build(&C->g, oom_pts, 900));
    OOM(C, NULL, sph_neighbors_build(&C->nl, &C->g, oom_pts, oom_pts + 2, 300, (sph_real)0.1, 0));
    OOM(C, NULL, sph_grid_build(&C->g2, oom_pts, 600));
    OOM(C, NULL, sph_neighbors_build(&C->nl2, &C->g2, oom_pts, oom_pts, 600, (sph_real)0.25, 1));
}

static void test_oom_setup(void) { oom_run("setup", scen_setup); }
static void test_oom_grid(void) { oom_run("grid_neighbors", scen_grid); }
static void test_oom_wcsph(void) { oom_run("wcsph_continuity", scen_wcsph); }
static void test_oom_wcsph_summation(void) { oom_run("wcsph_summation", scen_wcsph_summation); }
static void test_oom_wcsph_verlet(void) { oom_run("wcsph_verlet", scen_wcsph_verlet); }
static void test_oom_pcisph_original(void) { oom_run("pcisph_original", scen_pcisph_original); }
static void test_oom_pcisph_enhanced(void) { oom_run("pcisph_enhanced", scen_pcisph_enhanced); }
static void test_oom_pcisph_blocks(void) {
    oom_run_tol("pcisph_blocks", scen_pcisph_blocks, 0, 1);
}
static void test_oom_iisph(void) { oom_run("iisph", scen_iisph); }
static void test_oom_pbf(void) { oom_run("pbf", scen_pbf); }
static void test_oom_compressible(void) { oom_run("compressible_gas", scen_compressible); }
static void test_oom_second_order(void) { oom_run("second_order", scen_second_order); }
static void test_oom_second_order_midstep(void) {
    oom_run_tol("second_order_midstep", scen_second_order_midstep, 100 * TH_ROUNDOFF, 0);
}
static void test_oom_multiphase(void) { oom_run("multiphase_walls", scen_multiphase_walls); }
static void test_oom_akinci(void) { oom_run("akinci_moving", scen_akinci); }
static void test_oom_akinci_static(void) { oom_run("akinci_iisph", scen_akinci_static); }
/* The paths without allocation points: sph_world_init, the sph_op_* operators, sph_stable_dt and
   the readers allocate nothing, and neither does a step in the steady state (memory reused). */
static void test_oom_none(void) {
    static oom_ctx C;
    sph_world* w = &C.w;
    sph_world_def def = oom_def2();
    sph_kernel k;
    sph_real *vol, *B, *grad, *lap, *f;
    double mom[3];
    size_t n, i;
    memset(&C, 0, sizeof(C));
    C.name = "none";
    th_alloc_fail_at(0);
    CHECK_EQ_INT(sph_world_init(w, &def), SPH_OK);
    CHECK_EQ_INT(th_alloc_count(), 0);
    sph_world_free(w);
    oom_tank(&C, &def, 0);
    CHECK(!C.bad && !C.failed);
    for (i = 0; i < 3; ++i) CHECK_EQ_INT(th_step(w, (sph_real)2e-4), SPH_OK);
    th_alloc_fail_at(0);
    for (i = 0; i < 3; ++i) CHECK_EQ_INT(th_step(w, (sph_real)2e-4), SPH_OK);
    CHECK(sph_stable_dt(w, SPH_SOLVER_WCSPH) > 0);
    (void)sph_world_memory(w);
    (void)sph_world_mass(w);
    sph_world_momentum(w, mom);
    CHECK_EQ_INT(th_alloc_count(), 0);
    /* the operators on a standalone grid and lists */
    n = w->n;
    vol = (sph_real*)malloc(n * sizeof(sph_real));
    B = (sph_real*)malloc(n * 4 * sizeof(sph_real));
    grad = (sph_real*)malloc(n * 2 * sizeof(sph_real));
    lap = (sph_real*)malloc(n * sizeof(sph_real));
    f = (sph_real*)malloc(n * sizeof(sph_real));
    CHECK(vol && B && grad && lap && f);
    for (i = 0; i < n; ++i) f[i] = w->x[2 * i] * w->x[2 * i];
    CHECK_EQ_INT(sph_kernel_init(&k, SPH_KERNEL_WENDLAND_C2, 2, w->h), SPH_OK);
    CHECK_EQ_INT(sph_grid_init(&C.g, 2, k.radius, NULL, NULL, NULL), SPH_OK);
    CHECK_EQ_INT(sph_grid_build(&C.g, w->x, n), SPH_OK);
    CHECK_EQ_INT(sph_neighbors_build(&C.nl, &C.g, w->x, w->x, n, k.radius, 1), SPH_OK);
    th_alloc_fail_at(0);
    sph_op_volume(&C.g, &C.nl, &k, w->x, n, vol);
    (void)sph_op_correction(&C.g, &C.nl, &k, w->x, vol, n, B);
    sph_op_gradient(&C.g, &C.nl, &k, w->x, vol, B, f, 1, n, grad);
    sph_op_divergence(&C.g, &C.nl, &k, w->x, vol, B, w->v, n, lap);
    sph_op_shift(&C.g, &C.nl, &k, w->x, vol, n, grad);
    sph_op_laplacian(&C.g, &C.nl, &k, w->x, vol, B, f, 1, n, grad, lap);
    CHECK_EQ_INT(th_alloc_count(), 0);
    free(vol);
    free(B);
    free(grad);
    free(lap);
    free(f);
    oom_release(&C);
}

const th_test tests_oom[] = {
    {"oom/setup", test_oom_setup},
    {"oom/grid_neighbors", test_oom_grid},
    {"oom/wcsph_continuity", test_oom_wcsph},
    {"oom/wcsph_summation", test_oom_wcsph_summation},
    {"oom/wcsph_verlet", test_oom_wcsph_verlet},
    {"oom/pcisph_original", test_oom_pcisph_original},
    {"oom/pcisph_enhanced", test_oom_pcisph_enhanced},
    {"oom/pcisph_blocks", test_oom_pcisph_blocks},
    {"oom/iisph", test_oom_iisph},
    {"oom/pbf", test_oom_pbf},
    {"oom/compressible_gas", test_oom_compressible},
    {"oom/second_order", test_oom_second_order},
    {"oom/second_order_midstep", test_oom_second_order_midstep},
    {"oom/multiphase_walls", test_oom_multiphase},
    {"oom/akinci_moving", test_oom_akinci},
    {"oom/akinci_iisph", test_oom_akinci_static},
    {"oom/no_allocation_paths", test_oom_none},
    {0, 0},
};
