/* tests/test_hostile.c - hostile input (issue 19): loaded files checked like the API's input,
   coordinates too far from the origin for the spacing, wall boxes at O(surface) cost, periodic
   grids with points far outside the box, the force callback named when it writes a non-finite
   value. Each test failed on the sph.h before its fix. */
#include "harness.h"
#include "alloc.h"
#include "../sph.h"

#include <math.h>
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
    if (!pts || !vol) { nw = (size_t)-1; goto done; }
    for (i = 0; i < total; ++i) {
        size_t r = i, ix[3] = {0, 0, 0};
        int outside = 0, open = 0;
        sph_real V = 1;
        for (k = 0; k < dim; ++k) { ix[k] = r % cnt[k]; r /= cnt[k]; }
        for (k = 0; k < dim; ++k) {
            int sd = side[k][ix[k]];
            if (sd != 0) outside = 1;
            if (sd < 0 && (open_faces & (1u << (2 * k)))) open = 1;
            if (sd > 0 && (open_faces & (1u << (2 * k + 1)))) open = 1;
            V *= width[k][ix[k]];
        }
        if (!outside || open) continue;
        for (k = 0; k < dim; ++k) pts[nw * (size_t)dim + (size_t)k] = coord[k][ix[k]];
        vol[nw++] = V;
    }
done:
    for (k = 0; k < 3; ++k) { free(coord[k]); free(width[k]); free(side[k]); }
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
        {0, 0, 0, 1.0, 0.5, 0.3},          {-0.13, 0.07, 0.2, 0.313, 0.52, 0.61},
        {0, 0, 0, 0.05, 0.05, 0.05},       {1.0, -2.0, 3.0, 1.031, -1.71, 3.047},
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
                    if (sph_world_init(&w, &d) != SPH_OK) { CHECK(0); return; }
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
                            CHECK_MSG(0, "dim %d box %d layers %d open %u: %zu wall particles, "
                                      "the lattice walk gives %zu", dim, bx, layer_set[li], open,
                                      w.nb - nb0, nref);
                            ++mismatches;
                        } else {
                            int same = memcmp(w.b_x + nb0 * (size_t)dim, pts,
                                              nref * (size_t)dim * sizeof(sph_real)) == 0 &&
                                       memcmp(w.b_vol + nb0, vol, nref * sizeof(sph_real)) == 0;
                            for (b = nb0; b < w.nb; ++b)
                                if (w.b_id[b] != (uint32_t)b || w.b_body[b] != 0) same = 0;
                            if (!same) {
                                CHECK_MSG(0, "dim %d box %d layers %d open %u: positions, "
                                          "volumes or ids differ", dim, bx, layer_set[li], open);
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

/* A box whose lattice the old walk could not even allocate: 2D, 1e5 x 1e5 spacings (1e10
   lattice points, SPH_ERR_CAPACITY before; 4e5 wall particles), and a 3D open box of 600^3
   spacings with only its floor and one side closed (2.2e8 lattice points: 7 GB of scratch and
   seconds before; 7.3e5 wall particles). Both take well under a second now. The capacity rule
   counts wall particles: a 3D closed box of 1e6^3 spacings (6e12 walls) is refused before it
   allocates anything. */
static void test_wall_box_cost_follows_surface(void) {
    sph_world w;
    sph_world_def d = sph_world_def_default(2);
    sph_real lo[3] = {0, 0, 0}, hi[3] = {1000, 1000, 0};
    double t0, t;
    unsigned long allocs;
    d.spacing = (sph_real)0.01;
    CHECK_EQ_INT(sph_world_init(&w, &d), SPH_OK);
    t0 = hs_now();
    CHECK_EQ_INT(sph_add_wall_box(&w, lo, hi, 1, 0), SPH_OK);
    t = hs_now() - t0;
    CHECK_EQ_INT(w.nb, 100002ull * 100002ull - 100000ull * 100000ull);
    CHECK_LT(t, 2.0);
    TH_NOTE("2D 1e5 x 1e5 spacings, 1 layer: %zu wall particles in %.3f s", w.nb, t);
    sph_world_free(&w);

    d = sph_world_def_default(3);
    d.spacing = (sph_real)0.01;
    hi[0] = hi[1] = hi[2] = 6;
    CHECK_EQ_INT(sph_world_init(&w, &d), SPH_OK);
    t0 = hs_now();
    CHECK_EQ_INT(sph_add_wall_box(&w, lo, hi, 1,
                                  SPH_FACE_XMAX | SPH_FACE_YMAX | SPH_FACE_ZMIN | SPH_FACE_ZMAX),
                 SPH_OK);
    t = hs_now() - t0;
    /* floor (y layer below, x from the closed layer through the box) and the xmin side */
    CHECK_EQ_INT(w.nb, 601 * 600 + 600 * 600);
    CHECK_LT(t, 2.0);
    TH_NOTE("3D 600^3 spacings, floor and one side: %zu wall particles in %.3f s", w.nb, t);
    hi[0] = hi[1] = hi[2] = 1e4; /* 1e6 spacings per side */
    th_alloc_fail_at(0);
    CHECK_EQ_INT(sph_add_wall_box(&w, lo, hi, 1, 0), SPH_ERR_CAPACITY);
    allocs = th_alloc_count();
    CHECK_EQ_INT(allocs, 0);
    CHECK(strstr(w.error, "wall particles") != NULL);
    CHECK_EQ_INT(w.nb, 601 * 600 + 600 * 600);
    sph_world_free(&w);
}

const th_test tests_hostile[] = {
    {"hostile/wall_box_matches_lattice_walk", test_wall_box_matches_lattice_walk},
    {"hostile/wall_box_cost_follows_surface", test_wall_box_cost_follows_surface},
    {0, 0},
};
