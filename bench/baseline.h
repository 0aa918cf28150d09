/* bench/baseline.h - the reference implementation sph.h's speed is measured against.

   A straightforward gather implementation of the same WCSPH step sph.h takes with its defaults
   (symplectic Euler, continuity density with delta-SPH, Tait equation of state, symmetric
   pressure gradient, Monaghan artificial viscosity, Adami et al. 2012 wall pressure
   extrapolation, free-slip walls, Wendland C2), written the way a first working code is written:
     - a fixed-radius cell grid rebuilt every step by a counting sort of particle *indices*; the
       particle data stay in their original order (no reordering by cell);
     - neighbour lists rebuilt every step into fixed-capacity rows (MAXNB per particle), one
       distance test per candidate in the 3^d cells around the particle;
     - one loop per quantity (pressure, wall extrapolation, forces, kick, density rate, drift),
       each an OpenMP parallel for, with the dimension a run-time loop bound;
     - no effort for vectorisation or memory layout.
   It takes its initial state, kernel and phase constants from an sph_world, so both codes start
   from the same particles; bench checks that they then agree (the same step to round-off),
   which is what makes the speed ratio a fair one.
   Include after sph.h and bench_types.h (bench_now). Only Wendland C2 and one liquid phase with gamma = 7 are supported. */
#ifndef SPH_BENCH_BASELINE_H
#define SPH_BENCH_BASELINE_H

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* OpenMP loops only when built with it (no unknown-pragma warnings without) */
#if defined(_OPENMP)
#define BASE_PRAGMA(x) _Pragma(#x)
#else
#define BASE_PRAGMA(x)
#endif

#define BASE_MAXNB 128 /* list row capacity: 3D at h = 1.3 dx has ~76 neighbours */

typedef struct base_grid {
    int dim, ext[3];
    sph_real lo[3], cell;
    size_t ncell, cap_cell, cap_n;
    uint32_t* start;   /* [ncell + 1] */
    uint32_t* item;    /* [n] particle indices, grouped by cell */
    uint32_t* cell_of; /* [n] */
} base_grid;

typedef struct base_world {
    int dim;
    size_t n, nb;
    sph_real *x, *v, *rho, *p, *a, *drho; /* fluid, x[i*dim + k] */
    sph_real *bx, *bvol, *bp, *bkap;      /* walls: position, volume, pressure, rho_b/rho0 */
    uint32_t* id;
    base_grid gf, gb;
    uint32_t *ff, *ffn, *fb, *fbn, *bf, *bfn; /* neighbour rows of BASE_MAXNB */
    /* constants */
    sph_real m, rho0, B, pback, c0, h, R, inv_h, norm_w, norm_g, alpha, delta, eta2, g[3];
    double t_grid, t_lists, t_density, t_forces, t_other; /* seconds, accumulated */
    int overflow;
} base_world;


static void base__grid_free(base_grid* g) {
    free(g->start);
    free(g->item);
    free(g->cell_of);
    memset(g, 0, sizeof(*g));
}

static void base_free(base_world* b) {
    free(b->x);
    free(b->v);
    free(b->rho);
    free(b->p);
    free(b->a);
    free(b->drho);
    free(b->bx);
    free(b->bvol);
    free(b->bp);
    free(b->bkap);
    free(b->id);
    free(b->ff);
    free(b->ffn);
    free(b->fb);
    free(b->fbn);
    free(b->bf);
    free(b->bfn);
    base__grid_free(&b->gf);
    base__grid_free(&b->gb);
    memset(b, 0, sizeof(*b));
}

/* Copies the state of w (one liquid phase, Wendland C2, WCSPH defaults). Returns 0 on failure. */
static int base_init(base_world* b, const sph_world* w) {
    const size_t D = (size_t)w->dim;
    const sph_phase* P = &w->phases[0];
    int k;
    memset(b, 0, sizeof(*b));
    if (w->nphase != 1 || P->gamma != 7 || w->def.kernel != SPH_KERNEL_WENDLAND_C2 || w->m)
        return 0;
    b->dim = w->dim;
    b->n = w->n;
    b->nb = w->nb;
#define BASE__ARR(p, cnt) ((p) = (sph_real*)calloc((cnt) + 1, sizeof(sph_real)))
    if (!BASE__ARR(b->x, b->n * D) || !BASE__ARR(b->v, b->n * D) || !BASE__ARR(b->rho, b->n) ||
        !BASE__ARR(b->p, b->n) || !BASE__ARR(b->a, b->n * D) || !BASE__ARR(b->drho, b->n) ||
        !BASE__ARR(b->bx, b->nb * D) || !BASE__ARR(b->bvol, b->nb) || !BASE__ARR(b->bp, b->nb) ||
        !BASE__ARR(b->bkap, b->nb)) {
        base_free(b);
        return 0;
    }
#undef BASE__ARR
    b->id = (uint32_t*)calloc(b->n + 1, sizeof(uint32_t));
    b->ff = (uint32_t*)malloc((b->n + 1) * BASE_MAXNB * sizeof(uint32_t));
    b->fb = (uint32_t*)malloc((b->n + 1) * BASE_MAXNB * sizeof(uint32_t));
    b->bf = (uint32_t*)malloc((b->nb + 1) * BASE_MAXNB * sizeof(uint32_t));
    b->ffn = (uint32_t*)calloc(b->n + 1, sizeof(uint32_t));
    b->fbn = (uint32_t*)calloc(b->n + 1, sizeof(uint32_t));
    b->bfn = (uint32_t*)calloc(b->nb + 1, sizeof(uint32_t));
    if (!b->id || !b->ff || !b->fb || !b->bf || !b->ffn || !b->fbn || !b->bfn) {
        base_free(b);
        return 0;
    }
    memcpy(b->x, w->x, b->n * D * sizeof(sph_real));
    memcpy(b->v, w->v, b->n * D * sizeof(sph_real));
    memcpy(b->rho, w->rho, b->n * sizeof(sph_real));
    memcpy(b->id, w->id, b->n * sizeof(uint32_t));
    if (b->nb) {
        memcpy(b->bx, w->b_x, b->nb * D * sizeof(sph_real));
        memcpy(b->bvol, w->b_vol, b->nb * sizeof(sph_real));
    }
    b->m = w->mass;
    b->rho0 = P->rest_density;
    b->c0 = P->sound_speed;
    b->B = P->rest_density * P->sound_speed * P->sound_speed / 7;
    b->pback = P->back_pressure;
    b->h = w->h;
    b->R = w->kernel.radius;
    b->inv_h = 1 / w->h;
    b->norm_w = w->kernel.norm_w;
    b->norm_g = w->kernel.norm_g;
    b->alpha = w->def.alpha;
    b->delta = w->def.delta;
    b->eta2 = (sph_real)0.01 * w->h * w->h;
    for (k = 0; k < 3; ++k)
        b->g[k] = k < w->dim ? w->def.gravity[k] : 0;
    return 1;
}

/* Wendland C2 (d = 2, 3 share the form): W = norm_w (1 - q/2)^4 (2q + 1); grad W = F x_ij with
   F = norm_g (-5 (1 - q/2)^3), the same normalisations sph.h uses. */
static sph_real base__W(const base_world* b, sph_real r) {
    const sph_real q = r * b->inv_h, t = 1 - (sph_real)0.5 * q;
    return q < 2 ? b->norm_w * t * t * t * t * (2 * q + 1) : 0;
}
static sph_real base__F(const base_world* b, sph_real r) {
    const sph_real q = r * b->inv_h, t = 1 - (sph_real)0.5 * q;
    return q < 2 ? b->norm_g * (-5 * t * t * t) : 0;
}

/* Counting sort of point indices into cells of size R over the points' bounding box. */
static int base__grid_build(base_grid* g, int dim, const sph_real* x, size_t n, sph_real R) {
    sph_real hi[3];
    size_t i, c;
    int k;
    g->dim = dim;
    g->cell = R;
    for (k = 0; k < 3; ++k) {
        g->lo[k] = 0;
        hi[k] = 0;
        g->ext[k] = 1;
    }
    for (k = 0; k < dim; ++k) {
        g->lo[k] = n ? x[k] : 0;
        hi[k] = g->lo[k];
    }
    for (i = 0; i < n; ++i)
        for (k = 0; k < dim; ++k) {
            const sph_real v = x[i * (size_t)dim + (size_t)k];
            if (v < g->lo[k]) g->lo[k] = v;
            if (v > hi[k]) hi[k] = v;
        }
    g->ncell = 1;
    for (k = 0; k < dim; ++k) {
        g->ext[k] = (int)((hi[k] - g->lo[k]) / R) + 1;
        g->ncell *= (size_t)g->ext[k];
    }
    if (g->ncell + 1 > g->cap_cell) {
        free(g->start);
        g->start = (uint32_t*)malloc((g->ncell + 1) * sizeof(uint32_t));
        g->cap_cell = g->start ? g->ncell + 1 : 0;
        if (!g->start) return 0;
    }
    if (n > g->cap_n) {
        free(g->item);
        free(g->cell_of);
        g->item = (uint32_t*)malloc(n * sizeof(uint32_t));
        g->cell_of = (uint32_t*)malloc(n * sizeof(uint32_t));
        g->cap_n = (g->item && g->cell_of) ? n : 0;
        if (!g->cap_n) return 0;
    }
    memset(g->start, 0, (g->ncell + 1) * sizeof(uint32_t));
    for (i = 0; i < n; ++i) {
        size_t cell = 0;
        for (k = dim - 1; k >= 0; --k)
            cell = cell * (size_t)g->ext[k] +
                   (size_t)((x[i * (size_t)dim + (size_t)k] - g->lo[k]) / R);
        g->cell_of[i] = (uint32_t)cell;
        g->start[cell + 1]++;
    }
    for (c = 0; c < g->ncell; ++c)
        g->start[c + 1] += g->start[c];
    for (i = 0; i < n; ++i)
        g->item[g->start[g->cell_of[i]]++] = (uint32_t)i;
    for (c = g->ncell; c > 0; --c)
        g->start[c] = g->start[c - 1]; /* undo the shift */
    g->start[0] = 0;
    return 1;
}

/* Row i of `out` lists the points of grid g (positions y) within R of query point xi. */
static void base__lists(base_world* b, const base_grid* g, const sph_real* y, const sph_real* xq,
                        size_t nq, int exclude_self, uint32_t* out, uint32_t* cnt) {
    const int D = b->dim;
    const sph_real R2 = b->R * b->R;
    long i;
    int overflow = 0;
BASE_PRAGMA(omp parallel for schedule(static) reduction(| : overflow))
    for (i = 0; i < (long)nq; ++i) {
        const sph_real* xi = xq + (size_t)i * (size_t)D;
        int c[3] = {0, 0, 0}, o[3], k;
        uint32_t count = 0;
        for (k = 0; k < D; ++k) {
            c[k] = (int)floor((xi[k] - g->lo[k]) / g->cell);
        }
        for (o[2] = (D > 2 ? -1 : 0); o[2] <= (D > 2 ? 1 : 0); ++o[2])
            for (o[1] = (D > 1 ? -1 : 0); o[1] <= (D > 1 ? 1 : 0); ++o[1])
                for (o[0] = -1; o[0] <= 1; ++o[0]) {
                    size_t cell = 0, q;
                    int inside = 1;
                    for (k = D - 1; k >= 0; --k) {
                        const int ck = c[k] + o[k];
                        if (ck < 0 || ck >= g->ext[k]) inside = 0;
                        cell = cell * (size_t)g->ext[k] + (size_t)(ck < 0 ? 0 : ck);
                    }
                    if (!inside) continue;
                    for (q = g->start[cell]; q < g->start[cell + 1]; ++q) {
                        const uint32_t j = g->item[q];
                        sph_real r2 = 0;
                        if (exclude_self && j == (uint32_t)i) continue;
                        for (k = 0; k < D; ++k) {
                            const sph_real d = xi[k] - y[(size_t)j * (size_t)D + (size_t)k];
                            r2 += d * d;
                        }
                        if (r2 < R2) {
                            if (count < BASE_MAXNB)
                                out[(size_t)i * BASE_MAXNB + count] = j;
                            else
                                overflow = 1;
                            ++count;
                        }
                    }
                }
        cnt[i] = count < BASE_MAXNB ? count : BASE_MAXNB;
    }
    if (overflow) b->overflow = 1;
}

static sph_real base__kap(const base_world* b, sph_real p) { /* rho/rho0 for pressure p (Tait) */
    const sph_real t = (p - b->pback) / b->B + 1;
    const sph_real k = t > 0 ? (sph_real)pow((double)t, 1.0 / 7.0) : 0;
    return k > (sph_real)0.01 ? k : (sph_real)0.01;
}

/* One symplectic-Euler WCSPH step (the order of sph.h's: forces, kick, density rate, drift). */
static int base_step(base_world* b, sph_real dt) {
    const int D = b->dim;
    const size_t n = b->n, nb = b->nb;
    const sph_real dcoef = b->delta * b->h * b->c0 * 2 * b->rho0;
    double t0 = bench_now(), t1;
    long i;
    /* grids and lists, from scratch */
    if (!base__grid_build(&b->gf, D, b->x, n, b->R)) return 0;
    if (nb && !base__grid_build(&b->gb, D, b->bx, nb, b->R)) return 0;
    t1 = bench_now();
    b->t_grid += t1 - t0;
    t0 = t1;
    base__lists(b, &b->gf, b->x, b->x, n, 1, b->ff, b->ffn);
    if (nb) {
        base__lists(b, &b->gb, b->bx, b->x, n, 0, b->fb, b->fbn);
        base__lists(b, &b->gf, b->x, b->bx, nb, 0, b->bf, b->bfn);
    }
    t1 = bench_now();
    b->t_lists += t1 - t0;
    t0 = t1;
    if (b->overflow) return 0;
        /* pressure (Tait, gamma = 7) and body acceleration */
BASE_PRAGMA(omp parallel for schedule(static))
    for (i = 0; i < (long)n; ++i) {
        const sph_real t = b->rho[i] / b->rho0;
        int k;
        b->p[i] = b->B * ((sph_real)pow((double)t, 7.0) - 1) + b->pback;
        for (k = 0; k < D; ++k)
            b->a[(size_t)i * (size_t)D + (size_t)k] = b->g[k];
    }
    /* wall pressure: Adami et al. 2012 eq. 27 (static walls), wall density from eq. 28 */
BASE_PRAGMA(omp parallel for schedule(static))
    for (i = 0; i < (long)nb; ++i) {
        sph_real sw = 0, swp = 0, sgx = 0;
        uint32_t q;
        for (q = 0; q < b->bfn[i]; ++q) {
            const uint32_t f = b->bf[(size_t)i * BASE_MAXNB + q];
            sph_real d[3] = {0, 0, 0}, r2 = 0, W;
            int k;
            for (k = 0; k < D; ++k) {
                d[k] = b->bx[(size_t)i * (size_t)D + (size_t)k] -
                       b->x[(size_t)f * (size_t)D + (size_t)k];
                r2 += d[k] * d[k];
            }
            W = base__W(b, (sph_real)sqrt((double)r2));
            sw += W;
            swp += b->p[f] * W;
            for (k = 0; k < D; ++k)
                sgx += b->rho[f] * b->a[(size_t)f * (size_t)D + (size_t)k] * d[k] * W;
        }
        b->bp[i] = sw > 0 ? (swp + sgx) / sw : 0;
        b->bkap[i] = sw > 0 ? base__kap(b, b->bp[i]) : 1;
    }
    t1 = bench_now();
    b->t_other += t1 - t0;
    t0 = t1;
    /* forces: pressure (symmetric form) and artificial viscosity; walls without viscosity */
BASE_PRAGMA(omp parallel for schedule(static))
    for (i = 0; i < (long)n; ++i) {
        const sph_real* xi = b->x + (size_t)i * (size_t)D;
        const sph_real* vi = b->v + (size_t)i * (size_t)D;
        const sph_real pi_r2 = b->p[i] / (b->rho[i] * b->rho[i]);
        sph_real ai[3] = {0, 0, 0};
        uint32_t q;
        int k;
        for (q = 0; q < b->ffn[i]; ++q) {
            const uint32_t j = b->ff[(size_t)i * BASE_MAXNB + q];
            sph_real d[3] = {0, 0, 0}, r2 = 0, vd = 0, s, F;
            for (k = 0; k < D; ++k) {
                d[k] = xi[k] - b->x[(size_t)j * (size_t)D + (size_t)k];
                r2 += d[k] * d[k];
                vd += (vi[k] - b->v[(size_t)j * (size_t)D + (size_t)k]) * d[k];
            }
            F = base__F(b, (sph_real)sqrt((double)r2));
            s = -b->m * (pi_r2 + b->p[j] / (b->rho[j] * b->rho[j]));
            if (vd < 0) {
                const sph_real mu = b->h * vd / (r2 + b->eta2);
                s -= b->m * (-b->alpha * b->c0 * mu) * 2 / (b->rho[i] + b->rho[j]);
            }
            for (k = 0; k < D; ++k)
                ai[k] += s * F * d[k];
        }
        for (q = 0; q < b->fbn[i]; ++q) {
            const uint32_t j = b->fb[(size_t)i * BASE_MAXNB + q];
            const sph_real rhob = b->rho0 * b->bkap[j], psi = b->rho0 * b->bvol[j];
            sph_real d[3] = {0, 0, 0}, r2 = 0, s;
            for (k = 0; k < D; ++k) {
                d[k] = xi[k] - b->bx[(size_t)j * (size_t)D + (size_t)k];
                r2 += d[k] * d[k];
            }
            s = -psi * (pi_r2 + b->bp[j] / (rhob * rhob)) * base__F(b, (sph_real)sqrt((double)r2));
            for (k = 0; k < D; ++k)
                ai[k] += s * d[k];
        }
        for (k = 0; k < D; ++k)
            b->a[(size_t)i * (size_t)D + (size_t)k] += ai[k];
    }
    t1 = bench_now();
    b->t_forces += t1 - t0;
    t0 = t1;
BASE_PRAGMA(omp parallel for schedule(static))
    for (i = 0; i < (long)(n * (size_t)D); ++i)
        b->v[i] += dt * b->a[i]; /* kick */
        /* density rate: continuity with the new velocities, plus delta-SPH (Molteni & Colagrossi)
         */
BASE_PRAGMA(omp parallel for schedule(static))
    for (i = 0; i < (long)n; ++i) {
        const sph_real* xi = b->x + (size_t)i * (size_t)D;
        const sph_real* vi = b->v + (size_t)i * (size_t)D;
        const sph_real rhati = b->rho[i] / b->rho0;
        sph_real R = 0;
        uint32_t q;
        int k;
        for (q = 0; q < b->ffn[i]; ++q) {
            const uint32_t j = b->ff[(size_t)i * BASE_MAXNB + q];
            sph_real d[3] = {0, 0, 0}, r2 = 0, vd = 0, F;
            for (k = 0; k < D; ++k) {
                d[k] = xi[k] - b->x[(size_t)j * (size_t)D + (size_t)k];
                r2 += d[k] * d[k];
                vd += (vi[k] - b->v[(size_t)j * (size_t)D + (size_t)k]) * d[k];
            }
            F = base__F(b, (sph_real)sqrt((double)r2));
            R += b->m * F * vd;
            R += dcoef * (b->m / b->rho[j]) * (rhati - b->rho[j] / b->rho0) * F * r2 /
                 (r2 + b->eta2);
        }
        for (q = 0; q < b->fbn[i]; ++q) {
            const uint32_t j = b->fb[(size_t)i * BASE_MAXNB + q];
            sph_real d[3] = {0, 0, 0}, r2 = 0, vd = 0, F;
            for (k = 0; k < D; ++k) {
                d[k] = xi[k] - b->bx[(size_t)j * (size_t)D + (size_t)k];
                r2 += d[k] * d[k];
                vd += vi[k] * d[k]; /* static walls */
            }
            F = base__F(b, (sph_real)sqrt((double)r2));
            R += b->rho0 * b->bvol[j] * F * vd;
            R += dcoef * b->bvol[j] * (rhati - b->bkap[j]) * F * r2 / (r2 + b->eta2);
        }
        b->drho[i] = R;
    }
    t1 = bench_now();
    b->t_density += t1 - t0;
    t0 = t1;
BASE_PRAGMA(omp parallel for schedule(static))
    for (i = 0; i < (long)n; ++i) { /* density and drift */
        int k;
        b->rho[i] += dt * b->drho[i];
        for (k = 0; k < D; ++k)
            b->x[(size_t)i * (size_t)D + (size_t)k] += dt * b->v[(size_t)i * (size_t)D + (size_t)k];
    }
    t1 = bench_now();
    b->t_other += t1 - t0;
    return 1;
}

/* bytes per fluid particle held by the baseline (lists at their fixed capacity) */
static double base_bytes_per_particle(const base_world* b) {
    const double D = b->dim;
    double bytes =
        (double)b->n * ((3 * D + 4) * sizeof(sph_real) + 4 + 2 * 4 + 2 * BASE_MAXNB * 4.0 + 2 * 4) +
        (double)b->nb * ((D + 3) * sizeof(sph_real) + BASE_MAXNB * 4.0 + 4 + 2 * 4) +
        4.0 * (double)(b->gf.cap_cell + b->gb.cap_cell);
    return bytes / (double)b->n;
}

#endif
