/* tests/test_grid.c - cell grid and neighbour lists against an O(n^2) brute force.

   The brute force (tg_bf_*) is written here from the documented contract: a point j is a
   neighbour of p iff |d| < radius, where d = p - x_j with the minimum-image convention
   d - L * floor(d / L + 1/2) along periodic directions (L = hi - lo). It evaluates that in
   sph_real with the same operation order as the definition, so an exact set comparison is
   meaningful in both the double and the float build: the sets must be identical, index for
   index, with no duplicates. */
#include "harness.h"
#include "../sph.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef SPH_FLOAT
#define TG_EPS 1.1920928955078125e-07
#define TG_NEXTAFTER nextafterf
/* far coordinate beyond the cell clamp (2^20 cells) at which 0.3 cell is still resolved */
#define TG_FAR 2097152.0
#else
#define TG_EPS 2.220446049250313e-16
#define TG_NEXTAFTER nextafter
#define TG_FAR 5e12
#endif

/* splitmix64: a small deterministic generator (no rand(), identical on every platform) */
static uint64_t tg_next(uint64_t* s) {
    uint64_t z = (*s += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}
static double tg_unif(uint64_t* s) {
    return (double)(tg_next(s) >> 11) * (1.0 / 9007199254740992.0);
}

/* ---------------------------------------------------------------------------------------------- */
/* brute force                                                                                    */
/* ---------------------------------------------------------------------------------------------- */
typedef struct tg_bf {
    int dim;
    int periodic[3];
    sph_real len[3];
} tg_bf;

static tg_bf tg_bf_make(int dim, const int* periodic, const sph_real* lo, const sph_real* hi) {
    tg_bf b;
    int k;
    memset(&b, 0, sizeof(b));
    b.dim = dim;
    for (k = 0; k < dim; ++k) {
        b.periodic[k] = periodic && periodic[k];
        if (b.periodic[k]) b.len[k] = hi[k] - lo[k];
    }
    return b;
}

static sph_real tg_bf_r2(const tg_bf* b, const sph_real* p, const sph_real* q) {
    sph_real r2 = 0;
    int k;
    for (k = 0; k < b->dim; ++k) {
        sph_real d = p[k] - q[k];
        if (b->periodic[k]) {
            sph_real f = (sph_real)floor((double)(d / b->len[k] + (sph_real)0.5));
            d = d - b->len[k] * f;
        }
        r2 += d * d;
    }
    return r2;
}

/* Sorted indices j (skipping self if self != (size_t)-1) with |p - x_j| < radius. */
static size_t tg_bf_query(const tg_bf* b, const sph_real* x, size_t n, const sph_real* p,
                          sph_real radius, size_t self, uint32_t* out) {
    const sph_real r2max = radius * radius;
    size_t j, m = 0;
    for (j = 0; j < n; ++j)
        if (j != self && tg_bf_r2(b, p, x + j * (size_t)b->dim) < r2max) out[m++] = (uint32_t)j;
    return m;
}

static int tg_cmp_u32(const void* a, const void* b) {
    uint32_t x = *(const uint32_t*)a, y = *(const uint32_t*)b;
    return x < y ? -1 : x > y;
}

/* Sorts got[0..m) in place; 1 if it then equals ref[0..mref) (sorted ascending). */
static int tg_same_set(uint32_t* got, size_t m, const uint32_t* ref, size_t mref) {
    size_t i;
    qsort(got, m, sizeof(uint32_t), tg_cmp_u32);
    if (m != mref) return 0;
    for (i = 0; i < m; ++i)
        if (got[i] != ref[i]) return 0;
    return 1;
}

/* Every query point q_i: sph_grid_query equals the brute force. Returns the number of queries
   that differ (a failing query is reported once, the first few in full). Duplicated indices
   in the result make the sorted comparison fail, so "found exactly once" is part of it. */
static size_t tg_check_queries(const char* what, const sph_grid* g, const tg_bf* b,
                               const sph_real* x, size_t n, const sph_real* q, size_t nq,
                               sph_real radius, size_t* found_total) {
    uint32_t* got = (uint32_t*)malloc((n + 1) * sizeof(uint32_t));
    uint32_t* ref = (uint32_t*)malloc((n + 1) * sizeof(uint32_t));
    size_t i, bad = 0, tot = 0;
    if (!got || !ref) {
        CHECK_MSG(0, "out of memory");
        free(got);
        free(ref);
        return 1;
    }
    for (i = 0; i < nq; ++i) {
        const sph_real* p = q + i * (size_t)b->dim;
        size_t m = sph_grid_query(g, x, p, radius, got, n + 1);
        size_t mref = tg_bf_query(b, x, n, p, radius, (size_t)-1, ref);
        tot += mref;
        if (m > n + 1 || !tg_same_set(got, m, ref, mref)) {
            if (bad < 3)
                CHECK_MSG(0, "%s: query %lu at (%.17g, %.17g, %.17g) radius %g: found %lu, "
                             "brute force %lu",
                          what, (unsigned long)i, (double)p[0],
                          (double)(b->dim > 1 ? p[1] : 0), (double)(b->dim > 2 ? p[2] : 0),
                          (double)radius, (unsigned long)m, (unsigned long)mref);
            ++bad;
        }
    }
    if (bad) CHECK_MSG(0, "%s: %lu of %lu queries differ from the brute force", what,
                       (unsigned long)bad, (unsigned long)nq);
    if (found_total) *found_total += tot;
    free(got);
    free(ref);
    return bad;
}

/* uniform random points in [lo, hi)^dim */
static sph_real* tg_random_points(uint64_t* seed, size_t n, int dim, double lo, double hi) {
    sph_real* x = (sph_real*)malloc((n ? n : 1) * (size_t)dim * sizeof(sph_real));
    size_t i;
    if (!x) return NULL;
    for (i = 0; i < n * (size_t)dim; ++i) x[i] = (sph_real)(lo + (hi - lo) * tg_unif(seed));
    return x;
}

/* Cell size giving about `nb` neighbours at uniform density n / side^dim. */
static double tg_cell_for(int dim, size_t n, double side, double nb) {
    double rho = (double)n / pow(side, dim);
    double unit = dim == 1 ? 2.0 : dim == 2 ? 3.141592653589793 : 4.18879020478639;
    return pow(nb / (rho * unit), 1.0 / dim);
}

/* ---------------------------------------------------------------------------------------------- */
/* tests                                                                                          */
/* ---------------------------------------------------------------------------------------------- */

/* Non-periodic random points, dims 1-3, box [-0.4, 0.8)^d (negative cell indices too), queries
   at every point and at 400 random points of the larger box [-0.6, 1.0)^d (some outside the
   point cloud), radius = cell, 0.6 cell and 0.23 cell (radius smaller than the cell). A compact
   cloud uses the dense table (hashed == 0). Also: the return value with a small cap is the full
   count and nothing past cap is written. */
static void test_query_random_open(void) {
    uint64_t seed = 1;
    int dim;
    for (dim = 1; dim <= 3; ++dim) {
        const size_t n = dim == 1 ? 1500 : dim == 2 ? 2500 : 3000, nextra = 400;
        const double cell = tg_cell_for(dim, n, 1.2, 30);
        static const double rfac[3] = {1.0, 0.6, 0.23};
        sph_real* x = tg_random_points(&seed, n, dim, -0.4, 0.8);
        sph_real* q = (sph_real*)malloc((n + nextra) * (size_t)dim * sizeof(sph_real));
        sph_grid g;
        tg_bf b = tg_bf_make(dim, NULL, NULL, NULL);
        size_t i, total = 0;
        int ir;
        if (!x || !q) { CHECK_MSG(0, "out of memory"); free(x); free(q); return; }
        memcpy(q, x, n * (size_t)dim * sizeof(sph_real));
        for (i = n * (size_t)dim; i < (n + nextra) * (size_t)dim; ++i)
            q[i] = (sph_real)(-0.6 + 1.6 * tg_unif(&seed));
        CHECK_EQ_INT(sph_grid_init(&g, dim, (sph_real)cell, NULL, NULL, NULL), SPH_OK);
        CHECK_EQ_INT(sph_grid_build(&g, x, n), SPH_OK);
        CHECK_EQ_INT(g.n, n);
        CHECK_EQ_INT(g.hashed, 0);
        for (ir = 0; ir < 3; ++ir)
            tg_check_queries("open", &g, &b, x, n, q, n + nextra, (sph_real)(rfac[ir] * cell),
                             &total);
        TH_NOTE("dim %d: n %lu, cell %.4f, %.1f neighbours per query on average", dim,
                (unsigned long)n, cell, (double)total / (3.0 * (double)(n + nextra)));
        /* cap: returns the full count, writes only out[0..cap) */
        {
            uint32_t out[8], ref[64];
            size_t m, full = 0, k;
            for (i = 0; i < n && full < 5; ++i) {
                full = sph_grid_query(&g, x, x + i * (size_t)dim, (sph_real)cell, ref, 64);
                if (full > 64) full = 0;
            }
            CHECK(full >= 5);
            for (k = 0; k < 8; ++k) out[k] = 0xdeadbeefu;
            --i;
            m = sph_grid_query(&g, x, x + i * (size_t)dim, (sph_real)cell, out, 2);
            CHECK_EQ_INT(m, full);
            for (k = 2; k < 8; ++k) CHECK(out[k] == 0xdeadbeefu);
            for (k = 0; k < 2; ++k) {
                size_t l;
                int in = 0;
                for (l = 0; l < full; ++l) in |= ref[l] == out[k];
                CHECK(in);
            }
            CHECK_EQ_INT(sph_grid_query(&g, x, x + i * (size_t)dim, (sph_real)cell, NULL, 0),
                         full);
        }
        sph_grid_free(&g);
        free(x);
        free(q);
    }
}

/* One periodic configuration: n random points in the box (plus points on and slightly outside
   its faces), queried at every point and at 200 of them (the face points included) shifted by
   -1 and +2 box lengths along the periodic directions, radius = cell and 0.7 cell. */
static void tg_periodic_case(const char* what, uint64_t* seed, int dim, const int* per,
                             const double* lo, const double* hi, double cell, size_t n) {
    const size_t nspecial = 6;
    const size_t ntot = n + nspecial;
    const size_t nimg = ntot < 200 ? ntot : 200;
    sph_real slo[3] = {0, 0, 0}, shi[3] = {0, 0, 0};
    sph_real* x = (sph_real*)malloc(ntot * (size_t)dim * sizeof(sph_real));
    sph_real* q = (sph_real*)malloc((ntot + 2 * nimg) * (size_t)dim * sizeof(sph_real));
    sph_grid g;
    tg_bf b;
    size_t i;
    int k;
    if (!x || !q) { CHECK_MSG(0, "out of memory"); free(x); free(q); return; }
    for (k = 0; k < dim; ++k) {
        slo[k] = (sph_real)lo[k];
        shi[k] = (sph_real)hi[k];
    }
    for (i = 0; i < n; ++i)
        for (k = 0; k < dim; ++k)
            x[i * (size_t)dim + (size_t)k] =
                (sph_real)(lo[k] + (hi[k] - lo[k]) * tg_unif(seed));
    /* on the faces and just outside: lo, hi (outside the half-open box), hi + 1e-9, lo - 1e-9,
       and the lo-1e-9 / hi+1e-9 pair seen across the periodic seam */
    for (i = n; i < ntot; ++i) {
        for (k = 0; k < dim; ++k) {
            double v = lo[k] + (hi[k] - lo[k]) * tg_unif(seed);
            if (per[k] || k == 0) {
                switch (i - n) {
                case 0: v = lo[k]; break;
                case 1: v = hi[k]; break;
                case 2: v = hi[k] + 1e-9; break;
                case 3: v = lo[k] - 1e-9; break;
                case 4: v = hi[k] - 1e-9; break;
                default: v = lo[k] + 1e-9; break;
                }
            }
            x[i * (size_t)dim + (size_t)k] = (sph_real)v;
        }
    }
    /* queries: the points, then the images of the last nimg points (the special ones and some
       random ones) shifted by -1 and +2 box lengths along the periodic directions */
    for (i = 0; i < ntot; ++i)
        for (k = 0; k < dim; ++k) q[i * (size_t)dim + (size_t)k] = x[i * (size_t)dim + (size_t)k];
    for (i = 0; i < nimg; ++i) {
        for (k = 0; k < dim; ++k) {
            double v = (double)x[(ntot - nimg + i) * (size_t)dim + (size_t)k], L = hi[k] - lo[k];
            q[(ntot + i) * (size_t)dim + (size_t)k] = (sph_real)(per[k] ? v - L : v);
            q[(ntot + nimg + i) * (size_t)dim + (size_t)k] = (sph_real)(per[k] ? v + 2 * L : v);
        }
    }
    b = tg_bf_make(dim, per, slo, shi);
    CHECK_EQ_INT(sph_grid_init(&g, dim, (sph_real)cell, per, slo, shi), SPH_OK);
    CHECK_EQ_INT(sph_grid_build(&g, x, ntot), SPH_OK);
    tg_check_queries(what, &g, &b, x, ntot, q, ntot + 2 * nimg, (sph_real)cell, NULL);
    tg_check_queries(what, &g, &b, x, ntot, q, ntot + 2 * nimg, (sph_real)(0.7 * cell), NULL);
    sph_grid_free(&g);
    free(x);
    free(q);
}

/* Periodic in every direction, box [0, 1)^d, with cells of 0.5 and 0.4 (the box is 2 and 2.5
   cells long: two cells, so the stencil must visit each of them exactly once), 0.3 (three cells)
   and 0.12 (eight cells); a box with a negative origin [-0.3, 0.9) of 2.4 cells. */
static void test_query_periodic_all(void) {
    static const double cells[] = {0.5, 0.4, 0.3, 0.12};
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    const double lo2[3] = {-0.3, -0.3, -0.3}, hi2[3] = {0.9, 0.9, 0.9};
    const int per[3] = {1, 1, 1};
    uint64_t seed = 2;
    int dim;
    size_t c;
    for (dim = 1; dim <= 3; ++dim) {
        for (c = 0; c < sizeof(cells) / sizeof(cells[0]); ++c) {
            /* fewer points when every point neighbours most others */
            size_t n = dim == 3 && cells[c] < 0.2 ? 1500 : 400;
            tg_periodic_case("periodic all", &seed, dim, per, lo, hi, cells[c], n);
        }
        tg_periodic_case("periodic all, negative origin", &seed, dim, per, lo2, hi2, 0.5, 500);
    }
}

/* Mixed: 2D periodic in x only (x in [0, 1) with 2 cells and with 10 cells, y free in [0, 2]),
   3D periodic in x and z (y free), and 2D periodic in y only. */
static void test_query_periodic_mixed(void) {
    uint64_t seed = 3;
    {
        const int per[3] = {1, 0, 0};
        const double lo[3] = {0, 0, 0}, hi[3] = {1, 2, 0};
        tg_periodic_case("periodic x", &seed, 2, per, lo, hi, 0.4, 800);
        tg_periodic_case("periodic x", &seed, 2, per, lo, hi, 0.1, 1500);
    }
    {
        const int per[3] = {0, 1, 0};
        const double lo[3] = {0, -1, 0}, hi[3] = {3, 0.25, 0};
        tg_periodic_case("periodic y", &seed, 2, per, lo, hi, 0.6, 800);
    }
    {
        const int per[3] = {1, 0, 1};
        const double lo[3] = {0, 0, 0.5}, hi[3] = {1, 1.5, 1.5};
        tg_periodic_case("periodic xz", &seed, 3, per, lo, hi, 0.45, 1000);
        tg_periodic_case("periodic xz", &seed, 3, per, lo, hi, 0.15, 1500);
    }
}

/* A dense cluster plus points very far away (1e9 and -1e12 in every coordinate, and a point at
   0.3 cell from the 1e9 one; in float 1e9 + 0.3 cell rounds to 1e9, a coincident pair, still a
   neighbour): the results stay exact, the grid switches to the hash table
   (hashed == 1) and does not allocate a table proportional to the bounding box
   (nbucket <= 4 n + 1024). Rebuilding the same grid without the far points goes back to the
   dense table, and with them again to the hash table, exact each time (memory reuse). */
static void test_far_point(void) {
    uint64_t seed = 4;
    int dim;
    for (dim = 1; dim <= 3; ++dim) {
        const size_t nc = 2000, n = nc + 3;
        const double cell = tg_cell_for(dim, nc, 1.0, 20);
        sph_real* x = tg_random_points(&seed, n, dim, 0.0, 1.0);
        sph_grid g;
        tg_bf b = tg_bf_make(dim, NULL, NULL, NULL);
        int k, round;
        if (!x) { CHECK_MSG(0, "out of memory"); return; }
        for (k = 0; k < dim; ++k) {
            x[nc * (size_t)dim + (size_t)k] = (sph_real)1e9;
            x[(nc + 1) * (size_t)dim + (size_t)k] = (sph_real)-1e12;
            x[(nc + 2) * (size_t)dim + (size_t)k] = (sph_real)1e9;
        }
        x[(nc + 2) * (size_t)dim] = (sph_real)(1e9 + 0.3 * cell);
        CHECK_EQ_INT(sph_grid_init(&g, dim, (sph_real)cell, NULL, NULL, NULL), SPH_OK);
        for (round = 0; round < 3; ++round) {
            size_t nb = round == 1 ? nc : n;
            CHECK_EQ_INT(sph_grid_build(&g, x, nb), SPH_OK);
            CHECK_EQ_INT(g.hashed, round == 1 ? 0 : 1);
            CHECK_LE(g.nbucket, 4 * nb + 1024);
            tg_check_queries("far point", &g, &b, x, nb, x, nb, (sph_real)cell, NULL);
            if (round == 0) {
                uint32_t out[8];
                size_t m = sph_grid_query(&g, x, x + nc * (size_t)dim, (sph_real)cell, out, 8);
                CHECK_EQ_INT(m, 2); /* the 1e9 point and its partner 0.3 cell away */
                TH_NOTE("dim %d: n %lu with far points -> hashed %d, nbucket %lu", dim,
                        (unsigned long)n, g.hashed, (unsigned long)g.nbucket);
            }
        }
        sph_grid_free(&g);
        free(x);
    }
}

/* Cell coordinates are clamped to [-2^20, 2^20) cells: points beyond share the edge cells. They
   must still find their true neighbours and only those: +-1e30 (a coincident pair at 1e30),
   pairs at TG_FAR and TG_FAR + 0.3 cell (5e12 in double; 2^21 in float where 5e12 + 0.3 cell
   would round to 5e12), the same at -TG_FAR and in the second coordinate, a pair straddling the
   clamp boundary 2^20 cells (one clamped, one not) and its negative, and 40 points 10 cells
   apart beyond the clamp (one crowded cell, no false neighbours), next to a small cluster. */
static void test_clamped(void) {
    uint64_t seed = 5;
    const double c = 0.5, B = 1048576.0 * c;
    int dim;
    for (dim = 1; dim <= 3; ++dim) {
        const size_t ncl = 200, nfar = 40;
        const size_t n = ncl + 14 + nfar;
        sph_real* x = (sph_real*)calloc(n * (size_t)dim, sizeof(sph_real));
        sph_grid g;
        tg_bf b = tg_bf_make(dim, NULL, NULL, NULL);
        size_t i, p = ncl;
        uint32_t out[64];
        double first[14];
        if (!x) { CHECK_MSG(0, "out of memory"); return; }
        for (i = 0; i < ncl * (size_t)dim; ++i) x[i] = (sph_real)(2 * tg_unif(&seed));
        /* first coordinates; pairs (0,1) (2,3) ... (10,11) are neighbours, 12 and 13 are not
           (13 shares the clamped edge cell with 7 but lies 4.9 cells from it) */
        first[0] = 1e30;
        first[1] = 1e30;
        first[2] = TG_FAR;
        first[3] = TG_FAR + 0.3 * c;
        first[4] = -TG_FAR;
        first[5] = -TG_FAR - 0.3 * c;
        first[6] = B - 0.1 * c;
        first[7] = B + 0.1 * c;
        first[8] = -B + 0.1 * c;
        first[9] = -B - 0.1 * c;
        first[10] = 0.1; /* with the second coordinate at TG_FAR and TG_FAR + 0.3 cell */
        first[11] = 0.1 + 0.2 * c;
        first[12] = -1e30;
        first[13] = B + 5 * c;
        for (i = 0; i < 14; ++i, ++p) {
            int k;
            for (k = 0; k < dim; ++k)
                x[p * (size_t)dim + (size_t)k] = (sph_real)(k == 0 ? first[i] : 0.5);
            if ((i == 10 || i == 11) && dim > 1)
                x[p * (size_t)dim + 1] = (sph_real)(i == 10 ? TG_FAR : TG_FAR + 0.3 * c);
        }
        for (i = 0; i < nfar; ++i, ++p) {
            int k;
            for (k = 0; k < dim; ++k)
                x[p * (size_t)dim + (size_t)k] =
                    (sph_real)(k == 0 ? TG_FAR + 10 * c * (double)(i + 1) : -3.0);
        }
        CHECK_EQ_INT(sph_grid_init(&g, dim, (sph_real)c, NULL, NULL, NULL), SPH_OK);
        CHECK_EQ_INT(sph_grid_build(&g, x, n), SPH_OK);
        CHECK_EQ_INT(g.hashed, 1);
        tg_check_queries("clamped", &g, &b, x, n, x, n, (sph_real)c, NULL);
        /* the explicit pairs find each other; all but the 1e30 pair are distinct points */
        for (i = 0; i < 12; i += 2) {
            const sph_real* a = x + (ncl + i) * (size_t)dim;
            const sph_real* a2 = a + dim;
            size_t m = sph_grid_query(&g, x, a, (sph_real)c, out, 64), l;
            int found = 0;
            if (i > 0) CHECK(tg_bf_r2(&b, a, a2) > 0);
            CHECK(tg_bf_r2(&b, a, a2) < (sph_real)(c * c));
            for (l = 0; l < m && l < 64; ++l) found |= out[l] == (uint32_t)(ncl + i + 1);
            CHECK_MSG(found, "dim %d: pair %lu at %.17g not found", dim, (unsigned long)i,
                      first[i]);
        }
        CHECK(tg_bf_r2(&b, x + (ncl + 7) * (size_t)dim, x + (ncl + 13) * (size_t)dim) >
              (sph_real)(c * c));
        sph_grid_free(&g);
        free(x);
    }
}

/* Verifies neighbour lists nl (built over grid points x[0..n) for queries q[0..nq)) against the
   brute force: each list as a set, self excluded iff exclude_self, total = sum of counts, lists
   inside idx and pairwise disjoint; with exclude_self also symmetric among the queries (j in
   list(i) iff i in list(j)). */
static void tg_check_lists(const char* what, const sph_neighbors* nl, const tg_bf* b,
                           const sph_real* x, size_t n, const sph_real* q, size_t nq,
                           sph_real radius, int exclude_self) {
    uint32_t* got = (uint32_t*)malloc((n + 1) * sizeof(uint32_t));
    uint32_t* ref = (uint32_t*)malloc((n + 1) * sizeof(uint32_t));
    size_t i, bad = 0, sum = 0, asym = 0, overlap = 0, outside = 0;
    if (!got || !ref) {
        CHECK_MSG(0, "out of memory");
        free(got);
        free(ref);
        return;
    }
    CHECK_EQ_INT(nl->n, nq);
    for (i = 0; i < nq; ++i) {
        size_t m = nl->count[i];
        size_t mref = tg_bf_query(b, x, n, q + i * (size_t)b->dim, radius,
                                  exclude_self ? i : (size_t)-1, ref);
        sum += m;
        if (nl->begin[i] + m > nl->cap_idx) { ++outside; continue; }
        if (m > n) { ++bad; continue; }
        memcpy(got, nl->idx + nl->begin[i], m * sizeof(uint32_t));
        if (!tg_same_set(got, m, ref, mref)) {
            if (bad < 3)
                CHECK_MSG(0, "%s: list %lu has %lu entries, brute force %lu", what,
                          (unsigned long)i, (unsigned long)m, (unsigned long)mref);
            ++bad;
        }
        if (exclude_self) {
            size_t l;
            for (l = 0; l < m; ++l) {
                size_t j = nl->idx[nl->begin[i] + l], t;
                int back = 0;
                if (j >= nq) continue; /* not a query (the first nq points): no list */
                if (nl->begin[j] + nl->count[j] > nl->cap_idx) {
                    ++asym;
                    break;
                }
                for (t = 0; t < nl->count[j]; ++t) back |= nl->idx[nl->begin[j] + t] == i;
                if (!back) ++asym;
            }
        }
    }
    /* list regions are disjoint: mark every idx slot a list uses; a slot used twice overlaps */
    {
        unsigned char* used = (unsigned char*)calloc(nl->cap_idx + 1, 1);
        if (used) {
            for (i = 0; i < nq; ++i) {
                size_t l;
                if (nl->begin[i] + nl->count[i] > nl->cap_idx) continue; /* counted above */
                for (l = nl->begin[i]; l < nl->begin[i] + nl->count[i]; ++l) {
                    overlap += used[l];
                    used[l] = 1;
                }
            }
        }
        free(used);
    }
    CHECK_MSG(bad == 0, "%s: %lu of %lu lists differ from the brute force", what,
              (unsigned long)bad, (unsigned long)nq);
    CHECK_MSG(outside == 0, "%s: %lu lists reach past idx", what, (unsigned long)outside);
    CHECK_MSG(overlap == 0, "%s: %lu list regions overlap", what, (unsigned long)overlap);
    CHECK_MSG(asym == 0, "%s: %lu asymmetric entries", what, (unsigned long)asym);
    CHECK_EQ_INT(nl->total, sum);
    free(got);
    free(ref);
}

/* sph_neighbors_build against the brute force, reusing one sph_neighbors throughout:
   2D n = 3000 (12 chunks of 256 query points), exclude_self = 1; then the same points
   compressed into a box 0.4 times smaller (6x more neighbours: every chunk overflows its
   capacity from the first build and must grow); then a rebuild with only 700 points (fewer
   chunks than allocated); 3D; periodic with 2 cells; exclude_self = 0 with a different query
   set (boundary-like points on a line below the cloud and random points) and with the grid's
   own points (each list contains its own index); determinism of a repeated build; nq = 0;
   bad radius. */
static void test_neighbors_build(void) {
    uint64_t seed = 6;
    sph_neighbors nl;
    sph_grid g;
    const size_t n = 3000;
    const double cell = 0.035;
    sph_real* x = tg_random_points(&seed, n, 2, 0.0, 1.0);
    sph_real* xq = NULL;
    tg_bf b2 = tg_bf_make(2, NULL, NULL, NULL);
    size_t i, total0;
    memset(&nl, 0, sizeof(nl));
    if (!x) { CHECK_MSG(0, "out of memory"); return; }
    CHECK_EQ_INT(sph_grid_init(&g, 2, (sph_real)cell, NULL, NULL, NULL), SPH_OK);
    CHECK_EQ_INT(sph_grid_build(&g, x, n), SPH_OK);
    CHECK_EQ_INT(sph_neighbors_build(&nl, &g, x, x, n, (sph_real)cell, 1), SPH_OK);
    tg_check_lists("2D self", &nl, &b2, x, n, x, n, (sph_real)cell, 1);
    total0 = nl.total;
    /* determinism: the same build again gives the same lists in the same order */
    {
        size_t o = 0, diff = 0, sum = 0;
        size_t* begin = (size_t*)malloc(n * sizeof(size_t));
        uint32_t* flat;
        for (i = 0; i < n; ++i) sum += nl.count[i];
        flat = (uint32_t*)malloc((sum + 1) * sizeof(uint32_t));
        if (begin && flat) {
            for (i = 0; i < n; ++i) {
                memcpy(flat + o, nl.idx + nl.begin[i], nl.count[i] * sizeof(uint32_t));
                o += nl.count[i];
                begin[i] = nl.begin[i];
            }
            CHECK_EQ_INT(sph_neighbors_build(&nl, &g, x, x, n, (sph_real)cell, 1), SPH_OK);
            o = 0;
            for (i = 0; i < n; ++i) {
                if (o + nl.count[i] > sum) { /* the counts changed: stop before flat's end */
                    ++diff;
                    break;
                }
                if (nl.begin[i] != begin[i] ||
                    memcmp(flat + o, nl.idx + nl.begin[i], nl.count[i] * sizeof(uint32_t)))
                    ++diff;
                o += nl.count[i];
            }
            CHECK_EQ_INT(diff, 0);
            CHECK_EQ_INT(nl.total, total0);
        }
        free(begin);
        free(flat);
    }
    /* compress: counts grow beyond every chunk's capacity */
    for (i = 0; i < 2 * n; ++i) x[i] = (sph_real)(0.3 + 0.4 * (double)x[i]);
    CHECK_EQ_INT(sph_grid_build(&g, x, n), SPH_OK);
    CHECK_EQ_INT(sph_neighbors_build(&nl, &g, x, x, n, (sph_real)cell, 1), SPH_OK);
    tg_check_lists("2D compressed", &nl, &b2, x, n, x, n, (sph_real)cell, 1);
    TH_NOTE("2D n %lu: %.1f neighbours per point, %.1f after compression", (unsigned long)n,
            (double)total0 / (double)n, (double)nl.total / (double)n);
    CHECK_LT(5 * total0, nl.total);
    /* the first 500 of the grid's own points as queries, not in cell order */
    CHECK_EQ_INT(sph_neighbors_build(&nl, &g, x, x, 500, (sph_real)cell, 1), SPH_OK);
    tg_check_lists("2D first 500", &nl, &b2, x, n, x, 500, (sph_real)cell, 1);
    CHECK_EQ_INT(sph_neighbors_build(&nl, &g, x, x, 500, (sph_real)cell, 0), SPH_OK);
    tg_check_lists("2D first 500, self included", &nl, &b2, x, n, x, 500, (sph_real)cell, 0);
    /* fewer points */
    CHECK_EQ_INT(sph_grid_build(&g, x, 700), SPH_OK);
    CHECK_EQ_INT(sph_neighbors_build(&nl, &g, x, x, 700, (sph_real)cell, 1), SPH_OK);
    tg_check_lists("2D 700", &nl, &b2, x, 700, x, 700, (sph_real)cell, 1);
    /* exclude_self = 0: a different query set, 300 points on the line y = 0.29 (just below the
       compressed cloud, x spanning it) and 300 random points in and around the cloud */
    xq = (sph_real*)malloc(600 * 2 * sizeof(sph_real));
    if (xq) {
        for (i = 0; i < 300; ++i) {
            xq[2 * i] = (sph_real)(0.25 + 0.5 * (double)i / 299);
            xq[2 * i + 1] = (sph_real)0.29;
        }
        for (i = 300; i < 600; ++i) {
            xq[2 * i] = (sph_real)(0.2 + 0.6 * tg_unif(&seed));
            xq[2 * i + 1] = (sph_real)(0.2 + 0.6 * tg_unif(&seed));
        }
        CHECK_EQ_INT(sph_grid_build(&g, x, n), SPH_OK);
        CHECK_EQ_INT(sph_neighbors_build(&nl, &g, x, xq, 600, (sph_real)cell, 0), SPH_OK);
        tg_check_lists("2D boundary queries", &nl, &b2, x, n, xq, 600, (sph_real)cell, 0);
    }
    /* exclude_self = 0 on the grid's own points: every list contains its own index */
    CHECK_EQ_INT(sph_neighbors_build(&nl, &g, x, x, n, (sph_real)cell, 0), SPH_OK);
    tg_check_lists("2D self included", &nl, &b2, x, n, x, n, (sph_real)cell, 0);
    {
        size_t miss = 0;
        for (i = 0; i < n; ++i) {
            uint32_t l;
            int self = 0;
            for (l = 0; l < nl.count[i]; ++l) self |= nl.idx[nl.begin[i] + l] == (uint32_t)i;
            miss += !self;
        }
        CHECK_EQ_INT(miss, 0);
    }
    /* nq = 0 */
    CHECK_EQ_INT(sph_neighbors_build(&nl, &g, x, x, 0, (sph_real)cell, 1), SPH_OK);
    CHECK_EQ_INT(nl.n, 0);
    CHECK_EQ_INT(nl.total, 0);
    /* bad radius: 0, negative, NaN, larger than the cell */
    CHECK_EQ_INT(sph_neighbors_build(&nl, &g, x, x, n, 0, 1), SPH_ERR_ARG);
    CHECK_EQ_INT(sph_neighbors_build(&nl, &g, x, x, n, (sph_real)-cell, 1), SPH_ERR_ARG);
    CHECK_EQ_INT(sph_neighbors_build(&nl, &g, x, x, n, (sph_real)NAN, 1), SPH_ERR_ARG);
    CHECK_EQ_INT(sph_neighbors_build(&nl, &g, x, x, n, (sph_real)(1.01 * cell), 1), SPH_ERR_ARG);
    sph_grid_free(&g);
    free(x);
    free(xq);
    /* 3D, and periodic 2D with two cells per direction, into the same nl */
    {
        const size_t n3 = 2000;
        const double c3 = tg_cell_for(3, n3, 1.0, 25);
        sph_real* x3 = tg_random_points(&seed, n3, 3, 0.0, 1.0);
        tg_bf b3 = tg_bf_make(3, NULL, NULL, NULL);
        if (x3) {
            CHECK_EQ_INT(sph_grid_init(&g, 3, (sph_real)c3, NULL, NULL, NULL), SPH_OK);
            CHECK_EQ_INT(sph_grid_build(&g, x3, n3), SPH_OK);
            CHECK_EQ_INT(sph_neighbors_build(&nl, &g, x3, x3, n3, (sph_real)c3, 1), SPH_OK);
            tg_check_lists("3D self", &nl, &b3, x3, n3, x3, n3, (sph_real)c3, 1);
            CHECK_EQ_INT(sph_neighbors_build(&nl, &g, x3, x3, n3, (sph_real)(0.5 * c3), 1),
                         SPH_OK);
            tg_check_lists("3D half radius", &nl, &b3, x3, n3, x3, n3, (sph_real)(0.5 * c3), 1);
            sph_grid_free(&g);
        }
        free(x3);
    }
    {
        const size_t np = 600;
        const int per[3] = {1, 1, 0};
        const sph_real lo[3] = {0, 0, 0}, hi[3] = {1, 1, 0};
        sph_real* xp = tg_random_points(&seed, np, 2, 0.0, 1.0);
        tg_bf bp = tg_bf_make(2, per, lo, hi);
        if (xp) {
            CHECK_EQ_INT(sph_grid_init(&g, 2, (sph_real)0.4, per, lo, hi), SPH_OK);
            CHECK_EQ_INT(sph_grid_build(&g, xp, np), SPH_OK);
            CHECK_EQ_INT(sph_neighbors_build(&nl, &g, xp, xp, np, (sph_real)0.4, 1), SPH_OK);
            tg_check_lists("2D periodic two cells", &nl, &bp, xp, np, xp, np, (sph_real)0.4, 1);
            sph_grid_free(&g);
        }
        free(xp);
    }
    sph_neighbors_free(&nl);
    CHECK(nl.idx == NULL && nl.total == 0);
    sph_neighbors_free(&nl); /* a second free is harmless */
}

/* Points the host keeps in cell order take sph_neighbors_build's fast path (rows of cells read
   in place, cells beyond the radius skipped, a branch-free distance test); it must list exactly
   what the brute force finds. Random points (2D, 3D) are put into cell order by the grid's own
   permutation, plus pairs at distances just under and just over the radius straddling cell
   faces (the skip test's margin), at the radius and at half the cell (more cells skipped), for
   the points themselves, and for query points in, around and far outside the grid's box; then
   compressed so every chunk overflows its first capacity. */
static void test_neighbors_cell_ordered(void) {
    uint64_t seed = 17;
    int dim;
    for (dim = 2; dim <= 3; ++dim) {
        const size_t nr = dim == 2 ? 2500 : 2000, npair = 200, n = nr + 2 * npair;
        const double cell = tg_cell_for(dim, nr, 1.0, dim == 2 ? 20 : 40);
        sph_real* x0 = tg_random_points(&seed, n, dim, 0.0, 1.0);
        sph_real* x = (sph_real*)malloc(n * (size_t)dim * sizeof(sph_real) + 1);
        sph_real* xq = tg_random_points(&seed, 400, dim, -0.3, 1.3);
        tg_bf b = tg_bf_make(dim, NULL, NULL, NULL);
        sph_grid g;
        sph_neighbors nl;
        size_t i, ordered = 0, self_total = 0;
        int k, pass;
        char what[64];
        memset(&nl, 0, sizeof(nl));
        if (!x0 || !x || !xq) { CHECK_MSG(0, "out of memory"); free(x0); free(x); free(xq); return; }
        /* pairs straddling a cell face (x = 0.5 cell multiples), distance (1 -+ 1e-7) cell */
        for (i = 0; i < npair; ++i) {
            sph_real* a = x0 + (nr + 2 * i) * (size_t)dim;
            sph_real* c = a + dim;
            const double face = cell * (double)(1 + i % (size_t)(0.8 / cell));
            const double dist = cell * (i % 2 ? 1 - 1e-7 : 1 + 1e-7);
            const double off = 0.5 * dist * (double)(i % 5) / 4.0;
            a[0] = (sph_real)(face - off);
            c[0] = (sph_real)(face - off + dist);
            for (k = 1; k < dim; ++k) c[k] = a[k];
        }
        for (i = 0; i < 7; ++i) /* queries far outside the box, and on its faces */
            for (k = 0; k < dim; ++k)
                xq[i * (size_t)dim + (size_t)k] = (sph_real)(i < 3 ? 5.0 * (double)i - 4.0 : i == 3 ? 0 : 1);
        CHECK_EQ_INT(sph_grid_init(&g, dim, (sph_real)cell, NULL, NULL, NULL), SPH_OK);
        for (pass = 0; pass < 2; ++pass) {
            const double scale = pass ? 0.45 : 1.0;
            for (i = 0; i < n * (size_t)dim; ++i) x0[i] = (sph_real)(0.3 + scale * ((double)x0[i] - 0.3));
            CHECK_EQ_INT(sph_grid_build(&g, x0, n), SPH_OK);
            for (i = 0; i < n; ++i) /* into cell order */
                memcpy(x + i * (size_t)dim, x0 + (size_t)g.order[i] * (size_t)dim, (size_t)dim * sizeof(sph_real));
            CHECK_EQ_INT(sph_grid_build(&g, x, n), SPH_OK);
            for (i = 0, ordered = 1; i < n; ++i) ordered &= g.order[i] == (uint32_t)i;
            CHECK_MSG(ordered, "%dD: the sorted points are not in the grid's order", dim);
            snprintf(what, sizeof what, "%dD cell-ordered, radius = cell, pass %d", dim, pass);
            CHECK_EQ_INT(sph_neighbors_build(&nl, &g, x, x, n, (sph_real)cell, 1), SPH_OK);
            tg_check_lists(what, &nl, &b, x, n, x, n, (sph_real)cell, 1);
            self_total = nl.total;
            snprintf(what, sizeof what, "%dD cell-ordered, radius = cell / 2, pass %d", dim, pass);
            CHECK_EQ_INT(sph_neighbors_build(&nl, &g, x, x, n, (sph_real)(0.5 * cell), 1), SPH_OK);
            tg_check_lists(what, &nl, &b, x, n, x, n, (sph_real)(0.5 * cell), 1);
            snprintf(what, sizeof what, "%dD cell-ordered, own points kept, pass %d", dim, pass);
            CHECK_EQ_INT(sph_neighbors_build(&nl, &g, x, x, n, (sph_real)cell, 0), SPH_OK);
            tg_check_lists(what, &nl, &b, x, n, x, n, (sph_real)cell, 0);
            snprintf(what, sizeof what, "%dD cell-ordered, outside queries, pass %d", dim, pass);
            CHECK_EQ_INT(sph_neighbors_build(&nl, &g, x, xq, 400, (sph_real)cell, 0), SPH_OK);
            tg_check_lists(what, &nl, &b, x, n, xq, 400, (sph_real)cell, 0);
        }
        TH_NOTE("%dD: %lu points in cell order, %.1f neighbours each after compression", dim,
                (unsigned long)n, (double)self_total / (double)n);
        sph_neighbors_free(&nl);
        sph_grid_free(&g);
        free(x0);
        free(x);
        free(xq);
    }
}

/* An empty build: queries find nothing and neighbour lists are empty; many coincident points
   (one crowded cell) are all found, each exactly once. */
static void test_empty_and_duplicates(void) {
    sph_grid g;
    sph_neighbors nl;
    sph_real p[2] = {0.5, 0.5}, x[2 * 310];
    uint32_t out[400];
    size_t i;
    tg_bf b = tg_bf_make(2, NULL, NULL, NULL);
    memset(&nl, 0, sizeof(nl));
    CHECK_EQ_INT(sph_grid_init(&g, 2, (sph_real)0.1, NULL, NULL, NULL), SPH_OK);
    CHECK_EQ_INT(sph_grid_build(&g, NULL, 0), SPH_OK);
    CHECK_EQ_INT(sph_grid_query(&g, p, p, (sph_real)0.1, out, 400), 0);
    CHECK_EQ_INT(sph_neighbors_build(&nl, &g, NULL, p, 1, (sph_real)0.1, 0), SPH_OK);
    CHECK_EQ_INT(nl.count[0], 0);
    CHECK_EQ_INT(nl.total, 0);
    for (i = 0; i < 300; ++i) {
        x[2 * i] = (sph_real)0.25;
        x[2 * i + 1] = (sph_real)0.25;
    }
    for (i = 300; i < 310; ++i) {
        x[2 * i] = (sph_real)(0.25 + 0.0095 * (double)(i - 299));
        x[2 * i + 1] = (sph_real)0.25;
    }
    CHECK_EQ_INT(sph_grid_build(&g, x, 310), SPH_OK);
    tg_check_queries("duplicates", &g, &b, x, 310, x, 310, (sph_real)0.1, NULL);
    CHECK_EQ_INT(sph_grid_query(&g, x, x, (sph_real)0.1, out, 400), 310); /* all within 0.095 */
    CHECK_EQ_INT(sph_neighbors_build(&nl, &g, x, x, 310, (sph_real)0.1, 1), SPH_OK);
    tg_check_lists("duplicates", &nl, &b, x, 310, x, 310, (sph_real)0.1, 1);
    sph_neighbors_free(&nl);
    sph_grid_free(&g);
    sph_grid_free(&g); /* a second free is harmless */
}

/* The radius is strict (|d| < radius): on a 2D square lattice of spacing 0.25 (exact in binary),
   radius = 0.25 finds no neighbour (the 4 nearest lie at exactly 0.25), while radius = the next
   representable value above 0.25 finds the 4 axis neighbours of every interior point (the
   diagonal ones lie at 0.354). Checked with the grid query and with neighbour lists, at a cell
   size equal to the spacing (2-3 cells apart on both sides of a cell edge) and at 0.3. */
static void test_strict_radius(void) {
    sph_real x[2 * 64];
    sph_grid g;
    sph_neighbors nl;
    size_t i;
    int ic;
    const sph_real r_eq = (sph_real)0.25, r_up = TG_NEXTAFTER(r_eq, (sph_real)1);
    tg_bf b = tg_bf_make(2, NULL, NULL, NULL);
    memset(&nl, 0, sizeof(nl));
    for (i = 0; i < 64; ++i) {
        x[2 * i] = (sph_real)(0.25 * (double)(i % 8));
        x[2 * i + 1] = (sph_real)(0.25 * (double)(i / 8));
    }
    for (ic = 0; ic < 2; ++ic) {
        const sph_real cell = ic == 0 ? r_eq : (sph_real)0.3;
        CHECK_EQ_INT(sph_grid_init(&g, 2, cell, NULL, NULL, NULL), SPH_OK);
        CHECK_EQ_INT(sph_grid_build(&g, x, 64), SPH_OK);
        CHECK_EQ_INT(sph_neighbors_build(&nl, &g, x, x, 64, r_eq, 1), SPH_OK);
        CHECK_EQ_INT(nl.total, 0);
        tg_check_queries("strict radius", &g, &b, x, 64, x, 64, r_eq, NULL);
        if (ic == 1) {
            size_t interior = 0, four = 0;
            CHECK_EQ_INT(sph_neighbors_build(&nl, &g, x, x, 64, r_up, 1), SPH_OK);
            tg_check_lists("strict radius", &nl, &b, x, 64, x, 64, r_up, 1);
            for (i = 0; i < 64; ++i)
                if (i % 8 && i % 8 != 7 && i / 8 && i / 8 != 7) {
                    ++interior;
                    four += nl.count[i] == 4;
                }
            CHECK_EQ_INT(four, interior);
            CHECK_EQ_INT(nl.total, 4 * 8 * 7); /* 2 * (7 horizontal + 7 vertical links) * 8 */
        }
        sph_grid_free(&g);
    }
    sph_neighbors_free(&nl);
}

/* sph_grid_init rejects: NULL grid, dim 0/4/-1, cell <= 0, NaN or inf; for a periodic direction:
   missing lo/hi, non-finite lo/hi, a length below 2 cells (1.99 cells, 0, negative); and
   accepts a length of exactly 2 cells. Directions >= dim are not read. A failed init leaves a
   grid that sph_grid_free accepts. */
static void test_bad_input(void) {
    sph_grid g;
    const int per[3] = {1, 1, 1}, perx[3] = {1, 0, 0}, perz[3] = {0, 0, 1};
    const sph_real lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    const sph_real hi199[3] = {(sph_real)1.99, 1, 1}, hineg[3] = {-1, 1, 1};
    const sph_real hinan[3] = {(sph_real)NAN, 1, 1}, loinf[3] = {(sph_real)-INFINITY, 0, 0};
    const sph_real hibadz[3] = {1, 1, (sph_real)NAN};
    CHECK_EQ_INT(sph_grid_init(NULL, 2, 1, NULL, NULL, NULL), SPH_ERR_ARG);
    CHECK_EQ_INT(sph_grid_init(&g, 0, 1, NULL, NULL, NULL), SPH_ERR_ARG);
    CHECK_EQ_INT(sph_grid_init(&g, 4, 1, NULL, NULL, NULL), SPH_ERR_ARG);
    CHECK_EQ_INT(sph_grid_init(&g, -1, 1, NULL, NULL, NULL), SPH_ERR_ARG);
    CHECK_EQ_INT(sph_grid_init(&g, 2, 0, NULL, NULL, NULL), SPH_ERR_ARG);
    CHECK_EQ_INT(sph_grid_init(&g, 2, -1, NULL, NULL, NULL), SPH_ERR_ARG);
    CHECK_EQ_INT(sph_grid_init(&g, 2, (sph_real)NAN, NULL, NULL, NULL), SPH_ERR_ARG);
    CHECK_EQ_INT(sph_grid_init(&g, 2, (sph_real)INFINITY, NULL, NULL, NULL), SPH_ERR_ARG);
    CHECK_EQ_INT(sph_grid_init(&g, 2, (sph_real)0.5, per, NULL, hi), SPH_ERR_ARG);
    CHECK_EQ_INT(sph_grid_init(&g, 2, (sph_real)0.5, per, lo, NULL), SPH_ERR_ARG);
    CHECK_EQ_INT(sph_grid_init(&g, 2, 1, perx, lo, hi199), SPH_ERR_ARG);   /* 1.99 cells */
    CHECK_EQ_INT(sph_grid_init(&g, 2, (sph_real)0.51, per, lo, hi), SPH_ERR_ARG);
    CHECK_EQ_INT(sph_grid_init(&g, 1, (sph_real)0.5, per, lo, lo), SPH_ERR_ARG); /* length 0 */
    CHECK_EQ_INT(sph_grid_init(&g, 1, (sph_real)0.5, per, lo, hineg), SPH_ERR_ARG);
    CHECK_EQ_INT(sph_grid_init(&g, 1, (sph_real)0.1, per, lo, hinan), SPH_ERR_ARG);
    CHECK_EQ_INT(sph_grid_init(&g, 1, (sph_real)0.1, per, loinf, hi), SPH_ERR_ARG);
    sph_grid_free(&g);
    /* accepted: exactly two cells; periodic flags and bounds beyond dim are ignored; a
       non-periodic direction does not read lo/hi */
    CHECK_EQ_INT(sph_grid_init(&g, 3, (sph_real)0.5, per, lo, hi), SPH_OK);
    sph_grid_free(&g);
    CHECK_EQ_INT(sph_grid_init(&g, 2, 1, perz, lo, hibadz), SPH_OK);
    CHECK(g.periodic[2] == 0);
    sph_grid_free(&g);
    CHECK_EQ_INT(sph_grid_init(&g, 2, (sph_real)0.5, perx, lo, hibadz), SPH_OK);
    CHECK(g.periodic[0] != 0 && g.periodic[1] == 0);
    sph_grid_free(&g);
}

/* sph_grid_delta: along periodic directions the result is the image of a - b nearest to zero
   (found here by trying every shift a - b + m L, m = -8..8, in double), |d| <= L/2, and it
   differs from a - b by a whole number of box lengths; along non-periodic directions it is
   exactly a - b. Points range over [lo - 3L, hi + 3L). Tolerance: a few ulps of the operands. */
static void test_delta(void) {
    const int per[3] = {1, 0, 1};
    const sph_real lo[3] = {(sph_real)-0.3, 2, 5};
    const sph_real hi[3] = {(sph_real)0.9, (sph_real)2.5, (sph_real)6.7};
    sph_grid g;
    uint64_t seed = 7;
    int i, k;
    double worst = 0;
    CHECK_EQ_INT(sph_grid_init(&g, 3, (sph_real)0.1, per, lo, hi), SPH_OK);
    for (i = 0; i < 20000; ++i) {
        sph_real a[3], b[3], d[3];
        for (k = 0; k < 3; ++k) {
            double L = (double)(hi[k] - lo[k]);
            a[k] = (sph_real)((double)lo[k] - 3 * L + 7 * L * tg_unif(&seed));
            b[k] = (sph_real)((double)lo[k] - 3 * L + 7 * L * tg_unif(&seed));
        }
        sph_grid_delta(&g, a, b, d);
        for (k = 0; k < 3; ++k) {
            if (per[k]) {
                double L = (double)(hi[k] - lo[k]), raw = (double)a[k] - (double)b[k];
                double best = raw;
                double tol = 16 * TG_EPS * (fabs((double)a[k]) + fabs((double)b[k]) + L);
                double m;
                int s;
                for (s = -8; s <= 8; ++s)
                    if (fabs(raw + s * L) < fabs(best)) best = raw + s * L;
                CHECK_MSG(fabs((double)d[k] - best) <= tol,
                          "delta(%.17g, %.17g) = %.17g, minimum image %.17g", (double)a[k],
                          (double)b[k], (double)d[k], best);
                CHECK_LE(fabs((double)d[k]), 0.5 * L + tol);
                m = ((double)d[k] - raw) / L;
                CHECK_NEAR(m, floor(m + 0.5), tol / L);
                if (fabs((double)d[k] - best) > worst) worst = fabs((double)d[k] - best);
            } else {
                CHECK(d[k] == a[k] - b[k]);
            }
        }
    }
    TH_NOTE("worst |delta - minimum image| = %.2e", worst);
    sph_grid_free(&g);
}

/* A pair whose distance is just below the cell size (radius = cell, the way the world uses the
   grid) must be found: one point just left of the origin (-1e-30, cell -1) and one at the largest
   sph_real below the cell size (mathematically in cell 0). Swept over 128 cell sizes in
   [0.1, 1.1); the brute force decides (|d|^2 < cell^2 evaluated in sph_real) which pairs are
   neighbours. A failure means the cell index floor(x * (1/cell)) put the second point in cell 1
   (1/cell rounded up), two cells from the first, outside the 3-cell stencil. */
static void test_pair_just_inside_cell(void) {
    uint64_t seed = 8;
    int i, misses = 0, pairs = 0;
    double first = 0;
    for (i = 0; i < 128; ++i) {
        sph_real c = (sph_real)(0.1 + tg_unif(&seed)), x[2];
        sph_grid g;
        uint32_t out[4];
        tg_bf b = tg_bf_make(1, NULL, NULL, NULL);
        x[0] = (sph_real)-1e-30;
        x[1] = TG_NEXTAFTER(c, (sph_real)0);
        if (!(tg_bf_r2(&b, x, x + 1) < c * c)) continue;
        ++pairs;
        CHECK_EQ_INT(sph_grid_init(&g, 1, c, NULL, NULL, NULL), SPH_OK);
        CHECK_EQ_INT(sph_grid_build(&g, x, 2), SPH_OK);
        if (sph_grid_query(&g, x, x, c, out, 4) != 2 ||
            sph_grid_query(&g, x, x + 1, c, out, 4) != 2) {
            if (!misses) first = (double)c;
            ++misses;
        }
        sph_grid_free(&g);
    }
    if (misses)
        TH_NOTE("pair (-1e-30, nextafter(cell, 0)) missed for %d of %d cell sizes; first: "
                "cell = %.17g", misses, pairs, first);
    CHECK(pairs > 64);
    CHECK_MSG(misses == 0, "%d of %d neighbour pairs at distance just below the cell size missed",
              misses, pairs);
}

const th_test tests_grid[] = {
    {"grid/query_random_open", test_query_random_open},
    {"grid/query_periodic_all", test_query_periodic_all},
    {"grid/query_periodic_mixed", test_query_periodic_mixed},
    {"grid/far_point", test_far_point},
    {"grid/clamped", test_clamped},
    {"grid/neighbors_build", test_neighbors_build},
    {"grid/neighbors_cell_ordered", test_neighbors_cell_ordered},
    {"grid/empty_and_duplicates", test_empty_and_duplicates},
    {"grid/strict_radius", test_strict_radius},
    {"grid/bad_input", test_bad_input},
    {"grid/delta", test_delta},
    {"grid/pair_just_inside_cell", test_pair_just_inside_cell},
    {0, 0}};
