/* tests/test_hostile.c - hostile input (issue 19): loaded files checked like the API's input,
   coordinates too far from the origin for the spacing, wall boxes at O(surface) cost, periodic
   grids with points far outside the box, the force callback named when it writes a non-finite
   value, fluid added onto fluid or into walls, phases too different for a summed density. Each
   test failed on the sph.h before its fix. */
#include "harness.h"
#include "alloc.h"
#include "../sph.h"

#include <math.h>
#include <stdio.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#ifdef _OPENMP
#include <omp.h>
#endif

static double hs_now(void) {
#ifdef _OPENMP
    return omp_get_wtime();
#else
    return (double)clock() / CLOCKS_PER_SEC;
#endif
}

/* ---- wall boxes ------------------------------------------------------------------------------ */

/* The whole-lattice algorithm sph_add_wall_box used before it walked only the shell (kept as the
   reference for the particles, their order and their volumes): every point of the lattice of
   box and layers, x fastest, kept if it lies outside the box in some direction and not beyond
   an open face. Returns the number of points, or (size_t)-1 out of memory. */
static size_t ref_wall_box(const sph_world* w, const sph_real* lo, const sph_real* hi, int layers,
                           unsigned open_faces, sph_real** pts_out, sph_real** vol_out) {
    const int dim = w->dim;
    sph_real* coord[3] = {NULL, NULL, NULL};
    sph_real* width[3] = {NULL, NULL, NULL};
    int* side[3] = {NULL, NULL, NULL};
    size_t cnt[3] = {1, 1, 1}, total = 1, i, nw = 0;
    sph_real *pts = NULL, *vol = NULL;
    int k;
    if (layers == 0) layers = (int)ceil((double)(w->kernel.radius / w->dx) - 1e-9);
    for (k = 0; k < dim; ++k) {
        double span = (double)((hi[k] - lo[k]) / w->dx);
        size_t ni, j, c = 0;
        sph_real sp;
        ni = (size_t)(span + 0.5);
        if (ni < 1) ni = 1;
        sp = (hi[k] - lo[k]) / (sph_real)ni;
        cnt[k] = ni + 2 * (size_t)layers;
        coord[k] = (sph_real*)malloc(cnt[k] * sizeof(sph_real));
        width[k] = (sph_real*)malloc(cnt[k] * sizeof(sph_real));
        side[k] = (int*)malloc(cnt[k] * sizeof(int));
        for (j = (size_t)layers; j > 0; --j, ++c) {
            coord[k][c] = lo[k] - ((sph_real)(j - 1) + (sph_real)0.5) * w->dx;
            width[k][c] = w->dx;
            side[k][c] = -1;
        }
        for (j = 0; j < ni; ++j, ++c) {
            coord[k][c] = lo[k] + ((sph_real)j + (sph_real)0.5) * sp;
            width[k][c] = sp;
            side[k][c] = 0;
        }
        for (j = 0; j < (size_t)layers; ++j, ++c) {
            coord[k][c] = hi[k] + ((sph_real)j + (sph_real)0.5) * w->dx;
            width[k][c] = w->dx;
            side[k][c] = 1;
        }
        total *= cnt[k];
    }
    pts = (sph_real*)malloc(total * (size_t)dim * sizeof(sph_real) + 1);
    vol = (sph_real*)malloc(total * sizeof(sph_real) + 1);
    if (!pts || !vol) {
        nw = (size_t)-1;
        goto done;
    }
    for (i = 0; i < total; ++i) {
        size_t r = i, ix[3] = {0, 0, 0};
        int outside = 0, open = 0;
        sph_real V = 1;
        for (k = 0; k < dim; ++k) {
            ix[k] = r % cnt[k];
            r /= cnt[k];
        }
        for (k = 0; k < dim; ++k) {
            int sd = side[k][ix[k]];
            if (sd != 0) outside = 1;
            if (sd < 0 && (open_faces & (1u << (2 * k)))) open = 1;
            if (sd > 0 && (open_faces & (1u << (2 * k + 1)))) open = 1;
            V *= width[k][ix[k]];
        }
        if (!outside || open) continue;
        for (k = 0; k < dim; ++k)
            pts[nw * (size_t)dim + (size_t)k] = coord[k][ix[k]];
        vol[nw++] = V;
    }
done:
    for (k = 0; k < 3; ++k) {
        free(coord[k]);
        free(width[k]);
        free(side[k]);
    }
    *pts_out = pts;
    *vol_out = vol;
    return nw;
}

/* The shell walk gives bit for bit the particles of the whole-lattice walk, in the same order:
   1D, 2D, 3D, whole and fractional spacings, 1 to 5 layers and the automatic depth, every
   combination of open faces in 2D and a set of them in 3D, boxes off the origin and of one
   spacing, and a second box added after the first. */
static void test_wall_box_matches_lattice_walk(void) {
    static const double boxes[][6] = {
        {0, 0, 0, 1.0, 0.5, 0.3},    {-0.13, 0.07, 0.2, 0.313, 0.52, 0.61},
        {0, 0, 0, 0.05, 0.05, 0.05}, {1.0, -2.0, 3.0, 1.031, -1.71, 3.047},
        {0, 0, 0, 0.4, 0.05, 0.25},
    };
    static const int layer_set[] = {0, 1, 2, 3, 5};
    int dim, bx, li, mismatches = 0, cases = 0;
    for (dim = 1; dim <= 3; ++dim) {
        const unsigned faces = 1u << (2 * dim); /* all combinations of the dim's faces */
        for (bx = 0; bx < (int)(sizeof boxes / sizeof boxes[0]); ++bx)
            for (li = 0; li < (int)(sizeof layer_set / sizeof layer_set[0]); ++li) {
                unsigned open;
                for (open = 0; open < faces; open += dim == 3 ? 5u : 1u) {
                    sph_world_def d = sph_world_def_default(dim);
                    sph_world w;
                    sph_real lo[3], hi[3], *pts = NULL, *vol = NULL;
                    size_t nref, nb0, b;
                    int k, pass;
                    d.spacing = (sph_real)0.05;
                    if (sph_world_init(&w, &d) != SPH_OK) {
                        CHECK(0);
                        return;
                    }
                    for (k = 0; k < 3; ++k) {
                        lo[k] = (sph_real)boxes[bx][k];
                        hi[k] = (sph_real)boxes[bx][3 + k];
                    }
                    for (pass = 0; pass < 2; ++pass) { /* the second box lands after the first */
                        nb0 = w.nb;
                        nref = ref_wall_box(&w, lo, hi, layer_set[li], open, &pts, &vol);
                        CHECK_EQ_INT(sph_add_wall_box(&w, lo, hi, layer_set[li], open), SPH_OK);
                        ++cases;
                        if (nref == (size_t)-1 || w.nb - nb0 != nref) {
                            CHECK_MSG(0,
                                      "dim %d box %d layers %d open %u: %zu wall particles, "
                                      "the lattice walk gives %zu",
                                      dim, bx, layer_set[li], open, w.nb - nb0, nref);
                            ++mismatches;
                        } else {
                            /* nref = 0 (every face open): no arrays to compare (memcmp of
                               NULL is undefined even for 0 bytes) */
                            int same = nref == 0 ||
                                       (memcmp(w.b_x + nb0 * (size_t)dim, pts,
                                               nref * (size_t)dim * sizeof(sph_real)) == 0 &&
                                        memcmp(w.b_vol + nb0, vol, nref * sizeof(sph_real)) == 0);
                            for (b = nb0; b < w.nb; ++b)
                                if (w.b_id[b] != (uint32_t)b || w.b_body[b] != 0) same = 0;
                            if (!same) {
                                CHECK_MSG(0,
                                          "dim %d box %d layers %d open %u: positions, "
                                          "volumes or ids differ",
                                          dim, bx, layer_set[li], open);
                                ++mismatches;
                            }
                        }
                        free(pts);
                        free(vol);
                        pts = vol = NULL;
                        lo[0] = (sph_real)(lo[0] + 2); /* the second box: elsewhere */
                        hi[0] = (sph_real)(hi[0] + 2);
                    }
                    sph_world_free(&w);
                    if (mismatches > 5) return;
                }
            }
    }
    TH_NOTE("%d wall boxes identical to the whole-lattice walk", cases);
}

/* Boxes whose lattice is much larger than their walls. 2D, 16000 x 16000 spacings (as large as
   a float world centred on the origin may be, see far_coordinates_rejected): 2.6e8 lattice
   points, 6 GB of scratch and seconds before, 6.4e4 wall particles. In double also 1e5 x 1e5
   spacings (1e10 lattice points: SPH_ERR_CAPACITY before; 4e5 wall particles). 3D, 600^3
   spacings with only the floor and one side closed (2.2e8 lattice points, 7.3e5 walls). The
   capacity rule counts wall particles: a closed 16000^3 box 3 layers deep (4.6e9 walls) is
   refused before anything is allocated. */
static void test_wall_box_cost_follows_surface(void) {
    sph_world w;
    sph_world_def d = sph_world_def_default(2);
    sph_real lo[3] = {-80, -80, -80}, hi[3] = {80, 80, 80};
    double t0, t;
    unsigned long allocs;
    d.spacing = (sph_real)0.01;
    CHECK_EQ_INT(sph_world_init(&w, &d), SPH_OK);
    t0 = hs_now();
    CHECK_EQ_INT(sph_add_wall_box(&w, lo, hi, 1, 0), SPH_OK);
    t = hs_now() - t0;
    CHECK_EQ_INT(w.nb, 16002ull * 16002ull - 16000ull * 16000ull);
    CHECK_LT(t, 0.5);
    TH_NOTE("2D 16000^2 spacings, 1 layer: %zu wall particles in %.3f s", w.nb, t);
    sph_world_free(&w);
    if (sizeof(sph_real) == 8) {
        sph_real lo2[2] = {0, 0}, hi2[2] = {1000, 1000};
        CHECK_EQ_INT(sph_world_init(&w, &d), SPH_OK);
        t0 = hs_now();
        CHECK_EQ_INT(sph_add_wall_box(&w, lo2, hi2, 1, 0), SPH_OK);
        t = hs_now() - t0;
        CHECK_EQ_INT(w.nb, 100002ull * 100002ull - 100000ull * 100000ull);
        CHECK_LT(t, 2.0);
        TH_NOTE("2D 1e5^2 spacings, 1 layer: %zu wall particles in %.3f s", w.nb, t);
        sph_world_free(&w);
    }

    d = sph_world_def_default(3);
    d.spacing = (sph_real)0.01;
    CHECK_EQ_INT(sph_world_init(&w, &d), SPH_OK);
    {
        sph_real lo3[3] = {0, 0, 0}, hi3[3] = {6, 6, 6};
        t0 = hs_now();
        CHECK_EQ_INT(
            sph_add_wall_box(&w, lo3, hi3, 1,
                             SPH_FACE_XMAX | SPH_FACE_YMAX | SPH_FACE_ZMIN | SPH_FACE_ZMAX),
            SPH_OK);
        t = hs_now() - t0;
    }
    /* floor (y layer below, x from the closed layer through the box) and the xmin side */
    CHECK_EQ_INT(w.nb, 601 * 600 + 600 * 600);
    CHECK_LT(t, 2.0);
    TH_NOTE("3D 600^3 spacings, floor and one side: %zu wall particles in %.3f s", w.nb, t);
    th_alloc_fail_at(0);
    CHECK_EQ_INT(sph_add_wall_box(&w, lo, hi, 3, 0), SPH_ERR_CAPACITY);
    allocs = th_alloc_count();
    CHECK_EQ_INT(allocs, 0);
    CHECK_MSG(strstr(w.error, "wall particles") != NULL, "%s", w.error);
    CHECK_EQ_INT(w.nb, 601 * 600 + 600 * 600);
    sph_world_free(&w);
}

/* A box a denormal wide gives wall volumes that round to 0, which sph_add_boundary refuses:
   sph_add_wall_box refuses them too now (SPH_ERR_ARG, nothing added; the saved world would not
   load). Found by tests/fuzz_api.c. */
static void test_wall_box_zero_volume(void) {
    sph_world_def d = sph_world_def_default(2);
    sph_world w;
    sph_real lo[2] = {0, 0}, hi[2] = {0.2f, 0};
    hi[1] = (sph_real)(sizeof(sph_real) == 4 ? 1.4e-45 : 4.9e-324); /* the smallest denormal */
    d.spacing = (sph_real)0.02;
    CHECK_EQ_INT(sph_world_init(&w, &d), SPH_OK);
    CHECK_EQ_INT(sph_add_wall_box(&w, lo, hi, 2, 0), SPH_ERR_ARG);
    CHECK_MSG(strstr(w.error, "vol of particle") != NULL, "%s", w.error);
    CHECK_EQ_INT(w.nb, 0);
    CHECK_EQ_INT(w.error_index, -1);
    sph_world_free(&w);
}

/* ---- loaded files are checked like the API's input ----------------------------------------- */

/* A small tank: 2D water 10 x 8 at dx = 0.02 in walls, 5 WCSPH steps taken. */
static int hs_tank(sph_world* w, double x0) {
    sph_world_def d = sph_world_def_default(2);
    sph_phase water;
    sph_real lo[2], hi[2], whi[2];
    int q;
    memset(&water, 0, sizeof water);
    water.rest_density = 1000;
    d.spacing = (sph_real)0.02;
    lo[0] = (sph_real)x0;
    lo[1] = 0;
    hi[0] = (sph_real)(x0 + 0.2);
    hi[1] = (sph_real)0.16;
    whi[0] = hi[0];
    whi[1] = (sph_real)0.24;
    if (sph_world_init(w, &d) != SPH_OK || sph_world_add_phase(w, &water) != 0 ||
        sph_fill_box(w, 0, lo, hi) != SPH_OK ||
        sph_add_wall_box(w, lo, whi, 0, SPH_FACE_YMAX) != SPH_OK ||
        sph_set_hydrostatic(w) != SPH_OK)
        return 0;
    for (q = 0; q < 5; ++q)
        if (th_step(w, sph_stable_dt(w, SPH_SOLVER_WCSPH)) != SPH_OK) return 0;
    return 1;
}

/* FNV-1a 64 over all bytes but the last 8, which it replaces: the loader's checksum, so that an
   edited file reaches the field checks. */
static void hs_rehash(unsigned char* b, size_t n) {
    uint64_t h = 14695981039346656037ull;
    size_t i;
    for (i = 0; i + 8 < n; ++i)
        h = (h ^ b[i]) * 1099511628211ull;
    memcpy(b + n - 8, &h, 8);
}

/* Byte offsets of the saved layout (sph__save): header, def, phases, scalars, stats, arrays. */
typedef struct hs_layout {
    size_t phases, time, next_id, mass, stats, fluid, boundary; /* fluid/boundary: array count */
} hs_layout;

static hs_layout hs_layout_of(const unsigned char* b, int nphase) {
    hs_layout L;
    size_t at = 8 + 8 * 4 + sizeof(sph_world_def);
    uint32_t na, elem, k;
    uint64_t n;
    L.phases = at + 4;
    at = L.phases + (size_t)nphase * sizeof(sph_phase);
    L.time = at;
    at += 8 + 8 + 8 + 8 * SPH_STAGE_COUNT; /* time, steps, step_time_total, stage_time_total */
    memcpy(&n, b + at, 8);
    L.next_id = at + 16;
    L.mass = L.next_id + 16; /* next ids, has_m, have_mass */
    L.stats = L.mass + sizeof(sph_real);
    L.fluid = L.stats + sizeof(sph_stats);
    at = L.fluid;
    memcpy(&na, b + at, 4);
    at += 4;
    for (k = 0; k < na; ++k) {
        memcpy(&elem, b + at, 4);
        at += 4 + (size_t)n * elem;
    }
    L.boundary = at;
    return L;
}

/* Offset of the data of array `index` in the list starting at `list` (count = particles). */
static size_t hs_array(const unsigned char* b, size_t list, int index, size_t count) {
    size_t at = list + 4;
    uint32_t elem;
    int k;
    for (k = 0; k < index; ++k) {
        memcpy(&elem, b + at, 4);
        at += 4 + count * elem;
    }
    return at + 4;
}

static void hs_put_real(unsigned char* b, size_t at, double v) {
    sph_real r = (sph_real)v;
    memcpy(b + at, &r, sizeof r);
}

/* Each edit of issue 19 (and a few more), with a recomputed checksum: the loader refuses it with
   SPH_ERR_ARG and a message naming the field (the rule's message from the API), and leaves the
   world freed (n = 0, no arrays). Before, every one loaded with SPH_OK and stepped. The intact
   bytes still load to the same world. */
static void test_load_checks_fields(void) {
    sph_world a, b;
    unsigned char *bytes, *copy;
    size_t n, i, xoff, nf, nbw;
    hs_layout L;
    int e, cases = 0;
    uint32_t zero = 0;
    static const char* const expect[] = {
        "mass = -1",
        "sph_phase.gamma = -3",
        "sph_phase.sound_speed = -5",
        "sph_phase.viscosity = -1e+09",
        "vol of particle 0 = -1",
        "time = nan",
        "id",
        "pressure of particle 0",
        "x of particle 3 is not finite",
        "density of particle 2",
        "v of particle 1",
        "phase 7 does not exist",
        "too far from the origin",
        "b_x0 of particle",
        "stats field",
        "sph_phase.mass = -2",
    };
    CHECK(hs_tank(&a, 0));
    n = sph_world_save_mem(&a, NULL, 0);
    bytes = (unsigned char*)malloc(n);
    copy = (unsigned char*)malloc(n);
    CHECK_EQ_INT(sph_world_save_mem(&a, bytes, n), n);
    L = hs_layout_of(bytes, a.nphase);
    nf = a.n;
    nbw = a.nb;
    for (e = 0; e < (int)(sizeof expect / sizeof expect[0]); ++e) {
        sph_status s;
        memcpy(copy, bytes, n);
        switch (e) {
        case 0:
            hs_put_real(copy, L.mass, -1);
            break;
        case 1:
            hs_put_real(copy, L.phases + offsetof(sph_phase, gamma), -3);
            break;
        case 2:
            hs_put_real(copy, L.phases + offsetof(sph_phase, sound_speed), -5);
            break;
        case 3:
            hs_put_real(copy, L.phases + offsetof(sph_phase, viscosity), -1e9);
            break;
        case 4: /* every wall volume */
            xoff = hs_array(copy, L.boundary, 4, nbw);
            for (i = 0; i < nbw; ++i)
                hs_put_real(copy, xoff + i * sizeof(sph_real), -1);
            break;
        case 5: {
            double t = NAN;
            memcpy(copy + L.time, &t, 8);
        } break;
        case 6: /* all ids equal, next id 0 */
            xoff = hs_array(copy, L.fluid, 4, nf);
            for (i = 0; i < nf; ++i)
                memcpy(copy + xoff + 4 * i, &zero, 4);
            memcpy(copy + L.next_id, &zero, 4);
            break;
        case 7:
            hs_put_real(copy, hs_array(copy, L.fluid, 3, nf), NAN);
            break;
        case 8:
            hs_put_real(copy, hs_array(copy, L.fluid, 0, nf) + 7 * sizeof(sph_real), NAN);
            break;
        case 9:
            hs_put_real(copy, hs_array(copy, L.fluid, 2, nf) + 2 * sizeof(sph_real), -1);
            break;
        case 10:
            hs_put_real(copy, hs_array(copy, L.fluid, 1, nf) + 3 * sizeof(sph_real), INFINITY);
            break;
        case 11:
            copy[hs_array(copy, L.fluid, 5, nf) + 4] = 7;
            break;
        case 12:
            hs_put_real(copy, hs_array(copy, L.fluid, 0, nf) + 4 * sizeof(sph_real), 1e30);
            break;
        case 13:
            hs_put_real(copy, hs_array(copy, L.boundary, 3, nbw) + sizeof(sph_real), NAN);
            break;
        case 14: {
            double v = -1;
            memcpy(copy + L.stats + offsetof(sph_stats, a_max), &v, 8);
        } break;
        default:
            hs_put_real(copy, L.phases + offsetof(sph_phase, mass), -2);
            break;
        }
        hs_rehash(copy, n);
        s = sph_world_load_mem(&b, copy, n, NULL);
        CHECK_MSG(s == SPH_ERR_ARG, "edit %d (%s): status %d (%s)", e, expect[e], (int)s, b.error);
        CHECK_MSG(strstr(b.error, expect[e]) != NULL && strstr(b.error, "sph_world_load") != NULL,
                  "edit %d: message '%s' lacks '%s'", e, b.error, expect[e]);
        CHECK(b.n == 0 && b.nb == 0 && b.x == NULL && b.b_x == NULL && b.nphase == 0);
        if (s == SPH_OK) { /* before the fix: a first step even succeeded */
            TH_NOTE("edit %d loaded; step: %s", e, sph_status_string(th_step(&b, (sph_real)1e-5)));
        }
        sph_world_free(&b);
        ++cases;
    }
    /* a phase index error names the particle */
    memcpy(copy, bytes, n);
    copy[hs_array(copy, L.fluid, 5, nf) + 4] = 7;
    hs_rehash(copy, n);
    CHECK_EQ_INT(sph_world_load_mem(&b, copy, n, NULL), SPH_ERR_ARG);
    CHECK_EQ_INT(b.error_index, 4);
    sph_world_free(&b);
    /* the intact bytes (checksum recomputed: unchanged) load to the same world, which steps */
    memcpy(copy, bytes, n);
    hs_rehash(copy, n);
    CHECK(memcmp(copy, bytes, n) == 0);
    CHECK_EQ_INT(sph_world_load_mem(&b, copy, n, NULL), SPH_OK);
    CHECK_EQ_INT(b.n, a.n);
    CHECK_EQ_INT(th_step(&b, sph_stable_dt(&b, SPH_SOLVER_WCSPH)), SPH_OK);
    sph_world_free(&b);
    TH_NOTE("%d edited files refused with the field named", cases);
    free(bytes);
    free(copy);
    sph_world_free(&a);
}

/* ---- coordinates far from the origin ------------------------------------------------------- */

static double hs_far_limit(double dx) { return dx / (1000 * TH_EPS); }

/* A tank at rest 2D, 30 x 20 particles at dx = 0.02, at x = x0, for 1 s of WCSPH: the fluid
   particles that left the walls (beyond the box the water filled). */
static size_t hs_tank_lost(double x0, sph_status* status) {
    sph_world_def d = sph_world_def_default(2);
    sph_world w;
    sph_phase water;
    sph_real lo[2], hi[2], whi[2];
    size_t i, lost = 0;
    sph_status s;
    memset(&water, 0, sizeof water);
    water.rest_density = 1000;
    d.spacing = (sph_real)0.02;
    lo[0] = (sph_real)x0;
    lo[1] = 0;
    hi[0] = (sph_real)(x0 + 0.6);
    hi[1] = (sph_real)0.4;
    whi[0] = hi[0];
    whi[1] = (sph_real)0.6;
    s = sph_world_init(&w, &d);
    if (s == SPH_OK && sph_world_add_phase(&w, &water) < 0) s = w.status;
    if (s == SPH_OK) s = sph_fill_box(&w, 0, lo, hi);
    if (s == SPH_OK) s = sph_add_wall_box(&w, lo, whi, 0, SPH_FACE_YMAX);
    if (s == SPH_OK) s = sph_set_hydrostatic(&w);
    if (s == SPH_OK) s = sph_advance(&w, 1);
    for (i = 0; i < w.n; ++i) {
        const double x = (double)w.x[2 * i], y = (double)w.x[2 * i + 1];
        if (x < (double)lo[0] || x > (double)hi[0] || y < 0) ++lost;
    }
    *status = s;
    sph_world_free(&w);
    return lost;
}

/* At 0.95 of the documented limit (|x| eps <= dx / 1000: 159 m in float, 8.6e10 m in double at
   dx = 0.02) the tank at rest keeps every particle for 1 s; at twice the limit it is refused.
   Before the check the float tank at x = 1e4 m lost 308 of 600 particles, every call SPH_OK. */
static void test_far_tank(void) {
    const double lim = hs_far_limit(0.02);
    sph_status s;
    size_t lost = hs_tank_lost(0.95 * lim, &s);
    CHECK_EQ_INT(s, SPH_OK);
    CHECK_EQ_INT(lost, 0);
    TH_NOTE("tank at x = %.4g m (0.95 of the limit): %zu of 600 left the walls in 1 s", 0.95 * lim,
            lost);
    lost = hs_tank_lost(2 * lim, &s);
    CHECK_EQ_INT(s, SPH_ERR_ARG);
}

/* Every way positions enter is checked at twice the limit: the domain box at init, sph_fill_box,
   sph_add_fluid(_ex) and sph_add_boundary (naming the particle), sph_add_wall_box (its outer
   layer), the host writing a position between steps (the step changes nothing), and the loader.
   Each message names the remedy. */
static void test_far_coordinates_rejected(void) {
    const double dx = 0.02, far = 2 * hs_far_limit(dx);
    sph_world_def d = sph_world_def_default(2);
    sph_world w, b;
    sph_phase water;
    sph_real x[8], lo[2], hi[2];
    size_t i;
    int k;
    memset(&water, 0, sizeof water);
    water.rest_density = 1000;
    d.spacing = (sph_real)dx;
    d.domain_lo[0] = 0;
    d.domain_hi[0] = (sph_real)far;
    CHECK_EQ_INT(sph_world_init(&w, &d), SPH_ERR_ARG);
    CHECK_MSG(strstr(w.error, "domain_hi[0]") && strstr(w.error, "near the origin"), "%s", w.error);
    sph_world_free(&w);
    d.domain_hi[0] = 0;
    CHECK_EQ_INT(sph_world_init(&w, &d), SPH_OK);
    CHECK_EQ_INT(sph_world_add_phase(&w, &water), 0);
    lo[0] = (sph_real)far;
    lo[1] = 0;
    hi[0] = (sph_real)(far + 0.2);
    hi[1] = (sph_real)0.2;
    CHECK_EQ_INT(sph_fill_box(&w, 0, lo, hi), SPH_ERR_ARG);
    CHECK_MSG(strstr(w.error, "sph_fill_box") && strstr(w.error, "too far"), "%s", w.error);
    if (sizeof(sph_real) == 4) CHECK(strstr(w.error, "build in double") != NULL);
    for (i = 0; i < 4; ++i) {
        x[2 * i] = (sph_real)(0.02 * (double)i);
        x[2 * i + 1] = 0;
    }
    x[2 * 3 + 1] = (sph_real)-far;
    CHECK_EQ_INT(sph_add_fluid(&w, 0, 4, x, NULL), SPH_ERR_ARG);
    CHECK_EQ_INT(w.error_index, 3);
    CHECK_MSG(strstr(w.error, "particle 3 at x[1]") && strstr(w.error, "near the origin"), "%s",
              w.error);
    CHECK_EQ_INT(sph_add_fluid_ex(&w, 0, 4, x, NULL, NULL, NULL), SPH_ERR_ARG);
    CHECK_EQ_INT(sph_add_boundary(&w, 4, x, NULL, 0), SPH_ERR_ARG);
    CHECK_EQ_INT(w.error_index, 3);
    CHECK_EQ_INT(w.n + w.nb, 0);
    /* a wall box inside the limit whose layers reach beyond it */
    lo[0] = (sph_real)(far / 2 - 0.03);
    hi[0] = (sph_real)(far / 2 - 0.01);
    CHECK_EQ_INT(sph_add_wall_box(&w, lo, hi, 3, 0), SPH_ERR_ARG);
    CHECK_MSG(strstr(w.error, "outer layer"), "%s", w.error);
    CHECK_EQ_INT(w.nb, 0);
    /* the host writes a far position between steps: refused, nothing changed */
    lo[0] = 0;
    hi[0] = (sph_real)0.2;
    CHECK_EQ_INT(sph_fill_box(&w, 0, lo, hi), SPH_OK);
    CHECK_EQ_INT(th_step(&w, (sph_real)1e-4), SPH_OK);
    for (k = 0; k < 2; ++k) {
        const sph_real keep = w.x[2 * 5];
        const uint64_t steps = w.steps;
        w.x[2 * 5] = (sph_real)(k ? far : -far);
        CHECK_EQ_INT(th_step(&w, (sph_real)1e-4), SPH_ERR_ARG);
        CHECK_EQ_INT(w.error_index, 5);
        CHECK_MSG(strstr(w.error, "fluid particle 5") && strstr(w.error, "too far"), "%s", w.error);
        CHECK_EQ_INT(w.steps, steps);
        /* the loader refuses it too */
        {
            const size_t n = sph_world_save_mem(&w, NULL, 0);
            unsigned char* buf = (unsigned char*)malloc(n);
            sph_world_save_mem(&w, buf, n);
            CHECK_EQ_INT(sph_world_load_mem(&b, buf, n, NULL), SPH_ERR_ARG);
            CHECK_MSG(strstr(b.error, "sph_world_load") && strstr(b.error, "too far"), "%s",
                      b.error);
            sph_world_free(&b);
            free(buf);
        }
        w.x[2 * 5] = keep;
    }
    CHECK_EQ_INT(th_step(&w, (sph_real)1e-4), SPH_OK);
    sph_world_free(&w);
}

/* ---- periodic grids with points far outside the box ---------------------------------------- */

/* The exact image of x in the periodic box [lo, lo + len) (fmod is exact). */
static double hs_image(double x, double lo, double len) {
    double u = fmod(x - lo, len);
    return lo + (u < 0 ? u + len : u);
}

/* Issue 19's case (double: 0.55 + 2e12 and + 3e11 keep their fraction to 2.4e-4), then random
   points in 1D, 2D and 3D, some moved by 12345 to 2e12 box lengths (either sign), against brute
   force over their exact images with the minimum image: the grid's query, its neighbour lists
   and sph_grid_delta. Pairs within 1e-4 of the radius are not compared (the stored point is
   rounded). */
static void test_periodic_grid_far_points(void) {
    static const double shift[] = {0, 0, 12345, 3e11, -7e11, 2e12};
    sph_real lo[3] = {0, -0.3f, 0.25f}, hi[3] = {1, 0.9f, 1.25f};
    int per[3] = {1, 1, 1}, dim, missing = 0, extra = 0, compared = 0;
    if (sizeof(sph_real) == 8) {
        sph_grid g;
        sph_real x[4];
        uint32_t out[4];
        int c;
        x[0] = (sph_real)0.5;
        x[1] = (sph_real)(0.55 + 2e12);
        x[2] = (sph_real)0.45;
        x[3] = (sph_real)(0.55 + 3e11);
        CHECK_EQ_INT(sph_grid_init(&g, 1, (sph_real)0.2, per, lo, hi), SPH_OK);
        CHECK_EQ_INT(sph_grid_build(&g, x, 4), SPH_OK);
        for (c = 1; c <= 3; c += 2) {
            size_t found = sph_grid_query(&g, x, &x[c], (sph_real)0.2, out, 4), q;
            int has0 = 0;
            sph_real d;
            for (q = 0; q < found && q < 4; ++q)
                has0 |= out[q] == 0;
            CHECK_MSG(has0, "the point at 0.55 + %g does not find its neighbour at 0.5",
                      c == 1 ? 2e12 : 3e11);
            sph_grid_delta(&g, &x[c], &x[0], &d);
            CHECK_NEAR(d, 0.05, 1e-3);
        }
        sph_grid_free(&g);
    }
    for (dim = 1; dim <= 3; ++dim) {
        const size_t n = dim == 1 ? 60 : dim == 2 ? 300 : 800;
        const sph_real radius = (sph_real)0.2;
        sph_real* x = (sph_real*)malloc(n * (size_t)dim * sizeof(sph_real));
        double* img = (double*)malloc(n * (size_t)dim * sizeof(double));
        uint32_t* out = (uint32_t*)malloc(n * sizeof(uint32_t));
        sph_neighbors nl;
        sph_grid g;
        unsigned long r = 12345u + (unsigned long)dim;
        size_t i, j;
        int k;
        memset(&nl, 0, sizeof nl);
        for (i = 0; i < n * (size_t)dim; ++i) {
            const int kk = (int)(i % (size_t)dim);
            const double len = (double)(hi[kk] - lo[kk]);
            double u, s;
            r = r * 6364136223846793005ul + 1442695040888963407ul;
            u = (double)((r >> 11) & 0xfffff) / 1048576.0;
            s = shift[(r >> 40) % 6];
            x[i] = (sph_real)((double)lo[kk] + u * len + ((r >> 50) & 1 ? s : -s) * len);
            img[i] = hs_image((double)x[i], (double)lo[kk], len);
        }
        CHECK_EQ_INT(sph_grid_init(&g, dim, radius, per, lo, hi), SPH_OK);
        CHECK_EQ_INT(sph_grid_build(&g, x, n), SPH_OK);
        CHECK_EQ_INT(sph_neighbors_build(&nl, &g, x, x, n, radius, 1), SPH_OK);
        for (i = 0; i < n; ++i) {
            const size_t found = sph_grid_query(&g, x, x + i * (size_t)dim, radius, out, n);
            for (j = 0; j < n; ++j) {
                double r2 = 0, rr;
                int in_query = 0, in_list = 0;
                size_t q;
                sph_real d[3];
                for (k = 0; k < dim; ++k) {
                    const double len = (double)(hi[k] - lo[k]);
                    double dd = img[i * (size_t)dim + (size_t)k] - img[j * (size_t)dim + (size_t)k];
                    dd -= len * floor(dd / len + 0.5);
                    r2 += dd * dd;
                }
                rr = sqrt(r2);
                if (fabs(rr - (double)radius) < 1e-4) continue;
                ++compared;
                for (q = 0; q < found && q < n; ++q)
                    in_query |= out[q] == (uint32_t)j;
                for (q = 0; q < nl.count[i]; ++q)
                    in_list |= nl.idx[nl.begin[i] + q] == (uint32_t)j;
                if (rr < (double)radius && (!in_query || (i != j && !in_list))) ++missing;
                if (rr >= (double)radius && (in_query || in_list)) ++extra;
                sph_grid_delta(&g, x + i * (size_t)dim, x + j * (size_t)dim, d);
                r2 = 0;
                for (k = 0; k < dim; ++k)
                    r2 += (double)d[k] * (double)d[k];
                if (fabs(sqrt(r2) - rr) > 1e-4) ++extra;
            }
        }
        sph_neighbors_free(&nl);
        sph_grid_free(&g);
        free(x);
        free(img);
        free(out);
    }
    CHECK_EQ_INT(missing, 0);
    CHECK_EQ_INT(extra, 0);
    TH_NOTE("%d pairs against brute force: %d missing, %d wrong", compared, missing, extra);
}

/* ---- the force callback named when it writes a non-finite value ---------------------------- */

typedef struct hs_bad_force {
    uint32_t ids[4]; /* the particles (by id) whose acceleration becomes NaN */
    int count, armed;
} hs_bad_force;

static void hs_bad_force_fn(const sph_world* w, size_t begin, size_t end, sph_real* acc,
                            void* user) {
    const hs_bad_force* f = (const hs_bad_force*)user;
    size_t i;
    int q;
    for (i = begin; i < end; ++i) {
        acc[i * (size_t)w->dim] += (sph_real)0.1;
        for (q = 0; f->armed && q < f->count; ++q)
            if (w->id[i] == f->ids[q])
                acc[i * (size_t)w->dim + (size_t)(q % w->dim)] = (sph_real)NAN;
    }
}

/* 2D tank of 60 x 40 water particles (parallel loops above 2048) with walls, `solver`, the
   force callback above; 3 clean steps, then the callback writes NaN for the listed ids. Returns
   the failing step's status; *index the particle named. */
static sph_status hs_force_run(int solver, int verlet, const hs_bad_force* bad_in, long* index,
                               char* msg) {
    sph_world_def d = sph_world_def_default(2);
    sph_world w;
    sph_phase water;
    hs_bad_force bad = *bad_in;
    sph_real lo[2] = {0, 0}, hi[2] = {1.2f, 0.8f}, whi[2] = {1.2f, 1.0f};
    sph_status s = SPH_OK;
    int q;
    memset(&water, 0, sizeof water);
    water.rest_density = 1000;
    if (solver == SPH_SOLVER_PCISPH) sph_world_def_pcisph(&d, 1);
    d.spacing = (sph_real)0.02;
    d.solver = (sph_solver)solver;
    if (verlet) d.integrator = SPH_INTEGRATOR_VERLET;
    d.force = hs_bad_force_fn;
    d.force_user = &bad;
    bad.armed = 0;
    if (sph_world_init(&w, &d) != SPH_OK || sph_world_add_phase(&w, &water) != 0 ||
        sph_fill_box(&w, 0, lo, hi) != SPH_OK ||
        sph_add_wall_box(&w, lo, whi, 0, SPH_FACE_YMAX) != SPH_OK ||
        sph_set_hydrostatic(&w) != SPH_OK) {
        CHECK_MSG(0, "setup: %s", w.error);
        sph_world_free(&w);
        return SPH_ERR_ARG;
    }
    for (q = 0; q < 4 && s == SPH_OK; ++q) {
        bad.armed = q == 3;
        s = th_step(&w, sph_stable_dt(&w, (sph_solver)solver));
        if (q < 3) CHECK_EQ_INT(s, SPH_OK);
    }
    *index = w.error_index;
    memcpy(msg, w.error, SPH_ERROR_SIZE);
    if (*index >= 0 && (size_t)*index < w.n) {
        /* the named particle is one the callback poisoned, and the lowest such index */
        size_t i, lowest = w.n;
        for (i = 0; i < w.n && lowest == w.n; ++i)
            for (q = 0; q < bad.count; ++q)
                if (w.id[i] == bad.ids[q]) {
                    lowest = i;
                    break;
                }
        CHECK_MSG((size_t)*index == lowest,
                  "named particle %ld, the lowest poisoned index is %zu: %s", *index, lowest,
                  w.error);
    }
    sph_world_free(&w);
    return s;
}

/* A force callback that writes NaN for id 7 fails the step naming index and id 7 and the
   callback, in WCSPH (Euler and Verlet), PCISPH, IISPH and the compressible step; with ids
   2300, 7 and 1200 poisoned the lowest index among them is named, the same for 1 and 2 threads.
   Before, the error named the lowest index the NaN had spread to (id 1 in the issue). */
static void test_force_callback_culprit(void) {
    static const int solvers[][2] = {{SPH_SOLVER_WCSPH, 0},
                                     {SPH_SOLVER_WCSPH, 1},
                                     {SPH_SOLVER_PCISPH, 1},
                                     {SPH_SOLVER_IISPH, 0},
                                     {SPH_SOLVER_COMPRESSIBLE, 0}};
    hs_bad_force one, three;
    char msg[SPH_ERROR_SIZE];
    long index = -1, index1 = -1;
    int q, threads;
#ifdef _OPENMP
    const int max_threads = omp_get_max_threads();
#endif
    memset(&one, 0, sizeof one);
    one.ids[0] = 7;
    one.count = 1;
    memset(&three, 0, sizeof three);
    three.ids[0] = 2300;
    three.ids[1] = 7;
    three.ids[2] = 1200;
    three.count = 3;
    for (q = 0; q < 5; ++q) {
        const sph_status s = hs_force_run(solvers[q][0], solvers[q][1], &one, &index, msg);
        CHECK_MSG(s == SPH_ERR_UNSTABLE, "solver %d: %s", solvers[q][0], msg);
        CHECK_MSG(strstr(msg, "force callback") && strstr(msg, "(id 7)"), "solver %d: %s",
                  solvers[q][0], msg);
    }
    TH_NOTE("%s", msg);
#ifdef _OPENMP
    for (threads = 1; threads <= 2; ++threads) {
        omp_set_num_threads(threads);
#else
    for (threads = 1; threads <= 1; ++threads) {
#endif
        CHECK_EQ_INT(hs_force_run(SPH_SOLVER_WCSPH, 0, &three, &index, msg), SPH_ERR_UNSTABLE);
        if (threads == 1) index1 = index;
        CHECK_EQ_INT(index, index1);
    }
#ifdef _OPENMP
    omp_set_num_threads(max_threads);
#endif
}

typedef struct hs_bad_motion {
    uint32_t id;
    unsigned calls;
} hs_bad_motion;

static void hs_bad_motion_fn(sph_world* w, double time, void* user) {
    hs_bad_motion* m = (hs_bad_motion*)user;
    size_t b;
    (void)time;
    if (++m->calls < 3) return;
    for (b = 0; b < w->nb; ++b)
        if (w->b_id[b] == m->id) w->b_v[b * (size_t)w->dim + 1] = (sph_real)NAN;
}

/* The boundary-motion callback's output was already checked right after the call: the error
   names the wall particle where the NaN was written (index and id 13). */
static void test_motion_callback_culprit(void) {
    sph_world_def d = sph_world_def_default(2);
    sph_world w;
    sph_phase water;
    hs_bad_motion m;
    sph_real lo[2] = {0, 0}, hi[2] = {0.4f, 0.2f}, whi[2] = {0.4f, 0.3f};
    sph_status s = SPH_OK;
    size_t b;
    int q;
    memset(&water, 0, sizeof water);
    water.rest_density = 1000;
    m.id = 13;
    m.calls = 0;
    d.spacing = (sph_real)0.02;
    d.boundary_motion = hs_bad_motion_fn;
    d.boundary_user = &m;
    CHECK(sph_world_init(&w, &d) == SPH_OK && sph_world_add_phase(&w, &water) == 0 &&
          sph_fill_box(&w, 0, lo, hi) == SPH_OK &&
          sph_add_wall_box(&w, lo, whi, 0, SPH_FACE_YMAX) == SPH_OK);
    for (q = 0; q < 3 && s == SPH_OK; ++q)
        s = th_step(&w, (sph_real)1e-4);
    CHECK_EQ_INT(s, SPH_ERR_ARG);
    CHECK_MSG(strstr(w.error, "(id 13)") && strstr(w.error, "boundary motion callback"), "%s",
              w.error);
    for (b = 0; b < w.nb && w.b_id[b] != 13; ++b) {}
    CHECK_EQ_INT(w.error_index, b);
    sph_world_free(&w);
}

/* check_walls' tank check: with one closed box of sph_add_wall_box, a fluid particle that ends
   a step more than a spacing outside it fails the step, named, with given and with Akinci wall
   volumes (the wall volume fraction covers given volumes only, and only inside the layers: a
   particle beyond them, or through a box with Akinci volumes, went on unreported; a 3D block
   sliding down a single-layer ramp into such a box lost one through the floor that fell for
   1.4 s). A host's fluid outside the box, or a second box, turns it off. Here the host moves a
   particle below the floor between steps, past the wall's layers. */
static void test_tank_check(void) {
    int vol, mode;
    for (vol = 0; vol < 2; ++vol)
        for (mode = 0; mode < 3; ++mode) {
            sph_world_def d = sph_world_def_default(2);
            sph_world w;
            sph_phase water;
            const sph_real lo[2] = {0, 0}, hi[2] = {(sph_real)0.4, (sph_real)0.4};
            const sph_real flo[2] = {0, 0}, fhi[2] = {(sph_real)0.2, (sph_real)0.2};
            const sph_real olo[2] = {(sph_real)0.6, 0}, ohi[2] = {(sph_real)0.7, (sph_real)0.1};
            sph_status s;
            size_t i;
            memset(&water, 0, sizeof water);
            water.rest_density = 1000;
            d.spacing = (sph_real)0.02;
            d.boundary_volume = vol ? SPH_BVOL_AKINCI : SPH_BVOL_GIVEN;
            CHECK(sph_world_init(&w, &d) == SPH_OK && sph_world_add_phase(&w, &water) == 0 &&
                  sph_fill_box(&w, 0, flo, fhi) == SPH_OK &&
                  sph_add_wall_box(&w, lo, hi, 0, 0) == SPH_OK);
            if (mode == 1) CHECK_EQ_INT(sph_fill_box(&w, 0, olo, ohi), SPH_OK); /* outside */
            if (mode == 2) CHECK_EQ_INT(sph_add_wall_box(&w, olo, ohi, 0, 0), SPH_OK);
            CHECK_EQ_INT(sph_set_hydrostatic(&w), SPH_OK);
            CHECK_EQ_INT(th_step(&w, sph_stable_dt(&w, d.solver)), SPH_OK);
            for (i = 0; i < w.n && w.id[i] != 7; ++i) {}
            w.x[2 * i + 1] = (sph_real)-0.2; /* 10 spacings below the floor's face */
            s = th_step(&w, sph_stable_dt(&w, d.solver));
            if (mode == 0) {
                CHECK_EQ_INT(s, SPH_ERR_UNSTABLE);
                CHECK_MSG(strstr(w.error, "(id 7)") && strstr(w.error, "outside the closed box"),
                          "%s", w.error);
            } else {
                CHECK_EQ_INT(s, SPH_OK); /* the box is not the fluid's container: no check */
            }
            sph_world_free(&w);
        }
}

/* Fluid added where fluid already is: the same box filled twice, or an array holding a particle
   twice (or within 1e-3 spacings of one), is refused with SPH_ERR_ARG and a message naming both
   particles (w.error_index the caller's, or for sph_fill_box the world's), nothing added
   (coincident particles have a zero kernel gradient between them and never separate: WCSPH ran
   a box filled twice at twice its weight without a sign, IISPH and DFSPH threw its particles at
   60 m/s). Close but not coincident is accepted: 0.3 spacings off,
   or particles of a new box that only touch the old one. 2D and 3D. */
static void test_coincident_refused(void) {
    int dim;
    for (dim = 2; dim <= 3; ++dim) {
        sph_world_def d = sph_world_def_default(dim);
        sph_world w;
        sph_phase water;
        const sph_real lo[3] = {0, 0, 0}, hi[3] = {(sph_real)0.2, (sph_real)0.2, (sph_real)0.2};
        const sph_real lo2[3] = {(sph_real)0.2, 0, 0},
                       hi2[3] = {(sph_real)0.3, (sph_real)0.2, (sph_real)0.2};
        const sph_real lo3[3] = {0, (sph_real)0.1, 0},
                       hi3[3] = {(sph_real)0.2, (sph_real)0.3, (sph_real)0.2};
        sph_real x[6];
        size_t n0;
        int k;
        memset(&water, 0, sizeof water);
        water.rest_density = 1000;
        d.spacing = (sph_real)0.02;
        CHECK(sph_world_init(&w, &d) == SPH_OK && sph_world_add_phase(&w, &water) == 0 &&
              sph_fill_box(&w, 0, lo, hi) == SPH_OK);
        n0 = w.n;
        CHECK_EQ_INT(sph_fill_box(&w, 0, lo, hi), SPH_ERR_ARG); /* the same box again */
        CHECK_MSG(strstr(w.error, "sph_fill_box") && strstr(w.error, "never separate"), "%s",
                  w.error);
        /* half of it again: w.error_index names the world's particle (the box's points are not
           the caller's; it named the box's own first point, found by tests/fuzz_api.c) */
        CHECK_EQ_INT(sph_fill_box(&w, 0, lo3, hi3), SPH_ERR_ARG);
        {
            char named[64];
            snprintf(named, sizeof named, "fluid particle %ld ", w.error_index);
            CHECK(w.error_index >= 0 && (size_t)w.error_index < n0);
            CHECK_MSG(strstr(w.error, named) != NULL, "%s: %s", named, w.error);
        }
        CHECK_EQ_INT(w.n, n0);
        /* one particle 1e-4 spacings from particle 5, one 0.3 spacings from particle 9 */
        for (k = 0; k < dim; ++k) {
            x[k] = w.x[5 * (size_t)dim + (size_t)k] + (sph_real)(k == 0 ? 2e-6 : 0);
            x[dim + k] = w.x[9 * (size_t)dim + (size_t)k] + (sph_real)(k == 1 ? 0.006 : 0);
        }
        CHECK_EQ_INT(sph_add_fluid(&w, 0, 2, x, NULL), SPH_ERR_ARG);
        CHECK_MSG(strstr(w.error, "particle 0 lies within") && strstr(w.error, "(id 5)"), "%s",
                  w.error);
        CHECK(w.error_index == 0); /* the caller's particle */
        CHECK_EQ_INT(w.n, n0);
        CHECK_EQ_INT(sph_add_fluid(&w, 0, 1, x + dim, NULL), SPH_OK); /* 0.3 dx off: accepted */
        CHECK_EQ_INT(w.n, n0 + 1);
        /* twice in one call, far from the rest */
        for (k = 0; k < dim; ++k) x[k] = x[dim + k] = (sph_real)(k == 0 ? 1.0 : 0.5);
        CHECK_EQ_INT(sph_add_fluid(&w, 0, 2, x, NULL), SPH_ERR_ARG);
        CHECK_MSG(strstr(w.error, "particles 1 and 0") || strstr(w.error, "particles 0 and 1"),
                  "%s", w.error);
        CHECK_EQ_INT(w.n, n0 + 1);
        /* a box beside the first, touching it: accepted */
        CHECK_EQ_INT(sph_fill_box(&w, 0, lo2, hi2), SPH_OK);
        sph_world_free(&w);
    }
}

/* Fluid added into fluid (an emitter spawning onto a pool): a tank at rest (0.4 m wide, water
   0.3 m deep, 2D dx 0.02 and 3D dx 0.04), after 0.5 s (3D: 0.25 s) a block of 5 x 5 (x 5) particles whose
   lowest row lies half a spacing above the top row, 0.3 spacings aside (densities up to 1.35
   rho0 where it overlaps). Through sph_advance with the defaults: IISPH and DFSPH push the
   block apart and run on for 1 s (3D: 0.5 s; every frame SPH_OK, nothing outside the tank, the
   mass with the block exact). Before, max_compression read their density at the step's start, the host's overlap,
   which no smaller step undoes: sph_advance failed at the block with "time step too large" after
   12 retries down to 5e-4 of the stable step, and every later call failed the same way. The
   original PCISPH runs on in 3D; in 2D it does not undo the overlap, and its failure says so
   (compressed at the step's start already) and leaves the world as it was. */
static void test_fluid_added_into_fluid(void) {
    static const int solvers[3] = {SPH_SOLVER_IISPH, SPH_SOLVER_DFSPH, SPH_SOLVER_PCISPH};
    int dim, q;
    for (dim = 2; dim <= 3; ++dim)
        for (q = 0; q < 3; ++q) {
            const double dx = dim == 2 ? 0.02 : 0.04, W = 0.4, H = 0.3;
            const int frames = dim == 2 ? 20 : 10; /* 1 s after the block (3D: 0.5 s) */
            sph_world_def d = sph_world_def_default(dim);
            sph_world w;
            sph_phase water;
            const sph_real lo[3] = {0, 0, 0}, hi[3] = {(sph_real)W, (sph_real)0.6, (sph_real)W},
                           fhi[3] = {(sph_real)W, (sph_real)H, (sph_real)W};
            sph_real xs[3 * 125];
            sph_status s = SPH_OK;
            size_t m = 0, i, out = 0;
            double m0, t_add;
            int a, b, c, f;
            memset(&water, 0, sizeof water);
            water.rest_density = 1000;
            d.solver = (sph_solver)solvers[q];
            d.spacing = (sph_real)dx;
            CHECK(sph_world_init(&w, &d) == SPH_OK && sph_world_add_phase(&w, &water) == 0 &&
                  sph_fill_box(&w, 0, lo, fhi) == SPH_OK &&
                  sph_add_wall_box(&w, lo, hi, 0, 0) == SPH_OK && sph_set_hydrostatic(&w) == SPH_OK);
            for (f = 0; f < frames / 2 && s == SPH_OK; ++f) s = sph_advance(&w, (sph_real)0.05);
            CHECK_MSG(s == SPH_OK, "%s", w.error);
            for (a = 0; a < 5; ++a)
                for (b = 0; b < 5; ++b)
                    for (c = 0; c < (dim == 3 ? 5 : 1); ++c, ++m) {
                        xs[m * (size_t)dim] = (sph_real)((5.3 + a) * dx);
                        xs[m * (size_t)dim + 1] = (sph_real)(H - 0.5 * dx + (0.5 + b) * dx);
                        if (dim == 3) xs[m * 3 + 2] = (sph_real)((5.3 + c) * dx);
                    }
            CHECK_EQ_INT(sph_add_fluid(&w, 0, m, xs, NULL), SPH_OK);
            m0 = sph_world_mass(&w);
            t_add = w.time;
            for (f = 0; f < frames && s == SPH_OK; ++f) {
                s = sph_advance(&w, (sph_real)0.05);
                for (i = 0; s == SPH_OK && i < w.n; ++i) {
                    int k;
                    for (k = 0; k < dim; ++k)
                        out += (double)w.x[i * (size_t)dim + (size_t)k] < -0.5 * dx ||
                               (k != 1 && (double)w.x[i * (size_t)dim + (size_t)k] > W + 0.5 * dx);
                }
            }
            TH_NOTE("%dD %s: fluid added into fluid at t = %.2f s: %s, t = %.2f s, %llu steps, "
                    "largest speed %.3f m/s", dim, solvers[q] == SPH_SOLVER_IISPH ? "IISPH"
                    : solvers[q] == SPH_SOLVER_DFSPH ? "DFSPH" : "PCISPH", t_add,
                    s == SPH_OK ? "ok" : w.error, w.time, (unsigned long long)w.steps,
                    (double)w.stats.v_max);
            if (solvers[q] == SPH_SOLVER_PCISPH && s != SPH_OK) {
                CHECK_EQ_INT(s, SPH_ERR_UNSTABLE);
                CHECK_MSG(strstr(w.error, "at the step's start already"), "%s", w.error);
                CHECK_NEAR(w.time, t_add, 0);
            } else {
                CHECK_MSG(s == SPH_OK, "%s", w.error);
                CHECK_EQ_INT(out, 0);
                CHECK_LE(fabs(sph_world_mass(&w) - m0), 1e-12 * m0);
                CHECK_NEAR(w.time, t_add + 0.05 * frames, 1e-6); /* frames of (sph_real)0.05 */
            }
            sph_world_free(&w);
        }
}

/* Fluid placed inside walls: a fill box reaching one spacing into sph_add_wall_box's layers (its
   outer rows on the first layer's particles), and a block of boundary particles a host places
   into a filled tank, are refused by the first step (sph_advance and sph_step_*) with
   SPH_ERR_ARG naming a particle "inside the wall layers", time and particles as before (not
   even sorted). Before,
   every solver failed that first step after all its retries as a compression or a speed (IISPH:
   a particle at 39 m/s), which pointed at the step size. Fluid a host places closer to a wall
   than the lattice's spacing but short of its first layer is left to the wall contact, and
   sph_advance's failure, if the step fails, now asks whether fluid and walls just added
   overlap. 2D and 3D. */
static void test_fluid_inside_walls(void) {
    int dim, mode;
    for (dim = 2; dim <= 3; ++dim)
        for (mode = 0; mode < 3; ++mode) {
            const double dx = dim == 2 ? 0.02 : 0.04;
            sph_world_def d = sph_world_def_default(dim);
            sph_world w;
            sph_phase water;
            const sph_real lo[3] = {0, 0, 0}, hi[3] = {(sph_real)0.4, (sph_real)0.6, (sph_real)0.4},
                           fin[3] = {(sph_real)-dx, (sph_real)-dx, (sph_real)-dx},
                           fhi[3] = {(sph_real)0.4, (sph_real)0.3, (sph_real)0.4};
            sph_real xb[3 * 64], *x0;
            size_t nb = 0, n0;
            sph_status s;
            int a, b, c;
            memset(&water, 0, sizeof water);
            water.rest_density = 1000;
            d.solver = mode == 2 ? SPH_SOLVER_WCSPH : SPH_SOLVER_IISPH;
            d.spacing = (sph_real)dx;
            CHECK(sph_world_init(&w, &d) == SPH_OK && sph_world_add_phase(&w, &water) == 0);
            CHECK_EQ_INT(sph_fill_box(&w, 0, mode == 0 ? fin : lo, fhi), SPH_OK);
            CHECK_EQ_INT(sph_add_wall_box(&w, lo, hi, 0, 0), SPH_OK);
            if (mode > 0) { /* a 4 x 4 (x 4) block on the fluid's lattice, in the fluid */
                for (a = 0; a < 4; ++a)
                    for (b = 0; b < 4; ++b)
                        for (c = 0; c < (dim == 3 ? 4 : 1); ++c, ++nb) {
                            xb[nb * (size_t)dim] = (sph_real)((4.5 + a) * dx);
                            xb[nb * (size_t)dim + 1] = (sph_real)((2.5 + b) * dx);
                            if (dim == 3) xb[nb * 3 + 2] = (sph_real)((4.5 + c) * dx);
                        }
                CHECK_EQ_INT(sph_add_boundary(&w, nb, xb, NULL, 1), SPH_OK);
            }
            n0 = w.n;
            x0 = (sph_real*)malloc(n0 * (size_t)dim * sizeof(sph_real));
            memcpy(x0, w.x, n0 * (size_t)dim * sizeof(sph_real));
            s = mode == 1 ? sph_step_iisph(&w, (sph_real)1e-3) : sph_advance(&w, (sph_real)0.05);
            TH_NOTE("%dD %s: %s", dim, mode == 0 ? "fill box into the walls" : "block into the fluid",
                    w.error);
            CHECK_EQ_INT(s, SPH_ERR_ARG);
            CHECK_MSG(strstr(w.error, "inside the wall layers") != NULL, "%s", w.error);
            CHECK_NEAR(w.time, 0, 0);
            CHECK_EQ_INT(w.n, n0);
            CHECK(memcmp(x0, w.x, n0 * (size_t)dim * sizeof(sph_real)) == 0); /* not even sorted */
            free(x0);
            sph_world_free(&w);
        }
}

/* Phases of different rest density under IISPH and DFSPH, which sum the density (smearing the
   mass jump between phases): light fluid (800, then 700 kg/m^3) layered over water in a tank,
   0.4 m wide, 0.16 + 0.14 m deep, dx 0.02, through sph_advance. At a ratio of 0.8 they run
   (0.5 s, nothing outside, the energy not above its start by more than 0.01 M g dx); below 0.75
   (SPH__SUMMED_RATIO_MIN) the first call is refused with SPH_ERR_ARG naming the ratio, the world
   unchanged. Before, a light blob of 0.5 rising in water gained 0.4-0.6 M g dx in its first
   second and one of 0.2 reached 21 m/s in its first frame, every frame SPH_OK. */
static void test_summed_density_phase_ratio(void) {
    static const int solvers[2] = {SPH_SOLVER_IISPH, SPH_SOLVER_DFSPH};
    int q, light;
    for (q = 0; q < 2; ++q)
        for (light = 800; light >= 700; light -= 100) {
            const double dx = 0.02;
            sph_world_def d = sph_world_def_default(2);
            sph_world w;
            sph_phase water, oil;
            const sph_real lo[2] = {0, 0}, hi[2] = {(sph_real)0.4, (sph_real)0.5},
                           mid[2] = {(sph_real)0.4, (sph_real)0.16},
                           lo2[2] = {0, (sph_real)0.16}, top[2] = {(sph_real)0.4, (sph_real)0.3};
            double e0 = 0, e_max = -1e300, M;
            sph_status s = SPH_OK;
            size_t i, out = 0;
            int f;
            memset(&water, 0, sizeof water);
            memset(&oil, 0, sizeof oil);
            water.rest_density = 1000;
            oil.rest_density = (sph_real)light;
            d.solver = (sph_solver)solvers[q];
            d.spacing = (sph_real)dx;
            CHECK(sph_world_init(&w, &d) == SPH_OK && sph_world_add_phase(&w, &water) == 0 &&
                  sph_world_add_phase(&w, &oil) == 1 && sph_fill_box(&w, 0, lo, mid) == SPH_OK &&
                  sph_fill_box(&w, 1, lo2, top) == SPH_OK &&
                  sph_add_wall_box(&w, lo, hi, 0, 0) == SPH_OK && sph_set_hydrostatic(&w) == SPH_OK);
            M = sph_world_mass(&w);
            for (i = 0; i < w.n; ++i)
                e0 += (double)(w.m ? w.m[i] : w.mass) * 9.81 * (double)w.x[2 * i + 1];
            for (f = 0; f < 10 && s == SPH_OK; ++f) {
                double e;
                s = sph_advance(&w, (sph_real)0.05);
                if (s != SPH_OK) break;
                e = w.stats.kinetic_energy;
                for (i = 0; i < w.n; ++i) {
                    const double x = (double)w.x[2 * i], y = (double)w.x[2 * i + 1];
                    e += (double)(w.m ? w.m[i] : w.mass) * 9.81 * y;
                    out += x < -0.5 * dx || x > 0.4 + 0.5 * dx || y < -0.5 * dx;
                }
                if (e > e_max) e_max = e;
            }
            TH_NOTE("%s, rest densities %d and 1000: %s; energy above its start %.3g M g dx",
                    solvers[q] == SPH_SOLVER_IISPH ? "IISPH" : "DFSPH", light,
                    s == SPH_OK ? "ok" : w.error, s == SPH_OK ? (e_max - e0) / (M * 9.81 * dx) : 0.0);
            if (light == 800) {
                CHECK_MSG(s == SPH_OK, "%s", w.error);
                CHECK_EQ_INT(out, 0);
                CHECK_LE(e_max - e0, 0.01 * M * 9.81 * dx);
            } else {
                CHECK_EQ_INT(s, SPH_ERR_ARG);
                CHECK_MSG(strstr(w.error, "ratio 0.7") != NULL, "%s", w.error);
                CHECK_NEAR(w.time, 0, 0);
            }
            sph_world_free(&w);
        }
}

/* A derived sound speed follows fluid added after it was derived: a pool (0.6 m wide, 0.1 m
   deep) set hydrostatic, which derives c0 = 10 sqrt(2 g H) from the pool alone (14 m/s), then a
   block of water 0.4 m above it, WCSPH with the defaults through sph_advance for 0.6 s (2D dx
   0.02, 3D dx 0.04). The first step derives c0 again with the block's fall counted (36 m/s) and
   keeps the larger: the largest compression at a frame end 0.85 % (2D) and 2.9 % (3D) against
   6.4 % and 8.8 % with the pool's c0, 2.4 and 2.3 times the sub-steps (a ball dropped into a
   pool the same way in 3D failed at the impact, compressed to 1.2 rho0 after 38 retries). */
static void test_sound_speed_follows_added_fluid(void) {
    int dim;
    for (dim = 2; dim <= 3; ++dim) {
        const double dx = dim == 2 ? 0.02 : 0.04;
        sph_world_def d = sph_world_def_default(dim);
        sph_world w;
        sph_phase water;
        const sph_real lo[3] = {0, 0, 0}, hi[3] = {(sph_real)0.6, (sph_real)0.8, (sph_real)0.6},
                       fhi[3] = {(sph_real)0.6, (sph_real)0.1, (sph_real)0.6},
                       blo[3] = {(sph_real)0.2, (sph_real)0.5, (sph_real)0.2},
                       bhi[3] = {(sph_real)0.36, (sph_real)0.66, (sph_real)0.36};
        double c_pool, comp = 0, ylo = 1e300, yhi = -1e300;
        sph_status s = SPH_OK;
        size_t i;
        int f;
        memset(&water, 0, sizeof water);
        water.rest_density = 1000;
        d.spacing = (sph_real)dx;
        CHECK(sph_world_init(&w, &d) == SPH_OK && sph_world_add_phase(&w, &water) == 0 &&
              sph_fill_box(&w, 0, lo, fhi) == SPH_OK &&
              sph_add_wall_box(&w, lo, hi, 0, 0) == SPH_OK && sph_set_hydrostatic(&w) == SPH_OK);
        c_pool = (double)w.phases[0].sound_speed;
        CHECK_EQ_INT(sph_fill_box(&w, 0, blo, bhi), SPH_OK);
        for (i = 0; i < w.n; ++i) {
            ylo = fmin(ylo, (double)w.x[i * (size_t)dim + 1]);
            yhi = fmax(yhi, (double)w.x[i * (size_t)dim + 1]);
        }
        for (f = 0; f < 12 && s == SPH_OK; ++f) {
            s = sph_advance(&w, (sph_real)0.05);
            for (i = 0; i < w.n; ++i) comp = fmax(comp, (double)w.rho[i] / 1000 - 1);
        }
        TH_NOTE("%dD: c0 %.2f -> %.2f m/s, largest compression at a frame end %.4f: %s", dim,
                c_pool, (double)w.phases[0].sound_speed, comp, s == SPH_OK ? "ok" : w.error);
        CHECK_MSG(s == SPH_OK, "%s", w.error);
        /* 10 sqrt(2 g H), H the fluid's extent (block top to pool floor, centres) plus dx */
        CHECK_NEAR((double)w.phases[0].sound_speed, 10 * sqrt(2 * 9.81 * (yhi - ylo + dx)), 1e-3);
        CHECK_LT(comp, 0.05);
        sph_world_free(&w);
    }
}

/* An incompressible solver needs no sound speed: a block of water at rest with no gravity, no
   walls, viscosity 0.01 m^2/s and sound_speed = 0 (nothing to derive c0 from), IISPH, original PCISPH, DFSPH and PBF,
   2D (dx 0.02) and 3D (dx 0.04), 10 steps of sph_step at sph_stable_dt, then 0.1 s of
   sph_advance. Every call returns SPH_OK with an empty w.error, and the block stays at rest.
   Before, the step that did not settle the start (the second) kept the failed derivation's
   SPH_ERR_ARG as its result with the message wiped (found by tests/fuzz_world.c). */
static void test_incompressible_without_sound_speed(void) {
    static const sph_solver solvers[4] = {SPH_SOLVER_IISPH, SPH_SOLVER_PCISPH, SPH_SOLVER_DFSPH,
                                          SPH_SOLVER_PBF};
    int dim, k, step;
    for (dim = 2; dim <= 3; ++dim)
        for (k = 0; k < 4; ++k) {
            const double dx = dim == 2 ? 0.02 : 0.04;
            sph_world_def d = sph_world_def_default(dim);
            sph_world w;
            sph_phase water;
            const sph_real lo[3] = {0, 0, 0}, hi[3] = {(sph_real)0.2, (sph_real)0.2, (sph_real)0.2};
            sph_status s = SPH_OK;
            if (solvers[k] == SPH_SOLVER_PCISPH) sph_world_def_pcisph(&d, 0);
            d.solver = solvers[k];
            d.spacing = (sph_real)dx;
            d.gravity[1] = 0;
            memset(&water, 0, sizeof water);
            water.rest_density = 1000;
            water.viscosity = (sph_real)0.01; /* the one thing that limits the step here */
            CHECK(sph_world_init(&w, &d) == SPH_OK && sph_world_add_phase(&w, &water) == 0 &&
                  sph_fill_box(&w, 0, lo, hi) == SPH_OK);
            for (step = 0; step < 10 && s == SPH_OK; ++step) {
                const sph_real dt = sph_stable_dt(&w, solvers[k]);
                CHECK_MSG(dt > 0 && w.error[0] == 0, "sph_stable_dt: %g, '%s'", (double)dt, w.error);
                s = sph_step(&w, dt);
                CHECK_MSG(s == SPH_OK, "%dD solver %d, step %d: %s '%s'", dim, (int)solvers[k], step,
                          sph_status_string(s), w.error);
            }
            if (s == SPH_OK) s = sph_advance(&w, (sph_real)0.1);
            CHECK_MSG(s == SPH_OK, "%dD solver %d, sph_advance: %s '%s'", dim, (int)solvers[k],
                      sph_status_string(s), w.error);
            CHECK_EQ_INT(w.status, SPH_OK);
            CHECK(w.error[0] == 0);
            CHECK_LT(w.stats.v_max, 1e-3);
            TH_NOTE("%dD solver %d: t = %.3f s, %d steps, largest speed %.2g m/s", dim,
                    (int)solvers[k], w.time, (int)w.steps, (double)w.stats.v_max);
            sph_world_free(&w);
        }
}

/* SPH_PGRAD_DIFFERENCE at a free surface: a tank at rest (0.4 m wide, 0.3 m of water in a box of
   sph_add_wall_box, 0.6 m high, WCSPH's defaults but this gradient), 2D (dx 0.02) and 3D (dx
   0.04). The form takes no pressure from the empty side, so the rows under the surface sink:
   before, the 2D tank moved at 1.4 m/s with 22 % compression after 0.05 s, every frame SPH_OK,
   and failed at 0.13 s. Now the first call is refused (SPH_ERR_ARG naming a surface particle,
   the world unchanged), while the same box filled to its lid (no free surface; the form's use,
   tests/test_rt.c) runs 0.1 s with nothing moving faster than 1 % of sqrt(g H). */
static void test_difference_free_surface(void) {
    int dim, full;
    for (dim = 2; dim <= 3; ++dim)
        for (full = 0; full <= 1; ++full) {
            const double dx = dim == 2 ? 0.02 : 0.04, H = full ? 0.6 : 0.3;
            sph_world_def d = sph_world_def_default(dim);
            sph_world w;
            sph_phase water;
            const sph_real lo[3] = {0, 0, 0}, hi[3] = {(sph_real)0.4, (sph_real)0.6, (sph_real)0.4},
                           fhi[3] = {(sph_real)0.4, (sph_real)H, (sph_real)0.4};
            sph_real* x0;
            size_t n0;
            sph_status s;
            memset(&water, 0, sizeof water);
            water.rest_density = 1000;
            d.spacing = (sph_real)dx;
            d.pressure_grad = SPH_PGRAD_DIFFERENCE;
            d.density = SPH_DENSITY_PARTICLE; /* as the manual recommends it (sph.h, PHASES) */
            CHECK(sph_world_init(&w, &d) == SPH_OK && sph_world_add_phase(&w, &water) == 0);
            CHECK_EQ_INT(sph_fill_box(&w, 0, lo, fhi), SPH_OK);
            CHECK_EQ_INT(sph_add_wall_box(&w, lo, hi, 0, 0), SPH_OK);
            CHECK_EQ_INT(sph_set_hydrostatic(&w), SPH_OK);
            n0 = w.n;
            x0 = (sph_real*)malloc(n0 * (size_t)dim * sizeof(sph_real));
            memcpy(x0, w.x, n0 * (size_t)dim * sizeof(sph_real));
            s = sph_advance(&w, (sph_real)0.1);
            if (!full) {
                TH_NOTE("%dD tank with a free surface: %s", dim, w.error);
                CHECK_EQ_INT(s, SPH_ERR_ARG);
                CHECK_MSG(strstr(w.error, "free surface") != NULL, "%s", w.error);
                CHECK_NEAR(w.time, 0, 0);
                CHECK(memcmp(x0, w.x, n0 * (size_t)dim * sizeof(sph_real)) == 0);
            } else {
                CHECK_MSG(s == SPH_OK, "%dD filled box: %s", dim, w.error);
                CHECK_LT(w.stats.v_max, 0.01 * sqrt(9.81 * H));
                TH_NOTE("%dD box filled to its lid: 0.1 s, largest speed %.2g sqrt(g H)", dim,
                        (double)w.stats.v_max / sqrt(9.81 * H));
            }
            free(x0);
            sph_world_free(&w);
        }
}

const th_test tests_hostile[] = {
    {"hostile/difference_gradient_free_surface_refused", test_difference_free_surface},
    {"hostile/sound_speed_follows_added_fluid", test_sound_speed_follows_added_fluid},
    {"hostile/incompressible_without_sound_speed", test_incompressible_without_sound_speed},
    {"hostile/summed_density_phase_ratio", test_summed_density_phase_ratio},
    {"hostile/fluid_inside_walls_refused", test_fluid_inside_walls},
    {"hostile/fluid_added_into_fluid", test_fluid_added_into_fluid},
    {"hostile/coincident_fluid_refused", test_coincident_refused},
    {"hostile/tank_check_names_escaped_particle", test_tank_check},
    {"hostile/wall_box_matches_lattice_walk", test_wall_box_matches_lattice_walk},
    {"hostile/wall_box_cost_follows_surface", test_wall_box_cost_follows_surface},
    {"hostile/wall_box_zero_volume_refused", test_wall_box_zero_volume},
    {"hostile/load_checks_every_field", test_load_checks_fields},
    {"hostile/far_tank_stays_in_walls_at_the_limit", test_far_tank},
    {"hostile/far_coordinates_rejected", test_far_coordinates_rejected},
    {"hostile/periodic_grid_far_points", test_periodic_grid_far_points},
    {"hostile/force_callback_culprit_named", test_force_callback_culprit},
    {"hostile/motion_callback_culprit_named", test_motion_callback_culprit},
    {0, 0},
};
