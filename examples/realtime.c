/* realtime.c - an interactive 2D SPH tank for game programmers (SDL2).
   10k water particles in a closed tank: stir them with the mouse, run a wave paddle, switch
   between the four pressure solvers while it runs. By default the tank is at game scale,
   80 m x 50 m with 20 m of water and 0.4 m particles (--scale 1: the 1.6 m x 1.0 m model tank
   it is scaled from, see "scene"), stepped by PBF (position based fluids) aiming at a 2 % mean
   compression (1.4-2 % measured) with sph.h's own step control; IISPH at a 0.5 % tolerance is
   key 3 (0.5 % compression, about 1.4 times PBF's CPU time here). Each frame simulates
   the wall time of the last frame within a budget of wall time, so the window stays
   responsive; the top line shows the real-time factor (simulated seconds per wall second).
   When the water falls behind real time for 2 s, the demo starts a fresh tank with fewer
   particles and says so (--adapt 0: keep the detail, run in slow motion instead).

   Build: cc -O2 -std=c99 -fopenmp -I. examples/realtime.c $(sdl2-config --cflags --libs) -lm \
             -o build/realtime                       (or: make realtime; Debian: libsdl2-dev)
   Run:   ./build/realtime [--particles 10000] [--solver wcsph|pcisph|iisph|pbf] [--scale 50]
                           [--tolerance 0.005 (IISPH's)] [--compression 0.02 (PBF's)] [--adapt 1]
                           [--budget 40 (ms per frame)]
   Check: xvfb-run -a ./build/realtime --frames 150 --screenshot out/realtime.png [--solver iisph]
          runs scripted input (a stirring drag, a pull, the paddle) without a user, then writes
          the last frame as a PNG, one summary line per solver and the final line
          "real-time factor X at N particles, solver S" (simulated time over the wall time the
          frames asked for, from the first frame's start to the last one's, drawing included,
          as the text band shows it; N at the end); exit status 1 if a step failed or a particle
          left the tank. Without --solver the run switches WCSPH -> PCISPH -> IISPH -> PBF at
          each quarter. SDL_VIDEODRIVER=offscreen or dummy also work.

   Keys:  left mouse   stir: drags the water near the cursor along with the cursor's motion
          right mouse  pull: draws the water near the cursor towards it
          1 / 2 / 3 / 4  WCSPH / PCISPH (enhanced) / IISPH / PBF (rebuilds the world from the
                       current particle positions and velocities); PBF runs first: the
                       position based solver meant for games, about 1.4 times quicker than
                       IISPH here but four times as compressed (README, "Real time in a game")
          P paddle on/off   R reset   Esc quit
   Threads: OpenMP uses every core. On a machine busy with other work, OMP_WAIT_POLICY=passive
   keeps waiting threads from spinning (with gcc's default a step can take 10x longer there). */
#define SPH_IMPLEMENTATION
#include "sph.h"
#include "examples/image.h"

#include <SDL.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* ---- scene (SI units) ----------------------------------------------------------------------
   The constants describe the model tank, 1.6 m x 1.0 m. --scale S (default SCALE) builds it S
   times larger: every length times S and, by Froude similarity (gravity stays 9.81 m/s^2),
   every time and speed times sqrt(S), accelerations unchanged, kinematic viscosity times
   S^1.5. The flow is then the model's, sqrt(S) times slower, and so is every step sph.h
   chooses: the step grows like sqrt(dx) under gravity while the particle count stays. */
#define SCALE 50.0    /* default: an 80 m x 50 m tank, 20 m of water, 0.4 m particles at 10k */
#define TANK_W 1.6    /* model tank interior [m] */
#define TANK_H 1.0
#define DEPTH 0.4     /* water depth at rest [m]; the particle count sets the spacing */
#define SOUND_SPEED 20.0 /* c0 [m/s]. sph.h's automatic 10 sqrt(2 g H) would be 28 m/s here; 20
                            keeps density errors to a few % and makes WCSPH's step 1.4x longer */
#define VISCOSITY 1e-5   /* kinematic viscosity [m^2/s]: ten times water, calms the surface */
/* Tolerances of the iterative solvers (mean predicted compression). Steps are sph.h's own
   (sph_stable_dt; sph_advance halves a step that fails). IISPH at 0.5 %: its default 0.1 % needs
   4x the iterations (11 against 2-3 per step here) for a surface a game does not show; 2 %
   blew up, and 1 % failed 2 of 6 headless runs at 10k particles early in the first second (a
   particle left compressed 20 % by an accepted step, so no retry of the next could succeed;
   tests/check_realtime.sh caught it), while 0.5 % ran 4 of 4 at the same real-time factor
   (0.67-0.69 against 0.65). PCISPH keeps 0.1 %: at 1 % it let a particle out of the tank. */
#define TOL_IISPH 0.005
#define TOL_PCISPH 0.001
/* PBF: the mean compression its steps are chosen for (def.pbf_compression; sph_stable_dt picks
   the step from it, see sph.h's >>pbf) and its projections per step (def.pbf_iterations) */
#define PBF_COMPRESSION 0.02
#define PBF_ITERATIONS 3
#define PADDLE_BODY 1    /* body tag of the paddle's boundary particles */
#define PADDLE_X 1.25    /* paddle centre [m] (snapped to the particle lattice) */
#define PADDLE_AMP 0.1   /* stroke amplitude [m] */
#define PADDLE_PERIOD 1.4 /* [s], between the tank's first two sloshing periods (1.8 s, 1.1 s),
                             so the waves stay bounded */
#define PADDLE_Y0 0.08   /* bottom and top of the paddle [m]: water passes underneath */
#define PADDLE_Y1 0.80
#define PADDLE_RAMP 0.5  /* [s] to start or stop the paddle smoothly (no infinite acceleration) */
#define STIR_RADIUS 0.12 /* [m] reach of the mouse force, falling off as (1 - r/R)^2 */
#define STIR_TAU 0.05    /* [s] stir: relaxation time of the water's velocity to the cursor's */
#define STIR_VMAX 2.5    /* [m/s] cursor speed cap: keeps the flow well below c0 */
#define PULL_ACC 30.0    /* [m/s^2] pull towards the cursor */
#define MAX_FRAME 0.05   /* [s] of wall time: most time simulated per frame (after a stall, do
                            not catch up); longer frames mean slow motion */
#define PI 3.14159265358979

/* The scene scale S (--scale), set once in main before any world exists; the callbacks read it
   on the worker threads. */
static double scene_scale = SCALE;
static double len(double model) { return model * scene_scale; }         /* lengths [m] */
static double tim(double model) { return model * sqrt(scene_scale); }   /* times [s], speeds */

/* ---- screen -------------------------------------------------------------------------------- */
#define WIN_W 960
#define HUD_H 76        /* text band at the top [px] */
#define NBIN 32         /* speed colours */
#define VCOLOR 1.0      /* speed [m/s] at the top of the colour map */

#define NSOLVER 4
static const char* const solver_name[NSOLVER] = {"WCSPH", "PCISPH (enhanced)", "IISPH", "PBF"};
static const char* const solver_arg[NSOLVER] = {"wcsph", "pcisph", "iisph", "pbf"};
static const sph_solver solver_id[NSOLVER] = {SPH_SOLVER_WCSPH, SPH_SOLVER_PCISPH, SPH_SOLVER_IISPH,
                                              SPH_SOLVER_PBF};

/* Mouse state in world units. Written by the main thread between steps, read by the force
   callback on the worker threads during a step. */
typedef struct mouse {
    int stir, pull;     /* buttons held */
    double x, y;        /* cursor [m] */
    double vx, vy;      /* cursor velocity in simulated time [m/s], capped at STIR_VMAX */
    double px, py;      /* cursor at the previous frame [m] */
} mouse;

/* Paddle state, advanced by the boundary callback. speed ramps between 0 and 1 so starting
   and stopping are smooth; phase is the stroke angle. */
typedef struct paddle {
    int on;
    double speed, phase, t_last; /* t_last < 0: the world is new, its clock starts again */
} paddle;

typedef struct demo {
    int particles, solver;      /* requested particle count; 0, 1, 2 = WCSPH, PCISPH, IISPH */
    double budget;              /* simulation wall time per frame [s] */
    double tol_iisph;           /* IISPH's def.tolerance [-] */
    double pbf_compression;     /* PBF's def.pbf_compression [-] */
    int adapt;                  /* nonzero: fewer particles when the water falls behind real time */
    double win_sim, win_real;   /* adapt: simulated and wall time [s] since the last reset */
    int reduced;                /* times the detail was reduced */
    int win_h;                  /* window height [px] */
    double step_cost;           /* wall time of a sub-step [s], the last measured */
    sph_world w;
    int have_world;
    double goal;                /* simulated time the frames have asked for so far [s] */
    double dx, scale, margin;   /* particle spacing [m]; pixels per metre; border [m] around
                                   the tank interior, the walls' depth and 1 cm */
    mouse m;
    paddle pad;
    SDL_Rect* rects;            /* drawing scratch: one rect per particle */
    unsigned char* bin;         /* colour bin of each fluid particle */
    size_t rects_cap;
    char msg[SPH_ERROR_SIZE + 32]; /* last error, shown on screen for a few seconds */
    double msg_until;
} demo;

/* What the text band shows: means over windows of half a second of real time. */
typedef struct meter {
    double sim_ms, frame_ms, steps, ratio; /* shown: per frame; simulated s per real s */
    double a_sim_ms, a_frame_ms, a_steps, a_sim, a_real; /* sums over the current window */
    int a_n;
} meter;

/* Adds one frame: sim_ms and frame_ms [ms], steps, simulated and real duration [s]. */
static void meter_add(meter* m, double sim_ms, double frame_ms, int steps, double sim,
                      double real) {
    m->a_sim_ms += sim_ms;
    m->a_frame_ms += frame_ms;
    m->a_steps += steps;
    m->a_sim += sim;
    m->a_real += real;
    if (++m->a_n > 1 && m->a_real < 0.5) return;
    m->sim_ms = m->a_sim_ms / m->a_n;
    m->frame_ms = m->a_frame_ms / m->a_n;
    m->steps = m->a_steps / m->a_n;
    m->ratio = m->a_real > 0 ? m->a_sim / m->a_real : 0;
    m->a_sim_ms = m->a_frame_ms = m->a_steps = m->a_sim = m->a_real = 0;
    m->a_n = 0;
}

static double now(void) { /* wall clock [s] */
    return (double)SDL_GetPerformanceCounter() / (double)SDL_GetPerformanceFrequency();
}

/* ---- callbacks ----------------------------------------------------------------------------- */

/* def.force: stir and pull near the cursor. Runs on worker threads with disjoint ranges
   [begin, end): it reads the world and the mouse and writes only acc of its own particles. */
static void mouse_force(const sph_world* w, size_t begin, size_t end, sph_real* acc, void* user) {
    const mouse* m = (const mouse*)user;
    const double radius = len(STIR_RADIUS), tau = tim(STIR_TAU);
    size_t i;
    if (!m->stir && !m->pull) return;
    for (i = begin; i < end; ++i) {
        const double rx = (double)w->x[2 * i] - m->x, ry = (double)w->x[2 * i + 1] - m->y;
        const double r = sqrt(rx * rx + ry * ry);
        double q, ax = 0, ay = 0;
        if (r >= radius) continue;
        q = (1 - r / radius) * (1 - r / radius); /* falloff, 1 at the cursor */
        if (m->stir) { /* relax the velocity to the cursor's: the water follows the drag */
            ax += (m->vx - (double)w->v[2 * i]) / tau;
            ay += (m->vy - (double)w->v[2 * i + 1]) / tau;
        }
        if (m->pull && r > 1e-9) { /* towards the cursor, damped so the blob does not ring */
            ax += -PULL_ACC * rx / r - 5.0 / tim(1) * (double)w->v[2 * i];
            ay += -PULL_ACC * ry / r - 5.0 / tim(1) * (double)w->v[2 * i + 1];
        }
        acc[2 * i] += (sph_real)(q * ax);
        acc[2 * i + 1] += (sph_real)(q * ay);
    }
}

/* def.boundary_motion: moves the paddle (body PADDLE_BODY) horizontally, x = x0 + A sin(phase),
   with phase advancing at speed * 2 pi / T. Sets position, velocity and acceleration; the
   tank walls (body 0) stay where they are. Called once per step on the main thread. */
static void paddle_motion(sph_world* w, double t, void* user) {
    paddle* p = (paddle*)user;
    const double omega = 2 * PI / tim(PADDLE_PERIOD), amp = len(PADDLE_AMP), ramp = tim(PADDLE_RAMP);
    const double dt = p->t_last >= 0 && t > p->t_last ? t - p->t_last : 0;
    double ds = 0, off, vel, acc;
    size_t b;
    if (p->on && p->speed < 1) ds = fmin(dt / ramp, 1 - p->speed);
    if (!p->on && p->speed > 0) ds = -fmin(dt / ramp, p->speed);
    p->speed += ds;
    p->phase += omega * p->speed * dt;
    p->t_last = t;
    off = amp * sin(p->phase);
    vel = amp * omega * p->speed * cos(p->phase);
    acc = -amp * omega * omega * p->speed * p->speed * sin(p->phase) +
          (dt > 0 ? amp * omega * cos(p->phase) * ds / dt : 0);
    for (b = 0; b < w->nb; ++b) {
        if (w->b_body[b] != PADDLE_BODY) continue;
        w->b_x[2 * b] = w->b_x0[2 * b] + (sph_real)off;
        w->b_x[2 * b + 1] = w->b_x0[2 * b + 1];
        w->b_v[2 * b] = (sph_real)vel;
        w->b_v[2 * b + 1] = 0;
        w->b_a[2 * b] = (sph_real)acc;
        w->b_a[2 * b + 1] = 0;
    }
}

/* ---- world --------------------------------------------------------------------------------- */

/* The particle spacing [m] for about `particles` particles in a layer DEPTH deep: the tank's
   width is a whole number *nx of spacings. */
static double spacing(int particles, int* nx) {
    const int n = (int)floor(TANK_W / sqrt(TANK_W * DEPTH / particles) + 0.5);
    if (nx) *nx = n;
    return len(TANK_W) / n;
}

/* Builds the world for d->solver: tank walls, the paddle (4 layers, so no wall particle sees
   water on both sides), and the water, either a fresh layer at rest around the paddle
   (x == NULL) or n particles at x, v (a solver switch). Density and pressure start hydrostatic. */
static sph_status build_world(demo* d, const sph_real* x, const sph_real* v, size_t n) {
    sph_world_def def = sph_world_def_default(2);
    sph_phase water;
    /* lattice: nx columns across the tank, paddle columns ip-2 .. ip+1 from row j0 up, water
       rows 0 .. ny-1 around it; ny is chosen so that at least d->particles fit */
    int nx;
    const double dx = spacing(d->particles, &nx);
    const int ip = (int)floor(len(PADDLE_X) / dx + 0.5), j0 = (int)floor(len(PADDLE_Y0) / dx + 0.5);
    const int ny = (d->particles - 4 * j0 + nx - 5) / (nx - 4);
    const int npy = (int)(len(PADDLE_Y1 - PADDLE_Y0) / dx);
    sph_real lo[2] = {0, 0}, hi[2] = {(sph_real)len(TANK_W), (sph_real)len(TANK_H)};
    sph_real* pad = NULL;
    sph_status s;
    int phase, i, k;
    if (d->have_world) sph_world_free(&d->w);
    d->have_world = 0;
    d->dx = dx;
    def.spacing = (sph_real)dx;
    if (solver_id[d->solver] == SPH_SOLVER_PCISPH) sph_world_def_pcisph(&def, 1); /* sets solver */
    else def.solver = solver_id[d->solver];
    if (def.solver == SPH_SOLVER_PCISPH) def.tolerance = (sph_real)TOL_PCISPH;
    if (def.solver == SPH_SOLVER_IISPH) def.tolerance = (sph_real)d->tol_iisph;
    def.pbf_compression = (sph_real)d->pbf_compression;
    def.pbf_iterations = PBF_ITERATIONS;

    /* the particles that left the tank, w.stats.n_outside: those beyond the centres of the first
       wall layer (the water's outer particles sit half a spacing inside the walls' inner face) */
    def.domain_lo[0] = def.domain_lo[1] = (sph_real)(-0.5 * dx);
    def.domain_hi[0] = (sph_real)(len(TANK_W) + 0.5 * dx);
    def.domain_hi[1] = (sph_real)(len(TANK_H) + 0.5 * dx);
    def.force = mouse_force;
    def.force_user = &d->m;
    def.boundary_motion = paddle_motion;
    def.boundary_user = &d->pad;
    d->pad.t_last = -1;
    d->goal = 0;
    s = sph_world_init(&d->w, &def);
    d->have_world = 1; /* safe to free even after a failed init */
    if (s != SPH_OK) return s;
    memset(&water, 0, sizeof(water));
    water.rest_density = 1000;
    water.viscosity = (sph_real)(VISCOSITY * scene_scale * sqrt(scene_scale));
    water.sound_speed = (sph_real)tim(SOUND_SPEED);
    phase = sph_world_add_phase(&d->w, &water);
    if (phase < 0) return SPH_ERR_ARG;
    if (x) {
        s = sph_add_fluid(&d->w, phase, n, x, v);
    } else { /* left of the paddle, right of it, and the gap beneath it */
        sph_real a0[2], a1[2];
        a0[0] = a0[1] = 0;
        a1[0] = (sph_real)((ip - 2) * dx);
        a1[1] = (sph_real)(ny * dx);
        s = sph_fill_box(&d->w, phase, a0, a1);
        a0[0] = (sph_real)((ip + 2) * dx);
        a1[0] = (sph_real)len(TANK_W);
        if (s == SPH_OK) s = sph_fill_box(&d->w, phase, a0, a1);
        a0[0] = (sph_real)((ip - 2) * dx);
        a1[0] = (sph_real)((ip + 2) * dx);
        a1[1] = (sph_real)(j0 * dx);
        if (s == SPH_OK) s = sph_fill_box(&d->w, phase, a0, a1);
    }
    if (s == SPH_OK) s = sph_add_wall_box(&d->w, lo, hi, 0, 0);
    if (s != SPH_OK) return s;
    pad = (sph_real*)malloc(sizeof(sph_real) * 2 * 4 * (size_t)npy);
    if (!pad) return SPH_ERR_NOMEM;
    for (k = 0; k < 4; ++k)
        for (i = 0; i < npy; ++i) {
            pad[2 * (k * npy + i)] = (sph_real)((ip - 1.5 + k) * dx);
            pad[2 * (k * npy + i) + 1] = (sph_real)((j0 + i + 0.5) * dx);
        }
    s = sph_add_boundary(&d->w, 4 * (size_t)npy, pad, NULL, PADDLE_BODY);
    free(pad);
    if (s == SPH_OK) s = sph_set_hydrostatic(&d->w);
    if (s == SPH_OK && d->rects_cap < d->w.n + d->w.nb) { /* drawing scratch */
        free(d->rects);
        free(d->bin);
        d->rects_cap = d->w.n + d->w.nb;
        d->rects = (SDL_Rect*)malloc(sizeof(SDL_Rect) * d->rects_cap);
        d->bin = (unsigned char*)malloc(d->rects_cap);
        if (!d->rects || !d->bin) { d->rects_cap = 0; return SPH_ERR_NOMEM; }
    }
    return s;
}

/* Shows a message for 5 s (errors, resets). */
static void say(demo* d, const char* prefix, const char* text) {
    snprintf(d->msg, sizeof(d->msg), "%s%s", prefix, text);
    d->msg_until = now() + 5;
    fprintf(stderr, "realtime: %s\n", d->msg);
}

/* A fresh tank at rest: start, R, and the way out of a failed step. 0 if even that fails. */
static int reset(demo* d) {
    d->pad.speed = 0; /* the paddle starts from rest (ramping up if on) */
    d->pad.phase = 0;
    d->win_sim = d->win_real = 0; /* adapt() measures the new tank afresh */
    if (build_world(d, NULL, NULL, 0) == SPH_OK) return 1;
    say(d, "cannot build the scene: ", d->w.error);
    return 0;
}

/* Pixels per metre and the border around the tank (the walls' depth, which grows with the
   spacing, and 1 cm of the model) so that the tank fills the window below the text band. */
static void set_view(demo* d) {
    const double layers = sph_kernel_support(SPH_KERNEL_WENDLAND_C2) *
                          sph_kernel_default_h_factor(SPH_KERNEL_WENDLAND_C2); /* wall depth / dx */
    d->margin = len(0.01) + spacing(d->particles, NULL) * ceil(layers - 1e-9);
    d->scale = WIN_W / (len(TANK_W) + 2 * d->margin);
    if (d->win_h > 0) d->scale = fmin(d->scale, (d->win_h - HUD_H) / (len(TANK_H) + 2 * d->margin));
}

/* Graceful degradation: after each frame, the simulated and the wall time since the last
   reset. Once ADAPT_WINDOW of wall time shows the water behind real time (factor below
   ADAPT_BELOW), a fresh tank with fewer particles: a step costs about N and the stable step
   grows like sqrt(dx), N^-1/4, so the cost of a simulated second goes like N^1.25 and the count
   drops to N f^0.8 (with a 10 % margin, at least 10 % and at most half of it). Never back up:
   no oscillation between two details. Returns 0 if the new tank cannot be built. */
#define ADAPT_WINDOW 2.0  /* [s] of wall time measured before a decision */
#define ADAPT_BELOW 0.9   /* reduce below this real-time factor */
#define ADAPT_MIN 1000    /* fewest particles */
static int adapt(demo* d, double sim, double real) {
    double f;
    int n;
    char why[160];
    if (!d->adapt) return 1;
    d->win_sim += sim;
    d->win_real += real;
    if (d->win_real < ADAPT_WINDOW) return 1;
    f = d->win_sim / d->win_real;
    d->win_sim = d->win_real = 0;
    if (f >= ADAPT_BELOW || d->particles <= ADAPT_MIN) return 1;
    n = (int)(d->particles * fmin(0.9, fmax(0.5, 0.9 * pow(f, 0.8))));
    if (n < ADAPT_MIN) n = ADAPT_MIN;
    snprintf(why, sizeof(why), "real-time factor %.2f over %.0f s: fewer particles, %zu -> ", f,
             ADAPT_WINDOW, d->w.n);
    d->particles = n;
    ++d->reduced;
    set_view(d);
    if (!reset(d)) return 0;
    snprintf(why + strlen(why), sizeof(why) - strlen(why), "%zu (fresh tank)", d->w.n);
    say(d, "", why);
    return 1;
}

/* Keys 1/2/3: a new world with the other solver's def, from the current particles. Rebuilding
   is simpler and safer than editing w.def: sph_world_def_pcisph changes several fields that
   sph_world_init validates together, and each solver keeps different scratch state. */
static int switch_solver(demo* d, int solver) {
    const size_t n = d->w.n;
    sph_real* xv = (sph_real*)malloc(sizeof(sph_real) * 4 * (n ? n : 1));
    sph_status s;
    if (solver == d->solver) { free(xv); return 1; }
    d->solver = solver;
    if (!xv) return reset(d);
    memcpy(xv, d->w.x, sizeof(sph_real) * 2 * n);
    memcpy(xv + 2 * n, d->w.v, sizeof(sph_real) * 2 * n);
    s = build_world(d, xv, xv + 2 * n, n);
    free(xv);
    d->win_sim = d->win_real = 0;
    if (s == SPH_OK) return 1;
    say(d, "solver switch failed, reset: ", d->w.error);
    return reset(d);
}

/* Advances the world towards d->goal (the simulated time the frames asked for) with sph.h's
   own step control, within the wall-time budget: while the whole remainder fits the budget
   (at the cost of the last sub-step), one sph_advance lands on the goal (it splits a short
   remainder into halves, never a sliver step); otherwise one stable step at a time until the
   budget is spent, and the water falls behind (slow motion, which the factor on screen shows
   and adapt() answers). A remainder under half a step waits for the next frame. */
static sph_status simulate(demo* d, double want, int* steps) {
    const double t0 = now();
    *steps = 0;
    if (d->goal > d->w.time + MAX_FRAME) d->goal = d->w.time + MAX_FRAME; /* drop the backlog */
    d->goal += want;
    for (;;) {
        const double t1 = now(), remaining = d->goal - d->w.time;
        double dt, chunk;
        sph_status s;
        dt = (double)sph_stable_dt(&d->w, d->w.def.solver);
        if (!(dt > 0)) return d->w.status != SPH_OK ? d->w.status : SPH_ERR_UNSTABLE;
        dt *= d->w.stats.dt_factor > 0 ? d->w.stats.dt_factor : 1; /* what sph_advance takes */
        if (remaining < 0.5 * dt) break;
        if (*steps > 0 && t1 - t0 + d->step_cost > d->budget) break; /* at least one step a frame */
        /* one step is a hair under dt: sph_advance(w, dt) itself could see the remainder
           (time + dt) - time round to just above dt and split it into two half steps */
        chunk = d->step_cost > 0 && t1 - t0 + d->step_cost * ceil(remaining / dt) <= d->budget
                    ? remaining : fmin(remaining, dt * (1 - 1e-9));
        s = sph_advance(&d->w, (sph_real)chunk); /* retries a failed step at a smaller one */
        if (s != SPH_OK) return s;
        *steps += d->w.stats.substeps;
        d->step_cost = (now() - t1) / (d->w.stats.substeps > 0 ? d->w.stats.substeps : 1);
    }
    return SPH_OK;
}

/* ---- input --------------------------------------------------------------------------------- */

/* Cursor velocity from its motion over the last frame's simulated time, so the water follows
   the cursor as seen on screen even in slow motion; capped at STIR_VMAX (scaled). */
static void mouse_update(mouse* m, double sim_dt) {
    double vx = 0, vy = 0, sp;
    if (sim_dt > 1e-6) { vx = (m->x - m->px) / sim_dt; vy = (m->y - m->py) / sim_dt; }
    sp = sqrt(vx * vx + vy * vy);
    if (sp > tim(STIR_VMAX)) { vx *= tim(STIR_VMAX) / sp; vy *= tim(STIR_VMAX) / sp; }
    m->vx = 0.5 * (m->vx + vx); /* a little smoothing against jittery mouse events */
    m->vy = 0.5 * (m->vy + vy);
    m->px = m->x;
    m->py = m->y;
}

/* Check mode: frame f of nframes. Each segment (a third when the solvers switch) plays: a stir
   that sweeps through the water and back (u = 0.1 .. 0.6), the paddle off and on again
   (0.55 .. 0.65), a pull (0.65 .. 0.8), and a second stir from left to right (0.85 .. 1). */
static void script_input(demo* d, int f, int nframes, int segments) {
    const double u = fmod((f + 0.5) * segments / (double)nframes, 1.0);
    double s = -1; /* position along a sweep, 0 .. 1 (left .. right) */
    d->m.stir = (u >= 0.1 && u < 0.6) || u >= 0.85;
    d->m.pull = u >= 0.65 && u < 0.8;
    d->pad.on = u < 0.55 || u >= 0.65;
    if (u >= 0.1 && u < 0.6) s = (u - 0.1) / 0.25 < 1 ? (u - 0.1) / 0.25 : 2 - (u - 0.1) / 0.25;
    if (u >= 0.85) s = (u - 0.85) / 0.15;
    if (s >= 0) {
        d->m.x = len(0.15 + 1.3 * s);
        d->m.y = len(0.22 + 0.08 * sin(4 * PI * s));
    } else if (d->m.pull) {
        d->m.x = len(0.6);
        d->m.y = len(0.55);
    }
}

/* ---- drawing ------------------------------------------------------------------------------- */

static void world_to_px(const demo* d, double x, double y, int* px, int* py) {
    *px = (int)floor((x + d->margin) * d->scale);
    *py = HUD_H + (int)floor((len(TANK_H) + d->margin - y) * d->scale);
}

/* The square of a particle at x [m], size [px]. */
static void particle_rect(const demo* d, const sph_real* x, int size, SDL_Rect* q) {
    world_to_px(d, (double)x[0], (double)x[1], &q->x, &q->y);
    q->x -= size / 2;
    q->y -= size / 2;
    q->w = q->h = size;
}

/* Walls grey, paddle dark grey, water coloured by speed: particles are sorted into NBIN colour
   bins so the renderer gets one SDL_RenderFillRects call per colour. With the software renderer
   this and the text band take about 1 ms a frame at 10k particles; rasterising the squares
   into one streaming texture instead measured 1.2-1.3 ms (README, "Real time in a game"). */
static void draw_particles(SDL_Renderer* r, demo* d) {
    static unsigned char colour[NBIN][3];
    size_t count[NBIN], start[NBIN + 1], i, nw;
    const double px = d->dx * d->scale; /* spacing in pixels; squares 1.25 x that leave no gaps */
    const int size = px > 1.5 ? (int)(1.25 * px + 0.5) : 2;
    const sph_world* w = &d->w;
    int b, pass;
    if (colour[NBIN - 1][0] == 0) /* once: the colour map of examples/image.h */
        for (b = 0; b < NBIN; ++b) img_colormap(b / (NBIN - 1.0), colour[b]);
    for (pass = 0; pass < 2; ++pass) { /* the tank walls, then the paddle */
        for (i = 0, nw = 0; i < w->nb; ++i)
            if ((w->b_body[i] == PADDLE_BODY) == pass)
                particle_rect(d, w->b_x + 2 * i, size, &d->rects[nw++]);
        SDL_SetRenderDrawColor(r, pass ? 70 : 150, pass ? 70 : 150, pass ? 80 : 150, 255);
        SDL_RenderFillRects(r, d->rects, (int)nw);
    }
    memset(count, 0, sizeof(count));
    for (i = 0; i < w->n; ++i) { /* counting sort by colour */
        const double vx = (double)w->v[2 * i], vy = (double)w->v[2 * i + 1];
        const double t = sqrt(vx * vx + vy * vy) / tim(VCOLOR) * (NBIN - 1) + 0.5;
        d->bin[i] = (unsigned char)(t < NBIN - 1 ? t : NBIN - 1);
        ++count[d->bin[i]];
    }
    for (start[0] = 0, b = 0; b < NBIN; ++b) start[b + 1] = start[b] + count[b];
    for (i = 0; i < w->n; ++i) particle_rect(d, w->x + 2 * i, size, &d->rects[start[d->bin[i]]++]);
    for (i = 0, b = 0; b < NBIN; i += count[b], ++b) { /* start[b] is now where bin b ends */
        if (!count[b]) continue;
        SDL_SetRenderDrawColor(r, colour[b][0], colour[b][1], colour[b][2], 255);
        SDL_RenderFillRects(r, d->rects + i, (int)count[b]);
    }
}

/* The cursor's reach while a button is held: a circle of STIR_RADIUS. */
static void draw_cursor(SDL_Renderer* r, const demo* d) {
    SDL_Point pt[33];
    int k;
    if (!d->m.stir && !d->m.pull) return;
    for (k = 0; k <= 32; ++k)
        world_to_px(d, d->m.x + len(STIR_RADIUS) * cos(k * PI / 16),
                    d->m.y + len(STIR_RADIUS) * sin(k * PI / 16), &pt[k].x, &pt[k].y);
    if (d->m.stir) SDL_SetRenderDrawColor(r, 220, 60, 40, 255);
    else SDL_SetRenderDrawColor(r, 40, 120, 220, 255);
    SDL_RenderDrawLines(r, pt, 33);
}

/* The text band: drawn with examples/image.h's 5x7 font into an RGB image, uploaded into a
   streaming texture (SDL2 has no text of its own). */
static void draw_hud(SDL_Renderer* r, SDL_Texture* tex, img* hud, const demo* d, const meter* m) {
    char line[320];
    SDL_Rect band;
    img_fill(hud, 232, 232, 228);
    snprintf(line, sizeof(line), "%s   %zu particles of %.3g m   real-time factor %.2f%s",
             solver_name[d->solver], d->w.n, d->dx, m->ratio, m->ratio < 0.95 ? " (slow motion)" : "");
    img_text(hud, 8, 4, 2, line, 20, 20, 30);
    snprintf(line, sizeof(line), "sim %5.1f ms   frame %5.1f ms   %4.1f steps of %.2f ms   "
             "compression %.2f %%", m->sim_ms, m->frame_ms, m->steps, 1e3 * d->w.stats.dt,
             100 * d->w.stats.compression_avg);
    img_text(hud, 8, 26, 2, line, 20, 20, 30);
    snprintf(line, sizeof(line), "keys: 1 WCSPH  2 PCISPH  3 IISPH  4 PBF   P paddle (%s)   R reset   "
             "Esc quit      mouse: left stir, right pull", d->pad.on ? "on" : "off");
    img_text(hud, 8, 50, 1, line, 60, 60, 70);
    if (d->msg[0] && now() < d->msg_until) img_text(hud, 8, 62, 1, d->msg, 200, 30, 30);
    band.x = band.y = 0;
    band.w = hud->w;
    band.h = hud->h;
    SDL_UpdateTexture(tex, NULL, hud->rgb, 3 * hud->w);
    SDL_RenderCopy(r, tex, NULL, &band);
}

/* ---- main ---------------------------------------------------------------------------------- */

/* Check mode: what each solver did, and its frame times [ms] to take the median of. */
typedef struct tally {
    double *ms_frame, *ms_sim, *ms_draw, *ms_present; /* draw: into the renderer (particles,
                                                         cursor, text band); present: the flip */
    int frames;
    long steps;
    double simulated; /* [s] */
    double asked;     /* wall time its frames were to simulate, drawing included [s]: each frame
                         simulates the interval from the last frame's start to its own (real_dt),
                         so simulated / asked is the factor the text band shows */
    double wall, cpu; /* wall time of its frames, and the process's CPU time in them (all
                         threads) [s]: cpu / wall near the thread count = a free machine */
    double comp_max;  /* largest mean compression after a frame [-] */
    double comp_sum;  /* mean compressions after the frames, summed [-] */
    size_t outside;   /* most particles outside the tank after any frame */
    size_t n;         /* particles at its last frame */
    int errors;       /* failed steps (each followed by a reset) */
} tally;

static int cmp_double(const void* a, const void* b) {
    const double x = *(const double*)a, y = *(const double*)b;
    return x < y ? -1 : x > y;
}

static double median(double* v, int n) {
    qsort(v, (size_t)n, sizeof(double), cmp_double);
    return v[n / 2];
}

static int parse_solver(const char* s) {
    int k;
    for (k = 0; k < NSOLVER; ++k)
        if (strcmp(s, solver_arg[k]) == 0) return k;
    return -1;
}

/* A window with a renderer. A check run (hidden window) falls back to SDL's offscreen and dummy
   video drivers when there is no display, and prefers the software renderer, so that
   SDL_RenderReadPixels needs no GPU; the software renderer is the fallback everywhere. The
   software renderer draws into the window's framebuffer, which SDL by default shows through an
   OpenGL texture where it can: under Xvfb that is Mesa's software rasteriser, and it cost 5-14
   ms per present at 960 x 690 px here (measured with SDL_FRAMEBUFFER_ACCELERATION=1 against 0).
   The X11 driver's own framebuffer (shared memory) takes 0.1-0.8 ms, so the demo asks for it
   (hint SDL_FRAMEBUFFER_ACCELERATION=0; the environment variable of that name overrides). */
static SDL_Renderer* open_window(int w, int h, int check, SDL_Window** win) {
    SDL_Renderer* ren = NULL;
    SDL_SetHint(SDL_HINT_FRAMEBUFFER_ACCELERATION, "0"); /* read by the software renderer only */
    if (SDL_Init(SDL_INIT_VIDEO) != 0 && check) {
        SDL_setenv("SDL_VIDEODRIVER", "offscreen", 1);
        if (SDL_Init(SDL_INIT_VIDEO) != 0) {
            SDL_setenv("SDL_VIDEODRIVER", "dummy", 1);
            SDL_Init(SDL_INIT_VIDEO);
        }
    }
    if (!SDL_WasInit(SDL_INIT_VIDEO)) return NULL;
    *win = SDL_CreateWindow("sph.h realtime", SDL_WINDOWPOS_CENTERED, SDL_WINDOWPOS_CENTERED, w, h,
                            check ? SDL_WINDOW_HIDDEN : 0);
    if (*win) ren = SDL_CreateRenderer(*win, -1, check ? SDL_RENDERER_SOFTWARE : 0);
    if (*win && !ren) ren = SDL_CreateRenderer(*win, -1, SDL_RENDERER_SOFTWARE);
    return ren;
}

int main(int argc, char** argv) {
    demo d;
    meter hudm; /* the numbers on screen */
    tally tal[NSOLVER];
    img hud;
    int frames = 0, fixed = -1, running = 1, frame = 0, steps = 0, status = 0, a, k;
    const char* shot = NULL;
    SDL_Window* win = NULL;
    SDL_Renderer* ren;
    SDL_Texture* tex = NULL;
    double t_prev, sim_dt = 0, run_sim = 0, run_asked = 0;

    memset(&d, 0, sizeof(d));
    memset(&hudm, 0, sizeof(hudm));
    memset(tal, 0, sizeof(tal));
    d.particles = 10000;
    d.budget = 0.040;
    d.tol_iisph = TOL_IISPH;
    d.pbf_compression = PBF_COMPRESSION;
    d.adapt = 1;
    d.pad.on = 1;
    for (a = 1; a < argc; a += 2) { /* options come in pairs: --name value */
        const char* v = a + 1 < argc ? argv[a + 1] : NULL;
        if (strcmp(argv[a], "--particles") == 0 && v) d.particles = atoi(v);
        else if (strcmp(argv[a], "--frames") == 0 && v) frames = atoi(v);
        else if (strcmp(argv[a], "--screenshot") == 0 && v) shot = v;
        else if (strcmp(argv[a], "--budget") == 0 && v) d.budget = atof(v) / 1000;
        else if (strcmp(argv[a], "--scale") == 0 && v) scene_scale = atof(v);
        else if (strcmp(argv[a], "--tolerance") == 0 && v) d.tol_iisph = atof(v);
        else if (strcmp(argv[a], "--compression") == 0 && v) d.pbf_compression = atof(v);
        else if (strcmp(argv[a], "--adapt") == 0 && v) d.adapt = atoi(v);
        else if (strcmp(argv[a], "--solver") == 0 && v && parse_solver(v) >= 0)
            fixed = parse_solver(v);
        else break;
    }
    if (a < argc || d.particles < 100 || d.particles > 1000000 || frames < 0 || !(d.budget > 0) ||
        !(scene_scale >= 0.01 && scene_scale <= 1000) || !(d.tol_iisph > 0 && d.tol_iisph < 1) ||
        !(d.pbf_compression > 0 && d.pbf_compression <= 0.1)) {
        fprintf(stderr, "usage: %s [--particles 100..1000000] [--solver wcsph|pcisph|iisph|pbf] "
                        "[--scale 0.01..1000 (%g)] [--tolerance IISPH's, 0..1 (%g)] "
                        "[--compression PBF's, 0..0.1 (%g)] [--adapt 0|1] "
                        "[--budget ms > 0] [--frames N [--screenshot out.png]]\n", argv[0],
                SCALE, TOL_IISPH, PBF_COMPRESSION);
        return 2;
    }
    /* PBF by default: in the 80 m tank at 10k particles it needs 0.68-0.86 CPU seconds per
       simulated second, drawing included (IISPH about 1.4 times as much), at a mean compression
       of 1.4-2 % against IISPH's 0.5 % (README, "Real time in a game"); the check without
       --solver goes through all four in key order */
    d.solver = fixed >= 0 ? fixed : frames > 0 ? 0 : 3;
    for (k = 0; k < NSOLVER && frames > 0; ++k) {
        tal[k].ms_frame = (double*)malloc(sizeof(double) * (size_t)frames);
        tal[k].ms_sim = (double*)malloc(sizeof(double) * (size_t)frames);
        tal[k].ms_draw = (double*)malloc(sizeof(double) * (size_t)frames);
        tal[k].ms_present = (double*)malloc(sizeof(double) * (size_t)frames);
        if (!tal[k].ms_frame || !tal[k].ms_sim || !tal[k].ms_draw || !tal[k].ms_present) return 1;
    }

    /* the window: the tank and its walls (support radius / dx layers, rounded up) fill the width
       below the text band */
    set_view(&d);
    d.win_h = HUD_H + (int)ceil((len(TANK_H) + 2 * d.margin) * d.scale);
#if defined(__unix__) && !defined(__APPLE__)
    /* an interactive run needs a display: without one SDL may open an invisible window (or a
       console video driver) and the demo would run unseen until killed */
    if (frames == 0 && !getenv("DISPLAY") && !getenv("WAYLAND_DISPLAY") &&
        !getenv("SDL_VIDEODRIVER")) {
        fprintf(stderr, "realtime: no display (neither DISPLAY nor WAYLAND_DISPLAY is set); run "
                        "headless with --frames N, e.g.\n  xvfb-run -a %s --frames 150 "
                        "--screenshot out/realtime.png\n", argv[0]);
        return 1;
    }
#endif
    ren = open_window(WIN_W, d.win_h, frames > 0, &win);
    if (ren && frames == 0 && SDL_GetCurrentVideoDriver() &&
        (strcmp(SDL_GetCurrentVideoDriver(), "offscreen") == 0 ||
         strcmp(SDL_GetCurrentVideoDriver(), "dummy") == 0)) {
        fprintf(stderr, "realtime: video driver %s shows nothing; an interactive run needs a "
                        "display (headless: --frames N [--screenshot out.png])\n",
                SDL_GetCurrentVideoDriver());
        SDL_Quit();
        return 1;
    }
    if (ren) /* the text band's texture */
        tex = SDL_CreateTexture(ren, SDL_PIXELFORMAT_RGB24, SDL_TEXTUREACCESS_STREAMING, WIN_W,
                                HUD_H);
    if (!tex || !img_init(&hud, WIN_W, HUD_H)) {
        fprintf(stderr, "realtime: no window (video driver %s): %s (headless: --frames N)\n",
                SDL_GetCurrentVideoDriver() ? SDL_GetCurrentVideoDriver() : "none", SDL_GetError());
        SDL_Quit();
        return 1;
    }
    if (!reset(&d)) { running = 0; status = 1; }
    if (frames == 0) printf("realtime: %zu particles, spacing %.2f mm, %s, video %s\n", d.w.n,
                            1e3 * d.dx, solver_name[d.solver], SDL_GetCurrentVideoDriver());

    t_prev = now();
    while (running) {
        const double t0 = now(), real_dt = t0 - t_prev;
        const clock_t c0 = clock();
        double t_sim0, sim_ms, frame_ms, draw_ms, present_ms;
        sph_status s;
        SDL_Event ev;
        t_prev = t0;
        /* input: events and the mouse, or the script */
        while (SDL_PollEvent(&ev)) {
            if (ev.type == SDL_QUIT) running = 0;
            if (ev.type != SDL_KEYDOWN || frames > 0) continue;
            switch (ev.key.keysym.sym) {
            case SDLK_ESCAPE: running = 0; break;
            case SDLK_1: case SDLK_2: case SDLK_3: case SDLK_4:
                if (!switch_solver(&d, (int)(ev.key.keysym.sym - SDLK_1))) running = 0;
                break;
            case SDLK_p: d.pad.on = !d.pad.on; break;
            case SDLK_r: if (!reset(&d)) running = 0; break;
            default: break;
            }
        }
        if (!running) break;
        if (frames > 0) { /* without --solver: WCSPH, PCISPH, IISPH, PBF for a quarter each */
            const int want = fixed >= 0 ? fixed : frame * NSOLVER / frames;
            if (want != d.solver && !switch_solver(&d, want)) { status = 1; break; }
            script_input(&d, frame, frames, fixed >= 0 ? 1 : NSOLVER);
        } else {
            int mx, my;
            const Uint32 buttons = SDL_GetMouseState(&mx, &my);
            d.m.stir = (buttons & SDL_BUTTON(SDL_BUTTON_LEFT)) != 0;
            d.m.pull = (buttons & SDL_BUTTON(SDL_BUTTON_RIGHT)) != 0;
            d.m.x = fmin(fmax(mx / d.scale - d.margin, 0.0), len(TANK_W)); /* clamped into the tank */
            d.m.y = fmin(fmax(len(TANK_H) + d.margin - (my - HUD_H) / d.scale, 0.0), len(TANK_H));
        }
        mouse_update(&d.m, sim_dt);

        /* simulate the real time of the last frame, within the budget */
        t_sim0 = d.w.time; /* after a solver switch: 0 */
        sim_ms = now();
        s = simulate(&d, fmin(real_dt, MAX_FRAME), &steps);
        sim_dt = d.w.time - t_sim0;
        sim_ms = 1e3 * (now() - sim_ms);
        if (frames > 0) {
            tally* t = &tal[d.solver];
            if (d.w.stats.n_outside > t->outside) t->outside = d.w.stats.n_outside;
            t->steps += steps;
            t->simulated += s == SPH_OK ? sim_dt : 0;
            t->errors += s != SPH_OK;
            if (s == SPH_OK && d.w.stats.compression_avg > t->comp_max)
                t->comp_max = d.w.stats.compression_avg;
            if (s == SPH_OK) t->comp_sum += d.w.stats.compression_avg;
        }
        if (s != SPH_OK) { /* a demo must not crash: show why, start again */
            char why[64];
            snprintf(why, sizeof(why), "%s: %s, reset: ", solver_arg[d.solver],
                     sph_status_string(s));
            say(&d, why, d.w.error);
            if (!reset(&d)) { status = 1; break; }
            sim_dt = 0;
        }

        /* draw; the screenshot is read back before SDL_RenderPresent */
        draw_ms = now();
        SDL_SetRenderDrawColor(ren, 250, 250, 247, 255);
        SDL_RenderClear(ren);
        draw_particles(ren, &d);
        draw_cursor(ren, &d);
        draw_hud(ren, tex, &hud, &d, &hudm);
#if SDL_VERSION_ATLEAST(2, 0, 10)
        SDL_RenderFlush(ren); /* the renderer's queued commands run here, not in the present */
#endif
        draw_ms = 1e3 * (now() - draw_ms);
        if (shot && frame == frames - 1) {
            img pic;
            if (!img_init(&pic, WIN_W, d.win_h) ||
                SDL_RenderReadPixels(ren, NULL, SDL_PIXELFORMAT_RGB24, pic.rgb, 3 * WIN_W) != 0 ||
                img_write_png(&pic, shot) != 0) {
                fprintf(stderr, "realtime: screenshot %s failed (%s)\n", shot, SDL_GetError());
                status = 1;
            }
            img_free(&pic);
        }
        present_ms = now();
        SDL_RenderPresent(ren);
        present_ms = 1e3 * (now() - present_ms);
        frame_ms = 1e3 * (now() - t0);
        meter_add(&hudm, sim_ms, frame_ms, steps, sim_dt, real_dt);
        if (frames > 0) {
            tally* t = &tal[d.solver];
            t->ms_frame[t->frames] = frame_ms;
            t->ms_draw[t->frames] = draw_ms;
            t->ms_present[t->frames] = present_ms;
            t->ms_sim[t->frames++] = sim_ms;
            t->n = d.w.n;
        }
        /* fewer particles if the water falls behind (a fresh tank, counted in this frame) */
        if (!adapt(&d, sim_dt, real_dt)) { status = 1; break; }
        if (frames > 0) {
            tally* t = &tal[d.solver];
            const double wall = now() - t0;
            t->wall += wall;
            t->asked += real_dt;
            t->cpu += (double)(clock() - c0) / CLOCKS_PER_SEC;
            run_asked += real_dt;
            run_sim += s == SPH_OK ? sim_dt : 0;
            if (++frame >= frames) running = 0;
        } else if (frame_ms < 4) {
            SDL_Delay(1); /* idle a little when the frame was cheap */
        }
    }

    /* check mode: one line per solver that ran; exit status 1 on an error or an escape */
    for (k = 0; k < NSOLVER; ++k) {
        const tally* t = &tal[k];
        if (t->frames == 0) continue;
        printf("realtime: %-6s particles %zu  frames %d  median %.1f ms/frame (sim %.1f, draw "
               "%.1f, present %.1f ms)  steps %ld (%.1f/frame)  simulated %.3f s of %.3f s "
               "(frames %.3f s, cpu %.2f s)  factor %.3f  compression mean %.2f %%, <= %.2f %%  "
               "outside %zu  errors %d\n",
               solver_arg[k], t->n, t->frames, median(t->ms_frame, t->frames),
               median(t->ms_sim, t->frames), median(t->ms_draw, t->frames),
               median(t->ms_present, t->frames), t->steps, (double)t->steps / t->frames,
               t->simulated, t->asked, t->wall, t->cpu, t->asked > 0 ? t->simulated / t->asked : 0,
               100 * t->comp_sum / t->frames, 100 * t->comp_max,
               t->outside, t->errors);
        if (t->outside > 0 || t->errors > 0) status = 1;
    }
    if (frames > 0) {
        if (d.reduced) printf("realtime: detail reduced %d time(s) to keep up with real time\n",
                              d.reduced);
        printf("realtime: scale %g (tank %g m x %g m, water %g m deep, spacing %.3g m), IISPH "
               "tolerance %g, PBF compression %g, OMP_WAIT_POLICY=%s\n", scene_scale, len(TANK_W),
               len(TANK_H), len(DEPTH), d.dx, d.tol_iisph, d.pbf_compression, getenv("OMP_WAIT_POLICY") ? getenv("OMP_WAIT_POLICY") : "unset");
        if (shot && status == 0) printf("realtime: screenshot %s\n", shot);
        printf("real-time factor %.3g at %zu particles, solver %s\n",
               run_asked > 0 ? run_sim / run_asked : 0, d.w.n,
               fixed >= 0 ? solver_arg[fixed] : "wcsph+pcisph+iisph+pbf");
    }
    for (k = 0; k < NSOLVER; ++k) {
        free(tal[k].ms_frame);
        free(tal[k].ms_sim);
        free(tal[k].ms_draw);
        free(tal[k].ms_present);
    }
    free(d.rects);
    free(d.bin);
    if (d.have_world) sph_world_free(&d.w);
    img_free(&hud);
    SDL_DestroyTexture(tex);
    SDL_DestroyRenderer(ren);
    SDL_DestroyWindow(win);
    SDL_Quit();
    return status;
}
