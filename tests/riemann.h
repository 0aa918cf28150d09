/* tests/riemann.h - exact solution of the 1D Riemann problem for two stiffened gases.

   Reference code for the tests (not part of sph.h). Each side K has its own equation of state
       p = (gamma_K - 1) rho e - gamma_K pinf_K          (pinf = 0: ideal gas)
   with sound speed c^2 = gamma (p + pinf) / rho. For a stiffened gas every relation of the ideal
   gas holds with p replaced by p + pinf (Toro, "Riemann Solvers and Numerical Methods for Fluid
   Dynamics", 3rd ed., ch. 4, and its sec. 4.8 for the covolume/stiffened extensions), so the
   solver is Toro's: the star pressure p* solves
       f_L(p*) + f_R(p*) + u_R - u_L = 0
   with, for side K and P = (p + pinf_K) / (p_K + pinf_K),
       shock (p > p_K):        f_K = (p - p_K) sqrt(A_K / (p + pinf_K + B_K)),
                               A_K = 2 / ((gamma + 1) rho_K), B_K = (gamma - 1)/(gamma + 1) (p_K + pinf_K)
       rarefaction (p <= p_K): f_K = 2 c_K / (gamma - 1) (P^((gamma - 1)/(2 gamma)) - 1),
   solved here by safeguarded Newton iteration (f is increasing in p) to round-off; then
   u* = (u_L + u_R)/2 + (f_R - f_L)/2, star densities from the shock (Rankine-Hugoniot) or
   isentropic relations, and the self-similar solution sampled at any x/t.
   tests/test_compressible.c checks it against Toro's Table 4.3 and the Ott & Schnetter numbers. */
#ifndef SPH_TEST_RIEMANN_H
#define SPH_TEST_RIEMANN_H

#include <math.h>

typedef struct rm_state {
    double rho, u, p;   /* density [kg/m^3], velocity [m/s], pressure [Pa] */
    double gamma, pinf; /* equation of state of this side                 */
} rm_state;

typedef struct rm_solution {
    rm_state L, R;
    double p_star, u_star;       /* star region pressure and velocity           */
    double rho_star_L, rho_star_R;
    double cL, cR;               /* sound speeds of the initial states          */
    int shock_L, shock_R;        /* 1: the wave into that side is a shock       */
    double S_L, S_R;             /* shock speeds (where shock_*)                */
    double head_L, tail_L, head_R, tail_R; /* rarefaction fan edges (otherwise) */
    int iterations;
} rm_solution;

static double rm_sound(const rm_state* s) { return sqrt(s->gamma * (s->p + s->pinf) / s->rho); }

/* f_K(p) and its derivative (Toro eqs. 4.6-4.7 with p -> p + pinf). */
static void rm_f(const rm_state* s, double c, double p, double* f, double* df) {
    const double g = s->gamma, pk = s->p + s->pinf, pp = p + s->pinf;
    if (p > s->p) {
        const double A = 2 / ((g + 1) * s->rho), B = (g - 1) / (g + 1) * pk;
        const double q = sqrt(A / (pp + B));
        *f = (p - s->p) * q;
        *df = q * (1 - 0.5 * (p - s->p) / (pp + B));
    } else {
        const double P = pp / pk;
        *f = 2 * c / (g - 1) * (pow(P, (g - 1) / (2 * g)) - 1);
        *df = 1 / (s->rho * c) * pow(P, -(g + 1) / (2 * g));
    }
}

/* Solves the Riemann problem; returns 0 on success, -1 if a vacuum forms (not needed here). */
static int rm_solve(const rm_state* L, const rm_state* R, rm_solution* out) {
    const double du = R->u - L->u;
    double lo = -fmin(L->pinf, R->pinf), hi, p, fL, fR, dL, dR;
    int it;
    out->L = *L;
    out->R = *R;
    out->cL = rm_sound(L);
    out->cR = rm_sound(R);
    /* bracket: f(lo) < 0 unless the states pull apart into vacuum */
    rm_f(L, out->cL, lo + 1e-300, &fL, &dL);
    rm_f(R, out->cR, lo + 1e-300, &fR, &dR);
    if (fL + fR + du >= 0) return -1;
    hi = fmax(L->p, R->p);
    for (it = 0; it < 200; ++it) {
        rm_f(L, out->cL, hi, &fL, &dL);
        rm_f(R, out->cR, hi, &fR, &dR);
        if (fL + fR + du > 0) break;
        hi = 2 * hi + fmax(L->pinf, R->pinf) + 1;
    }
    p = 0.5 * (L->p + R->p); /* arithmetic mean start (Toro sec. 4.3.2), kept inside the bracket */
    if (!(p > lo && p < hi)) p = 0.5 * (lo + hi);
    for (it = 0; it < 200; ++it) {
        double F, pn;
        rm_f(L, out->cL, p, &fL, &dL);
        rm_f(R, out->cR, p, &fR, &dR);
        F = fL + fR + du;
        if (F > 0) hi = p; else lo = p;
        pn = p - F / (dL + dR);
        if (!(pn > lo && pn < hi)) pn = 0.5 * (lo + hi); /* Newton left the bracket: bisect */
        if (fabs(pn - p) <= 1e-15 * fabs(pn) + 1e-300) { p = pn; break; }
        p = pn;
    }
    out->iterations = it;
    rm_f(L, out->cL, p, &fL, &dL);
    rm_f(R, out->cR, p, &fR, &dR);
    out->p_star = p;
    out->u_star = 0.5 * (L->u + R->u) + 0.5 * (fR - fL);
    {
        const rm_state* S[2] = {L, R};
        int k;
        for (k = 0; k < 2; ++k) {
            const rm_state* s = S[k];
            const double g = s->gamma, c = k ? out->cR : out->cL;
            const double P = (p + s->pinf) / (s->p + s->pinf), G = (g - 1) / (g + 1);
            double rho_star;
            if (p > s->p) { /* Rankine-Hugoniot (Toro eq. 4.50) and shock speed (eq. 4.52) */
                const double S_speed = sqrt((g + 1) / (2 * g) * P + (g - 1) / (2 * g)) * c;
                rho_star = s->rho * (P + G) / (G * P + 1);
                if (k == 0) { out->shock_L = 1; out->S_L = s->u - S_speed; }
                else { out->shock_R = 1; out->S_R = s->u + S_speed; }
            } else { /* isentropic (Toro eq. 4.53) and the fan edges (eqs. 4.55-4.56) */
                const double cs = c * pow(P, (g - 1) / (2 * g));
                rho_star = s->rho * pow(P, 1 / g);
                if (k == 0) { out->shock_L = 0; out->head_L = s->u - c; out->tail_L = out->u_star - cs; }
                else { out->shock_R = 0; out->head_R = s->u + c; out->tail_R = out->u_star + cs; }
            }
            if (k == 0) out->rho_star_L = rho_star;
            else out->rho_star_R = rho_star;
        }
    }
    return 0;
}

/* The solution at xi = x / t (x measured from the initial discontinuity): density, velocity,
   pressure and the side (0 left, 1 right) whose equation of state holds there. */
static void rm_sample(const rm_solution* s, double xi, double* rho, double* u, double* p, int* side) {
    if (xi <= s->u_star) { /* left of the contact */
        const rm_state* L = &s->L;
        const double g = L->gamma;
        *side = 0;
        if (s->shock_L) {
            if (xi < s->S_L) { *rho = L->rho; *u = L->u; *p = L->p; }
            else { *rho = s->rho_star_L; *u = s->u_star; *p = s->p_star; }
        } else if (xi < s->head_L) {
            *rho = L->rho; *u = L->u; *p = L->p;
        } else if (xi > s->tail_L) {
            *rho = s->rho_star_L; *u = s->u_star; *p = s->p_star;
        } else { /* inside the left fan (Toro eq. 4.56) */
            const double q = 2 / (g + 1) + (g - 1) / ((g + 1) * s->cL) * (L->u - xi);
            *rho = L->rho * pow(q, 2 / (g - 1));
            *u = 2 / (g + 1) * (s->cL + 0.5 * (g - 1) * L->u + xi);
            *p = (L->p + L->pinf) * pow(q, 2 * g / (g - 1)) - L->pinf;
        }
    } else {
        const rm_state* R = &s->R;
        const double g = R->gamma;
        *side = 1;
        if (s->shock_R) {
            if (xi > s->S_R) { *rho = R->rho; *u = R->u; *p = R->p; }
            else { *rho = s->rho_star_R; *u = s->u_star; *p = s->p_star; }
        } else if (xi > s->head_R) {
            *rho = R->rho; *u = R->u; *p = R->p;
        } else if (xi < s->tail_R) {
            *rho = s->rho_star_R; *u = s->u_star; *p = s->p_star;
        } else { /* inside the right fan (Toro eq. 4.63) */
            const double q = 2 / (g + 1) - (g - 1) / ((g + 1) * s->cR) * (R->u - xi);
            *rho = R->rho * pow(q, 2 / (g - 1));
            *u = 2 / (g + 1) * (-s->cR + 0.5 * (g - 1) * R->u + xi);
            *p = (R->p + R->pinf) * pow(q, 2 * g / (g - 1)) - R->pinf;
        }
    }
}

#endif
