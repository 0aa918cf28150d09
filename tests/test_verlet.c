/* tests/test_verlet.c - neighbour lists kept between steps with a skin (def.neighbor_skin;
   Verlet 1967, Allen & Tildesley 1987 sec. 5.3): candidate lists within (1 + skin) R, searched
   again once a particle has moved half the skin, each step's lists filtered from them. The lists
   a step uses hold exactly the pairs within R (as a search every step gives), the candidates a
   superset of them; a search is made when a particle moved half the skin (by the flow or by a
   host writing w.x), after sph_advance rolled a step back and when the skin changes; a scene
   gives the same physics to round-off with and without a skin, moving walls included; results
   are bitwise the same on 1 and 2 threads; the default takes a skin for WCSPH only where it
   pays; bad values of the field are refused. */
#include "harness.h"
#include "../sph.h"
#include "../examples/scenes.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

/* ---- helpers ------------------------------------------------------------------------------- */

/* Positions by id (fluid: w.id, walls: w.b_id), so that a state from before a step (which may
   sort the particles) can be compared with the lists the step built. */
static void positions_by_id(const sph_world* w, sph_real* x, sph_real* bx) {
    const size_t D = (size_t)w->dim;
    size_t i;
    for (i = 0; i < w->n; ++i) memcpy(x + (size_t)w->id[i] * D, w->x + i * D, D * sizeof(sph_real));
    for (i = 0; i < w->nb; ++i)
        memcpy(bx + (size_t)w->b_id[i] * D, w->b_x + i * D, D * sizeof(sph_real));
}

static double dist2(const sph_world* w, const sph_real* a, const sph_real* b) {
    sph_real d[3] = {0, 0, 0};
    double r2 = 0;
    int k;
    sph_grid_delta(&w->priv.grid, a, b, d);
    for (k = 0; k < w->dim; ++k) r2 += (double)d[k] * (double)d[k];
    return r2;
}

/* Particles whose list in nl (queries: fluid particles; points: fluid if `walls` is 0, else wall
   particles) is not the set of points within `radius` of the positions xs / bxs (by id) at which
   the step searched: a count differing from a brute-force search, or a listed point beyond the
   radius, or a point listed twice. With exact 0 only the superset is checked (candidates). */
static size_t lists_wrong(const sph_world* w, const sph_neighbors* nl, int walls, double radius,
                          const sph_real* xs, const sph_real* bxs, int exact) {
    const size_t D = (size_t)w->dim, np = walls ? w->nb : w->n;
    const double r2max = radius * radius, R2 = (double)w->kernel.radius * w->kernel.radius;
    size_t i, bad = 0;
    unsigned char* seen = (unsigned char*)calloc(np + 1, 1);
    if (nl->n != w->n) return w->n + 1;
    for (i = 0; i < w->n; ++i) {
        const sph_real* p = xs + (size_t)w->id[i] * D;
        size_t kk, j, within = 0, listed_within = 0;
        int wrong = 0;
        for (kk = nl->begin[i]; kk < nl->begin[i] + nl->count[i]; ++kk) {
            const size_t q = nl->idx[kk];
            const sph_real* xq = walls ? bxs + (size_t)w->b_id[q] * D : xs + (size_t)w->id[q] * D;
            const double r2 = dist2(w, p, xq);
            if (q >= np || seen[q] || (!walls && q == i)) wrong = 1;
            else seen[q] = 1;
            if (exact && !(r2 < r2max * (1 + 1e-12))) wrong = 1;
            listed_within += r2 < R2;
        }
        for (kk = nl->begin[i]; kk < nl->begin[i] + nl->count[i]; ++kk)
            if (nl->idx[kk] < np) seen[nl->idx[kk]] = 0;
        for (j = 0; j < np; ++j) {
            const sph_real* xq = walls ? bxs + (size_t)w->b_id[j] * D : xs + (size_t)w->id[j] * D;
            if ((walls || j != i) && dist2(w, p, xq) < R2) ++within;
        }
        /* every pair within R is listed (exact: and nothing else) */
        if (listed_within != within || (exact && nl->count[i] != within)) wrong = 1;
        bad += (size_t)wrong;
    }
    free(seen);
    return bad;
}

/* One sph_step, then the check of the lists it used against the positions it searched at (a
   WCSPH step with symplectic Euler searches at its start; walls given no motion stay put).
   Returns the number of particles with a wrong list (ff, fb) or wrong candidates (cff, cfb). */
static size_t step_and_check(sph_world* w, sph_real dt) {
    const size_t D = (size_t)w->dim;
    sph_real* xs = (sph_real*)malloc((w->n + 1) * D * sizeof(sph_real));
    sph_real* bxs = (sph_real*)malloc((w->nb + 1) * D * sizeof(sph_real));
    size_t bad = 0;
    positions_by_id(w, xs, bxs);
    CHECK_EQ_INT(sph_step(w, dt), SPH_OK);
    bad += lists_wrong(w, &w->priv.ff, 0, w->kernel.radius, xs, bxs, 1);
    if (w->nb > 0) bad += lists_wrong(w, &w->priv.fb, 1, w->kernel.radius, xs, bxs, 1);
    if (w->def.neighbor_skin > 0) {
        bad += lists_wrong(w, &w->priv.cff, 0, w->priv.vl_radius, xs, bxs, 0);
        if (w->nb > 0) bad += lists_wrong(w, &w->priv.cfb, 1, w->priv.vl_radius, xs, bxs, 0);
    }
    free(xs);
    free(bxs);
    return bad;
}

static int build_dam(sph_world* w, int res, double skin) {
    sph_world_def def = sph_world_def_default(2);
    def.neighbor_skin = (sph_real)skin;
    def.domain_hi[0] = (sph_real)2.5; /* the tank of scene_dam_break at a = 0.5 m */
    def.domain_hi[1] = (sph_real)1.5;
    return scene_dam_break(w, def, 0.5, res, NULL) == SPH_OK;
}

/* Largest distance between the same particle (by id) in two worlds, in spacings. */
static double max_apart(const sph_world* a, const sph_world* b) {
    const size_t D = (size_t)a->dim;
    sph_real* xa = (sph_real*)malloc((a->n + 1) * D * sizeof(sph_real));
    sph_real* xb = (sph_real*)malloc((b->n + 1) * D * sizeof(sph_real));
    sph_real* ba = (sph_real*)malloc((a->nb + 1) * D * sizeof(sph_real));
    double m = 0;
    size_t i;
    positions_by_id(a, xa, ba);
    positions_by_id(b, xb, ba);
    for (i = 0; i < a->n; ++i) {
        const double r = sqrt(dist2(a, xa + i * D, xb + i * D)) / (double)a->dx;
        if (!(r <= m)) m = r; /* NaN too */
    }
    free(xa);
    free(xb);
    free(ba);
    return m;
}

/* ---- the lists ------------------------------------------------------------------------------ */

/* Over a dam break's first steps (the column collapsing: particles of every speed, walls): the
   lists of every step are exactly the pairs within R, the candidates a superset, while the
   candidates are kept for several steps between searches. */
static void test_lists_exact(void) {
    sph_world w;
    size_t bad = 0;
    int s;
    uint64_t builds0;
    CHECK(build_dam(&w, 12, 0.2));
    CHECK_EQ_INT(sph_advance(&w, (sph_real)0.15), SPH_OK); /* under way */
    builds0 = w.stats.neighbor_builds;
    for (s = 0; s < 60; ++s) bad += step_and_check(&w, sph_stable_dt(&w, w.def.solver));
    CHECK_EQ_INT(bad, 0);
    /* kept: fewer searches than steps; and searched again as the particles moved */
    CHECK(w.stats.neighbor_builds - builds0 < 60 / 2);
    CHECK(w.stats.neighbor_builds - builds0 >= 2);
    TH_NOTE("dam break 2D, skin 0.2 R: %d steps, %d searches", 60,
            (int)(w.stats.neighbor_builds - builds0));
    sph_world_free(&w);
}

/* A periodic box (Taylor-Green vortex, WCSPH) whose half length is below (1 + skin) R: the
   candidate radius is cut to half the box, and the lists stay exact across the wrap. */
static void test_lists_exact_periodic(void) {
    sph_world w;
    sph_world_def def = sph_world_def_default(2);
    size_t bad = 0;
    int s;
    def.neighbor_skin = 1;
    CHECK(scene_taylor_green(&w, def, 8, 10) == SPH_OK);
    for (s = 0; s < 20; ++s) bad += step_and_check(&w, sph_stable_dt(&w, w.def.solver));
    CHECK_EQ_INT(bad, 0);
    CHECK(w.priv.vl_radius > w.kernel.radius);
    CHECK(w.priv.vl_radius <= (sph_real)0.5 && w.priv.vl_radius < 2 * w.kernel.radius);
    sph_world_free(&w);
}

/* ---- when the lists are searched again ------------------------------------------------------ */

/* A tank at rest keeps its lists; a host moving one particle by less than half the skin keeps
   them too (and they stay exact); by more, or swapping two particles, makes the next step
   search; changing the skin does too. */
static void test_rebuild_triggers(void) {
    sph_world w;
    sph_world_def def = sph_world_def_default(2);
    uint64_t b;
    size_t bad = 0, i;
    sph_real half, dt, t[2];
    def.neighbor_skin = (sph_real)0.2;
    CHECK(scene_hydrostatic(&w, def, 0.3, 0.3, 15) == SPH_OK);
    dt = sph_stable_dt(&w, w.def.solver);
    half = (sph_real)0.1 * w.kernel.radius;
    bad += step_and_check(&w, dt);
    b = w.stats.neighbor_builds;
    for (i = 0; i < 5; ++i) bad += step_and_check(&w, dt);
    CHECK_EQ_INT(w.stats.neighbor_builds, b); /* at rest: kept */
    w.x[2 * 7] += (sph_real)0.8 * half; /* under half the skin (the rest barely move) */
    bad += step_and_check(&w, dt);
    CHECK_EQ_INT(w.stats.neighbor_builds, b);
    w.x[2 * 7] += (sph_real)0.4 * half; /* now beyond it */
    bad += step_and_check(&w, dt);
    CHECK_EQ_INT(w.stats.neighbor_builds, b + 1);
    /* two particles far apart swapped by the host: each moved far */
    t[0] = w.x[0];
    t[1] = w.x[1];
    w.x[0] = w.x[2 * (w.n - 1)];
    w.x[1] = w.x[2 * (w.n - 1) + 1];
    w.x[2 * (w.n - 1)] = t[0];
    w.x[2 * (w.n - 1) + 1] = t[1];
    bad += step_and_check(&w, dt);
    CHECK_EQ_INT(w.stats.neighbor_builds, b + 2);
    w.def.neighbor_skin = (sph_real)0.3;
    bad += step_and_check(&w, dt);
    CHECK_EQ_INT(w.stats.neighbor_builds, b + 3);
    w.def.neighbor_skin = 0; /* every step again, at the support's cells */
    bad += step_and_check(&w, dt);
    bad += step_and_check(&w, dt);
    CHECK_EQ_INT(w.stats.neighbor_builds, b + 5);
    CHECK(w.priv.grid.cell == w.kernel.radius && w.priv.bgrid.cell == w.kernel.radius);
    CHECK_EQ_INT(bad, 0);
    sph_world_free(&w);
}

/* A force that throws one particle far in one call (the step fails the displacement check and
   sph_advance rolls it back, then retries): the steps after the rollback use exact lists. */
typedef struct kick {
    int calls, at;
} kick;

static void kick_force(const sph_world* w, size_t begin, size_t end, sph_real* acc, void* user) {
    kick* k = (kick*)user;
    size_t i;
    if (begin == 0 && ++k->calls == k->at)
        for (i = begin; i < end && i < 1; ++i) acc[i * (size_t)w->dim] += (sph_real)1e9;
}

static void test_rebuild_after_rollback(void) {
    sph_world w;
    kick k;
    size_t bad = 0;
    int s;
    k.calls = 0;
    k.at = 40;
    CHECK(build_dam(&w, 10, 0.2));
    w.def.force = kick_force;
    w.def.force_user = &k;
    CHECK_EQ_INT(sph_advance(&w, (sph_real)0.05), SPH_OK);
    CHECK(k.calls > k.at);
    CHECK(w.stats.retries >= 1);
    for (s = 0; s < 10; ++s) bad += step_and_check(&w, sph_stable_dt(&w, w.def.solver));
    CHECK_EQ_INT(bad, 0);
    sph_world_free(&w);
}

/* ---- the physics ---------------------------------------------------------------------------- */

/* The dam break through sph_advance with and without a skin: the same pairs every step, summed
   in another order (the particles are sorted only at a search), so the runs agree to round-off
   over a short run; no particle is lost, and the skin saves searches. */
static void test_same_physics(void) {
    sph_world a, b;
    double apart, ke;
    CHECK(build_dam(&a, 12, 0));
    CHECK(build_dam(&b, 12, 0.2));
    CHECK_EQ_INT(sph_advance(&a, (sph_real)0.1), SPH_OK);
    CHECK_EQ_INT(sph_advance(&b, (sph_real)0.1), SPH_OK);
    CHECK_EQ_INT(a.n, b.n);
    CHECK_EQ_INT(a.steps, b.steps);
    apart = max_apart(&a, &b);
    ke = fabs(a.stats.kinetic_energy - b.stats.kinetic_energy) / a.stats.kinetic_energy;
#ifdef SPH_FLOAT
    CHECK(apart < 1e-3);
    CHECK(ke < 1e-3);
#else
    CHECK(apart < 1e-9);
    CHECK(ke < 1e-9);
#endif
    CHECK_EQ_INT(a.stats.neighbor_builds, a.steps);
    CHECK(b.stats.neighbor_builds * 4 < b.steps);
    TH_NOTE("dam break 2D to 0.1 s: %d steps, %d searches with skin 0.2; apart %.2g dx, KE %.2g",
            (int)b.steps, (int)b.stats.neighbor_builds, apart, ke);
    sph_world_free(&a);
    sph_world_free(&b);
}

/* Moving walls with Akinci volumes (the stirrer, Meiers 2025 sec. 5.1.2) with and without a
   skin: the walls' motion counts as displacement, their volumes are recomputed from the kept
   lists; the runs agree to round-off and the lists of a step are exact. */
static void test_moving_walls(void) {
    sph_world a, b;
    scene_stirrer sa, sb;
    sph_world_def def = sph_world_def_default(2);
    double apart;
    size_t bad = 0, i;
    int s;
    sa.omega = sb.omega = 2;
    def.neighbor_skin = 0;
    CHECK(scene_stirrer_build(&a, def, 0.025, 0.5, &sa) == SPH_OK);
    def.neighbor_skin = (sph_real)0.2;
    CHECK(scene_stirrer_build(&b, def, 0.025, 0.5, &sb) == SPH_OK);
    CHECK_EQ_INT(sph_advance(&a, (sph_real)0.1), SPH_OK);
    CHECK_EQ_INT(sph_advance(&b, (sph_real)0.1), SPH_OK);
    CHECK_EQ_INT(a.steps, b.steps);
    apart = max_apart(&a, &b);
#ifdef SPH_FLOAT
    CHECK(apart < 1e-3);
#else
    CHECK(apart < 1e-9);
#endif
    CHECK(b.stats.neighbor_builds < b.steps);
    for (i = 0; i < b.n; ++i) CHECK(b.x[2 * i] == b.x[2 * i] && b.x[2 * i + 1] == b.x[2 * i + 1]);
    TH_NOTE("stirrer to 0.1 s: %d steps, %d searches with skin 0.2; apart %.2g dx", (int)b.steps,
            (int)b.stats.neighbor_builds, apart);
    /* a step's lists against the fluid where the step began and the walls where its callback
       put them (before the search; a WCSPH step moves no wall after it) */
    for (s = 0; s < 5; ++s) {
        const size_t D = 2;
        sph_real* xs = (sph_real*)malloc(b.n * D * sizeof(sph_real));
        sph_real* bxs = (sph_real*)malloc(b.nb * D * sizeof(sph_real));
        sph_real* x1 = (sph_real*)malloc(b.n * D * sizeof(sph_real));
        positions_by_id(&b, xs, bxs);
        CHECK_EQ_INT(sph_step(&b, sph_stable_dt(&b, b.def.solver)), SPH_OK);
        positions_by_id(&b, x1, bxs);
        bad += lists_wrong(&b, &b.priv.ff, 0, b.kernel.radius, xs, bxs, 1);
        bad += lists_wrong(&b, &b.priv.fb, 1, b.kernel.radius, xs, bxs, 1);
        bad += lists_wrong(&b, &b.priv.cfb, 1, b.priv.vl_radius, xs, bxs, 0);
        free(xs);
        free(bxs);
        free(x1);
    }
    CHECK_EQ_INT(bad, 0);
    sph_world_free(&a);
    sph_world_free(&b);
}

/* Lists a and b the same, list for list and pair for pair in order; the lists that differ. */
static size_t lists_differ(const sph_neighbors* a, const sph_neighbors* b) {
    size_t i, kk, bad = 0;
    if (a->n != b->n || a->total != b->total) return a->n + 1;
    for (i = 0; i < a->n; ++i) {
        int same = a->count[i] == b->count[i];
        for (kk = 0; same && kk < a->count[i]; ++kk)
            same = a->idx[a->begin[i] + kk] == b->idx[b->begin[i] + kk];
        bad += !same;
    }
    return bad;
}

/* A step's wall lists (fluid->boundary fb, boundary->fluid bf) against a search of their own:
   the step reads bf off fb (sph__neighbors_transpose) and skips the fluid's stencils far from
   any wall (sph__grid_near); both must give the search's lists exactly, in the same order, for
   moving walls with Akinci volumes (IISPH, the 2D stirrer) and a 3D dam break's static box
   (DFSPH, the automatic cubic kernel). The reference: grids on the positions of the step's
   search (fluid by id from before the step, walls where the step left them), already in cell
   order, so sph_neighbors_build lists in the step's order. */
static size_t wall_lists_check(sph_world* w, int steps) {
    const size_t D = (size_t)w->dim;
    size_t bad = 0, i;
    int s;
    for (s = 0; s < steps; ++s) {
        sph_real* xs = (sph_real*)malloc((w->n + 1) * D * sizeof(sph_real));
        sph_real* bxs = (sph_real*)malloc((w->nb + 1) * D * sizeof(sph_real));
        sph_real* xq = (sph_real*)malloc((w->n + 1) * D * sizeof(sph_real));
        sph_real* bq = (sph_real*)malloc((w->nb + 1) * D * sizeof(sph_real));
        sph_grid g, bg;
        sph_neighbors fb, bf;
        const sph_real R = w->kernel.radius;
        memset(&fb, 0, sizeof fb);
        memset(&bf, 0, sizeof bf);
        positions_by_id(w, xs, bxs);
        if (sph_step(w, sph_stable_dt(w, w->def.solver)) != SPH_OK) {
            free(xs);
            free(bxs);
            free(xq);
            free(bq);
            return 1000000;
        }
        for (i = 0; i < w->n; ++i) memcpy(xq + i * D, xs + (size_t)w->id[i] * D, D * sizeof(sph_real));
        memcpy(bq, w->b_x, w->nb * D * sizeof(sph_real));
        CHECK_EQ_INT(sph_grid_init(&g, w->dim, R, NULL, NULL, NULL), SPH_OK);
        CHECK_EQ_INT(sph_grid_init(&bg, w->dim, R, NULL, NULL, NULL), SPH_OK);
        CHECK_EQ_INT(sph_grid_build(&g, xq, w->n), SPH_OK);
        CHECK_EQ_INT(sph_grid_build(&bg, bq, w->nb), SPH_OK);
        for (i = 0; i < w->n; ++i) bad += g.order[i] != (uint32_t)i; /* the step's cell order */
        for (i = 0; i < w->nb; ++i) bad += bg.order[i] != (uint32_t)i;
        CHECK_EQ_INT(sph_neighbors_build(&fb, &bg, bq, xq, w->n, R, 0), SPH_OK);
        CHECK_EQ_INT(sph_neighbors_build(&bf, &g, xq, bq, w->nb, R, 0), SPH_OK);
        bad += lists_differ(&w->priv.fb, &fb) + lists_differ(&w->priv.bf, &bf);
        CHECK(bf.total > 0);
        sph_neighbors_free(&fb);
        sph_neighbors_free(&bf);
        sph_grid_free(&g);
        sph_grid_free(&bg);
        free(xs);
        free(bxs);
        free(xq);
        free(bq);
    }
    return bad;
}

static void test_wall_lists_mirrored(void) {
    sph_world w;
    scene_stirrer st;
    sph_world_def def = sph_world_def_default(2);
    sph_real lo[3] = {0, 0, 0}, hi[3] = {(sph_real)0.3, (sph_real)0.3, (sph_real)0.3};
    sph_real box[3] = {(sph_real)0.6, (sph_real)0.5, (sph_real)0.4};
    sph_phase water;
    st.omega = 2;
    def.solver = SPH_SOLVER_IISPH;
    CHECK(scene_stirrer_build(&w, def, 0.025, 0.5, &st) == SPH_OK);
    CHECK(w.def.boundary_volume == SPH_BVOL_AKINCI && w.def.boundary_motion != NULL);
    CHECK_EQ_INT(sph_advance(&w, (sph_real)0.05), SPH_OK);
    CHECK_EQ_INT(wall_lists_check(&w, 4), 0);
    sph_world_free(&w);
    def = sph_world_def_default(3);
    def.solver = SPH_SOLVER_DFSPH;
    def.spacing = (sph_real)0.025;
    memset(&water, 0, sizeof water);
    water.rest_density = 1000;
    CHECK_EQ_INT(sph_world_init(&w, &def), SPH_OK);
    CHECK_EQ_INT(sph_fill_box(&w, sph_world_add_phase(&w, &water), lo, hi), SPH_OK);
    CHECK_EQ_INT(sph_add_wall_box(&w, lo, box, 0, 0), SPH_OK);
    CHECK_EQ_INT(sph_set_hydrostatic(&w), SPH_OK);
    CHECK_EQ_INT(wall_lists_check(&w, 3), 0);
    TH_NOTE("3D box: %zu fluid, %zu wall particles, %zu wall pairs", w.n, w.nb, w.priv.bf.total);
    sph_world_free(&w);
}

/* A step's fluid lists against a search of their own: the step searches each pair once (a half
   search, the other half of each list read off it, sph__neighbors_build_self) on the dense grid
   without periodic directions, and must give the whole search's lists exactly, pair for pair
   and in order. Without a skin the step's ff (at the positions of its search, by id from before
   the step, in the step's cell order); with one the candidates cff at their build positions
   (w.priv.vl_x) and radius. Returns the lists that differ (and points out of cell order). */
static size_t fluid_lists_check(sph_world* w, int steps) {
    const size_t D = (size_t)w->dim;
    size_t bad = 0, i;
    int s;
    for (s = 0; s < steps; ++s) {
        sph_real* xs = (sph_real*)malloc((w->n + 1) * D * sizeof(sph_real));
        sph_real* bxs = (sph_real*)malloc((w->nb + 1) * D * sizeof(sph_real));
        sph_real* xq = (sph_real*)malloc((w->n + 1) * D * sizeof(sph_real));
        const int skin = w->def.neighbor_skin > 0;
        sph_real r;
        sph_grid g;
        sph_neighbors ff;
        memset(&ff, 0, sizeof ff);
        positions_by_id(w, xs, bxs);
        if (sph_step(w, sph_stable_dt(w, w->def.solver)) != SPH_OK) bad += 1000000;
        r = skin ? w->priv.vl_radius : w->kernel.radius;
        if (skin) memcpy(xq, w->priv.vl_x, w->n * D * sizeof(sph_real));
        else
            for (i = 0; i < w->n; ++i)
                memcpy(xq + i * D, xs + (size_t)w->id[i] * D, D * sizeof(sph_real));
        CHECK_EQ_INT(sph_grid_init(&g, w->dim, r, NULL, NULL, NULL), SPH_OK);
        CHECK_EQ_INT(sph_grid_build(&g, xq, w->n), SPH_OK);
        for (i = 0; i < w->n; ++i) bad += g.order[i] != (uint32_t)i;
        CHECK_EQ_INT(sph_neighbors_build(&ff, &g, xq, xq, w->n, r, 1), SPH_OK);
        bad += lists_differ(skin ? &w->priv.cff : &w->priv.ff, &ff);
        CHECK(ff.total > 0);
        sph_neighbors_free(&ff);
        sph_grid_free(&g);
        free(xs);
        free(bxs);
        free(xq);
    }
    return bad;
}

/* The half search's lists on 1, 2 and 3 threads in turn (the unfolding runs in a part per
   thread; 3 parts on 2 processors too): a 2D dam break under way searched every step (IISPH) and
   with a skin (WCSPH, the candidates), a 3D box (DFSPH). Periodic grids are searched whole
   (their lists are checked by lists_exact_periodic). */
static void test_half_lists(void) {
    int t, c;
    for (c = 0; c < 3; ++c) {
        sph_world w;
        if (c < 2) {
            sph_world_def def = sph_world_def_default(2);
            def.solver = c ? SPH_SOLVER_WCSPH : SPH_SOLVER_IISPH;
            def.neighbor_skin = c ? (sph_real)0.2 : 0;
            def.domain_hi[0] = (sph_real)2.5;
            def.domain_hi[1] = (sph_real)1.5;
            CHECK(scene_dam_break(&w, def, 0.5, 40, NULL) == SPH_OK);
            CHECK_EQ_INT(sph_advance(&w, (sph_real)0.05), SPH_OK); /* under way */
        } else {
            sph_world_def def = sph_world_def_default(3);
            sph_real lo[3] = {0, 0, 0}, hi[3] = {(sph_real)0.3, (sph_real)0.3, (sph_real)0.3};
            sph_real box[3] = {(sph_real)0.6, (sph_real)0.5, (sph_real)0.4};
            sph_phase water;
            def.solver = SPH_SOLVER_DFSPH;
            def.spacing = (sph_real)0.02; /* 3375 particles: parts above 2048 */
            memset(&water, 0, sizeof water);
            water.rest_density = 1000;
            CHECK_EQ_INT(sph_world_init(&w, &def), SPH_OK);
            CHECK_EQ_INT(sph_fill_box(&w, sph_world_add_phase(&w, &water), lo, hi), SPH_OK);
            CHECK_EQ_INT(sph_add_wall_box(&w, lo, box, 0, 0), SPH_OK);
            CHECK_EQ_INT(sph_set_hydrostatic(&w), SPH_OK);
        }
        for (t = 1; t <= 3; ++t) {
#ifdef _OPENMP
            omp_set_num_threads(t);
#else
            if (t > 1) break;
#endif
            CHECK_EQ_INT(fluid_lists_check(&w, c == 1 ? 8 : 2), 0);
        }
#ifdef _OPENMP
        omp_set_num_threads(omp_get_num_procs());
#endif
        TH_NOTE("%dD %s: %zu particles, %zu pairs", w.dim, c == 1 ? "skin 0.2 R" : "no skin", w.n,
                c == 1 ? w.priv.cff.total : w.priv.ff.total);
        sph_world_free(&w);
    }
}

/* The default (-1, automatic): WCSPH keeps its lists over several steps; DFSPH, whose steps
   move particles up to 0.4 dx, searches every step. */
static void test_automatic_default(void) {
    int t;
    for (t = 0; t < 2; ++t) {
        sph_world w;
        sph_world_def def = sph_world_def_default(2);
        CHECK(def.neighbor_skin == -1);
        def.solver = t ? SPH_SOLVER_DFSPH : SPH_SOLVER_WCSPH;
        def.domain_hi[0] = (sph_real)2.5;
        def.domain_hi[1] = (sph_real)1.5;
        CHECK(scene_dam_break(&w, def, 0.5, 10, NULL) == SPH_OK);
        CHECK_EQ_INT(sph_advance(&w, (sph_real)0.1), SPH_OK);
        if (t) CHECK_EQ_INT(w.stats.neighbor_builds, w.steps);
        else CHECK(w.stats.neighbor_builds * 4 < w.steps);
        TH_NOTE("%s, defaults: %d steps, %d searches", t ? "DFSPH" : "WCSPH", (int)w.steps,
                (int)w.stats.neighbor_builds);
        sph_world_free(&w);
    }
}

/* ---- threads and bad input ------------------------------------------------------------------ */

static void test_threads(void) {
#ifndef _OPENMP
    TH_SKIP("built without OpenMP");
#else
    sph_world a, b;
    omp_set_num_threads(1);
    CHECK(build_dam(&a, 16, 0.2));
    CHECK_EQ_INT(sph_advance(&a, (sph_real)0.1), SPH_OK);
    omp_set_num_threads(2);
    CHECK(build_dam(&b, 16, 0.2));
    CHECK_EQ_INT(sph_advance(&b, (sph_real)0.1), SPH_OK);
    CHECK_EQ_INT(a.n, b.n);
    CHECK_EQ_INT(a.stats.neighbor_builds, b.stats.neighbor_builds);
    CHECK(memcmp(a.x, b.x, a.n * 2 * sizeof(sph_real)) == 0);
    CHECK(memcmp(a.v, b.v, a.n * 2 * sizeof(sph_real)) == 0);
    CHECK(memcmp(a.rho, b.rho, a.n * sizeof(sph_real)) == 0);
    CHECK(memcmp(a.id, b.id, a.n * sizeof(uint32_t)) == 0);
    sph_world_free(&a);
    sph_world_free(&b);
    omp_set_num_threads(omp_get_num_procs());
#endif
}

static void test_bad_skin(void) {
    sph_world w;
    sph_world_def def = sph_world_def_default(2);
    const double bad[4] = {-0.1, -2, 1.5, NAN};
    int k;
    for (k = 0; k < 4; ++k) {
        def.neighbor_skin = (sph_real)bad[k];
        CHECK_EQ_INT(sph_world_init(&w, &def), SPH_ERR_ARG);
        CHECK(strstr(sph_world_error(&w), "neighbor_skin") != NULL);
        sph_world_free(&w);
    }
    CHECK(build_dam(&w, 8, 0.2));
    CHECK_EQ_INT(sph_step(&w, sph_stable_dt(&w, w.def.solver)), SPH_OK);
    {
        const uint64_t steps = w.steps, builds = w.stats.neighbor_builds;
        const double t = w.time;
        w.def.neighbor_skin = (sph_real)-0.5;
        CHECK_EQ_INT(sph_step(&w, (sph_real)1e-4), SPH_ERR_ARG);
        CHECK(strstr(sph_world_error(&w), "neighbor_skin") != NULL);
        CHECK(w.steps == steps && w.time == t && w.stats.neighbor_builds == builds);
    }
    sph_world_free(&w);
}

const th_test tests_verlet[] = {
    {"verlet/lists_exact", test_lists_exact},
    {"verlet/lists_exact_periodic", test_lists_exact_periodic},
    {"verlet/rebuild_triggers", test_rebuild_triggers},
    {"verlet/rebuild_after_rollback", test_rebuild_after_rollback},
    {"verlet/same_physics", test_same_physics},
    {"verlet/moving_walls", test_moving_walls},
    {"verlet/wall_lists_mirrored", test_wall_lists_mirrored},
    {"verlet/half_lists_match_search", test_half_lists},
    {"verlet/automatic_default", test_automatic_default},
    {"verlet/threads_bitwise", test_threads},
    {"verlet/bad_skin", test_bad_skin},
    {0, 0},
};
