/* sph.h - smoothed particle hydrodynamics in one header. MIT licence (see end of file).

   A plain-struct particle world, SPH kernels, a cell grid for neighbour search, and time steps
   for weakly compressible SPH (WCSPH), predictive-corrective incompressible SPH (PCISPH, the
   original and an enhanced multiphase version), implicit incompressible SPH (IISPH),
   divergence-free SPH (DFSPH) and position based fluids (PBF, for games), with
   particle walls (three boundary pressure schemes), moving and irregular boundaries, and user
   forces.
   C99, also C++; libc and libm only; OpenMP when the compiler enables it.

   DO THIS in exactly one C or C++ file:

       #define SPH_IMPLEMENTATION
       #include "sph.h"

   and include sph.h without the define everywhere else.

   CONTENTS (grep for the anchors; the implementation repeats them in the same order)
       >>config        options, sph_real
       >>types         sph_status
       >>kernels       sph_kernel: W, dW/dr, grad W (usable on their own)
       >>grid          sph_grid, sph_neighbors: cell grid and neighbour lists (on their own)
       >>operators     sph_op_*: Bonet-Lok corrected gradient, divergence, Laplacian, shifting
       >>world         sph_world_def, sph_phase, sph_world: particles, walls, phases
       >>boundaries    wall particles: Adami pressure extrapolation, no-slip
       >>stages        the shared stages; sph_stable_dt, sph_step, sph_advance
       >>wcsph         sph_step_wcsph
       >>pcisph        sph_step_pcisph, sph_world_def_pcisph
       >>iisph         sph_step_iisph
       >>dfsph         sph_step_dfsph (divergence-free SPH)
       >>pbf           sph_step_pbf (position based fluids, for games)
       >>compressible  sph_step_compressible, sph_add_fluid_ex (gases, shocks, large density ratios)
       >>io            sph_write_csv, sph_write_vtu, sph_write_vtu_series (ParaView), sph_write_vtk;
                       sph_world_save / _load / _copy (checkpoints, bit-exact restart)

   COMPILE-TIME OPTIONS (define before including the implementation)
       SPH_FLOAT          sph_real is float instead of double
       SPH_STATIC         all functions static (a private copy in one translation unit)
       SPH_MALLOC(size), SPH_REALLOC(ptr, size), SPH_FREE(ptr)
                          the allocator (define all three or none; default libc)
       SPH_ASSERT(cond)   internal invariants (default assert); never used for user input
       SPH_VALIDATE       expensive self-checks (neighbour-list symmetry), for tests
       SPH_NO_SIMD        no SSE2 intrinsics (x86-64 uses them in the pair loops by default;
                          the results are bitwise the same either way)
       SPH_MAX_PHASES     phases per world (default 16; at most 256, phase indices are uint8_t)
   OpenMP is used when the compiler enables it (-fopenmp); otherwise everything runs serially.

   QUICK START (examples/hello.c; the tests check that this text is that file):
*/
#if 0 /* QUICKSTART-BEGIN */
#define SPH_IMPLEMENTATION
#include "sph.h"
#include <stdio.h>

int main(void) {
    sph_world_def def = sph_world_def_default(2); /* 2D, y up, gravity -9.81 m/s^2 */
    def.spacing = 0.02;                           /* particle spacing [m]          */
    sph_world w;
    if (sph_world_init(&w, &def) != SPH_OK) { printf("%s\n", w.error); return 1; }
    int water = sph_world_add_phase(&w, &(sph_phase){.rest_density = 1000});
    sph_real lo[2] = {0, 0}, column[2] = {0.4, 0.8}, tank[2] = {2.0, 1.0};
    sph_fill_box(&w, water, lo, column);   /* 0.4 m x 0.8 m of water              */
    sph_add_wall_box(&w, lo, tank, 0, 0);  /* closed tank, walls as deep as needed */
    for (int frame = 1; frame <= 20; ++frame) {
        if (sph_advance(&w, 0.05) != SPH_OK) { printf("error: %s\n", w.error); break; }
        double front = 0;
        for (size_t i = 0; i < w.n; ++i)
            if (w.x[i * 2] > front) front = w.x[i * 2];
        printf("t = %.2f s  steps %5llu  front at x = %.3f m  max speed %.2f m/s\n", w.time,
               (unsigned long long)w.steps, front, w.stats.v_max);
    }
    sph_world_free(&w);
    return 0;
}
#endif /* QUICKSTART-END */
/*
   UNITS AND SCALES
   SI throughout: m, s, kg, Pa. A world has a dimension (1, 2 or 3) fixed at init; vectors are
   stored with stride dim (x[i*dim + k]), so a 2D world stores no third component. y is up:
   the default gravity is (0, -9.81) in 2D and (0, -9.81, 0) in 3D. The particle spacing dx sets
   the resolution and, with h_factor, the smoothing length h = h_factor * dx; the kernel support
   is 2h or 3h. A particle has mass rest_density * dx^dim (its cell volume if sph_fill_box
   adjusted the spacing to fit a box), unless sph_phase.mass says otherwise.
   Coordinates must resolve the spacing: a position carries |x| eps(sph_real) of rounding, which
   the fluid feels as a disordered lattice, so every coordinate (domain box, added particles and
   walls, positions written between steps, loaded files) must satisfy |x| eps <= dx / 1000, else
   SPH_ERR_ARG: |x| <= 168 m at dx = 0.02 m in float (a float tank at rest there kept every
   particle for 1 s up to x = 510 m, and lost half at x = 1e4 m), 9e10 m in double. Place the scene
   near the origin or build in double.

   KERNELS
   sph_kernel_init(&k, type, dim, h) then sph_kernel_w / _dwdr / _grad. Wendland C2 (the world's
   default, h = 1.3 dx, 21 neighbours in 2D; in 3D IISPH, DFSPH and PBF with zero wall pressure
   default to the cubic B-spline at h = dx, 26 neighbours against 80: see sph_world_def.kernel),
   cubic and quintic B-splines, Wendland C4/C6, and a Gaussian
   truncated at 3h (shifted to vanish there and renormalised, so it integrates to exactly one;
   its slope still jumps by 7e-4 of its peak at 3h). All are normalised in 1D, 2D and 3D; W and
   its derivatives are exactly zero from the support radius on. Discrete sums are not exact: on
   a square lattice with Wendland C2 at h = 1.3 dx the pressure gradient is reproduced to 0.974
   and Morris' Laplacian to 0.963 (a larger h_factor improves both at more neighbours); the
   laminar viscosity divides that factor out, measured per particle (see VISCOSITY).

   NEIGHBOUR GRID
   sph_grid sorts points into cells of the support radius with a counting sort. Cells are
   addressed through a dense table over the points' bounding box when that is small, otherwise
   through a hash table, so one particle far away costs no memory. Periodic directions wrap.
   sph_neighbors stores compressed lists (begin/count/idx) filled in parallel chunks; memory is
   reused between builds and grows only when a chunk needs more room.
   A world keeps its lists between steps with a skin (Verlet lists: Verlet 1967; Allen &
   Tildesley 1987 sec. 5.3): with def.neighbor_skin = s > 0 the particles are sorted into cells
   of (1 + s) R and candidate lists within (1 + s) R are searched; each step keeps of them the
   pairs within R (so every pair loop sees exactly the pairs a search would give, in another
   order), and they are searched again once any fluid or boundary particle has moved s R / 2
   since (by the flow, a motion callback or the host writing w.x), or when particles were
   added, the walls changed, sph_advance rolled a step back or s changed. w.stats.
   neighbor_builds counts the searches. The default (-1) takes s = 0.2 for WCSPH and the
   compressible step and searches every step (s = 0) for PCISPH, IISPH, DFSPH and PBF, whose
   steps move particles up to 0.4 dx: a skin would be searched again almost every step.
   Measured (whole process, 1 thread, medians of 5 alternating pairs; README, "Speed"): the 2D
   WCSPH dam break takes 0.77-0.82 of the time without a skin, the 3D one 0.84-0.88; DFSPH,
   IISPH and PBF with s = 0.2 1.05-1.10. The candidate lists add about a third to the bytes
   per particle. A saved world keeps the positions of its last search, so a restart continues
   bit for bit.

   THE WORLD
   sph_world_def_default(dim) gives physical defaults; change fields, then sph_world_init, which
   rejects an invalid field with SPH_ERR_ARG and a message naming it. Add phases (materials) with
   sph_world_add_phase, fluid with sph_fill_box / sph_add_fluid, walls with sph_add_wall_box /
   sph_add_boundary. The world is a caller-owned struct: read n, x, v, rho, p, id, phase, and
   nb, b_x, b_v, b_p ... directly; fluid positions and velocities may be written between steps.
   Move boundary particles from def.boundary_motion: static walls are sorted into their grid once,
   and only a motion callback (or adding particles) makes the library re-sort them.
   Particles may be reordered by cell at any step: follow one by its id, not by its index. Array
   pointers change only when particles are added. A per-particle mass array (w.m) exists only
   when particles of different mass coexist; otherwise every particle has mass w.mass.

   SOLVER: WCSPH (sph_step_wcsph, or sph_step / sph_advance with def.solver)
   Pressure from a stiff equation of state per phase: Tait, p = B((rho/rho0)^gamma - 1) with
   B = rho0 c0^2 / gamma and gamma = 7, or linear, p = c0^2 (rho - rho0). A sound speed of 0
   asks for c0 = 10 max(sqrt(2 |g| H), |v|max), H the height the fluid can fall (its extent
   along gravity, plus the gap down to the walls below it), chosen at the first step, so density
   varies by about 1 %. Density by continuity (default) with delta-SPH diffusion (Molteni &
   Colagrossi 2009, delta = 0.1; without the hydrostatic part, Fourtakas et al. 2019, see
   sph__delta_hydro), by summation, or by Ott & Schnetter's particle-density continuity for
   phases of very different density; negative pressures are clamped unless the domain is
   periodic in every direction (no tension at a free surface, def.clamp: see sph__clamps for
   why, and sph__rho_floor for the least carried density). Phases: with particle
   density, the multiphase (or interface) pressure gradient holds layers at rest (see PHASES),
   while SPH_PGRAD_DIFFERENCE lets buoyancy-driven interfaces move as they should (Rayleigh-Taylor
   growth within 7 % of the viscous theory at Atwood 0.5 and 0.29, where the antisymmetric forms
   grow 3-10 times too slowly, tests/test_rt.c; for fluid that fills its walls: at a free surface
   it is refused, sph__check_free_surface). Once the interface mixes, that gradient needs
   def.shifting = 4 (particle shifting, Sun et al. 2017; see sph__stage_shift): on He, Chen &
   Zhang's 1999 Rayleigh-Taylor case (Atwood 0.5, Re 256) it fails without it at t sqrt(g/W) =
   1.3-2.3 (a particle compressed by 20 %, sooner at finer resolution), and with it reaches t
   sqrt(g/W) = 3: the spike 0.11, 0.07 and 0.04 W behind their position at 32, 64 and 128 particles
   across W, the bubble within 0.04 W. delta-SPH
   diffuses pressure, not rho/rho0, across a phase interface. Viscosity: Monaghan's
   artificial viscosity (alpha = 0.02 by default) and a laminar viscosity per phase (Morris et al.
   1997 by default, or the 2(d+2) form of Enhanced PCISPH 2018 eq. 2.5); see VISCOSITY below
   (all solvers share the term). Time integration:
   symplectic Euler (default) or Stormer-Verlet (second order in time); both take two neighbour
   passes per step over one neighbour list (forces, then the density rate with the new velocities,
   which stable integration of the acoustic waves requires). sph_stable_dt combines the acoustic CFL
   (0.25 h / (c0 + |v|)), the viscous limit (0.125 h^2 / nu) and the force limit
   (0.25 sqrt(h / |a|)); sph_advance(&w, duration) steps with it, landing exactly on the end
   (see ERRORS for what it does when a step fails).

   VISCOSITY (every solver but the second-order scheme, which has its own Laplacian)
   sph_phase.viscosity is the kinematic viscosity nu [m^2/s]. The default form is Morris et al.
   1997's Laplacian, divided by each particle's measured second moment m_i of the kernel gradient
   over its fluid and wall neighbours (the sum that must be 1 for the term to be nu Lap v; 0.963
   on a square lattice with Wendland C2 at h = 1.3 dx, at every resolution), pair factor
   (1/m_i + 1/m_j)/2 so momentum stays conserved, 1/m_i at most 2 (free surfaces, splashes).
   Measured through sph_advance (tests/test_viscous.c: plane Poiseuille between no-slip walls, Re
   0.5): the centre speed is 0.8 % fast at 20 particles across and 0.5 % at 40 (RMS over the
   profile 0.7 % and 0.4 %; without the normalisation 4.2 % and 3.9 %); the rest is the no-slip
   wall, whose fluid rows slip by 0.5 % of u_max (a wall-free periodic shear flow u = sin(2 pi y)
   comes out 1.5 % and 0.65 % fast at 20 and 40 per wavelength, 5.0 % and 4.1 % before). It
   costs one light neighbour pass per viscous pass: a 2D WCSPH step of a viscous 10k-particle box
   takes 23 % more CPU time, IISPH's step (36 iterations there) no measurable more. Numerical
   dissipation: a vortex filling a closed free-slip box (u = sin(pi x) cos(pi y), nu = 0.01,
   25 x 25, its exact kinetic energy decaying as exp(-4 pi^2 nu t)) keeps WCSPH's energy within
   3.5 % of the exact until t = 0.2 s; then the lattice breaks up along the vortex's stretching
   directions (no background pressure, no particle shifting: the disordered particles
   dissipate), and over 0.5 s the energy decays 4.2 (WCSPH), 3.1 (IISPH, DFSPH), 2.4 (original
   PCISPH) times as fast as it should (means of runs in 0.05 s and 0.1 s frames: where the steps
   land alone moves one run's rate by up to 0.3). The default artificial viscosity is not the
   cause: with alpha = 0 the rates are 4.26, 3.01, 2.96 and 2.27, at most 0.15 of the exact
   rate from the alpha = 0.02 ones (tests/test_viscous.c). It
   acts only on approaching pairs and is worth about alpha c0 h / 16 (6 % of nu there); it stays
   at 0.02 because it damps the acoustic noise of WCSPH's equation of state and of impacts (the
   dam-break and tank tests run with it); set def.alpha = 0 for a viscous flow that needs none.

   WCSPH, SECOND-ORDER SCHEME (def.scheme = SPH_SCHEME_SECOND_ORDER; periodic domains only)
   Negi & Ramachandran 2022, L-IPST-C: the fluid density rho (w->rho) is carried by
   continuity with the Bonet-Lok corrected divergence and gives p by the phase's EOS; the
   operators integrate with the Shepard volume 1/sum_j W_ij of the geometry, never m/rho; the
   pressure gradient is the corrected asymmetric form (1/rho_i) sum_j (p_j - p_i) B_i grad W_ij
   omega_j and viscosity the coupled corrected Laplacian nu div(grad u); RK2 (midpoint);
   iterative particle shifting every def.shift_every (10) steps with Taylor-corrected fields.
   Use the quintic spline with h = 1.2 dx and dt = 0.3 h/(U + c0) (def.cfl = 0.3) as the paper
   does; no walls, no delta-SPH or artificial viscosity. Velocity converges at second order on
   Taylor-Green (tests/test_soc.c; bench/convergence.c: the study at c0 = 20, 40, 80, with run
   times); the price is the correction matrices, two force stages per step and the shifting,
   and momentum is not conserved exactly (the corrected operators and the Taylor correction are
   not pairwise antisymmetric: |sum v| / sum |v| reaches 1e-5 ... 3e-4 by t = 0.5 on
   Taylor-Green). The operators are public (>>operators).

   SOLVER: PCISPH (sph_step_pcisph; sph_world_def_pcisph(&def, enhanced) sets it up)
   Predict-correct loop (Solenthaler & Pajarola 2009; Enhanced PCISPH 2018): pressures are corrected
   from the predicted density error until its mean is below def.tolerance (the presets use 0.01 %
   and at least 3 iterations); the last correction moves the particles. enhanced = 0 is the original
   (summation density on predicted positions, one gain per phase from a full lattice neighbour-
   hood). enhanced = 1 is Enhanced PCISPH 2018's engineering version: continuity density with
   delta-SPH, pressure smoothing (chi = 0.8), extrapolated walls with a Shepard wall density,
   Stormer-Verlet, a gain per particle from its actual neighbours and the multiphase pressure
   gradient, warm started from half the last pressure. Each part stays switchable through its def
   field. With density ratios of 0.2 and below, or interfaces that mix (Rayleigh-Taylor), choose
   def.density = SPH_DENSITY_PARTICLE (Ott & Schnetter 2003): the thesis' continuity equation lets a
   light particle at an interface take its heavy neighbours' masses (the tests show the 0.2 tank
   failing with it and holding with particle density). With Stormer-Verlet the predicted density
   is constrained with 0.47 v^n + 0.53 v* rather than the midpoint velocity, which would leave the
   compression rate of the last step undamped (derived in >>pcisph; on the layered column of
   PHASES it took the speed from 3.9 % to 0.5 % of sqrt(g H)). The original PCISPH holds phases
   of different density only at ratios near 1 (summation smears the mass jump; oil of 850 over
   water ran 3 s): at 0.5 it fails in its first step and says so. The original's step is also
   bounded by its largest pressure, dt <= 0.25 h / sqrt(p_max / rho0): its correction at the
   predicted positions diverges above (derived in sph_stable_dt). delta-SPH uses c = cfl h / dt, the speed for which dt is the acoustic step.

   SOLVER: IISPH (sph_step_iisph, or def.solver = SPH_SOLVER_IISPH)
   Implicit incompressible SPH (Ihmsen et al. 2014; Meiers 2025): summation density, then a pressure
   that makes the predicted density the rest density, by relaxed Jacobi (def.omega: 0.5, 0.3 with
   3D Wendland C2) from a
   warm start (0.5 of the last pressure), negative pressures clamped, until the mean predicted
   compression is below def.tolerance (0.1 %) after min_iterations (2), at most max_iterations
   (100); w.stats.iterations and .solver_error report the solve. Moving walls enter the source
   term with their velocity. No equation of state: sound_speed only scales artificial viscosity
   and the speed bound of the blow-up check (left 0 without gravity or motion, both are off).
   sph_stable_dt lets a particle move cfl_velocity (0.4) spacings per step, within the viscous
   and force limits. Iterations grow with depth and with dt; the time to solution has a minimum
   (bench/bench.c iisph-sweep: at dt = 0.03 sqrt(dx/g), 5 iterations, in a 40-deep tank). The
   pressure of single particles scatters by a few percent of rho g H while their densities hold;
   layer averages follow hydrostatics to 1 %. Summation densities are divided by the kernel's
   lattice sum so a lattice at spacing dx is exactly at rest density.
   def.pressure_solve = SPH_PSOLVE_CG solves the same system by preconditioned conjugate gradients
   (with zero wall pressure, where it is self-adjoint; sph__iisph_cg): the mean compression stops
   the solve long before the smooth part of the pressure is right, which Jacobi fixes slowest.
   Measured (2D, one thread): from the same state to a compression of 1e-8, 126 products with A
   against Jacobi's 1027 sweeps, pressures within 1 Pa of 30 kPa; the bench's 2D dam break at
   tolerance 1e-4 10.2 products a step against 25.7 sweeps (7.7 s against 12.7 s, 1 retry
   against 19); at the default 1e-3 both are alike (2.9 and 3.8 a step), and so is a small 3D dam
   break at either tolerance. Use it with a tighter tolerance (1e-4) where a tank must come to
   rest: a 2D tank's late speed 0.014-0.032 sqrt(g H) against 0.029-0.049 (README).
   def.shifting (particle shifting, see sph__stage_shift) applies to IISPH and DFSPH as to WCSPH,
   for flows that fill their walls, with half WCSPH's bound on the shift per step (their density
   is summed again, so what a shift compresses the next solve pushes apart, against gravity with
   work the shift never paid): a vortex in a closed 2D box then decays 2.0 (IISPH) and 2.1
   (DFSPH) times its exact rate instead of 3.3 and 3.2, the disordered lattice's excess.

   SOLVER: DFSPH (sph_step_dfsph, or def.solver = SPH_SOLVER_DFSPH)
   Divergence-free SPH (Bender & Koschier 2015, 2017): per step a divergence-free solve on the
   velocities at the step's start (until the mean compressive D rho/Dt dt / rho0 is below
   def.divergence_tolerance, 0.1 %), then, after gravity, user forces and viscosity, a
   constant-density solve like IISPH's (def.tolerance); both relaxed Jacobi with the factor
   alpha_i (eq. 11, walls included), def.omega and def.warm_start, negative pressures clamped.
   w.p is the constant-density pressure; w.drho keeps the divergence solve's warm start between
   steps. A solve that ends at max_iterations above its tolerance finishes the step and returns
   SPH_ERR_NOT_CONVERGED. Both wall schemes work on open tanks (EXTRAPOLATE runs the divergence
   solve with mirrored walls: its pressure balances no weight); a fluid that
   fills a closed box is solved with zero wall pressure whatever the scheme (with walls that
   copy the fluid's pressure it has no pressure level: see sph__enclosed). Phases may differ in
   rest density and mass down to a ratio of 0.75 (summation density smears the mass jump; below
   it IISPH and DFSPH refuse to step, see SPH__SUMMED_RATIO_MIN). Measured (tests/test_dfsph.c,
   2D dam break, 20 particles per a, the same fixed dt, one thread): 3.5 iterations per step (1.0 of them divergence) against IISPH's
   2.6, 1.41 against 1.30 ms per step, the same compression and front; on a tank at rest 31
   iterations per step like IISPH's 30. Choosing: WCSPH for small steps and simple code, IISPH
   for large steps on liquids, DFSPH when the velocity field itself must be divergence-free
   (splashes, moving boundaries, coupling that reads velocities), at about 10 % more per step
   here; PCISPH for the multiphase engineering setups of Enhanced PCISPH 2018; the compressible step for gases,
   shocks and large density ratios; PBF for a fixed cost per step.

   SOLVER: PBF (sph_step_pbf, or def.solver = SPH_SOLVER_PBF)
   Position based fluids (Macklin & Mueller 2013): per step the particles are predicted with
   gravity and def.force, then def.pbf_iterations (3) Jacobi projections of the density constraint
   C_i = rho_i/rho0 - 1 (clamped at 0: no tension) move them, with Akinci walls as in IISPH and
   eps relaxation (def.pbf_relaxation), the velocity is the displacement over dt, and XSPH
   (def.pbf_xsph, 0.01) and the phases' laminar viscosity smooth it; wall contact and blow-up
   checks as for every step. The tensile correction s_corr (def.pbf_scorr) is off: with the
   clamp there is no tension for it to balance, and it lifted a tank's top particles by 1.6 dx. No
   pressure solve to converge: a step costs the same whatever happens, and never returns
   SPH_ERR_NOT_CONVERGED. The price is compression: no pressure is kept between steps, so a fluid
   at rest sinks until its compression gradient carries it, about K (1 + eps) max(g H, v^2) dt^2
   / (iterations dx^2) on average, H the depth. sph_stable_dt therefore picks the step at which this
   is def.pbf_compression (1 %), within the velocity limit of the other incompressible solvers;
   it has no force limit and no cap of its own (def.max_dt is one; sph_advance never steps past
   the end of a frame). Measured (2D, 40-layer tank at rest, tests/test_pbf.c): 1.17 % mean
   compression, the surface 0.8 dx lower than at rest density. Not cheaper than IISPH at equal
   compression in a deep tank (README, "Real time in a game"); choose it for its fixed cost and
   its robustness at large steps. w.p is the pressure whose force would have made the step's
   correction. Details and measurements: >>pbf.

   BOUNDARIES
   Walls are layers of boundary particles with a volume each (sph_add_wall_box makes enough
   layers to cover the support). Their pressure is extrapolated from the fluid (Adami, Hu &
   Adams 2012, eq. 27) including the body force and the wall's own acceleration, their density
   follows from the equation of state; a wall acts on a fluid particle like fluid of that
   particle's own rest density. Free slip (default) leaves walls out of the viscous terms;
   no-slip uses Adami's extrapolated wall velocity. Boundary particles can move: see callbacks.
   def.boundary_pressure picks how the fluid sees a wall's pressure: automatic (default: zero for
   IISPH and DFSPH, extrapolated for the others), extrapolated (the only one that fits WCSPH) or
   zero (the wall-adjacent layer carries the load; with WCSPH and no wall contact particles got
   through). Mirrored (p_b = p_i) is refused (SPH_ERR_ARG), see below. Why zero for the
   incompressible solvers: IISPH and DFSPH (and PCISPH) hold the summation-density constraint C_i =
   rho_i / rho0 - 1 = 0, where rho_i includes the walls' psi_b W_ib, and their pressure force is
   the constraint force -sum_i lambda_i grad C_i (lambda_i ~ p_i / rho_i^2). Its wall part on
   particle i is -psi_b (p_i / rho_i^2) grad W_ib, the particle's own multiplier only: exactly zero
   wall pressure (Akinci et al. 2012, as used by Ihmsen et al. 2014). A constraint force held to
   dC/dt = 0 does no work, so the fluid cannot gain energy from it. Mirrored and extrapolated walls
   add -psi_b (p_b / rho_b^2) grad W_ib, which is not the gradient of any constraint: it does work
   whenever a particle moves towards or away from a wall while its pressure changes within the
   step, and near a floor that work is positive on average (a particle that compresses into the
   wall layer leaves it faster than it came). Mirroring doubles the wall term of particle i with
   its own pressure: the force on i is then -p_i/rho_i^2 grad(rho_f,i + 2 rho_w,i), with rho_w,i =
   sum_b psi_b W_ib, while the pressure holds rho_f,i + rho_w,i. Its work around a closed path,
   the integral of (p_i / rho_i^2) grad rho_w,i . dx, vanishes only where p_i / rho_i^2 is a
   function of rho_w,i alone, so it is not conservative in any solver, explicit or implicit:
   with gravity (pressure growing with depth) a particle circulating in a corner gains energy
   each turn. Measured on a 2D tank at rest
   (1 x 0.8 m of water in a 1 m box, dx 0.04, sph_advance, 1.5 s): the kinetic energy climbed to
   0.3 % (WCSPH) and 0.6 % (IISPH) of rho g H^2 per metre of tank, the water moving at 0.3-0.44
   sqrt(g H), where zero walls settled to 0.05 sqrt(g H); the 3D tank gained 3-7 % with every
   incompressible solver (make validate's long/scenes/schemes_*, before the scheme was refused).
   Making the solve consistent with the doubled wall term (IISPH's a_ii and A p counting the walls
   twice) only slowed the gain (largest rise 0.0047 against 0.012 of rho g H^2 within 1.5 s, the
   water still moving at 0.34 sqrt(g H)). So sph_world_init and every step refuse SPH_BP_MIRROR
   with SPH_ERR_ARG and say why; DFSPH's divergence solve still uses the mirror internally, where
   its pressure balances no weight (see >>dfsph). Extrapolated walls add the same kind of term,
   weighted by the wall's share of the fluid around it; it is small where the pressure is smooth
   (tanks at rest: energy rise at most 5.1e-4 of rho g H^2 in the scenes of tests/test_scenes.c),
   and IISPH, DFSPH and PCISPH drop it in a fluid that fills its walls (sph__enclosed). The zero
   scheme's price: a particle at a corner feels little wall push until its pressure rises, so
   the first steps from sph_set_hydrostatic pull the corners in (3D tank, dx 0.04: kinetic
   energy 0.9 J after 0.05 s against 0.016 J with extrapolated walls), and the tank comes to rest
   more slowly. def.boundary_volume = SPH_BVOL_AKINCI recomputes each wall particle's volume from
   the wall particles around it whenever walls move (Akinci et al. 2012), for single-layer and
   non-uniformly sampled walls, scaled by gamma_1 (def.boundary_gamma), by default the value that
   gives the fluid beside a flat single layer its rest density (sph__akinci_gamma; 0.585 for the
   default kernel). With gamma_1 = 1 (the default before) such a layer weighed 1.7 half spaces:
   the fluid a host placed beside it started 15-30 % compressed, IISPH, DFSPH and the original
   PCISPH refused their first step, and the others turned the compression into motion. Particles
   that reach the lighter layer's line do not pass between its particles: the wall contact below
   keeps them off (tests/test_scenes.c: single-layer ring and box walls, 2D and 3D). The default,
   SPH_BVOL_AUTO, gives each wall particle the larger of its given volume and Akinci's, once when
   walls are added: lattice walls of several layers keep their given volumes, a layer a host
   samples weighs as a full wall (with dx^dim it weighs too little where its particles are
   sparse: a 2D drum of one layer failed within 0.05 s under IISPH, a 3D one let particles out
   unreported); where walls are sampled denser than the fluid, the given volume is capped by d^dim,
   d the distance to the nearest other wall particle, or dx^dim each would weigh the wall twice or
   more.
   Wall contact (def.wall_contact, on by default): no pressure scheme stops a particle that is
   short of fluid neighbours (a splash, the one-particle sheet a dam break spreads along the floor)
   from sinking until the wall supplies the volume it lacks, i.e. onto and past the wall's first
   layer. So the end of every step keeps each fluid centre at least wall_contact dx (0.73 in 2D,
   0.89 in 3D) from every boundary particle, moving it along the wall's normal and removing its
   velocity into the wall (free slip, inelastic: it takes energy, never adds it); a carried
   density (continuity, particle density) gains the compression that move makes, as a summation
   density would (sph__contact_density). In 3D with zero
   wall pressure and PCISPH, IISPH or DFSPH that distance is for particles short of neighbours
   (fewer fluid and wall neighbours than 0.7 of a full lattice's) and ramps down to 0.6 dx (at a
   wall of one layer, or of Akinci volumes, from the nearest wall particle only) for those with
   0.85 and more: zero wall pressure rests those rows 0.5-0.65 dx from the wall's first layer, and
   a contact that fought them kept a 3D tank at rest moving at 0.2 sqrt(g H) (see
   sph__wall_contact). Moving walls are taken where the step ends. Measured on
   the 3D dam break at dx 0.05 (./build/bench tts --scene 3d-6k): fluid particles outside the
   container at a frame end, most at once, 390 -> 0 (WCSPH), 904 -> 0 (IISPH), 915 -> 0 (DFSPH);
   a one-particle sheet dropped on a host-placed floor (tests/test_reliability.c) sinks 0.67 dx
   past the wall's face without it (3D) and stays 0.39 dx above it with it. The walls' normals
   come from the boundary particles themselves, so any shape the host samples at about dx holds.

   CALLBACKS AND THREADS
   def.force: adds body accelerations for a range of fluid particles; called from worker threads
   with disjoint ranges once per force evaluation (once per step; twice with the second-order
   scheme, once per RK2 stage), before the pressure and viscous forces; the wall pressure
   sees these accelerations like gravity. def.boundary_motion: called once per step on the
   calling thread before the neighbour search with the time of the force evaluation; sets b_x,
   b_v (and b_a, the wall acceleration) of moving boundary particles; b_x0 keeps each particle's
   reference position and b_body the tag given when it was added. Loops over particles are
   OpenMP parallel and gather-only (each particle writes only its own values); small worlds run
   on one thread. A step opens several short parallel loops, and OpenMP's default may keep idle
   threads spinning between them: on a host shared with other work set OMP_WAIT_POLICY=passive
   in the environment (the repository's Makefile does), or steps can run several times slower.

   THREAD SAFETY
   The library keeps no global mutable state. sph_status_string and the sph_kernel_* functions
   use only their arguments (sph_kernel_init writes *k): call them from any thread. Every other
   function works on one world, grid or neighbour list; calls on different objects may run at
   once from different threads, but a call that writes an object must not overlap any other call
   on it. Writers: on a world, sph_world_init/_free, sph_world_add_phase, sph_fill_box,
   sph_add_*, sph_set_hydrostatic, the steps, sph_advance and sph_stable_dt (it fills in
   automatic sound speeds); on a grid, sph_grid_init/_build/_free; on lists,
   sph_neighbors_build/_free. Readers may overlap each other: sph_grid_query, sph_grid_delta,
   sph_op_* (each writing its own output array), sph_world_mass, _momentum, _memory and _error.
   The host must not touch a world's arrays while a call on that world runs, except from the
   callbacks as described above; def.force runs on several threads at once, so it must be safe
   for that. The loops open ordinary OpenMP parallel regions, so OpenMP's rules for nesting apply
   when a call runs inside a parallel region.

   MEMORY
   All allocation goes through SPH_MALLOC/SPH_REALLOC/SPH_FREE. Arrays grow when particles are
   added; scratch and neighbour lists grow when the neighbour count grows and are reused, so a
   step allocates nothing in the steady state. Optional arrays (per-particle mass, Verlet
   scratch) exist only when used. WCSPH with continuity density, IISPH and DFSPH keep the kernel
   gradient of every listed pair for the step's later passes (8 bytes a pair in double: the 2D
   WCSPH dam break takes 483 bytes per fluid particle, 283 without). The candidate lists of
   def.neighbor_skin (on by default for WCSPH) add about a third: the same scene at 10k
   particles 518 -> 714 bytes. sph_world_free releases everything the world allocated.

   ERRORS
   Functions that can fail return sph_status; w.error holds a message with the detail (field,
   particle index and id, value) and w.error_index the particle. Bad input (an invalid def field
   or phase, non-finite positions or velocities, dt <= 0, a bad phase index, fluid added within
   1e-3 spacings of fluid already there or of itself: the same box filled twice; at the next
   step, fluid placed inside the layers of lattice walls, sph__check_placed) is rejected before
   anything changes. A blow-up (a non-finite value, density <= 0, compression beyond
   def.max_compression, a speed beyond def.max_speed's bound, a particle moving more than
   def.max_displacement spacings in one step or ending inside a wall's layers, def.check_walls;
   for PCISPH, IISPH, DFSPH and PBF without force callback or moving walls, a mechanical energy
   (kinetic + gravity's potential) that climbs above the least it has had by more than half the
   largest kinetic energy: walls or solver doing work; PBF under gravity, and gravity along a
   periodic direction, count as forcing) is reported as SPH_ERR_UNSTABLE at the step where it
   happens, naming the first offending particle; an iterative pressure solve that stops at max_iterations above its tolerance returns
   SPH_ERR_NOT_CONVERGED (the step was taken). sph_advance turns both into retries: the failed
   sub-step is undone bit for bit and taken again at half the step (up to 12 times in a row, the
   pressure solve starting cold), the step grows back by 1.1 per success; a sub-step that fails
   that way may have started from a state an earlier sub-step left beyond repair, so the call is
   then taken again from its start at a quarter of its first step (twice at most); at most
   def.max_substeps sub-steps a call (SPH_ERR_BUDGET); when it gives up, the world is as before
   the call. Which scenes each solver holds this way is measured in tests/test_scenes.c. The
   library never calls exit or abort on user input and never drops particles: particles leaving
   def.domain are counted in w.stats.n_outside and kept. An allocation that fails makes the call
   return SPH_ERR_NOMEM ("out of memory" in w.error) with nothing added and no step taken (a step
   may have re-sorted the particles, and a step or sph_set_hydrostatic chosen automatic sound
   speeds, first); the world stays usable, repeating the call once memory is available gives
   what an uninterrupted run gives (bit for bit; the second-order scheme only to round-off if its
   lists had to grow mid-step), and sph_world_free releases everything (tests/test_oom.c fails
   every allocation in turn).

   DETERMINISM
   Reductions combine fixed blocks of particles in a fixed order and every loop is a gather, so
   results are bitwise identical for any number of threads (tests compare 1 and 2 threads).

   DIAGNOSTICS
   After each step w.stats holds dt, iterations, mean and max |rho/rho0 - 1|, max speed and
   acceleration, kinetic energy, fluid neighbour pairs, particles outside the domain and the
   wall-clock time per stage; w.step_time_total and w.stage_time_total accumulate them.

   SOLVER: COMPRESSIBLE (sph_step_compressible, or def.solver = SPH_SOLVER_COMPRESSIBLE)
   Explicit compressible multiphase SPH (Ott & Schnetter 2003): density by continuity
   (use def.density = SPH_DENSITY_PARTICLE, eq. 11, when phases of very different density meet),
   momentum by def.pressure_grad (SPH_PGRAD_MULTIPHASE is eq. 12; SPH_PGRAD_VOLUME for 1000:1
   interfaces, see PHASES), internal energy w.e [J/kg] by
   eq. 13 written so that total energy is conserved to round-off, Monaghan 1992 artificial
   viscosity with each particle's own sound speed. Per phase equation of state: Tait or linear
   (no energy), SPH_EOS_IDEAL_GAS p = (gamma - 1) rho e (c0 follows from back_pressure, the
   pressure at rest density; 0 gives dust), SPH_EOS_STIFFENED_GAS p = (gamma - 1) rho e - gamma
   p_inf with p_inf from sound_speed (liquids under shocks). Gas phases get w.e (set by
   sph_add_fluid / sph_fill_box to the back pressure; the host may overwrite it) and only this
   step accepts them. dt = cfl h / max(c_i + |v_i|). sph_add_fluid_ex takes per-particle masses
   and densities: put equal spacing and unequal masses across a density jump. Validated against
   Ott & Schnetter's advection, sound-wave and air | Diesel shock-tube tests, Toro's Riemann
   solutions and a 1000:1 interface at rest (tests/test_compressible.c). With multiphase walls each
   phase's wall pressure is extrapolated from its own particles only, and each wall particle
   acts as fluid of the phase of its nearest fluid particle (the phase that wets the wall there).

   PHASES (several fluids of different rest density)
   Recommended for layered or mixing liquids with density ratios down to 0.1: particle-density
   continuity (def.density = SPH_DENSITY_PARTICLE, Ott & Schnetter 2003 eq. 11) with
     - enhanced PCISPH, sph_world_def_pcisph(&def, 1), which brings the multiphase gradient but
       sets Enhanced PCISPH 2018's continuity density: set def.density = SPH_DENSITY_PARTICLE
       after it; or
     - WCSPH with def.pressure_grad = SPH_PGRAD_MULTIPHASE (eq. 12) or SPH_PGRAD_INTERFACE (Hu &
       Adams 2006).
   Measured on a dam break (water column 0.2 x 0.4 m at the left of a 1.0 x 0.6 m tank of
   sph_add_wall_box, the rest filled with a second phase, sph_set_hydrostatic, sph_advance in
   0.02 s frames for 1 s, 2D dx 0.02, 3D dx 0.04 and 0.2 m deep): enhanced PCISPH with the
   preset's continuity density failed at ratio 0.3 and below (0.1: within 0.06 s with the lighter
   phase filling the tank to its lid, within 0.2 s with it 0.1 m below the lid), held 0.5; below
   0.35 the first step now refuses it (SPH__CONTINUITY_RATIO_MIN). With particle density and the
   lighter phase 0.1 m below the lid, ratio 0.1 runs the whole second (2D 109 retries, 3D 63; no
   particle out, energy at most +0.17 % of M g H). With fluid that fills its closed walls the
   correction runs with zero wall pressure (sph__enclosed): in 3D enhanced PCISPH holds a tank
   full of water at rest for 1 s and the full tank's dam break at ratio 0.1 for 1 s (no retry),
   but fails it at 0.01 and 0.001 (0.56 s and 0.58 s, reported; in 2D they ran, with 160-600
   retries); WCSPH with particle density and the multiphase gradient runs the full tank's dam
   break at 0.1 and 0.01 in 2D and 3D (energy at most +0.05 % of M g H, no particle out) and fails
   at 0.001 (0.36 s, 0.38 s): for such ratios, and for gases, use the compressible step below.
   For interfaces that should overturn (Rayleigh-Taylor; the antisymmetric gradients slow them
   down 2-3 times): WCSPH with SPH_PGRAD_DIFFERENCE and def.shifting = 4 (see WCSPH).
   Both gradients are divided by the kernel gradient's lattice moment (0.974 for Wendland C2 at
   h = 1.3 dx in 2D), so that the pressure they balance with gravity is the hydrostatic one
   (without it 2.7 % too steep in every layer). Measured (tests/test_layers.c: 1000/500/100
   kg/m^3, 0.2 m each, 0.6 m wide, 20 across, sph_set_hydrostatic then sph_advance; largest speed
   over the last second against sqrt(g H), layer- and time-averaged pressure against the layered
   profile p(0)): enhanced PCISPH after 2 s 0.49 % and 1.2 % (float 1.08 % and 0.68 %: its motion
   after the first second depends on round-off; the pressure was 0.63 % before sph_advance split
   a frame's end into equal steps: where the steps land moves it), WCSPH after 0.5 s multiphase 0.96 %
   and 0.73 %, interface 0.50 % and 0.26 %; no particle past its layer's interface. After 10 s
   at 30 across (over the last second): WCSPH multiphase 0.34 % and 0.92 % (spread 0.12 dx),
   interface with continuity 0.25 % and 0.57 %, with particle density 4.7 % and 0.51 %, enhanced
   PCISPH 0.29 % and 3.9 % (its solve hits max_iterations in deep columns, and the retries
   restart the pressure from 0). Not met: staying below 1 % of sqrt(g H) throughout the 10 s.
   After coming to rest (0.2-0.5 % at 4-6 s, 20 across) episodes of 2-3 % follow (a row sliding
   along the floor or along the lower interface), as in a one-phase tank of the same depth and
   spacing (WCSPH 4.6 %, enhanced PCISPH 3.9 % within 10 s): a property of the walls and solvers,
   not of the phases. Not for phases of different density: the symmetric gradient, the multiphase
   gradient with the mass continuity equation (a light particle takes its heavy neighbours'
   masses), SPH_PGRAD_DIFFERENCE (for interfaces that should move in fluid that fills its walls,
   see WCSPH; a column with a free surface is refused), the original PCISPH, IISPH, DFSPH and PBF
   (summation density, or PBF's constraint on it, smears the mass jump: ratios near 1 only; IISPH
   and DFSPH refuse rest densities in a ratio below 0.75 with SPH_ERR_ARG: at 0.5 a light blob
   rising in water gained 0.4-0.6 M g dx in its first second, every frame SPH_OK, and on this
   column they ran at 2.0-2.4 m/s for 0.5 s before failing). On the column the others fail with
   SPH_ERR_UNSTABLE from sph_advance (WCSPH symmetric with particle density, multiphase with
   continuity; the original PCISPH within a few steps, tests/test_pcisph.c), or run without
   resting: WCSPH symmetric with continuity 7 % and PBF 72 % of sqrt(g H) after 0.5 s. None loses a
   particle silently (tests/test_layers.c checks every frame). Gases and
   1000:1 interfaces: the compressible step (SOLVER: COMPRESSIBLE) with particle density and
   def.pressure_grad = SPH_PGRAD_VOLUME, the momentum equation of the particle density (Hu &
   Adams 2006's (p_i/n_i^2 + p_j/n_j^2) with n = 1/V), a background pressure in both phases and
   an air stiffness rho c^2 about ten times it (tests/test_compressible.c, contact_line: water
   1000 and air 1 kg/m^3, 2000 Pa, c 44 and 150 m/s). Measured on water under air in a closed
   box, dx = 0.025 m, through sph_advance: at rest for 10 s (water at most 0.018 sqrt(g H)
   after 0.5 s, interface rows within 0.62 dx, no particle outside; the air: see WHAT IT DOES
   NOT DO); the dam break of Martin & Moyce's column in air follows the column alone within
   0.041 a (one spacing is 0.1 a) to T = 3, no water particle more than 1.16 dx from the
   water, air at most 2.2 sqrt(2 g a) (water 1.36). With Hu & Adams' density-weighted pair
   pressure (SPH_PGRAD_INTERFACE) the same interface breaks up after 1.5-2 s and the dam
   break's front is off by 0.3-0.6 a.

   WHAT IT DOES NOT DO (yet)
   No surface tension, no turbulence model, no rigid-body coupling (boundaries move kinematically),
   no adaptive resolution, no GPU. At a 1000:1 interface at rest the air is not quiet: on the
   square lattice of sph_fill_box under a background pressure the air's rows rearrange now and
   then (up to 0.28 sqrt(g H) over 10 s, with the water under it at 0.018), and a host-placed
   hexagonal lattice does not fit the square wall lattice of sph_add_wall_box (thrown about
   within 0.05 s). SPH_PGRAD_INTERFACE does not hold 1000:1 for long (see PHASES).

   REFERENCES
   Comments cite these as "Author Year, eq./sec./Table N", numbered as in the work itself.
   Adami, Hu & Adams 2012: A generalized wall boundary condition for smoothed particle
       hydrodynamics. J. Comput. Phys.
   Adami, Hu & Adams 2013: A transport-velocity formulation for smoothed particle hydrodynamics.
       J. Comput. Phys.
   Akinci et al. 2012: N. Akinci, M. Ihmsen, G. Akinci, B. Solenthaler, M. Teschner, Versatile
       rigid-fluid coupling for incompressible SPH. ACM Trans. Graph. (SIGGRAPH).
   Becker & Teschner 2007: Weakly compressible SPH for free surface flows. Symposium on Computer
       Animation.
   Bonet & Lok 1999: Variational and momentum preservation aspects of smooth particle
       hydrodynamic formulations. Comput. Methods Appl. Mech. Eng.
   Dehnen & Aly 2012: Improving convergence in smoothed particle hydrodynamics simulations
       without pairing instability. Mon. Not. R. Astron. Soc.
   Enhanced PCISPH 2018: "Enhanced PCISPH for engineering applications", master's thesis, 2018,
       written at ESS Engineering Software Steyr GmbH (the enhancements are credited to
       C. Peng, K. Szewc, H. Cao and the author; our copy lacks the title page, so the
       author's name is not given here). Also "the thesis" in the PCISPH comments.
   Harlow & Amsden 1971: Fluid dynamics. Los Alamos report LA-4700 (stiffened gas).
   Hu & Adams 2006: A multi-phase SPH method for macroscopic and mesoscopic flows. J. Comput.
       Phys.
   Huang et al. 2019: C. Huang, T. Long, S. M. Li, M. B. Liu, A kernel gradient-free SPH method
       with iterative particle shifting technology for modeling low-Reynolds flows around
       airfoils. Eng. Anal. Bound. Elem.
   Ihmsen et al. 2014: M. Ihmsen, J. Cornelis, B. Solenthaler, C. Horvath, M. Teschner,
       Implicit incompressible SPH. IEEE Trans. Vis. Comput. Graph.
   Koschier et al. 2020: D. Koschier, J. Bender, B. Solenthaler, M. Teschner, Smoothed particle
       hydrodynamics techniques for the physics based simulation of fluids and solids
       (Eurographics 2019 tutorial; arXiv:2009.06944).
   Meiers 2025: T. Meiers, Incompressible SPH with advanced boundary handling for dynamic and
       non-uniform boundaries. Bachelor's thesis, University of Freiburg, 2025.
   Molteni & Colagrossi 2009: A simple procedure to improve the pressure evaluation in
       hydrodynamic context using the SPH. Comput. Phys. Commun.
   Monaghan 1992: Smoothed particle hydrodynamics. Annu. Rev. Astron. Astrophys.
   Monaghan 1994: Simulating free surface flows with SPH. J. Comput. Phys.
   Monaghan 2005: Smoothed particle hydrodynamics. Rep. Prog. Phys.
   Morris 1996: Analysis of smoothed particle hydrodynamics with applications. PhD thesis,
       Monash University.
   Morris et al. 1997: J. P. Morris, P. J. Fox, Y. Zhu, Modeling low Reynolds number
       incompressible flows using SPH. J. Comput. Phys.
   Negi & Ramachandran 2022: P. Negi, P. Ramachandran, Techniques for second order convergent
       weakly-compressible smoothed particle hydrodynamics schemes without boundaries.
       arXiv:2107.11859 (v4, 2022).
   Ott & Schnetter 2003: F. Ott, E. Schnetter, A modified SPH approach for fluids with large
       density differences. arXiv:physics/0303112.
   Solenthaler & Pajarola 2009: Predictive-corrective incompressible SPH. ACM Trans. Graph.
       (SIGGRAPH).
   Toro: E. F. Toro, Riemann Solvers and Numerical Methods for Fluid Dynamics. Springer.
   Wendland 1995: Piecewise polynomial, positive definite and compactly supported radial
       functions of minimal degree. Adv. Comput. Math.
*/
/* ============================================================================================== */
/* >>config                                                                                       */
/* ============================================================================================== */
#ifndef SPH_H
#define SPH_H

#include <stddef.h>
#include <stdint.h>

#define SPH_VERSION_MAJOR 0
#define SPH_VERSION_MINOR 1
#define SPH_VERSION_PATCH 0

#ifndef SPHDEF
#ifdef SPH_STATIC
#if defined(__GNUC__) || defined(__clang__)
#define SPHDEF static __attribute__((unused))
#else
#define SPHDEF static
#endif
#else
#define SPHDEF extern
#endif
#endif

#ifdef SPH_FLOAT
typedef float sph_real;
#else
typedef double sph_real;
#endif

/* Largest number of phases (materials) in one world. */
#ifndef SPH_MAX_PHASES
#define SPH_MAX_PHASES 16
#endif

/* Size of the error message buffer kept in the world: room for sph_advance's account of a
   failed sub-step together with the failing step's own message (at 256 bytes the reason, e.g.
   which wall a particle entered, was cut off; at 512 the end of PCISPH's account of a particle
   compressed at its step's start, after sph_advance's hint on fluid just added). */
#define SPH_ERROR_SIZE 1024

#ifdef __cplusplus
extern "C" {
#endif

/* ============================================================================================== */
/* >>types                                                                                        */
/* ============================================================================================== */

/* Result of every function that can fail. The world keeps the detail in w.error. */
typedef enum sph_status {
    SPH_OK = 0,
    SPH_ERR_ARG,           /* an argument or a def field is invalid; nothing was changed (but
                              see sph_boundary_fn)                                            */
    SPH_ERR_NOMEM,         /* an allocation failed; the world is still valid and usable         */
    SPH_ERR_CAPACITY,      /* a count exceeds what the library can index (more than 2^32 - 2
                              fluid or boundary particles, more than SPH_MAX_PHASES phases)   */
    SPH_ERR_UNSTABLE,      /* a step produced a non-finite value, a runaway density or speed, a
                              particle that moved more than def.max_displacement in one step
                              or entered a wall; or sph_advance could not find a step that
                              succeeds                                                        */
    SPH_ERR_NOT_CONVERGED, /* an iterative pressure solve (PCISPH, IISPH, DFSPH) reached
                              def.max_iterations with its error above def.tolerance: the step
                              was taken with the last pressure (sph_advance retries it)       */
    SPH_ERR_IO,            /* a file could not be opened, written or read (errno says why)      */
    SPH_ERR_BUDGET,        /* sph_advance needed more than def.max_substeps sub-steps; the world
                              is as before the call                                           */
    SPH_STATUS_COUNT
} sph_status;

/* A short constant English text for the status ("unknown status" for other values). */
SPHDEF const char* sph_status_string(sph_status status);

/* ============================================================================================== */
/* >>kernels                                                                                      */
/* ============================================================================================== */

typedef enum sph_kernel_type {
    SPH_KERNEL_WENDLAND_C2 = 0, /* default: Wendland C2, support 2h                              */
    SPH_KERNEL_CUBIC,           /* Monaghan's cubic B-spline (M4), support 2h                     */
    SPH_KERNEL_QUINTIC,         /* Morris' quintic B-spline (M6), support 3h                      */
    SPH_KERNEL_WENDLAND_C4,     /* Wendland C4, support 2h                                        */
    SPH_KERNEL_WENDLAND_C6,     /* Wendland C6, support 2h                                        */
    SPH_KERNEL_GAUSSIAN,        /* Gaussian truncated at 3h, shifted to vanish there, renormalised */
    SPH_KERNEL_COUNT,
    SPH_KERNEL_AUTO = -1        /* sph_world_def only (its default): resolved by sph_world_init
                                   from the dimension, solver and wall scheme (see
                                   sph_world_def.kernel); not a kernel of its own               */
} sph_kernel_type;

/* A kernel bound to a dimension and smoothing length. Plain data: copy it freely. Set up with
   sph_kernel_init; the kernel functions only read it, so any number of threads may share one. */
typedef struct sph_kernel {
    sph_kernel_type type;
    int dim;         /* 1, 2 or 3                                                       */
    sph_real h;      /* smoothing length [m]                                            */
    sph_real radius; /* support radius [m] = support factor (2 or 3) * h                */
    /* derived constants (read-only) */
    int form;        /* private: polynomial variant (Wendland kernels differ in 1D)       */
    sph_real inv_h;  /* 1 / h [1/m]                                                      */
    sph_real norm_w; /* sigma_d / h^d     : W(r) = norm_w * w(r/h)                       */
    sph_real norm_g; /* sigma_d / h^(d+2) : grad W = norm_g * f(r/h) * x_ij              */
} sph_kernel;

/* Fills k for the given type, dimension (1..3) and smoothing length h > 0 [m]. SPH_ERR_ARG (k
   unchanged) for k NULL, an unknown type, dim outside 1..3, h not finite and > 0, or an h so
   small or large that 1/h or the normalisations are not finite and > 0 in sph_real. */
SPHDEF sph_status sph_kernel_init(sph_kernel* k, sph_kernel_type type, int dim, sph_real h);
/* Support radius in units of h: 2 (cubic, Wendland) or 3 (quintic, Gaussian). */
SPHDEF sph_real sph_kernel_support(sph_kernel_type type);
/* Recommended h / particle spacing for the type (used when sph_world_def.h_factor is 0) [-]:
   1.3 (Wendland C2, cubic), 1.2 (quintic), 1.5 (Wendland C4), 1.6 (Wendland C6), 1.0 (Gaussian). */
SPHDEF sph_real sph_kernel_default_h_factor(sph_kernel_type type);
/* Lower-case name ("wendland_c2", "cubic", "quintic", ...); "unknown" for an invalid type. */
SPHDEF const char* sph_kernel_name(sph_kernel_type type);
/* W(r) [1/m^dim] for a distance r >= 0 [m] (|r| is used); 0 from k->radius on. */
SPHDEF sph_real sph_kernel_w(const sph_kernel* k, sph_real r);
/* dW/dr [1/m^(dim+1)]. */
SPHDEF sph_real sph_kernel_dwdr(const sph_kernel* k, sph_real r);
/* grad_i W(x_i - x_j): xij = x_i - x_j (k->dim components) -> grad (k->dim components). */
SPHDEF void sph_kernel_grad(const sph_kernel* k, const sph_real* xij, sph_real* grad);

/* ============================================================================================== */
/* >>grid                                                                                         */
/* ============================================================================================== */

/* Uniform cell grid for fixed-radius neighbour search over a point set. Cells are addressed
   through a dense table over the points' bounding box when that box is small, and through a
   hash table otherwise, so a point far away costs no memory. Periodic directions wrap.
   The fields up to len are set by sph_grid_init; read them, do not write them. */
typedef struct sph_grid {
    int dim;              /* 1, 2 or 3                                                        */
    sph_real cell;        /* cell edge [m]; queries may use any radius <= cell               */
    int periodic[3];      /* nonzero: direction k wraps over [lo[k], lo[k] + len[k])          */
    sph_real lo[3];       /* periodic box origin [m]                                          */
    sph_real len[3];      /* periodic box length [m]                                          */
    /* filled by sph_grid_build (read-only) */
    size_t n;             /* points in the last build                                         */
    uint32_t* order;      /* [n] the k-th point in cell order is point order[k]               */
    uint32_t* start;      /* [nbucket + 1] bucket b holds sorted positions start[b]..start[b+1]) */
    uint64_t* key;        /* [n] hash mode only: packed cell of the k-th sorted point         */
    size_t nbucket;       /* cells of the dense table, or slots of the hash table             */
    int hashed;           /* 0: dense bounding-box table, 1: hash table                       */
    /* private */
    double inv[3];        /* 1 / cell edge per direction, slightly shrunk (see sph_grid_init)  */
    int32_t ncell[3];     /* cells along periodic directions                                  */
    int64_t cmin[3], ext[3];
    uint32_t* bucket;     /* [n] scratch: bucket of each point                                */
    size_t cap_n, cap_bucket;
} sph_grid;

/* Sets up an empty grid. cell_size >= the largest query radius [m]. periodic may be NULL (no
   direction periodic); lo/hi give the periodic box and are read only for periodic directions,
   whose length hi - lo must be finite and at least 2 * cell_size. SPH_ERR_ARG for g NULL, dim
   outside 1..3, a cell_size not finite and > 0, or a bad periodic box. Overwrites *g: free a
   built grid first. */
SPHDEF sph_status sph_grid_init(sph_grid* g, int dim, sph_real cell_size, const int* periodic,
                                const sph_real* lo, const sph_real* hi);
/* Releases the arrays; the grid keeps its cells and may be built again. NULL is ignored. */
SPHDEF void sph_grid_free(sph_grid* g);
/* Sorts n points x[i*dim + k] into cells (counting sort). x must stay valid for queries.
   Points may lie anywhere (periodic directions wrap them). SPH_ERR_CAPACITY beyond 2^32 - 2
   points, SPH_ERR_NOMEM (the grid then keeps its last build); memory is reused between builds. */
SPHDEF sph_status sph_grid_build(sph_grid* g, const sph_real* x, size_t n);
/* Indices of the built points within radius (< radius, radius <= cell) of point p. Writes at most
   cap indices to out and returns the total number found (compare with cap). */
SPHDEF size_t sph_grid_query(const sph_grid* g, const sph_real* x, const sph_real* p,
                             sph_real radius, uint32_t* out, size_t cap);
/* d = a - b, with the minimum-image convention along periodic directions. */
SPHDEF void sph_grid_delta(const sph_grid* g, const sph_real* a, const sph_real* b, sph_real* d);

/* Neighbour lists in compressed rows: the neighbours of query point i are
   idx[begin[i]] .. idx[begin[i] + count[i] - 1], in a deterministic order. Zero the struct
   before the first build (sph_neighbors nl = {0}); sph_neighbors_free zeroes it again. */
typedef struct sph_neighbors {
    size_t n;            /* query points                                                      */
    size_t* begin;       /* [n]                                                               */
    uint32_t* count;     /* [n]                                                               */
    uint32_t* idx;       /* neighbour indices into the grid's point set                        */
    size_t total;        /* sum of count                                                      */
    /* private: lists are filled in chunks of query points, each with its own region of idx */
    size_t cap_n, cap_idx, nchunk, cap_chunk;
    size_t* chunk_off;
    size_t* chunk_cap;
    size_t* chunk_need;
    sph_real* xs;        /* points not in cell order: a copy in the grid's order [n * dim]    */
    size_t cap_xs;
} sph_neighbors;

/* Builds the lists of all grid points within radius of each query point xq[i*dim + k].
   x is the array the grid was built on. exclude_self: xq is that same point set, and a point is
   not listed as its own neighbour. Points in any order: those not in the grid's cell order are
   searched through a copy in that order (n * dim more reals in nl), 3-6 times faster than
   through the grid's permutation. Memory is reused between builds and grows only when needed.
   SPH_ERR_ARG for radius not in (0, g->cell] or a NULL array; SPH_ERR_NOMEM (the lists are then
   empty, n = 0, until a build succeeds). */
SPHDEF sph_status sph_neighbors_build(sph_neighbors* nl, const sph_grid* g, const sph_real* x,
                                      const sph_real* xq, size_t nq, sph_real radius,
                                      int exclude_self);
SPHDEF void sph_neighbors_free(sph_neighbors* nl);

/* ============================================================================================== */
/* >>operators                                                                                    */
/* ============================================================================================== */

/* Corrected SPH derivative operators on any point set (Bonet & Lok 1999; Negi & Ramachandran
   2022, Table II), usable without a world. The points x (n of them, stride g->dim) are
   those the grid was built on, and nl their lists from sph_neighbors_build(nl, g, x, x, n, k->radius,
   exclude_self = 1); pair vectors follow the grid's periodic directions. vol[i] is the
   integration volume omega_i [m^dim] (sph_op_volume), B the d x d correction matrix of each point
   (d*d entries per point, row-major; sph_op_correction), or NULL for the uncorrected operator.
   Scalar fields are read as f[i * stride]. On a lattice B = I and the corrected and uncorrected
   operators agree; on disordered points only the corrected ones converge at second order
   (tests/test_operators.c). Loops are parallel over points (OpenMP) and deterministic. The
   operators only read their inputs; an output array must not overlap any input. */

/* omega_i = 1 / (W(0) + sum_j W_ij) [m^dim]: Shepard volume (Negi & Ramachandran 2022 eq. 6). */
SPHDEF void sph_op_volume(const sph_grid* g, const sph_neighbors* nl, const sph_kernel* k,
                          const sph_real* x, size_t n, sph_real* vol);
/* B_i = [sum_j omega_j grad W_ij (x) (x_j - x_i)]^-1 (Negi & Ramachandran 2022 eq. 11; Bonet & Lok
   1999): makes the gradient exact for linear fields. Returns the number of points whose moment
   matrix was singular (too few neighbours); theirs is set to the identity. */
SPHDEF size_t sph_op_correction(const sph_grid* g, const sph_neighbors* nl, const sph_kernel* k,
                                const sph_real* x, const sph_real* vol, size_t n, sph_real* B);
/* grad f_i = sum_j (f_j - f_i) B_i grad W_ij omega_j  (asym_bc)   -> grad[i * dim + a] [f/m] */
SPHDEF void sph_op_gradient(const sph_grid* g, const sph_neighbors* nl, const sph_kernel* k,
                            const sph_real* x, const sph_real* vol, const sph_real* B,
                            const sph_real* f, size_t stride, size_t n, sph_real* grad);
/* div u_i = sum_j (u_j - u_i) . B_i grad W_ij omega_j  (div_bc), u with stride dim -> div[i] [u/m] */
SPHDEF void sph_op_divergence(const sph_grid* g, const sph_neighbors* nl, const sph_kernel* k,
                              const sph_real* x, const sph_real* vol, const sph_real* B,
                              const sph_real* u, size_t n, sph_real* div);
/* The iterative particle shifting displacement (Huang et al. 2019; Negi & Ramachandran 2022 eq.
   19): dx_i = h sum_j n_ij W_ij omega_j, n_ij = (x_i - x_j)/|x_i - x_j|, which moves a point away
   from crowded neighbours; repeated with fresh lists it relaxes a set to uniform spacing. [m] */
SPHDEF void sph_op_shift(const sph_grid* g, const sph_neighbors* nl, const sph_kernel* k,
                         const sph_real* x, const sph_real* vol, size_t n, sph_real* dx);
/* Lap f_i = sum_j (G_j - G_i) . B_i grad W_ij omega_j, G = the corrected gradient of f
   (coupled_bc: the divergence of the gradient, two passes). grad: scratch of n * dim reals that
   holds G afterwards. -> lap[i] [f/m^2] */
SPHDEF void sph_op_laplacian(const sph_grid* g, const sph_neighbors* nl, const sph_kernel* k,
                             const sph_real* x, const sph_real* vol, const sph_real* B,
                             const sph_real* f, size_t stride, size_t n, sph_real* grad,
                             sph_real* lap);

/* ============================================================================================== */
/* >>world                                                                                        */
/* ============================================================================================== */

typedef enum sph_solver {
    SPH_SOLVER_WCSPH = 0, /* weakly compressible SPH with an equation of state                */
    SPH_SOLVER_IISPH,     /* implicit incompressible SPH (Ihmsen et al. 2014), relaxed Jacobi  */
    SPH_SOLVER_PCISPH,    /* predictive-corrective incompressible SPH (Solenthaler & Pajarola
                             2009) and the enhanced multiphase version of Enhanced PCISPH 2018 */
    SPH_SOLVER_COMPRESSIBLE, /* explicit compressible multiphase SPH with an energy equation
                             (Ott & Schnetter 2003): gases, shocks, large density
                             ratios                                                          */
    SPH_SOLVER_DFSPH,     /* divergence-free SPH (Bender & Koschier 2015, 2017): a constant-
                             density and a divergence-free pressure solve per step. Appended
                             last: saved worlds store the solver number                     */
    SPH_SOLVER_PBF        /* position based fluids (Macklin & Mueller 2013): a fixed number of
                             Jacobi projections of the density constraint per step, large
                             steps, no pressure solve to converge (games; see >>pbf)        */
} sph_solver;

/* PCISPH's pressure gain (Solenthaler & Pajarola 2009; Enhanced PCISPH 2018 sec. 3.1, eq. 3.5). */
typedef enum sph_pcisph_factor {
    SPH_PCISPH_PROTOTYPE = 0, /* one factor per phase from a particle with a full lattice
                                 neighbourhood (Solenthaler & Pajarola 2009, eq. 3.5) (default) */
    SPH_PCISPH_PER_PARTICLE   /* per particle and step from its actual neighbours and masses
                                 (Enhanced PCISPH 2018 sec. 3.2.4): for multiphase flows     */
} sph_pcisph_factor;

typedef enum sph_density {
    SPH_DENSITY_CONTINUITY = 0, /* d rho_i/dt = sum_j m_j v_ij . grad W_ij   (default)            */
    SPH_DENSITY_SUMMATION,      /* rho_i = sum_j m_j W_ij                                         */
    SPH_DENSITY_PARTICLE        /* Ott-Schnetter: d rho_i/dt = m_i sum_j v_ij . grad W_ij (eq. 11) */
} sph_density;

typedef enum sph_pressure_grad {
    SPH_PGRAD_SYMMETRIC = 0, /* sum_j m_j (p_i/rho_i^2 + p_j/rho_j^2) grad W_ij  (default)        */
    SPH_PGRAD_MULTIPHASE,    /* sum_j m_j (p_i + p_j)/(rho_i rho_j) grad W_ij (large density ratios;
                                Ott & Schnetter eq. 12)                                          */
    SPH_PGRAD_INTERFACE,     /* 1/m_i sum_j (V_i^2 + V_j^2) p_ij grad W_ij, V = m/rho, with the
                                density-weighted p_ij = (rho_j p_i + rho_i p_j)/(rho_i + rho_j)
                                (Hu & Adams 2006; Adami, Hu & Adams 2013 eq. 7-8): eq. 12 inside
                                a phase; at an interface the light side sees its own pressure,
                                which holds a 1000:1 interface under gravity                    */
    SPH_PGRAD_DIFFERENCE,    /* sum_j m_j (p_j - p_i)/(rho_i rho_j) grad W_ij: the multiphase form
                                without its zeroth-order error 2 p_i sum_j V_j grad W_ij, so a
                                uniform pressure exerts no force on any particle arrangement and
                                rows of particles slide past each other freely (buoyancy-driven
                                interfaces: Rayleigh-Taylor growth within 10 % of the viscous
                                theory, tests/test_rt.c, where the forms above grow 3-10 times
                                too slowly). Not pairwise antisymmetric: momentum is conserved
                                only to the discretisation error. WCSPH only (sph_world_init
                                rejects it for the other solvers: PCISPH's gain and the
                                compressible step's energy need the antisymmetric forms), for
                                fluid that fills its walls: a free surface is refused at the
                                first step (SPH_ERR_ARG, sph__check_free_surface)               */
    SPH_PGRAD_VOLUME         /* 1/m_i sum_j (V_i^2 p_i + V_j^2 p_j) grad W_ij, V = m/rho: the pair
                                term Hu & Adams 2006 derive with the particle number density
                                1/V, the momentum equation that goes with Ott & Schnetter's
                                particle-density continuity (eq. 10-11: dV_i/dt and the work of
                                the pressure forces cancel pair by pair). With it the
                                compressible step holds a 1000:1 interface at rest (PHASES)   */
} sph_pressure_grad;

typedef enum sph_integrator {
    SPH_INTEGRATOR_SYMPLECTIC_EULER = 0, /* kick-drift, one force evaluation (default)         */
    SPH_INTEGRATOR_VERLET                /* Stormer-Verlet drift-kick-drift, second order       */
} sph_integrator;

/* Which WCSPH scheme sph_step_wcsph runs. */
typedef enum sph_wcsph_scheme {
    SPH_SCHEME_STANDARD = 0, /* the options above: continuity/summation, delta-SPH, artificial and
                                laminar viscosity, walls (default)                             */
    SPH_SCHEME_SECOND_ORDER  /* L-IPST-C (Negi & Ramachandran 2022): Bonet-Lok
                                corrected pressure gradient and divergence, coupled Laplacian
                                viscosity, fluid density apart from the Shepard volume, RK2
                                midpoint, iterative shifting every def.shift_every steps with
                                Taylor-corrected fields. Needs every direction periodic, no walls
                                and no summation density (else the step fails, SPH_ERR_ARG).
                                Second order in space (tests/test_soc.c,
                                bench/convergence.c)                                     */
} sph_wcsph_scheme;

typedef enum sph_viscosity_form {
    SPH_VISC_MORRIS = 0, /* Morris et al. 1997: sum_j m_j (mu_i + mu_j) x_ij.grad W_ij /
                            (rho_i rho_j (r^2 + eta^2)) v_ij, divided by the particles' measured
                            second moments (see VISCOSITY at the top) (default)              */
    SPH_VISC_MONAGHAN    /* Monaghan 2005 / Enhanced PCISPH 2018 eq. 2.5: 2(d+2) ... (v_ij.x_ij)
                            grad W_ij; conserves angular momentum, less accurate on a lattice */
} sph_viscosity_form;

/* How IISPH solves its pressure system A p = s (Ihmsen et al. 2014 eq. 14). */
typedef enum sph_pressure_solve {
    SPH_PSOLVE_JACOBI = 0, /* relaxed Jacobi (Ihmsen et al. 2014 eq. 16; the default)        */
    SPH_PSOLVE_CG          /* preconditioned conjugate gradients on the active set (zero wall
                              pressure only, where A is self-adjoint; other schemes use Jacobi):
                              reduces the smooth part of the pressure error, which Jacobi
                              leaves in (sph__iisph_cg)                                        */
} sph_pressure_solve;

/* How a fluid particle sees the pressure of a wall particle (Meiers 2025 sec. 4.2). */
typedef enum sph_boundary_pressure {
    SPH_BP_EXTRAPOLATE = 0, /* Adami et al. 2012: p_b from the fluid with body force and wall
                               acceleration (WCSPH's and the compressible step's default)      */
    SPH_BP_MIRROR,          /* p_b = p_i, rho_b = rho_i (Koschier et al. 2020): REJECTED with
                               SPH_ERR_ARG by sph_world_init and every step. Its wall force is
                               no constraint force and not conservative, and it put energy into
                               a tank at rest with every solver (see BOUNDARIES); kept so that
                               code naming it compiles and gets the reason                    */
    SPH_BP_ZERO,            /* p_b = 0 (Akinci et al. 2012 as used by Ihmsen et al. 2014; Bender
                               & Koschier 2017): IISPH's and DFSPH's default                  */
    SPH_BP_AUTO             /* (the default of sph_world_def_default) resolved by
                               sph_world_init from def.solver: ZERO for IISPH and DFSPH, whose
                               every user scene of tests/test_scenes.c it holds (extrapolated
                               walls made IISPH's tank at rest slosh at 0.86 sqrt(g H) and
                               mirrored ones gained energy), EXTRAPOLATE for the others (WCSPH
                               with zero wall pressure lets particles into the walls). w.def
                               holds the scheme used                                          */
} sph_boundary_pressure;

/* Where wall particle volumes come from. */
typedef enum sph_boundary_volume {
    SPH_BVOL_GIVEN = 0, /* as added (dx^dim, or the array given to sph_add_boundary)           */
    SPH_BVOL_AKINCI,    /* V_b = gamma / sum_b' W_bb' over wall neighbours, recomputed whenever
                           walls move (Akinci et al. 2012): for single-layer and irregularly
                           sampled walls (lattice walls of several layers keep GIVEN). gamma
                           (def.boundary_gamma) is by default the one that gives a fluid
                           lattice its rest density beside a flat single layer
                           (sph__akinci_gamma: 0.585 for Wendland C2 at h = 1.3 dx)           */
    SPH_BVOL_AUTO       /* the larger of the two, per wall particle, when walls are added
                           (default): a lattice wall of several layers keeps its given volumes
                           bit for bit within the fluid's reach (Akinci's are smaller there:
                           0.59-0.74 dx^dim), a wall a host samples as one layer weighs as a
                           full wall; the given volume capped by d^dim, d the distance to
                           the nearest wall particle, where walls are sampled denser than the
                           fluid (see sph__stage_boundary_volume_auto)                        */
} sph_boundary_volume;

typedef enum sph_wall {
    SPH_WALL_FREE_SLIP = 0, /* no viscous interaction with wall particles (default)             */
    SPH_WALL_NO_SLIP        /* viscous terms use Adami's extrapolated wall velocity (not PBF,
                               whose walls are free slip: SPH_ERR_ARG)                         */
} sph_wall;

typedef enum sph_pressure_clamp {
    SPH_CLAMP_AUTO = 0, /* clamp in WCSPH (not fully periodic) or with summation (default)      */
    SPH_CLAMP_ON,       /* p = max(p, 0): no tension (free surfaces without a background pressure) */
    SPH_CLAMP_OFF       /* negative pressures act as tension                                     */
} sph_pressure_clamp;

/* Equation of state of a phase. p_b is the phase's back_pressure: its pressure at rest density.
   The gas forms depend on the specific internal energy e [J/kg] and need the compressible step,
   which evolves e; Tait and linear depend on the density only. */
typedef enum sph_eos {
    SPH_EOS_TAIT = 0,     /* p = B((rho/rho0)^gamma - 1) + p_b, B = rho0 c0^2 / gamma (default)   */
    SPH_EOS_LINEAR,       /* p = c0^2 (rho - rho0) + p_b                                        */
    SPH_EOS_IDEAL_GAS,    /* p = (gamma - 1) rho e; c^2 = gamma p / rho; gamma 0 = 1.4; the phase
                             starts at e0 with p(rho0, e0) = p_b                                 */
    SPH_EOS_STIFFENED_GAS /* p = (gamma - 1) rho e - gamma p_inf, c^2 = gamma (p + p_inf) / rho
                             (liquids in shocks; Harlow & Amsden 1971), with p_inf chosen so that
                             c(rho0, p_b) = sound_speed: p_inf = rho0 c0^2 / gamma - p_b;
                             gamma 0 = 4.4                                                      */
} sph_eos;

/* Faces of an axis-aligned box, for sph_add_wall_box's open_faces. */
enum {
    SPH_FACE_XMIN = 1, SPH_FACE_XMAX = 2, SPH_FACE_YMIN = 4,
    SPH_FACE_YMAX = 8, SPH_FACE_ZMIN = 16, SPH_FACE_ZMAX = 32
};

/* Stages whose time is measured in w.stats.stage_time. */
typedef enum sph_stage {
    SPH_STAGE_BOUNDARY = 0, /* boundary motion callback                                         */
    SPH_STAGE_NEIGHBORS,    /* sort by cell, grids, neighbour lists                              */
    SPH_STAGE_DENSITY,      /* summation density or density rate                                */
    SPH_STAGE_PRESSURE,     /* equation of state, wall pressure extrapolation                    */
    SPH_STAGE_FORCES,       /* pressure, viscous, body and user accelerations                    */
    SPH_STAGE_INTEGRATE,    /* time integration, diagnostics, blow-up detection                  */
    SPH_STAGE_COUNT
} sph_stage;

struct sph_world;

/* Adds body accelerations [m/s^2] of fluid particles begin..end-1 to acc[i*dim + k] (which holds
   gravity when it is called). Called once per force evaluation (once per step; once per RK2
   stage with SPH_SCHEME_SECOND_ORDER) for disjoint ranges of at most 256 particles, in parallel
   from worker threads (from the calling thread with at most 2048 fluid particles or without
   OpenMP), after the step's densities (and, except in PCISPH and IISPH, pressures) are known and
   before the pressure and viscous forces (PBF: at the step's start, with the last step's
   densities, before its prediction); w->time is the time at the start of the step. It may
   read the world and must write only acc[i*dim + k] for i in its range; it must be safe to run
   on several threads at once. The wall pressure extrapolation sees these accelerations like
   gravity. */
typedef void (*sph_force_fn)(const struct sph_world* w, size_t begin, size_t end, sph_real* acc,
                             void* user);

/* Kinematic boundary motion. Called once per step, on the calling thread, before the neighbour
   search, with the time [s] at which the step evaluates forces (the start of the step; its middle
   with Stormer-Verlet; its end with PBF, whose projection puts the particles against the walls
   as they stand then); not called while the world has no boundary particles. It sets w->b_x and
   w->b_v for the boundary particles it moves (identify them by w->b_body, w->b_id or the
   reference position w->b_x0) and may set w->b_a (wall acceleration, used by the pressure
   extrapolation). With a callback set, walls are re-sorted every step. A non-finite b_x, b_v or
   b_a, or a b_x too far from the origin for dx (sph_world_def.spacing), fails the step with
   SPH_ERR_ARG after the callback (and a Verlet half drift) changed the world. */
typedef void (*sph_boundary_fn)(struct sph_world* w, double time, void* user);

typedef struct sph_world_def {
    int dim;                   /* 1, 2 or 3 (set by sph_world_def_default)                         */
    sph_real spacing;          /* particle spacing dx [m]; default 0.01; finite, > 0              */
    sph_real h_factor;         /* h = h_factor * dx [-]; 0 (default) = kernel's recommended value
                                  (sph_kernel_default_h_factor); 0 or (0, 100]. w.def holds the
                                  value used                                                     */
    sph_kernel_type kernel;    /* default SPH_KERNEL_AUTO: sph_world_init takes the cubic B-spline
                                  at h = dx (h_factor 0) in 3D for IISPH, DFSPH and PBF with zero
                                  wall pressure, else Wendland C2 (h = 1.3 dx). Measured on the 3D
                                  dam break and tank (README, "The kernel in 3D"): the cubic's 26
                                  lattice neighbours against Wendland's 80 take those solvers
                                  through a simulated second in 0.5-0.7 of the time at the same
                                  compression, and their tank at rest comes closer to rest;
                                  WCSPH's hydrostatic pressure and extrapolated walls are worse
                                  with it, and in 2D it gains nothing. w.def holds the kernel
                                  used                                                           */
    sph_real gravity[3];       /* [m/s^2]; default (0, -9.81, 0) in 2D/3D (y is up), 0 in 1D;
                                  finite; components beyond dim are ignored                      */
    sph_solver solver;         /* used by sph_step / sph_advance (and sph_set_hydrostatic);
                                  default SPH_SOLVER_WCSPH. SPH_SOLVER_PCISPH with the other
                                  fields as sph_world_def_default left them gets the original
                                  PCISPH's settings, sph_world_def_pcisph(&def, 0)              */
    sph_density density;       /* default SPH_DENSITY_CONTINUITY; IISPH always uses summation    */
    sph_pressure_grad pressure_grad; /* default SPH_PGRAD_SYMMETRIC                               */
    sph_integrator integrator; /* default SPH_INTEGRATOR_SYMPLECTIC_EULER; read by WCSPH and
                                  PCISPH (IISPH and the compressible step: symplectic Euler)    */
    sph_wcsph_scheme scheme;   /* default SPH_SCHEME_STANDARD                                     */
    int shift_every;           /* SPH_SCHEME_SECOND_ORDER: shift every this many steps (Negi &
                                  Ramachandran 2022: 10, the default); 0 = never; >= 0           */
    sph_pressure_clamp clamp;  /* default SPH_CLAMP_AUTO: no tension in WCSPH unless the domain
                                  is periodic in every direction (see sph__clamps: a free
                                  surface's negative pressures clump the particles), and none
                                  with summation density. WCSPH and compressible only: the
                                  incompressible solvers always clamp                           */
    sph_real delta;            /* delta-SPH density diffusion coefficient [-]; default 0.1;
                                  [0, 1]. Acts in the continuity and particle density rates, not
                                  in IISPH or the second-order scheme                            */
    sph_real alpha;            /* Monaghan artificial viscosity alpha [-]; default 0.02; [0, 10]  */
    sph_real beta;             /* Monaghan artificial viscosity beta [-]; default 0; [0, 10]      */
    sph_real shifting;         /* particle shifting coefficient A [-] (see >>wcsph,
                                  sph__stage_shift): each step moves fluid particle i by
                                  -D sum_j V_j (1 + 0.2 (W_ij/W(dx))^4) grad W_ij, D = A h U dt
                                  but at most 0.2 h^2 / dim (IISPH, DFSPH: 0.1 h^2 / dim), U
                                  the last step's largest speed;
                                  4 is Sun et al. 2017's delta+-SPH. Default 0 (off); [0, 10];
                                  WCSPH (standard scheme), IISPH and DFSPH. No free-surface
                                  treatment: for flows that fill their walls (a vortex in a
                                  closed 2D box decays 1.1-2.1 times its exact rate with A = 4,
                                  3.2-4.2 times without: README, Validation)                   */
    sph_viscosity_form viscosity_form; /* laminar viscosity operator; default SPH_VISC_MORRIS    */
    sph_wall wall;             /* default SPH_WALL_FREE_SLIP                                      */
    sph_boundary_pressure boundary_pressure; /* default SPH_BP_AUTO (see there)                   */
    sph_boundary_volume boundary_volume;     /* default SPH_BVOL_AUTO                             */
    sph_real boundary_gamma;   /* Akinci volume factor gamma_1 (Meiers 2025 eq. 27) [-]; default 0:
                                  calibrated by sph_world_init (w.def holds the value) so that
                                  a flat single layer at spacing dx gives the fluid lattice
                                  beside it the rest density; else (0, 10]; SPH_BVOL_AKINCI only */
    sph_real cfl;              /* acoustic CFL number for sph_stable_dt (WCSPH, compressible; also
                                  PCISPH's delta-SPH speed cfl h / dt); default 0.25; (0, 1]     */
    sph_real cfl_viscous;      /* viscous limit dt <= cfl_viscous h^2 / nu (0.8 of it for
                                  SPH_VISC_MONAGHAN); default 0.125; (0, 1]                     */
    sph_real cfl_force;        /* force limit dt <= cfl_force sqrt(h / |a|), |a| the largest of
                                  the last step (|g| before the first and while there is no
                                  fluid); default 0.25; (0, 1]                                   */
    sph_real cfl_velocity;     /* incompressible solvers: dt <= cfl_velocity dx / |v|max;
                                  default 0.4; (0, 1]                                            */
    sph_real max_dt;           /* upper bound for sph_stable_dt [s]; 0 (default) = none; >= 0     */
    /* iterative pressure solvers (IISPH, PCISPH, DFSPH) */
    sph_real tolerance;        /* stop when the mean predicted compression <= tolerance [-];
                                  default 0.001 (sph_world_def_pcisph: 1e-4); (0, 1)             */
    int min_iterations;        /* default 2 (sph_world_def_pcisph: 3); [0, 100000]               */
    int max_iterations;        /* default 100; [max(1, min_iterations), 100000]. A solve that
                                  reaches it above its tolerance takes the step with its last
                                  pressure and returns SPH_ERR_NOT_CONVERGED (sph_advance then
                                  undoes the step and retries a smaller one)                     */
    sph_real omega;            /* IISPH's and DFSPH's relaxed Jacobi weight [-]; 0 or (0, 1];
                                  0 (default): 0.5, or 0.3 where a full lattice has more than 50
                                  neighbours (3D Wendland C2: see sph_world_def_default). w.def
                                  holds the value used                                           */
    sph_pressure_solve pressure_solve; /* IISPH: SPH_PSOLVE_JACOBI (default) or SPH_PSOLVE_CG (zero
                                  wall pressure only; Jacobi with the other schemes); max_iterations
                                  then counts products with A                                    */
    sph_real warm_start;       /* iterative solvers: initial pressure = warm_start * last pressure
                                  (PCISPH: times 4 (dt_prev / dt)^2 when the step more
                                  than doubles);
                                  0.5 (sph_world_def_pcisph: 0 for the original, 0.5 enhanced);
                                  [0, 1]                                                         */
    sph_real tolerance_max;    /* PCISPH: also stop only when the largest compression <= this;
                                  0 (default) = no such condition; 0 or (0, 1)                  */
    sph_pcisph_factor pcisph_factor; /* default SPH_PCISPH_PROTOTYPE                             */
    sph_real pcisph_gain;      /* 1 (default): displacement dt^2 F/m of the original paper; 2: the
                                  thesis' dt^2/2 F/m, which doubles the correction; (0, 4]    */
    sph_real pressure_smoothing; /* PCISPH: chi of p <- chi p + (1 - chi) <p> (Enhanced PCISPH 2018
                                  sec. 3.2.1); 1 (default) = off, [0, 1]                     */
    sph_real divergence_tolerance; /* DFSPH's divergence-free solve stops when the mean
                                  compressive density rate max(D rho/Dt, 0) dt / rho0 <= this
                                  [-] (after min_iterations, at most max_iterations); default
                                  0.001 (0.1 % per step, as the constant-density tolerance);
                                  (0, 1)                                                     */
    /* position based fluids (SPH_SOLVER_PBF; Macklin & Mueller 2013) */
    int pbf_iterations;        /* density projections per step (fewer once the mean compression
                                  is at most def.tolerance); default 3; [1, 1000]. The step's
                                  cost grows with it, its compression falls as 1 / it       */
    sph_real pbf_relaxation;   /* the constraint-force-mixing epsilon of eq. 11 as a multiple of
                                  a full lattice particle's sum_k |grad_k C_i|^2 (so the paper's
                                  epsilon [1/m^2] is this times that sum) [-]; default 1 (half
                                  the correction a particle's own constraint asks; Jacobi
                                  overshoots without it); (0, 100]                            */
    sph_real pbf_scorr;        /* k of the tensile correction s_corr = -k (W_ij / W(dq))^n, eq. 13,
                                  n = 4, |dq| = 0.2 support radii, in units of a full lattice
                                  particle's multiplier per unit C [-]; default 0: off (the
                                  paper's k is 0.1; with the clamped constraint it has no
                                  tension to balance and only pushes the surface up, see
                                  >>pbf); [0, 1]                                              */
    sph_real pbf_xsph;         /* c of XSPH viscosity, eq. 17, with V_j = m_j / rho0 [-]; default
                                  0.01 (the paper's); [0, 0.5]                                */
    sph_real pbf_compression;  /* the mean compression rho/rho0 - 1 that sph_stable_dt aims at
                                  for PBF [-] (its compression grows with dt^2, see >>pbf);
                                  default 0.01; (0, 0.1]                                      */
    sph_real domain_lo[3];     /* [m] domain box; particles outside are counted in                */
    sph_real domain_hi[3];     /*     w.stats.n_outside. lo == hi in a direction: unbounded there
                                  (default 0, 0: unbounded); finite, lo <= hi                    */
    int periodic[3];           /* nonzero: direction wraps over [domain_lo, domain_hi), which must
                                  be at least two kernel support radii long; default 0          */
    sph_real max_compression;  /* blow-up if rho/rho0 - 1 exceeds it [-]; default 0.2; 0 = no
                                  check; >= 0; not applied to gas phases. IISPH and DFSPH: the
                                  density their solve predicts for the step's end (a host's
                                  particles placed into others they push apart)               */
    sph_real max_speed;        /* blow-up if |v| exceeds it [m/s]; 0 (default) = the largest c0
                                  (WCSPH), 10 c0 (compressible step), c0 + 2 |v_wall|max for
                                  PCISPH, IISPH, DFSPH and PBF (ten times the free-fall speed
                                  over the height the fluid can fall, or the fastest start,
                                  with the automatic c0; the jets of impacts grow with the
                                  resolution and can pass it: raise it there), for them plus
                                  what a fall below the fluid's start gives: v^2 <= bound^2 +
                                  2 (head - (-g.x)), head the largest -g.x + v^2/2 at the first
                                  step since the host changed the state; no check while no c0
                                  is set; >= 0                                                 */
    sph_real max_displacement; /* blow-up if a fluid particle moves more than this many spacings
                                  dx in one step [-] (a large step through a thin wall, or a
                                  runaway); default 1; 0 = no check; >= 0                        */
    int check_walls;           /* nonzero (default): a fluid particle that ends a step inside the
                                  wall layers (its wall volume fraction sum_b V_b W_ib / S beyond
                                  that of a particle on the first layer of a flat wall) fails
                                  the step with SPH_ERR_UNSTABLE naming it; lattice walls of
                                  given volumes only (not SPH_BVOL_AKINCI, whose single layers
                                  weigh as a full wall). With one closed box of sph_add_wall_box
                                  and no boundary_motion, also any wall volumes: a fluid particle
                                  more than dx outside the box fails the step (off once fluid is
                                  added outside the box; not kept by sph_world_save). 0 = off   */
    sph_real wall_contact;     /* a fluid particle's centre stays at least wall_contact dx from
                                  every boundary particle's centre [-]: a step that ends closer
                                  moves it back out along the line between them and removes its
                                  velocity into that particle (relative to the wall's), a
                                  free-slip, inelastic contact (sph__wall_contact; every step
                                  but SPH_SCHEME_SECOND_ORDER's, not yet); in 3D with zero wall
                                  pressure and PCISPH, IISPH or DFSPH for particles short of
                                  neighbours (fewer fluid and wall neighbours than 0.7 of a full
                                  lattice's: splashes, sheets), ramping down to 0.6 for the
                                  others (0.85 and more), whose resting rows zero wall pressure
                                  puts nearer the wall than the lattice. Default
                                  0.02 + sqrt(dim)/2 (0.73 in 2D, 0.89 in 3D: a particle over the
                                  hollow between the particles of a wall lattice at dx keeps its
                                  centre on the fluid side of the wall's face; a fluid lattice
                                  sits 1 dx from its wall lattice); 0 = off; [0, 1.5]. Walls
                                  sampled at up to sqrt(2) wall_contact dx (3D; 2 wall_contact
                                  dx in 2D) stay watertight                                      */
    int max_substeps;          /* sph_advance: at most this many sub-steps (retries included) per
                                  call, else SPH_ERR_BUDGET with the world as before the call;
                                  default 100000; [1, 2^30]                                      */
    sph_real neighbor_skin;    /* Verlet skin of the neighbour lists, a fraction of the kernel's
                                  support radius R [-]: candidate lists within (1 + skin) R are
                                  searched (and the particles sorted by cell) only when a particle
                                  has moved half the skin since, and each step keeps of them the
                                  pairs within R (Verlet 1967; see NEIGHBOUR GRID). 0 = search
                                  every step; default -1: automatic, 0.2 for WCSPH and the
                                  compressible step, 0 for PCISPH, IISPH, DFSPH and PBF; -1 or
                                  [0, 1]                                                         */
    sph_force_fn force;        /* optional external accelerations (sph_force_fn); default NULL  */
    void* force_user;          /* passed to force as user                                        */
    sph_boundary_fn boundary_motion; /* optional moving boundary particles (default NULL)        */
    void* boundary_user;       /* passed to boundary_motion as user                              */
} sph_world_def;

/* A material. Zero fields take the documented defaults, so a compound literal with only the rest
   density is a complete phase. sph_world_add_phase checks every field (SPH_ERR_ARG names the
   first bad one) and keeps a copy with the defaults filled in as w.phases[index]. */
typedef struct sph_phase {
    sph_real rest_density;   /* rho0 [kg/m^3]; required, finite, > 0                              */
    sph_real viscosity;      /* kinematic viscosity nu [m^2/s]; 0 = inviscid (default); >= 0      */
    sph_real sound_speed;    /* c0 [m/s] at rest density; >= 0; 0 = automatic: 10 * max(sqrt(2
                                |g| H), |v|max), H = the phase's extent along gravity plus dx
                                plus the fall from the fluid's lowest particle to the walls
                                below it (sph__resolve_sound_speed; walls far below that the
                                fluid cannot reach raise it too, and WCSPH's step falls with
                                1/c0: set it then), chosen when a step (or sph_stable_dt,
                                sph_set_hydrostatic) first
                                finds particles of the phase, and again (kept if larger) at the
                                first step after fluid or walls are added later
                                (sph__rederive_sound_speed); with a force callback or moving
                                walls, WCSPH's sph_advance raises it to 10 |v|max when the
                                fastest particle passes 0.15 c0 (sph__sound_speed_follows_flow);
                                without gravity and motion that
                                fails (SPH_ERR_ARG) for WCSPH and the compressible step, and
                                IISPH and PCISPH run without c0. Required (> 0) for a stiffened
                                gas; an ideal gas's must be left 0: it is sqrt(gamma p_b / rho0),
                                filled in by sph_world_add_phase                                 */
    sph_eos eos;             /* default SPH_EOS_TAIT; the gas laws need sph_step_compressible    */
    sph_real gamma;          /* exponent [-]; 0 = 7 (Tait), 1.4 (ideal gas), 4.4 (stiffened gas);
                                0 or [1, 20], > 1 for a gas; unused by the linear law            */
    sph_real back_pressure;  /* p_b [Pa]: the pressure at rest density (the ambient pressure of a
                                gas); default 0; finite, >= 0 for an ideal gas, and a stiffened
                                gas needs p_b <= rho0 c0^2 / gamma (p_inf >= 0). Particles added
                                at rest density, and all gas particles, start at it            */
    sph_real mass;           /* particle mass [kg]; 0 = rest_density * dx^dim (default); >= 0     */
} sph_phase;

/* Diagnostics of the last step, taken at its end (fluid particles only). */
typedef struct sph_stats {
    double dt;                /* [s]                                                              */
    int iterations;           /* solver iterations (1 for WCSPH and the compressible step; with
                                 SPH_SCHEME_SECOND_ORDER the shifting iterations of a step that
                                 shifts)                                                         */
    double solver_error;      /* iterative solvers: mean predicted compression at the last iteration
                                 [-]; the other steps leave it unchanged                         */
    double density_error_avg; /* mean |rho/rho0 - 1| over fluid particles [-]                      */
    double density_error_max; /* max |rho/rho0 - 1| [-]                                           */
    double compression_avg;   /* mean max(rho/rho0 - 1, 0) [-]: compression only (Meiers 2025 eq. 15) */
    double v_max;             /* largest fluid speed [m/s]                                         */
    double a_max;             /* largest acceleration of the step [m/s^2]                          */
    double kinetic_energy;    /* sum 1/2 m |v|^2 [J]                                               */
    double potential_energy;  /* -sum m g . x [J], the fluid's in gravity (0 without; periodic
                                 directions left out): kinetic plus potential is the mechanical
                                 energy, which nothing but the forcing raises                    */
    size_t pairs;             /* fluid-fluid neighbour pairs (each counted from both sides); with
                                 SPH_SCHEME_SECOND_ORDER those of its lists, which reach 0.2 dx
                                 beyond the support                                              */
    size_t contacts;          /* fluid particles that def.wall_contact moved back out of a wall
                                 in the step                                                     */
    size_t n_outside;         /* fluid particles outside the domain box in a bounded, non-periodic
                                 direction (kept, still simulated)                               */
    double stage_time[SPH_STAGE_COUNT]; /* wall-clock seconds per stage                            */
    double step_time;         /* wall-clock seconds of the whole step                              */
    /* set by sph_advance for its last call (unchanged by sph_step_*): */
    int substeps;             /* sub-steps taken, retries included                                 */
    int retries;              /* sub-steps rolled back and retried with a smaller step             */
    double iterations_sum;    /* solver iterations summed over the sub-steps, retries included:
                                 the work of the call in sweeps (IISPH, DFSPH, PCISPH) or products
                                 with A (IISPH's SPH_PSOLVE_CG)                                  */
    double dt_min;            /* smallest sub-step that succeeded [s] (0 if none)                  */
    double dt_factor;         /* the step control's factor on sph_stable_dt after the call [-]: 1
                                 unless failed steps made it smaller; it grows back by 1.1 per
                                 successful sub-step (kept here, so saved with the world)        */
    /* solver state kept between steps (here, so that a saved world restarts bit for bit): */
    double a_np_max;          /* PCISPH, IISPH, DFSPH: largest non-pressure acceleration of the
                                 step [m/s^2], which their force limit reads                     */
    double omega;             /* IISPH, DFSPH: the Jacobi weight in use, def.omega unless a solve
                                 diverged (it then shrinks by 0.7 and grows back by 2 % per
                                 converged solve)                                                */
    double gain_factor;       /* PCISPH: factor on the gain, 1 unless a correction diverged      */
    int iterations_divergence; /* DFSPH: the divergence-free solve's share of iterations (the
                                 constant-density solve's is iterations minus this); 0 for the
                                 other solvers                                                  */
    double divergence_error;  /* DFSPH: mean max(D rho/Dt, 0) dt / rho0 after its divergence
                                 solve [-]; the other steps leave it unchanged                   */
    double ke_low, ke_high;   /* PCISPH, IISPH, DFSPH (PBF without gravity) without forcing: the
                                 least mechanical energy (kinetic + potential) and the largest
                                 kinetic energy since the forcing stopped [J] (the energy check,
                                 sph__energy_check)                                              */
    long unforced_steps;      /* steps since then (0: forced, or none yet)                       */
    int enclosed;             /* PCISPH, IISPH, DFSPH with walls that copy the fluid's pressure:
                                 1 once a step found the fluid enclosed, with no free surface
                                 (sph__enclosed); its walls keep zero pressure from then on  */
    uint64_t neighbor_builds; /* neighbour searches (sort by cell and list build) since
                                 sph_world_init, in the steps kept (sph_advance undoes a
                                 rolled-back step's with it): one a step with neighbor_skin 0,
                                 fewer with a skin (w.steps / neighbor_builds steps per search) */
} sph_stats;

/* Private state (do not touch). */
typedef struct sph__private {
    sph_grid grid, bgrid;           /* fluid and boundary grids (same cells)                       */
    uint8_t* b_near;                /* per cell of bgrid's dense table: a wall particle in the 3^dim
                                       cells around it (sph__grid_near); NULL-like when b_near_on 0 */
    size_t b_near_cap;
    int b_near_on;                  /* b_near holds the current bgrid's cells                      */
    sph_neighbors ff, fb, bf, bb;   /* fluid->fluid, fluid->boundary, boundary->fluid, ->boundary  */
    sph_neighbors cff, cfb, cbf;    /* def.neighbor_skin > 0: the candidate lists within (1 + skin)
                                       R that ff, fb and bf are filtered from every step        */
    sph_neighbors ffh;              /* the fluid's half lists (sph__neighbors_build_self)          */
    sph_real *vl_x, *vl_bx;         /* positions of fluid and boundary particles at their build    */
    size_t vl_x_cap, vl_bx_cap;     /* reals                                                      */
    int vl_valid;                   /* the candidate lists hold for the current particle order     */
    size_t vl_n, vl_nb;             /* particle counts at the build                               */
    uint64_t vl_sorts;              /* w->priv.sorts at the build                                 */
    int vl_restore;                 /* loaded: vl_x, vl_bx, vl_radius, vl_n/nb hold a saved build
                                       to search again at the next step (sph__verlet_restore)      */
    sph_real vl_radius;             /* their radius [m]                                           */
    uint8_t* perm_buf;              /* permutation scratch, capacity * largest element              */
    size_t perm_cap;                /* bytes                                                        */
    double* block;                  /* per-block partial reductions                                 */
    size_t block_cap;
    sph_real* rho_n;                /* Verlet: density at the start of the step (scratch)          */
    size_t rho_n_cap;
    sph_real *aii, *src, *ap;       /* IISPH: diagonal, source, pressure acceleration (scratch;
                                       DFSPH uses ap too)                                         */
    size_t aii_cap, src_cap, ap_cap;
    sph_real* cg;                   /* IISPH's conjugate gradients: r, d, B d, active set (4n)     */
    size_t cg_cap;
    sph_real *df_alpha, *df_alpha_v; /* DFSPH: factor alpha_i of the density and divergence solves */
    sph_real *df_vs, *df_kv, *df_pv; /* DFSPH: v before the pressure, accumulated divergence rate,
                                       divergence pressure (scratch)                              */
    size_t df_alpha_cap, df_alpha_v_cap, df_vs_cap, df_kv_cap, df_pv_cap;
    sph_real *ff_fw, *fb_fw;        /* iterative solvers: grad W_ij / x_ij per listed pair          */
    size_t ff_fw_cap, fb_fw_cap;
    sph_real* pr2;                  /* iterative solvers, WCSPH: p_i / rho_i^2 (scratch)          */
    size_t pr2_cap;
    sph_real* vol;                  /* WCSPH: m_i / rho_i (scratch)                               */
    size_t vol_cap;
    sph_real* shift;                /* each particle's displacement (scratch): WCSPH's shifting,
                                       the wall contact's with a carried density
                                       (sph__contact_density)                                    */
    size_t shift_cap;
    sph_real *xp, *vp;              /* PCISPH: predicted positions and velocities (scratch)         */
    size_t xp_cap, vp_cap;
    sph_real* xs;                   /* PCISPH with two drifts: x^n (scratch)                      */
    size_t xs_cap;
    const sph_real* x_start;        /* a step of two drifts: x^n (xp or xs) for the final drift's
                                       crossing check (sph__wall_crossed), in the particle order
                                       of x_start_sorts; NULL for steps of one drift            */
    uint64_t x_start_sorts;
    sph_real x_start_drift;         /* the time the first drift covered [s]                     */
    sph_real *de, *cs, *vn;         /* compressible: energy rate, sound speed, v at the step start  */
    size_t de_cap, cs_cap, vn_cap;
    sph_real* soc;                  /* second-order scheme: its per-particle scratch                */
    size_t soc_cap;
    sph_real* socw;                 /* second-order scheme: omega_j B_i grad W_ij per listed pair   */
    size_t socw_cap;
    sph_real* lapc;                 /* laminar viscosity (Morris form): each fluid particle's
                                       Laplacian normalisation 1 / m_i (sph__stage_visc_norm)      */
    size_t lapc_cap;
    sph_real* wg;                   /* IISPH, DFSPH: per fluid particle sum_b psi_ib grad W_ib and
                                       sum_b psi_ib v_b . grad W_ib over its wall neighbours, fixed
                                       within a step ((dim + 1) n; sph__wall_grad_sum)            */
    size_t wg_cap;
    sph_real* abody;                /* WCSPH with delta-SPH and a body force: each fluid particle's
                                       body acceleration of the step (gravity and def.force), for
                                       sph__delta_hydro (dim n)                                   */
    size_t abody_cap;
    sph_grid sgrid;                 /* second-order scheme: grid and lists at stage and shifted
                                       positions (the particles are not reordered mid-step)      */
    sph_neighbors snl;
    int sgrid_ready;
    int snl_valid;                  /* snl lists the current particle order (cleared by sorts)      */
    uint64_t sorts;                 /* fluid reorderings so far; snl_sorts: at the lists' build    */
    uint64_t snl_sorts;
    sph_real* bpq;                  /* multiphase walls: (p_b, rho_b/rho0) per wall particle and
                                       phase, extrapolated from that phase's particles (scratch)   */
    size_t bpq_cap;
    int has_energy;                 /* w->e exists (a phase has a gas equation of state)            */
    int solver;                     /* the sph_solver whose step is running                         */
    sph_real* b_sw;                 /* per wall particle: sum_f W_bf of its fluid neighbours        */
    int b_dirty;                    /* boundary particles changed since the last boundary grid     */
    int have_mass;                  /* w->mass is set                                               */
    sph_real lattice_sum;           /* dx^dim sum_j W(x_j) over a square lattice of spacing dx     */
    sph_real lattice_grad;          /* the gradient's first moment on that lattice, see
                                       sph__lattice_grad                                         */
    size_t full_count;              /* neighbours of a particle inside a full square lattice      */
    sph_real contact_short, contact_full; /* the wall contact's ramp, fractions of full_count
                                       (sph__contact_ramp)                                       */
    double thin_sum;                /* a wall particle whose kernel sum over its wall neighbours
                                       (itself included) is below this is in a thin wall: midway
                                       between a lattice plane's and a half space's (3D)         */
    uint8_t* b_thin;                /* [nb] 3D incompressible solvers: 1 for a wall particle of a
                                       thin wall (sph__wall_thin), else 0                        */
    int b_thin_on;                  /* b_thin holds the walls' present order                    */
    double head_ref;                /* the largest specific mechanical energy -g.x + v^2/2 of a
                                       fluid particle at the end of the first step since the host
                                       last changed the state [J/kg] (the speed bound's headroom
                                       for a fall, sph__integrate_with)                          */
    int head_ref_on;                /* head_ref is set                                          */
    sph_real wall_fraction_max;     /* check_walls: wall volume fraction of a particle on the
                                       first layer of a flat lattice wall                          */
    uint8_t c0_auto[SPH_MAX_PHASES]; /* the phase's sound speed was derived (sph_phase)      */
    int placed_c0;                  /* fluid or walls added since: derive it again
                                       (sph__rederive_sound_speed)                              */
    int placed;                     /* fluid or walls added since the last step began
                                       (sph__check_placed)                                      */
    int settle_snap;                /* sph_advance's first sub-step: 1 asks the step to keep its
                                       settled start in snap[1], 2 says it did (sph__settle_placed);
                                       3 a later sub-step; 0 a bare sph_step                      */
    size_t placed_from;             /* the first fluid index added since (0 once walls were)     */
    sph_real tank_lo[3], tank_hi[3]; /* check_walls: the inner faces of the closed box of
                                       sph_add_wall_box (sph__tank_check) [m]                    */
    int tanks;                      /* closed boxes added; -1: a fluid particle was added outside
                                       the one box (the tank check is then off)                  */
    uint8_t* snap[2];               /* sph_advance: the state at the call's start [0] and at the
                                       current sub-step's start [1] (rollback)                      */
    size_t snap_cap[2];             /* bytes                                                        */
    int cold_start;                 /* sph_advance's retry: pressure solves start from 0        */
    double b_time;                  /* when def.boundary_motion last placed the walls [s]       */
    double dt_unpressed;            /* the original PCISPH: sph_stable_dt's step before its
                                       pressure rule (0: none), see sph__standing_keep          */
    double correct_fraction;        /* PCISPH, IISPH, DFSPH: the fraction of the compression
                                       standing at the step's start that the step corrects:
                                       sph_advance's dt_factor while a retry has shortened the
                                       step below the rule, else 1                              */
} sph__private;

/* The world: a caller-owned plain struct. Read the arrays directly; positions and velocities may
   be written between steps. Particles are reordered by cell at every neighbour search (every
   step, or with def.neighbor_skin when the lists are searched again; the second-order scheme:
   whenever it rebuilds its lists): follow a particle by its id, not by its index. Array
   pointers change only when particles are added (w.e appears when a gas phase is added). Use one
   world from one thread at a time (see THREAD SAFETY at the top). */
typedef struct sph_world {
    sph_world_def def;         /* validated copy of the def (h_factor resolved, unused dims 0)     */
    int dim;                   /* 1, 2 or 3                                                        */
    sph_real dx;               /* particle spacing [m]                                             */
    sph_real h;                /* smoothing length [m]                                             */
    sph_kernel kernel;         /* the kernel of def.kernel at h                                    */
    sph_phase phases[SPH_MAX_PHASES]; /* the phases as added, defaults filled in (automatic
                                  sound speeds once chosen)                                      */
    int nphase;                /* phases added                                                     */
    double time;               /* simulated time [s]                                               */
    uint64_t steps;            /* steps taken                                                      */
    double step_time_total;    /* wall-clock seconds spent in steps since init                     */
    double stage_time_total[SPH_STAGE_COUNT]; /* the same per stage                               */

    /* fluid particles, i = 0 .. n-1 */
    size_t n, capacity;        /* particles; room in the arrays                                    */
    sph_real* x;               /* [n*dim] position [m]                                             */
    sph_real* v;               /* [n*dim] velocity [m/s]                                           */
    sph_real* rho;             /* [n] density [kg/m^3]                                             */
    sph_real* p;               /* [n] pressure [Pa]                                                */
    sph_real* m;               /* [n] mass [kg]; NULL while all particles have the same mass       */
    sph_real mass;             /* the mass of every fluid particle while m is NULL [kg]            */
    uint32_t* id;              /* [n] stable identity: 0, 1, 2 ... in the order of adding          */
    uint8_t* phase;            /* [n] phase index                                                  */
    sph_real* a;               /* [n*dim] acceleration of the last step [m/s^2] (scratch)          */
    sph_real* drho;            /* [n] density rate [kg/m^3/s] (scratch; after a DFSPH step the
                                  density rate its divergence solve removed, kept as the next
                                  step's warm start)                                             */
    sph_real* e;               /* [n] specific internal energy [J/kg]; NULL unless a phase has a
                                  gas equation of state (then sph_step_compressible evolves it)  */
    uint32_t next_id;          /* id of the next fluid particle added                              */
    sph_real fill_spacing[3];  /* [m] the spacing per direction that the last successful
                                  sph_fill_box used: dx, or the nearest spacing that fills its box
                                  exactly (the particles' mass follows it); 0 before any fill and
                                  after sph_world_load / _copy (not saved)                       */

    /* boundary particles, b = 0 .. nb-1 */
    size_t nb, b_capacity;     /* particles; room in the arrays                                    */
    sph_real* b_x;             /* [nb*dim] position [m]; move it from def.boundary_motion only     */
    sph_real* b_v;             /* [nb*dim] velocity [m/s] (0 unless the motion callback sets it)   */
    sph_real* b_a;             /* [nb*dim] acceleration [m/s^2]; 0 unless the callback sets it     */
    sph_real* b_x0;            /* [nb*dim] reference position: where the particle was added [m]    */
    sph_real* b_vol;           /* [nb] volume [m^dim] (recomputed with SPH_BVOL_AKINCI)            */
    sph_real* b_p;             /* [nb] extrapolated pressure [Pa] (0 unless SPH_BP_EXTRAPOLATE)    */
    sph_real* b_rho;           /* [nb] extrapolated density relative to rest, rho_b / rho0 [-]
                                  (IISPH, PCISPH: the Shepard average of the fluid's rho/rho0)    */
    sph_real* b_vw;            /* [nb*dim] no-slip wall velocity for viscous terms (scratch)       */
    uint32_t* b_id;            /* [nb] stable identity: 0, 1, 2 ... in the order of adding         */
    uint16_t* b_body;          /* [nb] body tag given when the particle was added                  */
    uint32_t b_next_id;        /* id of the next boundary particle added                           */

    sph_stats stats;           /* diagnostics of the last step                                     */
    sph_status status;         /* status of the last failing call (SPH_OK if none); a step that
                                  passes its input checks resets it, error and error_index       */
    char error[SPH_ERROR_SIZE];/* message of the last failing call                                 */
    long error_index;          /* index of the particle the last error names (fluid or boundary,
                                  as the message says; for sph_add_* an index into the caller's
                                  arrays), -1 if none                                            */
    sph__private priv;
} sph_world;

/* Defaults for dimension dim (1, 2 or 3); see each field's comment. dim is checked by init. */
SPHDEF sph_world_def sph_world_def_default(int dim);
/* Validates def (a bad field is named in w->error, SPH_ERR_ARG; the ranges are in the field
   comments) and sets up an empty world. Overwrites *w: free a world before initialising it
   again. On failure w is left safe to pass to sph_world_free. */
SPHDEF sph_status sph_world_init(sph_world* w, const sph_world_def* def);
/* Releases everything the world allocated and zeroes it; NULL is ignored. */
SPHDEF void sph_world_free(sph_world* w);
/* Adds a phase (see sph_phase for the checks); returns its index (0, 1, ...), or -1 with the
   reason in w->error and the status in w->status (SPH_ERR_ARG, SPH_ERR_CAPACITY beyond
   SPH_MAX_PHASES phases, SPH_ERR_NOMEM). The only adder that returns an index rather than a
   sph_status: check it for -1 before passing it on. */
SPHDEF int sph_world_add_phase(sph_world* w, const sph_phase* phase);
/* Fills the box [lo, hi] with fluid of the phase: round(extent / dx) particles per direction,
   at the spacing that fills the box exactly (dx when the extent is a whole number of spacings),
   each with the rest density times its cell volume as mass. The spacing used per direction is
   in w->fill_spacing afterwards (an extent of 1.03 dx gets one particle at spacing 1.03 dx and
   3 % more mass than w->phases[phase].mass; make extents whole multiples of dx to keep dx).
   Particles sit at the cell centres, half a spacing in from the faces, at rest. SPH_ERR_ARG for a bad phase, lo or hi NULL, not
   finite or hi <= lo, an extent below half a spacing, or a particle within 1e-3 spacings of
   fluid already there (the same box filled twice: coincident particles never separate);
   SPH_ERR_CAPACITY for a huge box. */
SPHDEF sph_status sph_fill_box(sph_world* w, int phase, const sph_real* lo, const sph_real* hi);
/* Adds n fluid particles at x[i*dim + k] with velocities v (NULL = at rest), density rho0, the
   phase's mass and its back pressure. SPH_ERR_ARG (nothing added) for a bad phase, x NULL, a
   non-finite x or v, or a particle within 1e-3 spacings of another of x or of fluid already in
   the world (coincident particles never separate; closer than a spacing but not coincident is
   accepted: the next step first moves fluid that starts more than 1 % compressed apart, in
   positions only: PCISPH, IISPH, DFSPH, PBF, and WCSPH where walls compress it, with one rest
   density; sph__settle_placed). Those solvers' next step refuses fluid placed denser than rest
   in bulk (SPH_ERR_ARG, the world unchanged: most particles away from walls more than 5 %
   compressed, as a lattice closer than def.spacing gives; set sph_phase.mass to the particles'
   share of the volume); n = 0 does nothing. Cost: a pass over the world's particles and
   a table of the n new ones. */
SPHDEF sph_status sph_add_fluid(sph_world* w, int phase, size_t n, const sph_real* x,
                                const sph_real* v);
/* The same with a mass m[i] [kg] and a density rho[i] [kg/m^3] per particle (either NULL: the
   phase's mass, the rest density; each m[i], rho[i] finite and > 0, else SPH_ERR_ARG naming the
   particle). Particles of a gas phase start at its back pressure (their internal energy follows
   from the density); the Tait and linear laws give the pressure of the density. New particles
   take indices from the old w.n up until the next step sorts them, so a host may set w.e (or any
   state) of the particles it just added. */
SPHDEF sph_status sph_add_fluid_ex(sph_world* w, int phase, size_t n, const sph_real* x,
                                   const sph_real* v, const sph_real* m, const sph_real* rho);
/* Adds wall particles around the box [lo, hi] (the fluid's container), `layers` deep (0 = enough
   layers to cover the kernel support). open_faces: SPH_FACE_* bits of faces left open. Body 0.
   Layers lie outside the box, dx apart across a face (the first half a spacing out) and along it
   at sph_fill_box's spacing; each particle's volume is its cell's. layers in [0, 64] and
   open_faces <= 63, a box as for sph_fill_box, else SPH_ERR_ARG; SPH_ERR_CAPACITY for a box
   more than 1e7 spacings long or when its wall particles would take the world past 2^32 - 2
   boundary particles. Only the wall shell is enumerated: time and memory grow with the number
   of wall particles, not with the box's volume. */
SPHDEF sph_status sph_add_wall_box(sph_world* w, const sph_real* lo, const sph_real* hi,
                                   int layers, unsigned open_faces);
/* Adds n boundary particles at x with volumes vol [m^dim] (NULL = dx^dim) and a body tag in
   [0, 65535], at rest, with b_x0 = x. SPH_ERR_ARG (nothing added) for x NULL, a non-finite x,
   a vol[i] not finite and > 0 or a body out of range; n = 0 does nothing. Fluid within a
   spacing of the new walls starts compressed: the next step moves it apart first (see
   sph_add_fluid); fluid inside their layers is refused by that step (def.check_walls). */
SPHDEF sph_status sph_add_boundary(sph_world* w, size_t n, const sph_real* x, const sph_real* vol,
                                   int body);
/* Sets density and pressure of all fluid particles to hydrostatic equilibrium under gravity, in
   columns of width dx across gravity: the pressure grows downwards from the back pressure of the
   column's top phase (0 by default) half a spacing above its top particle. The density is the
   equation of state's when def.solver is WCSPH or compressible (a gas also gets the matching
   w.e), and the rest density for the incompressible solvers. Also chooses automatic sound
   speeds. Velocities are kept. SPH_ERR_ARG if gravity is zero. */
SPHDEF sph_status sph_set_hydrostatic(sph_world* w);
/* The message of the last error (empty if none). */
SPHDEF const char* sph_world_error(const sph_world* w);
/* Bytes the world has allocated: particle arrays (at their capacity), grids, neighbour lists,
   scratch and sph_advance's copies of the state to roll back to. */
SPHDEF size_t sph_world_memory(const sph_world* w);
/* Total fluid mass [kg] and linear momentum [kg m/s] (out[dim]). */
SPHDEF double sph_world_mass(const sph_world* w);
SPHDEF void sph_world_momentum(const sph_world* w, double* out);

/* ============================================================================================== */
/* >>stages                                                                                       */
/* ============================================================================================== */

/* Largest stable time step [s] for the solver from the CFL (acoustic), viscous and force limits.
   Returns 0 and sets w->error if it cannot be determined. The first limit is cfl h / (max c0 +
   |v|max) for WCSPH, cfl h / max(c_i + |v_i|) over fluid particles for the compressible step,
   for IISPH, PCISPH, DFSPH and PBF the velocity limit on the speed reached within the step,
   (|v|max + |a| dt) dt <= cfl_velocity dx (|v|max over fluid and boundary particles, |a| their
   largest non-pressure acceleration: a step from rest is limited too); then the viscous and
   force limits (the incompressible solvers' at 0.4 cfl_force sqrt(h / |a|) with the non-pressure
   |a|: a pressure that enforces incompressibility grows like 1 / dt, and limiting the step by it
   feeds back); for the original PCISPH (summation density) also 0.25 h / sqrt(p_max / rho0)
   with its largest pressure now, or h / (32 |v|max) before any pressure (derived in the code);
   PBF has no force limit, but the step at which its compression is def.pbf_compression (see
   >>pbf); and def.max_dt (see their fields). Fills in automatic sound
   speeds. Fails (SPH_ERR_ARG) for an unknown solver, when WCSPH or the compressible step lacks a
   sound speed it cannot choose, when WCSPH has no sound speed at all (e.g. no particles yet), or
   when nothing limits the step; SPH_ERR_UNSTABLE when the step rounds to 0 (e.g. |v| near the
   largest sph_real, or a cfl factor of 1e-320). */
SPHDEF sph_real sph_stable_dt(sph_world* w, sph_solver solver);
/* One step of the solver selected in def.solver: sph_step_wcsph, _iisph, _pcisph, _compressible,
   _dfsph or _pbf. */
SPHDEF sph_status sph_step(sph_world* w, sph_real dt);
/* Advances by duration [s] in sub-steps of the stable time step (what a game calls per frame);
   the robust integrator. duration finite and >= 0. Each sub-step is dt_factor * sph_stable_dt,
   shortened to land exactly on the end (the call's remainder split into equal steps). A
   sub-step that fails with SPH_ERR_UNSTABLE (blow-up, runaway speed, a particle moving more than
   def.max_displacement or inside a wall) or SPH_ERR_NOT_CONVERGED is undone bit for bit and
   retried at half the step, up to 12 times in a row; dt_factor grows back by 1.1 per successful
   sub-step and is kept in the world. At most def.max_substeps sub-steps (retries included) per
   call (SPH_ERR_BUDGET). On any error the world is as it was before the call (its w.error and
   w.stats.retries tell what happened); on success w.time is exactly the old time + duration.
   w.stats.substeps, .retries, .dt_min and .dt_factor describe the call. */
SPHDEF sph_status sph_advance(sph_world* w, sph_real duration);

/* ============================================================================================== */
/* >>wcsph                                                                                        */
/* ============================================================================================== */

/* One weakly compressible step of dt [s] (finite, > 0) with def.scheme and def.integrator. On
   SPH_ERR_ARG the world is unchanged (but see sph_boundary_fn). */
SPHDEF sph_status sph_step_wcsph(sph_world* w, sph_real dt);

/* ============================================================================================== */
/* >>pcisph                                                                                       */
/* ============================================================================================== */

/* Settings for PCISPH in def: enhanced = 0 gives the original solver of Solenthaler & Pajarola
   2009 (summation density on predicted positions, prototype factor, no diffusion or smoothing,
   walls without extrapolated pressure, symplectic Euler); enhanced = 1 the engineering version of
   Enhanced PCISPH 2018 sec. 3.2 (continuity density with delta-SPH, pressure smoothing chi = 0.8,
   Adami walls with the Shepard wall density, Stormer-Verlet, per-particle factor and the multiphase
   pressure gradient). Each switch remains a def field to change afterwards. Both also set solver =
   SPH_SOLVER_PCISPH, tolerance = 1e-4, min_iterations = 3 and warm_start (0 original, 0.5
   enhanced). def NULL is ignored. A def that sets only solver = SPH_SOLVER_PCISPH (every field
   set here still at sph_world_def_default's value) is given the original's settings by
   sph_world_init (sph__pcisph_unset). */
SPHDEF void sph_world_def_pcisph(sph_world_def* def, int enhanced);
/* One predictive-corrective step of dt [s]: pressures are corrected until the predicted density
   error is below def.tolerance on average (and def.tolerance_max at most, if set), after
   def.min_iterations and at most def.max_iterations. w->stats.iterations and .solver_error
   report the solve. A fluid without a free surface (a closed box it fills) is corrected with
   zero wall pressure whatever def.boundary_pressure says (w.b_p is 0 in such a step), from the
   first step that finds it so on (w->stats.enclosed): walls that copy the fluid's pressure make
   its pressure force no constraint force there. */
SPHDEF sph_status sph_step_pcisph(sph_world* w, sph_real dt);

/* ============================================================================================== */
/* >>iisph                                                                                        */
/* ============================================================================================== */

/* One implicit incompressible step of dt [s] (Ihmsen et al. 2014; Meiers 2025): the pressure makes
   the predicted density rest density to def.tolerance on average. w->stats.iterations and
   .solver_error report the solve. On SPH_ERR_ARG the world is unchanged (but see
   sph_boundary_fn). */
SPHDEF sph_status sph_step_iisph(sph_world* w, sph_real dt);

/* ============================================================================================== */
/* >>dfsph                                                                                        */
/* ============================================================================================== */

/* One divergence-free SPH step of dt [s] (finite, > 0; Bender & Koschier 2015, 2017): the
   divergence-free solve on the velocities at the step's start (def.divergence_tolerance), then
   the constant-density solve on the predicted density (def.tolerance), each after
   def.min_iterations and at most def.max_iterations, warm started with def.warm_start.
   w->stats.iterations (both solves), .iterations_divergence, .solver_error and
   .divergence_error report them. SPH_ERR_NOT_CONVERGED (the step is complete, the message
   names the solve) when a solve ends at max_iterations above its tolerance; SPH_ERR_UNSTABLE as
   for every step. On SPH_ERR_ARG the world is unchanged (but see sph_boundary_fn). */
SPHDEF sph_status sph_step_dfsph(sph_world* w, sph_real dt);

/* ============================================================================================== */
/* >>pbf                                                                                          */
/* ============================================================================================== */

/* One position based fluids step of dt [s] (finite, > 0; Macklin & Mueller 2013): predict with
   gravity and def.force, project the density constraint def.pbf_iterations times (Jacobi; fewer
   once the mean compression is at most def.tolerance), velocity from the positions, XSPH and
   laminar viscosity, wall contact and the blow-up checks. A fixed amount of work per step:
   it never returns SPH_ERR_NOT_CONVERGED; its compression grows with dt^2 and the fluid's depth
   in particles (see >>pbf). w->stats.iterations and .solver_error report the projections; w->p
   is the pressure whose force would have made the step's correction. On SPH_ERR_ARG the world is
   unchanged (but see sph_boundary_fn). */
SPHDEF sph_status sph_step_pbf(sph_world* w, sph_real dt);

/* ============================================================================================== */
/* >>compressible                                                                                 */
/* ============================================================================================== */

/* One explicit compressible step of dt [s] (Ott & Schnetter 2003): density by the
   def.density option (SPH_DENSITY_PARTICLE, eq. 11, for phases of very different density), the
   momentum equation (eq. 12 with def.pressure_grad = SPH_PGRAD_MULTIPHASE), the internal energy
   equation (eq. 13) and Monaghan's (1992) artificial viscosity with def.alpha, def.beta and each
   particle's own sound speed; pressure from each phase's equation of state p(rho, e). Total
   energy (kinetic + internal) is conserved to round-off without walls and body forces. On
   SPH_ERR_ARG the world is unchanged (but see sph_boundary_fn). The only step that accepts gas
   phases. */
SPHDEF sph_status sph_step_compressible(sph_world* w, sph_real dt);

/* ============================================================================================== */
/* >>io                                                                                           */
/* ============================================================================================== */

/* The writers take a const world and change nothing: SPH_ERR_ARG for a NULL argument or a bad
   frame number, SPH_ERR_IO when a file cannot be opened or written (errno says why) or when the
   .pvd to extend is not one this library wrote. Call them between steps, on one thread. */

/* Fluid particles as CSV: id,phase,x,y[,z],vx,vy[,vz],rho,p[,e] (e with gas phases), 9 digits. */
SPHDEF sph_status sph_write_csv(const sph_world* w, const char* path);
/* Fluid and boundary particles as one VTK XML unstructured grid (.vtu; ParaView, VisIt, VTK):
   points in 3D (z = 0 in 2D, y = z = 0 in 1D), one vertex cell per particle, and the point data
   velocity (3 components) [m/s], density [kg/m^3], pressure [Pa], id, phase (-1 on walls),
   kind (0 fluid, 1 boundary), body (the wall's body tag, -1 for fluid) and internal_energy
   [J/kg] when the world has gas phases; the time [s] as the field TimeValue. Binary (raw
   appended, the machine's byte order, 64-bit block headers) and exact: reals are written in
   sph_real's precision (Float64, or Float32 with SPH_FLOAT) and read back bit for bit. Walls
   carry their velocity, extrapolated pressure and density (rho_b / rho0 times phase 0's rest
   density). Allocates nothing. */
SPHDEF sph_status sph_write_vtu(const sph_world* w, const char* path);
/* One frame of a time series: writes <base>_<frame>.vtu (frame with 4 digits, more if needed)
   and lists it with w->time in the ParaView collection <base>.pvd. frame 0 creates the .pvd;
   a later frame appends its entry, so the .pvd is complete after every call. base may contain
   directories (they must exist); the .pvd names each .vtu relative to itself. frame >= 0. */
SPHDEF sph_status sph_write_vtu_series(const sph_world* w, const char* base, int frame);
/* Fluid and boundary particles as a legacy ASCII VTK unstructured grid (.vtk; 9 digits): the
   same point data as sph_write_vtu without body. Larger and lossy; kept for old readers. */
SPHDEF sph_status sph_write_vtk(const sph_world* w, const char* path);

/* Save and restore: the whole state of a world (def, phases, time, every particle array, the
   statistics, and the second-order scheme's reusable neighbour lists), so that a run that saves,
   restores and continues is bitwise identical to one that did not. The format is binary with a
   versioned header (magic "SPHWORLD", format version, byte order, sizeof(sph_real) and of the
   def, phase and stats structs) and a 64-bit FNV-1a checksum at the end: a file is read back by
   the same version of sph.h built with the same sph_real on a machine of the same byte order;
   anything else, a truncated file or a changed byte gives SPH_ERR_IO with the reason in
   w->error. Every loaded field is then checked with the rules of the API that sets it (def,
   phases, particle positions, velocities, masses, densities, wall volumes, unique ids, a finite
   time): a value the API would refuse gives SPH_ERR_ARG with that rule's message. Callbacks
   are not saved: the loaders take force, force_user, boundary_motion and
   boundary_user from `callbacks` (NULL: none). On failure a loader leaves w as after
   sph_world_free plus the message (safe to free again, nothing leaks). */
SPHDEF sph_status sph_world_save(const sph_world* w, const char* path);
SPHDEF sph_status sph_world_load(sph_world* w, const char* path, const sph_world_def* callbacks);
/* The same in memory: returns the bytes the state needs and writes them to buf when cap is at
   least that (buf may be NULL to ask the size). */
SPHDEF size_t sph_world_save_mem(const sph_world* w, void* buf, size_t cap);
SPHDEF sph_status sph_world_load_mem(sph_world* w, const void* buf, size_t size,
                                     const sph_world_def* callbacks);
/* A deep copy of src into dst (a checkpoint: keep one before a risky step and, on
   SPH_ERR_UNSTABLE, free the world and copy the checkpoint back to retry with a smaller dt).
   dst must not be initialised (it is overwritten, not freed); callbacks are copied. */
SPHDEF sph_status sph_world_copy(sph_world* dst, const sph_world* src);

#ifdef __cplusplus
}
#endif
#endif /* SPH_H */

/* ============================================================================================== */
/* Implementation                                                                                 */
/* ============================================================================================== */
#ifdef SPH_IMPLEMENTATION
#ifndef SPH__IMPLEMENTATION_ONCE
#define SPH__IMPLEMENTATION_ONCE

/* >>config (implementation) */
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h> /* qsort; and malloc when no allocator is given (it was included only then) */
#include <string.h>

#if !defined(SPH_MALLOC) && !defined(SPH_REALLOC) && !defined(SPH_FREE)
#define SPH_MALLOC(size) malloc(size)
#define SPH_REALLOC(ptr, size) realloc(ptr, size)
#define SPH_FREE(ptr) free(ptr)
#elif !defined(SPH_MALLOC) || !defined(SPH_REALLOC) || !defined(SPH_FREE)
#error "sph.h: define all of SPH_MALLOC, SPH_REALLOC and SPH_FREE, or none"
#endif

#ifndef SPH_ASSERT
#include <assert.h>
#define SPH_ASSERT(c) assert(c)
#endif

#if defined(_OPENMP)
#include <omp.h>
#define SPH__PRAGMA(x) _Pragma(#x)
/* Loops over `count` items run in parallel only when there is enough work to pay for a team:
   tiny worlds (a few hundred particles) are faster on one thread. */
#define SPH__OMP_FOR(count) SPH__PRAGMA(omp parallel for schedule(static) if ((count) > 2048))
#define SPH__OMP_FOR_DYNAMIC(count) SPH__PRAGMA(omp parallel for schedule(dynamic, 1) if ((count) > 8))
#else
#define SPH__OMP_FOR(count)
#define SPH__OMP_FOR_DYNAMIC(count)
#endif

#if defined(_WIN32)
#ifndef WIN32_LEAN_AND_MEAN
#define WIN32_LEAN_AND_MEAN
#endif
#include <windows.h>
#elif defined(__unix__) || defined(__APPLE__)
#include <sys/time.h>
#else
#include <time.h>
#endif

#if defined(__GNUC__) || defined(__clang__)
#define SPH__INLINE static inline __attribute__((always_inline))
#elif defined(_MSC_VER)
#define SPH__INLINE static __forceinline
#else
#define SPH__INLINE static inline
#endif
#if defined(__GNUC__) || defined(__clang__)
#define SPH__NOINLINE static __attribute__((noinline))
#elif defined(_MSC_VER)
#define SPH__NOINLINE static __declspec(noinline)
#else
#define SPH__NOINLINE static
#endif

#define SPH__R(x) ((sph_real)(x))
typedef ptrdiff_t sph__idx; /* signed loop index for OpenMP */

#ifdef SPH_FLOAT
SPH__INLINE sph_real sph__sqrt(sph_real x) { return sqrtf(x); }
SPH__INLINE sph_real sph__exp(sph_real x) { return expf(x); }
SPH__INLINE sph_real sph__pow(sph_real x, sph_real y) { return powf(x, y); }
SPH__INLINE sph_real sph__fabs(sph_real x) { return fabsf(x); }
SPH__INLINE sph_real sph__floor(sph_real x) { return floorf(x); }
#else
SPH__INLINE sph_real sph__sqrt(sph_real x) { return sqrt(x); }
SPH__INLINE sph_real sph__exp(sph_real x) { return exp(x); }
SPH__INLINE sph_real sph__pow(sph_real x, sph_real y) { return pow(x, y); }
SPH__INLINE sph_real sph__fabs(sph_real x) { return fabs(x); }
SPH__INLINE sph_real sph__floor(sph_real x) { return floor(x); }
#endif

/* Packed arithmetic for the pair terms of a neighbour row (sph__interact_one's fast path). SSE2
   is part of x86-64, so a plain -O2 build gets it (gcc 12 at -O2 vectorises none of these loops
   itself: its cost model allows no loop of unknown trip count, and it will not pack sqrt without
   -fno-math-errno). IEEE add, mul, div and sqrt round a lane exactly as the scalar instruction,
   so the packed and the scalar path give the same bits. SPH_NO_SIMD, or another architecture,
   selects the scalar path (make check builds it). sph__vlt gives a mask (every bit of a lane set
   where a < b), sph__vand keeps a where the mask is set and gives +0 elsewhere, sph__vandnot
   keeps a where it is not. */
#if !defined(SPH_NO_SIMD) && (defined(__SSE2__) || defined(_M_X64) || \
                              (defined(_M_IX86_FP) && _M_IX86_FP >= 2))
#include <emmintrin.h>
#ifdef SPH_FLOAT
#define SPH__VN 4
typedef __m128 sph__v;
SPH__INLINE sph__v sph__vload(const sph_real* p) { return _mm_loadu_ps(p); }
SPH__INLINE void sph__vstore(sph_real* p, sph__v a) { _mm_storeu_ps(p, a); }
SPH__INLINE sph__v sph__vset(sph_real a) { return _mm_set1_ps(a); }
SPH__INLINE sph__v sph__vadd(sph__v a, sph__v b) { return _mm_add_ps(a, b); }
SPH__INLINE sph__v sph__vsub(sph__v a, sph__v b) { return _mm_sub_ps(a, b); }
SPH__INLINE sph__v sph__vmul(sph__v a, sph__v b) { return _mm_mul_ps(a, b); }
SPH__INLINE sph__v sph__vdiv(sph__v a, sph__v b) { return _mm_div_ps(a, b); }
SPH__INLINE sph__v sph__vsqrt(sph__v a) { return _mm_sqrt_ps(a); }
SPH__INLINE sph__v sph__vlt(sph__v a, sph__v b) { return _mm_cmplt_ps(a, b); }
SPH__INLINE sph__v sph__vand(sph__v m, sph__v a) { return _mm_and_ps(m, a); }
SPH__INLINE sph__v sph__vandnot(sph__v m, sph__v a) { return _mm_andnot_ps(m, a); }
#else
#define SPH__VN 2
typedef __m128d sph__v;
SPH__INLINE sph__v sph__vload(const sph_real* p) { return _mm_loadu_pd(p); }
SPH__INLINE void sph__vstore(sph_real* p, sph__v a) { _mm_storeu_pd(p, a); }
SPH__INLINE sph__v sph__vset(sph_real a) { return _mm_set1_pd(a); }
SPH__INLINE sph__v sph__vadd(sph__v a, sph__v b) { return _mm_add_pd(a, b); }
SPH__INLINE sph__v sph__vsub(sph__v a, sph__v b) { return _mm_sub_pd(a, b); }
SPH__INLINE sph__v sph__vmul(sph__v a, sph__v b) { return _mm_mul_pd(a, b); }
SPH__INLINE sph__v sph__vdiv(sph__v a, sph__v b) { return _mm_div_pd(a, b); }
SPH__INLINE sph__v sph__vsqrt(sph__v a) { return _mm_sqrt_pd(a); }
SPH__INLINE sph__v sph__vlt(sph__v a, sph__v b) { return _mm_cmplt_pd(a, b); }
SPH__INLINE sph__v sph__vand(sph__v m, sph__v a) { return _mm_and_pd(m, a); }
SPH__INLINE sph__v sph__vandnot(sph__v m, sph__v a) { return _mm_andnot_pd(m, a); }
#endif
#else
#define SPH__VN 1
typedef sph_real sph__v;
SPH__INLINE sph__v sph__vload(const sph_real* p) { return *p; }
SPH__INLINE void sph__vstore(sph_real* p, sph__v a) { *p = a; }
SPH__INLINE sph__v sph__vset(sph_real a) { return a; }
SPH__INLINE sph__v sph__vadd(sph__v a, sph__v b) { return a + b; }
SPH__INLINE sph__v sph__vsub(sph__v a, sph__v b) { return a - b; }
SPH__INLINE sph__v sph__vmul(sph__v a, sph__v b) { return a * b; }
SPH__INLINE sph__v sph__vdiv(sph__v a, sph__v b) { return a / b; }
SPH__INLINE sph__v sph__vsqrt(sph__v a) { return sph__sqrt(a); }
SPH__INLINE sph__v sph__vlt(sph__v a, sph__v b) { return a < b ? 1 : 0; }
SPH__INLINE sph__v sph__vand(sph__v m, sph__v a) { return m != 0 ? a : 0; }
SPH__INLINE sph__v sph__vandnot(sph__v m, sph__v a) { return m != 0 ? 0 : a; }
#endif

SPH__INLINE int sph__finite(double x) { return x == x && x - x == 0.0; }
SPH__INLINE sph_real sph__min(sph_real a, sph_real b) { return a < b ? a : b; }
SPH__INLINE sph_real sph__max(sph_real a, sph_real b) { return a > b ? a : b; }
SPH__INLINE size_t sph__maxz(size_t a, size_t b) { return a > b ? a : b; }

static const double sph__pi = 3.14159265358979323846;

static double sph__now(void) {
#if defined(_OPENMP)
    return omp_get_wtime();
#elif defined(_WIN32)
    LARGE_INTEGER f, c;
    QueryPerformanceFrequency(&f);
    QueryPerformanceCounter(&c);
    return (double)c.QuadPart / (double)f.QuadPart;
#elif defined(__unix__) || defined(__APPLE__)
    struct timeval tv;
    gettimeofday(&tv, NULL);
    return (double)tv.tv_sec + 1e-6 * (double)tv.tv_usec;
#else
    return (double)clock() / (double)CLOCKS_PER_SEC;
#endif
}

/* Grows *ptr to hold count elements of elem bytes; keeps *ptr valid on failure. */
static int sph__grow(void** ptr, size_t count, size_t elem) {
    void* q;
    if (count == 0) count = 1;
    if (count > ((size_t)-1) / elem) return 0;
    q = SPH_REALLOC(*ptr, count * elem);
    if (!q) return 0;
    *ptr = q;
    return 1;
}

/* memcpy of a particle array that may still be NULL: a world without fluid particles has no
   arrays, and memcpy(dst, NULL, 0) is undefined behaviour. */
static void sph__copy(void* dst, const void* src, size_t bytes) {
    if (bytes > 0) memcpy(dst, src, bytes);
}

static sph_status sph__fail(sph_world* w, sph_status s, long index, const char* fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(w->error, SPH_ERROR_SIZE, fmt, ap);
    va_end(ap);
    w->status = s;
    w->error_index = index;
    return s;
}

SPHDEF const char* sph_status_string(sph_status status) {
    switch (status) {
    case SPH_OK: return "ok";
    case SPH_ERR_ARG: return "invalid argument";
    case SPH_ERR_NOMEM: return "out of memory";
    case SPH_ERR_CAPACITY: return "capacity exceeded";
    case SPH_ERR_UNSTABLE: return "simulation unstable";
    case SPH_ERR_NOT_CONVERGED: return "solver did not converge";
    case SPH_ERR_IO: return "input/output error";
    case SPH_ERR_BUDGET: return "sub-step budget exceeded";
    default: return "unknown status";
    }
}

/* ============================================================================================== */
/* >>kernels (implementation)                                                                     */
/* ============================================================================================== */
/* W(r) = sigma_d / h^d * w(q), q = r/h. The private helpers return w(q) and f(q) = w'(q)/q, so
   grad_i W_ij = sigma_d / h^(d+2) * f(q) * x_ij without dividing by r (f is finite at q = 0).
   Polynomials and sigma_d: Monaghan 1992 (cubic), Morris 1996 (quintic), Wendland 1995 with the
   support-2h scaling of Dehnen & Aly 2012 (1D uses Wendland's psi_{3,1}, psi_{5,2}, psi_{7,3};
   2D/3D psi_{3,1}... of the d = 3 family). The tests integrate every kernel numerically. */
enum {
    SPH__KF_CUBIC, SPH__KF_QUINTIC, SPH__KF_WC2, SPH__KF_WC2_1D, SPH__KF_WC4, SPH__KF_WC4_1D,
    SPH__KF_WC6, SPH__KF_WC6_1D, SPH__KF_GAUSS
};
#define SPH__GAUSS_CUT 1.2340980408667956e-4 /* exp(-9): the Gaussian is shifted to vanish at 3h */

SPH__INLINE sph_real sph__kw(int form, sph_real q) {
    sph_real t, t2;
    switch (form) {
    case SPH__KF_CUBIC:
        if (q < 1) return 1 - SPH__R(1.5) * q * q + SPH__R(0.75) * q * q * q;
        if (q < 2) { t = 2 - q; return SPH__R(0.25) * t * t * t; }
        return 0;
    case SPH__KF_QUINTIC:
        if (q < 1) { t = q * q; return 66 - 60 * t + 30 * t * t - 10 * t * t * q; }
        if (q < 2) { t = 3 - q; t2 = 2 - q;
            return t * t * t * t * t - 6 * t2 * t2 * t2 * t2 * t2; }
        if (q < 3) { t = 3 - q; return t * t * t * t * t; }
        return 0;
    case SPH__KF_WC2:
        if (q < 2) { t = 1 - SPH__R(0.5) * q; t2 = t * t; return t2 * t2 * (2 * q + 1); }
        return 0;
    case SPH__KF_WC2_1D:
        if (q < 2) { t = 1 - SPH__R(0.5) * q; return t * t * t * (SPH__R(1.5) * q + 1); }
        return 0;
    case SPH__KF_WC4:
        if (q < 2) { t = 1 - SPH__R(0.5) * q; t2 = t * t * t;
            return t2 * t2 * (SPH__R(35.0 / 12.0) * q * q + 3 * q + 1); }
        return 0;
    case SPH__KF_WC4_1D:
        if (q < 2) { t = 1 - SPH__R(0.5) * q; t2 = t * t;
            return t2 * t2 * t * (2 * q * q + SPH__R(2.5) * q + 1); }
        return 0;
    case SPH__KF_WC6:
        if (q < 2) { t = 1 - SPH__R(0.5) * q; t2 = t * t; t2 = t2 * t2;
            return t2 * t2 * (((4 * q + SPH__R(6.25)) * q + 4) * q + 1); }
        return 0;
    case SPH__KF_WC6_1D:
        if (q < 2) { t = 1 - SPH__R(0.5) * q; t2 = t * t; t2 = t2 * t2 * t2 * t;
            return t2 * (((SPH__R(21.0 / 8.0) * q + SPH__R(4.75)) * q + SPH__R(3.5)) * q + 1); }
        return 0;
    case SPH__KF_GAUSS:
        if (q < 3) return sph__exp(-q * q) - SPH__R(SPH__GAUSS_CUT);
        return 0;
    default: return 0;
    }
}

SPH__INLINE sph_real sph__kf(int form, sph_real q) {
    sph_real t, t2;
    switch (form) {
    case SPH__KF_CUBIC:
        if (q < 1) return -3 + SPH__R(2.25) * q;
        if (q < 2) { t = 2 - q; return SPH__R(-0.75) * t * t / q; }
        return 0;
    case SPH__KF_QUINTIC:
        if (q < 1) return -120 + 120 * q * q - 50 * q * q * q;
        if (q < 2) { t = 3 - q; t2 = 2 - q;
            return (-5 * t * t * t * t + 30 * t2 * t2 * t2 * t2) / q; }
        if (q < 3) { t = 3 - q; return -5 * t * t * t * t / q; }
        return 0;
    case SPH__KF_WC2:
        if (q < 2) { t = 1 - SPH__R(0.5) * q; return -5 * t * t * t; }
        return 0;
    case SPH__KF_WC2_1D:
        if (q < 2) { t = 1 - SPH__R(0.5) * q; return -3 * t * t; }
        return 0;
    case SPH__KF_WC4:
        if (q < 2) { t = 1 - SPH__R(0.5) * q; t2 = t * t;
            return SPH__R(-14.0 / 3.0) * (1 + SPH__R(2.5) * q) * t2 * t2 * t; }
        return 0;
    case SPH__KF_WC4_1D:
        if (q < 2) { t = 1 - SPH__R(0.5) * q; t2 = t * t;
            return SPH__R(-3.5) * (1 + 2 * q) * t2 * t2; }
        return 0;
    case SPH__KF_WC6:
        if (q < 2) { t = 1 - SPH__R(0.5) * q; t2 = t * t; t2 = t2 * t2 * t2 * t;
            return SPH__R(-5.5) * t2 * ((4 * q + SPH__R(3.5)) * q + 1); }
        return 0;
    case SPH__KF_WC6_1D:
        if (q < 2) { t = 1 - SPH__R(0.5) * q; t2 = t * t; t2 = t2 * t2 * t2;
            return -t2 * ((SPH__R(13.125) * q + SPH__R(13.5)) * q + SPH__R(4.5)); }
        return 0;
    case SPH__KF_GAUSS:
        if (q < 3) return -2 * sph__exp(-q * q);
        return 0;
    default: return 0;
    }
}

SPHDEF sph_real sph_kernel_support(sph_kernel_type type) {
    return (type == SPH_KERNEL_QUINTIC || type == SPH_KERNEL_GAUSSIAN) ? SPH__R(3) : SPH__R(2);
}

SPHDEF sph_real sph_kernel_default_h_factor(sph_kernel_type type) {
    switch (type) {
    case SPH_KERNEL_QUINTIC: return SPH__R(1.2); /* Negi & Ramachandran 2022: h = 1.2 dx   */
    case SPH_KERNEL_GAUSSIAN: return SPH__R(1.0);
    case SPH_KERNEL_WENDLAND_C4: return SPH__R(1.5);
    case SPH_KERNEL_WENDLAND_C6: return SPH__R(1.6);
    default: return SPH__R(1.3); /* cubic, Wendland C2: 21 neighbours in 2D (self included) */
    }
}

SPHDEF const char* sph_kernel_name(sph_kernel_type type) {
    switch (type) {
    case SPH_KERNEL_WENDLAND_C2: return "wendland_c2";
    case SPH_KERNEL_CUBIC: return "cubic";
    case SPH_KERNEL_QUINTIC: return "quintic";
    case SPH_KERNEL_WENDLAND_C4: return "wendland_c4";
    case SPH_KERNEL_WENDLAND_C6: return "wendland_c6";
    case SPH_KERNEL_GAUSSIAN: return "gaussian";
    default: return "unknown";
    }
}

SPHDEF sph_status sph_kernel_init(sph_kernel* k, sph_kernel_type type, int dim, sph_real h) {
    double sigma = 0, hd, e9 = SPH__GAUSS_CUT, pi = sph__pi;
    int form = SPH__KF_CUBIC;
    if (!k || dim < 1 || dim > 3 || !(h > 0) || !sph__finite((double)h) ||
        (int)type < 0 || type >= SPH_KERNEL_COUNT)
        return SPH_ERR_ARG;
    switch (type) {
    case SPH_KERNEL_CUBIC:
        form = SPH__KF_CUBIC;
        sigma = dim == 1 ? 2.0 / 3.0 : dim == 2 ? 10.0 / (7.0 * pi) : 1.0 / pi;
        break;
    case SPH_KERNEL_QUINTIC:
        form = SPH__KF_QUINTIC;
        sigma = dim == 1 ? 1.0 / 120.0 : dim == 2 ? 7.0 / (478.0 * pi) : 1.0 / (120.0 * pi);
        break;
    case SPH_KERNEL_WENDLAND_C2:
        form = dim == 1 ? SPH__KF_WC2_1D : SPH__KF_WC2;
        sigma = dim == 1 ? 5.0 / 8.0 : dim == 2 ? 7.0 / (4.0 * pi) : 21.0 / (16.0 * pi);
        break;
    case SPH_KERNEL_WENDLAND_C4:
        form = dim == 1 ? SPH__KF_WC4_1D : SPH__KF_WC4;
        sigma = dim == 1 ? 3.0 / 4.0 : dim == 2 ? 9.0 / (4.0 * pi) : 495.0 / (256.0 * pi);
        break;
    case SPH_KERNEL_WENDLAND_C6:
        form = dim == 1 ? SPH__KF_WC6_1D : SPH__KF_WC6;
        sigma = dim == 1 ? 55.0 / 64.0 : dim == 2 ? 39.0 / (14.0 * pi) : 1365.0 / (512.0 * pi);
        break;
    case SPH_KERNEL_GAUSSIAN:
        /* integral of exp(-q^2) - exp(-9) over the ball q < 3 */
        form = SPH__KF_GAUSS;
        if (dim == 1) sigma = 1.0 / (sqrt(pi) * erf(3.0) - 6.0 * e9);
        else if (dim == 2) sigma = 1.0 / (pi * (1.0 - e9) - 9.0 * pi * e9);
        else sigma = 1.0 / (pow(pi, 1.5) * erf(3.0) - 42.0 * pi * e9);
        break;
    default: return SPH_ERR_ARG;
    }
    hd = dim == 1 ? (double)h : dim == 2 ? (double)h * (double)h : (double)h * (double)h * (double)h;
    /* an h so small (or large) that 1/h or a normalisation leaves sph_real (float: h below
       ~1e-8 m in 3D) would give infinite or zero kernel values */
    if (!sph__finite((double)(1 / h)) || !sph__finite((double)(sph_real)(sigma / hd)) ||
        !sph__finite((double)(sph_real)(sigma / (hd * (double)h * (double)h))) ||
        !((sph_real)(sigma / hd) > 0) || !((sph_real)(sigma / (hd * (double)h * (double)h)) > 0))
        return SPH_ERR_ARG;
    k->type = type;
    k->dim = dim;
    k->h = h;
    k->radius = sph_kernel_support(type) * h;
    k->form = form;
    k->inv_h = 1 / h;
    k->norm_w = (sph_real)(sigma / hd);
    k->norm_g = (sph_real)(sigma / (hd * (double)h * (double)h));
    return SPH_OK;
}

/* r * inv_h can round to just below the support factor at r = radius: the explicit cut makes
   W and its derivatives exactly zero from the radius on. */
SPHDEF sph_real sph_kernel_w(const sph_kernel* k, sph_real r) {
    r = sph__fabs(r);
    if (r >= k->radius) return 0;
    return k->norm_w * sph__kw(k->form, r * k->inv_h);
}

SPHDEF sph_real sph_kernel_dwdr(const sph_kernel* k, sph_real r) {
    r = sph__fabs(r);
    if (r >= k->radius) return 0;
    /* dW/dr = norm_g * f(q) * r  (since f = w'/q and norm_g = norm_w / h^2) */
    return k->norm_g * sph__kf(k->form, r * k->inv_h) * r;
}

SPHDEF void sph_kernel_grad(const sph_kernel* k, const sph_real* xij, sph_real* grad) {
    sph_real r2 = 0, s = 0;
    int d;
    for (d = 0; d < k->dim; ++d) r2 += xij[d] * xij[d];
    if (r2 < k->radius * k->radius) s = k->norm_g * sph__kf(k->form, sph__sqrt(r2) * k->inv_h);
    for (d = 0; d < k->dim; ++d) grad[d] = s * xij[d];
}

/* ============================================================================================== */
/* >>grid (implementation)                                                                        */
/* ============================================================================================== */
/* Cell coordinates are clamped to [-2^20, 2^20): clamping is monotone and moves two points at
   most as far apart as before, so two points within one cell of each other stay within one cell
   and no neighbour is missed; points beyond the clamp only share crowded cells. */
#define SPH__CELL_LIM 1048576
#define SPH__CHUNK 256 /* query points per neighbour-list chunk */

/* Offset of xk into the periodic box of direction k, in [0, len) up to rounding [m]. A point in
   the box takes the plain difference (the arithmetic the world's wrapped positions always had);
   one outside is wrapped first with fmod, which is exact, so that a point 2e12 boxes away lands
   in the cell (and at the distance) its image in the box has: scaling by the cell factor
   first, as before, put the rounding of 1e13 cells into the cell index. */
SPH__INLINE double sph__periodic_offset(const sph_grid* g, int k, sph_real xk) {
    double u;
    /* within a box length of the box: the old arithmetic (the cell index is wrapped later), so
       rounding at the support radius is the brute force's */
    if (xk >= g->lo[k] - g->len[k] && xk < g->lo[k] + 2 * g->len[k]) return (double)(xk - g->lo[k]);
    u = fmod((double)xk - (double)g->lo[k], (double)g->len[k]);
    return u < 0 ? u + (double)g->len[k] : u;
}

/* xk moved into the periodic box of direction k (itself when it lies in the box). */
SPH__INLINE sph_real sph__periodic_wrap(const sph_grid* g, int k, sph_real xk) {
    if (xk >= g->lo[k] - g->len[k] && xk < g->lo[k] + 2 * g->len[k]) return xk; /* as above */
    return (sph_real)((double)g->lo[k] + sph__periodic_offset(g, k, xk));
}

SPH__INLINE int32_t sph__cell_coord(const sph_grid* g, int k, sph_real xk) {
    double t;
    if (g->periodic[k]) {
        long long c;
        t = floor(sph__periodic_offset(g, k, xk) * g->inv[k]);
        if (!(t > -1e15)) t = 0; /* NaN or absurd: any cell; the distance test decides */
        if (t > 1e15) t = 0;
        c = (long long)t % (long long)g->ncell[k];
        if (c < 0) c += g->ncell[k];
        return (int32_t)c;
    }
    t = floor((double)xk * g->inv[k]);
    if (!(t >= -SPH__CELL_LIM)) t = -SPH__CELL_LIM; /* also catches NaN */
    if (t > SPH__CELL_LIM - 1) t = SPH__CELL_LIM - 1;
    return (int32_t)t;
}

SPH__INLINE uint64_t sph__cell_key(const int32_t* c, int dim) {
    uint64_t key = 0;
    int k;
    for (k = dim - 1; k >= 0; --k) key = (key << 21) | (uint64_t)(uint32_t)(c[k] + SPH__CELL_LIM);
    return key;
}

SPH__INLINE uint64_t sph__mix64(uint64_t x) {
    x ^= x >> 33;
    x *= 0xff51afd7ed558ccdULL;
    x ^= x >> 33;
    x *= 0xc4ceb9fe1a85ec53ULL;
    x ^= x >> 33;
    return x;
}

/* Bucket of cell c, or (size_t)-1 if the cell lies outside the dense table. */
SPH__INLINE size_t sph__cell_bucket(const sph_grid* g, const int32_t* c, uint64_t key) {
    if (g->hashed) return (size_t)(sph__mix64(key) & (uint64_t)(g->nbucket - 1));
    {
        int64_t lin = 0;
        int k;
        for (k = g->dim - 1; k >= 0; --k) {
            int64_t o = (int64_t)c[k] - g->cmin[k];
            if (o < 0 || o >= g->ext[k]) return (size_t)-1;
            lin = lin * g->ext[k] + o;
        }
        return (size_t)lin;
    }
}

SPH__INLINE sph_real sph__wrap_delta(sph_real d, sph_real len) {
    return d - len * sph__floor(d / len + SPH__R(0.5));
}

SPHDEF void sph_grid_delta(const sph_grid* g, const sph_real* a, const sph_real* b, sph_real* d) {
    int k;
    for (k = 0; k < g->dim; ++k) {
        if (g->periodic[k])
            d[k] = sph__wrap_delta(sph__periodic_wrap(g, k, a[k]) - sph__periodic_wrap(g, k, b[k]),
                                   g->len[k]);
        else
            d[k] = a[k] - b[k];
    }
}

SPHDEF sph_status sph_grid_init(sph_grid* g, int dim, sph_real cell_size, const int* periodic,
                                const sph_real* lo, const sph_real* hi) {
    int k;
    if (!g) return SPH_ERR_ARG;
    memset(g, 0, sizeof(*g));
    if (dim < 1 || dim > 3 || !(cell_size > 0) || !sph__finite((double)cell_size))
        return SPH_ERR_ARG;
    g->dim = dim;
    g->cell = cell_size;
    /* Cells are 2^-30 wider than asked: below the 2^20-cell clamp the rounding of x * inv is
       under 2^-32 cells, so two points closer than the cell size can never land two cells
       apart (with cells of exactly the radius, 1/cell rounding up could split such a pair). */
    for (k = 0; k < 3; ++k) {
        g->inv[k] = (1.0 - 1.0 / 1073741824.0) / (double)cell_size;
        if (k < dim && periodic && periodic[k]) {
            sph_real len;
            if (!lo || !hi || !sph__finite((double)lo[k]) || !sph__finite((double)hi[k]))
                return SPH_ERR_ARG;
            len = hi[k] - lo[k];
            if (!(len >= 2 * cell_size) || !sph__finite((double)len)) return SPH_ERR_ARG;
            g->periodic[k] = 1;
            g->lo[k] = lo[k];
            g->len[k] = len;
            /* clamp before the conversion: a long box has more cells than int32_t holds */
            g->ncell[k] =
                (int32_t)fmin(floor((double)len / (double)cell_size), (double)SPH__CELL_LIM);
            g->inv[k] = (1.0 - 1.0 / 1073741824.0) * (double)g->ncell[k] / (double)len;
        }
    }
    return SPH_OK;
}

SPHDEF void sph_grid_free(sph_grid* g) {
    if (!g) return;
    SPH_FREE(g->order);
    SPH_FREE(g->start);
    SPH_FREE(g->key);
    SPH_FREE(g->bucket);
    g->order = g->start = g->bucket = NULL;
    g->key = NULL;
    g->cap_n = g->cap_bucket = g->n = g->nbucket = 0;
}

SPHDEF sph_status sph_grid_build(sph_grid* g, const sph_real* x, size_t n) {
    const int dim = g->dim;
    int64_t cmin[3] = {0, 0, 0}, cmax[3] = {0, 0, 0};
    uint64_t cells = 1;
    size_t b, nbucket;
    sph__idx i;
    int k, hashed = 0;
    if (n > (size_t)UINT32_MAX - 1) return SPH_ERR_CAPACITY;
    if (n > g->cap_n) {
        size_t cap = n + n / 4 + 16;
        if (!sph__grow((void**)&g->order, cap, sizeof(uint32_t)) ||
            !sph__grow((void**)&g->key, cap, sizeof(uint64_t)) ||
            !sph__grow((void**)&g->bucket, cap, sizeof(uint32_t)))
            return SPH_ERR_NOMEM;
        g->cap_n = cap;
    }
    /* bounding box of the cells: min and max do not depend on the order they are taken in, so
       the parallel pass (OpenMP 3.1 min/max reductions) gives the serial result; it was the
       largest serial part of the grid build, which is 3 % of a 2D WCSPH step at 100k */
    for (k = 0; k < dim; ++k) { cmin[k] = SPH__CELL_LIM; cmax[k] = -SPH__CELL_LIM; }
    {
        int64_t lo0 = SPH__CELL_LIM, lo1 = SPH__CELL_LIM, lo2 = SPH__CELL_LIM;
        int64_t hi0 = -SPH__CELL_LIM, hi1 = -SPH__CELL_LIM, hi2 = -SPH__CELL_LIM;
#if defined(_OPENMP) && _OPENMP >= 201107
#pragma omp parallel for schedule(static) if (n > 2048) reduction(min : lo0, lo1, lo2) \
    reduction(max : hi0, hi1, hi2)
#endif
        for (i = 0; i < (sph__idx)n; ++i) {
            const sph_real* xi = x + (size_t)i * (size_t)dim;
            const int64_t c0 = sph__cell_coord(g, 0, xi[0]);
            const int64_t c1 = dim > 1 ? sph__cell_coord(g, 1, xi[1]) : 0;
            const int64_t c2 = dim > 2 ? sph__cell_coord(g, 2, xi[2]) : 0;
            if (c0 < lo0) lo0 = c0;
            if (c0 > hi0) hi0 = c0;
            if (c1 < lo1) lo1 = c1;
            if (c1 > hi1) hi1 = c1;
            if (c2 < lo2) lo2 = c2;
            if (c2 > hi2) hi2 = c2;
        }
        cmin[0] = lo0; cmax[0] = hi0;
        if (dim > 1) { cmin[1] = lo1; cmax[1] = hi1; }
        if (dim > 2) { cmin[2] = lo2; cmax[2] = hi2; }
    }
    if (n == 0) for (k = 0; k < dim; ++k) cmin[k] = cmax[k] = 0;
    for (k = 0; k < dim; ++k)
        if (cells <= ((uint64_t)1 << 40)) cells *= (uint64_t)(cmax[k] - cmin[k] + 1);
    /* dense while the table is small against the points or in absolute terms (256k cells, 1 MiB):
       a tank's walls are few points around many empty cells, and a hashed wall grid made every
       fluid particle's wall query 3^d hash probes (2D WCSPH at 100k: neighbour stage 14.5 ->
       9.3 ms with the dense table) */
    if (cells <= (uint64_t)(4 * n + 1024) || cells <= ((uint64_t)1 << 18)) {
        nbucket = (size_t)cells;
    } else {
        hashed = 1;
        nbucket = 1024;
        while (nbucket < 2 * n) nbucket *= 2;
    }
    if (nbucket + 1 > g->cap_bucket) {
        size_t cap = nbucket + nbucket / 4 + 16;
        if (!sph__grow((void**)&g->start, cap, sizeof(uint32_t))) return SPH_ERR_NOMEM;
        g->cap_bucket = cap;
    }
    /* the new box only now: out of memory above leaves the last build whole (it used to get
       this build's cmin/ext with the last build's buckets) */
    for (k = 0; k < dim; ++k) {
        g->cmin[k] = cmin[k];
        g->ext[k] = cmax[k] - cmin[k] + 1;
    }
    g->hashed = hashed;
    g->nbucket = nbucket;
    g->n = n;
    SPH__OMP_FOR(n)
    for (i = 0; i < (sph__idx)n; ++i) {
        int32_t c[3] = {0, 0, 0};
        int kk;
        uint64_t key;
        for (kk = 0; kk < dim; ++kk)
            c[kk] = sph__cell_coord(g, kk, x[(size_t)i * (size_t)dim + (size_t)kk]);
        key = sph__cell_key(c, dim);
        g->bucket[i] = (uint32_t)sph__cell_bucket(g, c, key);
    }
    /* counting sort by bucket, stable in the point index */
    memset(g->start, 0, (nbucket + 1) * sizeof(uint32_t));
    for (i = 0; i < (sph__idx)n; ++i) g->start[g->bucket[i] + 1]++;
    for (b = 0; b < nbucket; ++b) g->start[b + 1] += g->start[b];
    for (i = 0; i < (sph__idx)n; ++i) g->order[g->start[g->bucket[i]]++] = (uint32_t)i;
    for (b = nbucket; b > 0; --b) g->start[b] = g->start[b - 1];
    g->start[0] = 0;
    /* hash mode: cells of the sorted points, to tell apart cells that share a bucket */
    if (hashed) {
        SPH__OMP_FOR(n)
        for (i = 0; i < (sph__idx)n; ++i) {
            int32_t c[3] = {0, 0, 0};
            int kk;
            const sph_real* xi = x + (size_t)g->order[i] * (size_t)dim;
            for (kk = 0; kk < dim; ++kk) c[kk] = sph__cell_coord(g, kk, xi[kk]);
            g->key[i] = sph__cell_key(c, dim);
        }
    }
    return SPH_OK;
}

/* Calls EMIT(j, d, r2) for every point j of grid g within radius of p (d = p - x_j, r2 = |d|^2).
   order == NULL: the grid's points are already stored in cell order. Offsets along a periodic
   direction with two cells are visited once each. */
#define SPH__GRID_VISIT(g, x, order, p, radius, EMIT)                                              \
    do {                                                                                           \
        const int dim_ = (g)->dim;                                                                 \
        const sph_real r2max_ = (radius) * (radius);                                               \
        int32_t c0_[3] = {0, 0, 0}, lo_[3] = {0, 0, 0}, hi_[3] = {0, 0, 0};                        \
        int32_t cc_[3] = {0, 0, 0};                                                                \
        sph_real pw_[3] = {0, 0, 0}; /* p, wrapped into the periodic box */                        \
        int k_;                                                                                    \
        for (k_ = 0; k_ < dim_; ++k_) {                                                            \
            c0_[k_] = sph__cell_coord((g), k_, (p)[k_]);                                           \
            pw_[k_] = (g)->periodic[k_] ? sph__periodic_wrap((g), k_, (p)[k_]) : (p)[k_];          \
            if ((g)->periodic[k_] && (g)->ncell[k_] == 2) { lo_[k_] = 0; hi_[k_] = 1; }            \
            else { lo_[k_] = -1; hi_[k_] = 1; }                                                    \
        }                                                                                          \
        for (cc_[2] = lo_[2]; cc_[2] <= hi_[2]; ++cc_[2])                                          \
        for (cc_[1] = lo_[1]; cc_[1] <= hi_[1]; ++cc_[1])                                          \
        for (cc_[0] = lo_[0]; cc_[0] <= hi_[0]; ++cc_[0]) {                                        \
            int32_t c_[3] = {0, 0, 0};                                                             \
            int ok_ = 1;                                                                           \
            uint64_t key_;                                                                         \
            size_t bk_, s_, e_, q_;                                                                \
            for (k_ = 0; k_ < dim_; ++k_) {                                                        \
                int32_t v_ = c0_[k_] + cc_[k_];                                                    \
                if ((g)->periodic[k_]) {                                                           \
                    if (v_ < 0) v_ += (g)->ncell[k_];                                              \
                    if (v_ >= (g)->ncell[k_]) v_ -= (g)->ncell[k_];                                \
                } else if (v_ < -SPH__CELL_LIM || v_ >= SPH__CELL_LIM) ok_ = 0;                    \
                c_[k_] = v_;                                                                       \
            }                                                                                      \
            if (!ok_) continue;                                                                    \
            key_ = sph__cell_key(c_, dim_);                                                        \
            bk_ = sph__cell_bucket((g), c_, key_);                                                 \
            if (bk_ == (size_t)-1) continue;                                                       \
            s_ = (g)->start[bk_];                                                                  \
            e_ = (g)->start[bk_ + 1];                                                              \
            for (q_ = s_; q_ < e_; ++q_) {                                                         \
                uint32_t j_ = (order) ? (order)[q_] : (uint32_t)q_;                               \
                const sph_real* xj_ = (x) + (size_t)j_ * (size_t)dim_;                             \
                sph_real d_[3] = {0, 0, 0}, r2_ = 0;                                               \
                if ((g)->hashed && (g)->key[q_] != key_) continue;                                 \
                for (k_ = 0; k_ < dim_; ++k_) {                                                    \
                    if ((g)->periodic[k_])                                                         \
                        d_[k_] = sph__wrap_delta(pw_[k_] - sph__periodic_wrap((g), k_, xj_[k_]),   \
                                                 (g)->len[k_]);                                    \
                    else                                                                           \
                        d_[k_] = (p)[k_] - xj_[k_];                                                \
                    r2_ += d_[k_] * d_[k_];                                                        \
                }                                                                                  \
                if (r2_ < r2max_) { EMIT(j_, d_, r2_); }                                           \
            }                                                                                      \
        }                                                                                          \
    } while (0)

SPHDEF size_t sph_grid_query(const sph_grid* g, const sph_real* x, const sph_real* p,
                             sph_real radius, uint32_t* out, size_t cap) {
    size_t found = 0;
#define SPH__EMIT_OUT(j, d, r2)                                                                    \
    do { (void)(d); (void)(r2); if (found < cap) out[found] = (j); ++found; } while (0)
    if (!g || !x || !p || g->n == 0) return 0;
    SPH__GRID_VISIT(g, x, g->order, p, radius, SPH__EMIT_OUT);
#undef SPH__EMIT_OUT
    return found;
}

/* Fills the lists of query points in chunk c; returns the number of entries it needed. */
static size_t sph__neighbors_chunk(sph_neighbors* nl, const sph_grid* g, const sph_real* x,
                                   const uint32_t* order, const sph_real* xq, size_t nq,
                                   sph_real radius, int exclude_self, size_t c) {
    size_t i, i0 = c * SPH__CHUNK, i1 = i0 + SPH__CHUNK;
    size_t pos = nl->chunk_off[c], end = pos + nl->chunk_cap[c];
    const int dim = g->dim;
    if (i1 > nq) i1 = nq;
    for (i = i0; i < i1; ++i) {
        const sph_real* p = xq + i * (size_t)dim;
        size_t b0 = pos;
#define SPH__EMIT_LIST(j, d, r2)                                                                   \
    do {                                                                                           \
        (void)(d); (void)(r2);                                                                     \
        if (!(exclude_self && (size_t)(j) == i)) {                                                 \
            if (pos < end) nl->idx[pos] = (j);                                                     \
            ++pos;                                                                                 \
        }                                                                                          \
    } while (0)
        SPH__GRID_VISIT(g, x, order, p, radius, SPH__EMIT_LIST);
#undef SPH__EMIT_LIST
        nl->begin[i] = b0;
        nl->count[i] = (uint32_t)(pos - b0);
    }
    return pos - nl->chunk_off[c];
}

#if SPH__VN > 1
/* The distance test of sph__neighbors_chunk_dense for candidates q .. qend - 1 of a row, several
   at a time (SSE2; 2D and 3D in both precisions): each candidate is written at *m, and *m
   advances for those within the radius. r2 = (dx^2 + dy^2) + dz^2 as in the scalar loop, so the
   lists are the same. Returns the first candidate left to the scalar loop. */
SPH__INLINE size_t sph__row_within(const sph_real* x, const sph_real* p, size_t q, size_t qend,
                                   sph_real r2max, uint32_t* out, size_t* m, const int D) {
    size_t mm = *m;
    int bits;
#ifdef SPH_FLOAT
    if (D == 2) {
        const __m128 vp = _mm_setr_ps(p[0], p[1], p[0], p[1]), vr = _mm_set1_ps(r2max);
        for (; q + 4 <= qend; q += 4) {
            __m128 a = _mm_sub_ps(vp, _mm_loadu_ps(x + 2 * q));
            __m128 b = _mm_sub_ps(vp, _mm_loadu_ps(x + 2 * q + 4));
            a = _mm_mul_ps(a, a); /* dx0^2 dy0^2 dx1^2 dy1^2 */
            b = _mm_mul_ps(b, b);
            bits = _mm_movemask_ps(_mm_cmplt_ps(
                _mm_add_ps(_mm_shuffle_ps(a, b, _MM_SHUFFLE(2, 0, 2, 0)),
                           _mm_shuffle_ps(a, b, _MM_SHUFFLE(3, 1, 3, 1))), vr));
            out[mm] = (uint32_t)q; mm += (size_t)(bits & 1);
            out[mm] = (uint32_t)(q + 1); mm += (size_t)((bits >> 1) & 1);
            out[mm] = (uint32_t)(q + 2); mm += (size_t)((bits >> 2) & 1);
            out[mm] = (uint32_t)(q + 3); mm += (size_t)((bits >> 3) & 1);
        }
    } else if (D == 3) { /* four candidates per test, their coordinates gathered by lane */
        const __m128 vx = _mm_set1_ps(p[0]), vy = _mm_set1_ps(p[1]), vz = _mm_set1_ps(p[2]);
        const __m128 vr = _mm_set1_ps(r2max);
        for (; q + 4 <= qend; q += 4) {
            const sph_real* xj = x + 3 * q;
            const __m128 a = _mm_sub_ps(vx, _mm_setr_ps(xj[0], xj[3], xj[6], xj[9]));
            const __m128 b = _mm_sub_ps(vy, _mm_setr_ps(xj[1], xj[4], xj[7], xj[10]));
            const __m128 z = _mm_sub_ps(vz, _mm_setr_ps(xj[2], xj[5], xj[8], xj[11]));
            bits = _mm_movemask_ps(_mm_cmplt_ps(
                _mm_add_ps(_mm_add_ps(_mm_mul_ps(a, a), _mm_mul_ps(b, b)), _mm_mul_ps(z, z)), vr));
            out[mm] = (uint32_t)q; mm += (size_t)(bits & 1);
            out[mm] = (uint32_t)(q + 1); mm += (size_t)((bits >> 1) & 1);
            out[mm] = (uint32_t)(q + 2); mm += (size_t)((bits >> 2) & 1);
            out[mm] = (uint32_t)(q + 3); mm += (size_t)((bits >> 3) & 1);
        }
    }
#else
    if (D == 2 || D == 3) {
        const __m128d vp = _mm_setr_pd(p[0], p[1]), vz = _mm_set1_pd(D == 3 ? p[2] : 0);
        const __m128d vr = _mm_set1_pd(r2max);
        for (; q + 2 <= qend; q += 2) {
            const sph_real* xj = x + q * (size_t)D;
            __m128d a = _mm_sub_pd(vp, _mm_loadu_pd(xj)), b = _mm_sub_pd(vp, _mm_loadu_pd(xj + D));
            __m128d r2;
            a = _mm_mul_pd(a, a);
            b = _mm_mul_pd(b, b);
            r2 = _mm_add_pd(_mm_unpacklo_pd(a, b), _mm_unpackhi_pd(a, b));
            if (D == 3) {
                const __m128d z = _mm_sub_pd(vz, _mm_setr_pd(xj[2], xj[5]));
                r2 = _mm_add_pd(r2, _mm_mul_pd(z, z));
            }
            bits = _mm_movemask_pd(_mm_cmplt_pd(r2, vr));
            out[mm] = (uint32_t)q; mm += (size_t)(bits & 1);
            out[mm] = (uint32_t)(q + 1); mm += (size_t)((bits >> 1) & 1);
        }
    }
#endif
    (void)bits;
    *m = mm;
    return q;
}
#endif

/* The common case, specialised per dimension: a dense table, no periodic direction, points
   stored in cell order. The three cells along x of a row of the stencil are consecutive buckets,
   so each row is one contiguous range of points (3 ranges in 2D, 9 in 3D instead of 9 and 27
   cells). */
SPH__INLINE size_t sph__neighbors_chunk_dense(sph_neighbors* nl, const sph_grid* g,
                                              const sph_real* x, const sph_real* xq, size_t nq,
                                              sph_real radius, int exclude_self, size_t c,
                                              const uint8_t* near, int half, const int D) {
    const sph_real r2max = radius * radius;
    const int64_t ex0 = g->ext[0], ex1 = D > 1 ? g->ext[1] : 1, ex2 = D > 2 ? g->ext[2] : 1;
    size_t i, i0 = c * SPH__CHUNK, i1 = i0 + SPH__CHUNK;
    size_t pos = nl->chunk_off[c], end = pos + nl->chunk_cap[c];
    /* cell edges: a product instead of a division per face (within an ulp of it, far inside the
       pruning margin below, so the lists stay the same) */
    const double cw[3] = {1 / g->inv[0], 1 / g->inv[1], 1 / g->inv[2]};
    /* The grid's box widened by two cells [m]: a point outside it lies two cells or more beyond
       the box (see `outside` below) and is done after D comparisons (most wall particles of a
       tank, queried against the fluid's grid every step; 3D IISPH at 6.9k fluid and 60k wall
       particles: the wall lists 5.9 -> 4.5 ms per step). Only while the widened box stays clear
       of the clamp of the cell coordinates, where a point outside may share a clamped cell. */
    double blo[3] = {0, 0, 0}, bhi[3] = {0, 0, 0};
    int k, pre = 1;
    for (k = 0; k < D; ++k) {
        blo[k] = (double)(g->cmin[k] - 2) * cw[k];
        bhi[k] = (double)(g->cmin[k] + g->ext[k] + 2) * cw[k];
        if (g->cmin[k] - 2 <= -SPH__CELL_LIM || g->cmin[k] + g->ext[k] + 2 >= SPH__CELL_LIM)
            pre = 0;
    }
    if (i1 > nq) i1 = nq;
    for (i = i0; i < i1; ++i) {
        const sph_real* p = xq + i * (size_t)D;
        int64_t cc[3] = {0, 0, 0}, xa, xb, dy, dz;
        double lo2[3] = {0, 0, 0}, hi2[3] = {0, 0, 0}; /* squared distance to the cell's faces */
        const size_t b0 = pos;
        int outside = 0;
        if (pre) {
            for (k = 0; k < D; ++k) outside |= !((double)p[k] >= blo[k] && (double)p[k] < bhi[k]);
            if (outside) {
                nl->begin[i] = b0;
                nl->count[i] = 0;
                continue;
            }
        }
        for (k = 0; k < D; ++k) {
            const int32_t ca = sph__cell_coord(g, k, p[k]);
            const double f0 = (double)ca * cw[k], f1 = (double)(ca + 1) * cw[k];
            cc[k] = (int64_t)ca - g->cmin[k];
            lo2[k] = ((double)p[k] - f0) * ((double)p[k] - f0);
            hi2[k] = (f1 - (double)p[k]) * (f1 - (double)p[k]);
            /* two cells or more beyond the grid's box: no row of the stencil lies in it (most
               wall particles of a tank, queried against the fluid's grid every step) */
            outside |= cc[k] < -1 || cc[k] > g->ext[k];
        }
        /* a cell of the box with no point in the 3^D cells around it (sph__grid_near): the
           fluid inside a tank, queried against the walls' grid every step */
        if (near && cc[0] >= 0 && cc[0] < ex0 && cc[1] >= 0 && cc[1] < ex1 && cc[2] >= 0 &&
            cc[2] < ex2 && !near[(cc[2] * ex1 + cc[1]) * ex0 + cc[0]])
            outside = 1;
        if (!outside) {
            /* Cells of the stencil that lie wholly beyond the radius are skipped: a row (dy, dz)
               whose nearest point is farther than the radius, and the end cells of a row (the
               cell is the radius wide, so a corner row or end cell often lies wholly outside
               the sphere around the point). It saved little (3D neighbour stage 72 -> 70 ms
               at 100k): rejected candidates are cheap once the test is branch-free. The margin
               (1e-5 of r^2) keeps every cell a rounded distance test could still accept, so the
               lists stay exactly the same (tests/test_grid.c, neighbors_cell_ordered). */
            const double lim = (double)r2max * (1 + 1e-5);
            for (dz = (D > 2 ? -1 : 0); dz <= (D > 2 ? 1 : 0); ++dz) {
                const int64_t z = cc[2] + dz;
                const double dz2 = dz < 0 ? lo2[2] : dz > 0 ? hi2[2] : 0;
                if (z < 0 || z >= ex2 || dz2 > lim) continue;
                for (dy = (D > 1 ? -1 : 0); dy <= (D > 1 ? 1 : 0); ++dy) {
                    const int64_t y = cc[1] + dy;
                    const double dyz2 = dz2 + (dy < 0 ? lo2[1] : dy > 0 ? hi2[1] : 0);
                    size_t q, qe;
                    int64_t row;
                    if (y < 0 || y >= ex1 || dyz2 > lim) continue;
                    if (half && (dz < 0 || (dz == 0 && dy < 0))) continue; /* rows before i's */
                    xa = dyz2 + lo2[0] <= lim ? cc[0] - 1 : cc[0];
                    xb = dyz2 + hi2[0] <= lim ? cc[0] + 1 : cc[0];
                    if (xa < 0) xa = 0; /* the point may lie outside the grid's box */
                    if (xb > ex0 - 1) xb = ex0 - 1;
                    if (xa > xb) continue;
                    row = (z * ex1 + y) * ex0;
                    q = g->start[row + xa];
                    qe = g->start[row + xb + 1];
                    /* half (sph__neighbors_build_self): only the points after the query point,
                       which in cell order are the later points of its own cell and the cells
                       after it */
                    if (half) {
                        if (qe <= i + 1) continue;
                        if (q <= i) q = i + 1;
                    }
                    /* Branch-free: about a third of the candidates pass the distance test, in no
                       predictable pattern. Each candidate is written at pos and pos advances only
                       if it passed (the next one overwrites a reject); while the region has room
                       for the whole row, no bound check is needed per candidate, and the query
                       point itself is skipped by splitting the row around it instead of a test
                       per candidate. With the split, the 2D neighbour stage went from 18.5 to
                       14.5 ms at 100k particles (the branch-free write alone: no measurable
                       change). An empty row does nothing (idx may still be NULL). */
                    if (q < qe && pos <= end && end - pos >= qe - q) {
                        uint32_t* out = nl->idx + pos;
                        size_t m = 0, qs = qe; /* the query point itself, when it lies here */
                        int seg;
                        if (exclude_self && i >= q && i < qe) qs = i;
                        for (seg = 0; seg < 2; ++seg) { /* the row before the query point, after */
                            const size_t qend = seg ? qe : qs;
#if SPH__VN > 1
                            q = sph__row_within(x, p, q, qend, r2max, out, &m, D);
#endif
                            for (; q < qend; ++q) {
                                const sph_real* xj = x + q * (size_t)D;
                                sph_real r2 = 0, dd;
                                dd = p[0] - xj[0]; r2 += dd * dd;
                                if (D > 1) { dd = p[1] - xj[1]; r2 += dd * dd; }
                                if (D > 2) { dd = p[2] - xj[2]; r2 += dd * dd; }
                                out[m] = (uint32_t)q;
                                m += (size_t)(r2 < r2max);
                            }
                            if (!seg && qs < qe) ++q; /* skip the query point */
                        }
                        pos += m;
                    } else {
                        for (; q < qe; ++q) { /* near the region's end: counts what is missing */
                            const sph_real* xj = x + q * (size_t)D;
                            sph_real r2 = 0, dd;
                            dd = p[0] - xj[0]; r2 += dd * dd;
                            if (D > 1) { dd = p[1] - xj[1]; r2 += dd * dd; }
                            if (D > 2) { dd = p[2] - xj[2]; r2 += dd * dd; }
                            if (r2 < r2max && !(exclude_self && q == i)) {
                                if (pos < end) nl->idx[pos] = (uint32_t)q;
                                ++pos;
                            }
                        }
                    }
                }
            }
        }
        nl->begin[i] = b0;
        nl->count[i] = (uint32_t)(pos - b0);
    }
    return pos - nl->chunk_off[c];
}

/* Out of memory in a build: the lists are left empty (n = 0), not half rebuilt (begin/count of
   the failed pass may point past idx); every array stays allocated and accounted for. */
static sph_status sph__neighbors_nomem(sph_neighbors* nl) {
    nl->n = 0;
    nl->nchunk = 0;
    nl->total = 0;
    return SPH_ERR_NOMEM;
}

/* Room for nq lists in nchunk chunks (begin, count and the chunk tables; new chunks start with no
   room of their own); sets n and nchunk. 0 when out of memory. */
static int sph__neighbors_reserve(sph_neighbors* nl, size_t nq, size_t nchunk) {
    size_t c;
    if (nq > nl->cap_n) {
        size_t cap = nq + nq / 4 + 16;
        if (!sph__grow((void**)&nl->begin, cap, sizeof(size_t)) ||
            !sph__grow((void**)&nl->count, cap, sizeof(uint32_t)))
            return 0;
        nl->cap_n = cap;
    }
    if (nchunk > nl->cap_chunk) {
        size_t cap = nchunk + nchunk / 4 + 4;
        if (!sph__grow((void**)&nl->chunk_off, cap + 1, sizeof(size_t)) ||
            !sph__grow((void**)&nl->chunk_need, cap, sizeof(size_t)) ||
            !sph__grow((void**)&nl->chunk_cap, cap, sizeof(size_t)))
            return 0;
        for (c = nl->cap_chunk; c < cap; ++c) nl->chunk_cap[c] = 0;
        nl->cap_chunk = cap;
    }
    nl->n = nq;
    nl->nchunk = nchunk;
    return 1;
}

/* Lays the chunk regions out back to back in idx, growing it to hold them. 0 when out of memory. */
static int sph__neighbors_layout(sph_neighbors* nl) {
    size_t c, total = 0;
    for (c = 0; c < nl->nchunk; ++c) { nl->chunk_off[c] = total; total += nl->chunk_cap[c]; }
    if (total > nl->cap_idx) {
        if (!sph__grow((void**)&nl->idx, total, sizeof(uint32_t))) return 0;
        nl->cap_idx = total;
    }
    return 1;
}

/* After a pass: 1 if a chunk needed more room than it had (its room is then grown for the second
   pass), else 0 with nl->total set to the number of pairs listed. */
static int sph__neighbors_room(sph_neighbors* nl) {
    size_t c;
    int overflow = 0;
    for (c = 0; c < nl->nchunk; ++c) {
        if (nl->chunk_need[c] > nl->chunk_cap[c]) {
            overflow = 1;
            nl->chunk_cap[c] = nl->chunk_need[c] + nl->chunk_need[c] / 4 + 16;
        }
    }
    nl->total = 0;
    if (!overflow)
        for (c = 0; c < nl->nchunk; ++c) nl->total += nl->chunk_need[c];
    return overflow;
}

/* near: NULL, or sph__grid_near's table of g (dense grids without periodic directions). half:
   the dense path only (see sph__neighbors_build_self), each list keeps its points after i. */
static sph_status sph__neighbors_search(sph_neighbors* nl, const sph_grid* g, const sph_real* x,
                                        const uint32_t* order, const sph_real* xq, size_t nq,
                                        sph_real radius, int exclude_self, const uint8_t* near,
                                        int half) {
    const size_t nchunk = (nq + SPH__CHUNK - 1) / SPH__CHUNK;
    int pass;
    if (!sph__neighbors_reserve(nl, nq, nchunk)) return sph__neighbors_nomem(nl);
    for (pass = 0; pass < 2; ++pass) {
        sph__idx ci;
        if (!sph__neighbors_layout(nl)) return sph__neighbors_nomem(nl);
        const int fast = !order && !g->hashed && !g->periodic[0] && !g->periodic[1] &&
                         !g->periodic[2] && g->n > 0;
        SPH_ASSERT(!half || (fast && exclude_self && xq == x));
        SPH__OMP_FOR_DYNAMIC(nchunk)
        for (ci = 0; ci < (sph__idx)nchunk; ++ci) {
            size_t need;
            if (fast && g->dim == 2)
                need = sph__neighbors_chunk_dense(nl, g, x, xq, nq, radius, exclude_self, (size_t)ci, near, half, 2);
            else if (fast && g->dim == 3)
                need = sph__neighbors_chunk_dense(nl, g, x, xq, nq, radius, exclude_self, (size_t)ci, near, half, 3);
            else if (fast)
                need = sph__neighbors_chunk_dense(nl, g, x, xq, nq, radius, exclude_self, (size_t)ci, near, half, 1);
            else
                need = sph__neighbors_chunk(nl, g, x, order, xq, nq, radius, exclude_self, (size_t)ci);
            nl->chunk_need[ci] = need;
        }
        if (!sph__neighbors_room(nl)) break;
        SPH_ASSERT(pass == 0); /* the second pass has room for every chunk */
    }
    return SPH_OK;
}

static sph_status sph__neighbors_build_near(sph_neighbors* nl, const sph_grid* g,
                                            const sph_real* x, const uint32_t* order,
                                            const sph_real* xq, size_t nq, sph_real radius,
                                            int exclude_self, const uint8_t* near) {
    return sph__neighbors_search(nl, g, x, order, xq, nq, radius, exclude_self, near, 0);
}

static sph_status sph__neighbors_build(sph_neighbors* nl, const sph_grid* g, const sph_real* x,
                                       const uint32_t* order, const sph_real* xq, size_t nq,
                                       sph_real radius, int exclude_self) {
    return sph__neighbors_build_near(nl, g, x, order, xq, nq, radius, exclude_self, NULL);
}

/* For each cell of the dense table of g, whether a point of g lies in the 3^dim cells around it
   (occupancy widened by a cell along x, y and z in turn), into *near (grown to the table; 1
   byte a cell). A query point whose cell has none has no neighbours in g: the search then skips
   its stencil (the fluid inside a tank against the walls' grid; 3D dam break, 59k fluid and
   150k wall particles, 1 thread: the fluid's wall lists 4.9 -> 3.1 ms a step). *on: whether
   the table was made (not for a hashed or periodic grid, whose every stencil is visited);
   SPH_ERR_NOMEM when out of memory. */
static sph_status sph__grid_near(const sph_grid* g, uint8_t** near, size_t* cap, int* on) {
    const int64_t ex[3] = {g->ext[0], g->dim > 1 ? g->ext[1] : 1, g->dim > 2 ? g->ext[2] : 1};
    const int64_t st[3] = {1, ex[0], ex[0] * ex[1]};
    const int64_t nc = (int64_t)g->nbucket;
    sph__idx l;
    int k;
    *on = 0;
    if (g->hashed || g->periodic[0] || g->periodic[1] || g->periodic[2] || g->n == 0)
        return SPH_OK;
    if ((size_t)nc > *cap) {
        const size_t c = (size_t)nc + (size_t)nc / 4 + 16;
        if (!sph__grow((void**)near, c, 1)) return SPH_ERR_NOMEM;
        *cap = c;
    }
    SPH__OMP_FOR(nc)
    for (l = 0; l < (sph__idx)nc; ++l) (*near)[l] = (uint8_t)(g->start[l + 1] > g->start[l]);
    for (k = 0; k < g->dim; ++k) {
        const int64_t len = ex[k], stride = st[k], nline = nc / len;
        uint8_t* nr = *near;
        SPH__OMP_FOR(nline)
        for (l = 0; l < (sph__idx)nline; ++l) { /* line l: every coordinate but k fixed */
            uint8_t* c = nr + ((int64_t)l / stride) * stride * len + (int64_t)l % stride;
            uint8_t prev = 0;
            int64_t t;
            for (t = 0; t < len; ++t, c += stride) {
                const uint8_t cur = *c;
                *c = (uint8_t)(prev | cur | (t + 1 < len ? c[stride] : 0));
                prev = cur;
            }
        }
    }
    *on = 1;
    return SPH_OK;
}

/* sph_neighbors_build for points the host keeps in any order (2D, 100k random points, ~21
   neighbours, 1 thread: 765 ns a point through the permutation, 148 for the same points in cell
   order). The points are copied in the grid's order (xs[k] = x[order[k]]) and searched in place
   (the dense path where the grid has one), for the queries in the host's order, so that each
   row lies where a search through the permutation puts it (taking the queries in cell order as
   well was 4 % slower in the second-order scheme's steps, whose loops then read the rows out of
   order). Then every index is mapped back (order[j]), and with exclude_self the query's own
   point is dropped (it is the point of the same index). The lists hold the same pairs as the
   search through the permutation. */
static sph_status sph__neighbors_build_sorted(sph_neighbors* nl, const sph_grid* g,
                                              const sph_real* x, const sph_real* xq, size_t nq,
                                              sph_real radius, int exclude_self) {
    const size_t n = g->n, D = (size_t)g->dim;
    const uint32_t* order = g->order;
    size_t total = 0;
    sph_status s;
    sph__idx k;
    if (n * D > nl->cap_xs) {
        if (!sph__grow((void**)&nl->xs, n * D, sizeof(sph_real))) return sph__neighbors_nomem(nl);
        nl->cap_xs = n * D;
    }
    SPH__OMP_FOR(n)
    for (k = 0; k < (sph__idx)n; ++k) {
        size_t d;
        for (d = 0; d < D; ++d) nl->xs[(size_t)k * D + d] = x[(size_t)order[k] * D + d];
    }
    s = sph__neighbors_build(nl, g, nl->xs, NULL, xq, nq, radius, 0);
    if (s != SPH_OK) return s;
    SPH__OMP_FOR(nq)
    for (k = 0; k < (sph__idx)nq; ++k) {
        uint32_t* row = nl->idx + nl->begin[k];
        uint32_t l, m = 0;
        for (l = 0; l < nl->count[k]; ++l) {
            const uint32_t j = order[row[l]];
            row[m] = j;
            m += !(exclude_self && j == (uint32_t)k);
        }
        nl->count[k] = m;
    }
    if (exclude_self) { /* one entry fewer in most rows */
        for (k = 0; k < (sph__idx)nq; ++k) total += nl->count[k];
        nl->total = total;
    }
    return SPH_OK;
}

SPHDEF sph_status sph_neighbors_build(sph_neighbors* nl, const sph_grid* g, const sph_real* x,
                                      const sph_real* xq, size_t nq, sph_real radius,
                                      int exclude_self) {
    if (!nl || !g || (!x && g->n) || (!xq && nq) || !(radius > 0) || radius > g->cell)
        return SPH_ERR_ARG;
    /* points the host already keeps in cell order (as the world keeps its particles) take the
       fast path, which reads them in place instead of through the permutation: checking the
       order costs one pass over n indices, the indirection a random read per candidate */
    {
        size_t i = 0;
        while (i < g->n && g->order[i] == (uint32_t)i) ++i;
        if (i == g->n) return sph__neighbors_build(nl, g, x, NULL, xq, nq, radius, exclude_self);
        return sph__neighbors_build_sorted(nl, g, x, xq, nq, radius, exclude_self);
    }
}

/* r^2 of a candidate pair as the search computes it: d = p - x_j (periodic directions wrapped
   as in SPH__GRID_VISIT, pw = p wrapped), r^2 = (dx^2 + dy^2) + dz^2. */
SPH__INLINE sph_real sph__filter_r2(const sph_grid* g, const sph_real* p, const sph_real* pw,
                                    const sph_real* xj, int per, const int D) {
    sph_real r2 = 0, dd;
    int k;
    if (!per) {
        dd = p[0] - xj[0]; r2 += dd * dd;
        if (D > 1) { dd = p[1] - xj[1]; r2 += dd * dd; }
        if (D > 2) { dd = p[2] - xj[2]; r2 += dd * dd; }
        return r2;
    }
    for (k = 0; k < D; ++k) {
        dd = g->periodic[k] ? sph__wrap_delta(pw[k] - sph__periodic_wrap(g, k, xj[k]), g->len[k])
                            : p[k] - xj[k];
        r2 += dd * dd;
    }
    return r2;
}

/* Verlet lists (Verlet 1967): the pairs of candidate lists `cand` (built on grid g, points x,
   queries xq, with a radius beyond `radius`) that lie within radius, into nl, in the candidates'
   order, for the queries of chunk c. The test is the search's own (sph__filter_r2, r^2 <
   radius^2), so nl holds exactly the pairs a search with radius would find
   (tests/test_verlet.c). nl's chunk regions are its own, sized from the last filter as the
   search sizes them (not the candidates': the per-pair caches follow the lists' room); a query
   whose candidates all fit is written branch-free, as in the search. Returns the entries the
   chunk needed. */
SPH__INLINE size_t sph__neighbors_filter_chunk(sph_neighbors* nl, const sph_neighbors* cand,
                                               const sph_grid* g, const sph_real* x,
                                               const sph_real* xq, sph_real r2max, size_t c,
                                               const int D) {
    size_t i, i0 = c * SPH__CHUNK, i1 = i0 + SPH__CHUNK;
    size_t pos = nl->chunk_off[c], end = pos + nl->chunk_cap[c];
    const int per = g->periodic[0] || g->periodic[1] || g->periodic[2];
    if (i1 > cand->n) i1 = cand->n;
    for (i = i0; i < i1; ++i) {
        const sph_real* p = xq + i * (size_t)D;
        const size_t k0 = cand->begin[i], k1 = k0 + cand->count[i], b0 = pos;
        sph_real pw[3] = {0, 0, 0};
        size_t kk;
        int k;
        if (per)
            for (k = 0; k < D; ++k) pw[k] = g->periodic[k] ? sph__periodic_wrap(g, k, p[k]) : p[k];
        if (pos <= end && end - pos >= k1 - k0) {
            for (kk = k0; kk < k1; ++kk) {
                const uint32_t j = cand->idx[kk];
                const sph_real r2 = sph__filter_r2(g, p, pw, x + (size_t)j * (size_t)D, per, D);
                nl->idx[pos] = j;
                pos += (size_t)(r2 < r2max);
            }
        } else { /* near the region's end: counts what is missing */
            for (kk = k0; kk < k1; ++kk) {
                const uint32_t j = cand->idx[kk];
                if (sph__filter_r2(g, p, pw, x + (size_t)j * (size_t)D, per, D) < r2max) {
                    if (pos < end) nl->idx[pos] = j;
                    ++pos;
                }
            }
        }
        nl->begin[i] = b0;
        nl->count[i] = (uint32_t)(pos - b0);
    }
    return pos - nl->chunk_off[c];
}

/* Lays nl out like sph__neighbors_build (chunk regions from the last filter's needs, a second
   pass when one overflowed) and filters cand into it. Grows memory only when the lists grew. */
static sph_status sph__neighbors_filter(sph_neighbors* nl, const sph_neighbors* cand,
                                        const sph_grid* g, const sph_real* x, const sph_real* xq,
                                        sph_real radius) {
    const sph_real r2max = radius * radius;
    const size_t nchunk = cand->nchunk, nq = cand->n;
    int pass;
    if (!sph__neighbors_reserve(nl, nq, nchunk)) return sph__neighbors_nomem(nl);
    for (pass = 0; pass < 2; ++pass) {
        sph__idx ci;
        if (!sph__neighbors_layout(nl)) return sph__neighbors_nomem(nl);
        SPH__OMP_FOR_DYNAMIC(nchunk)
        for (ci = 0; ci < (sph__idx)nchunk; ++ci) {
            size_t need;
            if (g->dim == 2) need = sph__neighbors_filter_chunk(nl, cand, g, x, xq, r2max, (size_t)ci, 2);
            else if (g->dim == 3) need = sph__neighbors_filter_chunk(nl, cand, g, x, xq, r2max, (size_t)ci, 3);
            else need = sph__neighbors_filter_chunk(nl, cand, g, x, xq, r2max, (size_t)ci, 1);
            nl->chunk_need[ci] = need;
        }
        if (!sph__neighbors_room(nl)) break;
        SPH_ASSERT(pass == 0); /* the second pass has room for every chunk */
    }
    return SPH_OK;
}

/* The lists of the np points a set of lists src points at, read from the other side: point b's
   list holds, in ascending order, every query point of src whose list holds b. A search of the
   same pairs from b's side gives exactly these lists when the pair test is symmetric and the
   searched points are in cell order (see sph__wall_lists_mirrored), so the walls' lists
   (boundary->fluid) need no search of their own: their pairs are the fluid's wall lists'. A
   counting sort by b, one pass over the pairs (serial, as the pairs are few: those at the
   walls); idx keeps its room between calls. */
static sph_status sph__neighbors_transpose(sph_neighbors* nl, const sph_neighbors* src, size_t np) {
    const size_t total = src->total;
    size_t i, kk, b, sum = 0;
    if (!sph__neighbors_reserve(nl, np, (np + SPH__CHUNK - 1) / SPH__CHUNK))
        return sph__neighbors_nomem(nl);
    if (total > nl->cap_idx) {
        const size_t cap = total + total / 4 + 16;
        if (!sph__grow((void**)&nl->idx, cap, sizeof(uint32_t))) return sph__neighbors_nomem(nl);
        nl->cap_idx = cap;
    }
    for (b = 0; b < np; ++b) nl->count[b] = 0;
    for (i = 0; i < src->n; ++i)
        for (kk = src->begin[i]; kk < src->begin[i] + src->count[i]; ++kk) ++nl->count[src->idx[kk]];
    for (b = 0; b < np; ++b) { nl->begin[b] = sum; sum += nl->count[b]; nl->count[b] = 0; }
    for (i = 0; i < src->n; ++i)
        for (kk = src->begin[i]; kk < src->begin[i] + src->count[i]; ++kk) {
            const uint32_t j = src->idx[kk];
            nl->idx[nl->begin[j] + nl->count[j]++] = (uint32_t)i;
        }
    nl->total = total;
    return SPH_OK;
}

/* The first of the points whose lists may hold a point a or any point after it (the grid's
   points in cell order, dense, no periodic direction): a point's neighbours lie in the cells
   around its own, none more than `back` cells before it in the table's order, and the points of
   the cells after a's come after a. */
static size_t sph__cell_order_lo(const sph_grid* g, const sph_real* x, size_t a, int64_t back) {
    int64_t lin = 0;
    int k;
    for (k = g->dim - 1; k >= 0; --k)
        lin = lin * g->ext[k] + ((int64_t)sph__cell_coord(g, k, x[a * (size_t)g->dim + (size_t)k]) -
                                 g->cmin[k]);
    lin -= back;
    return lin > 0 ? (size_t)g->start[lin] : 0;
}

/* Narrows the half list hi[k0, k1) (ascending) to its points in the part [a, b). */
SPH__INLINE void sph__half_in_part(const uint32_t* hi, size_t a, size_t b, size_t* k0, size_t* k1) {
    while (*k0 < *k1 && hi[*k0] < a) ++*k0;
    while (*k1 > *k0 && hi[*k1 - 1] >= b) --*k1;
}

/* The lists of a point set against itself (exclude_self) from one distance test a pair: on
   the dense path a half search keeps in `half` each point's neighbours after it (the later
   points of its own cell and those of the cells after it), and each list is then
   unfolded: point i's list is the points h < i whose half list holds i, in ascending h, then
   its own half list. The search lists a point's neighbours in ascending index (the stencil's
   rows are ascending ranges of the cell order) and its distance test gives a pair the same r^2
   from either side (d and -d square alike, summed in the same order), so these are its lists
   pair for pair and in order (tests/test_verlet.c, half_lists_match_search). The unfolding runs
   in parts of consecutive lists, a part scanning the half lists of the points that may reach
   it (sph__cell_order_lo): the same lists for any number of parts. 59k points (a jittered
   39^3 lattice, R = 2 dx, 28 neighbours), 1 thread: whole search 12.0 ms, half search 6.4 ms
   and unfolding 3.4 ms (its stores are most of it); the 3D IISPH dam break at 59k to t = 0.3 s
   took 0.96 of the CPU time (whole process, 1 thread). Other grids (hashed, periodic) are
   searched whole. */
static sph_status sph__neighbors_build_self(sph_neighbors* nl, sph_neighbors* half,
                                            const sph_grid* g, const sph_real* x, size_t n,
                                            sph_real radius) {
    const int D = g->dim;
    const int64_t back = (D > 2 ? g->ext[0] * g->ext[1] : 0) + (D > 1 ? g->ext[0] : 0) + 1;
    size_t i, sum = 0, total;
    int nparts = 1;
    sph__idx t;
    sph_status s;
    if (g->hashed || g->periodic[0] || g->periodic[1] || g->periodic[2] || g->n != n || n == 0)
        return sph__neighbors_build(nl, g, x, NULL, x, n, radius, 1);
    s = sph__neighbors_search(half, g, x, NULL, x, n, radius, 1, NULL, 1);
    if (s != SPH_OK) return sph__neighbors_nomem(nl);
    total = 2 * half->total;
    if (!sph__neighbors_reserve(nl, n, (n + SPH__CHUNK - 1) / SPH__CHUNK))
        return sph__neighbors_nomem(nl);
    if (total > nl->cap_idx) {
        const size_t cap = total + total / 4 + 16;
        if (!sph__grow((void**)&nl->idx, cap, sizeof(uint32_t))) return sph__neighbors_nomem(nl);
        nl->cap_idx = cap;
    }
#ifdef _OPENMP
    /* a part per thread: each part also scans the half lists of about a layer of cells before
       it, so more parts would scan more */
    if (n > 2048) nparts = omp_get_max_threads();
#endif
    /* the number of points before i in i's list, into count */
#ifdef _OPENMP
#pragma omp parallel for schedule(static, 1) if (nparts > 1)
#endif
    for (t = 0; t < (sph__idx)nparts; ++t) {
        const size_t a = n * (size_t)t / (size_t)nparts, b = n * (size_t)(t + 1) / (size_t)nparts;
        const size_t* hb = half->begin;
        const uint32_t* hc = half->count;
        const uint32_t* hi = half->idx;
        uint32_t* cnt = nl->count;
        size_t h, kk;
        if (a == b) continue;
        for (h = a; h < b; ++h) cnt[h] = 0;
        for (h = sph__cell_order_lo(g, x, a, back); h < b; ++h) {
            size_t k0 = hb[h], k1 = k0 + hc[h];
            sph__half_in_part(hi, a, b, &k0, &k1);
            for (kk = k0; kk < k1; ++kk) ++cnt[hi[kk]];
        }
    }
    for (i = 0; i < n; ++i) {
        nl->begin[i] = sum;
        sum += nl->count[i] + half->count[i];
    }
    SPH_ASSERT(sum == total);
    /* the lists: point h goes into the lists of its half list's points, in ascending h, and its
       own half list follows the points before it (all written when h is reached); at[j]: where
       list j's next point goes (the arrays read into locals: the stores into idx would
       otherwise make the compiler read them again for every pair) */
#ifdef _OPENMP
#pragma omp parallel for schedule(static, 1) if (nparts > 1)
#endif
    for (t = 0; t < (sph__idx)nparts; ++t) {
        const size_t a = n * (size_t)t / (size_t)nparts, b = n * (size_t)(t + 1) / (size_t)nparts;
        const size_t* hb = half->begin;
        const uint32_t* hc = half->count;
        const uint32_t* hi = half->idx;
        size_t* at = nl->begin;
        uint32_t* out = nl->idx;
        size_t h, kk;
        if (a == b) continue;
        for (h = sph__cell_order_lo(g, x, a, back); h < b; ++h) {
            size_t k0 = hb[h], k1 = k0 + hc[h];
            if (h >= a) {
                size_t o = at[h];
                for (kk = k0; kk < k1; ++kk) out[o++] = hi[kk];
                at[h] = o;
            }
            sph__half_in_part(hi, a, b, &k0, &k1);
            for (kk = k0; kk < k1; ++kk) out[at[hi[kk]]++] = (uint32_t)h;
        }
        /* each list's end back to its beginning */
        for (h = a; h < b; ++h) {
            nl->count[h] += hc[h];
            at[h] -= nl->count[h];
        }
    }
    nl->total = total;
    return SPH_OK;
}

SPHDEF void sph_neighbors_free(sph_neighbors* nl) {
    if (!nl) return;
    SPH_FREE(nl->begin);
    SPH_FREE(nl->count);
    SPH_FREE(nl->idx);
    SPH_FREE(nl->chunk_off);
    SPH_FREE(nl->chunk_cap);
    SPH_FREE(nl->chunk_need);
    SPH_FREE(nl->xs);
    memset(nl, 0, sizeof(*nl));
}

/* ============================================================================================== */
/* >>operators (implementation)                                                                   */
/* ============================================================================================== */

SPHDEF void sph_op_volume(const sph_grid* g, const sph_neighbors* nl, const sph_kernel* k,
                          const sph_real* x, size_t n, sph_real* vol) {
    const size_t D = (size_t)g->dim;
    const sph_real w0 = sph_kernel_w(k, 0);
    sph__idx i;
    SPH__OMP_FOR(n)
    for (i = 0; i < (sph__idx)n; ++i) {
        const size_t k0 = nl->begin[i], k1 = k0 + nl->count[i];
        sph_real sum = w0, d[3], r2;
        size_t kk, a;
        for (kk = k0; kk < k1; ++kk) {
            sph_grid_delta(g, x + (size_t)i * D, x + (size_t)nl->idx[kk] * D, d);
            for (r2 = 0, a = 0; a < D; ++a) r2 += d[a] * d[a];
            sum += sph_kernel_w(k, sph__sqrt(r2));
        }
        vol[i] = 1 / sum;
    }
}

/* Inverts the d x d matrix A in place; returns 0 if it is singular relative to its size. */
static int sph__invert(sph_real* A, int d) {
    if (d == 1) {
        if (!(sph__fabs(A[0]) > SPH__R(1e-12))) return 0;
        A[0] = 1 / A[0];
        return 1;
    }
    if (d == 2) {
        const sph_real det = A[0] * A[3] - A[1] * A[2];
        const sph_real scale = sph__fabs(A[0] * A[3]) + sph__fabs(A[1] * A[2]);
        sph_real t;
        if (!(sph__fabs(det) > SPH__R(1e-9) * scale)) return 0;
        t = A[0];
        A[0] = A[3] / det;
        A[3] = t / det;
        A[1] = -A[1] / det;
        A[2] = -A[2] / det;
        return 1;
    } else {
        sph_real c[9], det, scale = 0;
        int q;
        c[0] = A[4] * A[8] - A[5] * A[7];
        c[1] = A[2] * A[7] - A[1] * A[8];
        c[2] = A[1] * A[5] - A[2] * A[4];
        c[3] = A[5] * A[6] - A[3] * A[8];
        c[4] = A[0] * A[8] - A[2] * A[6];
        c[5] = A[2] * A[3] - A[0] * A[5];
        c[6] = A[3] * A[7] - A[4] * A[6];
        c[7] = A[1] * A[6] - A[0] * A[7];
        c[8] = A[0] * A[4] - A[1] * A[3];
        det = A[0] * c[0] + A[1] * c[3] + A[2] * c[6];
        for (q = 0; q < 9; ++q) scale += sph__fabs(A[q]);
        if (!(sph__fabs(det) > SPH__R(1e-9) * scale * scale * scale)) return 0;
        for (q = 0; q < 9; ++q) A[q] = c[q] / det;
        return 1;
    }
}

SPHDEF size_t sph_op_correction(const sph_grid* g, const sph_neighbors* nl, const sph_kernel* k,
                                const sph_real* x, const sph_real* vol, size_t n, sph_real* B) {
    const int D = g->dim;
    const size_t DD = (size_t)(D * D);
    size_t singular = 0;
    sph__idx i;
#if defined(_OPENMP)
#pragma omp parallel for schedule(static) reduction(+ : singular) if (n > 2048)
#endif
    for (i = 0; i < (sph__idx)n; ++i) {
        const size_t k0 = nl->begin[i], k1 = k0 + nl->count[i];
        sph_real* Bi = B + (size_t)i * DD;
        sph_real d[3], gw[3];
        size_t kk;
        int a, b;
        for (a = 0; a < (int)DD; ++a) Bi[a] = 0;
        for (kk = k0; kk < k1; ++kk) {
            const size_t j = nl->idx[kk];
            sph_grid_delta(g, x + (size_t)i * (size_t)D, x + j * (size_t)D, d); /* x_i - x_j */
            sph_kernel_grad(k, d, gw);
            for (a = 0; a < D; ++a) /* A^{ab} = sum_j omega_j d_a W_ij (x_j - x_i)^b */
                for (b = 0; b < D; ++b) Bi[a * D + b] -= vol[j] * gw[a] * d[b];
        }
        if (!sph__invert(Bi, D)) {
            for (a = 0; a < (int)DD; ++a) Bi[a] = 0;
            for (a = 0; a < D; ++a) Bi[a * D + a] = 1;
            ++singular;
        }
    }
    return singular;
}

/* grad W_ij of the pair, corrected by B_i when B is given. */
SPH__INLINE void sph__op_gradw(const sph_grid* g, const sph_kernel* k, const sph_real* B,
                               const sph_real* xi, const sph_real* xj, size_t i, sph_real* gw) {
    const int D = g->dim;
    sph_real d[3], t[3];
    int a, b;
    sph_grid_delta(g, xi, xj, d);
    sph_kernel_grad(k, d, t);
    if (!B) {
        for (a = 0; a < D; ++a) gw[a] = t[a];
        return;
    }
    for (a = 0; a < D; ++a) {
        const sph_real* row = B + i * (size_t)(D * D) + (size_t)(a * D);
        gw[a] = 0;
        for (b = 0; b < D; ++b) gw[a] += row[b] * t[b];
    }
}

SPHDEF void sph_op_gradient(const sph_grid* g, const sph_neighbors* nl, const sph_kernel* k,
                            const sph_real* x, const sph_real* vol, const sph_real* B,
                            const sph_real* f, size_t stride, size_t n, sph_real* grad) {
    const int D = g->dim;
    sph__idx i;
    SPH__OMP_FOR(n)
    for (i = 0; i < (sph__idx)n; ++i) {
        const size_t k0 = nl->begin[i], k1 = k0 + nl->count[i];
        const sph_real fi = f[(size_t)i * stride];
        sph_real acc[3] = {0, 0, 0}, gw[3];
        size_t kk;
        int a;
        for (kk = k0; kk < k1; ++kk) {
            const size_t j = nl->idx[kk];
            const sph_real df = (f[j * stride] - fi) * vol[j];
            sph__op_gradw(g, k, B, x + (size_t)i * (size_t)D, x + j * (size_t)D, (size_t)i, gw);
            for (a = 0; a < D; ++a) acc[a] += df * gw[a];
        }
        for (a = 0; a < D; ++a) grad[(size_t)i * (size_t)D + (size_t)a] = acc[a];
    }
}

SPHDEF void sph_op_divergence(const sph_grid* g, const sph_neighbors* nl, const sph_kernel* k,
                              const sph_real* x, const sph_real* vol, const sph_real* B,
                              const sph_real* u, size_t n, sph_real* div) {
    const int D = g->dim;
    sph__idx i;
    SPH__OMP_FOR(n)
    for (i = 0; i < (sph__idx)n; ++i) {
        const size_t k0 = nl->begin[i], k1 = k0 + nl->count[i];
        const sph_real* ui = u + (size_t)i * (size_t)D;
        sph_real acc = 0, gw[3];
        size_t kk;
        int a;
        for (kk = k0; kk < k1; ++kk) {
            const size_t j = nl->idx[kk];
            const sph_real* uj = u + j * (size_t)D;
            sph_real dot = 0;
            sph__op_gradw(g, k, B, x + (size_t)i * (size_t)D, x + j * (size_t)D, (size_t)i, gw);
            for (a = 0; a < D; ++a) dot += (uj[a] - ui[a]) * gw[a];
            acc += dot * vol[j];
        }
        div[i] = acc;
    }
}

SPHDEF void sph_op_shift(const sph_grid* g, const sph_neighbors* nl, const sph_kernel* k,
                         const sph_real* x, const sph_real* vol, size_t n, sph_real* dx) {
    const int D = g->dim;
    sph__idx i;
    SPH__OMP_FOR(n)
    for (i = 0; i < (sph__idx)n; ++i) {
        const size_t k0 = nl->begin[i], k1 = k0 + nl->count[i];
        sph_real acc[3] = {0, 0, 0}, d[3];
        size_t kk;
        int a;
        for (kk = k0; kk < k1; ++kk) {
            const size_t j = nl->idx[kk];
            sph_real r2 = 0, r, c;
            sph_grid_delta(g, x + (size_t)i * (size_t)D, x + j * (size_t)D, d);
            for (a = 0; a < D; ++a) r2 += d[a] * d[a];
            r = sph__sqrt(r2);
            if (!(r > 0)) continue;
            c = sph_kernel_w(k, r) * vol[j] / r;
            for (a = 0; a < D; ++a) acc[a] += c * d[a];
        }
        for (a = 0; a < D; ++a) dx[(size_t)i * (size_t)D + (size_t)a] = k->h * acc[a];
    }
}

SPHDEF void sph_op_laplacian(const sph_grid* g, const sph_neighbors* nl, const sph_kernel* k,
                             const sph_real* x, const sph_real* vol, const sph_real* B,
                             const sph_real* f, size_t stride, size_t n, sph_real* grad,
                             sph_real* lap) {
    sph_op_gradient(g, nl, k, x, vol, B, f, stride, n, grad);
    sph_op_divergence(g, nl, k, x, vol, B, grad, n, lap);
}

/* ============================================================================================== */
/* >>world (implementation)                                                                       */
/* ============================================================================================== */

SPHDEF sph_world_def sph_world_def_default(int dim) {
    sph_world_def d;
    memset(&d, 0, sizeof(d));
    d.dim = dim;
    d.spacing = SPH__R(0.01);
    d.h_factor = 0;
    d.kernel = SPH_KERNEL_AUTO;
    if (dim >= 2) d.gravity[1] = SPH__R(-9.81);
    d.solver = SPH_SOLVER_WCSPH;
    d.density = SPH_DENSITY_CONTINUITY;
    d.pressure_grad = SPH_PGRAD_SYMMETRIC;
    d.integrator = SPH_INTEGRATOR_SYMPLECTIC_EULER;
    d.scheme = SPH_SCHEME_STANDARD;
    d.shift_every = 10;
    d.delta = SPH__R(0.1);  /* Molteni & Colagrossi 2009; Enhanced PCISPH 2018 sec. 3.2.1: "usually 0.1" */
    d.alpha = SPH__R(0.02);
    d.beta = 0;
    d.wall = SPH_WALL_FREE_SLIP;
    d.cfl = SPH__R(0.25);
    d.cfl_viscous = SPH__R(0.125); /* Morris et al. 1997; see sph_stable_dt for the margins */
    d.cfl_force = SPH__R(0.25);
    d.max_compression = SPH__R(0.2);
    d.max_speed = 0;
    d.max_displacement = 1;
    d.check_walls = 1;
    /* sqrt(dim)/2: a particle over the hollow between wall particles of a lattice at dx then
       keeps its centre on the fluid side of the wall's face (sph__wall_contact) */
    d.wall_contact = (sph_real)(0.02 + 0.5 * sqrt((double)(dim >= 1 && dim <= 3 ? dim : 3)));
    d.max_substeps = 100000;
    d.neighbor_skin = -1; /* automatic: see sph__verlet_radius */
    d.boundary_pressure = SPH_BP_AUTO;
    d.boundary_volume = SPH_BVOL_AUTO;
    d.boundary_gamma = 0; /* calibrated by sph_world_init (sph__akinci_gamma) */
    d.cfl_velocity = SPH__R(0.4); /* Meiers 2025 eq. 14 */
    d.tolerance = SPH__R(0.001);  /* 0.1 % mean compression, Meiers 2025 */
    d.min_iterations = 2;
    d.max_iterations = 100;
    /* automatic (resolved by sph_world_init): Ihmsen et al. 2014, Meiers 2025: 0.5.
       Relaxed Jacobi converges while omega lambda_max < 2, lambda_max of D^-1 A: 2.6 on a 2D
       lattice, 4.1 on a 3D one and 5.4-5.7 once it disorders (Wendland C2, h = 1.3 dx: 21
       neighbours in 2D, 73 in 3D), so a kernel with that many neighbours gets 0.3 */
    d.omega = 0;
    d.pressure_solve = SPH_PSOLVE_JACOBI;
    d.warm_start = SPH__R(0.5);   /* Ihmsen et al. 2014 */
    d.tolerance_max = 0;
    d.pcisph_factor = SPH_PCISPH_PROTOTYPE;
    d.pcisph_gain = 1;            /* Solenthaler & Pajarola 2009 */
    d.pressure_smoothing = 1;
    d.divergence_tolerance = SPH__R(0.001); /* 0.1 %, SPlisHSPlasH's default for DFSPH */
    d.pbf_iterations = 3;         /* see sph__step_pbf for the measurement */
    d.pbf_relaxation = 1;
    d.pbf_scorr = 0;              /* off: see >>pbf (the paper: 0.1) */
    d.pbf_xsph = SPH__R(0.01);    /* Macklin & Mueller 2013, sec. 5 */
    d.pbf_compression = SPH__R(0.01);
    return d;
}

SPHDEF void sph_world_def_pcisph(sph_world_def* def, int enhanced) {
    if (!def) return;
    def->solver = SPH_SOLVER_PCISPH;
    /* Solenthaler & Pajarola iterate at least 3 times; 0.01 % mean density error is the
       SPlisHSPlasH default (its PCISPH maxError = 0.01 %). A looser tolerance leaves the fluid
       resting on a standing compression near the tolerance, which keeps it oscillating. */
    def->min_iterations = 3;
    def->tolerance = SPH__R(1e-4);
    if (enhanced) { /* Enhanced PCISPH 2018 sec. 3.2 (a)-(e) */
        def->density = SPH_DENSITY_CONTINUITY;
        def->delta = SPH__R(0.1);
        def->pressure_smoothing = SPH__R(0.8);
        def->boundary_pressure = SPH_BP_EXTRAPOLATE;
        def->integrator = SPH_INTEGRATOR_VERLET;
        def->pcisph_factor = SPH_PCISPH_PER_PARTICLE;
        def->pressure_grad = SPH_PGRAD_MULTIPHASE;
        def->warm_start = SPH__R(0.5);
    } else { /* Solenthaler & Pajarola 2009 (Enhanced PCISPH 2018 Alg. 5) */
        def->warm_start = 0;
        def->density = SPH_DENSITY_SUMMATION;
        def->delta = 0;
        def->pressure_smoothing = 1;
        def->boundary_pressure = SPH_BP_ZERO;
        def->integrator = SPH_INTEGRATOR_SYMPLECTIC_EULER;
        def->pcisph_factor = SPH_PCISPH_PROTOTYPE;
        def->pressure_grad = SPH_PGRAD_SYMMETRIC;
    }
}

/* Coordinates far from the origin leave the spacing under-resolved: x carries |x| eps(sph_real)
   of rounding [m], and the fluid feels that noise as a disordered lattice. Measured with a 2D
   float tank at rest (600 particles, dx = 0.01 to 0.02 m, 1 s of WCSPH, tests/test_hostile.c):
   no particle left its walls while the rounding step ulp(x) <= 0.0015 dx (x up to 510 m at
   dx = 0.02), 2 of 600 did at ulp = 0.002 dx, 4 to 10 at 0.003 dx, 308 at x = 1e4 m (0.06 dx).
   Since ulp(x) <= |x| eps, |x| eps <= dx / 1000 keeps a margin of 1.5 below the last clean
   measurement: |x| <= 168 m at dx = 0.02 in float, 9e10 m in double. */
#define SPH__FAR_FRACTION 1000.0
#ifdef SPH_FLOAT
#define SPH__EPS 1.1920928955078125e-07 /* FLT_EPSILON */
#else
#define SPH__EPS 2.220446049250313e-16 /* DBL_EPSILON */
#endif

/* The largest |coordinate| [m] a world of spacing dx accepts. */
static double sph__far_limit(sph_real dx) { return (double)dx / (SPH__FAR_FRACTION * SPH__EPS); }

/* Index of the first of count coordinates beyond the limit, or count if none. */
static size_t sph__first_far(const sph_real* x, size_t count, double limit) {
    size_t i;
    for (i = 0; i < count; ++i)
        if (fabs((double)x[i]) > limit) return i;
    return count;
}

/* The message for a coordinate beyond the limit; what names the caller and the particle. */
static sph_status sph__fail_far(sph_world* w, sph_real dx, long index, const char* what,
                                double value) {
    return sph__fail(w, SPH_ERR_ARG, index,
                     "%s = %g m: too far from the origin for dx = %g m in %s (|x| must be <= "
                     "%.3g m, |x| eps <= dx/1000): place the scene near the origin%s",
                     what, value, (double)dx, sizeof(sph_real) == 4 ? "float" : "double",
                     sph__far_limit(dx),
                     sizeof(sph_real) == 4 ? " or build in double (without SPH_FLOAT)" : "");
}

/* Each check names the field and the value it rejects. */
#define SPH__CHECK(cond, ...)                                                                      \
    do { if (!(cond)) return sph__fail(w, SPH_ERR_ARG, -1, __VA_ARGS__); } while (0)

/* Why SPH_BP_MIRROR is refused (derived in BOUNDARIES): measured on a 2D tank at rest (1 x 0.8 m
   of water in a 1 m box, dx 0.04, sph_advance with frames of 0.05 s, 1.5 s) it kept the water
   moving at 0.3-0.44 sqrt(g H) with the kinetic energy climbing to 0.3 % (WCSPH) and 0.6 % (IISPH)
   of rho g H^2 per metre of tank, where extrapolated and zero walls come to rest. */
static const char sph__mirror_rejected[] =
    "boundary_pressure = SPH_BP_MIRROR: mirrored wall pressure (p_b = p_i) is not a conservative "
    "force and puts energy into a fluid at rest with every solver; use SPH_BP_AUTO (the "
    "default), SPH_BP_EXTRAPOLATE or SPH_BP_ZERO";

static sph_status sph__validate_def(sph_world* w, const sph_world_def* d) {
    int k;
    SPH__CHECK(d->dim >= 1 && d->dim <= 3, "sph_world_def.dim = %d: must be 1, 2 or 3", d->dim);
    SPH__CHECK(sph__finite((double)d->spacing) && d->spacing > 0,
               "sph_world_def.spacing = %g: must be finite and > 0", (double)d->spacing);
    /* up to 100: 1D studies use h = 20 dx (Ott & Schnetter 2003's sound wave) */
    SPH__CHECK(sph__finite((double)d->h_factor) && d->h_factor >= 0 && d->h_factor <= 100,
               "sph_world_def.h_factor = %g: must be 0 (kernel default) or in (0, 100]",
               (double)d->h_factor);
    SPH__CHECK(d->kernel == SPH_KERNEL_AUTO ||
                   ((int)d->kernel >= 0 && d->kernel < SPH_KERNEL_COUNT),
               "sph_world_def.kernel = %d: not a sph_kernel_type", (int)d->kernel);
    for (k = 0; k < 3; ++k)
        SPH__CHECK(sph__finite((double)d->gravity[k]), "sph_world_def.gravity[%d] = %g: not finite",
                   k, (double)d->gravity[k]);
    SPH__CHECK((int)d->solver >= 0 && d->solver <= SPH_SOLVER_PBF,
               "sph_world_def.solver = %d: not a sph_solver", (int)d->solver);
    SPH__CHECK((int)d->boundary_pressure >= 0 && d->boundary_pressure <= SPH_BP_AUTO,
               "sph_world_def.boundary_pressure = %d: not a sph_boundary_pressure",
               (int)d->boundary_pressure);
    SPH__CHECK(d->boundary_pressure != SPH_BP_MIRROR, "sph_world_def.%s", sph__mirror_rejected);
    SPH__CHECK((int)d->boundary_volume >= 0 && d->boundary_volume <= SPH_BVOL_AUTO,
               "sph_world_def.boundary_volume = %d: not a sph_boundary_volume",
               (int)d->boundary_volume);
    SPH__CHECK(sph__finite((double)d->boundary_gamma) && d->boundary_gamma >= 0 &&
                   d->boundary_gamma <= 10,
               "sph_world_def.boundary_gamma = %g: must be 0 (calibrated) or in (0, 10]",
               (double)d->boundary_gamma);
    SPH__CHECK(sph__finite((double)d->cfl_velocity) && d->cfl_velocity > 0 && d->cfl_velocity <= 1,
               "sph_world_def.cfl_velocity = %g: must be in (0, 1]", (double)d->cfl_velocity);
    SPH__CHECK(sph__finite((double)d->max_dt) && d->max_dt >= 0,
               "sph_world_def.max_dt = %g: must be finite and >= 0 (0 = no bound)", (double)d->max_dt);
    SPH__CHECK(sph__finite((double)d->tolerance) && d->tolerance > 0 && d->tolerance < 1,
               "sph_world_def.tolerance = %g: must be in (0, 1)", (double)d->tolerance);
    SPH__CHECK(d->min_iterations >= 0 && d->min_iterations <= 100000,
               "sph_world_def.min_iterations = %d: must be in [0, 100000]", d->min_iterations);
    SPH__CHECK(d->max_iterations >= 1 && d->max_iterations <= 100000 &&
                   d->max_iterations >= d->min_iterations,
               "sph_world_def.max_iterations = %d: must be in [max(1, min_iterations), 100000]",
               d->max_iterations);
    SPH__CHECK(sph__finite((double)d->omega) && d->omega >= 0 && d->omega <= 1,
               "sph_world_def.omega = %g: must be 0 (automatic) or in (0, 1]", (double)d->omega);
    SPH__CHECK((int)d->pressure_solve >= 0 && d->pressure_solve <= SPH_PSOLVE_CG,
               "sph_world_def.pressure_solve = %d: not a sph_pressure_solve", (int)d->pressure_solve);
    SPH__CHECK(sph__finite((double)d->warm_start) && d->warm_start >= 0 && d->warm_start <= 1,
               "sph_world_def.warm_start = %g: must be in [0, 1]", (double)d->warm_start);
    SPH__CHECK(sph__finite((double)d->tolerance_max) && d->tolerance_max >= 0 && d->tolerance_max < 1,
               "sph_world_def.tolerance_max = %g: must be 0 (off) or in (0, 1)",
               (double)d->tolerance_max);
    SPH__CHECK((int)d->pcisph_factor >= 0 && d->pcisph_factor <= SPH_PCISPH_PER_PARTICLE,
               "sph_world_def.pcisph_factor = %d: not a sph_pcisph_factor", (int)d->pcisph_factor);
    SPH__CHECK(sph__finite((double)d->pcisph_gain) && d->pcisph_gain > 0 && d->pcisph_gain <= 4,
               "sph_world_def.pcisph_gain = %g: must be in (0, 4]", (double)d->pcisph_gain);
    SPH__CHECK(sph__finite((double)d->pressure_smoothing) && d->pressure_smoothing >= 0 &&
                   d->pressure_smoothing <= 1,
               "sph_world_def.pressure_smoothing = %g: must be in [0, 1]",
               (double)d->pressure_smoothing);
    SPH__CHECK(sph__finite((double)d->divergence_tolerance) && d->divergence_tolerance > 0 &&
                   d->divergence_tolerance < 1,
               "sph_world_def.divergence_tolerance = %g: must be in (0, 1)",
               (double)d->divergence_tolerance);
    SPH__CHECK(d->pbf_iterations >= 1 && d->pbf_iterations <= 1000,
               "sph_world_def.pbf_iterations = %d: must be in [1, 1000]", d->pbf_iterations);
    SPH__CHECK(sph__finite((double)d->pbf_relaxation) && d->pbf_relaxation > 0 &&
                   d->pbf_relaxation <= 100,
               "sph_world_def.pbf_relaxation = %g: must be in (0, 100]", (double)d->pbf_relaxation);
    SPH__CHECK(sph__finite((double)d->pbf_scorr) && d->pbf_scorr >= 0 && d->pbf_scorr <= 1,
               "sph_world_def.pbf_scorr = %g: must be in [0, 1]", (double)d->pbf_scorr);
    SPH__CHECK(sph__finite((double)d->pbf_xsph) && d->pbf_xsph >= 0 && d->pbf_xsph <= SPH__R(0.5),
               "sph_world_def.pbf_xsph = %g: must be in [0, 0.5]", (double)d->pbf_xsph);
    SPH__CHECK(sph__finite((double)d->pbf_compression) && d->pbf_compression > 0 &&
                   d->pbf_compression <= SPH__R(0.1),
               "sph_world_def.pbf_compression = %g: must be in (0, 0.1]",
               (double)d->pbf_compression);
    SPH__CHECK((int)d->density >= 0 && d->density <= SPH_DENSITY_PARTICLE,
               "sph_world_def.density = %d: not a sph_density", (int)d->density);
    SPH__CHECK((int)d->pressure_grad >= 0 && d->pressure_grad <= SPH_PGRAD_VOLUME,
               "sph_world_def.pressure_grad = %d: not a sph_pressure_grad", (int)d->pressure_grad);
    SPH__CHECK(d->pressure_grad != SPH_PGRAD_DIFFERENCE || d->solver == SPH_SOLVER_WCSPH,
               "sph_world_def.pressure_grad = SPH_PGRAD_DIFFERENCE: WCSPH only (solver %d)",
               (int)d->solver);
    SPH__CHECK((int)d->integrator >= 0 && d->integrator <= SPH_INTEGRATOR_VERLET,
               "sph_world_def.integrator = %d: not a sph_integrator", (int)d->integrator);
    SPH__CHECK((int)d->scheme >= 0 && d->scheme <= SPH_SCHEME_SECOND_ORDER,
               "sph_world_def.scheme = %d: not a sph_wcsph_scheme", (int)d->scheme);
    SPH__CHECK(d->shift_every >= 0, "sph_world_def.shift_every = %d: must be >= 0", d->shift_every);
    SPH__CHECK(sph__finite((double)d->shifting) && d->shifting >= 0 && d->shifting <= 10,
               "sph_world_def.shifting = %g: must be in [0, 10]", (double)d->shifting);
    SPH__CHECK(d->shifting == 0 || (d->solver == SPH_SOLVER_WCSPH &&
                                    d->scheme == SPH_SCHEME_STANDARD) ||
                   d->solver == SPH_SOLVER_IISPH || d->solver == SPH_SOLVER_DFSPH,
               "sph_world_def.shifting = %g: WCSPH with SPH_SCHEME_STANDARD, IISPH or DFSPH only "
               "(the second-order scheme shifts by def.shift_every)", (double)d->shifting);
    SPH__CHECK((int)d->clamp >= 0 && d->clamp <= SPH_CLAMP_OFF,
               "sph_world_def.clamp = %d: not a sph_pressure_clamp", (int)d->clamp);
    SPH__CHECK((int)d->viscosity_form >= 0 && d->viscosity_form <= SPH_VISC_MONAGHAN,
               "sph_world_def.viscosity_form = %d: not a sph_viscosity_form", (int)d->viscosity_form);
    SPH__CHECK((int)d->wall >= 0 && d->wall <= SPH_WALL_NO_SLIP,
               "sph_world_def.wall = %d: not a sph_wall", (int)d->wall);
    SPH__CHECK(d->wall != SPH_WALL_NO_SLIP || d->solver != SPH_SOLVER_PBF,
               "sph_world_def.wall = SPH_WALL_NO_SLIP: PBF's walls are free slip (its viscosity "
               "and XSPH smooth over fluid neighbours only); choose SPH_WALL_FREE_SLIP or another "
               "solver");
    SPH__CHECK(sph__finite((double)d->delta) && d->delta >= 0 && d->delta <= 1,
               "sph_world_def.delta = %g: must be in [0, 1]", (double)d->delta);
    SPH__CHECK(sph__finite((double)d->alpha) && d->alpha >= 0 && d->alpha <= 10,
               "sph_world_def.alpha = %g: must be in [0, 10]", (double)d->alpha);
    SPH__CHECK(sph__finite((double)d->beta) && d->beta >= 0 && d->beta <= 10,
               "sph_world_def.beta = %g: must be in [0, 10]", (double)d->beta);
    SPH__CHECK(sph__finite((double)d->cfl) && d->cfl > 0 && d->cfl <= 1,
               "sph_world_def.cfl = %g: must be in (0, 1]", (double)d->cfl);
    SPH__CHECK(sph__finite((double)d->cfl_viscous) && d->cfl_viscous > 0 && d->cfl_viscous <= 1,
               "sph_world_def.cfl_viscous = %g: must be in (0, 1]", (double)d->cfl_viscous);
    SPH__CHECK(sph__finite((double)d->cfl_force) && d->cfl_force > 0 && d->cfl_force <= 1,
               "sph_world_def.cfl_force = %g: must be in (0, 1]", (double)d->cfl_force);
    SPH__CHECK(sph__finite((double)d->max_compression) && d->max_compression >= 0,
               "sph_world_def.max_compression = %g: must be finite and >= 0",
               (double)d->max_compression);
    SPH__CHECK(sph__finite((double)d->max_speed) && d->max_speed >= 0,
               "sph_world_def.max_speed = %g: must be finite and >= 0", (double)d->max_speed);
    SPH__CHECK(sph__finite((double)d->wall_contact) && d->wall_contact >= 0 &&
                   d->wall_contact <= SPH__R(1.5),
               "sph_world_def.wall_contact = %g: must be in [0, 1.5] (spacings)",
               (double)d->wall_contact);
    SPH__CHECK(sph__finite((double)d->max_displacement) && d->max_displacement >= 0,
               "sph_world_def.max_displacement = %g: must be finite and >= 0",
               (double)d->max_displacement);
    SPH__CHECK(d->max_substeps >= 1 && d->max_substeps <= (1 << 30),
               "sph_world_def.max_substeps = %d: must be in [1, 2^30]", d->max_substeps);
    SPH__CHECK(d->neighbor_skin == -1 || (d->neighbor_skin >= 0 && d->neighbor_skin <= 1),
               "sph_world_def.neighbor_skin = %g: must be -1 (automatic) or in [0, 1] (support "
               "radii)",
               (double)d->neighbor_skin);
    for (k = 0; k < d->dim; ++k) {
        SPH__CHECK(sph__finite((double)d->domain_lo[k]) && sph__finite((double)d->domain_hi[k]) &&
                       d->domain_lo[k] <= d->domain_hi[k],
                   "sph_world_def.domain_lo/hi[%d] = %g/%g: must be finite with lo <= hi", k,
                   (double)d->domain_lo[k], (double)d->domain_hi[k]);
        if (fabs((double)d->domain_lo[k]) > sph__far_limit(d->spacing) ||
            fabs((double)d->domain_hi[k]) > sph__far_limit(d->spacing)) {
            char what[64];
            const int hi = fabs((double)d->domain_hi[k]) > sph__far_limit(d->spacing);
            snprintf(what, sizeof what, "sph_world_def.domain_%s[%d]", hi ? "hi" : "lo", k);
            return sph__fail_far(w, d->spacing, -1, what,
                                 (double)(hi ? d->domain_hi[k] : d->domain_lo[k]));
        }
    }
    return SPH_OK;
}

/* Sums over a square lattice of spacing dx around a particle at the origin (itself included),
   times dx^dim: of W(|x_j|) (SPH__LATTICE_W) or of -|x_j| dW/dr(|x_j|) (SPH__LATTICE_RDW). */
typedef enum sph__lattice_term { SPH__LATTICE_W, SPH__LATTICE_RDW } sph__lattice_term;
static double sph__lattice(const sph_kernel* k, sph_real dx, sph__lattice_term term) {
    const int R = (int)(k->radius / dx) + 1, D = k->dim;
    double sum = 0, vol = 1;
    int i, j, l;
    for (i = 0; i < D; ++i) vol *= (double)dx;
    for (i = -R; i <= R; ++i)
        for (j = (D > 1 ? -R : 0); j <= (D > 1 ? R : 0); ++j)
            for (l = (D > 2 ? -R : 0); l <= (D > 2 ? R : 0); ++l) {
                const int q = i * i + j * j + l * l;
                const double r = (double)dx * sqrt((double)q);
                sum += term == SPH__LATTICE_W
                           ? (double)sph_kernel_w(k, dx * sph__sqrt((sph_real)q))
                           : -r * (double)sph_kernel_dwdr(k, (sph_real)r);
            }
    return sum * vol;
}

/* dx^dim sum_j W(|x_j|) over a square lattice of spacing dx, the particle itself included:
   the summation density of a lattice in units of m / dx^dim (1.0105 for Wendland C2, 2D,
   h = 1.3 dx). */
static sph_real sph__lattice_sum(const sph_kernel* k, sph_real dx) {
    return (sph_real)sph__lattice(k, dx, SPH__LATTICE_W);
}

/* The first moment of the kernel gradient over a square lattice of spacing dx (the particle at
   the origin, its neighbours at x_j), -dx^dim / dim sum_j |x_j| dW/dr(|x_j|): an SPH gradient
   sum_j V_j (A_j - A_i) grad W_ij of a linear A = a . x gives this times a on the lattice (the
   moment matrix sum_j V_j (x_j - x_i) grad W_ij^T is this times the identity, by the lattice's
   symmetry). Wendland C2 at h = 1.3 dx: 0.9739 in 2D, below 1 because the lattice sum
   replaces the integral: the hydrostatic pressure that the gradient balances with gravity is
   then 2.7 % too steep (sph__ctx_init's pg_norm). */
static sph_real sph__lattice_grad(const sph_kernel* k, sph_real dx) {
    return (sph_real)(sph__lattice(k, dx, SPH__LATTICE_RDW) / k->dim);
}

/* The wall volume fraction that check_walls allows (see sph__wall_fraction): that of a particle
   half a spacing past the first layer of a flat lattice wall, 1 dx past its face (0.94 for
   Wendland C2 at h = 1.3 dx in 2D and 3D). A fluid particle stays well below it: 0.5 on a face,
   0.39 in a 2D corner half a spacing from both faces, 0.75 at a 2D corner point and 0.875 at a
   3D one; on the first layer's line the fraction is 0.79. */
static sph_real sph__wall_fraction_limit(const sph_kernel* k, sph_real dx) {
    const int R = (int)(k->radius / dx) + 2, D = k->dim;
    double sum = 0, vol = 1;
    int i, j, l;
    for (i = 0; i < D; ++i) vol *= (double)dx;
    /* the particle at the origin; the wall's layers at x = 0.5, -0.5, -1.5 ... spacings, the
       lattice along the wall offset by half a spacing */
    for (i = -R; i <= 0; ++i)
        for (j = (D > 1 ? -R : 0); j <= (D > 1 ? R : 0); ++j)
            for (l = (D > 2 ? -R : 0); l <= (D > 2 ? R : 0); ++l) {
                const double x = (i + 0.5) * (double)dx, y = D > 1 ? (j + 0.5) * (double)dx : 0,
                             z = D > 2 ? (l + 0.5) * (double)dx : 0;
                sum += (double)sph_kernel_w(k, (sph_real)sqrt(x * x + y * y + z * z));
            }
    return (sph_real)(sum * vol);
}

/* The Akinci volume factor gamma_1 that makes a flat single layer of wall particles at spacing
   dx stand in for the wall's half space: a fluid particle in the first row of a lattice, 1 dx
   from the layer (where sph_fill_box and a host's lattice put it), then sums to the rest
   density,
       F + gamma V_1 sum_b W_ib = S,   V_1 = S / sum_b' W_bb'  (gamma = 1's volume),
   F the fluid half lattice's sum (its own row included), S the full lattice's, sums over the
   layer's particles in the plane (line in 2D) 1 dx away and within the layer. With gamma = 1
   (Akinci et al. 2012's volumes as they stand) that layer weighs 1.7 half spaces for Wendland
   C2 at h = 1.3 dx: the fluid beside a single layer started 15 % compressed (24 % at a corner
   of host-placed walls), which IISPH, DFSPH and the original PCISPH refused at their first step
   (max_compression) and, allowed to run, turned into kinetic energy (a tilted tank dam break,
   dx 0.02: energy rise 12-49 % of M g H). Values: 0.585 (2D) and 0.587 (3D) for Wendland C2 at
   h = 1.3 dx, 0.68 / 0.70 for the cubic B-spline at h = dx. */
static sph_real sph__akinci_gamma(const sph_kernel* k, sph_real dx) {
    const int R = (int)(k->radius / dx) + 1, D = k->dim;
    double full = 0, half = 0, line = 0, wall = 0;
    int i, j, l;
    for (i = -R; i <= R; ++i) /* i: the direction normal to the layer */
        for (j = (D > 1 ? -R : 0); j <= (D > 1 ? R : 0); ++j)
            for (l = (D > 2 ? -R : 0); l <= (D > 2 ? R : 0); ++l) {
                const double r = sqrt((double)(i * i + j * j + l * l)) * (double)dx;
                const double W = (double)sph_kernel_w(k, (sph_real)r);
                full += W;
                if (i >= 0) half += W;
                if (i == 0) line += W;
                if (i == -1) wall += W;
            }
    /* (S - F) / (V_1 sum W_ib) with V_1 = S / line: the lattice volume dx^dim cancels */
    return wall > 0 ? (sph_real)((full - half) * line / (full * wall)) : 1;
}

/* The wall contact's ramp in 3D (sph__wall_contact), from two neighbour counts on the lattice
   of the world's kernel, as fractions of a full neighbourhood (full_count): a one-particle sheet
   over the hollows of a single wall layer, 0.5 dx above it (what the contact is for: "short" is
   0.15 above its count), and a surface particle of a resting fluid beside a wall of ceil(R)
   layers, 0.6 dx from the first ("full" is 0.04 above its count, so such a particle rests at
   contact 0.68 dx and a particle with fluid on all sides at 0.6 dx). Wendland C2 at h = 1.3 dx
   (support R = 2.6 dx, 80 lattice neighbours): sheet 0.55, surface particle 0.81, so the ramp
   runs from 0.70 to 0.85, the thresholds measured for it on the 3D tank at rest (see
   sph__wall_contact); the cubic B-spline at h = dx (R = 2 dx, 26): 0.77 and 0.96, a ramp from
   0.85 to 1.0 (fixed fractions 0.7 and 0.85 let its sheet sink 0.19 dx past the face). */
static void sph__contact_ramp(sph_world* w) {
    const double R = (double)(w->kernel.radius / w->dx), R2 = R * R;
    const int M = (int)R + 2, L = (int)ceil(R);
    double sheet = 0, top = 0, full = (double)w->priv.full_count;
    int i, j, k;
    for (i = -M; i <= M; ++i)
        for (k = -M; k <= M; ++k) {
            /* the sheet particle at (0.5, 0.5, 0.5): its sheet and the layer at y = 0 */
            double d2 = (double)(i * i + k * k);
            if (d2 > 0 && d2 < R2) sheet += 1;
            d2 = (i - 0.5) * (i - 0.5) + 0.25 + (k - 0.5) * (k - 0.5);
            if (d2 < R2) sheet += 1;
            /* the surface particle at (0.1, 0, 0): fluid at x >= 0.1, y <= 0; wall at x <= -0.5 */
            for (j = 0; j <= M; ++j) {
                d2 = (double)(i * i + j * j + k * k);
                if (i >= 0 && d2 > 0 && d2 < R2) top += 1;
            }
            if (i < L) /* i is the wall layer here, k along it, j up and down */
                for (j = -M; j <= M; ++j) {
                    d2 = (0.6 + i) * (0.6 + i) + (double)(j * j + k * k);
                    if (i >= 0 && d2 < R2) top += 1;
                }
        }
    if (!(full > 0)) full = 1;
    { /* sph__wall_thin: a lattice plane's kernel sum and a half space's (the plane included) */
        double plane = 0, half = 0;
        for (i = -M; i <= M; ++i)
            for (k = (w->dim > 2 ? -M : 0); k <= (w->dim > 2 ? M : 0); ++k)
                for (j = -M; j <= 0; ++j) {
                    const double q = sqrt((double)(i * i + j * j + k * k)) * (double)w->dx /
                                     (double)w->kernel.h;
                    const double kw = (double)sph__kw(w->kernel.form, (sph_real)q);
                    half += kw;
                    if (j == 0) plane += kw;
                }
        w->priv.thin_sum = 0.5 * (plane + half);
    }
    w->priv.contact_full = (sph_real)(top / full + 0.04);
    w->priv.contact_short = (sph_real)fmin(sheet / full + 0.15, top / full + 0.04 - 0.15);
}

/* Whether def asks for PCISPH with none of the settings sph_world_def_pcisph makes: every one of
   them still as sph_world_def_default left it (a host that only set def.solver). That mix, WCSPH's
   continuity density with delta-SPH in a PCISPH solve with the prototype factor and a 0.1 %
   tolerance, is neither solver of the literature, and it failed where both presets hold (2D dam
   break, a 0.4 x 0.8 m column in a 1.6 x 1 m tank, dx 0.02, sph_advance in 0.02 s frames: failed
   at 1.14 s; in SPH_FLOAT at 1.26 s after a frame that gained 1.53 M g H of energy and returned
   SPH_OK). sph_world_init then gives it the original solver's settings, sph_world_def_pcisph(def,
   0) (Solenthaler & Pajarola 2009), which ran those scenes clean. */
static int sph__pcisph_unset(const sph_world_def* def) {
    const sph_world_def d = sph_world_def_default(def->dim);
    return def->solver == SPH_SOLVER_PCISPH && def->density == d.density &&
           def->integrator == d.integrator && def->pcisph_factor == d.pcisph_factor &&
           def->pressure_grad == d.pressure_grad && def->boundary_pressure == d.boundary_pressure &&
           def->min_iterations == d.min_iterations && def->tolerance == d.tolerance &&
           def->warm_start == d.warm_start && def->delta == d.delta &&
           def->pressure_smoothing == d.pressure_smoothing;
}

SPHDEF sph_status sph_world_init(sph_world* w, const sph_world_def* def) {
    sph_status s;
    sph_real hf, lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    int k, per[3] = {0, 0, 0};
    if (!w) return SPH_ERR_ARG;
    memset(w, 0, sizeof(*w));
    w->error_index = -1;
    if (!def) return sph__fail(w, SPH_ERR_ARG, -1, "sph_world_init: def is NULL");
    s = sph__validate_def(w, def);
    if (s != SPH_OK) return s;
    w->def = *def;
    for (k = def->dim; k < 3; ++k) {
        w->def.gravity[k] = 0;
        w->def.periodic[k] = 0;
        w->def.domain_lo[k] = w->def.domain_hi[k] = 0;
    }
    w->dim = def->dim;
    w->dx = def->spacing;
    w->priv.solver = (int)def->solver; /* until a step says which solver runs */
    if (sph__pcisph_unset(def)) sph_world_def_pcisph(&w->def, 0);
    if (w->def.boundary_pressure == SPH_BP_AUTO)
        w->def.boundary_pressure = def->solver == SPH_SOLVER_IISPH || def->solver == SPH_SOLVER_DFSPH ||
                                           def->solver == SPH_SOLVER_PBF
                                       ? SPH_BP_ZERO
                                       : SPH_BP_EXTRAPOLATE;
    /* the automatic kernel (sph_world_def.kernel): the cubic B-spline at h = dx, SPlisHSPlasH's
       support of 2 dx, where it was measured better (README, "The kernel in 3D") */
    if (def->kernel == SPH_KERNEL_AUTO) {
        const int cubic = def->dim == 3 && w->def.boundary_pressure == SPH_BP_ZERO &&
                          (def->solver == SPH_SOLVER_IISPH || def->solver == SPH_SOLVER_DFSPH ||
                           def->solver == SPH_SOLVER_PBF);
        w->def.kernel = cubic ? SPH_KERNEL_CUBIC : SPH_KERNEL_WENDLAND_C2;
        hf = def->h_factor > 0 ? def->h_factor
             : cubic           ? 1
                               : sph_kernel_default_h_factor(w->def.kernel);
    } else {
        hf = def->h_factor > 0 ? def->h_factor : sph_kernel_default_h_factor(def->kernel);
    }
    w->def.h_factor = hf;
    w->h = hf * def->spacing;
    s = sph_kernel_init(&w->kernel, w->def.kernel, def->dim, w->h);
    if (s != SPH_OK) /* the type and dim are valid: h is out of sph_real's reach */
        return sph__fail(w, s, -1,
                         "sph_world_def.spacing = %g: h = %g m gives kernel constants that are "
                         "not finite and > 0 in sph_real", (double)def->spacing, (double)w->h);
    w->priv.lattice_sum = sph__lattice_sum(&w->kernel, w->dx);
    w->priv.lattice_grad = sph__lattice_grad(&w->kernel, w->dx);
    w->priv.wall_fraction_max = sph__wall_fraction_limit(&w->kernel, w->dx) / w->priv.lattice_sum;
    if (def->boundary_gamma == 0) w->def.boundary_gamma = sph__akinci_gamma(&w->kernel, w->dx);
    {
        const int R = (int)(w->kernel.radius / w->dx) + 1, D = def->dim;
        int i, j, l;
        w->priv.full_count = 0;
        for (i = -R; i <= R; ++i)
            for (j = (D > 1 ? -R : 0); j <= (D > 1 ? R : 0); ++j)
                for (l = (D > 2 ? -R : 0); l <= (D > 2 ? R : 0); ++l)
                    if ((i || j || l) &&
                        w->dx * sph__sqrt((sph_real)(i * i + j * j + l * l)) < w->kernel.radius)
                        ++w->priv.full_count;
    }
    if (w->priv.full_count == 0) /* PCISPH's factor was 1/0 and its first pressure NaN */
        return sph__fail(w, SPH_ERR_ARG, -1,
                         "sph_world_def.h_factor = %g: the kernel's support (radius %g m) holds "
                         "no neighbour of a lattice at def.spacing = %g m, so every particle is "
                         "alone; h_factor must be above %g for this kernel",
                         (double)hf, (double)w->kernel.radius, (double)def->spacing,
                         (double)(hf * def->spacing / w->kernel.radius));
    sph__contact_ramp(w);
    /* the automatic Jacobi weight (sph_world_def.omega): lambda_max of D^-1 A grows with the
       neighbourhood (2.6 with 20 neighbours, 5.4-5.7 with 72 once disordered), and relaxed
       Jacobi needs omega lambda_max < 2 */
    if (def->omega == 0) w->def.omega = w->priv.full_count > 50 ? SPH__R(0.3) : SPH__R(0.5);
    for (k = 0; k < def->dim; ++k) {
        per[k] = def->periodic[k] != 0;
        lo[k] = def->domain_lo[k];
        hi[k] = def->domain_hi[k];
        if (per[k] && (!(hi[k] - lo[k] >= 2 * w->kernel.radius) ||
                       !sph__finite((double)(hi[k] - lo[k]))))
            return sph__fail(w, SPH_ERR_ARG, -1,
                             "sph_world_def.periodic[%d]: domain length %g must be finite and at "
                             "least two kernel support radii (%g)",
                             k, (double)(hi[k] - lo[k]), (double)(2 * w->kernel.radius));
    }
    s = sph_grid_init(&w->priv.grid, def->dim, w->kernel.radius, per, lo, hi);
    if (s == SPH_OK) s = sph_grid_init(&w->priv.bgrid, def->dim, w->kernel.radius, per, lo, hi);
    if (s != SPH_OK) return sph__fail(w, s, -1, "sph_world_init: grid setup failed");
    w->status = SPH_OK;
    return SPH_OK;
}

typedef struct sph__array {
    void** ptr;
    size_t elem;
    int persistent;
} sph__array;

static int sph__fluid_arrays(sph_world* w, sph__array* a);
static int sph__boundary_arrays(sph_world* w, sph__array* a);

SPHDEF void sph_world_free(sph_world* w) {
    struct sph__array arr[16];
    int k, n;
    if (!w) return;
    /* the particle arrays through the same lists that grow and reorder them */
    n = sph__fluid_arrays(w, arr);
    for (k = 0; k < n; ++k) SPH_FREE(*arr[k].ptr);
    n = sph__boundary_arrays(w, arr);
    for (k = 0; k < n; ++k) SPH_FREE(*arr[k].ptr);
    sph_grid_free(&w->priv.grid);
    sph_grid_free(&w->priv.bgrid);
    SPH_FREE(w->priv.b_near);
    sph_neighbors_free(&w->priv.ff);
    sph_neighbors_free(&w->priv.fb);
    sph_neighbors_free(&w->priv.bf);
    sph_neighbors_free(&w->priv.bb);
    sph_neighbors_free(&w->priv.cff);
    sph_neighbors_free(&w->priv.cfb);
    sph_neighbors_free(&w->priv.cbf);
    sph_neighbors_free(&w->priv.ffh);
    SPH_FREE(w->priv.vl_x);
    SPH_FREE(w->priv.vl_bx);
    SPH_FREE(w->priv.perm_buf);
    SPH_FREE(w->priv.block);
    SPH_FREE(w->priv.rho_n);
    SPH_FREE(w->priv.aii);
    SPH_FREE(w->priv.cg);
    SPH_FREE(w->priv.src);
    SPH_FREE(w->priv.ap);
    SPH_FREE(w->priv.df_alpha);
    SPH_FREE(w->priv.df_alpha_v);
    SPH_FREE(w->priv.df_vs);
    SPH_FREE(w->priv.df_kv);
    SPH_FREE(w->priv.df_pv);
    SPH_FREE(w->priv.ff_fw);
    SPH_FREE(w->priv.fb_fw);
    SPH_FREE(w->priv.pr2);
    SPH_FREE(w->priv.vol);
    SPH_FREE(w->priv.shift);
    SPH_FREE(w->priv.xp);
    SPH_FREE(w->priv.vp);
    SPH_FREE(w->priv.xs);
    SPH_FREE(w->priv.de);
    SPH_FREE(w->priv.cs);
    SPH_FREE(w->priv.vn);
    SPH_FREE(w->priv.bpq);
    SPH_FREE(w->priv.soc);
    SPH_FREE(w->priv.socw);
    SPH_FREE(w->priv.lapc);
    SPH_FREE(w->priv.wg);
    SPH_FREE(w->priv.abody);
    SPH_FREE(w->priv.snap[0]);
    SPH_FREE(w->priv.snap[1]);
    sph_grid_free(&w->priv.sgrid);
    sph_neighbors_free(&w->priv.snl);
    memset(w, 0, sizeof(*w));
    w->error_index = -1;
}

SPHDEF const char* sph_world_error(const sph_world* w) { return w ? w->error : ""; }

/* The per-particle arrays, listed once so that growing and reordering cannot forget one.
   persistent arrays carry state from step to step and follow the particles when they are sorted;
   the others are recomputed inside every step. */

static int sph__fluid_arrays(sph_world* w, sph__array* a) {
    const size_t vec = (size_t)w->dim * sizeof(sph_real), r = sizeof(sph_real);
    int n = 0;
    a[n].ptr = (void**)&w->x; a[n].elem = vec; a[n++].persistent = 1;
    a[n].ptr = (void**)&w->v; a[n].elem = vec; a[n++].persistent = 1;
    a[n].ptr = (void**)&w->rho; a[n].elem = r; a[n++].persistent = 1;
    a[n].ptr = (void**)&w->p; a[n].elem = r; a[n++].persistent = 1;
    a[n].ptr = (void**)&w->id; a[n].elem = sizeof(uint32_t); a[n++].persistent = 1;
    a[n].ptr = (void**)&w->phase; a[n].elem = sizeof(uint8_t); a[n++].persistent = 1;
    a[n].ptr = (void**)&w->drho; a[n].elem = r; a[n++].persistent = 1; /* Verlet keeps it */
    a[n].ptr = (void**)&w->a; a[n].elem = vec; a[n++].persistent = 0;
    if (w->m) { a[n].ptr = (void**)&w->m; a[n].elem = r; a[n++].persistent = 1; }
    if (w->priv.has_energy) { a[n].ptr = (void**)&w->e; a[n].elem = r; a[n++].persistent = 1; }
    return n;
}

static int sph__boundary_arrays(sph_world* w, sph__array* a) {
    const size_t vec = (size_t)w->dim * sizeof(sph_real), r = sizeof(sph_real);
    int n = 0;
    a[n].ptr = (void**)&w->b_x; a[n].elem = vec; a[n++].persistent = 1;
    a[n].ptr = (void**)&w->b_v; a[n].elem = vec; a[n++].persistent = 1;
    a[n].ptr = (void**)&w->b_a; a[n].elem = vec; a[n++].persistent = 1;
    a[n].ptr = (void**)&w->b_x0; a[n].elem = vec; a[n++].persistent = 1;
    a[n].ptr = (void**)&w->b_vol; a[n].elem = r; a[n++].persistent = 1;
    a[n].ptr = (void**)&w->b_id; a[n].elem = sizeof(uint32_t); a[n++].persistent = 1;
    a[n].ptr = (void**)&w->b_body; a[n].elem = sizeof(uint16_t); a[n++].persistent = 1;
    a[n].ptr = (void**)&w->b_p; a[n].elem = r; a[n++].persistent = 0;
    a[n].ptr = (void**)&w->b_rho; a[n].elem = r; a[n++].persistent = 0;
    a[n].ptr = (void**)&w->b_vw; a[n].elem = vec; a[n++].persistent = 0;
    a[n].ptr = (void**)&w->priv.b_sw; a[n].elem = r; a[n++].persistent = 0;
    a[n].ptr = (void**)&w->priv.b_thin; a[n].elem = sizeof(uint8_t); a[n++].persistent = 0;
    return n;
}

/* Room for `need` particles in every array of the set; the permutation buffer grows with it. */
static sph_status sph__reserve(sph_world* w, int boundary, size_t need) {
    sph__array arr[16];
    size_t* cap = boundary ? &w->b_capacity : &w->capacity;
    size_t newcap, bytes;
    int n, k;
    if (need <= *cap) return SPH_OK;
    if (need > (size_t)UINT32_MAX - 1)
        return sph__fail(w, SPH_ERR_CAPACITY, -1, "%zu particles exceed the limit of %u", need,
                         (unsigned)(UINT32_MAX - 1));
    newcap = *cap + *cap / 2 + 64;
    if (newcap < need) newcap = need;
    n = boundary ? sph__boundary_arrays(w, arr) : sph__fluid_arrays(w, arr);
    /* each array grows on its own: after a failure the grown ones are merely larger than needed */
    for (k = 0; k < n; ++k)
        if (!sph__grow(arr[k].ptr, newcap, arr[k].elem))
            return sph__fail(w, SPH_ERR_NOMEM, -1, "out of memory growing to %zu particles", newcap);
    bytes = newcap * (size_t)w->dim * sizeof(sph_real);
    if (bytes > w->priv.perm_cap) {
        if (!sph__grow((void**)&w->priv.perm_buf, bytes, 1))
            return sph__fail(w, SPH_ERR_NOMEM, -1, "out of memory growing to %zu particles", newcap);
        w->priv.perm_cap = bytes;
    }
    *cap = newcap;
    return SPH_OK;
}

static int sph__check_phase(sph_world* w, const char* fn, int phase) {
    if (phase < 0 || phase >= w->nphase) {
        sph__fail(w, SPH_ERR_ARG, -1, "%s: phase %d does not exist (the world has %d phases)", fn,
                  phase, w->nphase);
        return 0;
    }
    return 1;
}

/* p_inf of a stiffened gas (0 for the other equations of state) [Pa]. */
static sph_real sph__pinf(const sph_phase* P) {
    if (P->eos != SPH_EOS_STIFFENED_GAS) return 0;
    return P->rest_density * P->sound_speed * P->sound_speed / P->gamma - P->back_pressure;
}

/* The specific internal energy [J/kg] of a gas at pressure p and density rho, from
   p = (gamma - 1) rho e - gamma p_inf: e = (p + gamma p_inf) / (gamma - 1) / rho. Divided in this
   order, in double, so that a gas at zero pressure (dust) has e = 0 even at a density whose
   product with (gamma - 1) underflows to 0 (which would give 0/0). */
static sph_real sph__gas_energy(sph_real p, sph_real gamma, sph_real pinf, sph_real rho) {
    return (sph_real)(((double)p + (double)gamma * (double)pinf) / ((double)gamma - 1) / (double)rho);
}

/* The rules for a phase, shared by sph_world_add_phase and the loader. Fills in the defaults
   (gamma, the ideal gas's sound speed, the mass) of a phase as given; a saved phase (`saved`) has
   them filled in already, so its gamma and mass must be set and an ideal gas's sound speed must
   be the one that follows from its other fields. SPH_ERR_ARG naming the first bad field. */
static sph_status sph__check_phase_fields(sph_world* w, sph_phase* ph, int saved) {
    double vol;
    int gas;
#define SPH__PCHECK(cond, ...)                                                                     \
    do { if (!(cond)) return sph__fail(w, SPH_ERR_ARG, -1, __VA_ARGS__); } while (0)
    SPH__PCHECK(sph__finite((double)ph->rest_density) && ph->rest_density > 0,
                "sph_phase.rest_density = %g: must be finite and > 0", (double)ph->rest_density);
    SPH__PCHECK(sph__finite((double)ph->viscosity) && ph->viscosity >= 0,
                "sph_phase.viscosity = %g: must be finite and >= 0", (double)ph->viscosity);
    SPH__PCHECK(sph__finite((double)ph->sound_speed) && ph->sound_speed >= 0,
                "sph_phase.sound_speed = %g: must be finite and >= 0 (0 = automatic)",
                (double)ph->sound_speed);
    SPH__PCHECK((int)ph->eos >= 0 && ph->eos <= SPH_EOS_STIFFENED_GAS,
                "sph_phase.eos = %d: not a sph_eos", (int)ph->eos);
    gas = ph->eos == SPH_EOS_IDEAL_GAS || ph->eos == SPH_EOS_STIFFENED_GAS;
    SPH__PCHECK(sph__finite((double)ph->gamma) &&
                    (ph->gamma == 0 || (ph->gamma >= 1 && ph->gamma <= 20)),
                "sph_phase.gamma = %g: must be 0 (default) or in [1, 20]", (double)ph->gamma);
    SPH__PCHECK(!saved || ph->gamma != 0, "sph_phase.gamma = 0: a saved phase has its gamma");
    SPH__PCHECK(!gas || ph->gamma != 1,
                "sph_phase.gamma = 1: a gas equation of state needs gamma > 1");
    SPH__PCHECK(sph__finite((double)ph->back_pressure), "sph_phase.back_pressure = %g: not finite",
                (double)ph->back_pressure);
    SPH__PCHECK(sph__finite((double)ph->mass) && ph->mass >= 0,
                "sph_phase.mass = %g: must be finite and >= 0 (0 = rest_density * dx^dim)",
                (double)ph->mass);
    SPH__PCHECK(!saved || ph->mass > 0, "sph_phase.mass = 0: a saved phase has its mass");
    if (ph->gamma == 0)
        ph->gamma = ph->eos == SPH_EOS_IDEAL_GAS       ? SPH__R(1.4)
                    : ph->eos == SPH_EOS_STIFFENED_GAS ? SPH__R(4.4)
                                                       : 7;
    if (ph->eos == SPH_EOS_IDEAL_GAS) {
        const double c =
            sqrt((double)ph->gamma * (double)ph->back_pressure / (double)ph->rest_density);
        SPH__PCHECK(ph->back_pressure >= 0,
                    "sph_phase.back_pressure = %g: an ideal gas needs a pressure >= 0 (0: dust)",
                    (double)ph->back_pressure);
        SPH__PCHECK(saved ? ph->sound_speed == (sph_real)c : ph->sound_speed == 0,
                    "sph_phase.sound_speed = %g: an ideal gas's sound speed follows from gamma, "
                    "back_pressure and rest_density (here %g m/s); leave it 0",
                    (double)ph->sound_speed, c);
        SPH__PCHECK(sph__finite((double)(sph_real)c),
                    "sph_phase: an ideal gas's sound speed sqrt(gamma back_pressure / "
                    "rest_density) = sqrt(%g * %g / %g) is not finite (in sph_real)",
                    (double)ph->gamma, (double)ph->back_pressure, (double)ph->rest_density);
        ph->sound_speed = (sph_real)c;
    }
    if (ph->eos == SPH_EOS_STIFFENED_GAS) {
        SPH__PCHECK(ph->sound_speed > 0,
                    "sph_phase.sound_speed = 0: a stiffened gas needs its sound speed at rest "
                    "density (it sets p_inf)");
        SPH__PCHECK(sph__finite((double)sph__pinf(ph)),
                    "sph_phase: a stiffened gas's p_inf = rho0 c0^2 / gamma - back_pressure = "
                    "%g * %g^2 / %g - %g Pa is not finite (in sph_real)",
                    (double)ph->rest_density, (double)ph->sound_speed, (double)ph->gamma,
                    (double)ph->back_pressure);
        SPH__PCHECK(sph__pinf(ph) >= 0,
                    "sph_phase: a stiffened gas with rho0 c0^2 / gamma = %g Pa below its "
                    "back_pressure %g Pa would have p_inf < 0; raise sound_speed or use an ideal gas",
                    (double)(ph->rest_density * ph->sound_speed * ph->sound_speed / ph->gamma),
                    (double)ph->back_pressure);
    }
    SPH__PCHECK(!gas || sph__finite((double)sph__gas_energy(ph->back_pressure, ph->gamma,
                                                             sph__pinf(ph), ph->rest_density)),
                "sph_phase: a gas's internal energy at rest (back_pressure + gamma p_inf) / "
                "((gamma - 1) rest_density) is not finite (in sph_real) with gamma %g and "
                "rest_density %g", (double)ph->gamma, (double)ph->rest_density);
    vol = (double)w->dx;
    if (w->dim >= 2) vol *= (double)w->dx;
    if (w->dim >= 3) vol *= (double)w->dx;
    if (ph->mass == 0) ph->mass = (sph_real)((double)ph->rest_density * vol);
    /* rest_density * dx^dim can leave sph_real (a denormal float density or spacing) */
    SPH__PCHECK(sph__finite((double)ph->mass) && ph->mass > 0,
                "sph_phase: the particle mass rest_density * dx^dim = %g is not finite and > 0 in "
                "sph_real; set sph_phase.mass", (double)ph->rest_density * vol);
#undef SPH__PCHECK
    return SPH_OK;
}

SPHDEF int sph_world_add_phase(sph_world* w, const sph_phase* phase) {
    sph_phase ph;
    int gas;
    if (!w) return -1;
    if (!phase) { sph__fail(w, SPH_ERR_ARG, -1, "sph_world_add_phase: phase is NULL"); return -1; }
    if (w->nphase >= SPH_MAX_PHASES) {
        sph__fail(w, SPH_ERR_CAPACITY, -1, "sph_world_add_phase: a world holds at most %d phases",
                  SPH_MAX_PHASES);
        return -1;
    }
    ph = *phase;
    if (sph__check_phase_fields(w, &ph, 0) != SPH_OK) return -1;
    gas = ph.eos == SPH_EOS_IDEAL_GAS || ph.eos == SPH_EOS_STIFFENED_GAS;
    if (gas && !w->priv.has_energy) { /* the internal energy array, from now on */
        size_t i;
        if (!sph__grow((void**)&w->e, w->capacity, sizeof(sph_real))) {
            sph__fail(w, SPH_ERR_NOMEM, -1, "sph_world_add_phase: out of memory for the internal energy array");
            return -1;
        }
        for (i = 0; i < w->n; ++i) w->e[i] = 0;
        w->priv.has_energy = 1;
    }
    w->phases[w->nphase] = ph;
    return w->nphase++;
}

/* Appends n fluid particles of one phase and mass; x, v (NULL = 0) are validated by the caller. */
static sph_real sph__eos_phase(const sph_phase* P, sph_real rho);

/* Appends n fluid particles of one phase with the mass `mass` (or masses m[i]) and the rest
   density (or densities rho[i]); x, v (NULL = 0), m and rho are validated by the caller. A gas
   starts at its back pressure: e = (p_b + gamma p_inf) / ((gamma - 1) rho). */
/* The tank check (check_walls, sph__integrate_with): a world with exactly one closed box of
   sph_add_wall_box, whose walls no callback moves, fails a step that ends with a fluid particle
   more than a spacing past one of the box's faces (half a spacing past the centres of its first
   layer: through the wall), naming it, whatever the walls' volumes are. The wall volume fraction
   covers lattice walls of given volumes only (SPH_BVOL_AKINCI's single layers weigh as a full
   wall), and without it a particle that went through a box with Akinci volumes fell on
   unreported until its speed passed the bound 1.4 s later, 10 m below the floor (3D, a water
   block sliding down a single-layer ramp into the box, original PCISPH and PBF). Fluid a host
   places outside the box turns the check off: there the box is not the fluid's container. */
static int sph__tank_outside(const sph_world* w, const sph_real* x) {
    int k;
    for (k = 0; k < w->dim; ++k)
        if (!w->def.periodic[k] && (x[k] < w->priv.tank_lo[k] - w->dx || x[k] > w->priv.tank_hi[k] + w->dx))
            return 1;
    return 0;
}

/* Fluid particles from index first on were added: any outside the tank turns the check off. */
static void sph__tank_note(sph_world* w, size_t first) {
    size_t i;
    if (w->priv.tanks != 1) return;
    for (i = first; i < w->n; ++i)
        if (sph__tank_outside(w, w->x + i * (size_t)w->dim)) {
            w->priv.tanks = -1;
            return;
        }
}

static sph_status sph__append_fluid(sph_world* w, int phase, size_t n, const sph_real* x,
                                    const sph_real* v, sph_real mass, const sph_real* m_in,
                                    const sph_real* rho_in) {
    const size_t dim = (size_t)w->dim;
    const sph_phase* P = &w->phases[phase];
    const int gas = P->eos == SPH_EOS_IDEAL_GAS || P->eos == SPH_EOS_STIFFENED_GAS;
    size_t i, base = w->n;
    sph_status s;
    int need_m = 0;
    if (m_in && !w->priv.have_mass && n > 0) mass = m_in[0];
    for (i = 0; m_in && i < n; ++i)
        if (m_in[i] != mass) need_m = 1;
    need_m = w->m == NULL && (need_m || (w->priv.have_mass && mass != w->mass));
    s = sph__reserve(w, 0, w->n + n);
    if (s != SPH_OK) return s;
    if (need_m) { /* particles of different masses: keep a mass per particle from now on */
        sph_real* m = NULL;
        if (!sph__grow((void**)&m, w->capacity, sizeof(sph_real)))
            return sph__fail(w, SPH_ERR_NOMEM, -1, "out of memory for the mass array");
        for (i = 0; i < w->n; ++i) m[i] = w->mass;
        w->m = m;
    }
    for (i = 0; i < n; ++i) {
        size_t j = base + i, k;
        for (k = 0; k < dim; ++k) {
            w->x[j * dim + k] = x[i * dim + k];
            w->v[j * dim + k] = v ? v[i * dim + k] : 0;
            w->a[j * dim + k] = 0;
        }
        w->rho[j] = rho_in ? rho_in[i] : P->rest_density;
        w->p[j] = gas || !rho_in ? P->back_pressure : sph__eos_phase(P, w->rho[j]);
        w->drho[j] = 0;
        if (w->e)
            w->e[j] = gas ? sph__gas_energy(P->back_pressure, P->gamma, sph__pinf(P), w->rho[j]) : 0;
        w->id[j] = w->next_id++;
        w->phase[j] = (uint8_t)phase;
        if (w->m) w->m[j] = m_in ? m_in[i] : mass;
    }
    if (!w->priv.have_mass) { w->priv.have_mass = 1; w->mass = mass; }
    w->n += n;
    if (!w->priv.placed || base < w->priv.placed_from) w->priv.placed_from = base;
    w->priv.placed = 1;
    w->priv.placed_c0 = 1;
    sph__tank_note(w, base);
    return SPH_OK;
}

static int sph__all_finite(const sph_real* a, size_t count, size_t* bad) {
    size_t i;
    for (i = 0; i < count; ++i)
        if (!sph__finite((double)a[i])) { *bad = i; return 0; }
    return 1;
}

/* A position beyond the far limit (sph__far_limit) among n particles of dimension dim: the
   message names the caller, the particle and the component. */
static sph_status sph__check_far(sph_world* w, const char* fn, const char* kind, size_t n,
                                 const sph_real* x) {
    const size_t dim = (size_t)w->dim, bad = sph__first_far(x, n * dim, sph__far_limit(w->dx));
    char what[96];
    if (bad == n * dim) return SPH_OK;
    snprintf(what, sizeof what, "%s: %sparticle %zu at x[%zu]", fn, kind, bad / dim, bad % dim);
    return sph__fail_far(w, w->dx, (long)(bad / dim), what, (double)x[bad]);
}

/* The rules for fluid particles, shared by both ways of adding fluid and by the loader; fn
   names the caller in the message. m and rho may be NULL (not given). */
static sph_status sph__check_fluid(sph_world* w, const char* fn, size_t n, const sph_real* x,
                                   const sph_real* v, const sph_real* m, const sph_real* rho) {
    size_t bad = 0, dim = (size_t)w->dim;
    sph_status s;
    if (n == 0) return SPH_OK;
    if (!x) return sph__fail(w, SPH_ERR_ARG, -1, "%s: x is NULL", fn);
    if (!sph__all_finite(x, n * dim, &bad))
        return sph__fail(w, SPH_ERR_ARG, (long)(bad / dim),
                         "%s: x of particle %zu is not finite (%g)", fn, bad / dim, (double)x[bad]);
    if ((s = sph__check_far(w, fn, "", n, x)) != SPH_OK) return s;
    if (v && !sph__all_finite(v, n * dim, &bad))
        return sph__fail(w, SPH_ERR_ARG, (long)(bad / dim),
                         "%s: v of particle %zu is not finite (%g)", fn, bad / dim, (double)v[bad]);
    for (bad = 0; m && bad < n; ++bad)
        if (!sph__finite((double)m[bad]) || !(m[bad] > 0))
            return sph__fail(w, SPH_ERR_ARG, (long)bad,
                             "%s: mass of particle %zu is %g: must be finite and > 0", fn, bad,
                             (double)m[bad]);
    for (bad = 0; rho && bad < n; ++bad)
        if (!sph__finite((double)rho[bad]) || !(rho[bad] > 0))
            return sph__fail(w, SPH_ERR_ARG, (long)bad,
                             "%s: density of particle %zu is %g: must be finite and > 0", fn, bad,
                             (double)rho[bad]);
    return SPH_OK;
}

/* Fluid particles added where others already are (within SPH__COINCIDENT spacings: the same
   box filled twice, an array with a particle twice). Coincident particles never separate: each
   pair's kernel gradient is zero, so they move as one particle of twice the mass (WCSPH ran a
   box filled twice for 2 s at twice the weight without a sign; IISPH and DFSPH threw its
   particles at 60 m/s). Not coincident but close, as an emitter's particles landing between
   others, is left to the solvers. The new particles are hashed by cell (side dx); each old and
   new particle looks in its own cell and, within the distance of a face, the next: O(n + m)
   time, 2m + 2^k indices of memory for the call. */
#define SPH__COINCIDENT 1e-3
typedef enum sph__points { SPH__POINTS_ANY, SPH__POINTS_DISTINCT } sph__points;
static int sph__in_box(const sph_real* x, size_t dim, const double* lo, const double* hi) {
    size_t k;
    for (k = 0; k < dim; ++k) /* a NaN a host wrote into w.x is outside */
        if (!((double)x[k] >= lo[k] && (double)x[k] <= hi[k])) return 0;
    return 1;
}
static sph_status sph__check_coincident(sph_world* w, const char* fn, size_t m, const sph_real* x,
                                        sph__points given) {
    const size_t dim = (size_t)w->dim, n = w->n;
    const double inv = 1 / (double)w->dx, eps = SPH__COINCIDENT;
    double blo[3], bhi[3];
    size_t nh = 16, i, k, *head, *next, found_a = 0, found_b = 0, inside = 0;
    int found = 0;
    if (m == 0) return SPH_OK;
    /* the call's bounding box, eps wider; distinct points (sph_fill_box's lattice) need only be
       checked against the world's particles in it, and not at all when there are none */
    for (k = 0; k < dim; ++k) {
        blo[k] = 1e300;
        bhi[k] = -1e300;
    }
    for (i = 0; i < m * dim; ++i) {
        if ((double)x[i] < blo[i % dim]) blo[i % dim] = (double)x[i];
        if ((double)x[i] > bhi[i % dim]) bhi[i % dim] = (double)x[i];
    }
    for (k = 0; k < dim; ++k) {
        blo[k] -= eps * (double)w->dx;
        bhi[k] += eps * (double)w->dx;
    }
    for (i = 0; i < n; ++i) inside += (size_t)sph__in_box(w->x + i * dim, dim, blo, bhi);
    if (given == SPH__POINTS_DISTINCT && inside == 0) return SPH_OK;
    while (nh < 2 * m) nh *= 2;
    head = (size_t*)SPH_MALLOC((nh + m) * sizeof(size_t));
    if (!head) return sph__fail(w, SPH_ERR_NOMEM, -1, "%s: out of memory", fn);
    next = head + nh;
    for (i = 0; i < nh; ++i) head[i] = (size_t)-1;
    for (i = 0; i < m; ++i) { /* the call's particles by cell */
        uint64_t hsh = 1469598103934665603ull;
        for (k = 0; k < dim; ++k)
            hsh = (hsh ^ (uint64_t)(int64_t)floor((double)x[i * dim + k] * inv)) * 1099511628211ull;
        next[i] = head[hsh & (nh - 1)];
        head[hsh & (nh - 1)] = i;
    }
    /* each point of the world (i < n) inside the box and of the call (n + i): every cell within
       eps of it */
    for (i = 0; i < (given == SPH__POINTS_DISTINCT ? n : n + m) && !found; ++i) {
        const sph_real* xi = i < n ? w->x + i * dim : x + (i - n) * dim;
        double c[3] = {0, 0, 0}, f[3] = {0, 0, 0};
        int corner;
        if (i < n && !sph__in_box(xi, dim, blo, bhi)) continue;
        for (k = 0; k < dim; ++k) {
            c[k] = floor((double)xi[k] * inv);
            f[k] = (double)xi[k] * inv - c[k];
        }
        for (corner = 0; corner < (1 << (int)dim) && !found; ++corner) {
            double cc[3] = {0, 0, 0};
            uint64_t hsh = 1469598103934665603ull;
            size_t j;
            for (k = 0; k < dim; ++k) {
                const int up = (corner >> k) & 1;
                if (up && !(f[k] < eps || f[k] > 1 - eps)) break;
                cc[k] = c[k] + (up ? (f[k] < eps ? -1 : 1) : 0);
                hsh = (hsh ^ (uint64_t)(int64_t)cc[k]) * 1099511628211ull;
            }
            if (k < dim) continue;
            for (j = head[hsh & (nh - 1)]; j != (size_t)-1 && !found; j = next[j]) {
                double d2 = 0;
                for (k = 0; k < dim; ++k) {
                    const double d = ((double)x[j * dim + k] - (double)xi[k]) * inv;
                    d2 += d * d;
                }
                if (d2 < eps * eps && (i < n || j != i - n)) {
                    found = 1;
                    found_a = j;
                    found_b = i;
                }
            }
        }
    }
    SPH_FREE(head);
    if (!found) return SPH_OK;
    if (found_b < n) /* the error names the caller's particle, or (sph_fill_box, whose points
                        are its own) the world's (found by tests/fuzz_api.c) */
        return sph__fail(w, SPH_ERR_ARG, (long)(given == SPH__POINTS_DISTINCT ? found_b : found_a),
                         "%s: particle %zu lies within %g spacings of fluid particle %zu (id %u) "
                         "already in the world (the same fluid added twice?): coincident "
                         "particles never separate; nothing added",
                         fn, found_a, eps, found_b, (unsigned)w->id[found_b]);
    return sph__fail(w, SPH_ERR_ARG, (long)found_a,
                     "%s: particles %zu and %zu lie within %g spacings of each other: coincident "
                     "particles never separate; nothing added",
                     fn, found_a, found_b - n, eps);
}

static sph_status sph__add_fluid_checked(sph_world* w, const char* fn, int phase, size_t n,
                                         const sph_real* x, const sph_real* v, const sph_real* m,
                                         const sph_real* rho) {
    sph_status s;
    if (!w) return SPH_ERR_ARG;
    if (!sph__check_phase(w, fn, phase)) return SPH_ERR_ARG;
    if (n == 0) return SPH_OK;
    if ((s = sph__check_fluid(w, fn, n, x, v, m, rho)) != SPH_OK) return s;
    if ((s = sph__check_coincident(w, fn, n, x, SPH__POINTS_ANY)) != SPH_OK) return s;
    return sph__append_fluid(w, phase, n, x, v, w->phases[phase].mass, m, rho);
}

SPHDEF sph_status sph_add_fluid(sph_world* w, int phase, size_t n, const sph_real* x,
                                const sph_real* v) {
    return sph__add_fluid_checked(w, "sph_add_fluid", phase, n, x, v, NULL, NULL);
}

SPHDEF sph_status sph_add_fluid_ex(sph_world* w, int phase, size_t n, const sph_real* x,
                                   const sph_real* v, const sph_real* m, const sph_real* rho) {
    return sph__add_fluid_checked(w, "sph_add_fluid_ex", phase, n, x, v, m, rho);
}

static sph_status sph__check_box(sph_world* w, const char* fn, const sph_real* lo,
                                 const sph_real* hi) {
    int k;
    if (!lo || !hi) return sph__fail(w, SPH_ERR_ARG, -1, "%s: lo or hi is NULL", fn);
    for (k = 0; k < w->dim; ++k)
        if (!sph__finite((double)lo[k]) || !sph__finite((double)hi[k]) || !(hi[k] > lo[k]))
            return sph__fail(w, SPH_ERR_ARG, -1,
                             "%s: box [%g, %g] in direction %d must be finite with lo < hi", fn,
                             (double)lo[k], (double)hi[k], k);
    for (k = 0; k < w->dim; ++k) {
        const int high = fabs((double)hi[k]) > sph__far_limit(w->dx);
        if (high || fabs((double)lo[k]) > sph__far_limit(w->dx)) {
            char what[96];
            snprintf(what, sizeof what, "%s: %s[%d]", fn, high ? "hi" : "lo", k);
            return sph__fail_far(w, w->dx, -1, what, (double)(high ? hi[k] : lo[k]));
        }
    }
    return SPH_OK;
}

SPHDEF sph_status sph_fill_box(sph_world* w, int phase, const sph_real* lo, const sph_real* hi) {
    /* round(extent / dx) particles per direction at the spacing that fills the box exactly (the
       rule sph_add_wall_box uses, so a tank and its water line up); a particle's mass is the
       phase's mass times its cell volume over dx^dim, i.e. rest density times cell volume. */
    const int dim = w ? w->dim : 0;
    size_t cnt[3] = {1, 1, 1}, total = 1, i;
    sph_real sp[3] = {0, 0, 0}, *pts;
    double mass;
    sph_status s;
    int k;
    if (!w) return SPH_ERR_ARG;
    if (!sph__check_phase(w, "sph_fill_box", phase)) return SPH_ERR_ARG;
    s = sph__check_box(w, "sph_fill_box", lo, hi);
    if (s != SPH_OK) return s;
    mass = (double)w->phases[phase].mass;
    for (k = 0; k < dim; ++k) {
        double c = floor((double)((hi[k] - lo[k]) / w->dx) + 0.5);
        if (c < 1)
            return sph__fail(w, SPH_ERR_ARG, -1,
                             "sph_fill_box: box is thinner than half a spacing in direction %d", k);
        if (c > 1e7) return sph__fail(w, SPH_ERR_CAPACITY, -1, "sph_fill_box: box too large");
        cnt[k] = (size_t)c;
        sp[k] = (hi[k] - lo[k]) / (sph_real)c;
        mass *= (double)sp[k] / (double)w->dx;
        if (cnt[k] > ((size_t)UINT32_MAX - 1) / total) /* 1e7^3 would overflow size_t */
            return sph__fail(w, SPH_ERR_CAPACITY, -1, "sph_fill_box: too many particles");
        total *= cnt[k];
    }
    if (total + w->n > (size_t)UINT32_MAX - 1)
        return sph__fail(w, SPH_ERR_CAPACITY, -1, "sph_fill_box: too many particles");
    pts = (sph_real*)SPH_MALLOC(total * (size_t)dim * sizeof(sph_real));
    if (!pts) return sph__fail(w, SPH_ERR_NOMEM, -1, "sph_fill_box: out of memory");
    for (i = 0; i < total; ++i) { /* x fastest, as the cell sort would order them */
        size_t r = i;
        for (k = 0; k < dim; ++k) {
            pts[i * (size_t)dim + (size_t)k] = lo[k] + ((sph_real)(r % cnt[k]) + SPH__R(0.5)) * sp[k];
            r /= cnt[k];
        }
    }
    /* whole spacings keep the phase's mass bit for bit (no mass array for them) */
    for (k = 0; k < dim; ++k)
        if (sp[k] != w->dx) break;
    s = sph__check_coincident(w, "sph_fill_box", total, pts, SPH__POINTS_DISTINCT);
    if (s == SPH_OK)
        s = sph__append_fluid(w, phase, total, pts, NULL,
                              k == dim ? w->phases[phase].mass : (sph_real)mass, NULL, NULL);
    SPH_FREE(pts);
    if (s == SPH_OK)
        for (k = 0; k < 3; ++k) w->fill_spacing[k] = sp[k];
    return s;
}

static sph_status sph__append_boundary(sph_world* w, size_t n, const sph_real* x,
                                       const sph_real* vol, int body) {
    const size_t dim = (size_t)w->dim;
    size_t i, k, base = w->nb;
    sph_status s = sph__reserve(w, 1, w->nb + n);
    if (s != SPH_OK) return s;
    for (i = 0; i < n; ++i) {
        size_t j = base + i;
        for (k = 0; k < dim; ++k) {
            w->b_x[j * dim + k] = x[i * dim + k];
            w->b_x0[j * dim + k] = x[i * dim + k];
            w->b_v[j * dim + k] = 0;
            w->b_a[j * dim + k] = 0;
            w->b_vw[j * dim + k] = 0;
        }
        w->b_vol[j] = vol[i];
        w->b_p[j] = 0;
        w->b_rho[j] = 1;
        w->priv.b_sw[j] = 0; /* saved with the world: a step without fluid does not set it */
        w->b_id[j] = w->b_next_id++;
        w->b_body[j] = (uint16_t)body;
    }
    w->nb += n;
    w->priv.placed = 1;
    w->priv.placed_c0 = 1;
    w->priv.placed_from = 0; /* every fluid particle may now lie in the new walls */
    w->priv.b_dirty = 1;
    return SPH_OK;
}

/* The rules for boundary particles, shared by sph_add_boundary and the loader; vol may be NULL
   (dx^dim). */
static sph_status sph__check_boundary(sph_world* w, const char* fn, size_t n, const sph_real* x,
                                      const sph_real* vol, int body) {
    size_t bad = 0, i, dim = (size_t)w->dim;
    sph_status s;
    if (n == 0) return SPH_OK;
    if (!x) return sph__fail(w, SPH_ERR_ARG, -1, "%s: x is NULL", fn);
    if (body < 0 || body > 65535)
        return sph__fail(w, SPH_ERR_ARG, -1, "%s: body = %d: must be in [0, 65535]", fn, body);
    if (!sph__all_finite(x, n * dim, &bad))
        return sph__fail(w, SPH_ERR_ARG, (long)(bad / dim),
                         "%s: x of particle %zu is not finite (%g)", fn, bad / dim, (double)x[bad]);
    if ((s = sph__check_far(w, fn, "boundary ", n, x)) != SPH_OK) return s;
    for (i = 0; vol && i < n; ++i)
        if (!sph__finite((double)vol[i]) || !(vol[i] > 0))
            return sph__fail(w, SPH_ERR_ARG, (long)i,
                             "%s: vol of particle %zu = %g: must be finite and > 0", fn, i,
                             (double)vol[i]);
    return SPH_OK;
}

SPHDEF sph_status sph_add_boundary(sph_world* w, size_t n, const sph_real* x, const sph_real* vol,
                                   int body) {
    size_t i;
    sph_real* v0 = NULL;
    sph_status s;
    if (!w) return SPH_ERR_ARG;
    if (n == 0) return SPH_OK;
    if ((s = sph__check_boundary(w, "sph_add_boundary", n, x, vol, body)) != SPH_OK) return s;
    if (vol) return sph__append_boundary(w, n, x, vol, body);
    v0 = (sph_real*)SPH_MALLOC(n * sizeof(sph_real));
    if (!v0) return sph__fail(w, SPH_ERR_NOMEM, -1, "sph_add_boundary: out of memory");
    for (i = 0; i < n; ++i)
        v0[i] = w->dim == 1 ? w->dx : w->dim == 2 ? w->dx * w->dx : w->dx * w->dx * w->dx;
    s = sph__append_boundary(w, n, x, v0, body);
    SPH_FREE(v0);
    return s;
}

SPHDEF sph_status sph_add_wall_box(sph_world* w, const sph_real* lo, const sph_real* hi,
                                   int layers, unsigned open_faces) {
    /* Per direction: `layers` wall coordinates below lo, the interior at a spacing that divides
       hi - lo exactly (closest to dx), `layers` above hi. A lattice point is a wall point if it
       lies outside the box in some direction, unless it lies beyond an open face. Only the wall
       shell is visited, in the lattice order (x fastest, then y, then z): a row along x whose y
       and z lie inside the box holds wall points only in its x layers, so the work and memory
       grow with the surface, not the volume (a 4 m cube at dx = 0.01, 2.9 M wall particles: with
       the whole-lattice walk the call allocated 2.1 GB of scratch for 67 M lattice points and
       took 3.0 s; with the shell walk 94 MB and 1.9 s, most of it filling the world's arrays). */
    const int dim = w ? w->dim : 0;
    sph_real* coord[3] = {NULL, NULL, NULL};
    sph_real* width[3] = {NULL, NULL, NULL};
    int* side[3] = {NULL, NULL, NULL};
    size_t cnt[3] = {1, 1, 1}, nw = 0, iy, iz;
    double all = 1, inner = 1; /* lattice points not beyond an open face; of them inside the box */
    sph_real *pts = NULL, *vol = NULL;
    sph_status s;
    int k;
    if (!w) return SPH_ERR_ARG;
    s = sph__check_box(w, "sph_add_wall_box", lo, hi);
    if (s != SPH_OK) return s;
    if (layers < 0 || layers > 64)
        return sph__fail(w, SPH_ERR_ARG, -1, "sph_add_wall_box: layers = %d: must be in [0, 64]",
                         layers);
    if (open_faces > 63u)
        return sph__fail(w, SPH_ERR_ARG, -1, "sph_add_wall_box: open_faces = %u: not SPH_FACE_* bits",
                         open_faces);
    if (layers == 0) layers = (int)ceil((double)(w->kernel.radius / w->dx) - 1e-9);
    for (k = 0; k < dim; ++k) { /* the outermost layers, as sph_add_boundary would check them */
        const double depth = (double)layers * (double)w->dx;
        const double a = (double)lo[k] - depth, b = (double)hi[k] + depth;
        if (fabs(a) > sph__far_limit(w->dx) || fabs(b) > sph__far_limit(w->dx)) {
            char what[96];
            snprintf(what, sizeof what, "sph_add_wall_box: its outer layer at x[%d]", k);
            return sph__fail_far(w, w->dx, -1, what, fabs(b) > fabs(a) ? b : a);
        }
    }
    for (k = 0; k < dim; ++k) { /* the wall count first, before anything is allocated */
        double span = (double)((hi[k] - lo[k]) / w->dx), ni;
        /* before the conversion: a span beyond size_t (or hi - lo overflowing to inf) would make
           it undefined */
        if (!(span <= 1e7))
            return sph__fail(w, SPH_ERR_CAPACITY, -1, "sph_add_wall_box: box too large");
        ni = floor(span + 0.5);
        if (ni < 1) ni = 1;
        inner *= ni;
        all *= ni + (open_faces & (1u << (2 * k)) ? 0 : layers) +
               (open_faces & (1u << (2 * k + 1)) ? 0 : layers);
    }
    if (all - inner + (double)w->nb > (double)UINT32_MAX - 1)
        return sph__fail(w, SPH_ERR_CAPACITY, -1,
                         "sph_add_wall_box: %.0f wall particles (with the %zu there) exceed the "
                         "limit of %u", all - inner, w->nb, (unsigned)(UINT32_MAX - 1));
    for (k = 0; k < dim; ++k) {
        size_t ni = (size_t)((double)((hi[k] - lo[k]) / w->dx) + 0.5), j, c = 0;
        sph_real sp;
        if (ni < 1) ni = 1;
        sp = (hi[k] - lo[k]) / (sph_real)ni;
        cnt[k] = ni + 2 * (size_t)layers;
        coord[k] = (sph_real*)SPH_MALLOC(cnt[k] * sizeof(sph_real));
        width[k] = (sph_real*)SPH_MALLOC(cnt[k] * sizeof(sph_real));
        side[k] = (int*)SPH_MALLOC(cnt[k] * sizeof(int));
        if (!coord[k] || !width[k] || !side[k]) { s = SPH_ERR_NOMEM; goto done; }
        for (j = (size_t)layers; j > 0; --j, ++c) {
            coord[k][c] = lo[k] - ((sph_real)(j - 1) + SPH__R(0.5)) * w->dx;
            width[k][c] = w->dx;
            /* -2, 2: a layer beyond an open face (never a wall point); -1, 1: a wall layer */
            side[k][c] = open_faces & (1u << (2 * k)) ? -2 : -1;
        }
        for (j = 0; j < ni; ++j, ++c) {
            coord[k][c] = lo[k] + ((sph_real)j + SPH__R(0.5)) * sp;
            width[k][c] = sp;
            side[k][c] = 0;
        }
        for (j = 0; j < (size_t)layers; ++j, ++c) {
            coord[k][c] = hi[k] + ((sph_real)j + SPH__R(0.5)) * w->dx;
            width[k][c] = w->dx;
            side[k][c] = open_faces & (1u << (2 * k + 1)) ? 2 : 1;
        }
    }
    nw = (size_t)(all - inner);
    if (nw == 0) goto done; /* no layer (a support below 1e-9 dx) or every face open */
    pts = (sph_real*)SPH_MALLOC(nw * (size_t)dim * sizeof(sph_real));
    vol = (sph_real*)SPH_MALLOC(nw * sizeof(sph_real));
    if (!pts || !vol) { s = SPH_ERR_NOMEM; goto done; }
    nw = 0;
    for (iz = 0; iz < cnt[2]; ++iz) {
        const int sz = dim > 2 ? side[2][iz] : 0;
        if (sz == -2 || sz == 2) continue;
        for (iy = 0; iy < cnt[1]; ++iy) {
            const int sy = dim > 1 ? side[1][iy] : 0, inside = sy == 0 && sz == 0;
            size_t ix;
            if (sy == -2 || sy == 2) continue;
            /* a row inside the box in y and z has wall points only in its x layers; with both x
               faces open it has none, and neither have the rows after it up to the high y
               layers */
            if (inside && side[0][0] == -2 && side[0][cnt[0] - 1] == 2) {
                if (dim > 1) iy = cnt[1] - (size_t)layers - 1;
                continue;
            }
            for (ix = 0; ix < cnt[0]; ++ix) {
                size_t at[3];
                sph_real V = 1;
                if (inside && ix == (size_t)layers) ix = cnt[0] - (size_t)layers; /* the box */
                if (side[0][ix] == -2 || side[0][ix] == 2) continue;
                at[0] = ix;
                at[1] = iy;
                at[2] = iz;
                for (k = 0; k < dim; ++k) { /* V multiplied in the order of the lattice walk */
                    pts[nw * (size_t)dim + (size_t)k] = coord[k][at[k]];
                    V *= width[k][at[k]];
                }
                vol[nw++] = V;
            }
        }
    }
    SPH_ASSERT(nw == (size_t)(all - inner));
    /* the rules of sph_add_boundary: a box far thinner than a spacing gives volumes that round
       to 0 (a denormal spacing across it; found by tests/fuzz_api.c) */
    s = sph__check_boundary(w, "sph_add_wall_box", nw, pts, vol, 0);
    if (s != SPH_OK) w->error_index = -1; /* an index of the box's own list, not the caller's */
    if (s == SPH_OK) s = sph__append_boundary(w, nw, pts, vol, 0);
    if (s == SPH_OK && open_faces == 0 && w->priv.tanks >= 0 && w->priv.tanks++ == 0) {
        for (k = 0; k < dim; ++k) {
            w->priv.tank_lo[k] = lo[k];
            w->priv.tank_hi[k] = hi[k];
        }
        sph__tank_note(w, 0); /* fluid added before the box */
    }
done:
    if (s == SPH_ERR_NOMEM) sph__fail(w, s, -1, "sph_add_wall_box: out of memory");
    for (k = 0; k < 3; ++k) { SPH_FREE(coord[k]); SPH_FREE(width[k]); SPH_FREE(side[k]); }
    SPH_FREE(pts);
    SPH_FREE(vol);
    return s;
}

static size_t sph__grid_memory(const sph_grid* g) {
    return g->cap_n * (2 * sizeof(uint32_t) + sizeof(uint64_t)) + g->cap_bucket * sizeof(uint32_t);
}

static size_t sph__neighbors_memory(const sph_neighbors* nl) {
    return nl->cap_n * (sizeof(size_t) + sizeof(uint32_t)) + nl->cap_idx * sizeof(uint32_t) +
           nl->cap_chunk * 4 * sizeof(size_t) + nl->cap_xs * sizeof(sph_real);
}

SPHDEF size_t sph_world_memory(const sph_world* w) {
    sph__array arr[16];
    size_t bytes = 0;
    int k, n;
    if (!w) return 0;
    n = sph__fluid_arrays((sph_world*)w, arr);
    for (k = 0; k < n; ++k) bytes += w->capacity * arr[k].elem;
    n = sph__boundary_arrays((sph_world*)w, arr);
    for (k = 0; k < n; ++k) bytes += w->b_capacity * arr[k].elem;
    bytes += sph__grid_memory(&w->priv.grid) + sph__grid_memory(&w->priv.bgrid) +
             sph__grid_memory(&w->priv.sgrid) + w->priv.b_near_cap;
    bytes += sph__neighbors_memory(&w->priv.ff) + sph__neighbors_memory(&w->priv.fb) +
             sph__neighbors_memory(&w->priv.bf) + sph__neighbors_memory(&w->priv.bb) +
             sph__neighbors_memory(&w->priv.snl) + sph__neighbors_memory(&w->priv.cff) +
             sph__neighbors_memory(&w->priv.cfb) + sph__neighbors_memory(&w->priv.cbf) +
             sph__neighbors_memory(&w->priv.ffh) +
             (w->priv.vl_x_cap + w->priv.vl_bx_cap) * sizeof(sph_real);
    bytes += w->priv.perm_cap + w->priv.block_cap * sizeof(double) +
             (w->priv.rho_n_cap + w->priv.aii_cap + w->priv.src_cap + w->priv.ap_cap + w->priv.cg_cap +
              w->priv.df_alpha_cap + w->priv.df_alpha_v_cap + w->priv.df_vs_cap +
              w->priv.df_kv_cap + w->priv.df_pv_cap +
              w->priv.ff_fw_cap + w->priv.fb_fw_cap + w->priv.pr2_cap + w->priv.vol_cap +
              w->priv.shift_cap +
              w->priv.xp_cap + w->priv.xs_cap +
              w->priv.vp_cap + w->priv.de_cap + w->priv.cs_cap + w->priv.vn_cap + w->priv.bpq_cap + w->priv.soc_cap + w->priv.socw_cap +
              w->priv.lapc_cap + w->priv.wg_cap + w->priv.abody_cap) *
                 sizeof(sph_real);
    bytes += w->priv.snap_cap[0] + w->priv.snap_cap[1]; /* sph_advance's rollback copies */
    return bytes;
}

SPHDEF double sph_world_mass(const sph_world* w) {
    double sum = 0;
    size_t i;
    if (!w) return 0;
    for (i = 0; i < w->n; ++i) sum += (double)(w->m ? w->m[i] : w->mass);
    return sum;
}

SPHDEF void sph_world_momentum(const sph_world* w, double* out) {
    size_t i;
    int k;
    if (!w || !out) return;
    for (k = 0; k < w->dim; ++k) out[k] = 0;
    for (i = 0; i < w->n; ++i) {
        double mi = (double)(w->m ? w->m[i] : w->mass);
        for (k = 0; k < w->dim; ++k) out[k] += mi * (double)w->v[i * (size_t)w->dim + (size_t)k];
    }
}

/* ============================================================================================== */
/* >>boundaries (implementation)                                                                  */
/* ============================================================================================== */
/* Boundary particles stand in for the wall as a layer of "fluid" seen by each fluid particle i:
   a wall particle b of volume V_b acts on i like a particle of mass psi_ib = rho0_i V_b (Akinci et
   al. 2012 write the same psi for the density sum), pressure p_b and density rho0_i * b_rho[b].
   Taking the rest density of the fluid particle's own phase keeps walls neutral in multiphase
   flows; for one phase and lattice walls (V_b = dx^d) it is Adami et al.'s dummy particle. */

/* Tait or linear equation of state per phase, with the constants prepared once per step. */
/* For the gases B = rho0 c0^2 / gamma = p_b + p_inf too: along their isentrope through the rest
   state, p + p_inf = (p_b + p_inf)(rho/rho0)^gamma is the Tait law, so sph__eos_inverse serves
   walls and hydrostatic columns of every phase. */
typedef struct sph__phase_c {
    sph_real rho0, inv_rho0, c0, B, inv_B, gamma, inv_gamma, pb, mu;
    sph_real pinf; /* stiffened gas p_inf [Pa]                                                  */
    sph_real ck;   /* c^2 = gamma (p + ck) / rho: B - p_b (Tait), p_inf (gases)                  */
    int eos, gamma7, gas;
} sph__phase_c;

static void sph__phase_c_init(sph__phase_c* C, const sph_phase* P) {
    C->rho0 = P->rest_density;
    C->inv_rho0 = 1 / P->rest_density;
    C->c0 = P->sound_speed;
    C->gamma = P->gamma;
    C->inv_gamma = 1 / P->gamma;
    C->gamma7 = P->gamma == 7;
    C->B = P->rest_density * P->sound_speed * P->sound_speed / P->gamma;
    C->inv_B = C->B > 0 ? 1 / C->B : 0;
    C->pb = P->back_pressure;
    C->eos = (int)P->eos;
    C->gas = P->eos == SPH_EOS_IDEAL_GAS || P->eos == SPH_EOS_STIFFENED_GAS;
    C->pinf = sph__pinf(P);
    C->ck = C->gas ? C->pinf : C->B - C->pb;
    C->mu = P->rest_density * P->viscosity; /* dynamic viscosity [Pa s] */
}

SPH__INLINE sph_real sph__eos(const sph__phase_c* P, sph_real rho) {
    sph_real t = rho * P->inv_rho0;
    if (P->eos == SPH_EOS_LINEAR) return P->c0 * P->c0 * (rho - P->rho0) + P->pb;
    if (P->gamma7) { /* gamma = 7 without pow */
        sph_real t2 = t * t, t4 = t2 * t2;
        return P->B * (t4 * t2 * t - 1) + P->pb;
    }
    return P->B * (sph__pow(t, P->gamma) - 1) + P->pb;
}

/* The Tait or linear pressure of a phase at density rho (outside the stages). */
static sph_real sph__eos_phase(const sph_phase* P, sph_real rho) {
    sph__phase_c C;
    sph__phase_c_init(&C, P);
    return sph__eos(&C, rho);
}

/* rho/rho0 for pressure p: the inverse of sph__eos. Tension beyond what the fluid can carry is
   clamped at rho/rho0 = 0.01 (the wall would otherwise get a non-positive density). */
SPH__INLINE sph_real sph__eos_inverse(const sph__phase_c* P, sph_real p) {
    sph_real t;
    if (P->eos == SPH_EOS_LINEAR) {
        t = 1 + (p - P->pb) * P->inv_rho0 / (P->c0 * P->c0);
        return t > SPH__R(0.01) ? t : SPH__R(0.01);
    }
    t = (p - P->pb) * P->inv_B + 1;
    if (t < SPH__R(1e-14)) t = SPH__R(1e-14);
    t = sph__pow(t, P->inv_gamma);
    return t > SPH__R(0.01) ? t : SPH__R(0.01);
}

/* Everything a neighbour loop reads, gathered once per stage. */
typedef struct sph__ctx {
    int dim, periodic_any, per[3], has_b, nphase;
    sph_real len[3];
    sph_kernel k;
    sph_real h, eta2;          /* eta^2 = 0.01 h^2 regularises 1/r^2 (Monaghan 1992)            */
    const sph_real *x, *v, *rho, *p, *m;
    sph_real m0;
    const uint8_t* ph;
    const sph_real *bx, *bv, *bvw, *bvol, *bp, *brho;
    sph_real* bpq;             /* if set: per wall particle and phase (p_b, rho_b/rho0), see
                                  sph__stage_wall; the fluid sees its own phase's values       */
    sph__phase_c pc[SPH_MAX_PHASES];
    const sph_neighbors *ff, *fb, *bf;
    int density, pgrad, noslip, laminar, morris, av, delta_on;
    int bp_mode;               /* sph_boundary_pressure                                          */
    const sph_real *ff_fw, *fb_fw; /* cached grad W factors per listed pair (SPH__CACHED passes)  */
    sph_real *ff_fw_out, *fb_fw_out; /* where SPH__STORE passes write them                        */
    sph_real delta_c;          /* if > 0, the speed in the delta-SPH term instead of each phase's c0 */
    int delta_hs;              /* delta-SPH diffuses the density less its hydrostatic part (WCSPH
                                  with gravity or a force callback; sph__delta_hydro)           */
    const sph_real* abody;     /* delta_hs: the body accelerations of the step [m/s^2]          */
    const sph_real* pr2;       /* p / rho^2 per fluid particle (SPH__CACHED passes)              */
    const sph_real *pr2c, *volc; /* p / rho^2 and m / rho per fluid particle for fast-path passes
                                  (sph__pair_cache; NULL: computed per pair)                    */
    int eos_walls;             /* wall density from the equation of state (WCSPH) or a Shepard
                                  average of the fluid's (solvers without one; Enhanced PCISPH
                                  2018 sec. 3.2.3)                                               */
    sph_real alpha, beta, delta, visc_k;
    sph_real rho_alone;        /* W(0) / S: times m_i, the summation density of a particle
                                  alone, the least a carried density keeps (sph__rho_floor,
                                  sph__contact_density)                                          */
    int rho_floor;             /* sph__rho_floor holds carried densities at m_i rho_alone (where
                                  pressures are clamped, sph__clamps)                            */
    sph_real pg_norm;          /* 1 / the lattice gradient moment for the multiphase and interface
                                  pressure gradients (see sph__ctx_init), else 1                */
    sph_real* lapc;            /* laminar viscosity, Morris form: 1 / m_i per fluid particle
                                  (sph__stage_visc_norm fills it before each viscous pass)      */
    const sph_real* wg;        /* the walls' sums of sph__wall_grad_sum, for the cached pressure
                                  (wg_pressure: zero wall pressure) and rate passes of IISPH's
                                  and DFSPH's solves, else NULL                                 */
    int wg_pressure;
    sph_real g[3];
    /* the compressible step */
    const sph_real* e;         /* specific internal energy (NULL without gas phases)             */
    const sph_real* cs;        /* per-particle sound speed for artificial viscosity (else c0)    */
    const sph_real* vn;        /* velocities at the start of the step (SPH__ENERGY passes)       */
    sph_real* de;              /* energy rate output of SPH__ENERGY passes [J/kg/s]              */
} sph__ctx;

/* Multiphase walls with an equation of state extrapolate one wall pressure per phase: Adami et
   al.'s eq. 27 over all fluid neighbours would carry the dense phase's hydrostatic gradient
   across the interface (at 1000:1 a wall particle beside the air, one spacing above the water,
   gets -rho_w g dx, hundreds of pascals below the air's pressure, and pulls the air into the
   wall). Each phase's wall pressure is extrapolated from its own particles only.
   Which phase a wall particle stands for: Adami et al.'s wall particles continue the fluid
   beside them across the wall, so where an interface meets a wall (a contact line) a wall
   particle continues the phase that wets the wall there, not the phase of the particle it
   pushes. Every wall particle therefore stands for the phase of its nearest fluid particle
   (in a flat wall: the fluid row at its height), with that phase's extrapolated pressure and
   density and its rest density's mass rho0_q V_b, and acts on every fluid particle through the
   pair term of def.pressure_grad as a fluid particle of that phase would (with the interface
   and multiphase forms the water then sees the air's pressure on the wall beside the air, and
   the air sees the wall beside the water through the density-weighted pair pressure, as it
   sees the water itself). Before, each particle saw the wall as its own phase: the water's
   extrapolation reached up the wall beside the air (falling by rho_w g per metre, where the air
   falls by rho_a g) and the air's down the wall beside the water, so the rows at a contact line
   did not feel the forces of the same rows away from the wall. Measured on a 1000:1 interface
   at rest in a closed box (tests/test_compressible.c, contact_line; square lattice, dx 0.025 m):
   the largest difference from the row's acceleration in the middle of the box at the first
   step 3.66 m/s^2 (the air at the corner pulled into the wall), now 2.4e-4. A wall particle
   without fluid neighbours stands for no phase and is never asked. */
#define SPH__BPQ 3 /* reals per wall particle and phase in w->priv.bpq: p_b, rho_b/rho0, share */
static int sph__phase_walls_for(const sph_world* w, int solver) {
    return w->nphase > 1 && w->nb > 0 && w->def.boundary_pressure == SPH_BP_EXTRAPOLATE &&
           (solver == SPH_SOLVER_WCSPH || solver == SPH_SOLVER_COMPRESSIBLE);
}
static int sph__phase_walls(const sph_world* w) { return sph__phase_walls_for(w, w->priv.solver); }

/* Whether negative pressures are clamped to zero. PCISPH, IISPH, DFSPH and PBF always clamp.
   SPH_CLAMP_AUTO clamps WCSPH whatever the density: a summation density sees a deficit at a free
   surface (Becker & Teschner 2007 clamp it), and a carried density (continuity, or Ott &
   Schnetter's particle density) falls towards sph__rho_floor's value where a particle leaves its
   neighbours, where the Tait equation's pressure tends to -B: that tension pulled a dam break's
   splash into clumps of ten particles on one point (0.4 x 0.6 m column in a closed 1.6 x 0.8 m
   tank, dx 0.01: compressed 20 % at 2.22 s; clamped, it runs 6 s). A domain periodic in every
   direction has no free surface, and there the pressure's negative part is the flow's own (a
   Taylor-Green vortex without background pressure), so it keeps its tension. The compressible
   step keeps its tension (gases, and liquids under tension) unless asked. */
static int sph__clamps(const sph_world* w) {
    int k, all_periodic = 1;
    if (w->priv.solver != SPH_SOLVER_WCSPH && w->priv.solver != SPH_SOLVER_COMPRESSIBLE) return 1;
    if (w->def.clamp != SPH_CLAMP_AUTO) return w->def.clamp == SPH_CLAMP_ON;
    if (w->def.density == SPH_DENSITY_SUMMATION) return 1;
    for (k = 0; k < w->dim; ++k)
        if (!w->def.periodic[k]) all_periodic = 0;
    return w->priv.solver == SPH_SOLVER_WCSPH && !all_periodic;
}

/* Whether delta-SPH leaves out the hydrostatic part (sph__delta_hydro): WCSPH with delta-SPH and
   gravity or a force callback. */
static int sph__delta_hydro_on(const sph_world* w) {
    return w->def.delta > 0 && w->priv.solver == SPH_SOLVER_WCSPH &&
           (w->def.gravity[0] != 0 || w->def.gravity[1] != 0 || w->def.gravity[2] != 0 ||
            w->def.force != NULL);
}

static void sph__ctx_init(sph_world* w, sph__ctx* c) {
    int k, q;
    memset(c, 0, sizeof(*c));
    c->dim = w->dim;
    for (k = 0; k < w->dim; ++k) {
        c->per[k] = w->def.periodic[k] != 0;
        c->len[k] = w->def.domain_hi[k] - w->def.domain_lo[k];
        if (c->per[k]) c->periodic_any = 1;
        c->g[k] = w->def.gravity[k];
    }
    c->has_b = w->nb > 0;
    c->k = w->kernel;
    c->h = w->h;
    c->eta2 = SPH__R(0.01) * w->h * w->h;
    c->x = w->x; c->v = w->v; c->rho = w->rho; c->p = w->p; c->m = w->m;
    c->m0 = w->mass;
    c->rho_alone = w->kernel.norm_w * sph__kw(w->kernel.form, 0) / w->priv.lattice_sum;
    c->rho_floor = sph__clamps(w);
    c->ph = w->phase;
    c->bx = w->b_x; c->bv = w->b_v; c->bvw = w->b_vw; c->bvol = w->b_vol;
    c->bp = w->b_p; c->brho = w->b_rho;
    c->ff = &w->priv.ff; c->fb = &w->priv.fb; c->bf = &w->priv.bf;
    c->nphase = w->nphase;
    c->laminar = 0;
    for (q = 0; q < w->nphase; ++q) {
        sph__phase_c_init(&c->pc[q], &w->phases[q]);
        if (w->phases[q].viscosity > 0) c->laminar = 1;
    }
    c->density = (int)w->def.density;
    c->pgrad = (int)w->def.pressure_grad;
    /* The multiphase and interface gradients of a layered column at rest balance gravity with a
       pressure 1 / M times too steep, M = sph__lattice_grad (0.974: 2.7 % at the bottom of any
       column, in every solver; measured on tests/test_layers.c's 1000/500/100 column, WCSPH,
       20 across: rows 2.0-2.9 % of the bottom pressure above the layered profile in the heavy
       layer). Dividing their pair terms by M makes the gradient of a linear pressure exact on
       the lattice (the same correction, for the gradient, as the density's division by the
       lattice sum): the rows then within 0.2 % away from the interfaces (1.2 % on the row next to
       one). The symmetric form, the default of one-phase scenes, is left as it was. */
    c->pg_norm = 1;
    if ((c->pgrad == SPH_PGRAD_MULTIPHASE || c->pgrad == SPH_PGRAD_INTERFACE ||
         c->pgrad == SPH_PGRAD_VOLUME) &&
        w->priv.lattice_grad > 0)
        c->pg_norm = 1 / w->priv.lattice_grad;
    c->noslip = w->def.wall == SPH_WALL_NO_SLIP;
    c->bp_mode = (int)w->def.boundary_pressure;
    c->eos_walls = w->priv.solver == SPH_SOLVER_WCSPH || w->priv.solver == SPH_SOLVER_COMPRESSIBLE;
    c->bpq = sph__phase_walls(w) ? w->priv.bpq : NULL;
    if (w->priv.solver == SPH_SOLVER_COMPRESSIBLE) {
        c->e = w->e;
        c->cs = w->priv.cs;
        c->vn = w->priv.vn;
        c->de = w->priv.de;
    }
    c->morris = w->def.viscosity_form == SPH_VISC_MORRIS;
    c->alpha = w->def.alpha;
    c->beta = w->def.beta;
    c->av = w->def.alpha > 0 || w->def.beta > 0;
    c->delta = w->def.delta;
    c->delta_on = w->def.delta > 0;
    c->delta_hs = sph__delta_hydro_on(w);
    c->abody = NULL; /* set by sph__prepare_forces */
    /* Monaghan 2005 / Enhanced PCISPH 2018 sec. 2.2.2: nu Lap v = 2(d+2) sum_j m_j
       nu_bar/rho_bar ...; with (mu_i + mu_j)/(rho_i rho_j) the factor 2 of the average moves into
       visc_k = d + 2. */
    c->visc_k = (sph_real)(w->dim + 2);
    if (c->morris) c->visc_k = 1;
    if (c->laminar && c->morris) c->lapc = w->priv.lapc; /* reserved by sph__step_begin */
}

/* for (k = 0; k < D; ++k) STMT, written out for a compile-time D: each index is then a constant,
   so small arrays (d[3], ai[3]) live in registers. With the loop, gcc kept ai[] of the 3D passes
   on the stack, and every pair waited on a store and a reload (3D forces x1.6 without). */
#define SPH__FOR_K(D, ...)                                                                         \
    do {                                                                                           \
        k = 0; __VA_ARGS__;                                                                        \
        if ((D) > 1) { k = 1; __VA_ARGS__; }                                                       \
        if ((D) > 2) { k = 2; __VA_ARGS__; }                                                       \
    } while (0)

SPH__INLINE void sph__delta_vec(const sph__ctx* c, const sph_real* a, const sph_real* b,
                                sph_real* d, const int D) {
    int k;
    SPH__FOR_K(D, d[k] = a[k] - b[k];
               if (c->periodic_any && c->per[k]) d[k] = sph__wrap_delta(d[k], c->len[k]));
}

/* The same with the periodic test given (0 when known to be off). */
SPH__INLINE void sph__delta_vec_p(const sph__ctx* c, const int per, const sph_real* a,
                                  const sph_real* b, sph_real* d, const int D) {
    int k;
    SPH__FOR_K(D, d[k] = a[k] - b[k];
               if (per && c->per[k]) d[k] = sph__wrap_delta(d[k], c->len[k]));
}

/* Wall particles see their fluid neighbours f through Shepard averages (weights W_bf / sum_f W_bf).
   STATE (once per step): the sum b_sw = sum_f W_bf; for no-slip, Adami et al. 2012 eqs. 22-23:
       v~_b = 2 v_b - sum_f v_f W_bf / sum_f W_bf        (the velocity viscous terms see)
   and, for solvers without an equation of state, the wall density relative to rest as the
   Shepard average of rho_f/rho0_f (Enhanced PCISPH 2018 sec. 3.2.3's rho_w = sum_f rho_f W_bf /
   sum_f W_bf). PRESSURE (with SPH_BP_EXTRAPOLATE), Adami et al. 2012, eq. 27:
       p_b = (sum_f p_f W_bf + sum_f rho_f (g_f - a_b) . x_bf W_bf) / sum_f W_bf, x_bf = x_b - x_f,
   with g_f the body acceleration of fluid particle f (gravity, the user's forces and, for the
   iterative solvers, viscosity: w->a holds it when this runs) and a_b the wall's acceleration; so
   a force field that replaces gravity gives the same walls as gravity. With an equation of state
   the wall density follows from each neighbouring phase's (Adami eq. 28):
       b_rho[b] = sum_f W_bf (rho/rho0)_f(p_b) / sum_f W_bf.
   A wall particle without fluid neighbours has p_b = 0, b_rho = 1 and v~_b = v_b. */
enum { SPH__WALL_STATE = 1, SPH__WALL_PRESSURE = 2 };

static void sph__stage_wall(sph_world* w, const sph__ctx* c, int parts) {
    const int D = c->dim;
    const int pressure = (parts & SPH__WALL_PRESSURE) && c->bp_mode == SPH_BP_EXTRAPOLATE;
    sph__idx b;
    if (!(parts & SPH__WALL_STATE) && !pressure) return;
    SPH__OMP_FOR(w->nb)
    for (b = 0; b < (sph__idx)w->nb; ++b) {
        const sph_neighbors* nl = c->bf;
        const size_t bD = (size_t)b * (size_t)D;
        const sph_real* xb = c->bx + bD;
        sph_real sw = 0, swp = 0, sgx = 0, srr = 0, sv[3] = {0, 0, 0}, wph[SPH_MAX_PHASES];
        sph_real qp[SPH_MAX_PHASES], qg[SPH_MAX_PHASES], rmin = 0;
        size_t kk, k0 = nl->begin[b], k1 = k0 + nl->count[b];
        int k, q, qnear = -1;
        for (q = 0; q < c->nphase; ++q) wph[q] = qp[q] = qg[q] = 0;
        for (kk = k0; kk < k1; ++kk) {
            const size_t f = nl->idx[kk], fD = f * (size_t)D;
            sph_real d[3] = {0, 0, 0}, r2 = 0, W;
            sph__delta_vec(c, xb, c->x + fD, d, D);
            for (k = 0; k < D; ++k) r2 += d[k] * d[k];
            W = sph__kw(c->k.form, sph__sqrt(r2) * c->k.inv_h);
            sw += W;
            if (pressure) {
                swp += c->p[f] * W;
                for (k = 0; k < D; ++k) /* rho_f (g_f - a_b) . x_bf W_bf */
                    sgx += c->rho[f] * (w->a[fD + (size_t)k] - w->b_a[bD + (size_t)k]) * d[k] * W;
                wph[c->ph[f]] += W;
                if (qnear < 0 || r2 < rmin || (r2 == rmin && (int)c->ph[f] < qnear)) {
                    rmin = r2;
                    qnear = c->ph[f];
                }
                if (c->bpq) { /* the same sums per phase */
                    qp[c->ph[f]] += c->p[f] * W;
                    for (k = 0; k < D; ++k)
                        qg[c->ph[f]] += c->rho[f] * (w->a[fD + (size_t)k] - w->b_a[bD + (size_t)k]) * d[k] * W;
                }
            }
            if (parts & SPH__WALL_STATE) {
                for (k = 0; k < D; ++k) sv[k] += c->v[fD + (size_t)k] * W;
                srr += c->rho[f] * c->pc[c->ph[f]].inv_rho0 * W;
            }
        }
        if (parts & SPH__WALL_STATE) {
            w->priv.b_sw[b] = sw;
            for (k = 0; k < D; ++k)
                w->b_vw[bD + (size_t)k] = sw > 0 ? 2 * c->bv[bD + (size_t)k] - sv[k] / sw : c->bv[bD + (size_t)k];
            if (!c->eos_walls) w->b_rho[b] = sw > 0 ? srr / sw : 1;
            if (c->bp_mode != SPH_BP_EXTRAPOLATE) w->b_p[b] = 0;
        }
        if (pressure) {
            sph_real pb = 0, kap = 0;
            if (sw > 0) {
                pb = (swp + sgx) / sw;
                if (c->eos_walls) {
                    for (q = 0; q < c->nphase; ++q)
                        if (wph[q] > 0) kap += wph[q] * sph__eos_inverse(&c->pc[q], pb);
                    w->b_rho[b] = kap / sw;
                }
            } else if (c->eos_walls) {
                w->b_rho[b] = 1;
            }
            w->b_p[b] = pb;
            if (c->bpq) /* per phase, and the phase it stands for (share 1, see sph__phase_walls) */
                for (q = 0; q < c->nphase; ++q) {
                    const sph_real pq = wph[q] > 0 ? (qp[q] + qg[q]) / wph[q] : pb;
                    sph_real* o = c->bpq + ((size_t)b * (size_t)c->nphase + (size_t)q) * SPH__BPQ;
                    o[0] = pq;
                    o[1] = sph__eos_inverse(&c->pc[q], pq);
                    o[2] = q == qnear ? 1 : 0;
                }
        }
    }
}

/* ============================================================================================== */
/* >>stages (implementation)                                                                      */
/* ============================================================================================== */

static void sph__time(sph_world* w, sph_stage s, double* t0) {
    double t = sph__now();
    w->stats.stage_time[s] += t - *t0;
    *t0 = t;
}

/* Sound speeds left at 0 are chosen once, when the phase first has particles: c0 = 10 U with
   U = max(sqrt(2 |g| H), |v|max), so the density varies by about 1 % (Monaghan 1994). U is the
   fastest the phase can move, so H is the height it can fall: its own height (highest particle
   to lowest, along gravity) plus the gap below the whole fluid, from its lowest particle of any
   phase down to the lowest boundary particle less a wall's depth, R + dx (the walls of
   sph_add_wall_box are ceil(R / dx) layers deep, so a fluid resting on them has no gap; a light
   layer over a heavy one falls no further than its own height). Measured without the gap (a 2D
   disc of water, radius 0.15 m, its lowest point 0.55 m above the floor of a 1 m box, dx 0.01,
   the defaults, frames of 0.02 s): c0 was set by the disc's own 0.3 m, 24.3 m/s, the jets of its
   impact on the floor reached 12.2-14.0 m/s, over the incompressible solvers' bound then, 0.5 c0
   (sph__integrate_with), and every solver failed at 0.34 s. With the gap (c0 40.7 m/s) IISPH,
   DFSPH, PBF and both PCISPH run to 1.5 s; WCSPH still fails at 0.36 s, reported: its jets
   (17 m/s) meet the side walls 20 % compressed (def.max_compression). */
static sph_status sph__resolve_sound_speed(sph_world* w) {
    const size_t D = (size_t)w->dim;
    double gmag = 0, ghat[3] = {0, 0, 0}, gap = -1; /* gap < 0: not measured yet */
    size_t b, i;
    int q, k;
    for (k = 0; k < w->dim; ++k) gmag += (double)w->def.gravity[k] * (double)w->def.gravity[k];
    gmag = sqrt(gmag);
    for (k = 0; k < w->dim; ++k) ghat[k] = gmag > 0 ? (double)w->def.gravity[k] / gmag : 0;
    for (q = 0; q < w->nphase; ++q) {
        double smin = 1e300, smax = -1e300, v2max = 0, U, c0;
        size_t count = 0;
        if (w->phases[q].sound_speed > 0 || w->phases[q].eos == SPH_EOS_IDEAL_GAS) continue;
        for (i = 0; i < w->n; ++i) {
            double s = 0, v2 = 0;
            if (w->phase[i] != q) continue;
            ++count;
            for (k = 0; k < w->dim; ++k) {
                s += (double)w->x[i * D + (size_t)k] * ghat[k];
                v2 += (double)w->v[i * D + (size_t)k] * (double)w->v[i * D + (size_t)k];
            }
            if (s < smin) smin = s;
            if (s > smax) smax = s;
            if (v2 > v2max) v2max = v2;
        }
        if (count == 0) continue;
        if (gap < 0) { /* the gap below the fluid: once a call, when a phase is resolved now */
            double sbmax = -1e300, sfmax = -1e300;
            gap = 0;
            for (b = 0; gmag > 0 && b < w->nb; ++b) {
                double s = 0;
                for (k = 0; k < w->dim; ++k) s += (double)w->b_x[b * D + (size_t)k] * ghat[k];
                if (s > sbmax) sbmax = s;
            }
            for (i = 0; w->nb > 0 && gmag > 0 && i < w->n; ++i) {
                double s = 0;
                for (k = 0; k < w->dim; ++k) s += (double)w->x[i * D + (size_t)k] * ghat[k];
                if (s > sfmax) sfmax = s;
            }
            if (sbmax - (double)(w->kernel.radius + w->dx) - sfmax > 0)
                gap = sbmax - (double)(w->kernel.radius + w->dx) - sfmax;
        }
        U = sqrt(2 * gmag * (smax - smin + gap + (double)w->dx));
        if (sqrt(v2max) > U) U = sqrt(v2max);
        c0 = 10 * U;
        if (!(c0 > 0) || !sph__finite(c0))
            return sph__fail(w, SPH_ERR_ARG, -1,
                             "phase %d: sound_speed = 0 asks for an automatic value, but there is "
                             "no gravity and no motion to derive it from; set sph_phase.sound_speed",
                             q);
        w->phases[q].sound_speed = (sph_real)c0;
        w->priv.c0_auto[q] = 1;
    }
    return SPH_OK;
}

/* Hydrostatic initial state: per column (bins of width dx across gravity), pressure integrated
   down from zero at half a spacing above the column's top particle, density from the phase's
   equation of state. */
typedef struct sph__hs_item {
    int64_t bin[2];
    double s;
    size_t i;
} sph__hs_item;

static int sph__hs_cmp(const void* pa, const void* pb) {
    const sph__hs_item* a = (const sph__hs_item*)pa;
    const sph__hs_item* b = (const sph__hs_item*)pb;
    if (a->bin[0] != b->bin[0]) return a->bin[0] < b->bin[0] ? -1 : 1;
    if (a->bin[1] != b->bin[1]) return a->bin[1] < b->bin[1] ? -1 : 1;
    if (a->s != b->s) return a->s > b->s ? -1 : 1; /* top first */
    return a->i < b->i ? -1 : (a->i > b->i ? 1 : 0);
}

SPHDEF sph_status sph_set_hydrostatic(sph_world* w) {
    const size_t D = w ? (size_t)w->dim : 0;
    double gmag = 0, up[3] = {0, 0, 0}, e1[3] = {0, 0, 0}, e2[3] = {0, 0, 0};
    sph__hs_item* it;
    sph__ctx c;
    sph_status s;
    size_t i, a;
    int k;
    if (!w) return SPH_ERR_ARG;
    if (w->n == 0) return SPH_OK;
    for (k = 0; k < w->dim; ++k) gmag += (double)w->def.gravity[k] * (double)w->def.gravity[k];
    gmag = sqrt(gmag);
    if (!(gmag > 0)) return sph__fail(w, SPH_ERR_ARG, -1, "sph_set_hydrostatic: gravity is zero");
    /* positions the host may have written: the columns below are integer bins of x / dx */
    for (i = 0; i < w->n * D; ++i)
        if (!(fabs((double)w->x[i] / (double)w->dx) < 1e15))
            return sph__fail(w, SPH_ERR_ARG, (long)(i / D),
                             "sph_set_hydrostatic: fluid particle %zu (id %u) has a position %g "
                             "that is not finite or beyond 1e15 spacings; the world is unchanged",
                             i / D, (unsigned)w->id[i / D], (double)w->x[i]);
    s = sph__resolve_sound_speed(w);
    if (s != SPH_OK) return s;
    for (k = 0; k < w->dim; ++k) up[k] = -(double)w->def.gravity[k] / gmag;
    /* an orthonormal basis across gravity: e1 from the axis least aligned with up */
    if (w->dim >= 2) {
        int ax = 0;
        double dot = 0, nrm = 0;
        for (k = 1; k < w->dim; ++k) if (fabs(up[k]) < fabs(up[ax])) ax = k;
        e1[ax] = 1;
        dot = up[ax];
        for (k = 0; k < 3; ++k) e1[k] -= dot * up[k];
        for (k = 0; k < 3; ++k) nrm += e1[k] * e1[k];
        nrm = sqrt(nrm);
        for (k = 0; k < 3; ++k) e1[k] /= nrm;
        if (w->dim == 3) {
            e2[0] = up[1] * e1[2] - up[2] * e1[1];
            e2[1] = up[2] * e1[0] - up[0] * e1[2];
            e2[2] = up[0] * e1[1] - up[1] * e1[0];
        }
    }
    it = (sph__hs_item*)SPH_MALLOC(w->n * sizeof(sph__hs_item));
    if (!it) return sph__fail(w, SPH_ERR_NOMEM, -1, "sph_set_hydrostatic: out of memory");
    for (i = 0; i < w->n; ++i) {
        double s1 = 0, s2 = 0, h = 0;
        for (k = 0; k < w->dim; ++k) {
            double xk = (double)w->x[i * D + (size_t)k];
            h += xk * up[k];
            s1 += xk * e1[k];
            s2 += xk * e2[k];
        }
        it[i].bin[0] = (int64_t)floor(s1 / (double)w->dx + 0.5);
        it[i].bin[1] = (int64_t)floor(s2 / (double)w->dx + 0.5);
        it[i].s = h;
        it[i].i = i;
    }
    qsort(it, w->n, sizeof(sph__hs_item), sph__hs_cmp);
    sph__ctx_init(w, &c);
    for (a = 0; a < w->n;) {
        size_t b = a;
        double p = 0;
        while (b < w->n && it[b].bin[0] == it[a].bin[0] && it[b].bin[1] == it[a].bin[1]) ++b;
        for (i = a; i < b; ++i) {
            size_t j = it[i].i;
            const sph__phase_c* P = &c.pc[w->phase[j]];
            double rho0 = (double)w->phases[w->phase[j]].rest_density;
            /* the column's top phase sets the ambient pressure: its back pressure */
            if (i == a) p = (double)w->phases[w->phase[j]].back_pressure + rho0 * gmag * 0.5 * (double)w->dx;
            else {
                size_t jp = it[i - 1].i;
                double rho0p = (double)w->phases[w->phase[jp]].rest_density;
                p += gmag * 0.5 * (rho0 + rho0p) * (it[i - 1].s - it[i].s);
            }
            w->p[j] = (sph_real)p;
            /* weakly compressible: the density the equation of state gives that pressure (a
               gas: on the isentrope through its rest state, and the matching internal energy);
               incompressible solvers: the rest density */
            if (w->def.solver == SPH_SOLVER_WCSPH || w->def.solver == SPH_SOLVER_COMPRESSIBLE) {
                w->rho[j] = P->rho0 * sph__eos_inverse(P, (sph_real)p);
                if (P->gas)
                    w->e[j] = sph__gas_energy(w->p[j], P->gamma, P->pinf, w->rho[j]);
            } else {
                w->rho[j] = P->rho0;
            }
        }
        a = b;
    }
    SPH_FREE(it);
    return SPH_OK;
}

/* A per-particle scratch array of at least `count` reals, kept between steps. */
static sph_status sph__scratch(sph_world* w, sph_real** p, size_t count) {
    size_t* cap = p == &w->priv.rho_n   ? &w->priv.rho_n_cap
                  : p == &w->priv.aii   ? &w->priv.aii_cap
                  : p == &w->priv.cg    ? &w->priv.cg_cap
                  : p == &w->priv.src   ? &w->priv.src_cap
                  : p == &w->priv.ap    ? &w->priv.ap_cap
                  : p == &w->priv.df_alpha   ? &w->priv.df_alpha_cap
                  : p == &w->priv.df_alpha_v ? &w->priv.df_alpha_v_cap
                  : p == &w->priv.df_vs ? &w->priv.df_vs_cap
                  : p == &w->priv.df_kv ? &w->priv.df_kv_cap
                  : p == &w->priv.df_pv ? &w->priv.df_pv_cap
                  : p == &w->priv.ff_fw ? &w->priv.ff_fw_cap
                  : p == &w->priv.fb_fw ? &w->priv.fb_fw_cap
                  : p == &w->priv.pr2   ? &w->priv.pr2_cap
                  : p == &w->priv.vol   ? &w->priv.vol_cap
                  : p == &w->priv.shift ? &w->priv.shift_cap
                  : p == &w->priv.xp    ? &w->priv.xp_cap
                  : p == &w->priv.xs    ? &w->priv.xs_cap
                  : p == &w->priv.vp    ? &w->priv.vp_cap
                  : p == &w->priv.de    ? &w->priv.de_cap
                  : p == &w->priv.cs    ? &w->priv.cs_cap
                  : p == &w->priv.vn    ? &w->priv.vn_cap
                  : p == &w->priv.bpq   ? &w->priv.bpq_cap
                  : p == &w->priv.soc   ? &w->priv.soc_cap
                  : p == &w->priv.socw  ? &w->priv.socw_cap
                  : p == &w->priv.lapc  ? &w->priv.lapc_cap
                  : p == &w->priv.wg    ? &w->priv.wg_cap
                  : p == &w->priv.abody ? &w->priv.abody_cap
                                        : NULL;
    SPH_ASSERT(cap);
    if (count <= *cap && *p) return SPH_OK;
    if (!sph__grow((void**)p, count, sizeof(sph_real)))
        return sph__fail(w, SPH_ERR_NOMEM, -1, "out of memory (solver scratch)");
    *cap = count;
    return SPH_OK;
}

/* Reorders the persistent arrays of a particle set into the order of a grid build. */
static void sph__permute(sph_world* w, const sph__array* arr, int narr, const uint32_t* order,
                         size_t n) {
    int a;
    if (n == 0) return; /* the arrays may still be NULL (a step of an empty world): no memcpy */
    for (a = 0; a < narr; ++a) {
        const size_t e = arr[a].elem;
        uint8_t* src = (uint8_t*)*arr[a].ptr;
        uint8_t* dst = w->priv.perm_buf;
        sph__idx i;
        if (!arr[a].persistent) continue;
        /* fixed-size copies for the common element sizes */
#define SPH__GATHER(SZ)                                                                            \
    SPH__OMP_FOR(n) for (i = 0; i < (sph__idx)n; ++i)                                              \
        memcpy(dst + (size_t)i * (SZ), src + (size_t)order[i] * (SZ), (SZ))
        switch (e) {
        case 1: SPH__GATHER(1); break;
        case 2: SPH__GATHER(2); break;
        case 4: SPH__GATHER(4); break;
        case 8: SPH__GATHER(8); break;
        case 16: SPH__GATHER(16); break;
        case 24: SPH__GATHER(24); break;
        default: SPH__GATHER(e); break;
        }
#undef SPH__GATHER
        memcpy(src, dst, n * e);
    }
}

#ifdef SPH_VALIDATE
/* Brute force: how many of the n points pts lie within radius of p (p itself included). */
static size_t sph__count_within(const sph_grid* g, const sph_real* p, const sph_real* pts,
                                size_t n, sph_real radius) {
    size_t q, count = 0;
    for (q = 0; q < n; ++q) {
        sph_real d[3], r2 = 0;
        int k;
        sph_grid_delta(g, p, pts + q * (size_t)g->dim, d);
        for (k = 0; k < g->dim; ++k) r2 += d[k] * d[k];
        if (r2 < radius * radius) ++count;
    }
    return count;
}
#endif

/* The walls' own neighbour lists within radius (the kernel's support, or def.neighbor_skin's
   candidate radius, whose lists serve the steps that reuse them: the kernel is exactly 0 from its
   support on), for the two per-wall-particle sums below. */
static sph_status sph__wall_lists(sph_world* w, sph_real radius) {
    sph_status s = sph__neighbors_build(&w->priv.bb, &w->priv.bgrid, w->b_x, NULL, w->b_x, w->nb,
                                        radius, 1);
    if (s != SPH_OK)
        return sph__fail(w, s, -1, "boundary neighbour lists: %s", sph_status_string(s));
    return SPH_OK;
}

/* sum_b' W_bb' / norm_w over wall particle b's wall neighbours, b itself included (the thin
   walls' sum, which counts a point sampled twice once, is sph__wall_thin_of's). */
static sph_real sph__wall_kernel_sum(const sph_world* w, size_t b) {
    const int D = w->dim;
    const sph_neighbors* nl = &w->priv.bb;
    size_t kk, k0 = nl->begin[b], k1 = k0 + nl->count[b];
    sph_real sum = sph__kw(w->kernel.form, 0);
    for (kk = k0; kk < k1; ++kk) {
        const size_t q = nl->idx[kk];
        sph_real d[3] = {0, 0, 0}, r2 = 0;
        int k;
        sph_grid_delta(&w->priv.bgrid, w->b_x + b * (size_t)D, w->b_x + q * (size_t)D, d);
        for (k = 0; k < D; ++k) r2 += d[k] * d[k];
        sum += sph__kw(w->kernel.form, sph__sqrt(r2) * w->kernel.inv_h);
    }
    return sum;
}

/* Akinci et al. 2012 (Meiers 2025 eq. 27): a wall particle's volume is gamma_1 over its number
   density among wall particles, V_b = gamma_1 S / sum_b' W_bb' (b itself included; S the
   lattice sum, so a full lattice of wall particles keeps V_b = dx^dim), so sparse or single-layer
   walls weigh as much as a full lattice and dense clusters do not count twice. Recomputed
   whenever the walls are re-sorted (every step when they move). */
static sph_real sph__akinci_volume(const sph_world* w, size_t b) {
    return w->def.boundary_gamma * w->priv.lattice_sum /
           (w->kernel.norm_w * sph__wall_kernel_sum(w, b));
}

static void sph__stage_boundary_volume(sph_world* w) {
    sph__idx b;
    SPH__OMP_FOR(w->nb)
    for (b = 0; b < (sph__idx)w->nb; ++b) w->b_vol[b] = sph__akinci_volume(w, (size_t)b);
}

/* SPH_BVOL_AUTO: each wall particle keeps the larger of its given volume and Akinci's, V_b =
   max(V_b, gamma_1 S / sum_b' W_bb'), once, when walls are added (or loaded). Akinci's volume
   is below dx^dim wherever a lattice wall has several layers (0.585 dx^dim inside, 0.74 on the
   first layer, 0.59 at a 3D box's corner: Wendland C2 at h = 1.3 dx, gamma_1 0.585), so such
   walls keep their given volumes bit for bit (all but the edges and corners of the outermost
   layer of sph_add_wall_box's walls, which lie beyond the fluid's reach); a wall sampled as one
   layer (sum W that of a plane) gets the volume that gives the fluid beside it its rest density
   (1.02 dx^2 on a straight 2D line of Wendland C2 at h = 1.3 dx). Why: with dx^dim a layer
   weighs too little where its particles are sparse (the diagonal gaps of a staircase a host
   samples from a circle: Akinci's volume there is 1.40 dx^dim, its mean over a drum's layer
   1.10 dx^2 in 2D and 1.05 dx^3 in 3D), so the fluid there stays short of density, zero wall
   pressure lets it sink into the layer and the contact pushes it back onto its neighbours.
   Measured on drums of one layer (R 0.3 m, a third full, at rest or turning at 2 rad/s): in 2D
   (dx 0.02) IISPH, DFSPH, both PCISPH and WCSPH failed within 0.05-1.95 s (compressed by 20 %,
   reported); in 3D (dx 0.04) IISPH, DFSPH and PBF let a particle out within 0.35-0.4 s,
   unreported. Where the host samples a wall denser than the fluid, V_b = dx^dim counts the wall's
   volume more than once (a one-layer line at 0.5 dx: Akinci 0.51 dx^2 each, dx^2 weighs it twice),
   so the given volume is capped by d^dim, d the distance to the nearest other wall particle (a
   lattice's spacing: the volume of a lattice at d; for the same point given twice, d = 0, Akinci's
   alone): V_b = max(V_A, min(V_given, d^dim)). A one-layer wall gets Akinci's at any spacing
   (V_A ~ dx s^(dim-1) > s^dim), a lattice of several layers at s < dx its s^dim (V_A, 0.59-0.74
   s^dim, would weigh it too little), and a lattice at dx keeps its given volumes bit for bit (d^dim
   within 3 % of them counts as them). Measured: a 2D tank at rest (0.6 x 0.3 m of water, dx 0.02)
   in walls of one layer 0.5 dx apart jumped at the first step, and its energy rose 0.935 (IISPH),
   0.927 (DFSPH) and 0.041 (PBF) of rho g H^2 W within 0.5 s, every frame SPH_OK; a rule that gave
   Akinci's to pairs closer than 0.7 dx fixed that but left a 3D tank (dx 0.03) in walls of one
   layer 0.75 dx apart gaining 180 J in its first frame (1.7 M g H; 10-16 J at 0.9 dx), unreported,
   and its fluid refused at 0.5 dx as placed inside the walls (sph__check_placed weighed them with
   the given volumes). Now none of these rises (tests/test_reliability.c, dense_host_walls). A
   lattice at dx (sph_add_wall_box) is unchanged. Both rules are idempotent (volumes
   computed again after a load or a re-sort stay as they were); walls a callback moves keep the
   volumes of their positions when added (a rigid motion keeps them right; walls that deform
   want SPH_BVOL_AKINCI). */
/* the squared distance from wall particle b to its nearest other wall particle (the kernel's
   reach squared if none is in reach) */
static sph_real sph__wall_nearest2(const sph_world* w, size_t b) {
    const int D = w->dim;
    const sph_neighbors* nl = &w->priv.bb;
    const size_t k0 = nl->begin[b], k1 = k0 + nl->count[b];
    sph_real near2 = w->kernel.radius * w->kernel.radius;
    size_t kk;
    for (kk = k0; kk < k1; ++kk) {
        sph_real d[3] = {0, 0, 0}, r2 = 0;
        int k;
        sph_grid_delta(&w->priv.bgrid, w->b_x + b * (size_t)D, w->b_x + nl->idx[kk] * (size_t)D, d);
        for (k = 0; k < D; ++k) r2 += d[k] * d[k];
        if (r2 < near2) near2 = r2;
    }
    return near2;
}
/* The rule, per wall particle, from its given volume, Akinci's and the squared distance to its
   nearest wall neighbour: V_b = max(V_A, min(V_given, d^dim)). Also for sph__check_placed's look
   before the first sort. */
static sph_real sph__auto_volume(int dim, sph_real given, sph_real akinci, sph_real near2) {
    const sph_real vs = dim == 1 ? sph__sqrt(near2) : dim == 2 ? near2 : near2 * sph__sqrt(near2);
    const sph_real v = vs < SPH__R(0.97) * given ? vs : given; /* a lattice's rounding: given */
    return akinci > v ? akinci : v;
}
static void sph__stage_boundary_volume_auto(sph_world* w) {
    sph__idx b;
    SPH__OMP_FOR(w->nb)
    for (b = 0; b < (sph__idx)w->nb; ++b)
        w->b_vol[b] = sph__auto_volume(w->dim, w->b_vol[b], sph__akinci_volume(w, (size_t)b),
                                       sph__wall_nearest2(w, (size_t)b));
}

/* Which wall particles form a thin wall (one layer, as a host samples a surface): those whose
   kernel sum over their wall neighbours (themselves included) lies below midway between a
   lattice plane's and a half space's (priv.thin_sum), and every one with Akinci volumes. The 3D
   wall contact keeps the ramp's shorter distance (zero wall pressure's resting rows) for a thick
   wall of given volumes only: the ramp rests on the wall supplying the density a fluid would,
   which a lattice wall of given volumes does; at a thin one every wall particle but the nearest
   keeps d_c, which closes the layer's hollows and gaps (sph__wall_contact). Akinci volumes,
   gamma_1 / sum W calibrated for one layer, give the first layer of a thick lattice wall 0.74
   (Wendland C2) or 0.82 (cubic) of dx^3, and its corners 0.59 or 0.70 (a 3D box of
   sph_add_wall_box, dx 0.02): with the ramp there the original PCISPH sank a particle through
   the first layer at the corner of a 3D box of sph_add_wall_box (dx 0.04, at 0.16 s, reported
   by the tank check); as thin walls it holds. The crossing check (sph__wall_crossed) looks at
   thin walls, in 2D and 3D and with every solver. A point sampled twice (two wall particles
   closer than half a spacing: where two faces a host sampled separately meet) counts once in
   the sum: counted twice, the corner of a box of single layers 1.5 dx apart was not thin, and
   PBF let 2 of 400 particles out through the hole it left in the check
   (tests/test_reliability.c, coarse_host_walls).
   The sum alone calls a layer thick wherever another wall is within the kernel's reach: near
   the edges of a host's box and, in a small one, everywhere (a 3D tank 0.3 x 0.15 m at dx 0.03,
   its faces sampled 0.92-0.95 dx apart: every point), and then PBF let 2 particles a frame out
   through the hollows of a face (reliability/placed_compressed). So a point is thin as well
   when the others within 1.25 dx lie in one plane (a line in 2D; points sampled twice left out),
   or there are none: in 2D the smallest eigenvalue of their second moment about the point is
   below a tenth of the largest, in 3D its determinant over its second invariant (the smallest
   eigenvalue while that is small) below 0.05 of its trace (eigenvalues 0.11 : 2 : 2, a layer
   curved round a radius of three spacings, are thin; 0.3 : 2 : 2 thick). A lattice wall's first
   layer has the point behind it a spacing away (eigenvalues 1 : 2 : 2 in 3D); a face next to
   another face a spacing below has that face's point at its own line (0 : 2 : 2); the edge line
   where two faces meet stays thick (1 : 1 : 2). Static walls only (where the crossing check
   looks): the flags of walls a callback moves are computed again at every sort, and the moments
   made a run with a 3D box of sph_add_wall_box moved so take 1.08 times the CPU time (IISPH,
   2250 fluid and 6504 wall particles, 0.2 s; 1.37 with a pass of their own), so those keep the
   sum's rule. Static walls: once; moved walls: at every sort (a rigid motion keeps the
   flags). */
static int sph__wall_thin_of(const sph_world* w, size_t b, int planar) {
    const int D = w->dim;
    const sph_neighbors* nl = &w->priv.bb;
    const sph_real dx2 = w->dx * w->dx;
    const size_t k0 = nl->begin[b], k1 = k0 + nl->count[b];
    sph_real sum = sph__kw(w->kernel.form, 0);
    double m[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}, tr, lmin;
    size_t kk;
    int k, j;
    for (kk = k0; kk < k1; ++kk) {
        sph_real d[3] = {0, 0, 0}, r2 = 0;
        sph_grid_delta(&w->priv.bgrid, w->b_x + b * (size_t)D, w->b_x + nl->idx[kk] * (size_t)D,
                       d);
        for (k = 0; k < D; ++k) r2 += d[k] * d[k];
        if (!(r2 < SPH__R(0.25) * dx2)) /* the sum: a point sampled twice counts once */
            sum += sph__kw(w->kernel.form, sph__sqrt(r2) * w->kernel.inv_h);
        if (planar && r2 >= SPH__R(0.01) * dx2 && r2 <= SPH__R(1.5625) * dx2) /* the moments */
            for (k = 0; k < D; ++k)
                for (j = 0; j < D; ++j) m[k][j] += (double)d[k] * (double)d[j];
    }
    if ((double)sum < w->priv.thin_sum) return 1;
    if (!planar) return 0;
    tr = m[0][0] + m[1][1] + m[2][2];
    if (!(tr > 0)) return 1; /* no other point within 1.25 dx */
    if (D == 2) {
        const double h = 0.5 * (m[0][0] - m[1][1]);
        lmin = 0.5 * tr - sqrt(h * h + m[0][1] * m[0][1]);
        return lmin <= 0.1 * (tr - lmin);
    } else { /* det / I2, the smallest eigenvalue while it is small, against the trace */
        const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[1][2]) -
                           m[0][1] * (m[0][1] * m[2][2] - m[1][2] * m[0][2]) +
                           m[0][2] * (m[0][1] * m[1][2] - m[1][1] * m[0][2]);
        const double i2 = m[0][0] * m[1][1] + m[0][0] * m[2][2] + m[1][1] * m[2][2] -
                          m[0][1] * m[0][1] - m[0][2] * m[0][2] - m[1][2] * m[1][2];
        return det <= 0.05 * tr * i2;
    }
}

static void sph__wall_thin(sph_world* w) {
    const int akinci = w->def.boundary_volume == SPH_BVOL_AKINCI;
    const int planar = !w->def.boundary_motion; /* static walls (above) */
    sph__idx b;
    SPH__OMP_FOR(w->nb)
    for (b = 0; b < (sph__idx)w->nb; ++b)
        w->priv.b_thin[b] = (uint8_t)(akinci || sph__wall_thin_of(w, (size_t)b, planar));
    w->priv.b_thin_on = 1;
}

/* A grid's cells made `cell` wide, its arrays kept (the periodic box from w.def, as at
   sph_world_init). The cell must leave two cells along a periodic direction. */
static void sph__grid_recell(sph_world* w, sph_grid* g, sph_real cell) {
    const sph_grid keep = *g;
    int per[3];
    sph_status s;
    per[0] = keep.periodic[0];
    per[1] = keep.periodic[1];
    per[2] = keep.periodic[2];
    s = sph_grid_init(g, keep.dim, cell, per, w->def.domain_lo, w->def.domain_hi);
    SPH_ASSERT(s == SPH_OK);
    (void)s;
    g->order = keep.order;
    g->start = keep.start;
    g->key = keep.key;
    g->bucket = keep.bucket;
    g->cap_n = keep.cap_n;
    g->cap_bucket = keep.cap_bucket;
}

/* def.neighbor_skin = -1 (the default): the skin of the explicit steps (WCSPH, compressible),
   whose acoustic step moves a particle a few hundredths of R, so that lists within 1.2 R serve
   10-40 steps; none for PCISPH, IISPH, DFSPH and PBF, whose steps move particles up to
   cfl_velocity = 0.4 dx: a skin would be searched again almost every step, at a larger radius
   (their time to solution 5-10 % longer with a skin of 0.2 R: 2D dam break at 10k particles,
   3D at 6859). 0.1, 0.15 and 0.2 gave WCSPH the same time within the noise (2D dam break to
   t = 0.6 s: 0.785, 0.773 and 0.771 of the time without a skin; 3D to 0.12 s: 0.85 and 0.84). */
#define SPH__SKIN_AUTO SPH__R(0.2)

/* The reach of the candidate lists of a step of `solver` [m]: (1 + skin) R, at most half a
   periodic direction's length (the grid needs two cells there); R: no skin. */
static sph_real sph__verlet_radius_for(const sph_world* w, int solver) {
    const sph_real R = w->kernel.radius;
    const sph_real skin = w->def.neighbor_skin >= 0 ? w->def.neighbor_skin
                          : (solver == SPH_SOLVER_WCSPH || solver == SPH_SOLVER_COMPRESSIBLE)
                              ? SPH__SKIN_AUTO
                              : 0;
    sph_real r = R * (1 + skin);
    int k;
    for (k = 0; k < w->dim; ++k)
        if (w->priv.grid.periodic[k] && r > SPH__R(0.5) * w->priv.grid.len[k])
            r = SPH__R(0.5) * w->priv.grid.len[k];
    return r > R ? r : R;
}

static sph_real sph__verlet_radius(const sph_world* w) {
    return sph__verlet_radius_for(w, w->priv.solver);
}

/* The largest squared distance of a point of x from its place in x0 [m^2] (minimum image along
   periodic directions; a non-finite point counts as far). max does not depend on the order it
   is taken in, so the parallel pass gives the serial result. */
static sph_real sph__max_shift2(const sph_grid* g, const sph_real* x, const sph_real* x0, size_t n) {
    const int D = g->dim, per = g->periodic[0] || g->periodic[1] || g->periodic[2];
    sph_real m = 0;
    sph__idx i;
    if (!per) { /* the common case, inline: no minimum image (3D, 60k wall particles: 1.6 % of
                   a WCSPH step through sph_grid_delta) */
        sph_real m2 = 0;
#if defined(_OPENMP) && _OPENMP >= 201107
#pragma omp parallel for schedule(static) if (n > 4096) reduction(max : m2)
#endif
        for (i = 0; i < (sph__idx)n; ++i) {
            const sph_real* a = x + (size_t)i * (size_t)D;
            const sph_real* b = x0 + (size_t)i * (size_t)D;
            sph_real r2 = (a[0] - b[0]) * (a[0] - b[0]);
            if (D > 1) r2 += (a[1] - b[1]) * (a[1] - b[1]);
            if (D > 2) r2 += (a[2] - b[2]) * (a[2] - b[2]);
            if (!(r2 <= SPH__R(1e30))) r2 = SPH__R(1e30);
            if (r2 > m2) m2 = r2;
        }
        return m2;
    }
#if defined(_OPENMP) && _OPENMP >= 201107
#pragma omp parallel for schedule(static) if (n > 4096) reduction(max : m)
#endif
    for (i = 0; i < (sph__idx)n; ++i) {
        sph_real d[3] = {0, 0, 0}, r2 = 0;
        int k;
        sph_grid_delta(g, x + (size_t)i * (size_t)D, x0 + (size_t)i * (size_t)D, d);
        for (k = 0; k < D; ++k) r2 += d[k] * d[k];
        if (!(r2 <= SPH__R(1e30))) r2 = SPH__R(1e30);
        if (r2 > m) m = r2;
    }
    return m;
}

static int sph__incompressible(int solver);

/* The particles sorted by cell, in cells of `cell` (the grids re-celled if theirs differ): the
   fluid always, the walls when they moved or were added (or re-celled), with their Akinci
   volumes recomputed then. Shared by the search with and without a skin. */
static sph_status sph__sort_by_cell(sph_world* w, sph_real cell) {
    const int akinci = w->def.boundary_volume == SPH_BVOL_AKINCI;
    const int thin = w->dim > 1; /* sph__wall_thin */
    sph__array arr[16];
    sph_status s;
    int narr;
    if (w->priv.grid.cell != cell) sph__grid_recell(w, &w->priv.grid, cell);
    if (w->priv.bgrid.cell != cell) { /* the walls are sorted again into the new cells */
        sph__grid_recell(w, &w->priv.bgrid, cell);
        w->priv.b_dirty = 1;
    }
    s = sph_grid_build(&w->priv.grid, w->x, w->n);
    if (s != SPH_OK) return sph__fail(w, s, -1, "neighbour grid: %s", sph_status_string(s));
    narr = sph__fluid_arrays(w, arr);
    sph__permute(w, arr, narr, w->priv.grid.order, w->n);
    ++w->priv.sorts;
    if (w->nb > 0 && (w->priv.b_dirty || w->def.boundary_motion)) {
        /* walls added, loaded or re-celled (not only moved): SPH_BVOL_AUTO's volumes */
        const int auto_vol = w->def.boundary_volume == SPH_BVOL_AUTO && w->priv.b_dirty;
        w->priv.b_near_on = 0;
        s = sph_grid_build(&w->priv.bgrid, w->b_x, w->nb);
        if (s == SPH_OK)
            s = sph__grid_near(&w->priv.bgrid, &w->priv.b_near, &w->priv.b_near_cap,
                               &w->priv.b_near_on);
        if (s != SPH_OK) return sph__fail(w, s, -1, "boundary grid: %s", sph_status_string(s));
        narr = sph__boundary_arrays(w, arr);
        sph__permute(w, arr, narr, w->priv.bgrid.order, w->nb);
        w->priv.b_thin_on = 0;
        if (akinci || auto_vol || thin) {
            s = sph__wall_lists(w, cell);
            if (s != SPH_OK) return s;
        }
        if (akinci) sph__stage_boundary_volume(w);
        if (auto_vol) sph__stage_boundary_volume_auto(w);
        if (thin) sph__wall_thin(w);
        /* only now: out of memory for the Akinci volumes must leave the walls dirty, or static
           walls would keep their given volumes for good */
        w->priv.b_dirty = 0;
    }
    return SPH_OK;
}

/* Whether the boundary->fluid lists may be read off the fluid->boundary ones
   (sph__neighbors_transpose) instead of searched: without periodic directions the distance test
   of a pair gives the same r^2 from either side (d and -d square alike, summed in the same
   order), and the search of the fluid's dense grid (the fluid in cell order) lists a wall
   particle's neighbours in ascending index, so the lists are the search's, pair for pair and in
   order (tests/test_verlet.c, wall_lists_mirrored). The fluid's hashed grid (sparse fluid) lists
   them in bucket order and is still searched. 3D IISPH dam break, 59k fluid and 150k wall
   particles, 1 thread: the walls' lists 3.6 ms a step searched, 0.55 ms read off. */
static int sph__wall_lists_mirrored(const sph_world* w) {
    return !w->priv.grid.hashed && !w->priv.grid.periodic[0] && !w->priv.grid.periodic[1] &&
           !w->priv.grid.periodic[2];
}

/* The lists fluid->fluid, fluid->boundary and boundary->fluid within r, from the sorted grids. */
static sph_status sph__neighbors_lists(sph_world* w, sph_neighbors* ff, sph_neighbors* fb,
                                       sph_neighbors* bf, sph_real r) {
    sph_status s = sph__neighbors_build_self(ff, &w->priv.ffh, &w->priv.grid, w->x, w->n, r);
    if (s == SPH_OK && w->nb > 0) {
        s = sph__neighbors_build_near(fb, &w->priv.bgrid, w->b_x, NULL, w->x, w->n, r, 0,
                                      w->priv.b_near_on ? w->priv.b_near : NULL);
        if (s == SPH_OK)
            s = sph__wall_lists_mirrored(w)
                    ? sph__neighbors_transpose(bf, fb, w->nb)
                    : sph__neighbors_build(bf, &w->priv.grid, w->x, NULL, w->b_x, w->nb, r, 0);
    }
    if (s != SPH_OK) return sph__fail(w, s, -1, "neighbour lists: %s", sph_status_string(s));
    return SPH_OK;
}

/* def.neighbor_skin's search: the particles sorted by cell (cells of the candidate radius rs),
   candidate lists within rs, and the positions they were built at. */
static sph_status sph__verlet_build(sph_world* w, sph_real rs) {
    const size_t D = (size_t)w->dim;
    sph_status s;
    w->priv.vl_valid = 0;
    /* the build positions' room first: out of memory here changes nothing */
    if (w->n * D > w->priv.vl_x_cap) {
        const size_t cap = w->capacity * D;
        if (!sph__grow((void**)&w->priv.vl_x, cap, sizeof(sph_real)))
            return sph__fail(w, SPH_ERR_NOMEM, -1, "out of memory (neighbour lists)");
        w->priv.vl_x_cap = cap;
    }
    if (w->nb * D > w->priv.vl_bx_cap) {
        const size_t cap = w->b_capacity * D;
        if (!sph__grow((void**)&w->priv.vl_bx, cap, sizeof(sph_real)))
            return sph__fail(w, SPH_ERR_NOMEM, -1, "out of memory (neighbour lists)");
        w->priv.vl_bx_cap = cap;
    }
    s = sph__sort_by_cell(w, rs);
    if (s != SPH_OK) return s;
    s = sph__neighbors_lists(w, &w->priv.cff, &w->priv.cfb, &w->priv.cbf, rs);
    if (s != SPH_OK) return s;
    sph__copy(w->priv.vl_x, w->x, w->n * D * sizeof(sph_real));
    sph__copy(w->priv.vl_bx, w->b_x, w->nb * D * sizeof(sph_real));
    w->priv.vl_valid = 1;
    w->priv.vl_n = w->n;
    w->priv.vl_nb = w->nb;
    w->priv.vl_sorts = w->priv.sorts;
    w->priv.vl_radius = rs;
    ++w->stats.neighbor_builds;
    return SPH_OK;
}

/* A loaded world's candidate lists (sph_world_load, sph_world_copy): searched again at the
   positions of their build, which the file keeps, without sorting; the particles are still in
   the order of that build, so the lists come out as they were and the run continues bit for
   bit. Particles no longer in that order (a host's change) get a new search instead. */
static sph_status sph__verlet_restore(sph_world* w, sph_real rs) {
    const size_t n = w->n, nb = w->nb;
    sph_real* vx = w->priv.vl_x;
    sph_real* vbx = w->priv.vl_bx;
    sph_status s;
    size_t i;
    int in_order = 1;
    if (w->priv.grid.cell != rs) sph__grid_recell(w, &w->priv.grid, rs);
    if (w->priv.bgrid.cell != rs) sph__grid_recell(w, &w->priv.bgrid, rs);
    w->priv.b_near_on = 0;
    s = sph_grid_build(&w->priv.grid, vx, n);
    if (s == SPH_OK && nb > 0) s = sph_grid_build(&w->priv.bgrid, vbx, nb);
    if (s == SPH_OK && nb > 0)
        s = sph__grid_near(&w->priv.bgrid, &w->priv.b_near, &w->priv.b_near_cap, &w->priv.b_near_on);
    if (s != SPH_OK) return sph__fail(w, s, -1, "neighbour grid: %s", sph_status_string(s));
    for (i = 0; i < n && in_order; ++i) in_order = w->priv.grid.order[i] == (uint32_t)i;
    for (i = 0; i < nb && in_order; ++i) in_order = w->priv.bgrid.order[i] == (uint32_t)i;
    if (!in_order) {
        w->priv.vl_restore = 0;
        w->priv.b_dirty = nb > 0;
        return sph__verlet_build(w, rs);
    }
    if (nb > 0 && w->def.boundary_motion && w->def.boundary_volume == SPH_BVOL_AKINCI)
        s = sph__neighbors_build(&w->priv.bb, &w->priv.bgrid, vbx, NULL, vbx, nb, rs, 1);
    if (s == SPH_OK)
        s = sph__neighbors_build_self(&w->priv.cff, &w->priv.ffh, &w->priv.grid, vx, n, rs);
    if (s == SPH_OK && nb > 0) {
        s = sph__neighbors_build_near(&w->priv.cfb, &w->priv.bgrid, vbx, NULL, vx, n, rs, 0,
                                      w->priv.b_near_on ? w->priv.b_near : NULL);
        if (s == SPH_OK)
            s = sph__wall_lists_mirrored(w)
                    ? sph__neighbors_transpose(&w->priv.cbf, &w->priv.cfb, nb)
                    : sph__neighbors_build(&w->priv.cbf, &w->priv.grid, vx, NULL, vbx, nb, rs, 0);
    }
    if (s != SPH_OK) return sph__fail(w, s, -1, "neighbour lists: %s", sph_status_string(s));
    w->priv.b_dirty = 0;
    w->priv.vl_valid = 1;
    w->priv.vl_sorts = w->priv.sorts;
    w->priv.vl_restore = 0;
    return SPH_OK;
}

/* Verlet lists (Verlet 1967; Allen & Tildesley 1987 sec. 5.3): candidate lists within
   rs = R + s hold every pair within R while no particle has moved s/2 since their build (two
   particles then came at most s closer). They are searched again when one has (fluid or
   boundary, by the motion callback or the host), when particles were added or reordered
   (sph_advance's rollback, the second-order scheme, a load), when the walls changed or the
   skin did; else each step keeps of them the pairs within R, in ff, fb and bf, which are then
   exactly the lists a search would give (in another order: the particles are sorted by cell
   only at a search), so every pair loop sees the same pairs either way. */
static sph_status sph__stage_neighbors_skin(sph_world* w, sph_real rs) {
    const sph_real R = w->kernel.radius, half = SPH__R(0.5) * (rs - R);
    sph_status s;
    int reuse;
    if (w->priv.vl_restore) {
        if (w->priv.vl_radius == rs && w->priv.vl_n == w->n && w->priv.vl_nb == w->nb) {
            s = sph__verlet_restore(w, rs);
            if (s != SPH_OK) return s;
        }
        w->priv.vl_restore = 0;
    }
    reuse = w->priv.vl_valid && w->priv.vl_n == w->n && w->priv.vl_nb == w->nb &&
                w->priv.vl_sorts == w->priv.sorts && w->priv.vl_radius == rs && !w->priv.b_dirty;
    if (reuse) {
        sph_real m2 = sph__max_shift2(&w->priv.grid, w->x, w->priv.vl_x, w->n);
        if (w->nb > 0) {
            const sph_real b2 = sph__max_shift2(&w->priv.bgrid, w->b_x, w->priv.vl_bx, w->nb);
            if (b2 > m2) m2 = b2;
        }
        reuse = m2 < half * half;
    }
    if (!reuse) {
        s = sph__verlet_build(w, rs);
        if (s != SPH_OK) return s;
    } else if (w->nb > 0 && w->def.boundary_motion && w->def.boundary_volume == SPH_BVOL_AKINCI) {
        /* moved walls, not sorted again: their volumes from the kept wall lists */
        sph__stage_boundary_volume(w);
    }
    s = sph__neighbors_filter(&w->priv.ff, &w->priv.cff, &w->priv.grid, w->x, w->x, R);
    if (s == SPH_OK && w->nb > 0) {
        s = sph__neighbors_filter(&w->priv.fb, &w->priv.cfb, &w->priv.bgrid, w->b_x, w->x, R);
        if (s == SPH_OK)
            s = sph__neighbors_filter(&w->priv.bf, &w->priv.cbf, &w->priv.grid, w->x, w->b_x, R);
    }
    if (s != SPH_OK) {
        w->priv.vl_valid = 0;
        return sph__fail(w, s, -1, "neighbour lists: %s", sph_status_string(s));
    }
    return SPH_OK;
}

/* Sort fluid (and moving boundary) particles by cell, then build the lists fluid->fluid,
   fluid->boundary and boundary->fluid within R (no skin). */
static sph_status sph__stage_neighbors_search(sph_world* w, sph_real R) {
    sph_status s;
    w->priv.vl_valid = 0;
    w->priv.vl_restore = 0;
    ++w->stats.neighbor_builds;
    s = sph__sort_by_cell(w, R); /* cells of R (a skin, if one was on, had larger cells) */
    if (s != SPH_OK) return s;
    return sph__neighbors_lists(w, &w->priv.ff, &w->priv.fb, &w->priv.bf, R);
}

/* Neighbours stage: the lists fluid->fluid, fluid->boundary and boundary->fluid once for the
   whole step, searched (and the particles sorted by cell) every step, or with
   def.neighbor_skin filtered from candidate lists kept between steps. */
static sph_status sph__stage_neighbors(sph_world* w) {
    const sph_real R = w->kernel.radius, rs = sph__verlet_radius(w);
    sph_status s = rs > R ? sph__stage_neighbors_skin(w, rs) : sph__stage_neighbors_search(w, R);
    if (s != SPH_OK) return s;
    w->stats.pairs = w->priv.ff.total;
#ifdef SPH_VALIDATE
    { /* every fluid pair is listed from both sides; and now and then (small worlds) the lists
         hold exactly the pairs a brute-force search finds */
        size_t i, kk, q;
        for (i = 0; i < w->n; ++i) {
            for (kk = w->priv.ff.begin[i]; kk < w->priv.ff.begin[i] + w->priv.ff.count[i]; ++kk) {
                size_t j = w->priv.ff.idx[kk], found = 0;
                for (q = w->priv.ff.begin[j]; q < w->priv.ff.begin[j] + w->priv.ff.count[j]; ++q)
                    if (w->priv.ff.idx[q] == i) found = 1;
                SPH_ASSERT(found && j != i);
            }
        }
        if (w->steps % 97 == 0 && w->n <= 5000 && w->nb <= 5000) {
            for (i = 0; i < w->n; ++i) {
                const sph_real* xi = w->x + i * (size_t)w->dim;
                const size_t nf = sph__count_within(&w->priv.grid, xi, w->x, w->n, R) - 1;
                const size_t nbd = sph__count_within(&w->priv.grid, xi, w->b_x, w->nb, R);
                SPH_ASSERT(nf == w->priv.ff.count[i]);
                SPH_ASSERT(w->nb == 0 || nbd == w->priv.fb.count[i]);
            }
        }
    }
#endif
    return SPH_OK;
}

/* sum_b V_b w(|x - x_b| / h) over fluid particle i's wall list at position x (w without the
   kernel's norm): the walls' share of a summation density (the density stage, PBF's last pass,
   check_walls' wall fraction); with fw_out set, each pair's grad W factor from the same q. */
SPH__INLINE sph_real sph__wall_sum(const sph__ctx* c, size_t i, const sph_real* x, const int D,
                                   const int form, sph_real* fw_out) {
    sph_real sum = 0, q;
    size_t kk, k0 = c->fb->begin[i], k1 = k0 + c->fb->count[i];
    int k;
    for (kk = k0; kk < k1; ++kk) {
        const size_t b = c->fb->idx[kk];
        sph_real d[3] = {0, 0, 0}, r2 = 0;
        sph__delta_vec(c, x, c->bx + b * (size_t)D, d, D);
        SPH__FOR_K(D, r2 += d[k] * d[k]);
        q = sph__sqrt(r2) * c->k.inv_h;
        sum += c->bvol[b] * sph__kw(form, q);
        if (fw_out) fw_out[kk] = c->k.norm_g * sph__kf(form, q);
    }
    return sum;
}

#define SPH__ROW 64 /* neighbours per batch of sph__density_row and sph__accel_row */

/* sph__density_one's fluid sum on the fast path (one mass, no periodic direction; Wendland C2
   or the cubic spline), in rows of SPH__ROW neighbours as sph__accel_row: the square root and
   both kernel functions in packed lanes, the cubic's two pieces computed in every lane and the
   one that applies kept (lanes outside a piece are masked to +0, and x + (+0) is x), then the
   masses summed in list order. The same expressions in the same order as sph__kw and sph__kf,
   so the same bits, without the scalar loop's branch on q < 1 per pair. Returns
   sum_j m_j W_ij / norm_w (every m_j = m0 here) and stores the grad W factors. */
SPH__INLINE sph_real sph__density_row(const sph__ctx* c, size_t i, const int D, const int form) {
    const sph_real* xi = c->x + i * (size_t)D;
    const sph_real far = 4 * c->k.radius * c->k.radius; /* padding lanes: beyond the support */
    const sph__v v_inv_h = sph__vset(c->k.inv_h), v_norm = sph__vset(c->k.norm_g);
    const sph__v v_one = sph__vset(1), v_two = sph__vset(2), v_half = sph__vset(SPH__R(0.5));
    const sph__v v_m5 = sph__vset(-5), v_c15 = sph__vset(SPH__R(1.5));
    const sph__v v_c075 = sph__vset(SPH__R(0.75)), v_c025 = sph__vset(SPH__R(0.25));
    const sph__v v_m3 = sph__vset(-3), v_c225 = sph__vset(SPH__R(2.25));
    const sph__v v_mc075 = sph__vset(SPH__R(-0.75));
    sph_real r2[SPH__ROW + SPH__VN], wq[SPH__ROW + SPH__VN], fo[SPH__ROW + SPH__VN], sum = 0;
    size_t b0, k0 = c->ff->begin[i], k1 = k0 + c->ff->count[i];
    int k;
    for (b0 = k0; b0 < k1; b0 += SPH__ROW) {
        const size_t nb = k1 - b0 < SPH__ROW ? k1 - b0 : SPH__ROW;
        size_t m;
        for (m = 0; m < nb; ++m) {
            const sph_real* xj = c->x + c->ff->idx[b0 + m] * (size_t)D;
            sph_real d[3] = {0, 0, 0}, rr = 0;
            SPH__FOR_K(D, d[k] = xi[k] - xj[k]);
            SPH__FOR_K(D, rr += d[k] * d[k]);
            r2[m] = rr;
        }
        for (; m % SPH__VN; ++m) r2[m] = far;
        for (m = 0; m < nb; m += SPH__VN) {
            const sph__v q = sph__vmul(sph__vsqrt(sph__vload(r2 + m)), v_inv_h);
            const sph__v in2 = sph__vlt(q, v_two);
            sph__v W, F;
            if (form == SPH__KF_CUBIC) {
                const sph__v in1 = sph__vlt(q, v_one), t = sph__vsub(v_two, q);
                /* q < 1: 1 - 1.5 q q + 0.75 q q q and -3 + 2.25 q */
                const sph__v W1 = sph__vadd(sph__vsub(v_one, sph__vmul(sph__vmul(v_c15, q), q)),
                                            sph__vmul(sph__vmul(sph__vmul(v_c075, q), q), q));
                const sph__v F1 = sph__vadd(v_m3, sph__vmul(v_c225, q));
                /* 1 <= q < 2: 0.25 t t t and -0.75 t t / q, t = 2 - q */
                const sph__v W2 = sph__vmul(sph__vmul(sph__vmul(v_c025, t), t), t);
                const sph__v F2 = sph__vdiv(sph__vmul(sph__vmul(v_mc075, t), t), q);
                W = sph__vadd(sph__vand(in1, W1), sph__vandnot(in1, sph__vand(in2, W2)));
                F = sph__vadd(sph__vand(in1, F1), sph__vandnot(in1, sph__vand(in2, F2)));
            } else { /* Wendland C2: t = 1 - q/2; t^2 t^2 (2 q + 1) and -5 t t t */
                const sph__v t = sph__vsub(v_one, sph__vmul(v_half, q)), t2 = sph__vmul(t, t);
                const sph__v p1 = sph__vadd(sph__vmul(v_two, q), v_one);
                W = sph__vand(in2, sph__vmul(sph__vmul(t2, t2), p1));
                F = sph__vand(in2, sph__vmul(sph__vmul(sph__vmul(v_m5, t), t), t));
            }
            sph__vstore(wq + m, W);
            /* the factors straight to the cache, the padded last lanes through a buffer */
            if (c->ff_fw_out && m + SPH__VN <= nb)
                sph__vstore(c->ff_fw_out + b0 + m, sph__vmul(v_norm, F));
            else
                sph__vstore(fo + m, sph__vmul(v_norm, F));
        }
        if (c->ff_fw_out)
            for (m = nb - nb % SPH__VN; m < nb; ++m) c->ff_fw_out[b0 + m] = fo[m];
        for (m = 0; m < nb; ++m) sum += c->m0 * wq[m];
    }
    return sum;
}

/* rho_i of one particle; D and the kernel form compile-time constants where the stage knows
   them (the loops over k unroll and d[] stays in registers: 3D IISPH's density stage x2). With
   c->ff_fw_out set (IISPH, DFSPH) it also keeps every pair's grad W factor from the same q, for
   the passes of the step that would evaluate the kernel again. */
SPH__INLINE sph_real sph__density_one(const sph__ctx* c, size_t i, const int D, const int form,
                                      sph_real w0, sph_real S, const int fast) {
    const sph_real* xi = c->x + i * (size_t)D;
    const sph_real mi = c->m ? c->m[i] : c->m0;
    sph_real sum = 0, sumb = 0, q;
    size_t kk, k0 = c->ff->begin[i], k1 = k0 + c->ff->count[i];
    int k;
    if (fast) sum = sph__density_row(c, i, D, form);
    else for (kk = k0; kk < k1; ++kk) {
        const size_t j = c->ff->idx[kk];
        sph_real d[3] = {0, 0, 0}, r2 = 0;
        sph__delta_vec(c, xi, c->x + j * (size_t)D, d, D);
        SPH__FOR_K(D, r2 += d[k] * d[k]);
        q = sph__sqrt(r2) * c->k.inv_h;
        sum += (c->m ? c->m[j] : c->m0) * sph__kw(form, q);
        if (c->ff_fw_out) c->ff_fw_out[kk] = c->k.norm_g * sph__kf(form, q);
    }
    if (c->has_b) sumb = sph__wall_sum(c, i, xi, D, form, c->fb_fw_out);
    return (mi * w0 + c->k.norm_w * (sum + c->pc[c->ph[i]].rho0 * sumb)) / S;
}

/* Summation density (Enhanced PCISPH 2018 eq. 2.4), walls as psi = rho0_i V_b (Akinci et al. 2012):
       rho_i = (m_i W(0) + sum_f m_f W_if + sum_b rho0_i V_b W_ib) / S,
   S = the kernel's lattice sum (sph__lattice_sum): a particle lattice at spacing dx then has the
   rest density exactly, instead of 1 % more for Wendland C2 at h = 1.3 dx, which an incompressible
   solver would remove by expanding the fluid (Meiers 2025's reference code scales W the same way). */
static void sph__stage_density_summation(sph_world* w, const sph__ctx* c) {
    const int D = c->dim, form = c->k.form, wc2 = form == SPH__KF_WC2;
    const int cub = form == SPH__KF_CUBIC; /* 3D IISPH, DFSPH and PBF by default */
    const int fast = !c->m && !c->periodic_any && (wc2 || cub); /* sph__density_row */
    const sph_real w0 = c->k.norm_w * sph__kw(c->k.form, 0), S = w->priv.lattice_sum;
    sph__idx i;
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)w->n; ++i) {
        const size_t q = (size_t)i;
        w->rho[i] = D == 3 ? (wc2   ? sph__density_one(c, q, 3, SPH__KF_WC2, w0, S, fast)
                              : cub ? sph__density_one(c, q, 3, SPH__KF_CUBIC, w0, S, fast)
                                    : sph__density_one(c, q, 3, form, w0, S, 0))
                  : D == 2 ? (wc2   ? sph__density_one(c, q, 2, SPH__KF_WC2, w0, S, fast)
                              : cub ? sph__density_one(c, q, 2, SPH__KF_CUBIC, w0, S, fast)
                                    : sph__density_one(c, q, 2, form, w0, S, 0))
                           : sph__density_one(c, q, 1, form, w0, S, 0);
    }
}

static void sph__stage_eos(sph_world* w, const sph__ctx* c) {
    const int clamp = sph__clamps(w);
    sph__idx i;
    if (c->cs) { /* compressible step: gases from (rho, e), and every particle's sound speed */
        SPH__OMP_FOR(w->n)
        for (i = 0; i < (sph__idx)w->n; ++i) {
            const sph__phase_c* P = &c->pc[c->ph[i]];
            const sph_real rho = w->rho[i];
            sph_real p, c2;
            if (P->gas) p = (P->gamma - 1) * rho * c->e[i] - P->gamma * P->pinf;
            else p = sph__eos(P, rho);
            c2 = P->eos == SPH_EOS_LINEAR ? P->c0 * P->c0 : P->gamma * (p + P->ck) / rho;
            w->priv.cs[i] = c2 > 0 ? sph__sqrt(c2) : 0;
            w->p[i] = clamp && p < 0 ? 0 : p;
        }
        return;
    }
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)w->n; ++i) {
        const sph_real p = sph__eos(&c->pc[c->ph[i]], w->rho[i]);
        w->p[i] = clamp && p < 0 ? 0 : p;
    }
}

/* The normalisation of Morris' Laplacian, per fluid particle (laminar viscosity, SPH_VISC_MORRIS).
   Morris et al. 1997's term (see VISCOUS below) for particle i is sum_j K_ij (v_i - v_j),
   K_ij = m_j (mu_i + mu_j)/(rho_i rho_j) F_ij r_ij^2/(r_ij^2 + eta^2), grad W_ij = F_ij x_ij
   (F < 0). On a field with Hessian H (v_j - v_i = x_ji . grad v + 1/2 x_ji x_ji : H + ...), where
   the neighbourhood's first moment vanishes, it gives nu T_i : H with the second-moment tensor
       T_i = -sum_j V_j F_ij r_ij^2/(r_ij^2 + eta^2) x_ij (x) x_ij,   V_j = m_j / rho_j [-],
   so nu m_i Lap v when T_i = m_i I (a square or cubic lattice, a flat wall continuing it). Its
   continuous limit is exactly I (-(1/d) integral of r W'(r) dV = integral of W dV = 1, by parts),
   but the discrete sum is not: m = 0.963 on a square lattice with Wendland C2 at h = 1.3 dx, at
   any resolution (the quadrature error of a fixed h/dx), which made plane Poiseuille flow 4 % too
   fast at 20 and at 40 particles across. The pass measures
       m_i = tr T_i / d   [-],
   over the particle's own fluid and wall neighbours (walls with the volume V_b / kappa_b they
   have in the viscous term, free-slip walls included: m_i describes the particle arrangement, not
   the boundary condition), and the viscous term uses the pair factor (1/m_i + 1/m_j)/2 (1/m_i
   against walls). Then a quadratic field's Laplacian is reproduced wherever T_i is isotropic;
   the factor is symmetric in i and j, so fluid-fluid forces stay pairwise antisymmetric and
   momentum is conserved as before; m_i tends to 1 as h/dx grows (it is measured, not a lattice
   constant), and the pass is a light neighbour loop (positions and densities, no velocities)
   before each viscous pass. A particle with a truncated neighbourhood (free surface, splash) has m_i < 1, and
   the correction also restores part of what its missing neighbours took: on the top row of a
   square lattice (Wendland C2, h = 1.3 dx) m = 0.62, and the term gives 0.78 instead of 0.48 of
   the Laplacian of u(y) across the surface, 1.22 instead of 0.75 along it. m_i -> 0 for a
   particle with only far or no neighbours, so 1/m_i is bounded by 2: the largest eigenvalue of
   the viscous operator grows at most twice (1/0.963 in a lattice's interior), within the margin
   of def.cfl_viscous (a lattice is stable to dt = 0.29 h^2/nu for this form without the factor,
   see sph_stable_dt, so to 0.145 with the bound; the default is 0.125). [writes w->priv.lapc, 1 / m_i] */
static int sph__visc_norm_used(const sph_world* w) {
    int q;
    if (w->def.viscosity_form != SPH_VISC_MORRIS) return 0;
    for (q = 0; q < w->nphase; ++q)
        if (w->phases[q].viscosity > 0) return 1;
    return 0;
}

/* The wall's density relative to rest as fluid particle i of relative density rhati sees it (the
   boundary scheme's, see sph__interact_one). */
SPH__INLINE sph_real sph__wall_kappa(const sph__ctx* c, size_t b, size_t i, sph_real rhati) {
    if (c->bpq) return c->bpq[((size_t)b * (size_t)c->nphase + c->ph[i]) * SPH__BPQ + 1];
    return c->bp_mode == SPH_BP_EXTRAPOLATE ? c->brho[b] : rhati;
}

/* m_i for one particle; D and cached compile-time constants (the pass is specialised per
   dimension, as sph__stage_interact's are: the loop over k unrolls and d[] stays in registers).
   cached (the viscous pass is SPH__CACHED: IISPH, DFSPH): the density summation at these
   positions kept every listed pair's grad W factor fw = norm_g F in c->ff_fw / fb_fw, so the
   pair reads it instead of a square root and the kernel (3D IISPH at 59k particles, cubic
   spline: the pass x2.7); otherwise (WCSPH, PCISPH) it evaluates F and multiplies by norm_g
   once at the end. The two differ by rounding only. fast (a compile-time constant, as
   sph__interact_one's): one mass and no periodic direction, so the per-pair tests fold away. */
SPH__INLINE sph_real sph__visc_norm_one(const sph__ctx* c, size_t i, const int D,
                                        const int cached, const int fast) {
    const sph_real* xi = c->x + i * (size_t)D;
    const sph_real rhati = c->rho[i] * c->pc[c->ph[i]].inv_rho0;
    const sph_real* const cm = fast ? NULL : c->m; /* fast: one mass, no periodic direction */
    const int per = fast ? 0 : c->periodic_any, form = c->k.form;
    sph_real S = 0; /* sum_j V_j (-F_ij) r^4/(r^2 + eta^2) = d m_i, the factor norm_g in F when
                       cached, else applied at the end */
    size_t kk, k0 = c->ff->begin[i], k1 = k0 + c->ff->count[i];
    int k;
    for (kk = k0; kk < k1; ++kk) {
        const size_t j = c->ff->idx[kk];
        const sph_real mj = cm ? cm[j] : c->m0;
        sph_real d[3] = {0, 0, 0}, r2 = 0;
        sph__delta_vec_p(c, per, xi, c->x + j * (size_t)D, d, D);
        SPH__FOR_K(D, r2 += d[k] * d[k]);
        S -= mj / c->rho[j] * (cached ? c->ff_fw[kk] : sph__kf(form, sph__sqrt(r2) * c->k.inv_h)) *
             r2 * r2 / (r2 + c->eta2);
    }
    if (c->has_b) {
        k0 = c->fb->begin[i];
        k1 = k0 + c->fb->count[i];
        for (kk = k0; kk < k1; ++kk) {
            const size_t b = c->fb->idx[kk];
            sph_real d[3] = {0, 0, 0}, r2 = 0;
            sph__delta_vec_p(c, per, xi, c->bx + b * (size_t)D, d, D);
            SPH__FOR_K(D, r2 += d[k] * d[k]);
            S -= c->bvol[b] / sph__wall_kappa(c, b, i, rhati) *
                 (cached ? c->fb_fw[kk] : sph__kf(form, sph__sqrt(r2) * c->k.inv_h)) * r2 * r2 /
                 (r2 + c->eta2);
        }
    }
    return (cached ? S : S * c->k.norm_g) / (sph_real)D;
}

/* [writes w->priv.lapc] cached: as sph__visc_norm_one's, the viscous pass's SPH__CACHED. */
static void sph__stage_visc_norm(sph_world* w, const sph__ctx* c, int cached) {
    const int D = c->dim, fast = !c->m && !c->periodic_any;
    sph__idx i;
    SPH_ASSERT(c->lapc && w->priv.lapc_cap >= w->n);
    SPH_ASSERT(!cached || (c->ff_fw && (c->fb_fw || !c->has_b)));
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)w->n; ++i) {
        const size_t q = (size_t)i;
        const sph_real m =
            D == 2   ? (!cached ? sph__visc_norm_one(c, q, 2, 0, 0)
                        : fast  ? sph__visc_norm_one(c, q, 2, 1, 1)
                                : sph__visc_norm_one(c, q, 2, 1, 0))
            : D == 3 ? (!cached ? sph__visc_norm_one(c, q, 3, 0, 0)
                        : fast  ? sph__visc_norm_one(c, q, 3, 1, 1)
                                : sph__visc_norm_one(c, q, 3, 1, 0))
                     : sph__visc_norm_one(c, q, 1, cached, 0);
        w->priv.lapc[i] = m > SPH__R(0.5) ? 1 / m : 2;
    }
}

/* What a pass of the neighbour loop computes: pressure acceleration, viscous acceleration,
   density rate; SET overwrites the acceleration output instead of adding to it; ENERGY (with
   PRESSURE, VISCOUS and RATE) computes the internal energy rate instead of an acceleration.
   CACHED reads the grad W factor of every listed pair from c->ff_fw / fb_fw instead of
   evaluating the kernel; STORE writes the factors it evaluates to c->ff_fw_out / fb_fw_out, for
   a later pass at the same positions (WCSPH's density rate after its forces). */
enum { SPH__PRESSURE = 1, SPH__VISCOUS = 2, SPH__RATE = 4, SPH__SET = 8, SPH__CACHED = 16,
       SPH__ENERGY = 32, SPH__STORE = 64 };
#define SPH__ACCEL (SPH__PRESSURE | SPH__VISCOUS)

/* The one neighbour loop for accelerations and the density rate of fluid particle i.
   PRESSURE: sum_j m_j (p_i/rho_i^2 + p_j/rho_j^2) grad W_ij (Enhanced PCISPH 2018 sec. 2.2.1), or
          the multiphase form (p_i + p_j)/(rho_i rho_j) (Ott & Schnetter eq. 12); a wall particle is
          a particle of mass psi_ib with the pressure and density of the chosen boundary scheme
          (extrapolated; mirrored p_b = p_i, rho_b = rho_i; or p_b = 0). [m/s^2]
   VISCOUS: laminar viscosity (Morris et al. 1997: sum_j m_j (mu_i + mu_j)/(rho_i rho_j)
          x_ij.grad W_ij/(r^2+eta^2) v_ij, which needs only the second moment of grad W to give
          nu Lap v, 0.96 of it on a lattice with Wendland C2 at h = 1.3 dx, so each pair is
          multiplied by (1/m_i + 1/m_j)/2, m the measured moment (sph__stage_visc_norm); or Monaghan 2005 /
          Enhanced PCISPH 2018 eq. 2.5, 2(d+2) sum_j m_j nu_bar/rho_bar v_ij.x_ij/(r^2+eta^2) grad
          W, which conserves angular momentum but needs the fourth moment: 0.80 of nu Lap v on the
          same lattice) and Monaghan 1992 artificial viscosity Pi_ij = (-alpha c_bar mu_ij +
          beta mu_ij^2)/rho_bar, mu_ij = h v_ij.x_ij/(r^2+eta^2) when v_ij.x_ij < 0, c_bar the
          mean of the phases' c0 (of the particles' own sound speeds in the compressible step).
          [m/s^2]
   RATE:  continuity d rho_i/dt = sum_j m_j v_ij . grad W_ij (Enhanced PCISPH 2018 eq. 2.2), or
          m_i in place of m_j (Ott & Schnetter eq. 11), plus delta-SPH diffusion (Molteni &
          Colagrossi 2009; Enhanced PCISPH 2018 sec. 3.2.1) written with densities relative to
          each phase's rest density:
          delta h c0 sum_j 2 rho0_i V_j (rho_i/rho0_i - rho_j/rho0_j) x_ij.grad W_ij/(r^2+eta^2),
          which is the thesis' term for one phase and does not diffuse across a phase interface.
          Walls enter with their own velocity (a moving wall compresses). [kg/m^3/s]
   ENERGY: every pairwise acceleration above is m_j f_ij with f_ij = -f_ji, so the work of the
          pair goes half to each side: de_i/dt = -1/2 sum_j m_j f_ij . v_ij, which for pressure
          and artificial viscosity is Ott & Schnetter's eq. 13,
              de_i/dt = 1/2 sum_j m_j (P_ij + Pi_ij) v_ij . grad W_ij   [J/kg/s],
          P_ij the pressure term of the chosen gradient form. The forces are those of the
          force pass (velocities c->vn, pressures unchanged since), dotted with the mean
          velocity of the step (vn + v)/2: then the internal energy gains exactly the kinetic
          energy the kick took, and total energy is conserved to round-off. The density rate of
          the same pass uses the new velocity v (see the WCSPH step for why). */
/* Hu & Adams' pair term of SPH_PGRAD_INTERFACE: -(V_i^2 + V_j^2)/m_i p_ij, the factor of
   grad W_ij in the acceleration of i. */
SPH__INLINE sph_real sph__pgrad_interface(sph_real mi, sph_real rhoi, sph_real pi, sph_real mj,
                                          sph_real rhoj, sph_real pj) {
    const sph_real Vi = mi / rhoi, Vj = mj / rhoj;
    return -(Vi * Vi + Vj * Vj) / mi * (rhoj * pi + rhoi * pj) / (rhoi + rhoj);
}

/* SPH_PGRAD_VOLUME's pair term: -(V_i^2 p_i + V_j^2 p_j)/m_i, the factor of grad W_ij in the
   acceleration of i. With V = 1/n this is -(p_i/n_i^2 + p_j/n_j^2)/m_i, the form a Lagrangian
   sum_i m_i (v_i^2/2 - u_i(n_i)) gives when n_i = sum_j W_ij (Hu & Adams 2006): its work on a
   pair, (p_i V_i^2 + p_j V_j^2) v_ij . grad W_ij, is what particle-density continuity (Ott &
   Schnetter 2003 eq. 10: dV_i/dt = -V_i^2 sum_j v_ij . grad W_ij) takes from the internal energy
   p dV, so energy is exchanged only between a particle and its own pressure. Hu & Adams'
   density-weighted pair pressure (SPH_PGRAD_INTERFACE) breaks that pairing: at a 1000:1
   interface the air sees its own pressure across a water pair, the water the air's, and the
   work done on one side is not the work taken from the other. Measured (tests/
   test_compressible.c, water under air in the compressible step): the interface form breaks up
   after about 2 s (periodic sides) or 1.5 s (side walls); this form holds for 10 s with side
   walls (water at most 0.018 sqrt(g H)), and with periodic sides (hexagonal lattice) the speeds
   fall to 0.0014 sqrt(g H) by 5 s (a driver, not in the tests). */
SPH__INLINE sph_real sph__pgrad_volume(sph_real mi, sph_real rhoi, sph_real pi, sph_real mj,
                                       sph_real rhoj, sph_real pj) {
    const sph_real Vi = mi / rhoi, Vj = mj / rhoj;
    return -(Vi * Vi * pi + Vj * Vj * pj) / mi;
}

/* The pressure term of fluid particle i (mass mi, density rhoi, pressure pi, pi_r2 = pi / rhoi^2)
   with a wall particle that stands for fluid of mass psi, density rhob and pressure pb: the
   factor of grad W_ib in i's acceleration, in the form def.pressure_grad gives fluid pairs. */
SPH__INLINE sph_real sph__wall_pterm(const sph__ctx* c, int pgrad, sph_real mi, sph_real rhoi,
                                     sph_real inv_rhoi, sph_real pi, sph_real pi_r2, sph_real psi,
                                     sph_real rhob, sph_real pb) {
    if (pgrad == SPH_PGRAD_SYMMETRIC) return -psi * (pi_r2 + pb / (rhob * rhob));
    if (pgrad == SPH_PGRAD_MULTIPHASE) return -psi * (pi + pb) * inv_rhoi / rhob * c->pg_norm;
    if (pgrad == SPH_PGRAD_DIFFERENCE) return -psi * (pb - pi) * inv_rhoi / rhob;
    if (pgrad == SPH_PGRAD_VOLUME) return sph__pgrad_volume(mi, rhoi, pi, psi, rhob, pb) * c->pg_norm;
    return sph__pgrad_interface(mi, rhoi, pi, psi, rhob, pb) * c->pg_norm;
}

/* delta-SPH's difference for a pair of different phases (i's phase P). In a fluid at rest the
   pressure is continuous across an interface and each phase's equation of state turns it into
   its own relative density, so rho/rho0 jumps there (by p (1/(rho0_i c_i^2) - 1/(rho0_j c_j^2))
   to first order: 1 % at a 3:1 interface under 3 Pa with c0 = 14 m/s). Diffusing rho/rho0 across
   the interface, as within a phase, would drive that jump to zero against the pressure balance
   for as long as the fluid rests: a standing flow along the interface (measured on a flat 3:1
   interface, WCSPH, particle density, velocities zeroed every 0.02 s: the rows next to it keep
   0.006 m/s after 2 s; 0 with delta = 0 or with this difference), which also damped the
   Rayleigh-Taylor growth (tests/test_rt.c). So WCSPH's pair diffuses pressure: rho_i/rho0_i minus
   the relative density phase P would have at p_j, linearised, (p_i - p_j) / K with K = rho0 c0^2
   the bulk modulus; zero wherever the pressure is continuous. K is the larger of the two phases':
   the soft phase's own K would let the stiff phase's pressure noise drive it (water under air at
   1000:1 in the compressible step: the air compressed by 20 % within 0.003 s). PCISPH holds every
   phase at its own rest density (rho/rho0 = 1 on both sides at rest) and has no equation of
   state, and the compressible step's per-particle sound speeds (gases) are not one phase's
   modulus (its 1000:1 interface at rest, tests/test_compressible.c, kept the air 20 % calmer
   with the plain difference): both keep it. dph is the hydrostatic part of p_i - p_j, left out
   as within a phase (sph__delta_hydro): (rho_i + rho_j)/2 g . x_ij. Measured on the three-layer
   column of tests/test_layers.c (20 across, WCSPH): the layers' pressure error went from 0.29 %
   to 0.13 % (interface gradient, continuity), 0.24 % to 0.14 % (interface, particle density) and
   0.75 % to 0.84 % (multiphase gradient, particle density); with the part left out within each
   phase only, it was 1.10 %, 1.20 % and 1.68 %. */
SPH__INLINE sph_real sph__delta_across(const sph__ctx* c, const sph__phase_c* P,
                                       const sph__phase_c* Pj, sph_real rhati, sph_real rhatj,
                                       sph_real pi, sph_real pj, sph_real dph) {
    const sph_real Ki = P->rho0 * P->c0 * P->c0, Kj = Pj->rho0 * Pj->c0 * Pj->c0;
    if (!c->eos_walls || c->cs || !(Ki > 0) || !(Kj > 0)) return rhati - rhatj;
    return (pi - pj - dph) / (Ki > Kj ? Ki : Kj);
}

/* delta-SPH's hydrostatic part (Fourtakas, Dominguez, Vacondio & Rogers 2019, the density
   diffusion term with the hydrostatic density subtracted, as DualSPHysics offers it): in a fluid
   at rest under gravity WCSPH's equation of state makes rho/rho0 grow with depth, by (rho_i/rho0)
   g . x_ij / c_i^2 between two particles to first order (grad p = rho g, d p = c^2 d rho, c_i the
   local sound speed of particle i's state; gh = (rho_i/rho0) g / c_i^2; with c0 in place of c_i a
   film resting at rho/rho0 = 1.003 sank 0.06 dx in 4 s). g is particle i's body acceleration of
   the step (gravity plus def.force, as the walls' extrapolation reads it), so a force field that
   replaces gravity gives the same step. Molteni & Colagrossi's term diffuses that gradient too.
   Inside the fluid a linear profile diffuses to nothing, but where the kernel is cut (a free
   surface) or the other side is a wall whose extrapolated density carries the same gradient (Adami
   et al. 2012), the sum does not vanish and the carried density climbs: the surface rows and,
   worst, a film on a floor, whose every particle sees only the wall below. Measured on a film one
   particle thick on the floor of a 1 x 0.3 m tank (dx 0.02, WCSPH, sph_advance in 0.05 s frames):
   its density rose from 1002 to 1006 kg/m^3 within 1 s, lifting it 0.3 dx and its energy by 1.5 J
   per metre (0.38 rho g H^2 with H = dx) with every frame SPH_OK, climbing on (0.9 rho g H^2 at 4
   s); delta = 0 kept it at rest. So the pair diffuses rho_i/rho0 - rho_j/rho0 - gh . x_ij (a wall
   the same with its extrapolated density; zero and mirrored walls copy the particle's own density
   and get no hydrostatic part), which is zero everywhere in a fluid at rest. A pair across an
   interface diffuses its pressure difference less (rho_i + rho_j)/2 g . x_ij (sph__delta_across). */
SPH__INLINE sph_real sph__delta_hydro(const sph_real* gh, const sph_real* d, int D) {
    return D == 3 ? gh[0] * d[0] + gh[1] * d[1] + gh[2] * d[2]
           : D == 2 ? gh[0] * d[0] + gh[1] * d[1]
                    : gh[0] * d[0];
}

/* sph__accel_row's last loop: ai[k] += lm_m dv[k][m] (if lm) + fs_m dd[k][m] over the row, in
   list order. Not inlined on purpose: inlined into the passes, gcc kept one of the three sums
   in memory, so every pair waited on a store and a reload (3D IISPH at 59k particles, perf:
   22-24 % of the samples in the neighbour passes of sph__stage_interact, about 7 % of the run);
   here the sums live in registers. */
SPH__NOINLINE void sph__row_sum(const int D, size_t nb, const sph_real* lm,
                                sph_real (*dv)[SPH__ROW], const sph_real* fs,
                                sph_real (*dd)[SPH__ROW], sph_real* ai) {
    sph_real a0 = ai[0], a1 = D > 1 ? ai[1] : 0, a2 = D > 2 ? ai[2] : 0;
    size_t m;
    if (D == 3 && lm) {
        for (m = 0; m < nb; ++m) {
            a0 += lm[m] * dv[0][m]; a1 += lm[m] * dv[1][m]; a2 += lm[m] * dv[2][m];
            a0 += fs[m] * dd[0][m]; a1 += fs[m] * dd[1][m]; a2 += fs[m] * dd[2][m];
        }
    } else if (D == 3) {
        for (m = 0; m < nb; ++m) {
            a0 += fs[m] * dd[0][m]; a1 += fs[m] * dd[1][m]; a2 += fs[m] * dd[2][m];
        }
    } else if (lm) {
        for (m = 0; m < nb; ++m) {
            a0 += lm[m] * dv[0][m]; a1 += lm[m] * dv[1][m];
            a0 += fs[m] * dd[0][m]; a1 += fs[m] * dd[1][m];
        }
    } else {
        for (m = 0; m < nb; ++m) { a0 += fs[m] * dd[0][m]; a1 += fs[m] * dd[1][m]; }
    }
    ai[0] = a0;
    if (D > 1) ai[1] = a1;
    if (D > 2) ai[2] = a2;
}

/* sph__interact_one's fluid pairs on the fast path (viscous passes, with or without pressure,
   STORE or CACHED), in batches of SPH__ROW neighbours: a gather loop reads each neighbour in
   list order, a packed loop (SPH__VN lanes) does the square root and the kernel (or reads the
   cached factor), the division of the laminar term and the two of the artificial viscosity
   (branch-free: a receding pair's lane is masked to +0, and s - (+0) is s), and a last loop
   adds the pair forces in list order. Every lane computes the plain loop's expressions in the
   plain loop's order and the sums are taken in the same order, so the result has the same
   bits. The packed loop replaces a branch on the sign of v_ij . x_ij that went either way at
   random; for laminar viscosity it saves the plain loop's per-pair tests and halves the
   divisions of its term (3D IISPH at 59k particles: the viscous pass, without the
   normalisation, x1.45).
   [adds to ai, m/s^2] */
SPH__INLINE void sph__accel_row(const sph__ctx* c, size_t i, const int D, const int flags,
                                sph_real* ai) {
    const sph_real* xi = c->x + i * (size_t)D;
    const sph_real* vi = c->v + i * (size_t)D;
    const sph__phase_c* P = &c->pc[c->ph[i]];
    const sph_real rhoi = c->rho[i], mj = c->m0, inv_rhoi = 1 / rhoi;
    const sph_real pi_r2 = c->p[i] * inv_rhoi * inv_rhoi;
    const sph_real cbar = SPH__R(0.5) * (P->c0 + P->c0);
    const sph_real far = 4 * c->k.radius * c->k.radius; /* padding lanes: beyond the support */
    const sph__v v_inv_h = sph__vset(c->k.inv_h), v_two = sph__vset(2), v_one = sph__vset(1);
    const sph__v v_half = sph__vset(SPH__R(0.5)), v_m5 = sph__vset(-5);
    const sph__v v_norm = sph__vset(c->k.norm_g), v_zero = sph__vset(0);
    const sph__v v_s0 = sph__vset(-mj), v_pi = sph__vset(pi_r2), v_h = sph__vset(c->h);
    const sph__v v_eta2 = sph__vset(c->eta2), v_ac = sph__vset(-c->alpha * cbar);
    const sph__v v_beta = sph__vset(c->beta), v_mj = sph__vset(mj), v_rhoi = sph__vset(rhoi);
    const int av = (flags & SPH__VISCOUS) && c->av;
    /* laminar: the plain loop's lv = visc_k m_j (mu_i + mu_j)/rho_i / rho_j / (r^2 + eta^2),
       its first factor the same for every pair of i; Morris' term along v_ij (lm), else in s */
    const int lam = (flags & SPH__VISCOUS) && c->laminar, mor = lam && c->morris;
    const sph__v v_lv0 = sph__vset(c->visc_k * mj * (P->mu + P->mu) * inv_rhoi);
    const sph__v v_li = sph__vset(mor ? c->lapc[i] : 0);
    sph_real dd[3][SPH__ROW], dv[3][SPH__ROW], r2[SPH__ROW + SPH__VN], ud[SPH__ROW + SPH__VN];
    sph_real pr[SPH__ROW + SPH__VN], rj[SPH__ROW + SPH__VN], fs[SPH__ROW + SPH__VN];
    sph_real fwo[SPH__ROW + SPH__VN], lj[SPH__ROW + SPH__VN], lm[SPH__ROW + SPH__VN];
    size_t b0, k0 = c->ff->begin[i], k1 = k0 + c->ff->count[i];
    int k;
    for (b0 = k0; b0 < k1; b0 += SPH__ROW) {
        const size_t nb = k1 - b0 < SPH__ROW ? k1 - b0 : SPH__ROW;
        size_t m;
        for (m = 0; m < nb; ++m) {
            const size_t j = c->ff->idx[b0 + m];
            const sph_real* xj = c->x + j * (size_t)D;
            const sph_real* vj = c->v + j * (size_t)D;
            sph_real d[3] = {0, 0, 0}, rr = 0, vd = 0;
            SPH__FOR_K(D, d[k] = xi[k] - xj[k]; dd[k][m] = d[k]);
            SPH__FOR_K(D, rr += d[k] * d[k]);
            if (flags & SPH__VISCOUS) SPH__FOR_K(D, vd += (vi[k] - vj[k]) * d[k]);
            if (mor) SPH__FOR_K(D, dv[k][m] = vi[k] - vj[k]);
            r2[m] = rr;
            ud[m] = vd;
            rj[m] = c->rho[j];
            if (mor) lj[m] = c->lapc[j];
            if (flags & SPH__PRESSURE)
                pr[m] = (flags & SPH__CACHED) ? c->pr2[j]
                        : c->pr2c             ? c->pr2c[j]
                                              : c->p[j] / (rj[m] * rj[m]);
        }
        /* cached factors are read in place, but for the last, padded lanes (a copy of the row
           made here went out as a `rep movs`, whose start-up cost more than the copy) */
        if (flags & SPH__CACHED)
            for (m = nb - nb % SPH__VN; m < nb; ++m) fwo[m] = c->ff_fw[b0 + m];
        for (; m % SPH__VN; ++m) {
            r2[m] = far; ud[m] = 0; rj[m] = 1; pr[m] = 0; lj[m] = 0; fwo[m] = 0;
        }
        for (m = 0; m < nb; m += SPH__VN) {
            const sph__v vr2 = sph__vload(r2 + m);
            sph__v fw, sv = v_zero;
            if (flags & SPH__CACHED) {
                fw = m + SPH__VN <= nb ? sph__vload(c->ff_fw + b0 + m) : sph__vload(fwo + m);
            } else {
                const sph__v q = sph__vmul(sph__vsqrt(vr2), v_inv_h);
                const sph__v t = sph__vsub(v_one, sph__vmul(v_half, q));
                const sph__v t3 = sph__vmul(sph__vmul(sph__vmul(v_m5, t), t), t); /* -5 t^3 */
                const sph__v kf = sph__vand(sph__vlt(q, v_two), t3); /* Wendland C2's f(q) */
                fw = sph__vmul(v_norm, kf);
            }
            if (flags & SPH__PRESSURE) sv = sph__vmul(v_s0, sph__vadd(v_pi, sph__vload(pr + m)));
            if (lam) {
                const sph__v lv = sph__vdiv(sph__vdiv(v_lv0, sph__vload(rj + m)),
                                            sph__vadd(vr2, v_eta2));
                if (mor) /* lv fw r^2 (1/m_i + 1/m_j)/2, along v_ij */
                    sph__vstore(lm + m, sph__vmul(sph__vmul(sph__vmul(sph__vmul(lv, fw), vr2),
                                                            v_half),
                                                  sph__vadd(v_li, sph__vload(lj + m))));
                else
                    sv = sph__vadd(sv, sph__vmul(lv, sph__vload(ud + m)));
            }
            if (av) {
                const sph__v u = sph__vload(ud + m);
                const sph__v mu = sph__vdiv(sph__vmul(v_h, u), sph__vadd(vr2, v_eta2));
                const sph__v pv =
                    sph__vadd(sph__vmul(v_ac, mu), sph__vmul(sph__vmul(v_beta, mu), mu));
                const sph__v term = sph__vdiv(sph__vmul(sph__vmul(v_mj, pv), v_two),
                                              sph__vadd(v_rhoi, sph__vload(rj + m)));
                sv = sph__vsub(sv, sph__vand(sph__vlt(u, v_zero), term));
            }
            sph__vstore(fs + m, sph__vmul(sv, fw));
            if (flags & SPH__STORE) sph__vstore(fwo + m, fw);
        }
        if (flags & SPH__STORE)
            for (m = 0; m < nb; ++m) c->ff_fw_out[b0 + m] = fwo[m];
        sph__row_sum(D, nb, mor ? lm : NULL, dv, fs, dd, ai);
    }
}

SPH__INLINE void sph__interact_one(const sph__ctx* c, size_t i, const int D, const int flags,
                                   sph_real* acc, sph_real* rate, const int fast) {
    /* fast (a compile-time constant, see sph__stage_interact): the common configuration, known
       in advance, so the per-pair tests below fold away: one mass, no periodic direction, one
       phase, the symmetric pressure gradient, Wendland C2 (or the cached factor). The arithmetic
       is the same expressions in the same order, so the results are bitwise those of the general
       path; only the branches and the kernel switch go (WCSPH 2D: forces and density rate x1.9). */
    const sph_real* const cm = fast ? NULL : c->m;
    const int form = fast ? (int)SPH__KF_WC2 : c->k.form;
    const int per = fast ? 0 : c->periodic_any;
    const int pgrad = fast ? (int)SPH_PGRAD_SYMMETRIC : c->pgrad;
    const int laminar = c->laminar;
    const sph_real* const cs = fast ? NULL : c->cs;
    const sph_real* const bpqa = fast ? NULL : c->bpq;
    const int en = (flags & SPH__ENERGY) != 0;
    const sph_real* xi = c->x + i * (size_t)D;
    const sph_real* vi = c->v + i * (size_t)D;
    const sph_real* ui = en ? c->vn + i * (size_t)D : vi; /* velocity of the forces */
    const sph__phase_c* P = &c->pc[c->ph[i]];
    const sph_real rhoi = c->rho[i], pi = c->p[i], mi = cm ? cm[i] : c->m0;
    const sph_real inv_rhoi = 1 / rhoi, pi_r2 = pi * inv_rhoi * inv_rhoi;
    const sph_real rhati = rhoi * P->inv_rho0;
    const sph_real dcoef = c->delta * c->h * (c->delta_c > 0 ? c->delta_c : P->c0) * 2 * P->rho0;
    const sph_real ci = cs ? cs[i] : P->c0;
    sph_real gh[3] = {0, 0, 0}; /* (rho_i/rho0) g / c_i^2 [1/m]: sph__delta_hydro */
    sph_real ga[3] = {0, 0, 0}; /* g, i's body acceleration [m/s^2] (the same)        */
    const int os = c->density == SPH_DENSITY_PARTICLE;
    sph_real ai[3] = {0, 0, 0}, R = 0, E = 0;
    size_t kk, k0 = c->ff->begin[i], k1 = k0 + c->ff->count[i];
    int k;
    if (c->abody && (flags & SPH__RATE) && !P->gas) {
        const sph_real c2 = P->gamma * (pi + P->ck) * inv_rhoi; /* the local sound speed^2 */
        SPH__FOR_K(D, ga[k] = c->abody[i * (size_t)D + (size_t)k]);
        if (c2 > 0) SPH__FOR_K(D, gh[k] = rhati * ga[k] / c2);
    }
    /* the packed row: viscous passes (cached or not) and passes that evaluate the kernel
       (PCISPH's pressure passes at predicted positions); a cached pressure-only pass has no
       square root or division for it to pack */
    if (fast && (flags & SPH__ACCEL) && !(flags & (SPH__RATE | SPH__ENERGY)) &&
        ((flags & SPH__VISCOUS) || !(flags & SPH__CACHED)))
        sph__accel_row(c, i, D, flags, ai);
    else for (kk = k0; kk < k1; ++kk) {
        const size_t j = c->ff->idx[kk];
        const sph_real* xj = c->x + j * (size_t)D;
        const sph_real* vj = c->v + j * (size_t)D;
        const sph_real* uj = en ? c->vn + j * (size_t)D : vj;
        const sph_real mj = cm ? cm[j] : c->m0, rhoj = c->rho[j];
        const sph__phase_c* Pj =
            (flags & (SPH__VISCOUS | SPH__RATE)) && !fast ? &c->pc[c->ph[j]] : P;
        sph_real d[3] = {0, 0, 0}, r2 = 0, vd = 0, ud = 0, fw, s = 0, lm = 0;
        sph__delta_vec_p(c, per, xi, xj, d, D);
        SPH__FOR_K(D, r2 += d[k] * d[k]);
        if (flags & (SPH__VISCOUS | SPH__RATE))
            SPH__FOR_K(D, vd += (vi[k] - vj[k]) * d[k]);
        ud = vd;
        if (en) { ud = 0; SPH__FOR_K(D, ud += (ui[k] - uj[k]) * d[k]); }
        if (flags & SPH__CACHED) fw = c->ff_fw[kk]; /* grad W = fw d */
        else fw = c->k.norm_g * sph__kf(form, sph__sqrt(r2) * c->k.inv_h);
        if (flags & SPH__STORE) c->ff_fw_out[kk] = fw;
        if (flags & SPH__RATE) {
            R += (os ? mi : mj) * fw * vd;
            if (c->delta_on)
                R += dcoef * ((fast && c->volc) ? c->volc[j] : mj / rhoj) *
                     (Pj == P ? rhati - rhoj * Pj->inv_rho0 - sph__delta_hydro(gh, d, D)
                              : sph__delta_across(c, P, Pj, rhati, rhoj * Pj->inv_rho0, pi, c->p[j],
                                                  SPH__R(0.5) * (rhoi + rhoj) *
                                                      sph__delta_hydro(ga, d, D))) *
                     fw * r2 / (r2 + c->eta2);
        }
        if (flags & SPH__PRESSURE) {
            const sph_real pj = c->p[j];
            if (pgrad == SPH_PGRAD_SYMMETRIC)
                s = -mj * (pi_r2 + ((flags & SPH__CACHED) ? c->pr2[j]
                                    : (fast && c->pr2c) ? c->pr2c[j] : pj / (rhoj * rhoj)));
            else if (pgrad == SPH_PGRAD_MULTIPHASE) s = -mj * (pi + pj) * inv_rhoi / rhoj * c->pg_norm;
            else if (pgrad == SPH_PGRAD_DIFFERENCE) s = -mj * (pj - pi) * inv_rhoi / rhoj;
            else if (pgrad == SPH_PGRAD_VOLUME) s = sph__pgrad_volume(mi, rhoi, pi, mj, rhoj, pj) * c->pg_norm;
            else s = sph__pgrad_interface(mi, rhoi, pi, mj, rhoj, pj) * c->pg_norm;
        }
        if (flags & SPH__VISCOUS) {
            if (laminar) {
                const sph_real lv = c->visc_k * mj * (P->mu + Pj->mu) * inv_rhoi / rhoj / (r2 + c->eta2);
                if (c->morris) { /* along v_ij: x_ij . grad W = fw r^2; normalised by
                                    (1/m_i + 1/m_j)/2 (sph__stage_visc_norm) */
                    lm = lv * fw * r2 * SPH__R(0.5) * (c->lapc[i] + c->lapc[j]);
                    SPH__FOR_K(D, ai[k] += lm * (ui[k] - uj[k]));
                } else {
                    s += lv * ud;
                }
            }
            if (c->av && ud < 0) {
                const sph_real mu = c->h * ud / (r2 + c->eta2);
                const sph_real cbar = SPH__R(0.5) * (ci + (cs ? cs[j] : Pj->c0));
                s -= mj * (-c->alpha * cbar * mu + c->beta * mu * mu) * 2 / (rhoi + rhoj);
            }
        }
        if (en) { /* -1/2 m_j f_ij . (u_ij + v_ij)/2 */
            sph_real uv = 0;
            if (lm != 0)
                SPH__FOR_K(D, uv += (ui[k] - uj[k]) * (ui[k] - uj[k] + vi[k] - vj[k]));
            E -= SPH__R(0.25) * (s * fw * (ud + vd) + lm * uv);
        } else if (flags & SPH__ACCEL) {
            s *= fw;
            SPH__FOR_K(D, ai[k] += s * d[k]);
        }
    }
    /* walls add a pressure, a rate (STORE comes with PRESSURE) or a no-slip viscous term; a
       viscous pass against free-slip walls has none to add */
    if (c->wg && (flags == (SPH__PRESSURE | SPH__SET | SPH__CACHED)
                      ? c->wg_pressure
                      : flags == (SPH__RATE | SPH__CACHED) && !c->delta_on)) {
        /* the walls' terms from sums taken once a step (sph__wall_grad_sum): zero wall
           pressure gives sum_b -psi_ib (p_i/rho_i^2) grad W_ib, the density rate
           sum_b psi_ib (v_i - v_b) . grad W_ib */
        const sph_real* g = c->wg + i * (size_t)(D + 1);
        if (flags & SPH__PRESSURE) {
            SPH__FOR_K(D, ai[k] -= pi_r2 * g[k]);
        } else {
            sph_real vg = 0;
            SPH__FOR_K(D, vg += vi[k] * g[k]);
            R += vg - g[D];
        }
    } else if (c->has_b &&
               ((flags & (SPH__PRESSURE | SPH__RATE)) || (c->noslip && (laminar || c->av)))) {
        k0 = c->fb->begin[i];
        k1 = k0 + c->fb->count[i];
        for (kk = k0; kk < k1; ++kk) {
            const size_t b = c->fb->idx[kk];
            const sph_real* xb = c->bx + b * (size_t)D;
            const sph_real* vb = c->bv + b * (size_t)D;
            const sph_real Vb = c->bvol[b], psi = P->rho0 * Vb;
            /* the wall's density and pressure as the boundary scheme gives them */
            const sph_real* bq =
                bpqa ? bpqa + ((size_t)b * (size_t)c->nphase + c->ph[i]) * SPH__BPQ : NULL;
            const sph_real kap = bq ? bq[1] : c->bp_mode == SPH_BP_EXTRAPOLATE ? c->brho[b] : rhati;
            const sph_real rhob = P->rho0 * kap;
            sph_real d[3] = {0, 0, 0}, r2 = 0, vd = 0, ud = 0, fw, s = 0, lm = 0, ug = 0;
            sph__delta_vec_p(c, per, xi, xb, d, D);
            SPH__FOR_K(D, r2 += d[k] * d[k]);
            if (flags & SPH__RATE)
                SPH__FOR_K(D, vd += (vi[k] - vb[k]) * d[k]);
            if (en) SPH__FOR_K(D, ud += (ui[k] - vb[k]) * d[k]);
            if (flags & SPH__CACHED) fw = c->fb_fw[kk];
            else fw = c->k.norm_g * sph__kf(form, sph__sqrt(r2) * c->k.inv_h);
            if (flags & SPH__STORE) c->fb_fw_out[kk] = fw;
            if (flags & SPH__RATE) {
                R += psi * fw * vd; /* the wall's own velocity: a moving wall compresses */
                if (c->delta_on)
                    R += dcoef * Vb *
                         (rhati - kap -
                          (bq || c->bp_mode == SPH_BP_EXTRAPOLATE ? sph__delta_hydro(gh, d, D) : 0)) *
                         fw * r2 / (r2 + c->eta2);
            }
            if (flags & SPH__PRESSURE) {
                const sph_real pb = bq ? bq[0] : c->bp_mode == SPH_BP_EXTRAPOLATE ? c->bp[b]
                                    : c->bp_mode == SPH_BP_MIRROR    ? pi
                                                                     : 0;
                if (bq) { /* as fluid of the phase the wall stands for here (sph__phase_walls) */
                    const sph_real* bb = bpqa + (size_t)b * (size_t)c->nphase * SPH__BPQ;
                    int q;
                    for (q = 0; q < c->nphase; ++q, bb += SPH__BPQ)
                        if (bb[2] > 0)
                            s += bb[2] * sph__wall_pterm(c, pgrad, mi, rhoi, inv_rhoi, pi, pi_r2,
                                                         c->pc[q].rho0 * Vb,
                                                         c->pc[q].rho0 * bb[1], bb[0]);
                } else {
                    s = sph__wall_pterm(c, pgrad, mi, rhoi, inv_rhoi, pi, pi_r2, psi, rhob, pb);
                }
            }
            if ((flags & SPH__VISCOUS) && c->noslip && (laminar || c->av)) {
                const sph_real* vw = c->bvw + b * (size_t)D;
                SPH__FOR_K(D, ug += (ui[k] - vw[k]) * d[k]);
                if (laminar) {
                    const sph_real lv = c->visc_k * psi * 2 * P->mu * inv_rhoi / rhob / (r2 + c->eta2);
                    if (c->morris) {
                        lm = lv * fw * r2 * c->lapc[i];
                        SPH__FOR_K(D, ai[k] += lm * (ui[k] - vw[k]));
                    } else {
                        s += lv * ug;
                    }
                }
                if (c->av && ug < 0) {
                    const sph_real mu = c->h * ug / (r2 + c->eta2);
                    s -= psi * (-c->alpha * ci * mu + c->beta * mu * mu) * 2 / (rhoi + rhob);
                }
            }
            if (en) { /* as for fluid pairs, with the wall's velocity (walls take no energy) */
                sph_real uv = 0;
                if (lm != 0)
                    SPH__FOR_K(D, uv += (ui[k] - c->bvw[b * (size_t)D + (size_t)k]) *
                                        (ui[k] + vi[k] - 2 * vb[k]));
                E -= SPH__R(0.25) * (s * fw * (ud + vd) + lm * uv);
            } else if (flags & SPH__ACCEL) {
                s *= fw;
                SPH__FOR_K(D, ai[k] += s * d[k]);
            }
        }
    }
    if (en) c->de[i] = E;
    else if (flags & SPH__SET)
        SPH__FOR_K(D, acc[i * (size_t)D + (size_t)k] = ai[k]);
    else if (flags & SPH__ACCEL) /* acc holds the body acceleration already */
        SPH__FOR_K(D, acc[i * (size_t)D + (size_t)k] += ai[k]);
    if (flags & SPH__RATE) rate[i] = R;
}

#define SPH__BLOCK 256 /* particles per parallel work item (and per force-callback call) */

/* Runs the neighbour loop over all fluid particles; accelerations go to acc (w->a, or solver
   scratch), the density rate to w->drho. The loop is specialised per dimension and per kind
   of pass, so each pass pays only for the terms it computes. */
static void sph__stage_interact(sph_world* w, const sph__ctx* c, int flags, sph_real* acc) {
    const size_t nblk = (w->n + SPH__BLOCK - 1) / SPH__BLOCK;
    /* the configuration sph__interact_one's fast path assumes (see there); the kernel matters
       only to passes that evaluate it (the incompressible solvers' cached viscous, pressure and
       rate passes take the fast path with any kernel) */
    const int fast = !c->m && !c->periodic_any && c->nphase == 1 && !c->bpq && !c->cs &&
                     c->pgrad == SPH_PGRAD_SYMMETRIC &&
                     (c->k.form == SPH__KF_WC2 || (flags & SPH__CACHED)) &&
                     (c->dim == 2 || c->dim == 3);
    sph__idx blk;
    /* the Laplacian's normalisation at these positions (the energy pass reuses its force pass's) */
    if ((flags & SPH__VISCOUS) && !(flags & SPH__ENERGY) && c->lapc)
        sph__stage_visc_norm(w, c, (flags & SPH__CACHED) != 0);
    SPH__OMP_FOR(w->n) /* over blocks of SPH__BLOCK particles */
    for (blk = 0; blk < (sph__idx)nblk; ++blk) {
        const size_t i0 = (size_t)blk * SPH__BLOCK;
        const size_t i1 = i0 + SPH__BLOCK < w->n ? i0 + SPH__BLOCK : w->n;
        size_t i;
#define SPH__LOOP(D, FL, F)                                                                        \
    for (i = i0; i < i1; ++i) sph__interact_one(c, i, D, FL, acc, w->drho, F)
#define SPH__CASES(D, F)                                                                           \
    case (F) * 512 + D * 128 + SPH__ACCEL: SPH__LOOP(D, SPH__ACCEL, F); break;                     \
    case (F) * 512 + D * 128 + (SPH__ACCEL | SPH__STORE):                                          \
        SPH__LOOP(D, SPH__ACCEL | SPH__STORE, F); break;                                           \
    case (F) * 512 + D * 128 + SPH__VISCOUS: SPH__LOOP(D, SPH__VISCOUS, F); break;                 \
    case (F) * 512 + D * 128 + (SPH__VISCOUS | SPH__CACHED):                                       \
        SPH__LOOP(D, SPH__VISCOUS | SPH__CACHED, F); break;                                        \
    case (F) * 512 + D * 128 + (SPH__PRESSURE | SPH__SET):                                         \
        SPH__LOOP(D, SPH__PRESSURE | SPH__SET, F); break;                                          \
    case (F) * 512 + D * 128 + (SPH__PRESSURE | SPH__SET | SPH__CACHED):                           \
        SPH__LOOP(D, SPH__PRESSURE | SPH__SET | SPH__CACHED, F); break;                            \
    case (F) * 512 + D * 128 + SPH__RATE: SPH__LOOP(D, SPH__RATE, F); break;                       \
    case (F) * 512 + D * 128 + (SPH__RATE | SPH__CACHED):                                          \
        SPH__LOOP(D, SPH__RATE | SPH__CACHED, F); break;                                           \
    case (F) * 512 + D * 128 + (SPH__RATE | SPH__STORE):                                           \
        SPH__LOOP(D, SPH__RATE | SPH__STORE, F); break;
        switch (fast * 512 + c->dim * 128 + flags) {
            SPH__CASES(1, 0)
            SPH__CASES(2, 0)
            SPH__CASES(3, 0)
            SPH__CASES(2, 1)
            SPH__CASES(3, 1)
        case 1 * 128 + (SPH__RATE | SPH__ACCEL | SPH__ENERGY):
            SPH__LOOP(1, SPH__RATE | SPH__ACCEL | SPH__ENERGY, 0); break;
        case 2 * 128 + (SPH__RATE | SPH__ACCEL | SPH__ENERGY):
            SPH__LOOP(2, SPH__RATE | SPH__ACCEL | SPH__ENERGY, 0); break;
        case 3 * 128 + (SPH__RATE | SPH__ACCEL | SPH__ENERGY):
            SPH__LOOP(3, SPH__RATE | SPH__ACCEL | SPH__ENERGY, 0); break;
        default: SPH_ASSERT(0); break;
        }
#undef SPH__CASES
#undef SPH__LOOP
    }
}

/* Body accelerations: gravity plus the user's force callback, per block of particles. They start
   the acceleration array; the wall extrapolation reads them, the neighbour pass adds to them.
   The callback's output is checked right after each call, over the range it just wrote (cached,
   a few ns per particle): a non-finite value spreads to the neighbours within the step, and the
   end-of-step check would name the lowest index it reached instead of the particle where it
   entered. The lowest bad index over all blocks is a min-reduction, the same for any number of
   threads. SPH_ERR_UNSTABLE (the step has already sorted, and maybe drifted, the particles). */
static sph_status sph__stage_body_force(sph_world* w, const sph__ctx* c) {
    const size_t nblk = (w->n + SPH__BLOCK - 1) / SPH__BLOCK;
    const int D = c->dim;
    sph__idx blk, bad = (sph__idx)w->n;
#if defined(_OPENMP) && _OPENMP >= 201107
#pragma omp parallel for schedule(static) if (w->n > 2048) reduction(min : bad)
#else
    SPH__OMP_FOR(w->n) /* (OpenMP before 3.1 has no min-reduction: the check below is serial) */
#endif
    for (blk = 0; blk < (sph__idx)nblk; ++blk) {
        const size_t i0 = (size_t)blk * SPH__BLOCK;
        const size_t i1 = i0 + SPH__BLOCK < w->n ? i0 + SPH__BLOCK : w->n;
        size_t i;
        int k;
        for (i = i0; i < i1; ++i)
            for (k = 0; k < D; ++k) w->a[i * (size_t)D + (size_t)k] = c->g[k];
        if (!w->def.force) continue;
        w->def.force(w, i0, i1, w->a, w->def.force_user);
#if defined(_OPENMP) && _OPENMP >= 201107
        for (i = i0; i < i1 && (sph__idx)i < bad; ++i)
            for (k = 0; k < D; ++k)
                if (!sph__finite((double)w->a[i * (size_t)D + (size_t)k])) bad = (sph__idx)i;
#endif
    }
#if !(defined(_OPENMP) && _OPENMP >= 201107)
    if (w->def.force) {
        size_t i;
        int k;
        for (i = 0; i < w->n && (sph__idx)i < bad; ++i)
            for (k = 0; k < D; ++k)
                if (!sph__finite((double)w->a[i * (size_t)D + (size_t)k])) bad = (sph__idx)i;
    }
#endif
    if (bad < (sph__idx)w->n) {
        const size_t i = (size_t)bad;
        int k = 0;
        while (k < D - 1 && sph__finite((double)w->a[i * (size_t)D + (size_t)k])) ++k;
        return sph__fail(w, SPH_ERR_UNSTABLE, (long)i,
                         "force callback: it produced a non-finite acceleration a[%d] = %g for "
                         "fluid particle %zu (id %u) at t = %g",
                         k, (double)w->a[i * (size_t)D + (size_t)k], i, (unsigned)w->id[i],
                         w->time);
    }
    return SPH_OK;
}

/* Rejects a step on input that would poison it: dt, and non-finite positions, velocities or
   densities written by the host between steps. Nothing is changed. */
static sph_status sph__check_step_input(sph_world* w, sph_real dt) {
    const size_t D = (size_t)w->dim;
    const double far = sph__far_limit(w->dx); /* positions the host wrote far away */
    size_t i, k;
    if (!sph__finite((double)dt) || !(dt > 0))
        return sph__fail(w, SPH_ERR_ARG, -1, "step: dt = %g: must be finite and > 0", (double)dt);
    if (w->nphase == 0 && w->n > 0)
        return sph__fail(w, SPH_ERR_ARG, -1, "step: the world has particles but no phase");
    { /* the common case, all good, checked in parallel (the serial pass was 0.8 % of a 2D
         WCSPH step at 100k, which a second thread could not share); only a bad world is
         searched again, serially, for its first bad particle and the message */
        int bad = 0;
        /* the kinetic and potential energy the step starts from, for the energy check (pa: the
           size of the potential's terms, for the rounding of its sum) */
        double ke = 0, pe = 0, pa = 0;
        sph__idx j;
#if defined(_OPENMP)
#pragma omp parallel for schedule(static) reduction(| : bad) reduction(+ : ke, pe, pa) if (w->n > 2048)
#endif
        for (j = 0; j < (sph__idx)w->n; ++j) {
            double v2 = 0, gx = 0;
            int kk, b = !sph__finite((double)w->rho[j]) || !(w->rho[j] > 0) ||
                        (w->e && !sph__finite((double)w->e[j]));
            for (kk = 0; kk < (int)D; ++kk) {
                const double vk = (double)w->v[(size_t)j * D + (size_t)kk];
                b |= !sph__finite((double)w->x[(size_t)j * D + (size_t)kk]) || !sph__finite(vk) ||
                     fabs((double)w->x[(size_t)j * D + (size_t)kk]) > far;
                v2 += vk * vk;
                if (!w->def.periodic[kk])
                    gx += (double)w->def.gravity[kk] * (double)w->x[(size_t)j * D + (size_t)kk];
            }
            ke += 0.5 * (double)(w->m ? w->m[j] : w->mass) * v2;
            pe -= (double)(w->m ? w->m[j] : w->mass) * gx;
            pa += (double)(w->m ? w->m[j] : w->mass) * fabs(gx);
            bad |= b;
        }
        if (!bad) i = w->n; /* skip the serial search below */
        else i = 0;
        /* the host changed the velocities or positions (or added particles) since the last
           step: the energy check starts again from here (a rounding-level difference is the
           order of the sums) */
        if (!bad && (!(fabs(ke - w->stats.kinetic_energy) <= 1e-9 * (ke + w->stats.kinetic_energy)) ||
                     !(fabs(pe - w->stats.potential_energy) <= 1e-9 * pa))) {
            w->stats.unforced_steps = 0;
            w->priv.head_ref_on = 0; /* the fall's headroom too (sph__integrate_with) */
        }
    }
    for (; i < w->n; ++i) {
        for (k = 0; k < D; ++k) {
            if (!sph__finite((double)w->x[i * D + k]))
                return sph__fail(w, SPH_ERR_ARG, (long)i,
                                 "step: fluid particle %zu (id %u) has a non-finite position", i,
                                 (unsigned)w->id[i]);
            if (fabs((double)w->x[i * D + k]) > far) {
                char what[96];
                snprintf(what, sizeof what, "step: fluid particle %zu (id %u) at x[%zu]", i,
                         (unsigned)w->id[i], k);
                return sph__fail_far(w, w->dx, (long)i, what, (double)w->x[i * D + k]);
            }
            if (!sph__finite((double)w->v[i * D + k]))
                return sph__fail(w, SPH_ERR_ARG, (long)i,
                                 "step: fluid particle %zu (id %u) has a non-finite velocity", i,
                                 (unsigned)w->id[i]);
        }
        if (!sph__finite((double)w->rho[i]) || !(w->rho[i] > 0))
            return sph__fail(w, SPH_ERR_ARG, (long)i,
                             "step: fluid particle %zu (id %u) has density %g: must be finite and > 0",
                             i, (unsigned)w->id[i], (double)w->rho[i]);
        if (w->e && !sph__finite((double)w->e[i]))
            return sph__fail(w, SPH_ERR_ARG, (long)i,
                             "step: fluid particle %zu (id %u) has a non-finite internal energy", i,
                             (unsigned)w->id[i]);
    }
    for (i = 0; i < w->nb * D; ++i) {
        if (!sph__finite((double)w->b_x[i]) || !sph__finite((double)w->b_v[i]))
            return sph__fail(w, SPH_ERR_ARG, (long)(i / D),
                             "step: boundary particle %zu has a non-finite position or velocity",
                             i / D);
        if (fabs((double)w->b_x[i]) > far) {
            char what[96];
            snprintf(what, sizeof what, "step: boundary particle %zu at x[%zu]", i / D, i % D);
            return sph__fail_far(w, w->dx, (long)(i / D), what, (double)w->b_x[i]);
        }
    }
    return SPH_OK;
}

static sph_status sph__boundary_motion(sph_world* w, double t) {
    const size_t D = (size_t)w->dim;
    size_t i;
    if (!w->def.boundary_motion || w->nb == 0) return SPH_OK;
    w->def.boundary_motion(w, t, w->def.boundary_user);
    w->priv.b_time = t;
    for (i = 0; i < w->nb * D; ++i)
        if (!sph__finite((double)w->b_x[i]) || !sph__finite((double)w->b_v[i]) ||
            !sph__finite((double)w->b_a[i]))
            return sph__fail(w, SPH_ERR_ARG, (long)(i / D),
                             "boundary motion callback: boundary particle %zu (id %u) got a "
                             "non-finite position, velocity or acceleration at t = %g",
                             i / D, (unsigned)w->b_id[i / D], t);
    i = sph__first_far(w->b_x, w->nb * D, sph__far_limit(w->dx));
    if (i < w->nb * D) {
        char what[128];
        snprintf(what, sizeof what,
                 "boundary motion callback: boundary particle %zu (id %u) at x[%zu]", i / D,
                 (unsigned)w->b_id[i / D], i % D);
        return sph__fail_far(w, w->dx, (long)(i / D), what, (double)w->b_x[i]);
    }
    return SPH_OK;
}

/* Integration update v += kv a, rho += kr drho, x += kx v (in that order), periodic wrap. With
   `final`, also the step's diagnostics and blow-up detection. Reductions run over fixed blocks
   combined in block order, so the result does not depend on the number of threads. */
enum { SPH__RED_KE, SPH__RED_ERRSUM, SPH__RED_ERRMAX, SPH__RED_COMP, SPH__RED_V2MAX,
       SPH__RED_A2MAX, SPH__RED_OUT, SPH__RED_CONTACT, SPH__RED_WREL, SPH__RED_PE, SPH__RED_HEAD,
       SPH__RED_BAD, SPH__RED_KIND, SPH__RED_N };
enum { SPH__BAD_NONE, SPH__BAD_NONFINITE, SPH__BAD_DENSITY, SPH__BAD_COMPRESSION, SPH__BAD_SPEED,
       SPH__BAD_ENERGY, SPH__BAD_DISPLACEMENT, SPH__BAD_WALL, SPH__BAD_TANK };

static int sph__incompressible(int solver) {
    return solver != SPH_SOLVER_WCSPH && solver != SPH_SOLVER_COMPRESSIBLE;
}

/* check_walls: the wall volume fraction sum_b V_b W_ib / S of fluid particle i (S the lattice
   sum, so a particle deep inside a lattice wall has 1 and one on a flat wall's face 0.5), from
   the step's fluid->wall lists at the particle's position now. */
static sph_real sph__wall_fraction(const sph__ctx* c, const sph_real* xi, size_t i, sph_real S) {
    const int form = c->k.form, D = c->dim; /* the common kernels as constants: no switch a pair */
    sph_real sum;
    if (D == 3 && form == SPH__KF_CUBIC) sum = sph__wall_sum(c, i, xi, 3, SPH__KF_CUBIC, NULL);
    else if (D == 3 && form == SPH__KF_WC2) sum = sph__wall_sum(c, i, xi, 3, SPH__KF_WC2, NULL);
    else if (D == 2 && form == SPH__KF_WC2) sum = sph__wall_sum(c, i, xi, 2, SPH__KF_WC2, NULL);
    else sum = sph__wall_sum(c, i, xi, D, form, NULL);
    return sum * c->k.norm_w / S;
}


/* Wall contact (def.wall_contact). The pressure solvers keep a fluid particle off a wall only as
   far as its density needs: a particle short of fluid neighbours (a splash, the one-particle sheet
   a dam break spreads along the floor) reaches rho0 only once the wall supplies the missing
   volume, i.e. on or past the wall's first layer (wall volume fraction 0.78 there, 0.5 on the
   wall's face), and the walls alone cannot stop it. Zero wall pressure (the incompressible
   solvers' default, see BOUNDARIES) pushes no harder. So the end of a step keeps each fluid
   particle's centre at least d_c = wall_contact dx from every boundary particle's centre. A
   particle closer than that moves along the wall's normal at its position,
       n = -sum_b V_b grad W_ib / |sum_b V_b grad W_ib|      (the wall volume fraction's descent),
   by the least distance s >= 0 that puts it d_c from each wall particle b it touches:
       s_b = -(x_ib . n) + sqrt((x_ib . n)^2 - |x_ib|^2 + d_c^2),   x_ib = x_i - x_b,
   and its normal velocity relative to the wall, (v_i - v_b) . n < 0 (v_b of the nearest wall
   particle), is removed: no restitution, so the contact takes kinetic energy and never adds it.
   Moving along the wall's normal, not along x_ib, leaves a particle sliding over the bumps of a
   wall lattice free to slide (along x_ib the contact would brake it at every wall particle it
   passes). Each fluid particle moves only itself against fixed wall positions, so the result does
   not depend on the order of particles or threads. A fluid lattice sits 1 dx from its wall
   lattice, so at rest nothing is touched; over the hollow between the wall particles of a lattice
   at spacing s a particle stays sqrt(d_c^2 - (D - 1) s^2/4) above their layer, which the default
   d_c = (0.02 + sqrt(D)/2) dx keeps just over the wall's face (0.53 dx for s = dx, in 2D and
   3D; a smaller d_c let 3D dam breaks spread their thinnest sheets past the face, and a larger
   one pushed against the fluid that zero wall pressure lets settle closer than 1 dx). No particle
   passes between wall particles while s < sqrt(2) d_c (3D; s < 2 d_c in 2D). The step's
   fluid->wall lists reach the kernel support (>= 2 dx) around the particle's start, which covers
   d_c plus the step's displacement (at most max_displacement dx, checked next). Returns whether
   the particle moved.
   In 3D with zero wall pressure and an incompressible solver d_c is for particles short of
   neighbours: one whose fluid and wall neighbours number at least a fraction "full" of a full
   lattice neighbourhood (0.85 for Wendland C2 at h = 1.3 dx, from the kernel's lattice by
   sph__contact_ramp; the count sph__enclosed uses) has the wall supply only what a fluid
   would, so the pressure solve, which holds its density, holds it, and its contact distance is
   SPH__CONTACT_REST dx (over a wall particle its centre stays 0.1 dx on the fluid side of the
   wall's face; over the hollow between wall particles it is free to reach the face, where zero
   wall pressure's resting rows sit, +-0.04 dx; at a wall of one layer only the nearest wall
   particle has the shorter distance, see sph__wall_contact); the distance grows linearly to d_c
   as the count
   falls to a fraction "short" (0.7) of a full set (a switch instead
   of the ramp moved a particle 0.4 dx in one step whenever its count crossed the line, and its
   neighbours answered at 0.1-0.14 sqrt(g H)). Why: zero wall pressure's resting state is not the
   lattice. The wall pushes with p_i alone, so the rows at a wall settle up to 0.35 dx closer to
   it, 0.5-0.65 dx from the first layer in 3D, and a contact at 0.89 dx fought that at every
   step: about 200 of the 800 particles of a 3D tank at rest (0.4 m, dx 0.04) were moved each
   step and the tank kept moving at 0.2-0.25 sqrt(g H) for good; with the ramp it comes to rest
   (tests/test_scenes.c, tank_3d_settles). In 2D the rows rest at 0.75-0.93 dx, beyond the 2D
   d_c of 0.73 dx, and the ramp gained nothing but centres up to 0.06 dx past the face at the
   side walls near the surface, so 2D keeps d_c for every particle. A rule on the height above
   the wall along n instead of the distance (tried) fought the rows that settle at the face just
   as well (IISPH 0.12, DFSPH 0.23 sqrt(g H) after 4 s). The splashes and one-particle sheets the contact is for have few
   fluid neighbours and are still caught (tests/test_reliability.c's wall_contact_sheet; no
   particle through a wall in tests/test_scenes.c's dam breaks). Extrapolated and mirrored walls
   hold the fluid at the lattice's 1 dx, where d_c touches nothing, and WCSPH's equation of state
   holds no density (with zero wall pressure its floor row went through without the contact,
   tests/test_wcsph.c): there d_c applies to every particle. */
#define SPH__CONTACT_REST 0.6
/* x - x_b for the contact, with wall particle b where it will be at the step's end: moved walls
   are placed once per step (at its start, or its middle), and the fluid ends the step lead =
   t^{n+1} - t_walls later, so b is taken at x_b + lead v_b (lead = 0 for static walls). Against
   the placed positions a rotating drum of one host-placed layer (2D, dx 0.01, 2 rad/s, IISPH)
   carried its walls 0.11 dx per step into the particles the contact had just cleared, down to
   0.62 dx, and pushed them through the diagonal gaps of the layer (1.41 dx, held only while
   d_c > 0.71 dx): a particle escaped within 0.05 s. */
SPH__INLINE void sph__wall_delta(const sph__ctx* c, const sph_real* x, size_t b, sph_real lead,
                                 sph_real* d) {
    const int D = c->dim;
    int k;
    sph__delta_vec(c, x, c->bx + b * (size_t)D, d, D);
    if (lead != 0)
        for (k = 0; k < D; ++k) d[k] -= lead * c->bv[b * (size_t)D + (size_t)k];
}

/* The wall's normal at x, n = -sum_b V_b grad W(x - x_b) (unnormalised: the wall volume
   fraction's descent, pointing away from the wall's mass), over fluid particle i's wall list,
   with the walls at the step's end (sph__wall_delta). */
static void sph__wall_normal(const sph__ctx* c, size_t i, const sph_real* x, sph_real lead,
                             sph_real* g) {
    const int D = c->dim;
    const size_t k0 = c->fb->begin[i], k1 = k0 + c->fb->count[i];
    size_t kk;
    int k;
    for (k = 0; k < 3; ++k) g[k] = 0;
    for (kk = k0; kk < k1; ++kk) {
        const size_t b = c->fb->idx[kk];
        sph_real d[3] = {0, 0, 0}, r2 = 0, f;
        sph__wall_delta(c, x, b, lead, d);
        for (k = 0; k < D; ++k) r2 += d[k] * d[k];
        f = c->bvol[b] * sph__kf(c->k.form, sph__sqrt(r2) * c->k.inv_h);
        for (k = 0; k < D; ++k) g[k] -= f * d[k];
    }
}

/* Crossing guard (with the wall contact). A wall of one layer (a host's sampled surface) has no
   inside: a particle that a step carries past the layer's line finds the wall's normal pointing
   out of the container and the contact below would push it on, out. So a particle that moved
   far enough to cross (more than SPH__CROSS_MOVE spacings: the contact keeps centres at least
   0.46 dx above a layer's line) and whose wall normal at the step's end points against the one
   at its start went through the wall: it goes back to where the step found it (which the
   contact had left clear of the walls) and loses its velocity into the wall along the start's
   normal (inelastic, as the contact). Measured: a block of water thrown at 10 m/s into the
   corner of a box of single-layer walls with Akinci volumes (2D, dx 0.02, IISPH) shot a
   particle through the corner at 37 m/s, which flew off unreported; with the guard none passes.
   A particle that creeps into the line of a layer or a gap between its particles is the
   contact's (its first push may follow the start's normal, sph__wall_contact), and what gets
   past both is sph__wall_crossed's. Returns 1 if it acted. */
#define SPH__CROSS_MOVE 0.4
static int sph__wall_cross_guard(const sph__ctx* c, size_t i, const sph_real* xold,
                                 const sph_real* gold, sph_real lead, sph_real* xi, sph_real* vi) {
    const int D = c->dim;
    sph_real g[3], gg = 0, vn = 0, n2 = 0;
    int k;
    sph__wall_normal(c, i, xi, lead, g);
    for (k = 0; k < D; ++k) { gg += g[k] * gold[k]; n2 += gold[k] * gold[k]; }
    if (!(gg < 0) || !(n2 > 0)) return 0;
    n2 = 1 / sph__sqrt(n2);
    for (k = 0; k < D; ++k) {
        xi[k] = xold[k];
        vn += vi[k] * gold[k] * n2;
    }
    if (vn < 0)
        for (k = 0; k < D; ++k) vi[k] -= vn * gold[k] * n2;
    return 1;
}

/* The last line of a thin wall (sph__wall_thin: one layer, as a host samples a surface), after
   the contact, for every particle near one however far it moved: did the step take it behind
   the wall's face? Locally the wall is a plane (a line in 2D) through D of its particles. Of
   the six (four in 2D) thin wall particles nearest to the particle's end x_e, every D that lie
   within 2.25 dx of each other are tried, nearest first; the particle crossed one if x_e lies
   behind it and the step's start x_s in front (a start on the plane counts as in front), with
   x_e's foot on the plane within the triangle (the segment) of those particles widened by a
   quarter of its sides: past a thin plate's end the fluid flows round it, beside the plate's
   line, not through it. Only a particle whose nearest wall particle is within 1.1 dx at the end
   is looked at (in the middle of a square gap of a layer sampled at 1.5 dx it is 1.06 dx away),
   so a plane across a channel between two layers 2.2 dx apart or more is never tried. More than
   the nearest D are tried because at an edge the nearest D span two faces and make a chamfer
   the particle may already be behind (with the nearest D + 1 only, 18 (IISPH) and 22 (PBF) of
   the 800 particles below still got out through the 3D box's edges). Such a particle goes back
   to where the step found it (as with the guard above) and loses its velocity into the plane,
   relative to the nearest wall particle. A step of two drifts (Stormer-Verlet: enhanced PCISPH,
   WCSPH's option) is looked at whole, from x^n (sph__x_start): its first drift, before the
   search, has no lists to check against, and enhanced PCISPH took 15 (2D) and 96 (3D) particles
   out through it. The contact (sph__wall_contact) keeps centres d_c from wall particles, which
   closes a layer sampled at the fluid's spacing, but not a gap wider than 2 d_c (a host's
   coarser sampling), nor a wedge where its push follows a heavier wall's normal through a thin
   one. Measured, dam breaks in a box whose single-layer walls a host sampled at 1.5 dx (default
   volumes, sph_advance in 0.02 s frames for 1 s), particles outside the walls before -> with
   the check, every frame SPH_OK unless said: 2D (400 particles, dx 0.02) WCSPH 12 -> 0,
   original PCISPH 51 -> 0 (fails at 0.46 s, reported), enhanced 21 -> 0, IISPH 33 -> 0 (fails
   at 0.72 s, reported), DFSPH 56 -> 0, PBF 72 -> 0 (fails at 0.14 s, reported; the failures: a
   particle the check holds at a gap is compressed or driven past the speed bound by the fluid
   behind it; tests/test_reliability.c, coarse_host_walls); 3D (800 particles, dx 0.04) 150,
   209, 139, 519, 494 and 550 -> 0, 1, 0 (fails at 0.94 s, reported), 1, 2 and 3: fewer, not
   none. The original PCISPH's 3D dam break (1936 particles, dx 0.03) against a sphere of one
   layer (R 0.09 m, 0.02 m above the floor) put a particle into the sphere at 0.94 s, now none
   (1.5 s). Not kept:
   - lifting the particle besides to half a spacing in front of the plane (a wall's face at the
     fluid's spacing) kept more particles moving, but added energy: the one-layer box of
     tests/test_scenes.c's shell_3d rose 0.05 (the original PCISPH) and 0.0093 (DFSPH) of
     rho g H^2 W above its start, against 0.005 allowed;
   - the flip of the wall's normal -grad C between start and end: in a gap between wall
     particles its component along the wall, towards the gap's middle, outweighs the normal one
     near the layer, and the normals of a creeping step still agreed (the particles above went
     out through the 1.5 dx gaps unnoticed);
   - walls a callback moves: putting a particle back where the step found it, against walls that
     moved since, let one particle out of the turning drums of tests/test_scenes.c (drum_2d:
     IISPH and DFSPH; drum_3d: DFSPH and PBF) at 3.2-3.4 sqrt(g H): static walls only.
   Where a thin wall ends next to a thick one (a host's one-layer slope whose last points stop a
   spacing above a floor of sph_add_wall_box, 1.5-1.7 dx from the floor's first layer) the gap
   between them is closed by neither: the contact's push off the floor leaves out the slope's end
   ahead of it, and the slope's last points are thick by their kernel sums. So the planes that D
   of the SPH__CROSS_NEAR nearest thin particles span come first, then those with the
   SPH__CROSS_THICK nearest thick ones (at least one thin in each; in 3D, one thin and two thick
   only where a thick one lies within 1.25 dx of the thin one: the edge of a thin wall counted
   thick), and the particle is looked at when the nearest of either is within 1.1 dx. Not kept:
   one thin with any two thick. A plane through two points of a thick wall's first layer and a
   thin point beyond cut into that wall's contact zone, where fluid rests: a particle beside a
   3D slope's junction with a box's side was sent back every step while the solver sped it up
   (DFSPH, frozen at one place from 0.33 s, 40 m/s and failed at 0.94 s). Measured, a column
   running down such a slope (reliability/slope_junction, 1 s, every frame SPH_OK), particles more
   than 2 dx under the slope, most in a frame, before -> after: 2D box (dx 0.02) IISPH 5, PBF 4,
   original PCISPH 3 -> 0 (DFSPH and WCSPH 0); 3D channel periodic in z (dx 0.03) IISPH 35,
   DFSPH 27, PBF 33, original PCISPH 17 -> 0. In a 3D box the corner where the slope's end, the
   floor and a side wall meet is all thick (README, Limits): 27, 20, 24, 21 -> 1, 0, 0, 1.
   Walls of thick layers only are left to check_walls. Returns 1 if it acted. */
#define SPH__CROSS_NEAR 6  /* thin wall particles the crossing check looks at (4 in 2D) */
#define SPH__CROSS_THICK 6 /* and thick ones, where a thin wall meets a thick one (2 in 2D) */
static int sph__wall_crossed(const sph__ctx* c, size_t i, const uint8_t* thin, const sph_real* xs,
                             sph_real lead, sph_real lead_s, sph_real dx, sph_real* xi,
                             sph_real* vi) {
    const int D = c->dim, K = D == 3 ? SPH__CROSS_NEAR : 4, KT = D == 3 ? SPH__CROSS_THICK : 2;
    const size_t k0 = c->fb->begin[i], k1 = k0 + c->fb->count[i];
    const sph_real side2 = SPH__R(5.0625) * dx * dx; /* (2.25 dx)^2 */
    const sph_real near2 = SPH__R(1.5625) * dx * dx; /* (1.25 dx)^2 */
    /* the K nearest thin wall particles, nearest first, then the KT nearest thick ones */
    sph_real r2n[SPH__CROSS_NEAR + SPH__CROSS_THICK], dn[SPH__CROSS_NEAR + SPH__CROSS_THICK][3];
    size_t bn[SPH__CROSS_NEAR + SPH__CROSS_THICK], kk;
    int k, j, t, m = 0, mt = 0, v[3], mixed;
    if (D < 2) return 0;
    for (t = 1; t >= 0 && (t || m > 0); --t) /* the thin ones, then (near a thin one) the thick */
        for (kk = k0; kk < k1; ++kk) {
            const size_t b = c->fb->idx[kk];
            const int o = t ? 0 : K, cap = t ? K : KT;
            int* cnt = t ? &m : &mt;
            sph_real d[3] = {0, 0, 0}, r2 = 0;
            if ((thin[b] != 0) != t) continue;
            sph__wall_delta(c, xi, b, lead, d);
            for (k = 0; k < D; ++k) r2 += d[k] * d[k];
            if (*cnt == cap && !(r2 < r2n[o + cap - 1])) continue;
            for (j = *cnt < cap ? *cnt : cap - 1; j > 0 && r2 < r2n[o + j - 1]; --j) {
                r2n[o + j] = r2n[o + j - 1]; /* insert at j */
                bn[o + j] = bn[o + j - 1];
                for (k = 0; k < 3; ++k) dn[o + j][k] = dn[o + j - 1][k];
            }
            r2n[o + j] = r2;
            bn[o + j] = b;
            for (k = 0; k < 3; ++k) dn[o + j][k] = d[k];
            if (*cnt < cap) ++*cnt;
        }
    /* a thin wall particle among them, and the nearest of either within 1.1 dx */
    if (m < 1 || !(r2n[0] < SPH__R(1.21) * dx * dx || (mt > 0 && r2n[K] < SPH__R(1.21) * dx * dx)))
        return 0;
    if (m < K) /* the thick ones next to the thin ones */
        for (j = 0; j < mt; ++j) {
            r2n[m + j] = r2n[K + j];
            bn[m + j] = bn[K + j];
            for (k = 0; k < 3; ++k) dn[m + j][k] = dn[K + j][k];
        }
    /* every D of them (v[0] < v[1] < v[2]), nearest first: first the thin walls' own planes,
       then those of a thin wall's particles with a thick wall's (v[0] thin, the last thick) */
    for (mixed = 0; mixed < (mt > 0 ? 2 : 1); ++mixed)
        for (v[0] = 0; v[0] < m; ++v[0])
            for (v[1] = v[0] + 1; v[1] < (mixed ? m + mt : m); ++v[1])
                for (v[2] = D == 3 ? v[1] + 1 : 0; v[2] < (D == 3 ? (mixed ? m + mt : m) : 1);
                     ++v[2]) {
                    sph_real e1[3] = {0, 0, 0}, e2[3] = {0, 0, 0}, nrm[3] = {0, 0, 0};
                    sph_real ds[3] = {0, 0, 0}, q[3], a11 = 0, a12 = 0, a22 = 0, b1 = 0, b2 = 0;
                    sph_real ss = 0, se = 0, n2 = 0, vn = 0, u, al, be;
                    const sph_real* vb;
                    if (mixed != (v[D - 1] >= m)) continue; /* each tuple in its round */
                    /* the sides from the first: x_b' - x_b = d - d' (d = x_e - x_b); the normal */
                    for (k = 0; k < D; ++k) {
                        e1[k] = dn[v[0]][k] - dn[v[1]][k];
                        if (D == 3) e2[k] = dn[v[0]][k] - dn[v[2]][k];
                    }
                    if (D == 2) {
                        nrm[0] = -e1[1];
                        nrm[1] = e1[0];
                    } else {
                        nrm[0] = e1[1] * e2[2] - e1[2] * e2[1];
                        nrm[1] = e1[2] * e2[0] - e1[0] * e2[2];
                        nrm[2] = e1[0] * e2[1] - e1[1] * e2[0];
                    }
                    for (k = 0; k < D; ++k) {
                        a11 += e1[k] * e1[k];
                        a12 += e1[k] * e2[k];
                        a22 += e2[k] * e2[k];
                        n2 += nrm[k] * nrm[k];
                    }
                    /* wall particles of one layer lie close together (sampled at up to 1.5 dx) */
                    if (!(a11 <= side2) || !(n2 > 0)) continue;
                    if (D == 3) { /* the other sides; three nearly in a line span no plane */
                        sph_real e3 = 0;
                        for (k = 0; k < 3; ++k) e3 += (e1[k] - e2[k]) * (e1[k] - e2[k]);
                        if (!(a22 <= side2) || !(e3 <= side2) || !(n2 > SPH__R(0.03) * a11 * a22))
                            continue;
                        /* one thin and two thick: one of the thick a neighbour of the thin one
                           along its wall (a thin wall's edge counted thick); a plane through two
                           points of a thick wall's layer and a thin point further off cuts into
                           the thick wall's contact zone, where fluid rests, and held a particle
                           there while the solver sped it up (a 3D slope against a box's side) */
                        if (mixed && v[1] >= m && !(a11 <= near2) && !(a22 <= near2)) continue;
                    }
                    sph__wall_delta(c, xs, bn[v[0]], lead_s, ds);
                    for (k = 0; k < D; ++k) {
                        ss += ds[k] * nrm[k];
                        se += dn[v[0]][k] * nrm[k];
                    }
                    /* the same side at both ends, or not behind it at the end */
                    if (!(ss * se < 0) && !(ss == 0 && se != 0)) continue;
                    if (ss < 0 || (ss == 0 && se > 0)) {
                        for (k = 0; k < D; ++k) nrm[k] = -nrm[k];
                        ss = -ss;
                        se = -se;
                    }
                    /* the end's foot on the plane, from the first, within the widened triangle */
                    for (k = 0; k < D; ++k) {
                        q[k] = dn[v[0]][k] - se / n2 * nrm[k];
                        b1 += q[k] * e1[k];
                        b2 += q[k] * e2[k];
                    }
                    if (D == 2) {
                        al = b1 / a11;
                        if (!(al >= SPH__R(-0.25) && al <= SPH__R(1.25))) continue;
                    } else {
                        const sph_real det = a11 * a22 - a12 * a12;
                        al = (b1 * a22 - b2 * a12) / det;
                        be = (b2 * a11 - b1 * a12) / det;
                        if (!(al >= SPH__R(-0.25) && be >= SPH__R(-0.25) &&
                              al + be <= SPH__R(1.25)))
                            continue;
                    }
                    /* back to the start, without the velocity into the wall (relative to its
                       nearest particle) */
                    vb = c->bv + bn[0] * (size_t)D;
                    u = 1 / sph__sqrt(n2);
                    for (k = 0; k < D; ++k) {
                        xi[k] = xs[k];
                        vn += (vi[k] - vb[k]) * nrm[k] * u;
                    }
                    if (vn < 0)
                        for (k = 0; k < D; ++k) vi[k] -= vn * nrm[k] * u;
                    return 1;
                }
    return 0;
}

/* One particle's contact: its distance d [m] to the nearest wall particle (d_c, or less on the
   3D ramp), d_c [m] to every other, the walls' lead at the step's end and at the drift's start
   (sph__wall_delta). */
typedef struct sph__contact_arg {
    sph_real d, d_c, lead, lead_s;
    const uint8_t* thin; /* sph__wall_thin's flags, or NULL (every wall thick) */
    const sph_real* gs;  /* the wall normal at x_s if the crossing guard took it, else NULL */
} sph__contact_arg;

/* The contact of particle i, from the drift's start x_s. Measured on drums of one layer of
   lattice points (R <= r < R + dx, Akinci volumes, turning at 2 rad/s about their axis, a third
   full; tests/test_scenes.c, drum_2d):
   - At a thin wall (sph__wall_thin: one layer) the ramp's lower distance d holds only for the
     nearest wall particle, d_c for the others: with d for every one, the hollows of the layer
     (0.71 dx from their corners) and its gaps (0.87 dx in the 3D drum) were open at d = 0.6 dx,
     and 3D drums (dx 0.04) let IISPH, DFSPH and PBF particles out within 0.2-0.5 s. There
     nothing passes between wall particles closer than 2 d_c (1.25 d_c over a square hollow), as
     without the ramp; a centre over a hollow stays 0.53 dx above the layer, just over its face,
     and one over a wall particle 0.6 dx. Another wall particle ahead of the push (dn < 0) is
     left out: at a junction of walls whose normals differ (a ramp's last row 0.5 dx in front of
     a box's wall) its d_c pushed a particle 1.5 dx into the wall. Thick walls keep d for every
     wall particle: d_c for the others there (pushing rows over the hollows up to 0.53 dx) kept a
     3D tank at rest moving at 0.044 (IISPH) and 0.091 (DFSPH) sqrt(g H) after 10 s instead of
     0.0084 and 0.028 (long/scenes/tank_3d_settles).
   - The push follows the wall's normal at the end unless that turned more than 18 degrees
     (cos 0.95) from the normal at x_s, where the step found the particle on the fluid side: in
     the line of a single layer, and in the gaps between its particles, the end's normal has no
     side. Along the end's normal IISPH, DFSPH and PBF particles crept into the diagonal gaps of
     the 2D drum's staircase (1.41 dx) and were sent out within 0.06-0.14 s (dx 0.01-0.02); with
     the start's normal beyond 90 degrees DFSPH and PBF still got out at dx 0.02, beyond 60
     degrees DFSPH at dx 0.01; the start's normal always put a particle through the 3D shell's
     corner (scenes/shell_3d) and doubled the front's distance between PCISPH's and WCSPH's dam
     breaks (pcisph/dam_break_vs_wcsph, 0.31 against 0.15).
   - A second pass, for a particle pushed onto another wall, follows the normal where it is.
   With both, the drums run 2 s with every solver and nothing out (2D at dx 0.01, 0.015, 0.02;
   3D at dx 0.04; Akinci volumes), but IISPH's 2D drum at dx 0.015 fails at 1.86 s (reported).
   Drums of one layer with volumes dx^dim (SPH_BVOL_GIVEN) still let IISPH, DFSPH and PBF
   particles out in 3D within 0.35-0.4 s, unreported; the default volumes (SPH_BVOL_AUTO) weigh
   the layer as a full wall, and then PBF alone let one particle out, at 1.7 s of 2 s (dx 0.04;
   at 0.4 s in float): it crept into a gap 0.68 dx from the nearest wall particle, whose ramp
   distance allows that. d_c for the nearest too closed the route in both precisions but failed
   IISPH's 3D jet in float (reported, 0.03 s, a particle 21 % compressed); not kept. */
static int sph__wall_contact(const sph__ctx* c, size_t i, const sph__contact_arg* a,
                             const sph_real* xs, sph_real* xi, sph_real* vi) {
    const int D = c->dim;
    const size_t k0 = c->fb->begin[i], k1 = k0 + c->fb->count[i];
    const sph_real dc2 = a->d_c * a->d_c, d2 = a->d < a->d_c ? a->d * a->d : dc2;
    sph_real do2; /* the others' distance^2: d_c at a thin wall, else d */
    const sph_real lead = a->lead;
    int pass, moved = 0;
    for (pass = 0; pass < 2; ++pass) { /* a second pass for a particle pushed onto another wall */
        sph_real g[3], n[3] = {0, 0, 0}, gn = 0, s = 0, vn = 0, r2min = dc2, r2second = dc2;
        sph_real dn_near[3] = {0, 0, 0};
        size_t kk, near = k1;
        int k;
        for (kk = k0; kk < k1; ++kk) { /* the nearest two wall particles within d_c, if any */
            sph_real d[3] = {0, 0, 0}, r2 = 0;
            sph__wall_delta(c, xi, c->fb->idx[kk], lead, d);
            for (k = 0; k < D; ++k) r2 += d[k] * d[k];
            if (r2 < r2min) {
                r2second = r2min;
                r2min = r2;
                near = kk;
                for (k = 0; k < D; ++k) dn_near[k] = d[k];
            } else if (r2 < r2second) {
                r2second = r2;
            }
        }
        if (near == k1) break;
        do2 = a->thin && a->thin[c->fb->idx[near]] ? dc2 : d2;
        /* nearest at least d, the others at least their distance: nothing to do */
        if (!(r2min < d2) && !(r2second < do2)) break;
        sph__wall_normal(c, i, xi, lead, g);
        for (k = 0; k < D; ++k) gn += g[k] * g[k];
        if (pass == 0) { /* the start's normal where the end's turned from it by over 18 deg */
            sph_real gs[3], dot = 0, gs2 = 0;
            if (a->gs) for (k = 0; k < D; ++k) gs[k] = a->gs[k];
            else sph__wall_normal(c, i, xs, a->lead_s, gs);
            for (k = 0; k < D; ++k) { dot += g[k] * gs[k]; gs2 += gs[k] * gs[k]; }
            if (gs2 > 0 && !(dot > SPH__R(0.95) * sph__sqrt(gn * gs2))) {
                for (k = 0; k < D; ++k) g[k] = gs[k];
                gn = gs2;
            }
        }
        if (gn > 0) {
            gn = 1 / sph__sqrt(gn);
            for (k = 0; k < D; ++k) n[k] = g[k] * gn;
        } else { /* a symmetric spot (inside a thin wall): away from the nearest wall particle */
            const sph_real r = sph__sqrt(r2min);
            if (!(r > 0)) break; /* on a wall particle's centre: no direction (check_walls) */
            for (k = 0; k < D; ++k) n[k] = dn_near[k] / r;
        }
        for (kk = k0; kk < k1; ++kk) {
            const size_t b = c->fb->idx[kk];
            const sph_real rb2 = kk == near ? d2 : do2;
            sph_real d[3] = {0, 0, 0}, r2 = 0, dn = 0, sb;
            sph__wall_delta(c, xi, b, lead, d);
            for (k = 0; k < D; ++k) { r2 += d[k] * d[k]; dn += d[k] * n[k]; }
            /* on the ramp, another wall particle ahead along n (dn < 0) is not cleared by a push
               along n but through it and beyond: at a junction of walls whose normals differ (a
               ramp's row 0.5 dx in front of a box's wall) d_c for it pushed a particle 1.5 dx
               into the wall */
            if (!(r2 < rb2) || (rb2 > d2 && dn < 0)) continue;
            sb = -dn + sph__sqrt(dn * dn - r2 + rb2); /* real: rb2 > r2 */
            if (sb > s) s = sb;
        }
        for (k = 0; k < D; ++k) {
            xi[k] += s * n[k];
            vn += (vi[k] - c->bv[c->fb->idx[near] * (size_t)D + (size_t)k]) * n[k];
        }
        if (vn < 0)
            for (k = 0; k < D; ++k) vi[k] -= vn * n[k];
        moved = 1;
    }
    return moved;
}

/* The energy check of the incompressible solvers (PCISPH, IISPH, DFSPH; PBF without gravity).
   Without a force callback or moving walls nothing does work on their fluid but gravity, which
   only trades potential for kinetic energy, its pressure, which gives back no more than the
   compression it stores, and viscosity, which only takes; at their compression (0.1 %) the stored
   energy is tiny and only motion makes more of it. So once the forcing stops, a mechanical energy
   E = kinetic + potential (-sum m g . x) that climbs above the least it has had since by more than
   half the largest kinetic energy (or by more than twice the largest energy compression stored
   since, sum_i p_i V_i max(rho_i/rho0 - 1, 0); and a floor of 1e-4 c0 in speed (it was 1e-4
   spacings per step, which a retried step shrinking dt by a thousand made a thousand times larger,
   until a real gain passed) and, with gravity, of a tenth of a spacing's lift of the whole mass,
   0.1 M |g| dx) is the walls or the solver doing work: the step fails with SPH_ERR_UNSTABLE.
   Gravity along a periodic direction drives the flow (a channel): forcing. Measured without
   gravity: the original PCISPH with extrapolated wall pressure in a closed vortex box at a hand-
   set dt of 2 ms climbed from 5 J to 490 J within 0.4 s below the speed bound
   (tests/test_reliability.c's kinetic_energy_decays, which now runs at the library's own steps,
   where it decays); the decaying flows of the tests rise by at most 6 % of their start between
   samples. With gravity (where the check used to be off): a single particle bouncing on the floor
   of a box under enhanced PCISPH climbed to 298 m g dx above its start by 1.1 s, every frame
   SPH_OK, until its speed passed the bound; now the call at 0.85 s fails, the particle 0.82 m g dx
   above its start (the check allows half the largest kinetic energy, 2 m g dx there: it stops
   runaways, not every gain). The floor covers what the wall contact (sph__wall_contact) lifts when
   it moves particles out of a wall, and the potential energy a settling column gives back. WCSPH
   stores real elastic energy (a droplet may rebound) and the compressible step's gas trades
   internal energy for motion: both are exempt, and so is PBF under gravity: its projection keeps a
   column compressed by up to its 1 % target in the positions, not in a pressure, and gives it back
   as lift (its 2D tank at rest, 40 layers, rose more than the floor and failed at 0.1 s). A host
   that changes velocities or positions between steps (a game's splash, an emitter) starts the
   check again (sph__check_step_input). */
static sph_status sph__energy_check(sph_world* w, double ke, double pe, double wrel) {
    sph_stats* st = &w->stats;
    int k, forced = w->def.force != NULL || w->def.boundary_motion != NULL ||
                    !sph__incompressible(w->priv.solver);
    const double e = ke + pe;
    for (k = 0; k < w->dim; ++k) /* PBF: see above; gravity along a periodic direction drives */
        forced |= w->def.gravity[k] != 0 && (w->def.periodic[k] || w->priv.solver == SPH_SOLVER_PBF);
    if (forced || !(st->dt > 0)) {
        st->unforced_steps = 0;
        return SPH_OK;
    }
    if (st->unforced_steps > 0) {
        const double M = sph_world_mass(w);
        double g2 = 0, floor_v = 0;
        for (k = 0; k < w->nphase; ++k)
            if (1e-4 * (double)w->phases[k].sound_speed > floor_v)
                floor_v = 1e-4 * (double)w->phases[k].sound_speed;
        for (k = 0; k < w->dim; ++k) g2 += (double)w->def.gravity[k] * (double)w->def.gravity[k];
        if (e - st->ke_low >
            0.5 * st->ke_high + 0.5 * M * floor_v * floor_v + 0.1 * M * sqrt(g2) * (double)w->dx)
            return sph__fail(w, SPH_ERR_UNSTABLE, -1,
                             "step %llu (t = %g s): the mechanical energy (kinetic + potential) "
                             "rose %g J above the least it had since the forcing stopped (%g J; "
                             "kinetic now %g J, at most %g J) without forcing (no force callback "
                             "or moving wall): the walls or the solver did work on the fluid",
                             (unsigned long long)w->steps, w->time, e - st->ke_low, st->ke_low, ke,
                             st->ke_high);
        if (e < st->ke_low) st->ke_low = e;
        if (ke > st->ke_high) st->ke_high = ke;
        if (4 * wrel > st->ke_high) st->ke_high = 4 * wrel;
    } else {
        st->ke_low = e;
        st->ke_high = ke > 4 * wrel ? ke : 4 * wrel;
    }
    ++st->unforced_steps;
    return SPH_OK;
}

/* The least density a particle carries [kg/m^3]: alone, its summation density is its own term
   m_i W(0) / S (Enhanced PCISPH 2018 eq. 2.4 without neighbours). The continuity equation (and
   Ott & Schnetter's particle density) integrates that sum's change, so a particle leaving its
   neighbours tends to this value, and an explicit step overshoots it, to zero and below (a 2D dam
   break, 0.4 x 0.6 m column, dx 0.01: -5e-5 rho0 at 3.8 s, reported as a blow-up). The pressure
   there is clamped at zero (sph__clamps), so the floor changes no force; it keeps m / rho finite.
   Without the clamp a density below it is a blow-up, and is reported. */
SPH__INLINE sph_real sph__rho_floor(const sph__ctx* c, size_t i, sph_real rho) {
    const sph_real lo = (c->m ? c->m[i] : c->m0) * c->rho_alone;
    return c->rho_floor && rho < lo ? lo : rho;
}

/* The least ratio of two liquid phases' rest densities (1: one phase, or phases of one density). */
static double sph__rest_density_ratio(const sph_world* w) {
    double lo = 0, hi = 0;
    int k;
    for (k = 0; k < w->nphase; ++k) {
        const double r = (double)w->phases[k].rest_density;
        if (w->phases[k].eos == SPH_EOS_IDEAL_GAS || w->phases[k].eos == SPH_EOS_STIFFENED_GAS)
            continue;
        if (lo == 0 || r < lo) lo = r;
        if (r > hi) hi = r;
    }
    return hi > 0 ? lo / hi : 1;
}

/* Whether the step carries the density (the continuity equation or Ott & Schnetter's particle
   density) instead of summing it from the positions each step: WCSPH, enhanced PCISPH and the
   compressible step with def.density other than SPH_DENSITY_SUMMATION (IISPH, DFSPH and PBF
   always sum). */
static int sph__carries_density_for(const sph_world* w, int solver) {
    return w->def.density != SPH_DENSITY_SUMMATION &&
           (solver == SPH_SOLVER_WCSPH || solver == SPH_SOLVER_PCISPH || solver == SPH_SOLVER_COMPRESSIBLE);
}

/* The carried density of a wall contact's displacement. The contact and the crossing guard move a
   particle by dx_i after its step's density rate was taken: a motion the continuity equation
   never saw. A summation density sees it; a carried one must be told, or the displacement is a
   compression no pressure answers. So the displacement is integrated as the continuity equation
   (Monaghan 1992; Enhanced PCISPH 2018 eq. 3.2) integrates a velocity, exactly, as the change of
   the kernel sums it makes:
       rho_i += sum_j mu_j [W(x_i - x_j) - W(x_i - dx_i - x_j + dx_j)]
              + sum_b psi_b [W(x_i - x_b) - W(x_i - dx_i - x_b)],
   mu_j = m_j (m_i for the particle density), psi_b = rho0_i V_b (Akinci et al. 2012): the
   moved particle and the fluid it was pushed into gain what their summation densities gain.
   Why: the contact lifts a particle that the wall pressure did not stop (a sheet short of
   neighbours runs along the floor) back to d_c from the wall, i.e. into the fluid above it, every
   step, and that fluid's carried density never learned of it. Measured on a 2D dam break (0.4 x
   0.6 m column, 1.6 x 0.8 m tank of Akinci-volume walls, dx 0.01, enhanced PCISPH): the floor
   row's summation density rose to 1.6 times its carried density by t = 0.3 s (2 by 0.4 s;
   without the contact and delta-SPH 1.000, with delta-SPH alone 1.03), the contact's unrecorded
   displacements accounting for it (its share summed over the fluid +81 rho0 against -13 for
   everything else), so PCISPH saw rest density where particles were paired at 0.001 dx and
   piled into the bottom corner until one was compressed past max_compression at t = 1.18 s.
   With it the ratio stays at delta-SPH's 1.03 and the run reaches 3 s. A decrease stops at the
   density of a particle alone, m_i W(0) / S (the least a summation density can be): a splash
   particle whose carried density the explicit step had already taken below that (the continuity
   equation overshoots as a particle leaves its neighbours) was driven negative by it on a ramp
   and failed the run. dx_i is in w->priv.shift (scratch, reserved by sph__step_begin; all
   particles' before any density changes); the lists are the step's (the pairs its density rate used). */
static void sph__contact_density(sph_world* w, const sph__ctx* c, const sph_real* sh) {
    const int D = w->dim, os = w->def.density == SPH_DENSITY_PARTICLE;
    sph__idx i;
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)w->n; ++i) {
        const sph_real* xi = w->x + (size_t)i * (size_t)D;
        const sph_real* di = sh + (size_t)i * (size_t)D;
        const sph_real mi = c->m ? c->m[i] : c->m0, rho0 = c->pc[w->phase[i]].rho0;
        const int moved = di[0] != 0 || (D > 1 && di[1] != 0) || (D > 2 && di[2] != 0);
        sph_real sum = 0;
        size_t kk, k0 = c->ff->begin[i], k1 = k0 + c->ff->count[i];
        int k;
        for (kk = k0; kk < k1; ++kk) {
            const size_t j = c->ff->idx[kk];
            const sph_real* dj = sh + j * (size_t)D;
            sph_real d[3] = {0, 0, 0}, r1 = 0, r0 = 0;
            if (!moved && dj[0] == 0 && (D < 2 || dj[1] == 0) && (D < 3 || dj[2] == 0)) continue;
            sph__delta_vec(c, xi, w->x + j * (size_t)D, d, D);
            for (k = 0; k < D; ++k) {
                const sph_real e = d[k] - di[k] + dj[k];
                r1 += d[k] * d[k];
                r0 += e * e;
            }
            sum += (os ? mi : (c->m ? c->m[j] : c->m0)) * (sph__kw(c->k.form, sph__sqrt(r1) * c->k.inv_h) -
                                                           sph__kw(c->k.form, sph__sqrt(r0) * c->k.inv_h));
        }
        if (moved && c->has_b) {
            k0 = c->fb->begin[i];
            k1 = k0 + c->fb->count[i];
            for (kk = k0; kk < k1; ++kk) {
                const size_t b = c->fb->idx[kk];
                sph_real d[3] = {0, 0, 0}, r1 = 0, r0 = 0;
                sph__delta_vec(c, xi, c->bx + b * (size_t)D, d, D);
                for (k = 0; k < D; ++k) {
                    r1 += d[k] * d[k];
                    r0 += (d[k] - di[k]) * (d[k] - di[k]);
                }
                sum += rho0 * c->bvol[b] * (sph__kw(c->k.form, sph__sqrt(r1) * c->k.inv_h) -
                                            sph__kw(c->k.form, sph__sqrt(r0) * c->k.inv_h));
            }
        }
        sum *= c->k.norm_w;
        if (sum < 0) { /* no lower than a particle alone, m_i W(0) / S (a carried density below it
                          stays where it is) */
            const sph_real alone = mi * c->rho_alone;
            const sph_real lo = w->rho[i] < alone ? w->rho[i] : alone;
            w->rho[i] = w->rho[i] + sum > lo ? w->rho[i] + sum : lo;
        } else {
            w->rho[i] += sum;
        }
    }
}

static sph_status sph__integrate_with(sph_world* w, const sph__ctx* c, const sph_real* acc,
                                      sph_real kv, sph_real kr, sph_real kx, int final) {
    const int D = w->dim;
    const size_t nblk = (w->n + SPH__BLOCK - 1) / SPH__BLOCK;
    sph_real vlim = w->def.max_speed;
    /* the automatic bound's headroom for a fall: below, with the bound */
    const int fall = !(w->def.max_speed > 0) && sph__incompressible(w->priv.solver) &&
                     w->priv.head_ref_on;
    const double head_ref = w->priv.head_ref;
    double red[SPH__RED_N];
    /* the largest distance a particle may cover in one step at its final speed [m], and the
       wall fraction check_walls allows (lattice walls of given volumes only) */
    const double dmax = (double)w->def.max_displacement * (double)w->dx,
                 dt2 = w->stats.dt * w->stats.dt;
    /* max_compression fails a step that compressed a particle past it, not one that started
       with it so: a compression a host put in (particles placed into others: an emitter, a
       second fill of the same box) no smaller step can undo, and sph_advance's retries would
       all fail. IISPH and DFSPH sum rho at the step's start: their solves check the density
       they predict for its end instead (sph__step_iisph, sph__step_dfsph). PCISPH's rho is its
       last prediction, the others' the step's end */
    const double cmax = w->priv.solver == SPH_SOLVER_IISPH || w->priv.solver == SPH_SOLVER_DFSPH
                            ? 0
                            : (double)w->def.max_compression;
    const int tank = final && w->def.check_walls && w->priv.tanks == 1 && !w->def.boundary_motion;
    const int walls = final && w->def.check_walls && c->has_b && w->nb > 0 &&
                      w->def.boundary_volume != SPH_BVOL_AKINCI && w->priv.wall_fraction_max > 0;
    /* the contact distance [m] (sph__wall_contact), at the step's final drift, and whether it
       ramps down with the neighbour count (3D, zero wall pressure, incompressible solvers) */
    const sph_real dc = final && kx != 0 && c->has_b && w->nb > 0 ? w->def.wall_contact * w->dx : 0;
    /* moved walls at the step's end (sph__wall_delta); the time has advanced already */
    const sph_real lead = dc > 0 && w->def.boundary_motion ? (sph_real)(w->time - w->priv.b_time) : 0;
    const int ramp = D == 3 && sph__incompressible(w->priv.solver) &&
                     c->bp_mode == SPH_BP_ZERO && w->priv.full_count > 0;
    const sph_real inv_full = ramp ? 1 / (sph_real)w->priv.full_count : 0;
    /* the thin walls' flags, for the crossing check (sph__wall_crossed; static walls only) */
    const uint8_t* thin =
        dc > 0 && w->priv.b_thin_on && !w->def.boundary_motion ? w->priv.b_thin : NULL;
    const sph_real* xst = thin ? w->priv.x_start : NULL;
    /* the contact's displacements, for a carried density (sph__contact_density; the scratch
       comes from sph__step_begin) */
    sph_real* sh = dc > 0 && sph__carries_density_for(w, w->priv.solver) &&
                           w->priv.shift_cap >= w->n * (size_t)D ? w->priv.shift : NULL;
    sph__idx blk;
    size_t q;
    int k;
    if (vlim <= 0) {
        int ph;
        for (ph = 0; ph < w->nphase; ++ph) vlim = sph__max(vlim, w->phases[ph].sound_speed);
        /* the compressible step is for flows near and above the speed of sound (a shock's
           piston, an expansion into vacuum reaches 2 c0/(gamma - 1) = 5 c0 for air): there
           only a runaway is a blow-up */
        if (w->priv.solver == SPH_SOLVER_COMPRESSIBLE) vlim *= 10;
        /* the incompressible solvers have no sound speed that bounds the flow: the automatic c0
           is 10 max(sqrt(2 |g| H), |v|max), ten times the free-fall speed over the height the
           fluid can fall (sph__resolve_sound_speed) or the fastest start, and the bound is c0.
           The jets of an impact grow with the resolution (a round body's contact line starts
           infinitely fast, Wagner 1932): the disc of sph__resolve_sound_speed's measurement
           threw them at 3.8-4.7 times the free-fall speed at dx 0.01 (15.4-19.0 m/s at frame
           ends, IISPH, DFSPH, PBF and both PCISPH) and 5.1-7.1 times at dx 0.005 (20.9-28.8
           m/s), where the bound 0.5 c0 used before failed IISPH, DFSPH and PBF at 0.34 s; a
           dam break's splash reached 2.3 times, a block thrown at 5 m/s against a wall ran up it
           at 4.4-5.4 times its speed. That bound had been chosen because c0 let a runaway IISPH
           step grind on at a thousandth of its stable step for 4000 sub-steps (a fuzzed world
           of 320 particles, tests/fuzz_corpus/regressions/api/speed-bound-grind.bin: 50 s under
           the sanitizers against 0.06 s); with c0 that input now takes 0.08 s under ASan +
           UBSan (its sph_advance stops at def.max_substeps). Walls move the fluid at up to
           twice their speed (a piston's reflected wave), which is added. A fall adds what gravity
           gives: particle i may be as fast as v^2 <= vlim^2 + 2 (head_ref - phi_i), phi_i =
           -g.x_i, head_ref the largest -g.x + v^2/2 of a particle at the end of the first step
           since the host last changed the state (set below, cleared by sph__check_step_input),
           so that a runaway's own gain does not raise it. Without it a blob falling freely (no
           floor below: c0 from its own height) tripped the bound after about 100 of its
           heights. */
        if (sph__incompressible(w->priv.solver) && vlim > 0) {
            double vb2 = 0;
            size_t b;
            for (b = 0; b < w->nb * (size_t)D; b += (size_t)D) {
                double v2 = 0;
                for (k = 0; k < D; ++k) v2 += (double)w->b_v[b + (size_t)k] * (double)w->b_v[b + (size_t)k];
                if (v2 > vb2) vb2 = v2;
            }
            vlim = (sph_real)((double)vlim + 2 * sqrt(vb2));
        }
    }
    if (nblk * SPH__RED_N > w->priv.block_cap) {
        size_t cap = nblk * SPH__RED_N + 64;
        if (!sph__grow((void**)&w->priv.block, cap, sizeof(double)))
            return sph__fail(w, SPH_ERR_NOMEM, -1, "out of memory (reduction blocks)");
        w->priv.block_cap = cap;
    }
    SPH__OMP_FOR(w->n) /* over blocks of SPH__BLOCK particles */
    for (blk = 0; blk < (sph__idx)nblk; ++blk) {
        const size_t i0 = (size_t)blk * SPH__BLOCK;
        const size_t i1 = i0 + SPH__BLOCK < w->n ? i0 + SPH__BLOCK : w->n;
        /* the block's sums in a local array, stored to the shared one once per block instead of
           once per particle (no measurable change in the step time) */
        double r[SPH__RED_N];
        size_t i;
        int kk;
        for (kk = 0; kk < SPH__RED_N; ++kk) r[kk] = 0;
        r[SPH__RED_BAD] = -1;
        r[SPH__RED_HEAD] = -1e300;
        for (i = i0; i < i1; ++i) {
            sph_real* xi = w->x + i * (size_t)D;
            sph_real* vi = w->v + i * (size_t)D;
            const sph_real* ai = acc + i * (size_t)D;
            double v2 = 0, a2 = 0, err, mi, phi = 0;
            int out = 0, bad = SPH__BAD_NONE;
            sph_real xold[3], gold[3];
            int guard = 0;
            if (kv != 0) for (kk = 0; kk < D; ++kk) vi[kk] += kv * ai[kk];
            if (kr != 0) w->rho[i] = sph__rho_floor(c, i, w->rho[i] + kr * w->drho[i]);
            if (final && dc > 0 && c->fb->count[i] > 0) {
                /* sph__wall_cross_guard: only a particle that moves far enough to cross */
                sph_real m2 = 0;
                for (kk = 0; kk < D; ++kk) {
                    m2 += kx * vi[kk] * kx * vi[kk];
                    xold[kk] = xi[kk]; /* where the drift starts (sph__wall_contact) */
                }
                if (m2 > SPH__R(SPH__CROSS_MOVE * SPH__CROSS_MOVE) * w->dx * w->dx) {
                    guard = 1;
                    sph__wall_normal(c, i, xi, lead - kx, gold);
                }
            }
            for (kk = 0; kk < D; ++kk) {
                if (kx != 0) xi[kk] += kx * vi[kk];
                if (c->per[kk]) {
                    const sph_real lo = w->def.domain_lo[kk];
                    if (xi[kk] < lo || xi[kk] >= lo + c->len[kk])
                        xi[kk] -= c->len[kk] * sph__floor((xi[kk] - lo) / c->len[kk]);
                    if (xi[kk] >= lo + c->len[kk]) xi[kk] = lo; /* rounding at the top edge */
                }
            }
            if (!final) continue;
            if (sh) for (kk = 0; kk < D; ++kk) sh[i * (size_t)D + (size_t)kk] = xi[kk];
            if (dc > 0 && c->fb->count[i] > 0) {
                sph__contact_arg ca;
                ca.d = ca.d_c = dc;
                ca.lead = lead;
                ca.lead_s = lead - kx;
                ca.thin = ramp && w->priv.b_thin_on ? w->priv.b_thin : NULL;
                ca.gs = guard ? gold : NULL;
                if (ramp) { /* from d_c short of neighbours down to 0.6 dx with a full set */
                    const sph_real d0 = SPH__R(SPH__CONTACT_REST) * w->dx;
                    const sph_real nf = (sph_real)(c->ff->count[i] + c->fb->count[i]) * inv_full;
                    sph_real f = (w->priv.contact_full - nf) /
                                 (w->priv.contact_full - w->priv.contact_short);
                    f = f < 0 ? 0 : f > 1 ? 1 : f;
                    ca.d = d0 + f * (dc > d0 ? dc - d0 : 0);
                }
                if (guard && sph__wall_cross_guard(c, i, xold, gold, lead, xi, vi))
                    r[SPH__RED_CONTACT] += 1;
                else {
                    const int pushed = sph__wall_contact(c, i, &ca, xold, xi, vi);
                    /* from the step's start: x^n of a step of two drifts (sph__x_start) */
                    const sph_real* xs0 =
                        !xst ? xold
                        : w->priv.sorts == w->priv.x_start_sorts
                            ? xst + i * (size_t)D
                            : xst + (size_t)w->priv.grid.order[i] * (size_t)D;
                    const sph_real lead_s = lead - kx - (xst ? w->priv.x_start_drift : 0);
                    if ((thin && sph__wall_crossed(c, i, thin, xs0, lead, lead_s, w->dx, xi, vi)) ||
                        pushed)
                        r[SPH__RED_CONTACT] += 1;
                }
            }
            if (sh) /* the contact's (and the guard's) displacement */
                for (kk = 0; kk < D; ++kk) sh[i * (size_t)D + (size_t)kk] = xi[kk] - sh[i * (size_t)D + (size_t)kk];
            mi = (double)(w->m ? w->m[i] : w->mass);
            for (kk = 0; kk < D; ++kk) {
                if (!c->per[kk]) phi -= (double)c->g[kk] * (double)xi[kk];
                v2 += (double)vi[kk] * (double)vi[kk];
                a2 += (double)ai[kk] * (double)ai[kk];
                if (!sph__finite((double)xi[kk])) bad = SPH__BAD_NONFINITE;
                if (!c->per[kk] && w->def.domain_lo[kk] < w->def.domain_hi[kk] &&
                    (xi[kk] < w->def.domain_lo[kk] || xi[kk] > w->def.domain_hi[kk]))
                    out = 1;
            }
            err = (double)(w->rho[i] * c->pc[w->phase[i]].inv_rho0) - 1;
            if (!sph__finite(v2) || !sph__finite((double)w->rho[i]) ||
                (c->e && !sph__finite((double)c->e[i])))
                bad = SPH__BAD_NONFINITE;
            else if (!(w->rho[i] > 0)) bad = SPH__BAD_DENSITY;
            /* a gas compresses freely (a shock by (gamma + 1)/(gamma - 1)), but its sound speed
               must stay real: p + p_inf >= 0, i.e. rho e >= p_inf */
            else if (c->pc[w->phase[i]].gas && c->e && w->rho[i] * c->e[i] < c->pc[w->phase[i]].pinf)
                bad = SPH__BAD_ENERGY;
            else if (cmax > 0 && err > cmax && !c->pc[w->phase[i]].gas)
                bad = SPH__BAD_COMPRESSION;
            else if (vlim > 0 && v2 > (double)vlim * (double)vlim +
                                          (fall && head_ref > phi ? 2 * (head_ref - phi) : 0))
                bad = SPH__BAD_SPEED;
            else if (dmax > 0 && v2 * dt2 > dmax * dmax) bad = SPH__BAD_DISPLACEMENT;
            else if (walls && c->fb->count[i] > 0 &&
                     sph__wall_fraction(c, xi, i, w->priv.lattice_sum) > w->priv.wall_fraction_max)
                bad = SPH__BAD_WALL;
            else if (tank && sph__tank_outside(w, xi)) bad = SPH__BAD_TANK;
            r[SPH__RED_KE] += 0.5 * mi * v2;
            r[SPH__RED_PE] += mi * phi;
            if (phi + 0.5 * v2 > r[SPH__RED_HEAD]) r[SPH__RED_HEAD] = phi + 0.5 * v2;
            if (err > 0 && w->p && w->rho[i] > 0)
                r[SPH__RED_WREL] += (double)w->p[i] * mi / (double)w->rho[i] * err;
            r[SPH__RED_ERRSUM] += fabs(err);
            if (err > 0) r[SPH__RED_COMP] += err;
            if (fabs(err) > r[SPH__RED_ERRMAX]) r[SPH__RED_ERRMAX] = fabs(err);
            if (v2 > r[SPH__RED_V2MAX]) r[SPH__RED_V2MAX] = v2;
            if (a2 > r[SPH__RED_A2MAX]) r[SPH__RED_A2MAX] = a2;
            r[SPH__RED_OUT] += out;
            if (bad != SPH__BAD_NONE && r[SPH__RED_BAD] < 0) {
                r[SPH__RED_BAD] = (double)i;
                r[SPH__RED_KIND] = bad;
            }
        }
        if (final) memcpy(w->priv.block + (size_t)blk * SPH__RED_N, r, sizeof(r));
    }
    if (!final) return SPH_OK;
    for (k = 0; k < SPH__RED_N; ++k) red[k] = 0;
    red[SPH__RED_BAD] = -1;
    red[SPH__RED_HEAD] = -1e300;
    for (q = 0; q < nblk; ++q) {
        const double* r = w->priv.block + q * SPH__RED_N;
        red[SPH__RED_KE] += r[SPH__RED_KE];
        red[SPH__RED_ERRSUM] += r[SPH__RED_ERRSUM];
        red[SPH__RED_COMP] += r[SPH__RED_COMP];
        if (r[SPH__RED_ERRMAX] > red[SPH__RED_ERRMAX]) red[SPH__RED_ERRMAX] = r[SPH__RED_ERRMAX];
        if (r[SPH__RED_V2MAX] > red[SPH__RED_V2MAX]) red[SPH__RED_V2MAX] = r[SPH__RED_V2MAX];
        if (r[SPH__RED_A2MAX] > red[SPH__RED_A2MAX]) red[SPH__RED_A2MAX] = r[SPH__RED_A2MAX];
        red[SPH__RED_OUT] += r[SPH__RED_OUT];
        red[SPH__RED_CONTACT] += r[SPH__RED_CONTACT];
        red[SPH__RED_WREL] += r[SPH__RED_WREL];
        red[SPH__RED_PE] += r[SPH__RED_PE];
        if (r[SPH__RED_HEAD] > red[SPH__RED_HEAD]) red[SPH__RED_HEAD] = r[SPH__RED_HEAD];
        if (red[SPH__RED_BAD] < 0 && r[SPH__RED_BAD] >= 0) {
            red[SPH__RED_BAD] = r[SPH__RED_BAD];
            red[SPH__RED_KIND] = r[SPH__RED_KIND];
        }
    }
    if (sh && red[SPH__RED_CONTACT] > 0) {
        /* the contact's compression joins the carried density; a particle it compresses past
           max_compression fails the step as any other (the first by index) */
        sph__contact_density(w, c, sh);
        if (red[SPH__RED_BAD] < 0 && w->def.max_compression > 0)
            for (q = 0; q < w->n; ++q)
                if (!c->pc[w->phase[q]].gas && (double)(w->rho[q] * c->pc[w->phase[q]].inv_rho0) - 1 >
                                                   (double)w->def.max_compression) {
                    red[SPH__RED_BAD] = (double)q;
                    red[SPH__RED_KIND] = SPH__BAD_COMPRESSION;
                    break;
                }
    }
    w->stats.kinetic_energy = red[SPH__RED_KE];
    w->stats.potential_energy = red[SPH__RED_PE];
    if (!w->priv.head_ref_on && w->n > 0) {
        w->priv.head_ref = red[SPH__RED_HEAD];
        w->priv.head_ref_on = 1;
    }
    w->stats.density_error_avg = w->n ? red[SPH__RED_ERRSUM] / (double)w->n : 0;
    w->stats.density_error_max = red[SPH__RED_ERRMAX];
    w->stats.compression_avg = w->n ? red[SPH__RED_COMP] / (double)w->n : 0;
    w->stats.v_max = sqrt(red[SPH__RED_V2MAX]);
    w->stats.a_max = sqrt(red[SPH__RED_A2MAX]);
    w->stats.n_outside = (size_t)red[SPH__RED_OUT];
    w->stats.contacts = (size_t)red[SPH__RED_CONTACT];
    if (red[SPH__RED_BAD] < 0) {
        const sph_status s =
            sph__energy_check(w, red[SPH__RED_KE], red[SPH__RED_PE], red[SPH__RED_WREL]);
        if (s != SPH_OK) return s;
    }
    if (red[SPH__RED_BAD] >= 0) {
        const size_t i = (size_t)red[SPH__RED_BAD];
        const int kind = (int)red[SPH__RED_KIND];
        const double rr = (double)(w->rho[i] * c->pc[w->phase[i]].inv_rho0);
        double v2 = 0;
        for (k = 0; k < D; ++k) v2 += (double)w->v[i * (size_t)D + (size_t)k] * (double)w->v[i * (size_t)D + (size_t)k];
        switch (kind) {
        case SPH__BAD_NONFINITE:
            return sph__fail(w, SPH_ERR_UNSTABLE, (long)i,
                             "step %llu (t = %g s): fluid particle %zu (id %u) became non-finite",
                             (unsigned long long)w->steps, w->time, i, (unsigned)w->id[i]);
        case SPH__BAD_DENSITY:
            return sph__fail(w, SPH_ERR_UNSTABLE, (long)i,
                             "step %llu (t = %g s): fluid particle %zu (id %u) has density %g <= 0",
                             (unsigned long long)w->steps, w->time, i, (unsigned)w->id[i],
                             (double)w->rho[i]);
        case SPH__BAD_COMPRESSION:
            /* PCISPH keeps the step's starting density: compressed there already, the cause is
               the input, which no smaller step undoes */
            if (w->priv.solver == SPH_SOLVER_PCISPH &&
                (double)(w->priv.rho_n[i] * c->pc[w->phase[i]].inv_rho0) - 1 >
                    (double)w->def.max_compression)
                return sph__fail(w, SPH_ERR_UNSTABLE, (long)i,
                                 "step %llu (t = %g s): fluid particle %zu (id %u) compressed to "
                                 "rho/rho0 = %g (max_compression %g), and to %g at the step's "
                                 "start already: %s",
                                 (unsigned long long)w->steps, w->time, i, (unsigned)w->id[i], rr,
                                 (double)w->def.max_compression,
                                 (double)(w->priv.rho_n[i] * c->pc[w->phase[i]].inv_rho0),
                                 w->def.density == SPH_DENSITY_SUMMATION &&
                                         sph__rest_density_ratio(w) < 1
                                     ? "the summed density smears the mass jump between phases "
                                       "(the original PCISPH is not for phases of different "
                                       "density: sph.h, PHASES)"
                                     : "particles placed into others? (IISPH and DFSPH push "
                                       "such overlaps apart)");
            return sph__fail(w, SPH_ERR_UNSTABLE, (long)i,
                             "step %llu (t = %g s): fluid particle %zu (id %u) compressed to "
                             "rho/rho0 = %g (max_compression %g): time step too large or "
                             "sound speed too low",
                             (unsigned long long)w->steps, w->time, i, (unsigned)w->id[i], rr,
                             (double)w->def.max_compression);
        case SPH__BAD_ENERGY:
            return sph__fail(w, SPH_ERR_UNSTABLE, (long)i,
                             "step %llu (t = %g s): fluid particle %zu (id %u) of a gas phase has "
                             "internal energy %g J/kg at density %g: pressure below -p_inf, no "
                             "real sound speed",
                             (unsigned long long)w->steps, w->time, i, (unsigned)w->id[i],
                             (double)c->e[i], (double)w->rho[i]);
        case SPH__BAD_DISPLACEMENT:
            return sph__fail(w, SPH_ERR_UNSTABLE, (long)i,
                             "step %llu (t = %g s): fluid particle %zu (id %u) moves %g spacings "
                             "per step (%g m/s at dt = %g s; max_displacement %g): the step is "
                             "too large for this speed, a particle could cross a wall",
                             (unsigned long long)w->steps, w->time, i, (unsigned)w->id[i],
                             sqrt(v2 * dt2) / (double)w->dx, sqrt(v2), w->stats.dt,
                             (double)w->def.max_displacement);
        case SPH__BAD_TANK:
            return sph__fail(w, SPH_ERR_UNSTABLE, (long)i,
                             "step %llu (t = %g s): fluid particle %zu (id %u) at (%g, %g, %g) is "
                             "more than a spacing outside the closed box of sph_add_wall_box: it "
                             "crossed a wall", (unsigned long long)w->steps, w->time, i,
                             (unsigned)w->id[i], (double)w->x[i * (size_t)D],
                             D > 1 ? (double)w->x[i * (size_t)D + 1] : 0.0,
                             D > 2 ? (double)w->x[i * (size_t)D + 2] : 0.0);
        case SPH__BAD_WALL:
            return sph__fail(w, SPH_ERR_UNSTABLE, (long)i,
                             "step %llu (t = %g s): fluid particle %zu (id %u) at (%g, %g, %g) is "
                             "inside the wall layers (wall volume fraction %g > %g): it crossed "
                             "a wall", (unsigned long long)w->steps, w->time, i,
                             (unsigned)w->id[i], (double)w->x[i * (size_t)D],
                             D > 1 ? (double)w->x[i * (size_t)D + 1] : 0.0,
                             D > 2 ? (double)w->x[i * (size_t)D + 2] : 0.0,
                             (double)sph__wall_fraction(c, w->x + i * (size_t)D, i, w->priv.lattice_sum),
                             (double)w->priv.wall_fraction_max);
        default:
            return sph__fail(w, SPH_ERR_UNSTABLE, (long)i,
                             "step %llu (t = %g s): fluid particle %zu (id %u) moves at %g m/s, "
                             "above the limit %g m/s (%s; if such speeds are real, raise "
                             "def.max_speed or the phase's sound_speed)",
                             (unsigned long long)w->steps, w->time, i, (unsigned)w->id[i], sqrt(v2),
                             (double)vlim,
                             w->def.max_speed > 0 ? "def.max_speed"
                             : w->priv.solver == SPH_SOLVER_COMPRESSIBLE
                                 ? "ten times the sound speed"
                             : sph__incompressible(w->priv.solver)
                                 ? "the sound speed plus twice the fastest wall's speed"
                                 : "the sound speed");
        }
    }
    return SPH_OK;
}

static sph_status sph__integrate(sph_world* w, const sph__ctx* c, sph_real kv, sph_real kr,
                                 sph_real kx, int final) {
    return sph__integrate_with(w, c, w->a, kv, kr, kx, final);
}

/* The share of the compression standing at a step's start that PCISPH, IISPH and DFSPH leave
   for later steps. Their density solves drive the predicted density to rho0 within the step,
   so a standing compression delta is removed by a velocity of about delta dx / dt: the smaller the step, the
   harder the kick. When sph_advance retries a failed step at half the size, that kick would
   double and the retry fail harder (with an ever smaller step it grows without bound). A step
   that a retry shortened to dt_factor of the rule therefore corrects only dt_factor of the
   standing compression (as a Baumgarte-stabilised constraint: the correction velocity stays that
   of the rule's step) and the rest in the steps that follow. A step shortened only to land on the
   end of sph_advance's call corrects all of it: leaving the rest made the first step of the next
   call face it together with its own, and IISPH's 2D tank at rest (dx 0.02, 0.05 s frames)
   stopped at max_iterations there about once a frame. The original PCISPH's step rule, dt <=
   0.25 h / sqrt(p_max / rho0) (sph_stable_dt), closes a loop: a small standing excess (0.08 % at a
   vortex's centre) corrected within a short step takes a pressure of order eps rho0 h^2 / dt^2,
   which shortens the next step, which raises the pressure; in a closed 2D vortex box the step fell
   from 9 ms to 3e-5 s within 0.05 s and the kinetic energy rose by 0.2-0.4 of its start
   (tests/test_reliability.c, pcisph_orig_box_frames). So while that rule holds the step below a
   quarter of the rest of the rule (w->priv.dt_unpressed), the fraction is cut in proportion: the
   correction velocity stays that of a quarter of the pressure-free step. sph_step_* called
   directly correct all of it. */
static sph_real sph__standing_keep(const sph_world* w) {
    const double f = w->priv.correct_fraction;
    return f > 0 && f < 1 ? (sph_real)(1 - f) : 0;
}

/* Solvability of an enclosed fluid. With walls that copy the fluid's pressure (MIRROR, and
   EXTRAPOLATE, whose p_b is the fluid's Shepard average) a uniform pressure pushes nowhere, so
   the pressure system of a fluid without a free surface is a pure-Neumann problem: A 1 is
   almost 0 and a source s_i = rho0 - rho*_i with a nonzero mean cannot be produced by any
   pressure. As the particles disorder, the summation density of a box full of fluid drifts
   above rho0 everywhere (1e-5 after one step, 3.5e-3 after twenty in a 2D box of 2500), every
   Jacobi sweep adds omega <s> / a_ii to the constant mode, the pressure level climbs (1.3 to
   22 kPa in 22 steps), the step shrinks, a_ii ~ dt^2 makes the drift grow like 1 / dt^2, and the
   fluid gains energy until it blows up. PCISPH, IISPH and DFSPH therefore solve an enclosed
   fluid with the density constraint's own wall term, p_b = 0 (derived in sph__step_pcisph), which
   has no null mode: a uniform pressure pushes the first fluid layer off the walls.
   Enclosed means that no free surface anchors the pressure level: fewer than 0.2 n^((d-1)/d)
   particles (a fifth of one lattice face of the fluid) lie on a surface. A surface particle has
   fewer than 0.85 of a full lattice neighbourhood of fluid and wall particles, and a lopsided one:
   the mean offset |sum_j (x_j - x_i)| / N_i of its N_i fluid and wall neighbours exceeds 0.3 dx
   (a lattice's top layer has about 0.9 dx, its second layer about 0.45). The count alone did
   not tell a surface from a wall: the incompressible solvers compress a tank's top layer to
   rho0 as it settles (IISPH's 2D tank at rest: 5 of its 40 top particles below 0.7 of a full set
   by 3 s), a particle in the corner of a box the fluid fills keeps 0.81-0.84 (3D vortex box, dx =
   0.05 m), and a vortex's core thins out; there the mean offsets stay below 0.2 dx (measured in
   tests/test_scenes.c's and tests/test_reliability.c's vortex boxes), on tank surfaces mostly
   0.4-1.1 dx. A wrong call turned the walls back to the copied pressure every few steps: IISPH's
   3D box needed 17 retries and DFSPH's kinetic energy rose by 0.2 of its start in one frame.
   With ZERO walls the wall pressure anchors the level and nothing changes.
   The decision is kept once made (w->stats.enclosed, carried by sph_advance's rollback and by
   sph_world_save). A fluid that fills a sealed box under gravity settles into the floor's wall
   lattice and its top layer leaves the lid: in a 3D box of 1 x 1 x 0.3 m at dx = 0.05 the whole
   top layer (120 particles, against an anchor of 36) turned into surface within one step at t =
   0.4 s, the walls went back to the copied pressure, and enhanced PCISPH failed at every step
   size (a particle at 139 m/s after 28 retries). Kept on zero wall pressure it runs on; so does
   every solver where a fluid that filled its box later opens a gap, at zero wall pressure's
   accuracy (the tank's hydrostatic pressure within 1.6 % instead of 1 %, README). Deterministic:
   one serial pass, stopped at the anchor count; the neighbour offsets are summed only for the
   particles short of neighbours. */
static int sph__enclosed(sph_world* w, const sph__ctx* c) {
    const int D = w->dim;
    const double anchor = fmax(1.0, 0.2 * pow((double)w->n, (D - 1.0) / D));
    const double need = 0.85 * (double)w->priv.full_count;
    size_t i, surface = 0;
    if (w->def.boundary_pressure == SPH_BP_ZERO || w->nb == 0 || w->n == 0) return 0;
    if (w->stats.enclosed) return 1;
    for (i = 0; i < w->n && (double)surface < anchor; ++i) {
        const size_t nf = w->priv.ff.count[i], nw = w->priv.fb.count[i];
        const sph_real* xi = c->x + i * (size_t)D;
        double s[3] = {0, 0, 0}, s2 = 0;
        size_t kk;
        int k;
        if ((double)(nf + nw) >= need) continue;
        for (kk = 0; kk < nf; ++kk) { /* sum of the offsets x_j - x_i [m] */
            sph_real d[3];
            sph__delta_vec(c, c->x + w->priv.ff.idx[w->priv.ff.begin[i] + kk] * (size_t)D, xi, d, D);
            for (k = 0; k < D; ++k) s[k] += (double)d[k];
        }
        for (kk = 0; kk < nw; ++kk) {
            sph_real d[3];
            sph__delta_vec(c, c->bx + w->priv.fb.idx[w->priv.fb.begin[i] + kk] * (size_t)D, xi, d, D);
            for (k = 0; k < D; ++k) s[k] += (double)d[k];
        }
        for (k = 0; k < D; ++k) s2 += s[k] * s[k];
        surface += nf + nw == 0 || sqrt(s2) > 0.3 * (double)(nf + nw) * (double)w->dx;
    }
    w->stats.enclosed = (double)surface < anchor;
    return w->stats.enclosed;
}

/* Divergence of relaxed Jacobi. The weight converges only while omega lambda_max(D^-1 A) < 2,
   and lambda_max grows as the particles disorder (a 2D box with a vortex at omega = 0.5 ran 70
   steps at 2 iterations, then one solve's error rose for 100 iterations and its mean pressure
   reached 150 kPa). When the error of a solve rises above twice the smallest it had (after four
   sweeps), the weight is cut to 0.7 of itself for the rest of the solve and the steps that
   follow, and grows back by 2 % per converged solve up to def.omega. */
static void sph__jacobi_guard(sph_world* w, int it, double err, double* err_min) {
#ifdef SPH_NO_GUARD
    (void)w; (void)it; (void)err; (void)err_min; return;
#endif
    if (it == 1 || err < *err_min) *err_min = err;
    if (it >= 4 && err > 2 * *err_min && w->stats.omega > 1e-3 * (double)w->def.omega) {
        w->stats.omega *= 0.7;
        *err_min = err;
    }
}

/* The same for the largest error, which sees a divergence confined to a few particles (a
   corner, whose extrapolated walls make its true diagonal up to 1.65 times the one used) long
   before the mean does. */
static void sph__jacobi_guard2(sph_world* w, int it, double err, double errmax, double* m) {
#ifdef SPH_NO_GUARD
    (void)w; (void)it; (void)err; (void)errmax; (void)m; return;
#endif
    sph__jacobi_guard(w, it, err, &m[0]);
    if (it == 1 || errmax < m[1]) m[1] = errmax;
    if (it >= 4 && errmax > 2 * m[1] && w->stats.omega > 1e-3 * (double)w->def.omega) {
        w->stats.omega *= 0.7;
        m[1] = errmax;
    }
}

static void sph__jacobi_begin(sph_world* w) {
    if (!(w->stats.omega > 0) || w->stats.omega > (double)w->def.omega)
        w->stats.omega = (double)w->def.omega;
}

static void sph__jacobi_end(sph_world* w, int converged) {
    if (converged) w->stats.omega = fmin((double)w->def.omega, 1.02 * w->stats.omega);
}

/* The largest non-pressure acceleration |g + user forces + viscosity| of the step (w->a before
   the pressure acceleration is added), which sph_stable_dt's force limit of the incompressible
   solvers reads. Their pressure acceleration is a constraint force that grows like 1 / dt (it
   removes a density error within the step): limiting dt by it feeds back -- a 3D tank at rest
   with IISPH halved its step eight times in a row, its surface pressure growing fourfold each
   time, until a particle left at 8 m/s. Serial, so the same for any thread count. */
static void sph__record_nonpressure(sph_world* w) {
    const size_t D = (size_t)w->dim;
    double m = 0;
    size_t i, k;
    for (i = 0; i < w->n; ++i) {
        double a2 = 0;
        for (k = 0; k < D; ++k) a2 += (double)w->a[i * D + k] * (double)w->a[i * D + k];
        if (a2 > m) m = a2;
    }
    w->stats.a_np_max = sqrt(m);
}

/* The warm start of the pressure solves: def.warm_start times the last pressure, except in a step
   sph_advance is retrying: from its first retry with extrapolated wall pressure, from its second
   with the others. The pressure of the failed step's start can be part of what failed: a corner
   particle whose walls extrapolate its own pressure can carry a pressure that, half of it
   warm-started, blows the retry up at any dt (enhanced PCISPH's dam break failed 13 retries down
   to dt = 4e-9 s, its 2D jet of tests/test_scenes.c 12 retries down to 5e-7 s); such a retry
   starts from p = 0. Otherwise the first retry keeps the warm start: from p = 0 a solve meets the
   mean-compression tolerance long before it has rebuilt the hydrostatic pressure (a uniform sag
   compresses only the bottom rows), so the column fell for a step at every retry. IISPH's 2D tank
   at rest (zero wall pressure, 1 x 0.8 m, dx 0.02, 0.05 s frames) retried about once a frame, and
   with cold first retries its speed late in 3 s stayed near 0.1 sqrt(g H). */
static sph_real sph__warm(const sph_world* w) { return w->priv.cold_start ? 0 : w->def.warm_start; }

/* The end of an iterative solve above its tolerance: the step was taken with the last pressure,
   and the caller hears of it (sph_advance undoes the step and retries a smaller one). */
static sph_status sph__not_converged(sph_world* w, const char* solver, int it, double err,
                                     double errmax) {
    return sph__fail(w, SPH_ERR_NOT_CONVERGED, -1,
                     "step %llu (t = %g s): %s stopped at max_iterations = %d with a mean "
                     "compression of %g (tolerance %g; largest %g): the step was taken with the "
                     "last pressure; a smaller dt converges faster",
                     (unsigned long long)w->steps, w->time, solver, it, err,
                     (double)w->def.tolerance, errmax);
}

/* Room for the per-block reductions of any step of the world's n particles (sph__integrate_with's
   SPH__RED_N values per block are the most a step uses; PCISPH and IISPH need 2 and 1). Reserved
   by sph__step_begin, before a step changes anything: the steps used to grow it in their last
   sph__integrate, after they had advanced the particles and w->time, so running out of memory
   there left a half-done step that a repeated call advanced again. */
static sph_status sph__reserve_blocks(sph_world* w) {
    const size_t nblk = (w->n + SPH__BLOCK - 1) / SPH__BLOCK;
    if (nblk * SPH__RED_N > w->priv.block_cap) {
        const size_t cap = nblk * SPH__RED_N + 64;
        if (!sph__grow((void**)&w->priv.block, cap, sizeof(double)))
            return sph__fail(w, SPH_ERR_NOMEM, -1, "out of memory (reduction blocks)");
        w->priv.block_cap = cap;
    }
    return SPH_OK;
}

/* Common start of every step: input checks, the step-independent scratch, automatic sound
   speeds, stats reset. */
/* w.def as a step finds it: a host may change the tunable fields between steps (tolerances,
   limits, callbacks, the solver), within their ranges; the fields the world was built from (dim,
   spacing, kernel, h_factor, periodic directions and their box) and the ones sph_world_init
   resolved (boundary_pressure, boundary_gamma and an automatic omega, see there) must stay. A
   bad value fails the step with SPH_ERR_ARG naming the field, before anything changed. */
static sph_status sph__check_def_now(sph_world* w) {
    const sph_world_def* d = &w->def;
    int k, changed = d->dim != w->dim || d->spacing != w->dx || d->kernel != w->kernel.type ||
                     d->h_factor * d->spacing != w->h;
    for (k = 0; k < 3 && !changed; ++k)
        changed = (d->periodic[k] != 0) != (w->priv.grid.periodic[k] != 0) ||
                  (d->periodic[k] && (d->domain_lo[k] != w->priv.grid.lo[k] ||
                                      d->domain_hi[k] - d->domain_lo[k] != w->priv.grid.len[k]));
    if (changed)
        return sph__fail(w, SPH_ERR_ARG, -1,
                         "step: w.def.dim, spacing, kernel, h_factor, periodic or a periodic "
                         "direction's domain_lo/hi changed after sph_world_init; make a new world");
    if (d->boundary_pressure == SPH_BP_MIRROR)
        return sph__fail(w, SPH_ERR_ARG, -1, "step: w.def.%s", sph__mirror_rejected);
    if (d->boundary_pressure == SPH_BP_AUTO || !(d->boundary_gamma > 0))
        return sph__fail(w, SPH_ERR_ARG, -1,
                         "step: w.def.boundary_pressure = SPH_BP_AUTO or boundary_gamma = %g set "
                         "after sph_world_init, which resolves them; set a scheme (SPH_BP_ZERO, "
                         "SPH_BP_EXTRAPOLATE) and a gamma > 0",
                         (double)d->boundary_gamma);
    if (!(d->omega > 0))
        return sph__fail(w, SPH_ERR_ARG, -1,
                         "step: w.def.omega = 0 (automatic) set after sph_world_init, which "
                         "resolves it; set a weight in (0, 1]");
    if (sph__validate_def(w, d) != SPH_OK) {
        char msg[SPH_ERROR_SIZE];
        memcpy(msg, w->error, sizeof msg);
        return sph__fail(w, SPH_ERR_ARG, -1, "step: w.%s",
                         msg + (strncmp(msg, "sph_world_", 10) == 0 ? 10 : 0));
    }
    return SPH_OK;
}

/* A derived sound speed (sph_phase.sound_speed = 0) is taken again when the host adds fluid or
   walls after it was derived, and kept if larger: a ball added above a pool that
   sph_set_hydrostatic had already resolved kept the pool's 12.5 m/s, and WCSPH failed where it
   hit the water (3D, dx 0.04, t = 0.30 s, compressed to 1.2 rho0 after 38 retries); with the
   ball's fall counted, 40.8 m/s, it runs clean (tests/test_hostile.c,
   sound_speed_follows_added_fluid: a block dropped 0.4 m into a pool, largest compression at a
   frame end 6.4 % -> 0.85 % in 2D, 8.8 % -> 2.9 % in 3D). Never lowered, so a stepping scene
   keeps its step; the hydrostatic densities set for the old value then stand a little
   compressed. */
static void sph__rederive_sound_speed(sph_world* w) {
    sph_real old[SPH_MAX_PHASES];
    int q, any = 0;
    for (q = 0; q < w->nphase; ++q) {
        old[q] = w->phases[q].sound_speed;
        if (w->priv.c0_auto[q]) {
            w->phases[q].sound_speed = 0;
            any = 1;
        }
    }
    if (!any) return;
    if (sph__resolve_sound_speed(w) != SPH_OK) { /* nothing to derive it from now: keep it */
        w->status = SPH_OK;
        w->error[0] = 0;
    }
    for (q = 0; q < w->nphase; ++q)
        if (w->priv.c0_auto[q] && !(w->phases[q].sound_speed > old[q]))
            w->phases[q].sound_speed = old[q];
}

/* WCSPH's derived sound speed follows a forced flow (sph_advance, between sub-steps). The
   automatic c0 = 10 U holds the density within about 1 % of rest (Mach 0.1, Monaghan 1994) only
   while the flow is no faster than the U it was derived from: sqrt(2 |g| H) at the start, the
   fastest a fluid can fall, which bounds an unforced flow by its energy. A force callback or
   moving walls (a shaken tank, a paddle, a stirrer) put energy in without that bound. In such a
   scene, when a phase's fastest fluid particle passes SPH__MACH_RAISE c0, its derived c0 is
   raised to 10 |v|max: never lowered, and the step (sph_stable_dt, ~ h / c0) shrinks with it.
   Unforced scenes keep theirs: a raise multiplies the pressure of every compressed particle by
   (c_new / c_old)^2, and raised for the few particles of an impact's splash (faster than the
   flow that hit, Wagner 1932) it fed them energy: a 2D jet at 10 m/s into a wall gained
   2.6 rho g H^2 W, a block dropped into a tank 0.034. Measured (2D tank 1 m wide, water 0.3 m
   deep, dx 0.02, a_x = 0.3 g sin(omega t) at the first sloshing mode, frames of 0.02 s): with c0
   fixed at its start, 24.3 m/s, the speeds reached 5.8 m/s (Mach 0.24) and the run failed at
   t = 1.72 s, a particle 20 % compressed (def.max_compression), reported; following the flow, c0
   rose to 54.7 m/s and it runs to the end (test wcsph/sound_speed_follows_flow). The
   incompressible solvers use c0 only to scale artificial viscosity and their runaway bound, so
   theirs stays. */
#define SPH__MACH_RAISE 0.15
static void sph__sound_speed_follows_flow(sph_world* w) {
    double v2max[SPH_MAX_PHASES];
    const size_t D = (size_t)w->dim;
    size_t i;
    int q, any = 0;
    for (q = 0; q < w->nphase; ++q) {
        v2max[q] = 0;
        any |= w->priv.c0_auto[q] && w->phases[q].sound_speed > 0;
    }
    if (!any || (!w->def.force && !w->def.boundary_motion)) return;
    for (i = 0; i < w->n; ++i) {
        const sph_real* v = w->v + i * D;
        double v2 = 0;
        size_t k;
        for (k = 0; k < D; ++k) v2 += (double)v[k] * (double)v[k];
        if (v2 > v2max[w->phase[i]]) v2max[w->phase[i]] = v2;
    }
    for (q = 0; q < w->nphase; ++q) {
        const double c0 = (double)w->phases[q].sound_speed, vmax = sqrt(v2max[q]);
        if (w->priv.c0_auto[q] && c0 > 0 && vmax > SPH__MACH_RAISE * c0 && sph__finite(vmax))
            w->phases[q].sound_speed = (sph_real)(10 * vmax);
    }
}

/* the points of p within the kernel's reach of x, their indices in *buf (grown as needed) */
static sph_status sph__grid_within(const sph_world* w, const sph_grid* g, const sph_real* p,
                                   const sph_real* x, uint32_t** buf, size_t* cap, size_t* m) {
    *m = sph_grid_query(g, p, x, w->kernel.radius, *buf, *cap);
    if (*m > *cap) { /* more neighbours than room: a larger buffer, the query again */
        uint32_t* more = (uint32_t*)SPH_MALLOC(*m * sizeof(uint32_t));
        if (!more) return SPH_ERR_NOMEM;
        SPH_FREE(*buf);
        *buf = more;
        *cap = *m;
        *m = sph_grid_query(g, p, x, w->kernel.radius, *buf, *cap);
    }
    return SPH_OK;
}
static double sph__grid_r2(const sph_world* w, const sph_grid* g, const sph_real* x,
                           const sph_real* y) {
    sph_real d[3] = {0, 0, 0}, r2 = 0;
    int k;
    sph_grid_delta(g, x, y, d);
    for (k = 0; k < w->dim; ++k) r2 += d[k] * d[k];
    return (double)r2;
}
/* sum_j V_j W(|x - p_j|) over the points p of grid g (built on p) within the kernel's support of
   x, V_j = vol[j] or, without vol, v0: the kernel sums of the checks before a step, which run
   before the step's lists exist. *buf (*cap entries, grown as needed) holds a query's result. */
static sph_status sph__grid_kernel_sum(const sph_world* w, const sph_grid* g, const sph_real* p,
                                       const sph_real* vol, double v0, const sph_real* x,
                                       uint32_t** buf, size_t* cap, double* sum) {
    const size_t D = (size_t)w->dim;
    size_t m = 0, q;
    const sph_status s = sph__grid_within(w, g, p, x, buf, cap, &m);
    *sum = 0;
    for (q = 0; q < m; ++q) {
        const double r2 = sph__grid_r2(w, g, x, p + (size_t)(*buf)[q] * D);
        *sum += (vol ? (double)vol[(*buf)[q]] : v0) *
                (double)sph_kernel_w(&w->kernel, (sph_real)sqrt(r2));
    }
    return s;
}

/* Two grids at the kernel's reach over the world's domain (the free-surface check's fluid and
   walls); on failure neither is left allocated. */
static sph_status sph__grid_pair_init(const sph_world* w, sph_grid* ga, sph_grid* gb) {
    sph_status s = sph_grid_init(ga, w->dim, w->kernel.radius, w->def.periodic, w->def.domain_lo,
                                 w->def.domain_hi);
    if (s != SPH_OK) return s;
    s = sph_grid_init(gb, w->dim, w->kernel.radius, w->def.periodic, w->def.domain_lo,
                      w->def.domain_hi);
    if (s != SPH_OK) sph_grid_free(ga);
    return s;
}

/* The volumes SPH_BVOL_AUTO gives walls just added (sph__stage_boundary_volume_auto, which runs
   at the first sort), from the walls' own grid: so the check below weighs a wall sampled denser
   than the fluid as the step will. */
static sph_status sph__placed_auto_volumes(const sph_world* w, const sph_grid* g, uint32_t** buf,
                                           size_t* cap, sph_real* vol) {
    const size_t D = (size_t)w->dim;
    const double reach2 = (double)w->kernel.radius * (double)w->kernel.radius;
    size_t b, m = 0, q;
    for (b = 0; b < w->nb; ++b) {
        const sph_real* xb = w->b_x + b * D;
        double sum = 0, near2 = reach2;
        const sph_status s = sph__grid_within(w, g, w->b_x, xb, buf, cap, &m);
        if (s != SPH_OK) return s;
        for (q = 0; q < m; ++q) {
            const double r2 = sph__grid_r2(w, g, xb, w->b_x + (size_t)(*buf)[q] * D);
            sum += (double)sph_kernel_w(&w->kernel, (sph_real)sqrt(r2));
            if ((*buf)[q] != b && r2 < near2) near2 = r2;
        }
        vol[b] = sph__auto_volume(
            w->dim, w->b_vol[b],
            (sph_real)((double)w->def.boundary_gamma * (double)w->priv.lattice_sum / sum),
            (sph_real)near2);
    }
    return SPH_OK;
}

/* Fluid placed inside walls (check_walls, lattice walls of given volumes): before the first step
   after the host added fluid or walls, a fluid particle whose wall volume fraction
   sum_b V_b W_ib / S lies beyond that of the wall's first layer (sph__wall_fraction_limit; a fill
   box reaching into sph_add_wall_box's layers, an obstacle placed into the fluid) is bad input:
   SPH_ERR_ARG, named, the world unchanged. Left to the step it failed as a compression or a speed
   ("time step too large", a particle at 39 m/s) after every retry. Fluid closer to a wall than
   the lattice's spacing but short of its first layer is left to the wall contact. Only the fluid
   added since the last step is checked, unless walls were added: the walls are sorted into a
   grid of their own (sph_grid) and each fluid particle queried, about a neighbour search. */
static sph_status sph__check_placed(sph_world* w) {
    const size_t D = (size_t)w->dim;
    sph_grid g;
    uint32_t* buf;
    sph_real* vol = NULL; /* SPH_BVOL_AUTO's volumes of walls just added */
    size_t cap = 256, i, bad = (size_t)-1;
    double fbad = 0, sum = 0;
    sph_status s;
    if (!w->def.check_walls || w->nb == 0 || w->def.boundary_volume == SPH_BVOL_AKINCI ||
        !(w->priv.wall_fraction_max > 0) || w->priv.placed_from >= w->n)
        return SPH_OK;
    s = sph_grid_init(&g, w->dim, w->kernel.radius, w->def.periodic, w->def.domain_lo,
                      w->def.domain_hi);
    if (s != SPH_OK) return sph__fail(w, s, -1, "step: the walls' grid: %s", sph_status_string(s));
    buf = (uint32_t*)SPH_MALLOC(cap * sizeof(uint32_t));
    s = buf ? sph_grid_build(&g, w->b_x, w->nb) : SPH_ERR_NOMEM;
    if (s == SPH_OK && w->def.boundary_volume == SPH_BVOL_AUTO && w->priv.b_dirty) {
        vol = (sph_real*)SPH_MALLOC(w->nb * sizeof(sph_real));
        s = vol ? sph__placed_auto_volumes(w, &g, &buf, &cap, vol) : SPH_ERR_NOMEM;
    }
    for (i = w->priv.placed_from; s == SPH_OK && i < w->n && bad == (size_t)-1; ++i) {
        s = sph__grid_kernel_sum(w, &g, w->b_x, vol ? vol : w->b_vol, 0, w->x + i * D, &buf, &cap,
                                 &sum);
        if (s == SPH_OK && sum / (double)w->priv.lattice_sum > (double)w->priv.wall_fraction_max) {
            bad = i;
            fbad = sum / (double)w->priv.lattice_sum;
        }
    }
    SPH_FREE(vol);
    SPH_FREE(buf);
    sph_grid_free(&g);
    if (s != SPH_OK) return sph__fail(w, s, -1, "step: out of memory (the walls' grid)");
    if (bad != (size_t)-1) {
        const sph_real* xb = w->x + bad * D;
        return sph__fail(w, SPH_ERR_ARG, (long)bad,
                         "fluid particle %zu (id %u) at (%g, %g, %g) lies inside the wall layers "
                         "(wall volume fraction %g > %g, the first layer's): fluid placed where "
                         "walls are (a fill box reaching into the walls, an obstacle placed into "
                         "the fluid?); remove it",
                         bad, (unsigned)w->id[bad], (double)xb[0], D > 1 ? (double)xb[1] : 0.0,
                         D > 2 ? (double)xb[2] : 0.0, fbad, (double)w->priv.wall_fraction_max);
    }
    return SPH_OK;
}

/* SPH_PGRAD_DIFFERENCE's force sum_j V_j (p_j - p_i) grad W_ij takes no pressure from where no
   neighbour is: at a free surface it misses the zero pressure of the empty side, which the
   antisymmetric forms bring in through p_i sum_j V_j grad W_ij, so the rows under a surface feel
   too little of the hydrostatic gradient and sink. Measured (a 2D tank at rest, 0.5 m wide, 15
   particles deep, sph_advance with WCSPH's defaults but this gradient): 1.4 m/s and 22 %
   compression after 0.05 s, every frame SPH_OK, then a failure at 0.13 s. So the first step after
   fluid or walls are added refuses a world with this gradient in which a fluid particle's kernel
   sum sum_j V_j W_ij / S (V = dx^dim for fluid and walls alike: a count of neighbours, so a single
   wall layer counts as it weighs in a thick wall) is below SPH__SURFACE_SUM. Measured on that tank
   (Wendland C2, h = 1.3 dx) in 2D and 3D: the lattice's top row 0.79 (0.83-0.87 where it meets the
   side walls), the row under it and the rest 0.995-1.0; a single wall layer one spacing away
   stands in for the missing row (+0.21). */
#define SPH__SURFACE_SUM 0.9
static sph_status sph__check_free_surface(sph_world* w) {
    const size_t D = (size_t)w->dim;
    double vdx = 1, sum = 0, sb = 0;
    sph_grid gf, gb;
    uint32_t* buf;
    size_t cap = 256, i, bad = (size_t)-1;
    sph_status s;
    int k;
    if (w->def.pressure_grad != SPH_PGRAD_DIFFERENCE || w->n == 0) return SPH_OK;
    for (k = 0; k < w->dim; ++k) vdx *= (double)w->dx;
    s = sph__grid_pair_init(w, &gf, &gb);
    if (s != SPH_OK)
        return sph__fail(w, s, -1, "step: the free-surface check's grid: %s", sph_status_string(s));
    buf = (uint32_t*)SPH_MALLOC(cap * sizeof(uint32_t));
    s = buf ? sph_grid_build(&gf, w->x, w->n) : SPH_ERR_NOMEM;
    if (s == SPH_OK && w->nb > 0) s = sph_grid_build(&gb, w->b_x, w->nb);
    for (i = 0; s == SPH_OK && i < w->n && bad == (size_t)-1; ++i) {
        const sph_real* xi = w->x + i * D;
        s = sph__grid_kernel_sum(w, &gf, w->x, NULL, vdx, xi, &buf, &cap, &sum);
        if (s == SPH_OK && w->nb > 0)
            s = sph__grid_kernel_sum(w, &gb, w->b_x, NULL, vdx, xi, &buf, &cap, &sb);
        if (s == SPH_OK && (sum + sb) / (double)w->priv.lattice_sum < SPH__SURFACE_SUM) {
            bad = i;
            sum = (sum + sb) / (double)w->priv.lattice_sum;
        }
        sb = 0;
    }
    SPH_FREE(buf);
    sph_grid_free(&gf);
    sph_grid_free(&gb);
    if (s != SPH_OK) return sph__fail(w, s, -1, "step: out of memory (the free-surface check)");
    if (bad != (size_t)-1) {
        const sph_real* xb = w->x + bad * D;
        return sph__fail(w, SPH_ERR_ARG, (long)bad,
                         "def.pressure_grad = SPH_PGRAD_DIFFERENCE needs fluid that fills its "
                         "walls and periodic directions, but fluid particle %zu (id %u) at (%g, "
                         "%g, %g) has a free surface (kernel sum %g of a full neighbourhood): "
                         "there the difference form misses the empty side's zero pressure and "
                         "the surface rows sink; use SPH_PGRAD_MULTIPHASE or the default",
                         bad, (unsigned)w->id[bad], (double)xb[0], D > 1 ? (double)xb[1] : 0.0,
                         D > 2 ? (double)xb[2] : 0.0, sum);
    }
    return SPH_OK;
}

/* IISPH and DFSPH sum the density, which smears the mass jump between phases: a blob of light
   fluid rising in water (2D, dx 0.02, 1 s, through sph_advance) gained kinetic + potential
   energy, in units of M g dx: 0 at a rest-density ratio of 0.8, 0.005 (IISPH) and 0 (DFSPH) at
   0.75, 0.045 and 0.020 at 0.7, 0.09 and 0.12 at 0.6, 0.64 and 0.39 at 0.5; at 0.2 it reached
   21 m/s in its first frame, every frame SPH_OK (the energy check's allowance grows with the
   kinetic energy the spurious pressure makes). Below this ratio they refuse to step. */
#define SPH__SUMMED_RATIO_MIN 0.75
/* PCISPH with the mass continuity equation (sph_world_def_pcisph's enhanced preset): a light
   particle at an interface takes its heavy neighbours' masses into its density rate. Measured
   (tests/test_pcisph.c, two_layer: water under a lighter fluid at rest, 2D, dx 0.05): holds at
   0.8 and 0.4, fails at 0.2 (SPH_ERR_UNSTABLE, after steps); a dam break (a water column 0.2 x
   0.4 m in a 1 x 0.6 m tank filled with a second phase, 2D dx 0.02) holds at 0.5 and fails at 0.3
   and below (0.1: within 0.06 s). Below this ratio it refuses to step; with particle density
   (Ott & Schnetter 2003) the same solver holds every ratio of the two-layer test. */
#define SPH__CONTINUITY_RATIO_MIN 0.35

static int sph__settles(const sph_world* w, sph_solver solver);
static sph_status sph__settle_placed(sph_world* w, int walls_only);
static sph_status sph__snapshot_take(sph_world* w, int slot);
static void sph__snapshot_restore(sph_world* w, int slot);
static long sph__restore_named(sph_world* w, int slot);
static sph_status sph__step_begin(sph_world* w, sph_real dt, sph_solver solver) {
    sph_status s;
    int k, settle = 0;
    if (!w) return SPH_ERR_ARG;
    w->priv.x_start = NULL; /* a step of two drifts sets it (sph__wall_crossed) */
    if (solver != SPH_SOLVER_COMPRESSIBLE)
        for (k = 0; k < w->nphase; ++k)
            if (w->phases[k].eos == SPH_EOS_IDEAL_GAS || w->phases[k].eos == SPH_EOS_STIFFENED_GAS)
                return sph__fail(w, SPH_ERR_ARG, -1,
                                 "step: phase %d has a gas equation of state, which needs the "
                                 "internal energy only sph_step_compressible evolves", k);
    s = sph__check_def_now(w);
    if (s != SPH_OK) return s;
    /* sph_world_init checks these against def.solver; a host may call another sph_step_* */
    if (solver == SPH_SOLVER_PBF && w->def.wall == SPH_WALL_NO_SLIP)
        return sph__fail(w, SPH_ERR_ARG, -1,
                         "sph_step_pbf: def.wall = SPH_WALL_NO_SLIP, but PBF's walls are free "
                         "slip (its viscosity and XSPH smooth over fluid neighbours only)");
    if (solver != SPH_SOLVER_WCSPH && w->def.pressure_grad == SPH_PGRAD_DIFFERENCE)
        return sph__fail(w, SPH_ERR_ARG, -1,
                         "step: def.pressure_grad = SPH_PGRAD_DIFFERENCE is for WCSPH only "
                         "(solver %d)", (int)solver);
    if ((solver == SPH_SOLVER_IISPH || solver == SPH_SOLVER_DFSPH) &&
        sph__rest_density_ratio(w) < SPH__SUMMED_RATIO_MIN)
        return sph__fail(w, SPH_ERR_ARG, -1,
                         "step: phases of rest densities in the ratio %g (below %g): %s sums the "
                         "density, which smears the mass jump between phases (a light blob "
                         "rising in water gains energy); for phases of different density use "
                         "def.density = SPH_DENSITY_PARTICLE with enhanced PCISPH "
                         "(sph_world_def_pcisph(&def, 1), then the density) or WCSPH, for 1000:1 "
                         "with the compressible step (sph.h, PHASES)",
                         sph__rest_density_ratio(w), SPH__SUMMED_RATIO_MIN,
                         solver == SPH_SOLVER_IISPH ? "IISPH" : "DFSPH");
    if (solver == SPH_SOLVER_PCISPH && w->def.density == SPH_DENSITY_CONTINUITY &&
        sph__rest_density_ratio(w) < SPH__CONTINUITY_RATIO_MIN)
        return sph__fail(w, SPH_ERR_ARG, -1,
                         "step: phases of rest densities in the ratio %g (below %g) with "
                         "def.density = SPH_DENSITY_CONTINUITY, which gives a light particle at "
                         "an interface its heavy neighbours' masses: set def.density = "
                         "SPH_DENSITY_PARTICLE after sph_world_def_pcisph (sph.h, PHASES)",
                         sph__rest_density_ratio(w), SPH__CONTINUITY_RATIO_MIN);
    s = sph__check_step_input(w, dt);
    if (s != SPH_OK) return s;
    if (w->priv.placed) { /* fluid or walls added since the last step */
        s = sph__check_placed(w);
        if (s == SPH_OK) s = sph__check_free_surface(w);
        if (s != SPH_OK) return s;
        w->priv.placed = 0;
        settle = sph__settles(w, solver);
    }
    if (w->priv.placed_c0) {
        sph__rederive_sound_speed(w);
        w->priv.placed_c0 = 0;
    }
    /* scratch first, so that running out of memory here changes nothing */
    s = sph__reserve_blocks(w);
    if (s == SPH_OK && sph__phase_walls_for(w, (int)solver))
        s = sph__scratch(w, &w->priv.bpq, w->nb * (size_t)w->nphase * SPH__BPQ);
    if (s == SPH_OK && sph__visc_norm_used(w)) s = sph__scratch(w, &w->priv.lapc, w->capacity);
    if (s == SPH_OK && w->def.wall_contact > 0 && w->nb > 0 && sph__carries_density_for(w, (int)solver))
        s = sph__scratch(w, &w->priv.shift, w->capacity * (size_t)w->dim); /* sph__contact_density */
    if (s != SPH_OK) return s;
    s = sph__resolve_sound_speed(w);
    if (s != SPH_OK) {
        /* an incompressible solver uses c0 only to scale artificial viscosity and the speed
           bound of the blow-up check: without one, both are off */
        if (solver == SPH_SOLVER_WCSPH || solver == SPH_SOLVER_COMPRESSIBLE) return s;
        s = SPH_OK; /* the step goes on: a begin without settling returns this */
    }
    for (k = 0; k < SPH_STAGE_COUNT; ++k) w->stats.stage_time[k] = 0;
    w->stats.step_time = 0;
    w->stats.dt = (double)dt;
    w->stats.iterations = 1;
    w->stats.iterations_divergence = 0;
    w->error[0] = 0;
    w->error_index = -1;
    w->status = SPH_OK;
    w->priv.solver = (int)solver;
    if (settle) { /* fluid placed compressed moved apart before time starts (sph__settle_placed) */
        /* a start it refuses is put back as it was: sph_advance restores its own copy, a bare
           sph_step this one (the settling sorts and moves the particles), freed after use */
        const int keep = settle == 1 && w->priv.settle_snap == 0;
        if (keep && (s = sph__snapshot_take(w, 0)) != SPH_OK) {
            w->priv.placed = 1;
            return s;
        }
        s = sph__settle_placed(w, settle == 2);
        if (keep) {
            if (s == SPH_ERR_ARG) sph__restore_named(w, 0);
            SPH_FREE(w->priv.snap[0]);
            w->priv.snap[0] = NULL;
            w->priv.snap_cap[0] = 0;
        }
        if (s != SPH_OK) w->priv.placed = 1; /* checked and settled again by the next attempt */
        /* sph_advance retries a failed first sub-step from here, not from before the settling
           (the same positions again, 500 projections each): a call whose 13 attempts failed took
           19 s under the sanitizers, 1401 particles (tests/fuzz_api.c) */
        else if (w->priv.settle_snap == 1 && (s = sph__snapshot_take(w, 1)) == SPH_OK)
            w->priv.settle_snap = 2;
    }
    return s;
}

/* Boundary motion at time t, neighbour search, summation density if chosen, equation of state,
   wall extrapolation: the state every force evaluation starts from. */
/* delta-SPH's hydrostatic part (sph__delta_hydro) reads each particle's body acceleration: a copy
   of w->a right after sph__stage_body_force, before the passes add to it, into scratch reserved
   when the step begins (sph__body_accel_reserve: a step that runs out of memory changes nothing). */
static sph_status sph__body_accel_reserve(sph_world* w) {
    if (!sph__delta_hydro_on(w)) return SPH_OK;
    return sph__scratch(w, &w->priv.abody, w->capacity * (size_t)w->dim);
}

static void sph__keep_body_accel(sph_world* w, sph__ctx* c) {
    if (!c->delta_hs || w->priv.abody_cap < w->n * (size_t)w->dim) return;
    sph__copy(w->priv.abody, w->a, w->n * (size_t)w->dim * sizeof(sph_real));
    c->abody = w->priv.abody;
}

static sph_status sph__prepare_forces(sph_world* w, sph__ctx* c, double t, double* t0) {
    sph_status s = sph__boundary_motion(w, t);
    if (s != SPH_OK) return s;
    sph__time(w, SPH_STAGE_BOUNDARY, t0);
    s = sph__stage_neighbors(w);
    if (s != SPH_OK) return s;
    sph__ctx_init(w, c); /* after the sort: the arrays are the same, their content moved */
    sph__time(w, SPH_STAGE_NEIGHBORS, t0);
    if (w->def.density == SPH_DENSITY_SUMMATION) {
        sph__stage_density_summation(w, c);
        sph__time(w, SPH_STAGE_DENSITY, t0);
    }
    sph__stage_eos(w, c);
    sph__time(w, SPH_STAGE_PRESSURE, t0);
    if ((s = sph__stage_body_force(w, c)) != SPH_OK) return s;
    sph__keep_body_accel(w, c);
    sph__time(w, SPH_STAGE_FORCES, t0);
    if (w->nb > 0) sph__stage_wall(w, c, SPH__WALL_STATE | SPH__WALL_PRESSURE);
    sph__time(w, SPH_STAGE_PRESSURE, t0);
    return SPH_OK;
}

/* A step of two drifts (Stormer-Verlet: WCSPH's and enhanced PCISPH's) keeps x^n for the final
   drift's crossing check, which then looks at the whole step (sph__wall_crossed): the first
   drift, before the neighbour search, has no wall lists to check against. */
static void sph__x_start(sph_world* w, const sph_real* xn, sph_real drift) {
    w->priv.x_start = xn;
    w->priv.x_start_sorts = w->priv.sorts;
    w->priv.x_start_drift = drift;
}

/* Stormer-Verlet drifts the particles half a step before its neighbour search. When the search
   fails (out of memory: the grid or the lists had to grow), the step returns with the positions
   of the step's start, kept in xn before the drift, or a repeated call would drift them twice;
   if the particles were already sorted, xn is read through the sort's permutation. */
static void sph__undo_drift(sph_world* w, const sph_real* xn, uint64_t sorts) {
    const size_t D = (size_t)w->dim;
    size_t i;
    if (w->priv.sorts == sorts) {
        sph__copy(w->x, xn, w->n * D * sizeof(sph_real));
        return;
    }
    for (i = 0; i < w->n; ++i)
        memcpy(w->x + i * D, xn + (size_t)w->priv.grid.order[i] * D, D * sizeof(sph_real));
}

/* ============================================================================================== */
/* >>wcsph (implementation)                                                                       */
/* ============================================================================================== */
/* Per-particle factors the fast-path passes would otherwise divide out for every pair:
   p_j / rho_j^2 (forces) and m_j / rho_j (delta-SPH), the same expressions, so the same bits.
   Measured at 100k particles in 2D: the density-rate pass 10 % and the force pass 6 % faster.
   Only while rho and p stay as they are (symplectic Euler: both passes see rho^n, p^n), and for
   exactly the worlds whose passes take sph__interact_one's fast path (sph__stage_interact). */
static int sph__pair_cache_used(const sph_world* w) {
    return !w->m && w->nphase == 1 && w->phases[0].viscosity <= 0 &&
           w->kernel.form == SPH__KF_WC2 &&
           (w->dim == 2 || w->dim == 3) && !w->def.periodic[0] && !w->def.periodic[1] &&
           !w->def.periodic[2] && w->def.pressure_grad == SPH_PGRAD_SYMMETRIC;
}

/* Its arrays, reserved before the step changes anything (out of memory then leaves the world as
   it was; tests/test_oom.c). */
static sph_status sph__pair_cache_reserve(sph_world* w) {
    sph_status s = SPH_OK;
    if (!sph__pair_cache_used(w)) return SPH_OK; /* the fast path does not run: nothing to cache */
    if ((s = sph__scratch(w, &w->priv.pr2, w->capacity)) == SPH_OK)
        s = sph__scratch(w, &w->priv.vol, w->capacity);
    return s;
}

static void sph__pair_cache(sph_world* w, sph__ctx* c) {
    sph__idx i;
    if (!sph__pair_cache_used(w)) return;
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)w->n; ++i) {
        w->priv.pr2[i] = w->p[i] / (w->rho[i] * w->rho[i]);
        w->priv.vol[i] = w->mass / w->rho[i];
    }
    c->pr2c = w->priv.pr2;
    c->volc = w->priv.vol;
}

/* The force pass keeps grad W_ij / x_ij of every listed pair, and the density-rate pass of the
   same positions reads it instead of evaluating the kernel again (the same value, so the same
   bits). Reserved after the neighbour search, which sizes the lists. */
static sph_status sph__rate_cache(sph_world* w, sph__ctx* c) {
    sph_status s;
    if ((s = sph__scratch(w, &w->priv.ff_fw, w->priv.ff.cap_idx)) != SPH_OK ||
        (s = sph__scratch(w, &w->priv.fb_fw, w->priv.fb.cap_idx)) != SPH_OK)
        return s;
    c->ff_fw = c->ff_fw_out = w->priv.ff_fw;
    c->fb_fw = c->fb_fw_out = w->priv.fb_fw;
    return SPH_OK;
}

/* Particle shifting (def.shifting = A > 0), after the step's last neighbour pass, at the positions
   of its lists: fluid particle i moves by
       dr_i = -A h U dt sum_j V_j (1 + R (W_ij / W(dx))^n) grad_i W_ij,   R = 0.2, n = 4,
   over fluid and wall neighbours (V_j = m_j / rho_j, a wall particle's volume), U the largest fluid
   speed of the last step: Lind et al. 2012 (J. Comput. Phys. 231, 1499), the gradient of the
   particle concentration with their anti-clumping term, with the step-size scaling of Sun et al.
   2017 (Comput. Methods Appl. Mech. Engrg. 315, 25, delta+-SPH: CFL Ma (2h)^2 with dt = CFL h / c0
   and Ma = U / c0 is 4 h U dt, so A = 4 is theirs). Why: the pressure-difference gradient
   (SPH_PGRAD_DIFFERENCE) is consistent but exerts no force against pairing and is not the adjoint
   of the continuity divergence, so it conserves no acoustic energy; on the disordered particles of
   a mixing layer its pressure noise grows until a particle is compressed past def.max_compression
   (tests/test_rt.c, the Rayleigh-Taylor late phase). The shift keeps the particles ordered; it is
   first order in h U dt per step and moves no particle of a fluid at rest (U = 0). Density and
   velocity are not corrected for the shift (an error of the shift's order). A free surface would
   pull its particles outwards (no surface detection here): for flows that fill their walls. Gather
   only: each particle writes its own shift, then all move.
   IISPH and DFSPH (after the pressure solve, before the drift; their density is summed again at
   the next step, so the shift needs no density correction) take 5-10 times WCSPH's step, and D =
   A h U dt grows with it: the shift is an explicit diffusion step of the particle concentration,
   stable only below a D that falls like 1/dim (the Laplacian's largest eigenvalue sums over the
   directions). In a 2D vortex box of 25 x 25 particles (U = 1 m/s) A = 4 at IISPH's step gave D =
   0.6 h^2: it overshot, a particle at a wall reached 15 m/s and the step failed (reported); 0.25
   h^2 held with retries. In the 3D box (20 x 20 x 6) 0.1 h^2 raised the kinetic energy from one
   0.05 s frame to the next by 1.0 % (IISPH) and 2.4 % (DFSPH) of its start; 0.067 h^2 and 0.05
   h^2 did not. So D <= 0.2 h^2 / dim (SPH__SHIFT_DMAX): 0.1 h^2 in 2D, WCSPH's own D at its
   acoustic step at Mach 0.1 (A CFL Ma h^2 = 4 x 0.25 x 0.1 h^2), so WCSPH's 2D shifts are
   unchanged below that Mach number. IISPH and DFSPH (every summation density) take half that
   (SPH__SHIFT_DMAX_SUMMED): the shift moves mass without work, and a summed density turns what it
   compresses into pressure that the next solve spends pushing the particles apart; against
   gravity's hydrostatic pressure that push puts energy in. In the vortex box under gravity (2D 25 x
   25 and 3D 20 x 20 x 6, A = 4, frames of 0.04-0.125 s, tests/test_viscous.c box_gravity_shifting)
   the mechanical energy rose from one frame to the next in 8 of 16 runs at 0.2 h^2 / dim, by up to
   8.6 % (2D) and 20 % (3D) of the start's kinetic energy, and in none at 0.1 h^2 / dim. WCSPH
   carries its density: its particles move with their density and pressure, and it rose in none of 6
   such runs. Shifting before the density summation instead (so that the same step's solve removes
   the compression) was worse: at 0.2 h^2 / dim the 3D box under gravity gained 34 % of its start's
   kinetic energy in a frame (IISPH, 0.05 s frames), against 7.5 % shifting after the solve.
   Measured in the vortex boxes without gravity, the kinetic energy's decay over its exact rate in
   2D (tests/test_viscous.c): IISPH 3.3 -> 2.0, DFSPH 3.2 -> 2.1, WCSPH 4.2 -> 1.13 (IISPH and DFSPH
   1.7 at 0.2 h^2 / dim); the 3D box's kinetic energy after 0.5 s (exact 0.82 of its start): IISPH
   0.48 -> 0.54, DFSPH 0.48 -> 0.54, WCSPH 0.53 -> 0.80. The frame-end mean density error (summed
   afresh) of IISPH and DFSPH is 0.3-0.4 % (2D) and 0.7-1.1 % (3D) against 0.2-0.37 % unshifted (the
   next solve removes what the shift compressed). */
#define SPH__SHIFT_DMAX SPH__R(0.2) /* dim times the bound on A h U dt [h^2]: sph__stage_shift */
#define SPH__SHIFT_DMAX_SUMMED SPH__R(0.1) /* the same for a summation density (IISPH, DFSPH) */
static sph_status sph__shift_reserve(sph_world* w) {
    if (!(w->def.shifting > 0)) return SPH_OK;
    return sph__scratch(w, &w->priv.shift, w->capacity * (size_t)w->dim);
}

/* One neighbour's share of the shift direction: g += V_j (1 + 0.2 (W_ij / W(dx))^4) grad W_ij
   (a fluid neighbour, V_j = m_j / rho_j, or a wall particle, V_j its volume). */
SPH__INLINE void sph__shift_pair(const sph__ctx* c, sph_real inv_wdx, const sph_real* xi,
                                 const sph_real* xj, sph_real vol, const int D, sph_real* g) {
    sph_real d[3] = {0, 0, 0}, r2 = 0, q, wr, f;
    int k;
    sph__delta_vec_p(c, c->periodic_any, xi, xj, d, D);
    SPH__FOR_K(D, r2 += d[k] * d[k]);
    q = sph__sqrt(r2) * c->k.inv_h;
    wr = sph__kw(c->k.form, q) * inv_wdx;
    wr *= wr;
    f = (1 + SPH__R(0.2) * wr * wr) * vol * c->k.norm_g *
        sph__kf(c->k.form, q); /* grad W_ij = norm_g f(q) x_ij */
    SPH__FOR_K(D, g[k] += f * d[k]);
}

static void sph__stage_shift(sph_world* w, const sph__ctx* c, sph_real dt) {
    const int D = c->dim, form = c->k.form;
    const sph_real inv_wdx = 1 / sph__kw(form, w->dx * c->k.inv_h);
    const int summed = !sph__carries_density_for(w, w->priv.solver);
    const sph_real dmax =
        (summed ? SPH__SHIFT_DMAX_SUMMED : SPH__SHIFT_DMAX) * c->h * c->h / (sph_real)D;
    const sph_real coef0 = w->def.shifting * c->h * (sph_real)w->stats.v_max * dt;
    const sph_real coef = -(coef0 < dmax ? coef0 : dmax);
    sph_real* sh = w->priv.shift;
    sph__idx i;
    if (!(w->def.shifting > 0) || !(coef < 0)) return;
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)w->n; ++i) {
        const sph_real* xi = c->x + (size_t)i * (size_t)D;
        sph_real g[3] = {0, 0, 0};
        size_t kk, k0 = c->ff->begin[i], k1 = k0 + c->ff->count[i];
        int k;
        for (kk = k0; kk < k1; ++kk) {
            const size_t j = c->ff->idx[kk];
            sph__shift_pair(c, inv_wdx, xi, c->x + j * (size_t)D,
                            (c->m ? c->m[j] : c->m0) / c->rho[j], D, g);
        }
        if (c->has_b) {
            k0 = c->fb->begin[i];
            k1 = k0 + c->fb->count[i];
            for (kk = k0; kk < k1; ++kk) {
                const size_t b = c->fb->idx[kk];
                sph__shift_pair(c, inv_wdx, xi, c->bx + b * (size_t)D, c->bvol[b], D, g);
            }
        }
        SPH__FOR_K(D, sh[(size_t)i * (size_t)D + (size_t)k] = coef * g[k]);
    }
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)(w->n * (size_t)D); ++i) w->x[i] += sh[i];
}

/* Symplectic Euler (Enhanced PCISPH 2018 sec. 2.3, "semi-implicit"):
       v^{n+1}   = v^n + dt a(x^n, rho^n, v^n)
       rho^{n+1} = rho^n + dt R(x^n, v^{n+1})          R = density rate (continuity + delta-SPH)
       x^{n+1}   = x^n + dt v^{n+1}
   The density must see the new velocity: with R(x^n, v^n) the acoustic pair (rho, v) would be
   integrated by forward Euler, which is unconditionally unstable (a tank at rest blows up within
   a few hundred steps). So a step is two neighbour passes over the same lists: forces, then the
   density rate.
   Stormer-Verlet, drift-kick-drift (Enhanced PCISPH 2018 sec. 2.3). The thesis leaves open how the
   density joins the half steps. Decision: rho is a position-like variable advanced by
   the midpoint rule, R being linear in v:
       x^{n+1/2}   = x^n + dt/2 v^n
       rho~        = rho^n + dt/2 R_prev            (predictor, used only for the forces)
       v^{n+1}     = v^n + dt a(x^{n+1/2}, rho~, v^n)
       rho^{n+1}   = rho^n + dt R(x^{n+1/2}, (v^n + v^{n+1})/2)
       x^{n+1}     = x^{n+1/2} + dt/2 v^{n+1}
   R_prev is the previous step's rate; its lag makes rho~ wrong by O(dt^2), which changes the
   forces by O(dt^2), so the step stays second order (tests/test_wcsph.c measures the order).
   The kick is split in two halves so the rate pass sees the mean velocity. Two passes per step. */
static sph_status sph__step_wcsph_euler(sph_world* w, sph_real dt) {
    const int cont = w->def.density != SPH_DENSITY_SUMMATION;
    double t0 = sph__now(), tstart = t0;
    sph__ctx c;
    sph_status s = sph__pair_cache_reserve(w);
    if (s == SPH_OK) s = sph__shift_reserve(w);
    if (s == SPH_OK) s = sph__body_accel_reserve(w);
    if (s == SPH_OK) s = sph__prepare_forces(w, &c, w->time, &t0);
    if (s == SPH_OK && cont) s = sph__rate_cache(w, &c);
    if (s != SPH_OK) return s;
    sph__pair_cache(w, &c);
    sph__stage_interact(w, &c, cont ? SPH__ACCEL | SPH__STORE : SPH__ACCEL, w->a);
    sph__time(w, SPH_STAGE_FORCES, &t0);
    s = sph__integrate(w, &c, dt, 0, 0, 0); /* kick */
    if (s != SPH_OK) return s;
    if (cont) {
        sph__stage_interact(w, &c, SPH__RATE | SPH__CACHED, NULL);
        sph__time(w, SPH_STAGE_DENSITY, &t0);
    }
    sph__stage_shift(w, &c, dt);
    ++w->steps;
    w->time += (double)dt;
    s = sph__integrate(w, &c, 0, cont ? dt : 0, dt, 1); /* density and drift */
    sph__time(w, SPH_STAGE_INTEGRATE, &t0);
    w->stats.step_time = sph__now() - tstart;
    return s;
}

static sph_status sph__step_wcsph_verlet(sph_world* w, sph_real dt) {
    const int cont = w->def.density != SPH_DENSITY_SUMMATION;
    const sph_real half = SPH__R(0.5) * dt;
    double t0 = sph__now(), tstart = t0;
    uint64_t sorts;
    sph__ctx c;
    sph_status s;
    sph__idx i;
    if (cont) { /* scratch for rho^n */
        s = sph__scratch(w, &w->priv.rho_n, w->capacity);
        if (s != SPH_OK) return s;
    }
    if ((s = sph__shift_reserve(w)) != SPH_OK) return s;
    if ((s = sph__body_accel_reserve(w)) != SPH_OK) return s;
    /* x^n, to undo the drift if the neighbour search runs out of memory (sph__undo_drift) */
    s = sph__scratch(w, &w->priv.xp, w->capacity * (size_t)w->dim);
    if (s != SPH_OK) return s;
    sph__copy(w->priv.xp, w->x, w->n * (size_t)w->dim * sizeof(sph_real));
    sph__x_start(w, w->priv.xp, half);
    sph__ctx_init(w, &c);
    s = sph__integrate(w, &c, 0, 0, half, 0); /* drift */
    if (s != SPH_OK) return s;
    sph__time(w, SPH_STAGE_INTEGRATE, &t0);
    s = sph__boundary_motion(w, w->time + (double)half);
    if (s != SPH_OK) return s;
    sph__time(w, SPH_STAGE_BOUNDARY, &t0);
    sorts = w->priv.sorts;
    s = sph__stage_neighbors(w);
    sph__ctx_init(w, &c);
    if (s == SPH_OK && cont) s = sph__rate_cache(w, &c);
    if (s != SPH_OK) {
        sph__undo_drift(w, w->priv.xp, sorts);
        return s;
    }
    sph__time(w, SPH_STAGE_NEIGHBORS, &t0);
    if (cont) {
        SPH__OMP_FOR(w->n)
        for (i = 0; i < (sph__idx)w->n; ++i) {
            w->priv.rho_n[i] = w->rho[i];
            w->rho[i] = sph__rho_floor(&c, (size_t)i, w->rho[i] + half * w->drho[i]);
        }
    } else {
        sph__stage_density_summation(w, &c);
    }
    sph__time(w, SPH_STAGE_DENSITY, &t0);
    sph__stage_eos(w, &c);
    sph__time(w, SPH_STAGE_PRESSURE, &t0);
    if ((s = sph__stage_body_force(w, &c)) != SPH_OK) return s;
    sph__keep_body_accel(w, &c);
    sph__time(w, SPH_STAGE_FORCES, &t0);
    if (w->nb > 0) sph__stage_wall(w, &c, SPH__WALL_STATE | SPH__WALL_PRESSURE);
    sph__time(w, SPH_STAGE_PRESSURE, &t0);
    sph__stage_interact(w, &c, cont ? SPH__ACCEL | SPH__STORE : SPH__ACCEL, w->a);
    sph__time(w, SPH_STAGE_FORCES, &t0);
    s = sph__integrate(w, &c, half, 0, 0, 0); /* half kick: v = (v^n + v^{n+1}) / 2 */
    if (s != SPH_OK) return s;
    if (cont) {
        sph__stage_interact(w, &c, SPH__RATE | SPH__CACHED, NULL);
        SPH__OMP_FOR(w->n)
        for (i = 0; i < (sph__idx)w->n; ++i) w->rho[i] = sph__rho_floor(&c, (size_t)i, w->priv.rho_n[i] + dt * w->drho[i]);
        sph__time(w, SPH_STAGE_DENSITY, &t0);
    }
    sph__stage_shift(w, &c, dt);
    ++w->steps;
    w->time += (double)dt;
    s = sph__integrate(w, &c, half, 0, half, 1); /* half kick, drift */
    sph__time(w, SPH_STAGE_INTEGRATE, &t0);
    w->stats.step_time = sph__now() - tstart;
    return s;
}

/* Adds the step's timings to the world's totals. */

/* ---- the second-order scheme (L-IPST-C) --------------------------------------------------------
   Negi & Ramachandran 2022 (sec. II D 1), for periodic domains:
       d rho_i/dt = -rho_i <div u>_i                         div_bc (Table II)
       d u_i/dt   = -<grad p>_i / rho_i + nu <Lap u>_i + g    asym_bc, coupled_bc
   with rho the fluid density carried by the particle (w->rho) and p = p(rho) by the phase's
   equation of state; the operators' volumes are the Shepard volumes omega = 1/sum_j W_ij of the
   geometry, never m/rho (sec. III A: the EOS must not see the particle density). Decisions where
   the paper is silent: RK2 is the midpoint rule (y* = y + dt/2 f(y), then
   y += dt f(y*)), the midpoint with its own neighbour lists; shifting (eq. 19-21) runs after
   every def.shift_every-th step, at most 10 iterations, until max_i |chi_i - chi_0| < 1e-3 chi_0
   with chi = h^d sum_j W_ij (chi_0 its lattice value; the paper leaves epsilon open), and each
   iteration Taylor-corrects u and rho with their corrected gradients at the positions before
   it moved (eq. 22; p follows from rho). No delta-SPH term, no artificial viscosity: the
   scheme is what converges. The corrected operators do not conserve momentum exactly (the
   tests report the drift). */
static sph_status sph__soc_check(sph_world* w) {
    int k;
    for (k = 0; k < w->dim; ++k)
        if (!w->def.periodic[k])
            return sph__fail(w, SPH_ERR_ARG, -1,
                             "def.scheme = SPH_SCHEME_SECOND_ORDER needs every direction periodic "
                             "(direction %d is not): the scheme has no wall condition", k);
    if (w->nb > 0)
        return sph__fail(w, SPH_ERR_ARG, -1,
                         "def.scheme = SPH_SCHEME_SECOND_ORDER runs without walls (%zu boundary "
                         "particles)", w->nb);
    if (w->def.density == SPH_DENSITY_SUMMATION)
        return sph__fail(w, SPH_ERR_ARG, -1,
                         "def.scheme = SPH_SCHEME_SECOND_ORDER carries the fluid density by "
                         "continuity: def.density must not be SPH_DENSITY_SUMMATION");
    return SPH_OK;
}

/* Scratch layout (n particles, D dims): vol n, B n D^2, gp n D, tmp n D, lap n, x0 n D, v0 n D,
   r0 n, dxs n D, xref n D (the positions the lists were built at). */
typedef struct sph__soc {
    sph_real *vol, *B, *gp, *tmp, *lap, *x0, *v0, *r0, *dxs, *xref;
} sph__soc;

/* The lists carry a skin of 0.2 dx beyond the support and hold while no particle has moved
   half of it since they were built: one build serves both RK2 stages and the shifting
   iterations, and usually several steps (pairs beyond the support add zero). */
#define SPH__SOC_SKIN SPH__R(0.2)

static sph_status sph__soc_scratch(sph_world* w, sph__soc* S) {
    const size_t n = w->capacity, D = (size_t)w->dim;
    sph_status s = sph__scratch(w, &w->priv.soc, n * (3 + 6 * D + D * D));
    sph_real* q = w->priv.soc;
    if (s != SPH_OK) return s;
    S->vol = q; q += n;
    S->B = q; q += n * D * D;
    S->gp = q; q += n * D;
    S->tmp = q; q += n * D;
    S->lap = q; q += n;
    S->x0 = q; q += n * D;
    S->v0 = q; q += n * D;
    S->r0 = q; q += n;
    S->dxs = q; q += n * D;
    S->xref = q;
    if (!w->priv.sgrid_ready) {
        s = sph_grid_init(&w->priv.sgrid, w->dim, w->kernel.radius + SPH__SOC_SKIN * w->dx,
                          w->priv.grid.periodic, w->def.domain_lo, w->def.domain_hi);
        if (s != SPH_OK) return sph__fail(w, s, -1, "second-order scheme: grid setup failed");
        w->priv.sgrid_ready = 1;
    }
    return SPH_OK;
}

/* Makes w->priv.snl valid for the current positions: kept if no particle moved half the skin
   since its build (and nothing reordered or added particles), else rebuilt, after sorting the
   particles by cell when `sort` (only between steps: the stage copies are not reordered). */
static sph_status sph__soc_lists(sph_world* w, const sph__soc* S, int sort) {
    const size_t n = w->n, D = (size_t)w->dim;
    const sph_real half = SPH__R(0.5) * SPH__SOC_SKIN * w->dx;
    sph_status s;
    if (w->priv.snl_valid && w->priv.snl_sorts == w->priv.sorts && w->priv.snl.n == n) {
        sph_real m2 = 0;
        size_t i;
        for (i = 0; i < n; ++i) {
            sph_real d[3], r2 = 0;
            size_t a;
            sph_grid_delta(&w->priv.sgrid, w->x + i * D, S->xref + i * D, d);
            for (a = 0; a < D; ++a) r2 += d[a] * d[a];
            if (r2 > m2) m2 = r2;
        }
        if (m2 < half * half) return SPH_OK;
    }
    if (sort) {
        sph__array arr[16];
        int narr;
        s = sph_grid_build(&w->priv.grid, w->x, n);
        if (s != SPH_OK) return sph__fail(w, s, -1, "neighbour grid: %s", sph_status_string(s));
        narr = sph__fluid_arrays(w, arr);
        sph__permute(w, arr, narr, w->priv.grid.order, n);
        ++w->priv.sorts;
    }
    s = sph_grid_build(&w->priv.sgrid, w->x, n);
    if (s == SPH_OK)
        s = sph_neighbors_build(&w->priv.snl, &w->priv.sgrid, w->x, w->x, n,
                                w->kernel.radius + SPH__SOC_SKIN * w->dx, 1);
    if (s != SPH_OK) return sph__fail(w, s, -1, "second-order scheme: neighbour lists: %s",
                                      sph_status_string(s));
    sph__copy(S->xref, w->x, n * D * sizeof(sph_real));
    w->priv.snl_valid = 1;
    w->priv.snl_sorts = w->priv.sorts;
    w->stats.pairs = w->priv.snl.total;
    return SPH_OK;
}

/* d = a - b with the periodic minimum image (the scheme's domain is periodic). */
SPH__INLINE void sph__soc_delta(const sph_grid* g, const sph_real* a, const sph_real* b,
                                sph_real* d, int D) {
    int k;
    for (k = 0; k < D; ++k) d[k] = sph__wrap_delta(a[k] - b[k], g->len[k]);
}

/* The geometry of a neighbourhood, once per stage: the Shepard volumes omega_i and, with
   `gradients`, the corrected kernel gradient of every listed pair weighted by the neighbour's
   volume, gw[kk] = omega_j B_i grad W_ij, so that each operator after it is a few multiply-adds
   per pair (the public sph_op_* recompute the kernel in every call). */
static sph_status sph__soc_geometry(sph_world* w, const sph_grid* g, const sph_neighbors* nl,
                                    const sph__soc* S, int gradients) {
    const size_t n = w->n, D = (size_t)w->dim;
    const int Di = w->dim;
    const sph_kernel* k = &w->kernel;
    sph_real* gw;
    sph__idx i;
    if (!gradients) {
        sph_op_volume(g, nl, k, w->x, n, S->vol);
        return SPH_OK;
    }
    /* indexed like nl->idx, whose chunks leave gaps: sized by its capacity */
    if (sph__scratch(w, &w->priv.socw, nl->cap_idx * D + D) != SPH_OK) return w->status;
    gw = w->priv.socw;
    SPH__OMP_FOR(n)
    for (i = 0; i < (sph__idx)n; ++i) { /* W sums and raw gradients */
        const size_t k0 = nl->begin[i], k1 = k0 + nl->count[i];
        sph_real sum = k->norm_w * sph__kw(k->form, 0), d[3], r2, q, f;
        size_t kk, a;
        for (kk = k0; kk < k1; ++kk) {
            sph__soc_delta(g, w->x + (size_t)i * D, w->x + (size_t)nl->idx[kk] * D, d, Di);
            for (r2 = 0, a = 0; a < D; ++a) r2 += d[a] * d[a];
            q = sph__sqrt(r2) * k->inv_h; /* the skin's pairs beyond the support add zero */
            sum += k->norm_w * sph__kw(k->form, q);
            f = k->norm_g * sph__kf(k->form, q);
            for (a = 0; a < D; ++a) gw[kk * D + a] = f * d[a];
        }
        S->vol[i] = 1 / sum;
    }
    SPH__OMP_FOR(n)
    for (i = 0; i < (sph__idx)n; ++i) { /* B_i, then gw = omega_j B_i grad W_ij */
        const size_t k0 = nl->begin[i], k1 = k0 + nl->count[i];
        sph_real* Bi = S->B + (size_t)i * D * D;
        sph_real d[3], t[3];
        size_t kk;
        int a, b;
        for (a = 0; a < Di * Di; ++a) Bi[a] = 0;
        for (kk = k0; kk < k1; ++kk) {
            const size_t j = nl->idx[kk];
            sph__soc_delta(g, w->x + (size_t)i * D, w->x + j * D, d, Di); /* x_i - x_j */
            for (a = 0; a < Di; ++a)
                for (b = 0; b < Di; ++b) Bi[a * Di + b] -= S->vol[j] * gw[kk * D + (size_t)a] * d[b];
        }
        if (!sph__invert(Bi, Di)) { /* too few neighbours: uncorrected */
            for (a = 0; a < Di * Di; ++a) Bi[a] = 0;
            for (a = 0; a < Di; ++a) Bi[a * Di + a] = 1;
        }
        for (kk = k0; kk < k1; ++kk) {
            const sph_real vj = S->vol[nl->idx[kk]];
            for (a = 0; a < Di; ++a) t[a] = gw[kk * D + (size_t)a];
            for (a = 0; a < Di; ++a) {
                sph_real acc = 0;
                for (b = 0; b < Di; ++b) acc += Bi[a * Di + b] * t[b];
                gw[kk * D + (size_t)a] = vj * acc;
            }
        }
    }
    return SPH_OK;
}

/* grad f_i = sum_j (f_j - f_i) gw_ij (asym_bc), f read with a stride. */
static void sph__soc_grad(const sph_world* w, const sph_neighbors* nl, const sph_real* f,
                          size_t stride, sph_real* grad) {
    const size_t D = (size_t)w->dim;
    const sph_real* gw = w->priv.socw;
    sph__idx i;
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)w->n; ++i) {
        const size_t k0 = nl->begin[i], k1 = k0 + nl->count[i];
        const sph_real fi = f[(size_t)i * stride];
        sph_real acc[3] = {0, 0, 0};
        size_t kk, a;
        for (kk = k0; kk < k1; ++kk) {
            const sph_real df = f[(size_t)nl->idx[kk] * stride] - fi;
            for (a = 0; a < D; ++a) acc[a] += df * gw[kk * D + a];
        }
        for (a = 0; a < D; ++a) grad[(size_t)i * D + a] = acc[a];
    }
}

/* div u_i = sum_j (u_j - u_i) . gw_ij (div_bc), u with stride D. */
static void sph__soc_div(const sph_world* w, const sph_neighbors* nl, const sph_real* u, sph_real* div) {
    const size_t D = (size_t)w->dim;
    const sph_real* gw = w->priv.socw;
    sph__idx i;
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)w->n; ++i) {
        const size_t k0 = nl->begin[i], k1 = k0 + nl->count[i];
        const sph_real* ui = u + (size_t)i * D;
        sph_real acc = 0;
        size_t kk, a;
        for (kk = k0; kk < k1; ++kk) {
            const sph_real* uj = u + (size_t)nl->idx[kk] * D;
            for (a = 0; a < D; ++a) acc += (uj[a] - ui[a]) * gw[kk * D + a];
        }
        div[i] = acc;
    }
}

/* The right-hand sides at the world's current x, v, rho with lists (g, nl): w->a, w->drho. */
static sph_status sph__soc_rhs(sph_world* w, const sph__ctx* c, const sph__soc* S,
                               const sph_grid* g, const sph_neighbors* nl) {
    const size_t n = w->n, D = (size_t)w->dim;
    sph__idx i;
    size_t a;
    int any_visc = 0, q;
    if (sph__soc_geometry(w, g, nl, S, 1) != SPH_OK) return w->status;
    SPH__OMP_FOR(n)
    for (i = 0; i < (sph__idx)n; ++i) w->p[i] = sph__eos(&c->pc[w->phase[i]], w->rho[i]);
    sph__soc_grad(w, nl, w->p, 1, S->gp);
    sph__soc_div(w, nl, w->v, S->lap);
    if (sph__stage_body_force(w, c) != SPH_OK) return w->status; /* w->a = g + user forces */
    SPH__OMP_FOR(n)
    for (i = 0; i < (sph__idx)n; ++i) {
        const sph_real inv = 1 / w->rho[i];
        size_t b;
        w->drho[i] = -w->rho[i] * S->lap[i];
        for (b = 0; b < D; ++b) w->a[(size_t)i * D + b] -= S->gp[(size_t)i * D + b] * inv;
    }
    for (q = 0; q < w->nphase; ++q) if (w->phases[q].viscosity > 0) any_visc = 1;
    if (!any_visc || n == 0) return SPH_OK; /* n = 0: w->v may be NULL, w->v + a undefined */
    for (a = 0; a < D; ++a) { /* nu <Lap u_a>_i = div of the corrected gradient (coupled_bc) */
        sph__soc_grad(w, nl, w->v + a, D, S->tmp);
        sph__soc_div(w, nl, S->tmp, S->lap);
        SPH__OMP_FOR(n)
        for (i = 0; i < (sph__idx)n; ++i)
            w->a[(size_t)i * D + a] += w->phases[w->phase[i]].viscosity * S->lap[i];
    }
    return SPH_OK;
}

static void sph__soc_wrap(sph_world* w, const sph__ctx* c, sph_real* x) {
    const int D = w->dim;
    sph__idx i;
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)w->n; ++i) {
        int kk;
        for (kk = 0; kk < D; ++kk) {
            sph_real* xi = x + (size_t)i * (size_t)D + (size_t)kk;
            const sph_real lo = w->def.domain_lo[kk];
            if (*xi < lo || *xi >= lo + c->len[kk]) *xi -= c->len[kk] * sph__floor((*xi - lo) / c->len[kk]);
            if (*xi >= lo + c->len[kk]) *xi = lo;
        }
    }
}

/* Iterative particle shifting with Taylor-corrected velocity and density (eq. 19-22). Returns
   the iterations that moved particles in w->stats.iterations. The new densities go to S->lap and
   the new velocities to S->gp (once the density gradient there is used): S->x0, v0, r0 keep the
   step's start state, which sph__step_soc restores when the shifting runs out of memory. */
static sph_status sph__soc_shift(sph_world* w, const sph__ctx* c, const sph__soc* S) {
    const size_t n = w->n, D = (size_t)w->dim;
    const sph_kernel* k = &w->kernel;
    const sph_grid* g = &w->priv.sgrid;
    const sph_neighbors* nl = &w->priv.snl;
    double chi0 = (double)w->priv.lattice_sum, hd = 1;
    int it, dd;
    for (dd = 0; dd < w->dim; ++dd) {
        chi0 *= (double)(k->h / w->dx); /* h^d sum W on the lattice */
        hd *= (double)k->h;
    }
    for (it = 0; it < 10; ++it) {
        double dev = 0;
        sph__idx i;
        sph_status s = sph__soc_lists(w, S, 0);
        size_t a;
        if (s != SPH_OK) return s;
        s = sph__soc_geometry(w, g, nl, S, 1);
        if (s != SPH_OK) return s;
        for (i = 0; i < (sph__idx)n; ++i) { /* chi_i = h^d / omega_i */
            const double dv = fabs(hd / (double)S->vol[i] - chi0);
            if (dv > dev) dev = dv;
        }
        if (dev < 1e-3 * chi0) break;
        SPH__OMP_FOR(n)
        for (i = 0; i < (sph__idx)n; ++i) { /* eq. 19: dx_i = h sum_j n_ij W_ij omega_j */
            const size_t k0 = nl->begin[i], k1 = k0 + nl->count[i];
            sph_real acc[3] = {0, 0, 0}, d[3];
            size_t kk, b;
            for (kk = k0; kk < k1; ++kk) {
                const size_t j = nl->idx[kk];
                sph_real r2 = 0, r, cw;
                sph__soc_delta(g, w->x + (size_t)i * D, w->x + j * D, d, w->dim);
                for (b = 0; b < D; ++b) r2 += d[b] * d[b];
                r = sph__sqrt(r2);
                if (!(r > 0)) continue;
                cw = k->norm_w * sph__kw(k->form, r * k->inv_h) * S->vol[j] / r;
                for (b = 0; b < D; ++b) acc[b] += cw * d[b];
            }
            for (b = 0; b < D; ++b) S->dxs[(size_t)i * D + b] = k->h * acc[b];
        }
        /* Taylor correction, gradients at the positions before the move */
        sph__soc_grad(w, nl, w->rho, 1, S->gp);
        SPH__OMP_FOR(n)
        for (i = 0; i < (sph__idx)n; ++i) {
            sph_real dr = 0;
            size_t b;
            for (b = 0; b < D; ++b) dr += S->dxs[(size_t)i * D + b] * S->gp[(size_t)i * D + b];
            S->lap[i] = w->rho[i] + dr;
        }
        for (a = 0; a < D; ++a) {
            sph__soc_grad(w, nl, w->v + a, D, S->tmp);
            SPH__OMP_FOR(n)
            for (i = 0; i < (sph__idx)n; ++i) {
                sph_real dv = 0;
                size_t b;
                for (b = 0; b < D; ++b) dv += S->dxs[(size_t)i * D + b] * S->tmp[(size_t)i * D + b];
                S->gp[(size_t)i * D + a] = w->v[(size_t)i * D + a] + dv;
            }
        }
        SPH__OMP_FOR(n)
        for (i = 0; i < (sph__idx)n; ++i) {
            size_t b;
            w->rho[i] = S->lap[i];
            for (b = 0; b < D; ++b) {
                w->v[(size_t)i * D + b] = S->gp[(size_t)i * D + b];
                w->x[(size_t)i * D + b] += S->dxs[(size_t)i * D + b];
            }
        }
        sph__soc_wrap(w, c, w->x);
    }
    w->stats.iterations = it;
    return SPH_OK;
}

/* From the step's start state: x = x0 + k u, v = v0 + k a, rho = r0 + k drho, with u = v0 (first
   stage) or the midpoint velocity in w->v (read before it is overwritten). */
static void sph__soc_update(sph_world* w, const sph__ctx* c, const sph__soc* S, sph_real k,
                            const sph_real* u) {
    const size_t D = (size_t)w->dim;
    sph__idx i;
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)w->n; ++i) {
        const size_t o = (size_t)i * D;
        size_t b;
        for (b = 0; b < D; ++b) {
            w->x[o + b] = S->x0[o + b] + k * u[o + b];
            w->v[o + b] = S->v0[o + b] + k * w->a[o + b];
        }
        w->rho[i] = S->r0[i] + k * w->drho[i];
    }
    sph__soc_wrap(w, c, w->x);
}

/* Out of memory after the first stage moved the particles (the midpoint or shifting lists, or
   the pair scratch, had to grow): back to the step's start state x0, v0, r0, time and steps, so
   that the step can be repeated (the lists may then differ from an uninterrupted run's). */
static sph_status sph__soc_undo(sph_world* w, const sph__soc* S, double time, uint64_t steps,
                                sph_status s) {
    const size_t n = w->n, D = (size_t)w->dim;
    sph__copy(w->x, S->x0, n * D * sizeof(sph_real));
    memcpy(w->v, S->v0, n * D * sizeof(sph_real));
    memcpy(w->rho, S->r0, n * sizeof(sph_real));
    w->time = time;
    w->steps = steps;
    return s;
}

static sph_status sph__step_soc(sph_world* w, sph_real dt) {
    const size_t n = w->n, D = (size_t)w->dim;
    const sph_real h2 = SPH__R(0.5) * dt;
    const double time0 = w->time;
    const uint64_t steps0 = w->steps;
    double t0 = sph__now(), tstart = t0;
    sph__ctx c;
    sph__soc S;
    sph_status s = sph__soc_scratch(w, &S);
    if (s != SPH_OK) return s;
    s = sph__soc_lists(w, &S, 1); /* sorts the particles by cell when the lists are rebuilt */
    if (s != SPH_OK) return s;
    sph__ctx_init(w, &c);
    sph__time(w, SPH_STAGE_NEIGHBORS, &t0);
    sph__copy(S.x0, w->x, n * D * sizeof(sph_real));
    sph__copy(S.v0, w->v, n * D * sizeof(sph_real));
    sph__copy(S.r0, w->rho, n * sizeof(sph_real));
    /* stage 1 at t^n */
    s = sph__soc_rhs(w, &c, &S, &w->priv.sgrid, &w->priv.snl);
    if (s != SPH_OK) return s;
    sph__time(w, SPH_STAGE_FORCES, &t0);
    sph__soc_update(w, &c, &S, h2, S.v0);
    /* stage 2 at the midpoint */
    s = sph__soc_lists(w, &S, 0);
    if (s != SPH_OK) return sph__soc_undo(w, &S, time0, steps0, s);
    sph__time(w, SPH_STAGE_NEIGHBORS, &t0);
    s = sph__soc_rhs(w, &c, &S, &w->priv.sgrid, &w->priv.snl);
    if (s != SPH_OK) return sph__soc_undo(w, &S, time0, steps0, s);
    sph__time(w, SPH_STAGE_FORCES, &t0);
    sph__soc_update(w, &c, &S, dt, w->v);
    ++w->steps;
    w->time += (double)dt;
    sph__time(w, SPH_STAGE_INTEGRATE, &t0);
    if (w->def.shift_every > 0 && w->steps % (uint64_t)w->def.shift_every == 0) {
        s = sph__soc_shift(w, &c, &S);
        if (s != SPH_OK) return sph__soc_undo(w, &S, time0, steps0, s);
        sph__time(w, SPH_STAGE_INTEGRATE, &t0);
    }
    s = sph__integrate_with(w, &c, w->a, 0, 0, 0, 1); /* diagnostics and blow-up checks only */
    w->stats.step_time = sph__now() - tstart;
    return s;
}

static sph_status sph__step_end(sph_world* w, sph_status s) {
    int k;
    w->step_time_total += w->stats.step_time;
    for (k = 0; k < SPH_STAGE_COUNT; ++k) w->stage_time_total[k] += w->stats.stage_time[k];
    return s;
}

SPHDEF sph_status sph_step_wcsph(sph_world* w, sph_real dt) {
    sph_status s = sph__step_begin(w, dt, SPH_SOLVER_WCSPH);
    if (s != SPH_OK) return s;
    if (w->def.scheme == SPH_SCHEME_SECOND_ORDER) {
        s = sph__soc_check(w);
        if (s != SPH_OK) return s;
        return sph__step_end(w, sph__step_soc(w, dt));
    }
    if (w->def.integrator == SPH_INTEGRATOR_VERLET) return sph__step_end(w, sph__step_wcsph_verlet(w, dt));
    return sph__step_end(w, sph__step_wcsph_euler(w, dt));
}

/* ============================================================================================== */
/* >>pcisph (implementation)                                                                      */
/* ============================================================================================== */
/* Predictive-corrective incompressible SPH (Solenthaler & Pajarola 2009; Enhanced PCISPH 2018
   Alg. 5 and sec. 3.2). Each step, after the non-pressure accelerations a_np:
     p = warm_start * p^{n-1} (Alg. 5: 0), a_p = 0;  repeat:
       v* = v^n + dt (a_np + a_p)
       rho* = summation over predicted positions x* = x + dt v*           (original)
            | rho^n + dt [sum_j m_j (v*_i - v*_j).grad W_ij + delta-SPH]   (enhanced, thesis
              sec. 3.2.1 and 3.2.4; Ott-Schnetter's m_i with SPH_DENSITY_PARTICLE)
       p_i = max(0, p_i + f_i (rho*_i - rho0_i))      negative pressure is clamped (free surfaces)
       [p_i = chi p_i + (1 - chi) <p>_i]              pressure smoothing, thesis sec. 3.2.1
       a_p = pressure acceleration of p (at x* with summation density, at x^n otherwise)
     until the mean compression max(rho* / rho0 - 1, 0) <= tolerance (and the largest <= tolerance_max
     if set), after min_iterations and at most max_iterations; then v^{n+1} = v^n + dt (a_np + a_p)
     with the last a_p, x^{n+1} = x^n + dt v^{n+1}, and with continuity rho^{n+1} = rho^n + dt R(v^{n+1}).
   The gain f (Enhanced PCISPH 2018 eq. 3.5 and sec. 3.2.4; Solenthaler & Pajarola 2009 move a
   particle by dt^2 F/m where the thesis has dt^2/2 F/m, which doubles its gain: pcisph_gain):
     prototype    f = gain rho0^2 / (2 dt^2 m^2 sum_j |grad W_0j|^2), a full lattice neighbourhood
                  (where sum_j grad W_0j = 0), per phase;
     per particle f_i = gain rho_i / (2 dt^2 [(sum_j V_j gW_ij).(sum_j m_j gW_ij) + m_i sum_j V_j |gW_ij|^2])
                  from the actual neighbours and masses at x^n (walls in the first product), per step.
   With summation density the predicted density is divided by the lattice sum S, so f is too.
   Decisions where the thesis is silent:
     (b) diffusion and smoothing act inside the loop: delta-SPH is part of every predicted
         density (it must be, or the correction would undo it), and the accumulated pressure is
         smoothed after each correction (Shepard-normalised, so free surfaces and walls are not
         biased low), i.e. the iteration converges to a smooth pressure, until the error stalls
         above the tolerance (the smoothing's fixed point): the rest of that solve sums its
         corrections unsmoothed and the forces take the smoothed sum;
     (c) wall pressure is extrapolated from the current pressure in every iteration, the wall
         density is the Shepard average of the fluid's (thesis sec. 3.2.3);
     (e) Alg. 5 starts every step from p = 0: one step of gravity barely compresses the predicted
         state, so the loop stops with a fraction of the hydrostatic pressure and the fluid sags
         until a standing compression near the tolerance carries it (an underdamped, WCSPH-like
         equilibrium). The enhanced preset warm-starts from half the last pressure, as IISPH,
         times 4 (dt_prev / dt)^2 when the step more than doubles (a correction's pressure
         scales as 1 / dt^2);
     (d) with Stormer-Verlet the positions drift half a step, the correction runs at the half step
         and constrains the density at the end of the step, predicted at x^{n+1/2} with the
         velocity beta v^n + (1 - beta) v*, beta = SPH__PCI_BETA = 0.47 (summation: at x^{n+1/2}
         + dt/2 v*), which sees 1 - beta of a velocity change (summation: half), so the gain is
         divided by that; the velocity kick and the second drift use the final pressure, and the
         density integrates by the midpoint rule, rho^{n+1} = rho^n + dt R(x^{n+1/2}, (v^n +
         v^{n+1})/2). Why off-centre (as the theta-methods' theta > 1/2 damps the two-step mode
         of Crank-Nicolson): per mode, with e = dt R(v) and d = rho - rho0, the constraint gives
         e' = -(d + beta e)/(1 - beta) and d' = d + (e + e')/2, whose eigenvalues have the
         product (1 - 2 beta)/(2 (1 - beta)) and the sum 1 - (1/2 + beta)/(1 - beta): at the
         midpoint, beta = 1/2, they are 0 and -1, so the compression rate of v^n comes back with
         the opposite sign every step, undamped, and noise feeds it; at 0.47 they are -0.75 and
         -0.08. Measured on the layered column of tests/test_layers.c (20 across, particle
         density, sph_advance, over the second second): beta = 1/2 3.9 % of sqrt(g H) and 5.7 %
         time-averaged pressure error, the region-averaged pressure at frame ends off by up to
         33 % (interior rows) and 107 % (bottom row) of the bottom pressure; beta = 0.47 0.49 %
         and 0.63 % (with the gradient's lattice normalisation, pg_norm). Smaller beta damps more
         in the model (0 gives 0.71, 0.4 gives 0.41) but not in a fluid: tests/test_reliability.c's
         periodic box of random velocities gained kinetic energy without forcing (SPH_ERR_UNSTABLE)
         at beta <= 0.46, more checks failing the smaller beta. The dam break of
         tests/test_pcisph.c at sph_stable_dt without retries depends on any change of the
         numerics: a particle in a corner compresses without bound at beta = 0.48 and 0.5 (with
         pg_norm), not at 0.40-0.47 or 0.49. */

#define SPH__PCI_BETA 0.47 /* weight of v^n in enhanced PCISPH's Verlet prediction, see (d) */

/* sum_j |grad W(x_j)|^2 over a square lattice of spacing dx (the prototype's neighbourhood). */
static double sph__lattice_grad2(const sph_kernel* k, sph_real dx) {
    const int R = (int)(k->radius / dx) + 1, D = k->dim;
    double sum = 0;
    int i, j, l;
    for (i = -R; i <= R; ++i)
        for (j = (D > 1 ? -R : 0); j <= (D > 1 ? R : 0); ++j)
            for (l = (D > 2 ? -R : 0); l <= (D > 2 ? R : 0); ++l) {
                const double g = (double)sph_kernel_dwdr(k, dx * sph__sqrt((sph_real)(i * i + j * j + l * l)));
                sum += g * g;
            }
    return sum;
}

/* Denominator of the per-particle gain at x^n (without dt^2), Enhanced PCISPH 2018 sec. 3.2.4:
       (sum_j V_j gW_ij) . (sum_j mu_j gW_ij) + m_i sum_j (mu_j / rho_j) |gW_ij|^2,
   where mu_j is the mass that weighs neighbour j in the density change: m_j for the continuity
   equation (the thesis' derivation), m_i for Ott-Schnetter's particle density, for which the
   thesis' gain would be several times too large for a heavy particle among light ones (the
   corrector then oscillates across a 5:1 interface). */
SPH__INLINE sph_real sph__pcisph_denominator(const sph__ctx* c, size_t i, const int D) {
    const sph_real* xi = c->x + i * (size_t)D;
    const sph__phase_c* P = &c->pc[c->ph[i]];
    const sph_real mi = c->m ? c->m[i] : c->m0;
    const int os = c->density == SPH_DENSITY_PARTICLE;
    sph_real sv[3] = {0, 0, 0}, sm[3] = {0, 0, 0}, q = 0, dot = 0;
    size_t kk, k0 = c->ff->begin[i], k1 = k0 + c->ff->count[i];
    int k;
    for (kk = k0; kk < k1; ++kk) {
        const size_t j = c->ff->idx[kk];
        const sph_real mj = c->m ? c->m[j] : c->m0, Vj = mj / c->rho[j], mu = os ? mi : mj;
        sph_real d[3] = {0, 0, 0}, r2 = 0, fw;
        sph__delta_vec(c, xi, c->x + j * (size_t)D, d, D);
        for (k = 0; k < D; ++k) r2 += d[k] * d[k];
        fw = c->k.norm_g * sph__kf(c->k.form, sph__sqrt(r2) * c->k.inv_h);
        for (k = 0; k < D; ++k) { sv[k] += Vj * fw * d[k]; sm[k] += mu * fw * d[k]; }
        q += mu / c->rho[j] * fw * fw * r2;
    }
    if (c->has_b) {
        k0 = c->fb->begin[i];
        k1 = k0 + c->fb->count[i];
        for (kk = k0; kk < k1; ++kk) {
            const size_t b = c->fb->idx[kk];
            const sph_real Vb = c->bvol[b];
            sph_real d[3] = {0, 0, 0}, r2 = 0, fw;
            sph__delta_vec(c, xi, c->bx + b * (size_t)D, d, D);
            for (k = 0; k < D; ++k) r2 += d[k] * d[k];
            fw = c->k.norm_g * sph__kf(c->k.form, sph__sqrt(r2) * c->k.inv_h);
            for (k = 0; k < D; ++k) { sv[k] += Vb * fw * d[k]; sm[k] += P->rho0 * Vb * fw * d[k]; }
        }
    }
    for (k = 0; k < D; ++k) dot += sv[k] * sm[k];
    return dot + mi * q;
}

/* Shepard-normalised kernel average of the pressure c->p, blended into out:
   out_i = chi p_i + (1 - chi) <p>_i (out is not c->p: every particle reads the old pressures). */
static void sph__stage_smooth_pressure(sph_world* w, const sph__ctx* c, sph_real chi,
                                       sph_real* out) {
    const int D = c->dim;
    const sph_real w0 = sph__kw(c->k.form, 0);
    sph__idx i;
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)w->n; ++i) {
        const sph_real* xi = c->x + (size_t)i * (size_t)D;
        const sph_real Vi = (c->m ? c->m[i] : c->m0) / c->rho[i];
        sph_real num = Vi * c->p[i] * w0, den = Vi * w0;
        size_t kk, k0 = c->ff->begin[i], k1 = k0 + c->ff->count[i];
        for (kk = k0; kk < k1; ++kk) {
            const size_t j = c->ff->idx[kk];
            const sph_real Vj = (c->m ? c->m[j] : c->m0) / c->rho[j];
            sph_real d[3] = {0, 0, 0}, r2 = 0, W;
            int k;
            sph__delta_vec(c, xi, c->x + j * (size_t)D, d, D);
            for (k = 0; k < D; ++k) r2 += d[k] * d[k];
            W = sph__kw(c->k.form, sph__sqrt(r2) * c->k.inv_h);
            num += Vj * c->p[j] * W;
            den += Vj * W;
        }
        out[i] = chi * c->p[i] + (1 - chi) * num / den;
    }
}

static sph_status sph__step_pcisph(sph_world* w, sph_real dt, double dt_prev) {
    const int D = w->dim, verlet = w->def.integrator == SPH_INTEGRATOR_VERLET;
    const int summation = w->def.density == SPH_DENSITY_SUMMATION;
    const int per_particle = w->def.pcisph_factor == SPH_PCISPH_PER_PARTICLE;
    const size_t nblk = (w->n + SPH__BLOCK - 1) / SPH__BLOCK, nD = w->n * (size_t)D;
    const sph_real drift = verlet ? SPH__R(0.5) * dt : dt;
    /* with Verlet the predicted density sees a fraction of a velocity change: half with
       summation (a half drift), 1 - SPH__PCI_BETA with continuity (see (d) above); the gain
       grows by its inverse */
    const double S = (summation ? (double)w->priv.lattice_sum : 1.0) *
                     (verlet ? (summation ? 2.0 : 1.0 / (1.0 - SPH__PCI_BETA)) : 1.0);
    double t0 = sph__now(), tstart = t0, err = 0, errmax = 0, proto[SPH_MAX_PHASES];
    sph_real keep;
    double errmax_min = 0, err_mark = 0;
    /* (b) pressure smoothing: 1 smooths the pressure after every correction, p <- S(p + a e),
       until the error stalls; 2 then sums the corrections unsmoothed, p <- p + a e, and the
       forces (and the pressure the step leaves) take S p. The first has a fixed point where
       the smoothing takes out what the correction adds, e = (S^-1 - 1) p / a, nonzero wherever
       the pressure is not smooth: enhanced PCISPH's correction in a sealed 3D box under gravity
       (0.6 x 0.6 x 0.15 m, dx 0.05) froze at a mean compression of 1.06-1.76e-4 against its
       tolerance of 1e-4 after 30-40 iterations, ran to max_iterations, and sph_advance retried
       the step at half the size 4-9 times per 0.1 s (without smoothing no solve stalled). The
       second has none (S is positive definite) but, alone, leaves a rougher pressure (a tank at
       rest, tests/test_pcisph.c: particle pressure error 0.0225 against 0.0086). So 1 runs until
       the error has fallen by less than 2 % over 5 iterations (from the 10th on) while above
       the tolerance, then 2. */
    int smooth = w->def.pressure_smoothing < 1;
    /* with continuity the solve's passes all run at the same positions: the first rate pass
       keeps grad W of every pair (sph__rate_cache) and the later ones read it, the same values
       (so the same bits); the symmetric gradient's cached form would read p / rho^2 (c.pr2),
       which this solve does not keep, so its pressure pass evaluates the kernel */
    const int cached_p = !summation && w->def.pressure_grad != SPH_PGRAD_SYMMETRIC;
    uint64_t sorts;
    sph__ctx c;
    sph_status s;
    sph__idx i;
    int it = 0, q;
    if ((s = sph__scratch(w, &w->priv.aii, w->capacity)) != SPH_OK ||
        (s = sph__scratch(w, &w->priv.ap, w->capacity * (size_t)D)) != SPH_OK ||
        (s = sph__scratch(w, &w->priv.xp, w->capacity * (size_t)D)) != SPH_OK ||
        (s = sph__scratch(w, &w->priv.vp, w->capacity * (size_t)D)) != SPH_OK ||
        (s = sph__scratch(w, &w->priv.pr2, w->capacity)) != SPH_OK ||
        (s = sph__scratch(w, &w->priv.rho_n, w->capacity)) != SPH_OK ||
        (verlet && w->nb > 0 &&
         (s = sph__scratch(w, &w->priv.xs, w->capacity * (size_t)D)) != SPH_OK))
        return s;
    if (2 * nblk > w->priv.block_cap) {
        if (!sph__grow((void**)&w->priv.block, 2 * nblk + 64, sizeof(double)))
            return sph__fail(w, SPH_ERR_NOMEM, -1, "out of memory (reduction blocks)");
        w->priv.block_cap = 2 * nblk + 64;
    }
    if (verlet) { /* first drift; the correction then runs at the half step */
        sph__copy(w->priv.xp, w->x, nD * sizeof(sph_real)); /* x^n for sph__undo_drift */
        if (w->nb > 0) { /* and for the crossing check (xp holds predictions later) */
            sph__copy(w->priv.xs, w->x, nD * sizeof(sph_real));
            sph__x_start(w, w->priv.xs, SPH__R(0.5) * dt);
        }
        sph__ctx_init(w, &c);
        s = sph__integrate(w, &c, 0, 0, SPH__R(0.5) * dt, 0);
        if (s != SPH_OK) return s;
    }
    s = sph__boundary_motion(w, w->time + (verlet ? 0.5 * (double)dt : 0.0));
    if (s != SPH_OK) return s;
    sph__time(w, SPH_STAGE_BOUNDARY, &t0);
    sorts = w->priv.sorts;
    s = sph__stage_neighbors(w);
    if (s != SPH_OK) {
        if (verlet) sph__undo_drift(w, w->priv.xp, sorts);
        return s;
    }
    sph__ctx_init(w, &c);
    if (!summation && (s = sph__rate_cache(w, &c)) != SPH_OK) {
        if (verlet) sph__undo_drift(w, w->priv.xp, sorts);
        return s;
    }
    /* delta-SPH needs a speed of sound, which PCISPH does not have (Enhanced PCISPH 2018 sec. 3.2.1
       leaves it open). The phase's c0 would make the explicit diffusion unstable at PCISPH's large
       steps (delta h c0 dt / h^2 grows with dt); c = cfl h / dt is the speed for which dt is the
       acoustic CFL step, so the term has per step the strength it has in WCSPH. */
    c.delta_c = w->def.cfl * w->h / dt;
    sph__time(w, SPH_STAGE_NEIGHBORS, &t0);
    if (summation) sph__stage_density_summation(w, &c);
    sph__copy(w->priv.rho_n, w->rho, w->n * sizeof(sph_real));
    sph__time(w, SPH_STAGE_DENSITY, &t0);
    /* non-pressure accelerations a_np (kept in w->a) */
    if ((s = sph__stage_body_force(w, &c)) != SPH_OK) return s;
    if (w->nb > 0) sph__stage_wall(w, &c, SPH__WALL_STATE);
    if (c.laminar || c.av) sph__stage_interact(w, &c, SPH__VISCOUS, w->a);
    sph__time(w, SPH_STAGE_FORCES, &t0);
    /* the warm start, (e) above: a pressure the last step built is a guess for this one only as
       far as the steps match. The share that corrected a density error within the step scales
       as 1 / dt^2 (as the gain does), so after a shorter step it is too large for a longer one:
       a step that sph_advance or a caller shortened to land on a frame's end corrects its
       standing compression with a pressure up to (dt / dt_short)^2 times the usual, and half of
       it warm-started the next, full step, which overshot and diverged (tests/test_pcisph.c's
       dam break at sph_stable_dt: after a step of 1/18 of the rule, 880 kPa at the base of a
       0.1 m column, the next step's largest predicted density went 1.15, 1.39, 2.0, 6.6 rho0
       in its first iterations, and the step failed). So the warm start is scaled by
       4 (dt_prev / dt)^2 when the step more than doubles (never up: a shorter step than the last
       starts from at most warm_start of its pressure, as before). Not for smaller growth: most
       of a warm start is the standing (hydrostatic) pressure, which does not scale with dt, and
       sph_advance's equal steps change dt by less between frames; scaled there too, a layered
       column at rest (tests/test_layers.c, enhanced PCISPH, float) moved at 0.0207 sqrt(g H)
       against 0.0134 */
    const sph_real warm = sph__warm(w) * (dt_prev > 0 && 2 * dt_prev < (double)dt
                                              ? (sph_real)(4 * (dt_prev / (double)dt) * (dt_prev / (double)dt))
                                              : 1);
    /* gains (the gradient's lattice normalisation pg_norm moves a particle that much further per
       pascal, so the gain is divided by it) */
    if (!(w->stats.gain_factor > 0) || w->stats.gain_factor > 1) w->stats.gain_factor = 1;
    {
        const double g2 = sph__lattice_grad2(&w->kernel, w->dx);
        for (q = 0; q < w->nphase; ++q) {
            const double m = (double)w->phases[q].mass, r0 = (double)w->phases[q].rest_density;
            proto[q] = (double)w->def.pcisph_gain * w->stats.gain_factor * S / (double)c.pg_norm * r0 * r0 /
                       (2 * (double)dt * (double)dt * m * m * g2);
        }
    }
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)w->n; ++i) {
        sph_real f;
        if (per_particle) {
            const sph_real den = D == 2   ? sph__pcisph_denominator(&c, (size_t)i, 2)
                                 : D == 3 ? sph__pcisph_denominator(&c, (size_t)i, 3)
                                          : sph__pcisph_denominator(&c, (size_t)i, 1);
            f = den > 0 ? (sph_real)((double)w->def.pcisph_gain * w->stats.gain_factor * S / (double)c.pg_norm * (double)w->rho[i] /
                                     (2 * (double)dt * (double)dt * (double)den))
                        : 0;
        } else {
            f = (sph_real)proto[w->phase[i]];
        }
        w->priv.aii[i] = f;
        w->p[i] = w->p[i] > 0 ? warm * w->p[i] : 0; /* Alg. 5: warm_start = 0 */
    }
    memset(w->priv.ap, 0, nD * sizeof(sph_real));
    keep = sph__standing_keep(w);
    if (sph__enclosed(w, &c)) { /* from the density at x^n */
        /* An enclosed fluid with walls that copy its pressure (extrapolated, mirrored): the
           correction runs with the wall term of the density constraint instead, p_b = 0 (as
           IISPH's and DFSPH's solves do, see sph__enclosed).
           The constraint is C_i = rho*_i with the continuity rate (Enhanced PCISPH 2018 eq. 3.2)
               R_i = sum_j m_j v_ij . grad W_ij + sum_b psi_b v_ib . grad W_ib,  psi_b = rho0 V_b,
           whose pressure force as a constraint force (Koschier et al. 2019 tutorial: the
           pressure force is built from the gradients of the density constraints), here in the
           multiphase form (eq. 12),
               a_i = -sum_j m_j (p_i + p_j) / (rho_i rho_j) grad W_ij
                     - sum_b psi_b p_i / (rho_i rho_b) grad W_ib,
           carries the particle's own pressure at the wall: the wall term of zero wall pressure
           (Akinci et al. 2012). Band et al. 2018 ("Pressure boundaries for implicit incompressible
           SPH") go further and solve for the boundary samples' pressures in an extended pressure
           equation instead of copying the fluid's; not done here. Its power is
           P = sum_i m_i v_i . a_i = -sum_i p_i m_i / (rho_i rho_*) R_i (rho_* the neighbour's
           density), so a pressure that holds the constraint does no work, and the per-particle gain
           (sph__pcisph_denominator: walls in the first product only) is this constraint's own.
           The extrapolated wall pressure p_b = sum_f p_f W_bf / sum_f W_bf (Adami et al. 2012 eq.
           27) adds -sum_b psi_b p_b / (rho_i rho_b) grad W_ib, no derivative of any C_j: its
           constant mode cancels the fluid's gradient exactly (the pure-Neumann problem), while
           the rate's sum over particles, sum_i v_i . (2 m G_i + B_i) with G_i = sum_j grad W_ij and
           B_i = sum_b psi_b grad W_ib (m G_i + B_i = 0 in a full neighbourhood), stays m sum_i
           v_i . G_i for a fluid moving along a wall, so the mean density drifts where no pressure
           can hold it. Measured in tests/test_scenes.c's vortex boxes with extrapolated walls:
           the mean of rho - rho0 reached +63 kg/m^3 in 3D by t = 0.2 s (the mean projection
           hid it from the correction until sph__enclosed's count of thin neighbourhoods turned
           it off at t = 0.09 s, then the pressure level rose to 1e8 Pa and sph_advance failed),
           and the mean |rho / rho0 - 1| 4.6 % in 2D by 0.3 s, where the kinetic energy rose
           by 1.7 % of its start in one frame. With p_b = 0 a uniform pressure pushes the first
           layer off the walls, the mean density error stays at 0.06-0.26 % (2D) and 0.2-1.6 %
           (3D), and the kinetic energy only decays. Tried and not kept: keeping p_b and adding
           its adjoint to the rate (each wall particle's compression rate handed back to the fluid
           with the Shepard weights it took p_b with)
           removed half the drift and the 2D rise, not the 3D failure; removing the rate's mean,
           or fixing the pressure level at min p = 0, made the boxes fail earlier. */
        c.bp_mode = SPH_BP_ZERO;
        memset(w->b_p, 0, w->nb * sizeof(sph_real));
    }
    /* predict and correct */
    for (;;) {
        const size_t nb2 = nblk;
        sph__idx blk;
        /* predicted velocity (and, for the rate, the velocity it sees), positions */
        SPH__OMP_FOR(nD)
        for (i = 0; i < (sph__idx)nD; ++i) {
            const sph_real vs = w->v[i] + dt * (w->a[i] + w->priv.ap[i]);
            w->priv.xp[i] = w->x[i] + drift * vs;
            w->priv.vp[i] = verlet ? SPH__R(SPH__PCI_BETA) * w->v[i] + SPH__R(1 - SPH__PCI_BETA) * vs : vs;
        }
        if (summation) {
            sph__ctx cp = c;
            cp.x = w->priv.xp;
            sph__stage_density_summation(w, &cp);
        } else {
            sph__ctx cr = c;
            cr.v = w->priv.vp;
            sph__stage_interact(w, &cr, it == 0 ? SPH__RATE | SPH__STORE : SPH__RATE | SPH__CACHED,
                                NULL);
            SPH__OMP_FOR(w->n)
            for (i = 0; i < (sph__idx)w->n; ++i) w->rho[i] = sph__rho_floor(&c, (size_t)i, w->priv.rho_n[i] + dt * w->drho[i]);
        }
        /* correct the pressure; mean and largest predicted compression (fixed-order blocks) */
        SPH__OMP_FOR(w->n)
        for (blk = 0; blk < (sph__idx)nb2; ++blk) {
            const size_t i0 = (size_t)blk * SPH__BLOCK;
            const size_t i1 = i0 + SPH__BLOCK < w->n ? i0 + SPH__BLOCK : w->n;
            double e = 0, emax = 0;
            size_t j;
            for (j = i0; j < i1; ++j) {
                const sph_real r0 = c.pc[w->phase[j]].rho0, rn = w->priv.rho_n[j];
                const sph_real drho = w->rho[j] - r0 - keep * (rn > r0 ? rn - r0 : 0);
                const sph_real p = w->p[j] + w->priv.aii[j] * drho;
                const double comp = drho > 0 ? (double)(drho / r0) : 0.0;
                w->p[j] = p > 0 ? p : 0;
                e += comp;
                if (comp > emax) emax = comp;
            }
            w->priv.block[2 * (size_t)blk] = e;
            w->priv.block[2 * (size_t)blk + 1] = emax;
        }
        err = 0;
        errmax = 0;
        for (blk = 0; blk < (sph__idx)nb2; ++blk) {
            err += w->priv.block[2 * (size_t)blk];
            if (w->priv.block[2 * (size_t)blk + 1] > errmax) errmax = w->priv.block[2 * (size_t)blk + 1];
        }
        err = w->n ? err / (double)w->n : 0;
        /* a correction that overshoots (the gain of a particle whose walls extrapolate its own
           pressure is too large for it: a corner) grows its largest error; then the gain is cut
           to 0.7 of itself, as sph__jacobi_guard cuts IISPH's weight */
        if (it == 0 || errmax < errmax_min) errmax_min = errmax;
        if (it >= 3 && errmax > 2 * errmax_min && w->stats.gain_factor > 1e-3) {
            w->stats.gain_factor *= 0.7;
            errmax_min = errmax;
            SPH__OMP_FOR(w->n)
            for (i = 0; i < (sph__idx)w->n; ++i) w->priv.aii[i] *= SPH__R(0.7);
        }
        {
            sph__ctx cq = c; /* pressure positions: predicted with summation density */
            if (summation) cq.x = w->priv.xp;
            if (smooth == 1 && it % 5 == 0) { /* the smoothing's fixed point: see smooth */
                if (it >= 10 && err > (double)w->def.tolerance && err > 0.98 * err_mark) smooth = 2;
                err_mark = err;
            }
            if (smooth) sph__stage_smooth_pressure(w, &cq, w->def.pressure_smoothing, w->priv.pr2);
            if (smooth == 1) sph__copy(w->p, w->priv.pr2, w->n * sizeof(sph_real));
            if (smooth == 2) cq.p = w->priv.pr2;
            if (w->nb > 0) sph__stage_wall(w, &cq, SPH__WALL_PRESSURE);
            sph__stage_interact(w, &cq, cached_p ? SPH__PRESSURE | SPH__SET | SPH__CACHED
                                                 : SPH__PRESSURE | SPH__SET, w->priv.ap);
        }
        ++it;
        if ((it >= w->def.min_iterations && err <= (double)w->def.tolerance &&
             (w->def.tolerance_max <= 0 || errmax <= (double)w->def.tolerance_max)) ||
            it >= w->def.max_iterations)
            break;
    }
    if (err <= (double)w->def.tolerance) w->stats.gain_factor = fmin(1.0, 1.02 * w->stats.gain_factor);
    if (smooth == 2) sph__copy(w->p, w->priv.pr2, w->n * sizeof(sph_real)); /* the one that acted */
    sph__time(w, SPH_STAGE_PRESSURE, &t0);
    sph__record_nonpressure(w);
    /* the motion uses the last pressure; with continuity the density follows the new velocity */
    SPH__OMP_FOR(nD)
    for (i = 0; i < (sph__idx)nD; ++i) {
        const sph_real vn = w->v[i], v1 = vn + dt * (w->a[i] + w->priv.ap[i]);
        w->priv.vp[i] = verlet ? SPH__R(0.5) * (vn + v1) : v1;
        w->v[i] = v1;
        w->a[i] += w->priv.ap[i]; /* total acceleration, for the diagnostics */
    }
    if (!summation) {
        sph__ctx cr = c;
        cr.v = w->priv.vp;
        sph__stage_interact(w, &cr, SPH__RATE | SPH__CACHED, NULL);
        SPH__OMP_FOR(w->n)
        for (i = 0; i < (sph__idx)w->n; ++i) w->rho[i] = sph__rho_floor(&c, (size_t)i, w->priv.rho_n[i] + dt * w->drho[i]);
    }
    w->stats.iterations = it;
    w->stats.solver_error = err;
    ++w->steps;
    w->time += (double)dt;
    s = sph__integrate(w, &c, 0, 0, drift, 1);
    sph__time(w, SPH_STAGE_INTEGRATE, &t0);
    w->stats.step_time = sph__now() - tstart;
    if (s == SPH_OK && (err > (double)w->def.tolerance ||
                        (w->def.tolerance_max > 0 && errmax > (double)w->def.tolerance_max)))
        s = sph__not_converged(w, "PCISPH", it, err, errmax);
    return s;
}

SPHDEF sph_status sph_step_pcisph(sph_world* w, sph_real dt) {
    const double dt_prev = w ? w->stats.dt : 0; /* the last step's, before sph__step_begin sets it */
    sph_status s = sph__step_begin(w, dt, SPH_SOLVER_PCISPH);
    if (s != SPH_OK) return s;
    return sph__step_end(w, sph__step_pcisph(w, dt, dt_prev));
}

/* ============================================================================================== */
/* >>iisph (implementation)                                                                       */
/* ============================================================================================== */
/* Implicit incompressible SPH, Ihmsen et al. 2014 in the form of Koschier et al. 2020 and Meiers
   2025 (Alg. 1-2), with the thesis' errata and the reference code's bugs fixed:
     rho_i   summation density at x^n (walls as psi = rho0_i V_b; all density sums below are
             divided by the kernel's lattice sum S, as the summation density is);
     v*      = v^n + dt a_np, a_np = gravity + user forces + viscosity;
     rho*_i  = rho_i + dt sum_j m_j (v*_i - v*_j).grad W_ij + dt sum_b psi_ib (v*_i - v_b).grad W_ib
               (the wall's velocity enters: a moving wall compresses; the reference code left it out)
     solve   (A p)_i = s_i = rho0_i - rho*_i with
             (A p)_i = dt^2 [sum_j m_j (a^p_i - a^p_j).grad W_ij + sum_b psi_ib a^p_i.grad W_ib],
             a^p the pressure acceleration of the boundary scheme, by relaxed Jacobi
             p_i <- max(0, p_i + omega (s_i - (A p)_i) / a_ii)  (negative pressure clamped),
             starting from warm_start * p of the last step;
     stop    when the mean predicted compression max(0, ((A p)_i - s_i)/rho0_i) <= tolerance,
             after min_iterations and at most max_iterations;
     move    v = v* + dt a^p(p_final), x += dt v: the last update is applied (the thesis'
             algorithm moves with the pressure before the last update).
   The diagonal is exact for the operator above (Meiers 2025 eq. 22 and 26, made exact
   and generalised to unequal masses):
     a_ii = dt^2 [ -(sum_j m_j gW_ij + sum_b psi_ib (1 + k_b rho_i^2/rho_b^2) gW_ib)
                    . (sum_j m_j gW_ij + sum_b psi_ib gW_ib) / rho_i^2 - m_i/rho_i^2 sum_j m_j |gW_ij|^2 ]
   with k_b = d p_b / d p_i: 0 for zero pressure, 1 for mirroring, W_bi / sum_f W_bf for
   extrapolation. a_ii < 0; a particle without neighbours has a_ii = 0 and gets p = 0. */

/* The walls' fixed part of the pressure solves' passes (IISPH, DFSPH), per fluid particle i:
   out[i (D + 1) + k] = sum_b psi_ib grad_k W_ib and out[i (D + 1) + D] = sum_b psi_ib v_b .
   grad W_ib, psi_ib = rho0_i V_b, from the grad W factors of the density summation. Within a
   solve the positions and wall velocities do not change, so a pass with zero wall pressure
   adds -(p_i/rho_i^2) times the first sum (Akinci et al. 2012's wall term) and the density
   rate v_i . (first) - (second), where it would run over the wall neighbours in every
   iteration. Reading the sums changes the order of the additions, not the terms. */
SPH__INLINE void sph__wall_grad_sum(const sph__ctx* c, size_t i, const int D, sph_real* out) {
    const sph_real* xi = c->x + i * (size_t)D;
    const sph_real rho0 = c->pc[c->ph[i]].rho0;
    sph_real G[3] = {0, 0, 0}, gv = 0;
    size_t kk, k0 = c->fb->begin[i], k1 = k0 + c->fb->count[i];
    int k;
    for (kk = k0; kk < k1; ++kk) {
        const size_t b = c->fb->idx[kk];
        const sph_real* vb = c->bv + b * (size_t)D;
        const sph_real f = c->fb_fw[kk] * rho0 * c->bvol[b];
        sph_real d[3] = {0, 0, 0}, vd = 0;
        sph__delta_vec(c, xi, c->bx + b * (size_t)D, d, D);
        SPH__FOR_K(D, G[k] += f * d[k]; vd += vb[k] * d[k]);
        gv += f * vd;
    }
    SPH__FOR_K(D, out[i * (size_t)(D + 1) + (size_t)k] = G[k]);
    out[i * (size_t)(D + 1) + (size_t)D] = gv;
}

/* Diagonal and source term of fluid particle i (one neighbour pass). */
SPH__INLINE void sph__iisph_prepare_one(const sph_world* w, const sph__ctx* c, size_t i, const int D,
                                        sph_real dt, const int fast) {
    const sph_real* const cm = fast ? NULL : c->m; /* fast: as sph__visc_norm_one's */
    const int per = fast ? 0 : c->periodic_any;
    const sph_real* xi = c->x + i * (size_t)D;
    const sph_real* vi = c->v + i * (size_t)D;
    const sph__phase_c* P = &c->pc[c->ph[i]];
    const sph_real rhoi = c->rho[i], mi = c->m ? c->m[i] : c->m0, inv_r2 = 1 / (rhoi * rhoi);
    sph_real A[3] = {0, 0, 0}, dv[3] = {0, 0, 0}, Q = 0, R = 0, dot = 0;
    size_t kk, k0 = c->ff->begin[i], k1 = k0 + c->ff->count[i];
    int k;
    for (kk = k0; kk < k1; ++kk) {
        const size_t j = c->ff->idx[kk];
        const sph_real mj = cm ? cm[j] : c->m0;
        sph_real d[3] = {0, 0, 0}, r2 = 0, vd = 0, fw;
        sph__delta_vec_p(c, per, xi, c->x + j * (size_t)D, d, D);
        SPH__FOR_K(D, r2 += d[k] * d[k]; vd += (vi[k] - c->v[j * (size_t)D + (size_t)k]) * d[k]);
        fw = c->ff_fw[kk]; /* from the density summation; reused by every iteration */
        SPH__FOR_K(D, A[k] += mj * fw * d[k]; dv[k] += mj * fw * d[k]);
        Q += mj * fw * fw * r2;
        R += mj * fw * vd;
    }
    if (c->has_b) {
        k0 = c->fb->begin[i];
        k1 = k0 + c->fb->count[i];
        for (kk = k0; kk < k1; ++kk) {
            const size_t b = c->fb->idx[kk];
            const sph_real psi = P->rho0 * c->bvol[b];
            sph_real d[3] = {0, 0, 0}, vd = 0, fw = c->fb_fw[kk], kb = 0; /* the summation's */
            sph__delta_vec(c, xi, c->bx + b * (size_t)D, d, D);
            SPH__FOR_K(D, vd += (vi[k] - c->bv[b * (size_t)D + (size_t)k]) * d[k]);
            if (c->bp_mode == SPH_BP_MIRROR) kb = 1;
            else if (c->bp_mode == SPH_BP_EXTRAPOLATE && w->priv.b_sw[b] > 0) {
                const sph_real rb = P->rho0 * c->brho[b];
                sph_real r2 = 0;
                SPH__FOR_K(D, r2 += d[k] * d[k]);
                kb = sph__kw(c->k.form, sph__sqrt(r2) * c->k.inv_h) / w->priv.b_sw[b] * rhoi *
                     rhoi / (rb * rb);
            }
            SPH__FOR_K(D, A[k] += psi * fw * d[k]; dv[k] += psi * (1 + kb) * fw * d[k]);
            R += psi * fw * vd;
        }
        if (w->priv.wg) sph__wall_grad_sum(c, i, D, w->priv.wg);
    }
    for (k = 0; k < D; ++k) dot += dv[k] * A[k];
    /* density sums are normalised by the lattice sum S (sph__stage_density_summation), so are
       their rates of change */
    w->priv.aii[i] = dt * dt * (-dot * inv_r2 - mi * inv_r2 * Q) / w->priv.lattice_sum;
    w->priv.src[i] = P->rho0 - (rhoi + dt * R / w->priv.lattice_sum) +
                     sph__standing_keep(w) * (rhoi > P->rho0 ? rhoi - P->rho0 : 0);
}

/* (A p)_i [kg/m^3] from the pressure accelerations a^p in w->priv.ap (Ihmsen et al. 2014 eq. 14:
   the density change the pressure's displacements dt^2 a^p cause). */
SPH__INLINE sph_real sph__iisph_Ap_one(const sph_world* w, const sph__ctx* c, size_t i, const int D,
                                       sph_real dt, const int fast) {
    const sph_real* xi = c->x + i * (size_t)D;
    const sph_real* api = w->priv.ap + i * (size_t)D;
    const sph_real* const cm = fast ? NULL : c->m; /* fast: as sph__visc_norm_one's */
    const int per = fast ? 0 : c->periodic_any;
    sph_real Ap = 0;
    size_t kk, k0 = c->ff->begin[i], k1 = k0 + c->ff->count[i];
    int k;
    for (kk = k0; kk < k1; ++kk) {
        const size_t j = c->ff->idx[kk];
        const sph_real* apj = w->priv.ap + j * (size_t)D;
        const sph_real mj = cm ? cm[j] : c->m0;
        sph_real d[3] = {0, 0, 0}, dd = 0;
        sph__delta_vec_p(c, per, xi, c->x + j * (size_t)D, d, D);
        SPH__FOR_K(D, dd += (api[k] - apj[k]) * d[k]);
        Ap += mj * w->priv.ff_fw[kk] * dd;
    }
    if (c->has_b) { /* positions are fixed within the solve: the walls' sum is taken once */
        const sph_real* sb = w->priv.wg + i * (size_t)(D + 1);
        for (k = 0; k < D; ++k) Ap += api[k] * sb[k];
    }
    return Ap * (dt * dt / w->priv.lattice_sum);
}

/* The Jacobi update of p_i (in place: A p reads only accelerations) and the predicted
   compression before the update. */
SPH__INLINE double sph__iisph_update_one(sph_world* w, const sph__ctx* c, size_t i, const int D,
                                         sph_real dt, sph_real omega, const int fast) {
    const sph_real Ap = sph__iisph_Ap_one(w, c, i, D, dt, fast), aii = w->priv.aii[i];
    const sph_real err = (Ap - w->priv.src[i]) * c->pc[c->ph[i]].inv_rho0;
    const sph_real p = aii < 0 ? w->p[i] + omega * (w->priv.src[i] - Ap) / aii : 0;
    w->p[i] = p > 0 ? p : 0;
    return err > 0 ? (double)err : 0.0;
}

/* One Jacobi sweep over all particles; returns the mean predicted compression and, in *emax, the
   largest (fixed-order block sums, so the iteration count does not depend on the thread
   count). */
static double sph__iisph_sweep(sph_world* w, const sph__ctx* c, sph_real dt, double* emax) {
    const size_t nblk = (w->n + SPH__BLOCK - 1) / SPH__BLOCK;
    const sph_real omega = (sph_real)w->stats.omega;
    const int fast = !c->m && !c->periodic_any;
    double sum = 0;
    sph__idx blk;
    size_t q;
    SPH__OMP_FOR(w->n) /* over blocks of SPH__BLOCK particles */
    for (blk = 0; blk < (sph__idx)nblk; ++blk) {
        const size_t i0 = (size_t)blk * SPH__BLOCK;
        const size_t i1 = i0 + SPH__BLOCK < w->n ? i0 + SPH__BLOCK : w->n;
        double e = 0, m = 0, ei;
        size_t i;
        for (i = i0; i < i1; ++i) {
            ei = c->dim == 2   ? (fast ? sph__iisph_update_one(w, c, i, 2, dt, omega, 1)
                                       : sph__iisph_update_one(w, c, i, 2, dt, omega, 0))
                 : c->dim == 3 ? (fast ? sph__iisph_update_one(w, c, i, 3, dt, omega, 1)
                                       : sph__iisph_update_one(w, c, i, 3, dt, omega, 0))
                               : sph__iisph_update_one(w, c, i, 1, dt, omega, 0);
            e += ei;
            if (ei > m) m = ei;
        }
        w->priv.block[2 * (size_t)blk] = e;
        w->priv.block[2 * (size_t)blk + 1] = m;
    }
    *emax = 0;
    for (q = 0; q < nblk; ++q) {
        sum += w->priv.block[2 * q];
        if (w->priv.block[2 * q + 1] > *emax) *emax = w->priv.block[2 * q + 1];
    }
    return w->n ? sum / (double)w->n : 0;
}

/* a^p from the current pressures: wall pressures (extrapolation), p / rho^2, one cached pass. */
static void sph__iisph_pressure_acceleration(sph_world* w, const sph__ctx* c) {
    sph__idx i;
    if (w->nb > 0) sph__stage_wall(w, c, SPH__WALL_PRESSURE);
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)w->n; ++i) w->priv.pr2[i] = w->p[i] / (w->rho[i] * w->rho[i]);
    sph__stage_interact(w, c, SPH__PRESSURE | SPH__SET | SPH__CACHED, w->priv.ap);
}

/* IISPH's pressure system by preconditioned conjugate gradients (def.pressure_solve =
   SPH_PSOLVE_CG). Why: relaxed Jacobi removes the rough part of a pressure error within a few
   sweeps and its smooth part only over hundreds, while the stopping rule (the mean predicted
   compression) hardly sees a smooth error: in one step, a pressure field short of hydrostatic
   lets gravity compress only the layer on the floor, and the mean over all layers dilutes that.
   A solve then ends after min_iterations with that error left in, and the following steps see
   it as motion (README, "Choosing a solver": a 2D tank at rest kept moving at 0.03-0.04
   sqrt(g H)). Conjugate gradients reduce the error at both ends of the spectrum first.
   Why it applies: with zero wall pressure the pressure acceleration is the constraint force of
   the density constraints, a^p_i = -1/m_i sum_k mu_k grad_i rho_k with mu_k = m_k p_k/rho_k^2
   (the symmetric SPH gradient; Bender & Koschier 2017 sec. 3; Koschier et al. 2019 sec. 4),
   so the density change it causes is A p = -dt^2 J M^-1 J^T D p with J_ki = grad_i rho_k and
   D = diag(m_k/rho_k^2): B = -A is self-adjoint and positive in the inner product
   <x, y>_D = sum_k x_k y_k m_k/rho_k^2, and the Jacobi preconditioner diag(-a_ii) is too (it
   is diagonal). Mirrored or extrapolated wall pressures add a term that is no constraint force
   (BOUNDARIES) and break the symmetry: those schemes keep Jacobi.
   The clamp p >= 0 (a free surface pulls nothing) is kept by an active set: CG runs on the
   particles whose pressure is positive or whose predicted density is above rho0 (the rest stay
   at p = 0); pressures that come out negative are set to 0 and leave the set, particles left
   compressed outside it join, and CG restarts (at most 16 times). A Jacobi sweep comes first (in
   sph__iisph_cg). The stopping rule is Jacobi's, def.min_iterations and max_iterations count
   products with A (the sweep is one); every reduction is a fixed-order block sum, so the result
   does not depend on the thread count. Scratch: residual r = A p - s of every particle, direction
   d, B d, active mask. */
static void sph__iisph_cg_product(sph_world* w, const sph__ctx* c, sph_real dt, const sph_real* x,
                                  sph_real* out) {
    sph__ctx cx = *c;
    sph__idx i;
    cx.p = x;
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)w->n; ++i) w->priv.pr2[i] = x[i] / (w->rho[i] * w->rho[i]);
    sph__stage_interact(w, &cx, SPH__PRESSURE | SPH__SET | SPH__CACHED, w->priv.ap);
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)w->n; ++i)
        out[i] = c->dim == 2   ? sph__iisph_Ap_one(w, c, (size_t)i, 2, dt, 0)
                 : c->dim == 3 ? sph__iisph_Ap_one(w, c, (size_t)i, 3, dt, 0)
                               : sph__iisph_Ap_one(w, c, (size_t)i, 1, dt, 0);
}

/* Fixed-order block sums: returns <a, b>_D over the active set (b = NULL: the preconditioned
   a / (-a_ii) as b); with err != NULL (a = the residual A p - s) also the mean and, in *emax,
   the largest predicted compression max(a_i, 0)/rho0 over all particles, and in err[1] the
   mean |a_i|/rho0 over the set (over all n). */
static double sph__iisph_cg_dot(sph_world* w, const sph__ctx* c, const sph_real* a,
                                const sph_real* b, const sph_real* mask, double* err,
                                double* emax) {
    const size_t nblk = (w->n + SPH__BLOCK - 1) / SPH__BLOCK;
    double dot = 0, sum = 0, set = 0;
    sph__idx blk;
    size_t q;
    SPH__OMP_FOR(w->n)
    for (blk = 0; blk < (sph__idx)nblk; ++blk) {
        const size_t i0 = (size_t)blk * SPH__BLOCK;
        const size_t i1 = i0 + SPH__BLOCK < w->n ? i0 + SPH__BLOCK : w->n;
        double e0 = 0, e1 = 0, e2 = 0, e3 = 0;
        size_t i;
        for (i = i0; i < i1; ++i) {
            const double ei = err ? (double)a[i] * (double)c->pc[c->ph[i]].inv_rho0 : 0;
            if (mask[i] != 0) {
                const double rhoi = (double)w->rho[i];
                const double wi = (double)(c->m ? c->m[i] : c->m0) / (rhoi * rhoi);
                const double bi = b ? (double)b[i] : (double)a[i] / -(double)w->priv.aii[i];
                e0 += wi * (double)a[i] * bi;
                e3 += fabs(ei);
            }
            if (ei > 0) {
                e1 += ei;
                if (ei > e2) e2 = ei;
            }
        }
        w->priv.block[4 * (size_t)blk] = e0;
        w->priv.block[4 * (size_t)blk + 1] = e1;
        w->priv.block[4 * (size_t)blk + 2] = e2;
        w->priv.block[4 * (size_t)blk + 3] = e3;
    }
    if (emax) *emax = 0;
    for (q = 0; q < nblk; ++q) {
        dot += w->priv.block[4 * q];
        sum += w->priv.block[4 * q + 1];
        if (emax && w->priv.block[4 * q + 2] > *emax) *emax = w->priv.block[4 * q + 2];
        set += w->priv.block[4 * q + 3];
    }
    if (err) {
        err[0] = w->n ? sum / (double)w->n : 0;
        err[1] = w->n ? set / (double)w->n : 0;
    }
    return dot;
}

/* Solves A p = s from the warm-started w->p; *iters counts the products with A. */
static sph_status sph__iisph_cg(sph_world* w, const sph__ctx* c, sph_real dt, int* iters,
                                double* err, double* emax) {
    const size_t n = w->n, nblk = (n + SPH__BLOCK - 1) / SPH__BLOCK;
    const sph_real* aii = w->priv.aii;
    sph_real *r, *d, *q, *mask;
    int restart, it = 0;
    sph_status s;
    sph__idx i;
    if ((s = sph__scratch(w, &w->priv.cg, 4 * w->capacity)) != SPH_OK) return s;
    if (4 * nblk > w->priv.block_cap) {
        if (!sph__grow((void**)&w->priv.block, 4 * nblk + 64, sizeof(double)))
            return sph__fail(w, SPH_ERR_NOMEM, -1, "out of memory (reduction blocks)");
        w->priv.block_cap = 4 * nblk + 64;
    }
    r = w->priv.cg;
    d = r + w->capacity;
    q = d + w->capacity;
    mask = q + w->capacity;
    /* one Jacobi sweep first: it sets the pressure of a particle the free surface leaves short
       of rho0 to 0, which fixes most of the set (without it, the warm-started surface layer of a
       dam break wanted negative pressures and CG on it stalled: 100 products at step 1) */
    sph__jacobi_begin(w);
    sph__iisph_pressure_acceleration(w, c);
    sph__iisph_sweep(w, c, dt, emax);
    ++it;
    for (restart = 0;; ++restart) {
        double rz, e[2];
        int clamped = 0;
        /* the residual r = A p - s = b - B p (b = -s, B = -A) of every particle; the set */
        sph__iisph_cg_product(w, c, dt, w->p, r);
        ++it;
        SPH__OMP_FOR(n)
        for (i = 0; i < (sph__idx)n; ++i) {
            r[i] -= w->priv.src[i];
            mask[i] = aii[i] < 0 && (w->p[i] > 0 || r[i] > 0) ? 1 : 0;
            d[i] = mask[i] != 0 ? r[i] / -aii[i] : 0; /* z = P^-1 r */
        }
        rz = sph__iisph_cg_dot(w, c, r, NULL, mask, e, emax);
        /* CG on the set, until the whole solve converges or the set's own residual is a tenth of
           the tolerance (then the set changes: restart) */
        while (!(it >= w->def.min_iterations && e[0] <= (double)w->def.tolerance &&
                 (w->def.tolerance_max <= 0 || *emax <= (double)w->def.tolerance_max)) &&
               e[1] > 0.1 * (double)w->def.tolerance && it < w->def.max_iterations && rz > 0) {
            double dq, alpha, beta, rz1;
            sph__iisph_cg_product(w, c, dt, d, q); /* A d; B d = -A d */
            ++it;
            SPH__OMP_FOR(n)
            for (i = 0; i < (sph__idx)n; ++i) q[i] = -q[i];
            dq = sph__iisph_cg_dot(w, c, d, q, mask, NULL, NULL);
            if (!(dq > 0)) break;
            alpha = rz / dq;
            SPH__OMP_FOR(n)
            for (i = 0; i < (sph__idx)n; ++i) { /* every particle's residual, the set's pressure */
                w->p[i] += (sph_real)alpha * d[i];
                r[i] -= (sph_real)alpha * q[i];
            }
            rz1 = sph__iisph_cg_dot(w, c, r, NULL, mask, e, emax);
            beta = rz1 / rz;
            rz = rz1;
            SPH__OMP_FOR(n)
            for (i = 0; i < (sph__idx)n; ++i)
                d[i] = mask[i] != 0 ? r[i] / -aii[i] + (sph_real)beta * d[i] : 0;
        }
        for (i = 0; i < (sph__idx)n; ++i)
            if (w->p[i] < 0) { w->p[i] = 0; clamped = 1; }
        *err = e[0];
        if (restart == 16 || it >= w->def.max_iterations ||
            (!clamped && it >= w->def.min_iterations && e[0] <= (double)w->def.tolerance &&
             (w->def.tolerance_max <= 0 || *emax <= (double)w->def.tolerance_max))) {
            if (clamped) { /* the error of the clamped pressure */
                sph__iisph_cg_product(w, c, dt, w->p, r);
                for (i = 0; i < (sph__idx)n; ++i) r[i] -= w->priv.src[i];
                sph__iisph_cg_dot(w, c, r, NULL, mask, e, emax);
                *err = e[0];
            }
            break;
        }
    }
    *iters = it;
    return SPH_OK;
}

static sph_status sph__step_iisph(sph_world* w, sph_real dt) {
    const size_t nblk = (w->n + SPH__BLOCK - 1) / SPH__BLOCK;
    double t0 = sph__now(), tstart = t0, err = 0, errmax = 0, err_min[2] = {0, 0};
    size_t worst = 0; /* the most compressed particle of a solve that ends beyond the bound */
    sph__ctx c;
    sph_status s;
    sph__idx i;
    int it = 0;
    if ((s = sph__shift_reserve(w)) != SPH_OK ||
        (s = sph__scratch(w, &w->priv.aii, w->capacity)) != SPH_OK ||
        (s = sph__scratch(w, &w->priv.src, w->capacity)) != SPH_OK ||
        (s = sph__scratch(w, &w->priv.ap, w->capacity * (size_t)w->dim)) != SPH_OK ||
        (w->nb > 0 &&
         (s = sph__scratch(w, &w->priv.wg, w->capacity * (size_t)(w->dim + 1))) != SPH_OK))
        return s;
    if (2 * nblk > w->priv.block_cap) {
        if (!sph__grow((void**)&w->priv.block, 2 * nblk + 64, sizeof(double)))
            return sph__fail(w, SPH_ERR_NOMEM, -1, "out of memory (reduction blocks)");
        w->priv.block_cap = 2 * nblk + 64;
    }
    s = sph__boundary_motion(w, w->time);
    if (s != SPH_OK) return s;
    sph__time(w, SPH_STAGE_BOUNDARY, &t0);
    s = sph__stage_neighbors(w);
    if (s != SPH_OK) return s;
    if ((s = sph__scratch(w, &w->priv.ff_fw, w->priv.ff.cap_idx)) != SPH_OK ||
        (s = sph__scratch(w, &w->priv.fb_fw, w->priv.fb.cap_idx)) != SPH_OK ||
        (s = sph__scratch(w, &w->priv.pr2, w->capacity)) != SPH_OK)
        return s;
    sph__ctx_init(w, &c);
    c.ff_fw = c.ff_fw_out = w->priv.ff_fw; /* filled by the density summation */
    c.fb_fw = c.fb_fw_out = w->priv.fb_fw;
    c.pr2 = w->priv.pr2;
    c.delta_on = 0;          /* the density is a summation, no diffusion */
    c.density = SPH_DENSITY_CONTINUITY;
    if (sph__enclosed(w, &c)) c.bp_mode = SPH_BP_ZERO; /* no pressure level: see sph__enclosed */
    sph__time(w, SPH_STAGE_NEIGHBORS, &t0);
    sph__stage_density_summation(w, &c);
    sph__time(w, SPH_STAGE_DENSITY, &t0);
    /* non-pressure accelerations and the predicted velocity v* (kept in w->v) */
    if ((s = sph__stage_body_force(w, &c)) != SPH_OK) return s;
    if (w->nb > 0) sph__stage_wall(w, &c, SPH__WALL_STATE);
    if (c.laminar || c.av) sph__stage_interact(w, &c, SPH__VISCOUS | SPH__CACHED, w->a);
    s = sph__integrate(w, &c, dt, 0, 0, 0);
    if (s != SPH_OK) return s;
    sph__time(w, SPH_STAGE_FORCES, &t0);
    /* diagonal, source, warm start */
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)w->n; ++i) {
        const int fast = !c.m && !c.periodic_any;
        if (c.dim == 2 && fast) sph__iisph_prepare_one(w, &c, (size_t)i, 2, dt, 1);
        else if (c.dim == 2) sph__iisph_prepare_one(w, &c, (size_t)i, 2, dt, 0);
        else if (c.dim == 3 && fast) sph__iisph_prepare_one(w, &c, (size_t)i, 3, dt, 1);
        else if (c.dim == 3) sph__iisph_prepare_one(w, &c, (size_t)i, 3, dt, 0);
        else sph__iisph_prepare_one(w, &c, (size_t)i, 1, dt, 0);
        w->p[i] = w->p[i] > 0 ? sph__warm(w) * w->p[i] : 0;
    }
    /* with zero wall pressure the walls' part of every pressure pass is p_i/rho_i^2 times the
       sum the diagonal's pass took */
    if (c.has_b) {
        c.wg = w->priv.wg;
        c.wg_pressure = c.bp_mode == SPH_BP_ZERO && !c.bpq && c.pgrad == SPH_PGRAD_SYMMETRIC;
    }
    if (w->def.pressure_solve == SPH_PSOLVE_CG && c.bp_mode == SPH_BP_ZERO) {
        if ((s = sph__iisph_cg(w, &c, dt, &it, &err, &errmax)) != SPH_OK) return s;
    } else {
        /* relaxed Jacobi on the pressure */
        sph__jacobi_begin(w);
        for (;;) {
            sph__iisph_pressure_acceleration(w, &c);
            err = sph__iisph_sweep(w, &c, dt, &errmax);
            ++it;
            sph__jacobi_guard2(w, it, err, errmax, err_min);
            if ((it >= w->def.min_iterations && err <= (double)w->def.tolerance &&
                 (w->def.tolerance_max <= 0 || errmax <= (double)w->def.tolerance_max)) ||
                it >= w->def.max_iterations)
                break;
        }
        sph__jacobi_end(w, err <= (double)w->def.tolerance);
    }
    /* the motion uses the final pressure */
    sph__iisph_pressure_acceleration(w, &c);
    /* a solve that ends with a particle predicted beyond max_compression: which one (the
       largest predicted compression under the final pressure; serial, only then) */
    if (w->def.max_compression > 0 && errmax > (double)w->def.max_compression) {
        size_t q;
        sph_real emax = -1;
        for (q = 0; q < w->n; ++q) {
            const sph_real e = (sph__iisph_Ap_one(w, &c, q, c.dim, dt, 0) - w->priv.src[q]) *
                               c.pc[c.ph[q]].inv_rho0;
            if (e > emax) { emax = e; worst = q; }
        }
    }
    sph__time(w, SPH_STAGE_PRESSURE, &t0);
    sph__record_nonpressure(w);
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)(w->n * (size_t)w->dim); ++i) {
        w->v[i] += dt * w->priv.ap[i];
        w->a[i] += w->priv.ap[i]; /* total acceleration, for the diagnostics */
    }
    w->stats.iterations = it;
    w->stats.solver_error = err;
    sph__stage_shift(w, &c, dt);
    ++w->steps;
    w->time += (double)dt;
    s = sph__integrate(w, &c, 0, 0, dt, 1);
    sph__time(w, SPH_STAGE_INTEGRATE, &t0);
    w->stats.step_time = sph__now() - tstart;
    /* the density check of sph__integrate reads rho at the step's start; a step whose solve
       ends with a particle predicted beyond max_compression fails now, not one step late (where
       no smaller step can undo it) */
    if (s == SPH_OK && w->def.max_compression > 0 && errmax > (double)w->def.max_compression)
        return sph__fail(w, SPH_ERR_UNSTABLE, (long)worst,
                         "step %llu (t = %g s): IISPH's solve ends with fluid particle %zu (id %u) "
                         "predicted at rho/rho0 = %g (max_compression %g) after %d iterations: "
                         "time step too large", (unsigned long long)w->steps, w->time, worst,
                         (unsigned)w->id[worst], 1 + errmax, (double)w->def.max_compression, it);
    if (s == SPH_OK && (err > (double)w->def.tolerance ||
                        (w->def.tolerance_max > 0 && errmax > (double)w->def.tolerance_max)))
        s = sph__not_converged(w, "IISPH", it, err, errmax);
    return s;
}

SPHDEF sph_status sph_step_iisph(sph_world* w, sph_real dt) {
    sph_status s = sph__step_begin(w, dt, SPH_SOLVER_IISPH);
    if (s != SPH_OK) return s;
    return sph__step_end(w, sph__step_iisph(w, dt));
}

/* ============================================================================================== */
/* >>dfsph (implementation)                                                                       */
/* ============================================================================================== */
/* Divergence-free SPH, Bender & Koschier 2015 (SCA) and 2017 (IEEE TVCG; equation and algorithm
   numbers below are the 2017 paper's). Two pressure solves per step, both Jacobi iterations on
   velocity level with the same per-particle factor; written in pressures, p_i = kappa_i rho_i,
   so the pressure acceleration is the symmetric form the other solvers use (the paper's
   -sum_j m_j (kappa_i/rho_i + kappa_j/rho_j) grad W_ij; def.pressure_grad is not read):
     a^p_i = -sum_j m_j (p_i/rho_i^2 + p_j/rho_j^2) grad W_ij - sum_b psi_ib (p_i/rho_i^2 + p_b/rho_b^2) grad W_ib.
   One step (Alg. 1, with the step boundary after "move" instead of after the divergence solve:
   the paper ends a step with neighbourhoods, densities and factors at the new positions and the
   divergence solve; we begin the next step with them, which is the same sequence, one neighbour
   search per step, and walls at the time of the new positions):
     rho_i   summation density at x^n, walls as psi_ib = rho0_i V_b, divided by the lattice sum S
             (sph__stage_density_summation; every density rate below is divided by S too);
     alpha_i = S rho_i / D_i (eq. 11 with walls), with
             D_i = (sum_j m_j gW_ij + sum_b psi_ib gW_ib) . (sum_j m_j gW_ij + sum_b psi_ib (1 + k_b) gW_ib)
                   + m_i sum_j m_j |gW_ij|^2,
             k_b = d(p_b/rho_b^2)/d(p_i/rho_i^2) of the boundary scheme (as in >>iisph); the paper's
             sum_j |m_j gW_ij|^2 is m_i sum_j m_j |gW_ij|^2 with unequal masses (the reaction of
             neighbour j to p_i). alpha_i = -dt^2 / (rho_i a_ii) with IISPH's diagonal. D_i below
             1e-6 (m_i |gW|_scale)^2 (a particle without neighbours) gives alpha_i = 0, no pressure.
     divergence-free solve (Alg. 3) on v^n: p^v_i = rho_i alpha_i K_i / dt with K_i >= 0 starting
             at warm_start times the last step's K_i (kept in w->drho between steps):
               v = v^n + dt a^p(p^v);  (D rho/Dt)_i = sum_j m_j v_ij . gW_ij + sum_b psi_ib (v_i - v_b) . gW_ib
               stop when mean max(D rho/Dt, 0) dt / rho0 <= divergence_tolerance (after
               min(1, min_iterations) updates, at most max_iterations), else
               K_i <- max(0, K_i + omega D rho_i/Dt)
             (the paper's kappa^v_i = alpha_i/dt D rho_i/Dt, relaxed); the wall's velocity enters,
             so a moving wall compresses;
     non-pressure accelerations a = g + user forces + viscosity; v* = v + dt a;
     constant-density solve (Alg. 2): p_i starting at warm_start times the last step's p_i:
               v = v* + dt a^p(p);  rho*_i = rho_i + dt (D rho/Dt)_i of v
               stop when mean max(rho*_i/rho0_i - 1, 0) <= tolerance (after min_iterations updates,
               at most max_iterations), else p_i <- max(0, p_i + omega rho_i alpha_i (rho*_i - rho0_i) / dt^2)
             (the paper's kappa_i = alpha_i (rho*_i - rho0)/dt^2, relaxed);
     move    x += dt v, with the v of the last evaluation (it has the error reported).
   Each evaluation takes a^p of the whole pressure, not of the last increment: Adami's wall
   pressure is affine in p (its body-force term), and the velocity then matches the pressure the
   step reports. The errors count compression only, the updates are two-sided and the pressures
   clamped at 0 (projected Jacobi, as >>iisph): a particle at a free surface, with a density
   deficit or an expanding neighbourhood, has its pressure driven to 0, never to tension.
   Measured on this library's lattices with Wendland C2 (tests/test_dfsph.c): the paper's
   unrelaxed update (omega = 1) diverges on the shortest waves (a 2D tank blows up in its first
   step), and one-sided increments (compression only, pressures never lowered within a step)
   ratchet: with a full warm start the pressures only grow, with half of it each step rebuilds
   half the hydrostatic pressure; so the update is relaxed by def.omega (0.5; 3D tanks with
   Wendland C2's 80 neighbours need 0.3)
   and warm started with def.warm_start (0.5), as IISPH's. Per iteration a solve costs one
   pressure pass and one cached continuity pass, as an IISPH iteration does.
   Boundary schemes: ZERO (p_b = 0, k_b = 0) is Akinci et al.'s boundary as Bender & Koschier use
   it: the wall pushes with the fluid particle's own kappa_i. MIRROR (p_b = p_i, rho_b = rho_i,
   k_b = 1) doubles that push; users cannot choose it (see BOUNDARIES), the divergence solve
   uses it internally (below). EXTRAPOLATE: the constant-density solve extrapolates Adami's p_b
   from the fluid's p (with the body force and the wall's acceleration, k_b = W_bi / sum_f W_bf
   rho_i^2 / rho_b^2); the divergence solve's p^v balances no weight, so its wall condition is
   dp^v/dn = 0, whose per-pair form is the mirror: EXTRAPOLATE runs the divergence solve as MIRROR
   (alpha_i of that solve with k_b = 1).
   Multiphase: masses (w->m) and rest densities per particle enter every sum (psi_ib = rho0_i V_b,
   errors relative to each particle's rho0_i); the summation density smears the mass jump over
   the kernel support, so, as with IISPH, only phases of similar density (ratios down to about
   0.5) rest correctly at an interface; large ratios need the compressible step. */

/* alpha_i of both solves and the grad W / x_ij factor of every listed pair (reused by every
   pass of the step). */
SPH__INLINE void sph__dfsph_factor_one(sph_world* w, const sph__ctx* c, size_t i, const int D) {
    const sph_real* xi = c->x + i * (size_t)D;
    const sph__phase_c* P = &c->pc[c->ph[i]];
    const sph_real rhoi = c->rho[i], mi = c->m ? c->m[i] : c->m0;
    const sph_real gs = mi * c->k.norm_g * c->k.h; /* scale of m |grad W| */
    sph_real A[3] = {0, 0, 0}, B[3] = {0, 0, 0}, Bm[3] = {0, 0, 0}, Q = 0, dd = 0, dm = 0;
    size_t kk, k0 = c->ff->begin[i], k1 = k0 + c->ff->count[i];
    int k;
    for (kk = k0; kk < k1; ++kk) {
        const size_t j = c->ff->idx[kk];
        const sph_real mj = c->m ? c->m[j] : c->m0;
        sph_real d[3] = {0, 0, 0}, r2 = 0, fw;
        sph__delta_vec(c, xi, c->x + j * (size_t)D, d, D);
        SPH__FOR_K(D, r2 += d[k] * d[k]);
        fw = c->ff_fw[kk]; /* from the density summation */
        SPH__FOR_K(D, A[k] += mj * fw * d[k]);
        Q += mj * fw * fw * r2;
    }
    for (k = 0; k < D; ++k) B[k] = Bm[k] = A[k];
    if (c->has_b) {
        k0 = c->fb->begin[i];
        k1 = k0 + c->fb->count[i];
        for (kk = k0; kk < k1; ++kk) {
            const size_t b = c->fb->idx[kk];
            const sph_real psi = P->rho0 * c->bvol[b];
            sph_real d[3] = {0, 0, 0}, fw = c->fb_fw[kk], kb = 0; /* the summation's */
            sph__delta_vec(c, xi, c->bx + b * (size_t)D, d, D);
            if (c->bp_mode == SPH_BP_MIRROR) kb = 1;
            else if (c->bp_mode == SPH_BP_EXTRAPOLATE && w->priv.b_sw[b] > 0) {
                const sph_real rb = P->rho0 * c->brho[b];
                sph_real r2 = 0;
                SPH__FOR_K(D, r2 += d[k] * d[k]);
                kb = sph__kw(c->k.form, sph__sqrt(r2) * c->k.inv_h) / w->priv.b_sw[b] * rhoi *
                     rhoi / (rb * rb);
            }
            SPH__FOR_K(D, A[k] += psi * fw * d[k]; B[k] += psi * (1 + kb) * fw * d[k];
                       Bm[k] += 2 * psi * fw * d[k]);
        }
        if (w->priv.wg) sph__wall_grad_sum(c, i, D, w->priv.wg);
    }
    for (k = 0; k < D; ++k) {
        dd += A[k] * B[k];
        dm += A[k] * Bm[k];
    }
    dd += mi * Q;
    dm += mi * Q;
    w->priv.df_alpha[i] = dd > SPH__R(1e-6) * gs * gs ? w->priv.lattice_sum * rhoi / dd : 0;
    if (c->bp_mode != SPH_BP_EXTRAPOLATE) w->priv.df_alpha_v[i] = w->priv.df_alpha[i];
    else w->priv.df_alpha_v[i] = dm > SPH__R(1e-6) * gs * gs ? w->priv.lattice_sum * rhoi / dm : 0;
}

static void sph__dfsph_factors(sph_world* w, const sph__ctx* c) {
    sph__idx i;
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)w->n; ++i) {
        if (c->dim == 2) sph__dfsph_factor_one(w, c, (size_t)i, 2);
        else if (c->dim == 3) sph__dfsph_factor_one(w, c, (size_t)i, 3);
        else sph__dfsph_factor_one(w, c, (size_t)i, 1);
    }
}

/* v = v0 + dt a^p(p) with the pressure of the context (w->p, or the divergence pressure);
   Adami's wall pressure first when the context's scheme extrapolates. */
static void sph__dfsph_velocity(sph_world* w, const sph__ctx* c, const sph_real* v0, sph_real dt) {
    const size_t nD = w->n * (size_t)w->dim;
    sph__idx i;
    if (w->nb > 0) sph__stage_wall(w, c, SPH__WALL_PRESSURE); /* no-op unless EXTRAPOLATE */
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)w->n; ++i) w->priv.pr2[i] = c->p[i] / (w->rho[i] * w->rho[i]);
    sph__stage_interact(w, c, SPH__PRESSURE | SPH__SET | SPH__CACHED, w->priv.ap);
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)nD; ++i) w->v[i] = v0[i] + dt * w->priv.ap[i];
}

/* The density rate of the current velocities (the cached continuity pass), then per particle the
   error the solve corrects, kept in w->drho: max(rho*_i - rho0_i, 0) for the constant-density
   solve, max(D rho_i/Dt, 0) for the divergence solve. Returns the mean relative error
   (compression, or compression per step) from fixed-order block sums, so the iteration count
   does not depend on the thread count. */
static double sph__dfsph_error(sph_world* w, const sph__ctx* c, sph_real dt, int density) {
    const size_t nblk = (w->n + SPH__BLOCK - 1) / SPH__BLOCK;
    const sph_real inv_s = 1 / w->priv.lattice_sum, keep = density ? sph__standing_keep(w) : 0;
    double sum = 0;
    sph__idx blk;
    size_t q;
    sph__stage_interact(w, c, SPH__RATE | SPH__CACHED, NULL);
    SPH__OMP_FOR(w->n) /* over blocks of SPH__BLOCK particles */
    for (blk = 0; blk < (sph__idx)nblk; ++blk) {
        const size_t i0 = (size_t)blk * SPH__BLOCK;
        const size_t i1 = i0 + SPH__BLOCK < w->n ? i0 + SPH__BLOCK : w->n;
        double e = 0;
        size_t i;
        for (i = i0; i < i1; ++i) {
            const sph__phase_c* P = &c->pc[c->ph[i]];
            sph_real r = w->drho[i] * inv_s;
            if (density) /* a shortened step leaves part of the standing compression */
                r = w->rho[i] + dt * r - P->rho0 - keep * (w->rho[i] > P->rho0 ? w->rho[i] - P->rho0 : 0);
            w->drho[i] = r; /* signed: expansion lowers the pressure (to 0 at most) */
            if (r > 0) e += (double)(density ? r * P->inv_rho0 : r * dt * P->inv_rho0);
        }
        w->priv.block[blk] = e;
    }
    for (q = 0; q < nblk; ++q) sum += w->priv.block[q];
    return w->n ? sum / (double)w->n : 0;
}

/* The stiffness update of the error in w->drho: p_i += rho_i alpha_i (rho*_i - rho0_i)/dt^2
   (constant density), or K_i += D rho_i/Dt and p^v_i = rho_i alpha_i K_i / dt (divergence). */
static void sph__dfsph_update(sph_world* w, sph_real dt, int density) {
    const sph_real omega = (sph_real)w->stats.omega;
    sph__idx i;
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)w->n; ++i) {
        if (density) {
            const sph_real p = w->p[i] + omega * w->rho[i] * w->priv.df_alpha[i] * w->drho[i] / (dt * dt);
            w->p[i] = p > 0 ? p : 0;
        } else {
            const sph_real K = w->priv.df_kv[i] + omega * w->drho[i];
            w->priv.df_kv[i] = K > 0 ? K : 0;
            w->priv.df_pv[i] = w->rho[i] * w->priv.df_alpha_v[i] * w->priv.df_kv[i] / dt;
        }
    }
}

/* Alg. 2 (density) or Alg. 3: evaluate the velocity and error of the current pressure, update
   until the error is at most tol after min_it updates, or max_iterations updates were made.
   Returns the updates; *err is the error of the final velocity, which the step keeps. */
static int sph__dfsph_solve(sph_world* w, const sph__ctx* c, const sph_real* v0, sph_real dt,
                            int density, int min_it, double tol, double* err) {
    int it = 0;
    double err_min = 0;
    sph__jacobi_begin(w);
    sph__dfsph_velocity(w, c, v0, dt);
    *err = sph__dfsph_error(w, c, dt, density);
    while (!(it >= min_it && *err <= tol) && it < w->def.max_iterations) {
        sph__dfsph_update(w, dt, density);
        ++it;
        sph__dfsph_velocity(w, c, v0, dt);
        *err = sph__dfsph_error(w, c, dt, density);
        sph__jacobi_guard(w, it, *err, &err_min);
    }
    sph__jacobi_end(w, *err <= tol);
    return it;
}

static sph_status sph__step_dfsph(sph_world* w, sph_real dt) {
    const size_t nD = w->n * (size_t)w->dim;
    const double tol = (double)w->def.tolerance, tolv = (double)w->def.divergence_tolerance;
    const int min_v = w->def.min_iterations < 1 ? w->def.min_iterations : 1;
    double t0 = sph__now(), tstart = t0, err = 0, errv = 0;
    sph__ctx c, cv;
    sph_status s;
    sph__idx i;
    int it, itv;
    if ((s = sph__shift_reserve(w)) != SPH_OK ||
        (s = sph__scratch(w, &w->priv.ap, w->capacity * (size_t)w->dim)) != SPH_OK ||
        (s = sph__scratch(w, &w->priv.df_vs, w->capacity * (size_t)w->dim)) != SPH_OK ||
        (s = sph__scratch(w, &w->priv.df_alpha, w->capacity)) != SPH_OK ||
        (s = sph__scratch(w, &w->priv.df_alpha_v, w->capacity)) != SPH_OK ||
        (s = sph__scratch(w, &w->priv.df_kv, w->capacity)) != SPH_OK ||
        (s = sph__scratch(w, &w->priv.df_pv, w->capacity)) != SPH_OK ||
        (s = sph__scratch(w, &w->priv.pr2, w->capacity)) != SPH_OK ||
        (w->nb > 0 &&
         (s = sph__scratch(w, &w->priv.wg, w->capacity * (size_t)(w->dim + 1))) != SPH_OK))
        return s;
    s = sph__boundary_motion(w, w->time);
    if (s != SPH_OK) return s;
    sph__time(w, SPH_STAGE_BOUNDARY, &t0);
    s = sph__stage_neighbors(w);
    if (s != SPH_OK) return s;
    if ((s = sph__scratch(w, &w->priv.ff_fw, w->priv.ff.cap_idx)) != SPH_OK ||
        (s = sph__scratch(w, &w->priv.fb_fw, w->priv.fb.cap_idx)) != SPH_OK)
        return s;
    sph__ctx_init(w, &c);
    c.ff_fw = c.ff_fw_out = w->priv.ff_fw; /* filled by the density summation */
    c.fb_fw = c.fb_fw_out = w->priv.fb_fw;
    c.pr2 = w->priv.pr2;
    c.delta_on = 0; /* the density is a summation: its rate is plain continuity */
    c.density = SPH_DENSITY_CONTINUITY;
    c.pgrad = SPH_PGRAD_SYMMETRIC; /* p = kappa rho: the paper's pressure acceleration */
    if (sph__enclosed(w, &c)) c.bp_mode = SPH_BP_ZERO; /* both solves: see sph__enclosed */
    cv = c;                        /* the divergence solve: its own pressure, walls as above */
    cv.p = w->priv.df_pv;
    if (cv.bp_mode == SPH_BP_EXTRAPOLATE) cv.bp_mode = SPH_BP_MIRROR;
    sph__time(w, SPH_STAGE_NEIGHBORS, &t0);
    /* densities and factors at x^n (Alg. 1) */
    sph__stage_density_summation(w, &c);
    if (w->nb > 0) sph__stage_wall(w, &c, SPH__WALL_STATE);
    sph__dfsph_factors(w, &c);
    if (c.has_b) { /* the walls' part of the solves' passes (sph__wall_grad_sum) */
        c.wg = cv.wg = w->priv.wg;
        c.wg_pressure = c.bp_mode == SPH_BP_ZERO && !c.bpq;
        cv.wg_pressure = cv.bp_mode == SPH_BP_ZERO && !cv.bpq;
    }
    sph__time(w, SPH_STAGE_DENSITY, &t0);
    /* divergence-free solve on v^n (Alg. 3), warm started from the rate kept in w->drho */
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)w->n; ++i) {
        const sph_real k0 = w->drho[i] > 0 ? sph__warm(w) * w->drho[i] : 0;
        w->priv.df_kv[i] = k0;
        w->priv.df_pv[i] = w->rho[i] * w->priv.df_alpha_v[i] * k0 / dt;
    }
    sph__copy(w->priv.df_vs, w->v, nD * sizeof(sph_real));
    itv = sph__dfsph_solve(w, &cv, w->priv.df_vs, dt, 0, min_v, tolv, &errv);
    sph__time(w, SPH_STAGE_PRESSURE, &t0);
    /* non-pressure accelerations and v* = v + dt a (Alg. 1) */
    sph__stage_body_force(w, &c);
    if (w->nb > 0 && c.noslip && (c.laminar || c.av))
        sph__stage_wall(w, &c, SPH__WALL_STATE); /* the wall velocity of the corrected v */
    if (c.laminar || c.av) sph__stage_interact(w, &c, SPH__VISCOUS | SPH__CACHED, w->a);
    s = sph__integrate(w, &c, dt, 0, 0, 0);
    if (s != SPH_OK) return s;
    sph__copy(w->priv.df_vs, w->v, nD * sizeof(sph_real));
    sph__time(w, SPH_STAGE_FORCES, &t0);
    /* constant-density solve on rho* (Alg. 2), warm started from the last pressure */
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)w->n; ++i) w->p[i] = w->p[i] > 0 ? sph__warm(w) * w->p[i] : 0;
    it = sph__dfsph_solve(w, &c, w->priv.df_vs, dt, 1, w->def.min_iterations, tol, &err);
    /* a particle still predicted beyond max_compression fails this step, not the next one
       (the density check of sph__integrate reads rho at the step's start); serial */
    if (w->def.max_compression > 0) {
        size_t q, worst = 0;
        sph_real cmax = 0;
        for (q = 0; q < w->n; ++q) {
            const sph_real r = w->drho[q] * c.pc[c.ph[q]].inv_rho0;
            if (r > cmax) { cmax = r; worst = q; }
        }
        if (cmax > w->def.max_compression)
            return sph__fail(w, SPH_ERR_UNSTABLE, (long)worst,
                             "step %llu (t = %g s): DFSPH's constant-density solve ends with "
                             "fluid particle %zu (id %u) predicted at rho/rho0 = %g "
                             "(max_compression %g) after %d iterations: time step too large",
                             (unsigned long long)w->steps + 1, w->time + (double)dt, worst,
                             (unsigned)w->id[worst], 1 + (double)cmax,
                             (double)w->def.max_compression, it);
    }
    sph__record_nonpressure(w);
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)nD; ++i) w->a[i] += w->priv.ap[i]; /* for the diagnostics */
    sph__copy(w->drho, w->priv.df_kv, w->n * sizeof(sph_real)); /* the next warm start */
    sph__time(w, SPH_STAGE_PRESSURE, &t0);
    /* move: x += dt v, diagnostics and blow-up checks */
    w->stats.iterations = it + itv;
    w->stats.iterations_divergence = itv;
    w->stats.solver_error = err;
    w->stats.divergence_error = errv;
    sph__stage_shift(w, &c, dt);
    ++w->steps;
    w->time += (double)dt;
    s = sph__integrate(w, &c, 0, 0, dt, 1);
    sph__time(w, SPH_STAGE_INTEGRATE, &t0);
    w->stats.step_time = sph__now() - tstart;
    if (s != SPH_OK) return s;
    if (err > tol || errv > tolv)
        return sph__fail(w, SPH_ERR_NOT_CONVERGED, -1,
                         "step %llu (t = %g s): DFSPH %s solve not converged after %d iterations "
                         "(max_iterations): mean error %g above its tolerance %g%s",
                         (unsigned long long)w->steps, w->time,
                         err > tol ? "constant-density" : "divergence-free", err > tol ? it : itv,
                         err > tol ? err : errv, err > tol ? tol : tolv,
                         err > tol && errv > tolv ? " (the divergence-free solve neither)" : "");
    return SPH_OK;
}

SPHDEF sph_status sph_step_dfsph(sph_world* w, sph_real dt) {
    sph_status s = sph__step_begin(w, dt, SPH_SOLVER_DFSPH);
    if (s != SPH_OK) return s;
    return sph__step_end(w, sph__step_dfsph(w, dt));
}

/* ============================================================================================== */
/* >>pbf (implementation)                                                                         */
/* ============================================================================================== */
/* Position Based Fluids, Macklin & Mueller 2013 (ACM TOG 32(4)); equation numbers are the
   paper's. One step (its Algorithm 1):
     predict   v* = v^n + dt a_ext (gravity, def.force), x* = x^n + dt v*;
     search    neighbour lists at x* (the particles sorted by cell), kept for the whole step;
     project   def.pbf_iterations times, Jacobi (each particle gathers from the positions of the
               last projection and writes only its own):
                 rho_i = (m_i W(0) + sum_j m_j W_ij + sum_b psi_b W_ib) / S, psi_b = rho0_i V_b
                         (Akinci et al. 2012 walls; S the lattice sum, as in >>iisph, >>dfsph)
                 C_i   = max(rho_i / rho0_i - 1, 0)                                      eq. 1
                 lambda_i = -C_i / (sum_k (1/m_k) |grad_k C_i|^2 + eps / m_i)         eqs. 9-11
                 dx_i  = (1/m_i) sum_k lambda_k grad_i C_k                          eqs. 12, 14
               (unequal masses weighed by 1/m as position based dynamics does; with equal masses
               this is the paper's form). With a_i = lambda_i / (m_i rho0_i):
                 a_i   = -C_i rho0_i S^2 / (|G_i|^2 + m_i Q_i + eps_r m_i^2 Q_lat),
                         G_i = sum_j m_j gW_ij + sum_b psi_b gW_ib,  Q_i = sum_j m_j |gW_ij|^2,
                 dx_i  = (1/S) [sum_j m_j (a_i + a_j + s_ij) gW_ij + a_i sum_b psi_b gW_ib],
               gW_ij = grad_i W(x_i - x_j), Q_lat = sum_j |gW|^2 over a full lattice and eps_r
               = def.pbf_relaxation: the paper's eps [1/m^2] is eps_r Q_lat (m / rho0)^2 / S^2,
               eps_r times what a lattice particle's own constraint contributes, so eps_r = 1
               moves it half the way its own constraint asks: Jacobi sums the corrections of all
               neighbours' constraints and overshoots without it (measured in the 20 m tank of
               examples/realtime.c, --scale 12.5, at the same compression target: eps_r = 0.25
               failed the compression check at t = 0.21 s; 0.5 ran at 2-2.7 % mean compression against
               1.4-1.8 % at 1, at the 1.15 times longer step the rule then gives). The walls do
               not move and
               carry no multiplier: the constraint's own wall term (zero wall pressure; >>iisph
               derives why). Every pair term is antisymmetric (m_i dx_i + m_j dx_j = 0 per pair),
               so without walls momentum is conserved to round-off;
     velocity  v = (x_proj - x^n) / dt, then XSPH (eq. 17) and laminar viscosity at x_proj, both
               from the velocities before them (Jacobi):
                 v_i += c sum_j 2 m_j / (rho0_i + rho0_j) (v_j - v_i) W_ij
                        + dt sum_j m_j (mu_i + mu_j) / (rho0_i rho0_j) (x_ij . gW_ij) / (r^2 + eta^2) v_ij
               (eq. 17 with the volumes m_j / rho0 that make it dimensionless, c = def.pbf_xsph;
               Morris et al. 1997 with rho0 for rho, as the projection holds the density, without
               the library's lattice normalisation; both pairwise symmetric, both only take
               kinetic energy);
     move      x^{n+1} = x^n + dt v by the shared integrator, which applies the wall contact and
               every blow-up check (sph__integrate).
   Free surface: C_i is clamped at 0, the library's convention for its incompressible solvers (no
   tension: a particle short of neighbours at a surface or in a splash is not pulled in). The
   paper keeps C bilateral and needs s_corr against the clumping its negative pressures cause;
   clamped, nothing clumps, and s_corr only repels pairs closer than the lattice (so it is off by
   default; at the paper's k = 0.1 a 1 m tank at rest, dx = 0.04 m, lifted its highest particles
   from 0.76 m to 0.83 m within 1 s at its 3.3 ms steps and kept 3.1 J of kinetic energy against
   0.9 J without; at 1.3 ms steps they reached 0.92 m: s_corr is a fixed displacement per
   projection, a force that grows like 1 / dt^2):
                 s_ij = -k (W_ij / W(dq))^n S^2 (rho0_i + rho0_j) / (2 m_i m_j Q_lat)      eq. 13
   with k = def.pbf_scorr (default 0), n = 4, |dq| = 0.2 support radii (the paper: k = 0.1, n = 4,
   |dq| = 0.1 ... 0.3 h, its h being the support radius). The last factor is the multiplier a
   lattice particle gets per unit C: the paper adds a bare number to lambda, which carries m^2
   with its unit masses, so its k is not scale-free. Vorticity confinement (eqs. 15-16) is not
   implemented; def.alpha is not read (XSPH is PBF's artificial viscosity); walls are free-slip.
   The walls stand where they are at the step's end (the boundary motion callback gets t + dt):
   the projection moves the particles to that time.
   w->p gets the pressure whose force would have made the step's correction, dx = -dt^2 sum_j
   m_j (p_i/rho_i^2 + p_j/rho_j^2) gW_ij, i.e. p_i = -rho0_i^2 sum_projections a_i / (S dt^2):
   PBF has no pressure of its own, and a host that colours by pressure sees the load.
   Compression: a projection reaches one kernel radius and keeps nothing between steps but the
   compression left in the positions (no warm start, unlike IISPH's pressure), so a fluid at rest
   sinks until the correction of its compression gradient, iterations times per step, balances
   gravity's g dt^2: its compression grows with dt^2 and with the depth in particles, and falls
   as 1 / iterations (sph__pbf_dt gives the rule and its constant). A compressed block relaxes
   from its rim inwards, one kernel radius per projection (tests/test_pbf.c: 16 x 16 particles
   10.8 % compressed keep 5.8 % after 1 projection, 1.9 % after 8, 0.08 % after 32). */
typedef struct sph__pbf {
    const sph_real* x; /* positions the pass reads (x*, then the last projection's)            */
    sph_real* xo;      /* positions a projection writes                                         */
    sph_real* a;       /* a_i = lambda_i / (m_i rho0_i) [m^5/kg]                                */
    sph_real* fw;      /* per fluid pair: gW_ij / x_ij, then s_ij (2 values)                    */
    sph_real* bw;      /* per wall pair: gW_ib / x_ib                                           */
    sph_real inv_s, s2, w0, inv_wq, k, q_lat, eps_q; /* 1/S, S^2, norm_w w(0), 1 / w(dq),
                          def.pbf_scorr S^2 / Q_lat, Q_lat, eps_r Q_lat */
    sph_real f;        /* the share of the compression a step corrects (sph__standing_keep)    */
    sph_real* p;       /* w->p, accumulated over the projections                                */
    sph_real p_scale;  /* 1 / (S dt^2)                                                          */
    sph_real wall;     /* the walls' share of a pair's multipliers: 1, the particle's own (PBF: the
                          walls have none), or 2 (sph__settle_placed: the walls mirror it)       */
    sph_real move2;    /* the largest move of a projection, squared [m^2] (0: any)               */
} sph__pbf;

/* The constants of a step's projections. */
static void sph__pbf_setup(sph_world* w, sph__ctx* c, sph__pbf* P, sph_real dt) {
    const sph_real q_lat = (sph_real)sph__lattice_grad2(&w->kernel, w->dx);
    const sph_real S = w->priv.lattice_sum;
    sph__ctx_init(w, c); /* after the sort */
    c->bp_mode = SPH_BP_ZERO; /* the walls carry no multiplier, whatever def.boundary_pressure */
    memset(P, 0, sizeof(*P));
    P->a = w->priv.src;
    P->fw = w->priv.ff_fw;
    P->bw = w->priv.fb_fw;
    P->inv_s = 1 / S;
    P->s2 = S * S;
    P->w0 = c->k.norm_w * sph__kw(c->k.form, 0);
    /* |dq| = 0.2 support radii (Macklin & Mueller 2013 sec. 4: 0.1 ... 0.3 h, h the support) */
    P->inv_wq = 1 / sph__kw(c->k.form, SPH__R(0.2) * c->k.radius * c->k.inv_h);
    P->k = w->def.pbf_scorr * S * S / q_lat;
    P->q_lat = q_lat;
    P->eps_q = w->def.pbf_relaxation * q_lat;
    /* a step that sph_advance shortened below the rule corrects only dt / dt_rule of the
       compression (as PCISPH, IISPH and DFSPH do, sph__standing_keep): the correction becomes
       the velocity dx / dt, and a retry at a hundredth of the step turned a standing 8 %
       compression into 1000 m/s in a 20 m tank */
    P->f = 1 - sph__standing_keep(w);
    P->p = w->p;
    P->p_scale = 1 / (S * dt * dt);
    P->wall = 1;
}

/* The first pass of a projection for particle i: rho_i, C_i and a_i at P->x (eqs. 1, 9-11), and
   the pair factors the second pass reuses (its positions are the same). Returns C_i. */
SPH__INLINE sph_real sph__pbf_lambda_one(sph_world* w, const sph__ctx* c, const sph__pbf* P,
                                         size_t i, const int D, const int form) {
    const sph_real* xi = P->x + i * (size_t)D;
    const sph__phase_c* ph = &c->pc[c->ph[i]];
    const sph_real mi = c->m ? c->m[i] : c->m0;
    sph_real G[3] = {0, 0, 0}, Q = 0, sum = 0, sumb = 0, C, den;
    size_t kk, k0 = c->ff->begin[i], k1 = k0 + c->ff->count[i];
    int k;
    for (kk = k0; kk < k1; ++kk) {
        const size_t j = c->ff->idx[kk];
        const sph_real mj = c->m ? c->m[j] : c->m0;
        sph_real d[3] = {0, 0, 0}, r2 = 0, q, W, fw, s = 0;
        sph__delta_vec(c, xi, P->x + j * (size_t)D, d, D);
        SPH__FOR_K(D, r2 += d[k] * d[k]);
        q = sph__sqrt(r2) * c->k.inv_h;
        W = sph__kw(form, q);
        fw = c->k.norm_g * sph__kf(form, q);
        sum += mj * W;
        SPH__FOR_K(D, G[k] += mj * fw * d[k]);
        Q += mj * fw * fw * r2;
        if (P->k > 0) { /* eq. 13, n = 4 */
            sph_real t = W * P->inv_wq;
            t *= t;
            s = -P->k * t * t * SPH__R(0.5) * (ph->rho0 + c->pc[c->ph[j]].rho0) / (mi * mj);
        }
        P->fw[2 * kk] = fw;
        P->fw[2 * kk + 1] = s;
    }
    if (c->has_b) {
        k0 = c->fb->begin[i];
        k1 = k0 + c->fb->count[i];
        for (kk = k0; kk < k1; ++kk) {
            const size_t b = c->fb->idx[kk];
            const sph_real psi = ph->rho0 * c->bvol[b];
            sph_real d[3] = {0, 0, 0}, r2 = 0, q, fw;
            sph__delta_vec(c, xi, c->bx + b * (size_t)D, d, D);
            SPH__FOR_K(D, r2 += d[k] * d[k]);
            q = sph__sqrt(r2) * c->k.inv_h;
            sumb += c->bvol[b] * sph__kw(form, q);
            fw = c->k.norm_g * sph__kf(form, q);
            SPH__FOR_K(D, G[k] += psi * fw * d[k]);
            P->bw[kk] = fw;
        }
    }
    w->rho[i] = (mi * P->w0 + c->k.norm_w * (sum + ph->rho0 * sumb)) * P->inv_s;
    C = w->rho[i] * ph->inv_rho0 - 1;
    if (!(C > 0)) C = 0; /* eq. 1, clamped: no tension at a free surface */
    den = mi * Q + P->eps_q * mi * mi;
    SPH__FOR_K(D, den += G[k] * G[k]);
    P->a[i] = -C * ph->rho0 * P->s2 * P->f / den; /* den >= eps_r m_i^2 Q_lat > 0 */
    return C;
}

/* The second pass: the correction of eq. 14 from the multipliers of the first, written to P->xo. */
SPH__INLINE void sph__pbf_project_one(const sph__ctx* c, const sph__pbf* P, size_t i, const int D) {
    const sph_real* xi = P->x + i * (size_t)D;
    const sph_real ai = P->a[i];
    sph_real dx[3] = {0, 0, 0};
    size_t kk, k0 = c->ff->begin[i], k1 = k0 + c->ff->count[i];
    int k;
    for (kk = k0; kk < k1; ++kk) {
        const size_t j = c->ff->idx[kk];
        const sph_real f = (ai + P->a[j] + P->fw[2 * kk + 1]) * (c->m ? c->m[j] : c->m0) * P->fw[2 * kk];
        sph_real d[3] = {0, 0, 0};
        sph__delta_vec(c, xi, P->x + j * (size_t)D, d, D);
        SPH__FOR_K(D, dx[k] += f * d[k]);
    }
    if (c->has_b && ai != 0) {
        const sph_real ap = P->wall * ai * c->pc[c->ph[i]].rho0;
        k0 = c->fb->begin[i];
        k1 = k0 + c->fb->count[i];
        for (kk = k0; kk < k1; ++kk) {
            const size_t b = c->fb->idx[kk];
            const sph_real f = ap * c->bvol[b] * P->bw[kk];
            sph_real d[3] = {0, 0, 0};
            sph__delta_vec(c, xi, c->bx + b * (size_t)D, d, D);
            SPH__FOR_K(D, dx[k] += f * d[k]);
        }
    }
    if (P->move2 > 0) { /* sph__settle_placed: small moves */
        sph_real m2 = 0, f = P->inv_s, *xo = P->xo + i * (size_t)D;
        SPH__FOR_K(D, m2 += dx[k] * dx[k]);
        if (m2 * f * f > P->move2) f = sph__sqrt(P->move2 / m2);
        SPH__FOR_K(D, xo[k] = xi[k] + dx[k] * f);
    } else {
        SPH__FOR_K(D, P->xo[i * (size_t)D + (size_t)k] = xi[k] + dx[k] * P->inv_s);
    }
    /* the pressure of this correction, accumulated over the projections (see above) */
    if (P->p) P->p[i] -= c->pc[c->ph[i]].rho0 * c->pc[c->ph[i]].rho0 * ai * P->p_scale;
}

/* The last pass, at the projected positions: rho_i, and the velocity after XSPH (eq. 17) and
   laminar viscosity, from w->v (the projection's velocities) into vo. */
SPH__INLINE void sph__pbf_velocity_one(sph_world* w, const sph__ctx* c, const sph__pbf* P,
                                       size_t i, const int D, const int form, sph_real dt,
                                       sph_real* vo) {
    const sph_real* xi = P->x + i * (size_t)D;
    const sph_real* vi = w->v + i * (size_t)D;
    const sph__phase_c* ph = &c->pc[c->ph[i]];
    const sph_real mi = c->m ? c->m[i] : c->m0, cx = w->def.pbf_xsph;
    sph_real xs[3] = {0, 0, 0}, av[3] = {0, 0, 0}, sum = 0, sumb = 0;
    size_t kk, k0 = c->ff->begin[i], k1 = k0 + c->ff->count[i];
    int k;
    for (kk = k0; kk < k1; ++kk) {
        const size_t j = c->ff->idx[kk];
        const sph__phase_c* pj = &c->pc[c->ph[j]];
        const sph_real mj = c->m ? c->m[j] : c->m0;
        const sph_real* vj = w->v + j * (size_t)D;
        sph_real d[3] = {0, 0, 0}, r2 = 0, q, W, f;
        sph__delta_vec(c, xi, P->x + j * (size_t)D, d, D);
        SPH__FOR_K(D, r2 += d[k] * d[k]);
        q = sph__sqrt(r2) * c->k.inv_h;
        W = sph__kw(form, q);
        sum += mj * W;
        f = 2 * mj / (ph->rho0 + pj->rho0) * W; /* eq. 17 */
        SPH__FOR_K(D, xs[k] += f * (vj[k] - vi[k]));
        if (c->laminar && ph->mu + pj->mu > 0) { /* Morris et al. 1997, rho0 for rho */
            f = mj * (ph->mu + pj->mu) * ph->inv_rho0 * pj->inv_rho0 * c->k.norm_g *
                sph__kf(form, q) * r2 / (r2 + c->eta2);
            SPH__FOR_K(D, av[k] += f * (vi[k] - vj[k]));
        }
    }
    if (c->has_b) sumb = sph__wall_sum(c, i, xi, D, form, NULL);
    w->rho[i] = (mi * P->w0 + c->k.norm_w * (sum + ph->rho0 * sumb)) * P->inv_s;
    SPH__FOR_K(D, vo[i * (size_t)D + (size_t)k] = vi[k] + cx * c->k.norm_w * xs[k] + dt * av[k]);
}

/* The first pass over all particles; returns the mean C (compression) from fixed-order block
   sums, so the iteration count is the same for any number of threads. */
static double sph__pbf_lambdas(sph_world* w, const sph__ctx* c, const sph__pbf* P) {
    const size_t nblk = (w->n + SPH__BLOCK - 1) / SPH__BLOCK;
    const int form = c->k.form, wc2 = form == SPH__KF_WC2;
    double sum = 0;
    sph__idx blk;
    size_t q;
    SPH__OMP_FOR(w->n) /* over blocks of SPH__BLOCK particles */
    for (blk = 0; blk < (sph__idx)nblk; ++blk) {
        const size_t i0 = (size_t)blk * SPH__BLOCK;
        const size_t i1 = i0 + SPH__BLOCK < w->n ? i0 + SPH__BLOCK : w->n;
        double e = 0;
        size_t i;
        /* D and the kernel compile-time constants for Wendland C2 (the loops unroll, and w and
           f share their powers of 1 - q/2) */
        for (i = i0; i < i1; ++i)
            e += (double)(c->dim == 2 ? (wc2 ? sph__pbf_lambda_one(w, c, P, i, 2, SPH__KF_WC2)
                                             : sph__pbf_lambda_one(w, c, P, i, 2, form))
                          : c->dim == 3 ? (wc2 ? sph__pbf_lambda_one(w, c, P, i, 3, SPH__KF_WC2)
                                               : sph__pbf_lambda_one(w, c, P, i, 3, form))
                                        : sph__pbf_lambda_one(w, c, P, i, 1, form));
        w->priv.block[blk] = e;
    }
    for (q = 0; q < nblk; ++q) sum += w->priv.block[q];
    return w->n ? sum / (double)w->n : 0;
}

static void sph__pbf_project(sph_world* w, const sph__ctx* c, const sph__pbf* P) {
    sph__idx i;
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)w->n; ++i) {
        if (c->dim == 2) sph__pbf_project_one(c, P, (size_t)i, 2);
        else if (c->dim == 3) sph__pbf_project_one(c, P, (size_t)i, 3);
        else sph__pbf_project_one(c, P, (size_t)i, 1);
    }
}

static void sph__pbf_velocities(sph_world* w, const sph__ctx* c, const sph__pbf* P, sph_real dt,
                                sph_real* vo) {
    const int form = c->k.form, wc2 = form == SPH__KF_WC2;
    sph__idx i;
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)w->n; ++i) {
        if (c->dim == 2 && wc2) sph__pbf_velocity_one(w, c, P, (size_t)i, 2, SPH__KF_WC2, dt, vo);
        else if (c->dim == 2) sph__pbf_velocity_one(w, c, P, (size_t)i, 2, form, dt, vo);
        else if (c->dim == 3 && wc2) sph__pbf_velocity_one(w, c, P, (size_t)i, 3, SPH__KF_WC2, dt, vo);
        else if (c->dim == 3) sph__pbf_velocity_one(w, c, P, (size_t)i, 3, form, dt, vo);
        else sph__pbf_velocity_one(w, c, P, (size_t)i, 1, form, dt, vo);
    }
}

/* Prediction (Algorithm 1, lines 2-3): v* = v + dt a_ext, x* = x + dt v*, with x^n and v^n kept
   in xp and vp until the neighbour search has succeeded. */
static void sph__pbf_predict(sph_world* w, sph_real dt) {
    const size_t nD = w->n * (size_t)w->dim;
    sph__idx i;
    sph__copy(w->priv.xp, w->x, nD * sizeof(sph_real));
    sph__copy(w->priv.vp, w->v, nD * sizeof(sph_real));
    SPH__OMP_FOR(nD)
    for (i = 0; i < (sph__idx)nD; ++i) {
        w->v[i] += dt * w->a[i];
        w->x[i] += dt * w->v[i];
    }
}

/* Out of memory in the search: x^n and v^n back (read through the sort's permutation if the
   particles were sorted), so that a repeated call predicts once. */
static void sph__pbf_unpredict(sph_world* w, uint64_t sorts) {
    const size_t D = (size_t)w->dim;
    size_t i;
    sph__undo_drift(w, w->priv.xp, sorts);
    if (w->priv.sorts == sorts) sph__copy(w->v, w->priv.vp, w->n * D * sizeof(sph_real));
    else
        for (i = 0; i < w->n; ++i)
            memcpy(w->v + i * D, w->priv.vp + (size_t)w->priv.grid.order[i] * D, D * sizeof(sph_real));
}

/* After the sort: a_ext into ap (w->a is scratch, not sorted), x* into xp for the projections,
   x back to x^n (to rounding) for the final move, and w->p cleared for its accumulation. The
   sort's permutation applies only if the search sorted (sorts changed; def.neighbor_skin's
   steps that keep their lists do not). */
static void sph__pbf_begin(sph_world* w, sph_real dt, uint64_t sorts) {
    const size_t D = (size_t)w->dim;
    const int sorted = w->priv.sorts != sorts;
    sph__idx i;
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)w->n; ++i) {
        const size_t o = (sorted ? (size_t)w->priv.grid.order[i] : (size_t)i) * D;
        size_t k;
        for (k = 0; k < D; ++k) {
            const size_t q = (size_t)i * D + k;
            w->priv.ap[q] = w->a[o + k];
            w->priv.xp[q] = w->x[q];
            w->x[q] -= dt * w->v[q];
        }
        w->p[i] = 0;
    }
}

/* Line 21: v = (x_proj - x^n) / dt; then line 22 (XSPH, viscosity) through scratch `vo`, and
   w->a = (v^{n+1} - v^n) / dt for the diagnostics. */
static void sph__pbf_velocity(sph_world* w, const sph__ctx* c, sph__pbf* P, const sph_real* xproj,
                              sph_real* vo, sph_real dt) {
    const size_t nD = w->n * (size_t)w->dim;
    sph__idx i;
    SPH__OMP_FOR(nD)
    for (i = 0; i < (sph__idx)nD; ++i) {
        const sph_real v = (xproj[i] - w->x[i]) / dt;
        w->a[i] = w->priv.ap[i] - w->v[i] / dt; /* a_ext - v* / dt, completed below */
        w->v[i] = v;
    }
    P->x = xproj;
    sph__pbf_velocities(w, c, P, dt, vo);
    SPH__OMP_FOR(nD)
    for (i = 0; i < (sph__idx)nD; ++i) {
        w->v[i] = vo[i];
        w->a[i] += vo[i] / dt;
    }
}

static sph_status sph__step_pbf(sph_world* w, sph_real dt) {
    double t0 = sph__now(), tstart = t0, err = 0;
    sph_real *xa, *xb, *tmp;
    uint64_t sorts;
    sph__ctx c;
    sph__pbf P;
    sph_status s;
    int it;
    if ((s = sph__scratch(w, &w->priv.xp, w->capacity * (size_t)w->dim)) != SPH_OK ||
        (s = sph__scratch(w, &w->priv.vp, w->capacity * (size_t)w->dim)) != SPH_OK ||
        (s = sph__scratch(w, &w->priv.ap, w->capacity * (size_t)w->dim)) != SPH_OK ||
        (s = sph__scratch(w, &w->priv.src, w->capacity)) != SPH_OK)
        return s;
    /* walls where the projection moves the particles to: at the step's end */
    s = sph__boundary_motion(w, w->time + (double)dt);
    if (s != SPH_OK) return s;
    sph__time(w, SPH_STAGE_BOUNDARY, &t0);
    /* predict with gravity and def.force at x^n */
    sph__ctx_init(w, &c);
    if ((s = sph__stage_body_force(w, &c)) != SPH_OK) return s;
    sph__record_nonpressure(w);
    sph__pbf_predict(w, dt);
    sph__time(w, SPH_STAGE_FORCES, &t0);
    /* neighbours at x* (line 5), kept for the whole step */
    sorts = w->priv.sorts;
    s = sph__stage_neighbors(w);
    if (s == SPH_OK) s = sph__scratch(w, &w->priv.ff_fw, 2 * w->priv.ff.cap_idx);
    if (s == SPH_OK) s = sph__scratch(w, &w->priv.fb_fw, w->priv.fb.cap_idx);
    if (s != SPH_OK) {
        sph__pbf_unpredict(w, sorts);
        return s;
    }
    sph__pbf_setup(w, &c, &P, dt);
    sph__pbf_begin(w, dt, sorts);
    sph__time(w, SPH_STAGE_NEIGHBORS, &t0);
    /* project (lines 8-19): Jacobi, two passes each, between the buffers xp and vp */
    xa = w->priv.xp;
    xb = w->priv.vp;
    for (it = 0; it < w->def.pbf_iterations; ++it) {
        P.x = xa;
        P.xo = xb;
        err = sph__pbf_lambdas(w, &c, &P);
        sph__pbf_project(w, &c, &P);
        tmp = xa;
        xa = xb;
        xb = tmp;
    }
    sph__time(w, SPH_STAGE_PRESSURE, &t0);
    /* velocity, XSPH and viscosity at the projected positions xa (lines 21-22) */
    sph__pbf_velocity(w, &c, &P, xa, xb, dt);
    sph__time(w, SPH_STAGE_FORCES, &t0);
    /* move x^{n+1} = x^n + dt v (line 23), wall contact, diagnostics and blow-up checks */
    w->stats.iterations = it;
    w->stats.solver_error = err;
    ++w->steps;
    w->time += (double)dt;
    s = sph__integrate(w, &c, 0, 0, dt, 1);
    sph__time(w, SPH_STAGE_INTEGRATE, &t0);
    w->stats.step_time = sph__now() - tstart;
    return s;
}

/* PBF's compression limit of sph_stable_dt [s] (1e300: none). A projection corrects a
   compression gradient by a displacement of about its multiplier's gradient, so a fluid at rest
   settles where iterations times that balances the pressure scale's displacement per step; its
   mean compression is about
       c = K (1 + eps_r) max(|g| H, |v|max^2) dt^2 / (iterations dx^2),
   H the fluid's extent along gravity plus dx (|g| H the hydrostatic, |v|^2 the dynamic pressure
   over rho0; their sum instead of the larger took 1.2 times the steps in the bench's dam breaks,
   `./build/bench tts --scene 2d|3d-6k --solver pbf`: 1408 against 1196 sub-steps to t = 1 s in
   2D, 400 against 328 in 3D, at a mean compression of 0.15 against 0.22 % and 0.07 against
   0.11 %). The limit is the dt of c = def.pbf_compression. K = 0.12 from 2D tanks at rest,
   started from rest density, through sph_advance in frames of 1/60 s (3 projections, eps_r = 1;
   mean over the frames): a 1 m tank 20 layers deep settled to 0.55, 0.97 and 1.79 % at targets
   of 0.5, 1 and 2 % (2 s), the 20 m tank of examples/realtime.c at --scale 12.5 (50 layers,
   10k particles) to
   0.95 and 1.76 % at 1 and 2 % (3 s), the 40-layer tank of tests/test_pbf.c to 1.17 % at 1 %
   (frames of 0.05 s). A start from rest density overshoots
   about twice the mean it settles to (the fluid falls until its compression carries it): the
   20 m tank at a 4 % target reached 7.7 % at 0.3 s and failed the 20 % bound of
   max_compression. Without gravity and motion nothing limits the step (sph_stable_dt then fails
   unless viscosity or def.max_dt does). */
#define SPH__PBF_K 0.12
static double sph__pbf_dt(const sph_world* w, double v2max) {
    const int D = w->dim;
    double g2 = 0, lo = 1e300, hi = -1e300, scale;
    size_t i;
    int k;
    for (k = 0; k < D; ++k) g2 += (double)w->def.gravity[k] * (double)w->def.gravity[k];
    if (g2 > 0) /* the fluid's extent along gravity */
        for (i = 0; i < w->n; ++i) {
            double y = 0;
            for (k = 0; k < D; ++k)
                y += (double)w->x[i * (size_t)D + (size_t)k] * (double)w->def.gravity[k];
            lo = y < lo ? y : lo;
            hi = y > hi ? y : hi;
        }
    scale = fmax(v2max, w->n > 0 && g2 > 0 ? hi - lo + sqrt(g2) * (double)w->dx : 0);
    if (!(scale > 0)) return 1e300;
    return (double)w->dx * sqrt((double)w->def.pbf_compression * w->def.pbf_iterations /
                                (SPH__PBF_K * (1 + (double)w->def.pbf_relaxation) * scale));
}

SPHDEF sph_status sph_step_pbf(sph_world* w, sph_real dt) {
    sph_status s = sph__step_begin(w, dt, SPH_SOLVER_PBF);
    if (s != SPH_OK) return s;
    return sph__step_end(w, sph__step_pbf(w, dt));
}

/* Fluid placed compressed. A host that puts its walls on the faces of the fluid's box (half a
   spacing from the fluid), or fills a box that reaches up to an obstacle or into other fluid,
   starts the fluid denser than rest: rho/rho0 = 1.25 at the walls of a 2D tank (0.6 x 0.3 m, dx
   0.02, one host-placed wall layer on the box's faces), 1.46 at a 3D tank's corners. An
   incompressible step turns that compression into velocity within a step. Measured through
   sph_advance with the defaults (tests/test_reliability.c, placed_compressed, the tank above for
   0.5 s): IISPH and DFSPH gained 20.1 and 19.2 M g H and threw particles out of the tank, every
   call SPH_OK; both PCISPH failed the first call; with the walls a quarter spacing further out
   IISPH still gained 0.57 M g H; in 3D every solver failed the first call or gained 4.6 M g H.
   Refusing such a start is no answer: a world rebuilt from a running simulation
   (examples/realtime.c's solver switch) is a valid start with fluid as close to its walls. So the
   first step after fluid or walls were added (one rest density; PCISPH, IISPH, DFSPH, PBF, and
   WCSPH where a particle with walls in reach is compressed) moves the fluid apart before time
   starts: Macklin & Mueller's (2013) position projection, eqs. 1 and 9-14 (the walls fixed and
   mirroring each particle's multiplier, no artificial pressure, C clamped to compression, eps =
   SPH__SETTLE_EPS of the lattice's sum |grad C|^2), in positions only, the velocities, pressures
   and any carried density as they were, until no particle is compressed by more than
   SPH__SETTLE_TO, at most SPH__SETTLE_ITERATIONS projections. Each projection moves a particle at
   most SPH__SETTLE_MOVE dx and is followed by the wall contact at SPH__SETTLE_WALL dx
   (sph__settle_contact, the lattice's distance): without either, corner particles went through a
   layer of one wall particle (2 of the 2D tank's 450). The lists are searched again whenever the
   largest moves since the last search add up to SPH__SETTLE_RESEARCH dx: with the first lists kept
   to the end, a 3D tank (0.6 x 0.3 x 0.3 m, dx 0.03) settled to 0.2 % by the projection's count was
   32 % compressed by the step's. A start at most SPH__SETTLE_ABOVE compressed is left exactly as it
   is (a lattice a spacing from lattice walls, a running incompressible solver's state: then the
   stage costs a neighbour search and one pass). WCSPH and the compressible step are compressible:
   fluid compressed away from walls is theirs to expand (tests/test_wcsph.c,
   free_expansion_ballistic), and the compressible step keeps any start. But WCSPH's tank with walls
   0.8-0.9 dx from its fluid (compressed 3-6 % by them) rose 0.17-0.22 M g H by 2 s, unreported, its
   kinetic energy growing from about 1 s on; settled, it holds. Measured on the tanks above: 156
   projections in 2D, 98-159 in 3D; the energy then rose by the lift of the volume that did not fit
   and no more (every solver 0.048-0.050 M g H in 2D against 0.051 estimated, none after the first
   frame), no particle out (PBF in 3D aside: README, Limits). */
#define SPH__SETTLE_ABOVE 0.01
#define SPH__SETTLE_TO 0.002
#define SPH__SETTLE_ITERATIONS 500
#define SPH__SETTLE_EPS 0.1
#define SPH__SETTLE_MOVE 0.1
#define SPH__SETTLE_RESEARCH 0.2
#define SPH__SETTLE_WALL 1.0
static int sph__settles(const sph_world* w, sph_solver solver) {
    if (sph__rest_density_ratio(w) != 1 || w->n == 0) return 0;
    if (sph__incompressible((int)solver)) return 1;
    return solver == SPH_SOLVER_WCSPH && w->nb > 0 && w->def.scheme != SPH_SCHEME_SECOND_ORDER
               ? 2 /* where walls are in reach */
               : 0;
}

/* The largest rho/rho0 - 1 of the last projection's first pass (w->rho); with walls_only, of
   the particles with walls in reach. */
static double sph__max_compression(const sph_world* w, const sph__ctx* c, int walls_only) {
    double m = 0;
    size_t i;
    for (i = 0; i < w->n; ++i) {
        const double e = (double)w->rho[i] * (double)c->pc[c->ph[i]].inv_rho0 - 1;
        if (!walls_only || (c->has_b && c->fb->count[i] > 0)) m = e > m ? e : m;
    }
    return m;
}

/* The wall contact (sph__wall_contact) after each projection, at SPH__SETTLE_WALL dx from every
   wall particle: the moved fluid ends where the step's contact leaves it alone. */
static void sph__settle_contact(sph_world* w, const sph__ctx* c, const sph_real* xs, sph_real* x) {
    const size_t D = (size_t)w->dim;
    sph__contact_arg ca;
    sph__idx i;
    ca.d = ca.d_c = SPH__R(SPH__SETTLE_WALL) * w->dx;
    ca.lead = ca.lead_s = 0;
    ca.thin = NULL;
    ca.gs = NULL;
    SPH__OMP_FOR(w->n)
    for (i = 0; i < (sph__idx)w->n; ++i) {
        sph_real v[3] = {0, 0, 0}; /* the contact's velocity change, not kept */
        if (c->fb->count[i] > 0)
            sph__wall_contact(c, (size_t)i, &ca, xs + (size_t)i * D, x + (size_t)i * D, v);
    }
}

/* Lists at the positions in w->x, and the projection's constants and scratch for them. The
   projections write their densities to w->rho, which a step that carries the density (WCSPH,
   enhanced PCISPH) keeps: it is kept in w->priv.ap meanwhile (sorted with the particles). */
static sph_status sph__settle_lists(sph_world* w, sph__ctx* c, sph__pbf* P) {
    const uint64_t builds = w->stats.neighbor_builds; /* the steps' searches, not these */
    sph_status s = sph__stage_neighbors(w);
    w->stats.neighbor_builds = builds;
    w->priv.vl_valid = 0; /* the step searches again, as without this stage */
    if (s != SPH_OK || (s = sph__scratch(w, &w->priv.ff_fw, 2 * w->priv.ff.cap_idx)) != SPH_OK ||
        (s = sph__scratch(w, &w->priv.fb_fw, w->priv.fb.cap_idx)) != SPH_OK)
        return s;
    sph__copy(w->priv.ap, w->rho, w->n * sizeof(sph_real));
    sph__pbf_setup(w, c, P, 1);
    P->k = 0;    /* no artificial pressure */
    P->f = 1;    /* the whole compression */
    P->p = NULL; /* no pressure: w->p is the solvers' warm start */
    P->wall = 2; /* walls that push as hard as the fluid behind (no particle pushed through) */
    P->eps_q = SPH__R(SPH__SETTLE_EPS) * P->q_lat;
    P->move2 = SPH__R(SPH__SETTLE_MOVE * SPH__SETTLE_MOVE) * w->dx * w->dx;
    return SPH_OK;
}

/* Fluid placed denser than rest in bulk (the incompressible solvers' settling only): more than
   half of the fluid particles without walls in reach compressed by more than SPH__SETTLE_BULK,
   as a lattice at a spacing below def.spacing gives (each particle carries rest_density *
   spacing^dim: a lattice at 0.97 spacing is 6.3 % compressed in 2D, a hexagonal one at the
   spacing 15.5 %). That is not an overlap to move apart but more mass than the volume holds:
   the projection moves only what borders a free surface or a wall (a 2D block of 100 x 50
   particles at 0.97 spacing in a tank of its width, 500 projections: the mean compression 5.5 ->
   0.8 %, the largest 6 -> 4.8 %), and the step turned the rest into motion, unreported (IISPH:
   0.11 M g H gained within 0.05 s, 0.59 sqrt(g H); at 0.95 spacing every retry failed with a
   speed). So such a start is refused (SPH_ERR_ARG) with the compression and the particle named.
   Returns that particle's index, or -1. */
#define SPH__SETTLE_BULK 0.05
static long sph__bulk_compressed(const sph_world* w, const sph__ctx* c, double* mean) {
    size_t i, away = 0, over = 0;
    long first = -1;
    double sum = 0;
    for (i = 0; i < w->n; ++i) {
        double e;
        if (c->has_b && c->fb->count[i] > 0) continue;
        e = (double)w->rho[i] * (double)c->pc[c->ph[i]].inv_rho0 - 1;
        ++away;
        if (e > SPH__SETTLE_BULK) {
            if (first < 0) first = (long)i;
            ++over;
            sum += e;
        }
    }
    *mean = over ? sum / (double)over : 0;
    return 2 * over > away ? first : -1;
}

static sph_status sph__settle_placed(sph_world* w, int walls_only) {
    const size_t nD = w->n * (size_t)w->dim;
    sph_real *xa = w->x, *xb;
    double moved = 0; /* the largest moves summed since the lists were built */
    sph__ctx c;
    sph__pbf P;
    sph_status s;
    int it;
    if ((s = sph__boundary_motion(w, w->time)) != SPH_OK) return s; /* the walls of time t */
    if ((s = sph__scratch(w, &w->priv.xp, w->capacity * (size_t)w->dim)) != SPH_OK ||
        (s = sph__scratch(w, &w->priv.vp, w->capacity * (size_t)w->dim)) != SPH_OK ||
        (s = sph__scratch(w, &w->priv.src, w->capacity)) != SPH_OK ||
        (s = sph__scratch(w, &w->priv.ap, w->capacity * (size_t)w->dim)) != SPH_OK ||
        (s = sph__settle_lists(w, &c, &P)) != SPH_OK)
        return s;
    xb = w->priv.xp;
    for (it = 0; it <= SPH__SETTLE_ITERATIONS; ++it) {
        if (moved > SPH__SETTLE_RESEARCH * (double)w->dx) { /* the lists again, at xa */
            if (xa != w->x) sph__copy(w->x, xa, nD * sizeof(sph_real));
            sph__copy(w->rho, w->priv.ap, w->n * sizeof(sph_real));
            if ((s = sph__settle_lists(w, &c, &P)) != SPH_OK) return s;
            xa = w->x;
            xb = w->priv.xp;
            moved = 0;
        }
        P.x = xa;
        P.xo = xb;
        sph__pbf_lambdas(w, &c, &P);
        if (it == 0 && !walls_only) {
            double mean;
            const long bad = sph__bulk_compressed(w, &c, &mean);
            if (bad >= 0) {
                const sph_real* xq = w->x + (size_t)bad * (size_t)w->dim;
                sph__copy(w->rho, w->priv.ap, w->n * sizeof(sph_real));
                return sph__fail(
                    w, SPH_ERR_ARG, bad,
                    "the fluid starts denser than its rest density in bulk: most particles away "
                    "from walls are compressed by more than %g %% (on average %.3g %%; the "
                    "first is the fluid particle with id %u at (%g, %g, %g)). Each particle "
                    "carries rest_density * spacing^dim (spacing %g m): particles placed closer "
                    "than def.spacing (a hexagonal lattice at the spacing is 15.5 %% denser in "
                    "2D) hold more mass than their volume; place them at def.spacing or set "
                    "sph_phase.mass",
                    100 * SPH__SETTLE_BULK, 100 * mean, (unsigned)w->id[bad], (double)xq[0],
                    w->dim > 1 ? (double)xq[1] : 0.0, w->dim > 2 ? (double)xq[2] : 0.0,
                    (double)w->dx);
            }
        }
        if (sph__max_compression(w, &c, it == 0 && walls_only) <=
                (it == 0 ? SPH__SETTLE_ABOVE : SPH__SETTLE_TO) ||
            it == SPH__SETTLE_ITERATIONS)
            break;
        sph__pbf_project(w, &c, &P);
        if (c.has_b) sph__settle_contact(w, &c, xa, xb);
        moved += (double)sph__sqrt(sph__max_shift2(&w->priv.grid, xb, xa, w->n));
        xa = xb;
        xb = xb == w->priv.xp ? w->priv.vp : w->priv.xp;
    }
    if (xa != w->x) sph__copy(w->x, xa, nD * sizeof(sph_real));
    sph__copy(w->rho, w->priv.ap, w->n * sizeof(sph_real));
    return SPH_OK;
}

/* ============================================================================================== */
/* >>compressible (implementation)                                                                */
/* ============================================================================================== */
/* Explicit compressible multiphase SPH (Ott & Schnetter 2003). Symplectic Euler as in
   the WCSPH step, with an internal energy that conserves the total energy:
       a^n       = g + a(x^n, rho^n, e^n, v^n)                 eq. 12 + artificial viscosity
       v^{n+1}   = v^n + dt a^n
       rho^{n+1} = rho^n + dt R(x^n, v^{n+1})                  eq. 11 (def.density: or 8, or 7)
       e^{n+1}   = e^n + dt E(x^n, rho^n, e^n; v^n, v^{n+1})   eq. 13, forces of a^n dotted with
                                                               the step's mean velocity
       x^{n+1}   = x^n + dt v^{n+1}
   The kinetic energy changes by sum_i m_i dt a_i . (v^n + v^{n+1})/2 exactly, and E returns
   exactly that (sph__interact_one, ENERGY), so kinetic + internal energy is conserved to
   round-off by any dt (tests/test_compressible.c). The density takes the new velocity (stable
   acoustics, see >>wcsph); the energy's mean velocity differs from it by dt a/2, an O(dt)
   entropy error per unit time in smooth flow (the sound-pulse test bounds its effect).
   Decisions where the paper is silent: its artificial viscosity is Monaghan's (1992) with the
   particles' own sound speeds in c_bar and beta left to def.beta (its shock tube needs only alpha);
   walls are Adami walls whose density follows each phase's isentrope through its rest state;
   phases with the Tait or linear law keep them and their energy is evolved but unused. Two
   neighbour passes per step: forces, then density and energy rates. */
static sph_status sph__step_compressible(sph_world* w, sph_real dt) {
    const int cont = w->def.density != SPH_DENSITY_SUMMATION;
    const size_t D = (size_t)w->dim;
    double t0 = sph__now(), tstart = t0;
    sph__ctx c;
    sph_status s;
    sph__idx i;
    s = sph__scratch(w, &w->priv.cs, w->capacity);
    if (s == SPH_OK) s = sph__scratch(w, &w->priv.vn, w->capacity * D);
    if (s == SPH_OK) s = sph__scratch(w, &w->priv.de, w->capacity);
    if (s != SPH_OK) return s;
    s = sph__prepare_forces(w, &c, w->time, &t0); /* also p(rho, e) and the sound speeds */
    if (s != SPH_OK) return s;
    sph__stage_interact(w, &c, SPH__ACCEL, w->a);
    sph__time(w, SPH_STAGE_FORCES, &t0);
    sph__copy(w->priv.vn, w->v, w->n * D * sizeof(sph_real));
    s = sph__integrate(w, &c, dt, 0, 0, 0); /* kick */
    if (s != SPH_OK) return s;
    if (w->e) {
        sph__stage_interact(w, &c, SPH__RATE | SPH__ACCEL | SPH__ENERGY, NULL);
        SPH__OMP_FOR(w->n)
        for (i = 0; i < (sph__idx)w->n; ++i) w->e[i] += dt * w->priv.de[i];
    } else if (cont) {
        sph__stage_interact(w, &c, SPH__RATE, NULL);
    }
    sph__time(w, SPH_STAGE_DENSITY, &t0);
    ++w->steps;
    w->time += (double)dt;
    s = sph__integrate(w, &c, 0, cont ? dt : 0, dt, 1); /* density and drift */
    sph__time(w, SPH_STAGE_INTEGRATE, &t0);
    w->stats.step_time = sph__now() - tstart;
    return s;
}

SPHDEF sph_status sph_step_compressible(sph_world* w, sph_real dt) {
    sph_status s = sph__step_begin(w, dt, SPH_SOLVER_COMPRESSIBLE);
    if (s != SPH_OK) return s;
    return sph__step_end(w, sph__step_compressible(w, dt));
}

/* Sound speed of a particle of phase P at density rho and specific internal energy e [m/s]. */
static double sph__sound_speed(const sph_phase* P, double rho, double e) {
    const double g = (double)P->gamma, c0 = (double)P->sound_speed;
    double c2;
    if (P->eos == SPH_EOS_LINEAR) return c0;
    if (P->eos == SPH_EOS_TAIT) c2 = c0 * c0 * pow(rho / (double)P->rest_density, g - 1);
    else c2 = (g - 1) * (e - (double)sph__pinf(P) / rho) * g; /* gamma (p + p_inf) / rho */
    return c2 > 0 ? sqrt(c2) : 0;
}

/* >>stages: time step control */

SPHDEF sph_real sph_stable_dt(sph_world* w, sph_solver solver) {
    const size_t D = w ? (size_t)w->dim : 0;
    double cmax = 0, numax = 0, v2max = 0, amax, dt = 1e300, g2 = 0;
    size_t i, k;
    int q;
    if (!w) return 0;
    if ((int)solver < 0 || solver > SPH_SOLVER_PBF) {
        sph__fail(w, SPH_ERR_ARG, -1, "sph_stable_dt: solver %d is not a sph_solver", (int)solver);
        return 0;
    }
    if (sph__resolve_sound_speed(w) != SPH_OK) {
        if (solver == SPH_SOLVER_WCSPH || solver == SPH_SOLVER_COMPRESSIBLE) return 0;
        w->status = SPH_OK; /* incompressible solvers do not need c0 */
        w->error[0] = 0;
    }
    for (q = 0; q < w->nphase; ++q) {
        if ((double)w->phases[q].sound_speed > cmax) cmax = (double)w->phases[q].sound_speed;
        if ((double)w->phases[q].viscosity > numax) numax = (double)w->phases[q].viscosity;
    }
    for (i = 0; i < w->n * D; i += D) {
        double v2 = 0;
        for (k = 0; k < D; ++k) v2 += (double)w->v[i + k] * (double)w->v[i + k];
        if (v2 > v2max) v2max = v2;
    }
    for (i = 0; i < w->nb * D; i += D) {
        double v2 = 0;
        for (k = 0; k < D; ++k) v2 += (double)w->b_v[i + k] * (double)w->b_v[i + k];
        if (v2 > v2max) v2max = v2;
    }
    for (k = 0; k < D; ++k) g2 += (double)w->def.gravity[k] * (double)w->def.gravity[k];
    /* a step without fluid particles measures no acceleration (a_max = 0): then |g| as before
       the first step, or sph_advance over an empty world would find nothing limiting its second
       sub-step and fail with SPH_ERR_ARG after the first had changed the world */
    amax = w->steps > 0 && w->n > 0
               ? (sph__incompressible((int)solver) && w->stats.a_np_max > 0 ? w->stats.a_np_max
                                                                             : w->stats.a_max)
               : sqrt(g2);
    if (solver == SPH_SOLVER_WCSPH) {
        if (!(cmax > 0)) {
            sph__fail(w, SPH_ERR_ARG, -1, "sph_stable_dt: no phase has a sound speed (add particles)");
            return 0;
        }
        dt = (double)w->def.cfl * (double)w->h / (cmax + sqrt(v2max));
    } else if (solver == SPH_SOLVER_COMPRESSIBLE) {
        /* the acoustic CFL with each particle's sound speed now (a gas heats and cools); the
           artificial viscosity of alpha <= 1 is a viscosity of about alpha c h / 8, whose own limit
           (h / (alpha c)) lies far above this one */
        double smax = 0;
        for (i = 0; i < w->n; ++i) {
            double v2 = 0, sp;
            for (k = 0; k < D; ++k) v2 += (double)w->v[i * D + k] * (double)w->v[i * D + k];
            sp = sph__sound_speed(&w->phases[w->phase[i]], (double)w->rho[i],
                                  w->e ? (double)w->e[i] : 0) + sqrt(v2);
            if (sp > smax) smax = sp;
        }
        if (smax > 0) dt = (double)w->def.cfl * (double)w->h / smax;
    } else if (v2max > 0 || amax > 0) {
        /* Meiers 2025 eq. 14: a particle moves at most cfl_velocity dx per step, here with the
           speed it reaches within the step, |v| + |a| dt <= C dx / dt (the larger root of
           |a| dt^2 + |v| dt - C dx = 0), so a step from rest is limited too */
        const double C = (double)w->def.cfl_velocity * (double)w->dx, vm = sqrt(v2max);
        dt = amax > 0 ? 2 * C / (vm + sqrt(vm * vm + 4 * amax * C)) : C / vm;
    }
    if (solver == SPH_SOLVER_PBF) dt = fmin(dt, sph__pbf_dt(w, v2max)); /* its compression */
    /* The explicit viscous step is stable while dt nu lambda_max <= 2. A Fourier analysis of the
       operators on a lattice (h = 1-2 dx, 2D and 3D) gives lambda_max = 2 / (C h^2 / nu) with
       C = 0.29-0.36 (Morris form, cubic and Wendland C2), 0.50 (quintic), but only C = 0.112-0.15
       for the 2(d+2) form; the default 0.125 keeps a margin for Morris, and the 2(d+2) form gets
       0.8 of it. tests/test_wcsph.c checks the limit by running just below and above it. */
    if (numax > 0)
        dt = fmin(dt, (double)w->def.cfl_viscous * (w->def.viscosity_form == SPH_VISC_MONAGHAN ? 0.8 : 1.0) *
                          (double)w->h * (double)w->h / numax);
    /* the incompressible solvers' pressure solves converge within max_iterations only at
       0.4 of the explicit force limit: at 0.25 sqrt(h / |g|) (13 ms in a 2D tank of dx = 0.02)
       IISPH needed 98 iterations per step and blew up with mirrored walls, at 0.1 (the 0.4 x
       0.25 used here) IISPH and DFSPH hold the tank at 30 iterations (tests/test_dfsph.c) */
    if (amax > 0 && solver != SPH_SOLVER_PBF) /* PBF: see sph__pbf_dt */
        dt = fmin(dt, (sph__incompressible((int)solver) ? 0.4 : 1.0) * (double)w->def.cfl_force *
                          sqrt((double)w->h / amax));
    /* The original PCISPH (summation density) corrects at the predicted positions x* = x + dt v +
       dt^2 (a_np + a_p), which every correction moves: the pressure acceleration's derivative with
       respect to position, about p / (rho0 h^2), feeds each correction back into the next with a
       factor of about dt^2 p / (rho0 h^2), and once the pressure the correction has built brings
       it to 0.3-0.8, a mode of neighbours a spacing apart grows, the gain guard cuts the gain and
       the step fails. The force and velocity limits above do not see it (both failures the tests
       met were at steps they allowed). Measured: the dam break of tests/test_pcisph.c (dx = 5 mm)
       at the force limit's 2.45 ms: restarted from p = 0 (Alg. 5) each step with its mean error
       below the tolerance, the column fell for three steps on a fraction of its weight (largest
       pressure 380 Pa), then the fourth step's correction rebuilt 5600 Pa (3 rho0 g 2a) over 34
       iterations and diverged at 0.8 (8.6 m/s); the periodic box of random velocities of
       tests/test_reliability.c (0.34 m/s, dx = 0.02, no gravity, a solve that never converges at
       1e-4, so its pressure level climbs) diverged at dt = 8 and 6 ms once that level reached 3800
       and 6000 Pa (0.36 and 0.32) and ran at 4 ms and below. The enhanced variant (continuity
       density) takes the pressure at x^n: no such feedback. The rule: dt^2 p_max / (rho0 h^2) <=
       1/16 with the largest pressure now (the last step's, or sph_set_hydrostatic's): dt <= 0.25 h
       / sqrt(p_max / rho0), a margin of 5-13 in dt^2 p for a step that builds more than its
       predecessor did. Before any pressure (a first step without sph_set_hydrostatic) the pressure
       that stops a relative velocity of up to 2 |v|max over h within the step, rho0 h 2 |v|max /
       dt, in the same bound: dt <= h / (16 * 2 |v|max) (the periodic box: 2.4 ms). It is the force
       limit of the pressure acceleration p / (rho0 h) at 0.25: a pressure that removes a density
       error eps within the step (eps rho0 h^2 / dt^2) shrinks the next step only for eps > 1/16.
       With it the dam break runs at 0.85 ms on average and the periodic box at 1.5-12 ms without a
       failure; sph_advance's scenes (tests/test_scenes.c) take 23 % fewer (2D box) to 60 % more
       (3D dam) steps with fewer retries (2D tank 669 steps and 93 retries before, 707 and 50 now;
       2D slosh 288 and 40, 332 and 4), and the 2D tank's late speed rose from 0.045 to 0.088
       sqrt(g H). */
    w->priv.dt_unpressed = 0;
    if (solver == SPH_SOLVER_PCISPH && w->def.density == SPH_DENSITY_SUMMATION) {
        double pr = 0;
        for (i = 0; i < w->n; ++i) {
            const double r = (double)w->p[i] / (double)w->phases[w->phase[i]].rest_density;
            if (r > pr) pr = r;
        }
        w->priv.dt_unpressed = dt < 1e300 ? dt : 0;
        if (pr > 0) dt = fmin(dt, 0.25 * (double)w->h / sqrt(pr));
        else if (v2max > 0) dt = fmin(dt, (double)w->h / (16 * 2 * sqrt(v2max)));
    }
    if (w->def.max_dt > 0) dt = fmin(dt, (double)w->def.max_dt);
    if (dt >= 1e300) {
        sph__fail(w, SPH_ERR_ARG, -1, "sph_stable_dt: nothing limits the step (no motion, no force, "
                                      "no viscosity); choose dt yourself");
        return 0;
    }
    /* valid but extreme input (a cfl factor of 1e-320, speeds near overflow) can round the step
       to 0 in sph_real: report it instead of returning 0 with no error */
    if (!((sph_real)dt > 0)) {
        sph__fail(w, SPH_ERR_UNSTABLE, -1,
                  "sph_stable_dt: the stable step (%g s) rounds to 0 in sph_real; check the "
                  "def.cfl* factors and the speeds", dt);
        return 0;
    }
    return (sph_real)dt;
}

SPHDEF sph_status sph_step(sph_world* w, sph_real dt) {
    if (!w) return SPH_ERR_ARG;
    switch (w->def.solver) {
    case SPH_SOLVER_WCSPH: return sph_step_wcsph(w, dt);
    case SPH_SOLVER_IISPH: return sph_step_iisph(w, dt);
    case SPH_SOLVER_PCISPH: return sph_step_pcisph(w, dt);
    case SPH_SOLVER_COMPRESSIBLE: return sph_step_compressible(w, dt);
    case SPH_SOLVER_DFSPH: return sph_step_dfsph(w, dt);
    case SPH_SOLVER_PBF: return sph_step_pbf(w, dt);
    default: return sph__fail(w, SPH_ERR_ARG, -1, "sph_step: unknown solver %d", (int)w->def.solver);
    }
}

/* sph_advance's rollback: a copy of everything a step changes. The persistent particle arrays
   of the registry (sph__fluid_arrays: x, v, rho, p, id, phase, drho, and m, e when present), the
   walls' extrapolated p_b and rho_b (which a host reads), and, when a step may move or re-sort
   the walls (a motion callback, walls not yet sorted), every persistent wall array; the time,
   step count, diagnostics and the sort state. Scratch is recomputed by every step. */
typedef struct sph__snap_head {
    double time;
    uint64_t steps, sorts;
    sph_stats stats;
    int b_dirty, walls, placed, placed_c0;
    size_t n, nb;
    sph_real c0[SPH_MAX_PHASES]; /* derived sound speeds change (sph__sound_speed_follows_flow) */
} sph__snap_head;

static int sph__snap_arrays(sph_world* w, sph__array* arr, int walls) {
    sph__array b[16];
    int n = 0, nb, k;
    const int na = sph__fluid_arrays(w, b);
    for (k = 0; k < na; ++k)
        if (b[k].persistent) arr[n++] = b[k];
    nb = w->nb > 0 ? sph__boundary_arrays(w, b) : 0;
    for (k = 0; k < nb; ++k)
        if ((walls && b[k].persistent) || b[k].ptr == (void**)&w->b_p || b[k].ptr == (void**)&w->b_rho)
            arr[n++] = b[k];
    return n;
}

/* The fluid arrays come first in sph__snap_arrays: entry k is a fluid array for k < nfluid. */
static int sph__snap_nfluid(sph_world* w) {
    sph__array b[16];
    int k, n = 0;
    const int na = sph__fluid_arrays(w, b);
    for (k = 0; k < na; ++k) n += b[k].persistent;
    return n;
}

static sph_status sph__snapshot_take(sph_world* w, int slot) {
    sph__array arr[32];
    sph__snap_head head;
    /* the walls are re-sorted by a step when they move, were changed, or their cells change
       size (def.neighbor_skin turned on, off or changed) */
    const int walls = w->nb > 0 && (w->def.boundary_motion != NULL || w->priv.b_dirty ||
                                    w->priv.bgrid.cell != sph__verlet_radius_for(w, (int)w->def.solver));
    const int na = sph__snap_arrays(w, arr, walls), nf = sph__snap_nfluid(w);
    size_t bytes = sizeof(head), pos;
    int k;
    for (k = 0; k < na; ++k) bytes += (k < nf ? w->n : w->nb) * arr[k].elem;
    if (bytes > w->priv.snap_cap[slot]) {
        if (!sph__grow((void**)&w->priv.snap[slot], bytes, 1))
            return sph__fail(w, SPH_ERR_NOMEM, -1, "sph_advance: out of memory (rollback copy)");
        w->priv.snap_cap[slot] = bytes;
    }
    head.time = w->time;
    head.steps = w->steps;
    head.sorts = w->priv.sorts;
    head.stats = w->stats;
    head.b_dirty = w->priv.b_dirty;
    head.placed = w->priv.placed;
    head.placed_c0 = w->priv.placed_c0;
    for (k = 0; k < SPH_MAX_PHASES; ++k)
        head.c0[k] = k < w->nphase ? w->phases[k].sound_speed : 0;
    head.walls = walls;
    head.n = w->n;
    head.nb = w->nb;
    memcpy(w->priv.snap[slot], &head, sizeof(head));
    pos = sizeof(head);
    for (k = 0; k < na; ++k) {
        const size_t sz = (k < nf ? w->n : w->nb) * arr[k].elem;
        if (sz) memcpy(w->priv.snap[slot] + pos, *arr[k].ptr, sz);
        pos += sz;
    }
    return SPH_OK;
}

/* sph__snapshot_restore after a failure that names a particle in w->error_index: the failing
   step may have re-sorted the particles, so the named one is found again by its id in the
   restored order (fluid or boundary, as the message says). Returns the index (-1: none). */
static long sph__restore_named(sph_world* w, int slot) {
    long idx = w->error_index;
    const int boundary = strstr(w->error, "boundary particle") != NULL &&
                         strstr(w->error, "fluid particle") == NULL;
    const size_t count = boundary ? w->nb : w->n;
    const uint32_t id = idx >= 0 && (size_t)idx < count ? (boundary ? w->b_id : w->id)[idx] : 0;
    sph__snapshot_restore(w, slot);
    if (idx >= 0 && (size_t)idx < count) {
        const uint32_t* now = boundary ? w->b_id : w->id;
        size_t q;
        for (q = 0; q < count && now[q] != id; ++q) {}
        idx = q < count ? (long)q : -1;
    }
    w->error_index = idx;
    return idx;
}

/* Puts the world back, bit for bit, to the state of sph__snapshot_take(slot). */
static void sph__snapshot_restore(sph_world* w, int slot) {
    sph__array arr[32];
    sph__snap_head head;
    int na, nf, k;
    size_t pos = sizeof(head);
    memcpy(&head, w->priv.snap[slot], sizeof(head));
    SPH_ASSERT(head.n == w->n && head.nb == w->nb);
    na = sph__snap_arrays(w, arr, head.walls);
    nf = sph__snap_nfluid(w);
    for (k = 0; k < na; ++k) {
        const size_t sz = (k < nf ? w->n : w->nb) * arr[k].elem;
        if (sz) memcpy(*arr[k].ptr, w->priv.snap[slot] + pos, sz);
        pos += sz;
    }
    w->time = head.time;
    w->steps = head.steps;
    w->priv.sorts = head.sorts;
    w->stats = head.stats;
    /* walls put back into an order their grid may no longer have: sorted again */
    w->priv.b_dirty = head.b_dirty || head.walls;
    w->priv.snl_valid = 0; /* the second-order scheme's lists name the order that was undone */
    w->priv.vl_valid = 0;  /* and so may the candidate lists of def.neighbor_skin */
    w->priv.placed = head.placed; /* a start undone is checked and settled again */
    w->priv.placed_c0 = head.placed_c0;
    for (k = 0; k < w->nphase; ++k) w->phases[k].sound_speed = head.c0[k];
}

/* The step control of sph_advance (DESIGN: "the robust integrator"):
     dt = dt_factor * sph_stable_dt, shortened to land exactly on the end: the remainder of the
          call is split into equal steps no longer than that (a lone short last step made the
          pressure solves fail the step after it: see sph__standing_keep);
     a sub-step that fails with SPH_ERR_UNSTABLE (blow-up, runaway, a particle through a wall or
          moving too far) or SPH_ERR_NOT_CONVERGED is undone bit for bit and retried with half
          the step (dt_factor halves), at most SPH__RETRIES times in a row;
     after each successful sub-step dt_factor grows by 1.1 back towards 1;
     before each WCSPH sub-step of a scene with a force callback or moving walls, a derived
          sound speed follows the flow (sph__sound_speed_follows_flow);
     a sub-step that still fails (not the call's first) is taken as a sign that an accepted
          sub-step left a state no step can continue from: the call starts again from its
          beginning at a quarter of the step it began with, at most twice.
   The factor is kept in the world, so a scene that needs a smaller step than the rule gives
   pays for the failed attempts once, not every frame. Any failure that remains, and every other
   error (out of memory, a bad callback value), puts the world back to the state before the
   call. The work is bounded by def.max_substeps sub-steps, retries included. */
#define SPH__RETRIES 12

SPHDEF sph_status sph_advance(sph_world* w, sph_real duration) {
    double t_end;
    int substeps = 0, retries = 0, in_row = 0, restarts = 0, first = 1, placed;
    int first_slot = 0; /* where a failed first sub-step starts again: 1 once it settled */
    double dt_min = 0, dt_last = 0, iterations = 0, factor0;
    uint64_t steps0;
    sph_status s;
    if (!w) return SPH_ERR_ARG;
    /* the host added fluid or walls since the last step, all of one rest density (phases of
       different density start off rest density for a solver that sums it) */
    placed = w->priv.placed && sph__rest_density_ratio(w) == 1;
    steps0 = w->steps;
    if (!sph__finite((double)duration) || duration < 0)
        return sph__fail(w, SPH_ERR_ARG, -1, "sph_advance: duration = %g: must be finite and >= 0",
                         (double)duration);
    t_end = w->time + (double)duration;
    if (!(t_end > w->time)) return SPH_OK; /* nothing to do at the resolution of w.time */
    if (!(w->stats.dt_factor > 0) || w->stats.dt_factor > 1) w->stats.dt_factor = 1;
    factor0 = w->stats.dt_factor;
    s = sph__snapshot_take(w, 0);
    if (s != SPH_OK) return s;
    while (w->time < t_end) {
        double dt, remaining = t_end - w->time, dt_stable;
        int last = 0;
        /* the halves of a split remainder may leave a rounding residue of a few ulp of t_end */
        if (remaining <= 16 * DBL_EPSILON * fabs(t_end)) {
            w->time = t_end;
            break;
        }
        if (substeps >= w->def.max_substeps) {
            sph__snapshot_restore(w, 0);
            return sph__fail(w, SPH_ERR_BUDGET, -1,
                             "sph_advance: %d sub-steps (def.max_substeps, %d retries) reached "
                             "%g s short of the end, the last at a step of %g s; the world is as "
                             "before the call", substeps, retries, remaining, dt_last);
        }
        if (w->def.solver == SPH_SOLVER_WCSPH) sph__sound_speed_follows_flow(w);
        dt_stable = (double)sph_stable_dt(w, w->def.solver);
        if (!(dt_stable > 0)) {
            char msg[SPH_ERROR_SIZE];
            s = w->status != SPH_OK ? w->status : SPH_ERR_UNSTABLE;
            memcpy(msg, w->error, sizeof msg);
            sph__snapshot_restore(w, 0);
            return sph__fail(w, s, -1, "sph_advance: no stable step at t = %g s: %s", w->time, msg);
        }
        dt = dt_stable * w->stats.dt_factor;
        /* a remainder within rounding of one step is that step (sph_advance(w, sph_stable_dt(w))
           came out an ulp above the step and was split into two halves) */
        if (remaining <= dt * (1 + 1e-5)) { dt = remaining; last = 1; }
        else dt = remaining / ceil(remaining / dt); /* equal steps to the end: no sliver */
        if (dt < 1e-12 * (double)duration && !last) {
            double t = w->time;
            sph__snapshot_restore(w, 0);
            return sph__fail(w, SPH_ERR_UNSTABLE, -1,
                             "sph_advance: the stable time step collapsed to %g s at t = %g s (a "
                             "runaway the step checks did not stop: speeds, sound speeds or "
                             "accelerations grew without bound); the world is as before the call",
                             dt, t);
        }
        if (!(w->time + dt > w->time) || !((sph_real)dt > 0)) {
            double t = w->time;
            sph__snapshot_restore(w, 0);
            return sph__fail(w, SPH_ERR_UNSTABLE, -1,
                             "sph_advance: the step %g s is below the resolution of the time %g s "
                             "(or of sph_real); the world is as before the call", dt, t);
        }
        if (!first) { /* the state of this sub-step's start (slot 0 holds the first's) */
            s = sph__snapshot_take(w, 1);
            if (s != SPH_OK) {
                sph__snapshot_restore(w, 0);
                return s;
            }
        }
        ++substeps;
        dt_last = dt;
        w->priv.correct_fraction = fmin(1.0, w->stats.dt_factor);
        if (w->priv.dt_unpressed > 4 * dt_stable)
            w->priv.correct_fraction *= 4 * dt_stable / w->priv.dt_unpressed;
        w->priv.cold_start = in_row > (w->def.boundary_pressure == SPH_BP_EXTRAPOLATE ? 0 : 1);
        w->priv.settle_snap = first ? 1 : 3; /* 0 is a bare sph_step's */
        s = sph_step(w, (sph_real)dt);
        if (w->priv.settle_snap == 2) first_slot = 1;
        w->priv.settle_snap = 0;
        iterations += w->stats.iterations;
        w->priv.correct_fraction = 1;
        w->priv.cold_start = 0;
        if (s == SPH_OK) {
            if (dt_min == 0 || dt < dt_min) dt_min = dt;
            in_row = 0;
            first = 0;
            w->stats.dt_factor = fmin(1.0, 1.1 * w->stats.dt_factor);
            /* land exactly on the end: a float step, or time + dt rounded, may leave a residue
               that a sliver step would make the incompressible solvers treat as a real step */
            if (last) w->time = t_end;
            continue;
        }
        /* retry, unless 12 failed in a row or the step has come down to 1/4096 of the rule
           (failures between successes: the scene needs a step the rule does not give, and a
           run of ever smaller steps would only spend the sub-step budget) */
        if ((s == SPH_ERR_UNSTABLE || s == SPH_ERR_NOT_CONVERGED) && in_row < SPH__RETRIES &&
            0.5 * fmin(w->stats.dt_factor, dt / dt_stable) >= 1.0 / 4096) {
            sph__snapshot_restore(w, first ? first_slot : 1);
            ++retries;
            ++in_row;
            w->stats.dt_factor = 0.5 * fmin(w->stats.dt_factor, dt / dt_stable);
            continue;
        }
        /* a sub-step that fails at every step from its start may start from a state an earlier
           sub-step left beyond repair (an accepted step whose actual densities came out beyond
           what its linearised prediction showed: IISPH at a 1 % tolerance put a particle 20 %
           over rest density, and every retry of the next sub-step failed on it): the whole call
           is taken again from its start, at a quarter of the step it began with, at most twice */
        if ((s == SPH_ERR_UNSTABLE || s == SPH_ERR_NOT_CONVERGED) && !first && restarts < 2) {
            sph__snapshot_restore(w, 0);
            ++restarts;
            ++retries;
            in_row = 0;
            first = 1;
            first_slot = 0; /* snap[1] holds a later sub-step's start now */
            factor0 *= 0.25;
            w->stats.dt_factor = factor0;
            continue;
        }
        {
            char msg[SPH_ERROR_SIZE];
            long idx;
            const double factor = 0.5 * fmin(w->stats.dt_factor, dt / dt_stable);
            const int early = placed && w->steps - steps0 <= 10; /* within 10 steps of the adding */
            double t;
            memcpy(msg, w->error, sizeof msg);
            idx = sph__restore_named(w, 0);
            w->stats.substeps = substeps;
            w->stats.retries = retries;
            w->stats.iterations_sum = iterations;
            w->stats.dt_min = dt_min;
            w->stats.dt_factor = factor; /* the next call starts from the step that failed, halved */
            t = w->time;
            if (s == SPH_ERR_UNSTABLE || s == SPH_ERR_NOT_CONVERGED)
                return sph__fail(w, s, idx,
                                 "sph_advance: the sub-step failed (%d in a row), the last at dt "
                                 "= %g s (%g of the stable step); the world is as before the "
                                 "call (t = %g s).%s Last failure: %s",
                                 in_row + 1, dt, dt / dt_stable, t,
                                 early ? " Fluid or walls were added just before the call: "
                                          "do they overlap (fluid closer than a spacing to walls "
                                          "or to other fluid starts compressed)?"
                                        : "",
                                 msg);
            w->status = s; /* other errors keep their own message */
            memcpy(w->error, msg, sizeof msg);
            w->error_index = idx;
            return s;
        }
    }
    w->stats.substeps = substeps;
    w->stats.retries = retries;
    w->stats.iterations_sum = iterations;
    w->stats.dt_min = dt_min;
    return SPH_OK;
}

/* ============================================================================================== */
/* >>io (implementation)                                                                          */
/* ============================================================================================== */

SPHDEF sph_status sph_write_csv(const sph_world* w, const char* path) {
    const char* names = "xyz";
    FILE* f;
    size_t i;
    int k;
    if (!w || !path) return SPH_ERR_ARG;
    f = fopen(path, "w");
    if (!f) return SPH_ERR_IO;
    fprintf(f, "id,phase");
    for (k = 0; k < w->dim; ++k) fprintf(f, ",%c", names[k]);
    for (k = 0; k < w->dim; ++k) fprintf(f, ",v%c", names[k]);
    fprintf(f, w->e ? ",rho,p,e\n" : ",rho,p\n");
    for (i = 0; i < w->n; ++i) {
        fprintf(f, "%u,%u", (unsigned)w->id[i], (unsigned)w->phase[i]);
        for (k = 0; k < w->dim; ++k) fprintf(f, ",%.9g", (double)w->x[i * (size_t)w->dim + (size_t)k]);
        for (k = 0; k < w->dim; ++k) fprintf(f, ",%.9g", (double)w->v[i * (size_t)w->dim + (size_t)k]);
        fprintf(f, ",%.9g,%.9g", (double)w->rho[i], (double)w->p[i]);
        if (w->e) fprintf(f, ",%.9g", (double)w->e[i]);
        fputc('\n', f);
    }
    if (ferror(f)) { fclose(f); return SPH_ERR_IO; }
    return fclose(f) == 0 ? SPH_OK : SPH_ERR_IO;
}

/* VTK XML unstructured grid (.vtu), "raw appended" binary: the XML header declares every array
   with its byte offset into the block after <AppendedData encoding="raw"> _ ; each array there is
   a UInt64 byte count followed by the values in the machine's byte order. The values are written
   in chunks through a small buffer on the stack, so writing allocates nothing. */
#define SPH__VTU_CHUNK 512

/* A wall particle's density for output: its extrapolated rho_b / rho0 times the rest density of
   phase 0 (with several phases each phase sees its own wall density; phase 0's is written). */
static sph_real sph__wall_density(const sph_world* w, size_t b) {
    return w->b_rho[b] * (w->nphase > 0 ? w->phases[0].rest_density : (sph_real)1);
}

typedef struct sph__vtu {
    FILE* f;
    const sph_world* w;
    size_t n;           /* fluid + boundary particles                                      */
    uint64_t offset;    /* running offset of the next array in the appended block [bytes] */
} sph__vtu;

enum { SPH__VTU_POS, SPH__VTU_VEL, SPH__VTU_RHO, SPH__VTU_P, SPH__VTU_E, SPH__VTU_ID,
       SPH__VTU_PHASE, SPH__VTU_KIND, SPH__VTU_BODY, SPH__VTU_CONN, SPH__VTU_OFFS,
       SPH__VTU_TYPES, SPH__VTU_COUNT };

/* VTK type name and bytes per component of array a. */
static const char* sph__vtu_type(const sph__vtu* o, int a, size_t* size) {
    switch (a) {
    case SPH__VTU_POS: case SPH__VTU_VEL: case SPH__VTU_RHO: case SPH__VTU_P: case SPH__VTU_E:
        *size = sizeof(sph_real);
        return sizeof(sph_real) == 4 ? "Float32" : "Float64";
    case SPH__VTU_ID: *size = 4; return "UInt32";
    case SPH__VTU_PHASE: case SPH__VTU_BODY: *size = 4; return "Int32";
    case SPH__VTU_KIND: case SPH__VTU_TYPES: *size = 1; return "UInt8";
    default: /* connectivity and offsets: 32 bits while they fit */
        *size = o->n < 0x7fffffffu ? 4 : 8;
        return *size == 4 ? "Int32" : "Int64";
    }
}

static int sph__vtu_comps(int a) { return a == SPH__VTU_POS || a == SPH__VTU_VEL ? 3 : 1; }

static void sph__vtu_decl(sph__vtu* o, int a, const char* name) {
    size_t size;
    const char* type = sph__vtu_type(o, a, &size);
    const int nc = sph__vtu_comps(a);
    fprintf(o->f, "        <DataArray type=\"%s\"", type);
    if (name) fprintf(o->f, " Name=\"%s\"", name);
    if (nc > 1) fprintf(o->f, " NumberOfComponents=\"%d\"", nc);
    fprintf(o->f, " format=\"appended\" offset=\"%llu\"/>\n", (unsigned long long)o->offset);
    o->offset += 8 + (uint64_t)o->n * (uint64_t)nc * (uint64_t)size;
}

/* Component c of array a at particle i (fluid first, then boundary), as the bytes of its type. */
static void sph__vtu_value(const sph__vtu* o, int a, size_t i, int c, size_t size,
                           unsigned char* out) {
    const sph_world* w = o->w;
    const size_t d = (size_t)w->dim;
    const int fluid = i < w->n;
    const size_t b = fluid ? 0 : i - w->n;
    sph_real r = 0;
    uint32_t u = 0;
    int32_t s = 0;
    int64_t l = 0;
    int32_t l4 = 0;
    unsigned char k = 0;
    switch (a) {
    case SPH__VTU_POS:
        if ((size_t)c < d) r = fluid ? w->x[i * d + (size_t)c] : w->b_x[b * d + (size_t)c];
        memcpy(out, &r, sizeof r); return;
    case SPH__VTU_VEL:
        if ((size_t)c < d) r = fluid ? w->v[i * d + (size_t)c] : w->b_v[b * d + (size_t)c];
        memcpy(out, &r, sizeof r); return;
    case SPH__VTU_RHO: r = fluid ? w->rho[i] : sph__wall_density(w, b);
        memcpy(out, &r, sizeof r); return;
    case SPH__VTU_P: r = fluid ? w->p[i] : w->b_p[b]; memcpy(out, &r, sizeof r); return;
    case SPH__VTU_E: r = fluid && w->e ? w->e[i] : 0; memcpy(out, &r, sizeof r); return;
    case SPH__VTU_ID: u = fluid ? w->id[i] : w->b_id[b]; memcpy(out, &u, 4); return;
    case SPH__VTU_PHASE: s = fluid ? (int32_t)w->phase[i] : -1; memcpy(out, &s, 4); return;
    case SPH__VTU_BODY: s = fluid ? -1 : (int32_t)w->b_body[b]; memcpy(out, &s, 4); return;
    case SPH__VTU_KIND: k = (unsigned char)(fluid ? 0 : 1); *out = k; return;
    case SPH__VTU_TYPES: *out = 1; return; /* VTK_VERTEX */
    default: /* connectivity i, offsets i + 1 (where each one-point cell ends) */
        l = (int64_t)i + (a == SPH__VTU_OFFS);
        l4 = (int32_t)l;
        if (size == 4) memcpy(out, &l4, 4);
        else memcpy(out, &l, 8);
        return;
    }
}

static void sph__vtu_data(sph__vtu* o, int a) {
    unsigned char buf[SPH__VTU_CHUNK * 8];
    size_t size, i, fill = 0;
    const int nc = sph__vtu_comps(a);
    uint64_t bytes;
    int c;
    (void)sph__vtu_type(o, a, &size);
    bytes = (uint64_t)o->n * (uint64_t)nc * (uint64_t)size;
    fwrite(&bytes, 8, 1, o->f);
    for (i = 0; i < o->n; ++i)
        for (c = 0; c < nc; ++c) {
            sph__vtu_value(o, a, i, c, size, buf + fill);
            fill += size;
            if (fill + 8 > sizeof buf) { fwrite(buf, 1, fill, o->f); fill = 0; }
        }
    if (fill) fwrite(buf, 1, fill, o->f);
}

SPHDEF sph_status sph_write_vtu(const sph_world* w, const char* path) {
    static const char* const names[SPH__VTU_COUNT] = {
        NULL, "velocity", "density", "pressure", "internal_energy", "id", "phase", "kind", "body",
        "connectivity", "offsets", "types"};
    const uint16_t one = 1;
    unsigned char first;
    sph__vtu o;
    int a;
    if (!w || !path) return SPH_ERR_ARG;
    o.f = fopen(path, "wb");
    if (!o.f) return SPH_ERR_IO;
    o.w = w;
    o.n = w->n + w->nb;
    o.offset = 0;
    memcpy(&first, &one, 1);
    fprintf(o.f, "<?xml version=\"1.0\"?>\n<!-- sph.h particles: fluid first, then boundary -->\n"
                 "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"%s\" "
                 "header_type=\"UInt64\">\n  <UnstructuredGrid>\n    <FieldData>\n"
                 "      <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" "
                 "format=\"ascii\">%.17g</DataArray>\n    </FieldData>\n"
                 "    <Piece NumberOfPoints=\"%llu\" NumberOfCells=\"%llu\">\n"
                 "      <PointData Scalars=\"density\" Vectors=\"velocity\">\n",
            first ? "LittleEndian" : "BigEndian", w->time, (unsigned long long)o.n,
            (unsigned long long)o.n);
    for (a = SPH__VTU_VEL; a <= SPH__VTU_BODY; ++a)
        if (a != SPH__VTU_E || w->e) sph__vtu_decl(&o, a, names[a]);
    fprintf(o.f, "      </PointData>\n      <Points>\n");
    sph__vtu_decl(&o, SPH__VTU_POS, NULL);
    fprintf(o.f, "      </Points>\n      <Cells>\n");
    for (a = SPH__VTU_CONN; a <= SPH__VTU_TYPES; ++a) sph__vtu_decl(&o, a, names[a]);
    fprintf(o.f, "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n"
                 "  <AppendedData encoding=\"raw\">\n   _");
    /* the same order as declared */
    for (a = SPH__VTU_VEL; a <= SPH__VTU_BODY; ++a)
        if (a != SPH__VTU_E || w->e) sph__vtu_data(&o, a);
    sph__vtu_data(&o, SPH__VTU_POS);
    for (a = SPH__VTU_CONN; a <= SPH__VTU_TYPES; ++a) sph__vtu_data(&o, a);
    fprintf(o.f, "\n  </AppendedData>\n</VTKFile>\n");
    if (ferror(o.f)) { fclose(o.f); return SPH_ERR_IO; }
    return fclose(o.f) == 0 ? SPH_OK : SPH_ERR_IO;
}

/* The .pvd ends with this footer; a new frame overwrites it with its entry and the footer again,
   so the file is a complete collection after every frame without keeping state between calls. */
static const char sph__pvd_footer[] = "  </Collection>\n</VTKFile>\n";

SPHDEF sph_status sph_write_vtu_series(const sph_world* w, const char* base, int frame) {
    char vtu[4096], pvd[4096], tail[sizeof sph__pvd_footer];
    const size_t flen = sizeof sph__pvd_footer - 1;
    const char* name = base;
    const char* c;
    FILE* f = NULL;
    sph_status s;
    int len;
    if (!w || !base || frame < 0) return SPH_ERR_ARG;
    for (c = base; *c; ++c)
        if (*c == '/' || *c == '\\') name = c + 1;
    len = snprintf(vtu, sizeof vtu, "%s_%04d.vtu", base, frame);
    if (len < 0 || (size_t)len >= sizeof vtu) return SPH_ERR_ARG;
    len = snprintf(pvd, sizeof pvd, "%s.pvd", base);
    if (len < 0 || (size_t)len >= sizeof pvd) return SPH_ERR_ARG;
    if (frame > 0) {
        /* extend an existing collection: its last bytes must be our footer (checked before the
           frame is written, so a refused call writes nothing) */
        f = fopen(pvd, "r+b");
        if (!f) return SPH_ERR_IO;
        if (fseek(f, -(long)flen, SEEK_END) != 0 || fread(tail, 1, flen, f) != flen ||
            memcmp(tail, sph__pvd_footer, flen) != 0 || fseek(f, -(long)flen, SEEK_END) != 0) {
            fclose(f);
            return SPH_ERR_IO;
        }
    }
    s = sph_write_vtu(w, vtu);
    if (s != SPH_OK) {
        if (f) fclose(f);
        return s;
    }
    if (frame == 0) {
        f = fopen(pvd, "wb");
        if (!f) return SPH_ERR_IO;
        fprintf(f, "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n"
                   "  <Collection>\n");
    }
    fprintf(f, "    <DataSet timestep=\"%.17g\" part=\"0\" file=\"%s_%04d.vtu\"/>\n", w->time,
            name, frame);
    fputs(sph__pvd_footer, f);
    if (ferror(f)) { fclose(f); return SPH_ERR_IO; }
    return fclose(f) == 0 ? SPH_OK : SPH_ERR_IO;
}

SPHDEF sph_status sph_write_vtk(const sph_world* w, const char* path) {
    FILE* f;
    size_t i, n;
    int k;
    if (!w || !path) return SPH_ERR_ARG;
    f = fopen(path, "w");
    if (!f) return SPH_ERR_IO;
    n = w->n + w->nb;
    fprintf(f, "# vtk DataFile Version 3.0\nsph.h particles t=%.9g\nASCII\nDATASET UNSTRUCTURED_GRID\n",
            w->time);
    fprintf(f, "POINTS %zu double\n", n);
    for (i = 0; i < n; ++i) {
        const sph_real* x = i < w->n ? w->x + i * (size_t)w->dim : w->b_x + (i - w->n) * (size_t)w->dim;
        for (k = 0; k < 3; ++k) fprintf(f, "%.9g%c", k < w->dim ? (double)x[k] : 0.0, k < 2 ? ' ' : '\n');
    }
    fprintf(f, "CELLS %zu %zu\n", n, 2 * n);
    for (i = 0; i < n; ++i) fprintf(f, "1 %zu\n", i);
    fprintf(f, "CELL_TYPES %zu\n", n);
    for (i = 0; i < n; ++i) fprintf(f, "1\n");
    fprintf(f, "POINT_DATA %zu\nSCALARS kind int 1\nLOOKUP_TABLE default\n", n);
    for (i = 0; i < n; ++i) fprintf(f, "%d\n", i < w->n ? 0 : 1);
    fprintf(f, "SCALARS id int 1\nLOOKUP_TABLE default\n");
    for (i = 0; i < n; ++i) fprintf(f, "%u\n", i < w->n ? (unsigned)w->id[i] : (unsigned)w->b_id[i - w->n]);
    fprintf(f, "SCALARS phase int 1\nLOOKUP_TABLE default\n");
    for (i = 0; i < n; ++i) fprintf(f, "%d\n", i < w->n ? (int)w->phase[i] : -1);
    fprintf(f, "SCALARS density double 1\nLOOKUP_TABLE default\n");
    for (i = 0; i < n; ++i)
        fprintf(f, "%.9g\n", i < w->n ? (double)w->rho[i] : (double)sph__wall_density(w, i - w->n));
    fprintf(f, "SCALARS pressure double 1\nLOOKUP_TABLE default\n");
    for (i = 0; i < n; ++i) fprintf(f, "%.9g\n", i < w->n ? (double)w->p[i] : (double)w->b_p[i - w->n]);
    if (w->e) {
        fprintf(f, "SCALARS internal_energy double 1\nLOOKUP_TABLE default\n");
        for (i = 0; i < n; ++i) fprintf(f, "%.9g\n", i < w->n ? (double)w->e[i] : 0.0);
    }
    fprintf(f, "VECTORS velocity double\n");
    for (i = 0; i < n; ++i) {
        const sph_real* v = i < w->n ? w->v + i * (size_t)w->dim : w->b_v + (i - w->n) * (size_t)w->dim;
        for (k = 0; k < 3; ++k) fprintf(f, "%.9g%c", k < w->dim ? (double)v[k] : 0.0, k < 2 ? ' ' : '\n');
    }
    if (ferror(f)) { fclose(f); return SPH_ERR_IO; }
    return fclose(f) == 0 ? SPH_OK : SPH_ERR_IO;
}


/* ---- save / restore ------------------------------------------------------------------------ */

/* Where the bytes go: counted always, hashed (FNV-1a 64), copied to buf while they fit, or
   written to f. */
typedef struct sph__sink {
    unsigned char* buf;
    size_t cap, pos;
    FILE* f;
    uint64_t hash;
    int err;
} sph__sink;

#define SPH__SAVE_VERSION 3u /* 2: sph_stats.potential_energy; 3: sph_stats.enclosed */
#define SPH__FNV_OFFSET 14695981039346656037ull
#define SPH__FNV_PRIME 1099511628211ull

static uint64_t sph__fnv(uint64_t h, const void* data, size_t n) {
    const unsigned char* p = (const unsigned char*)data;
    size_t i;
    for (i = 0; i < n; ++i) h = (h ^ p[i]) * SPH__FNV_PRIME;
    return h;
}

static void sph__put(sph__sink* o, const void* data, size_t n) {
    if (n == 0) return;
    o->hash = sph__fnv(o->hash, data, n);
    if (o->f) {
        if (fwrite(data, 1, n, o->f) != n) o->err = 1;
    } else if (o->buf && o->pos + n <= o->cap) {
        memcpy(o->buf + o->pos, data, n);
    }
    o->pos += n;
}

static void sph__put_u64(sph__sink* o, uint64_t v) { sph__put(o, &v, 8); }
static void sph__put_u32(sph__sink* o, uint32_t v) { sph__put(o, &v, 4); }

/* The second-order scheme's lists are state: kept lists decide the next steps' summation order
   (and when the particles are sorted), so a restart must reuse them to stay bitwise identical. */
static int sph__soc_lists_saved(const sph_world* w) {
    return w->def.scheme == SPH_SCHEME_SECOND_ORDER && w->priv.snl_valid &&
           w->priv.snl_sorts == w->priv.sorts && w->priv.snl.n == w->n && w->priv.soc != NULL;
}

/* Header and payload; the payload layout (after the fixed header):
     def (callback and user pointers zeroed), nphase, phases, time, steps, timings, counters,
     stats, every fluid array (elem size, n * elem bytes), every boundary array, then the
     second-order lists (flag; total, xref, count, idx), then def.neighbor_skin's candidate
     lists (flag; radius, the fluid and boundary positions of their search). The checksum
     follows. */
static void sph__save(const sph_world* w, sph__sink* o) {
    sph_world_def def = w->def;
    sph__array arr[16];
    const size_t n = w->n, nb = w->nb, D = (size_t)w->dim;
    /* the array lists take a non-const world but only read the pointers here */
    sph_world* ww = (sph_world*)(uintptr_t)w;
    const uint32_t bom = 0x01020304u;
    int k, na;
    def.force = NULL;
    def.force_user = NULL;
    def.boundary_motion = NULL;
    def.boundary_user = NULL;
    o->hash = SPH__FNV_OFFSET;
    sph__put(o, "SPHWORLD", 8);
    sph__put_u32(o, SPH__SAVE_VERSION);
    sph__put_u32(o, bom);
    sph__put_u32(o, (uint32_t)sizeof(sph_real));
    sph__put_u32(o, (uint32_t)sizeof(sph_world_def));
    sph__put_u32(o, (uint32_t)sizeof(sph_phase));
    sph__put_u32(o, (uint32_t)sizeof(sph_stats));
    sph__put_u32(o, (uint32_t)SPH_MAX_PHASES);
    sph__put_u32(o, (uint32_t)SPH_STAGE_COUNT);
    sph__put(o, &def, sizeof def);
    sph__put_u32(o, (uint32_t)w->nphase);
    sph__put(o, w->phases, (size_t)w->nphase * sizeof(sph_phase));
    sph__put(o, &w->time, sizeof w->time);
    sph__put_u64(o, w->steps);
    sph__put(o, &w->step_time_total, sizeof w->step_time_total);
    sph__put(o, w->stage_time_total, sizeof w->stage_time_total);
    sph__put_u64(o, (uint64_t)n);
    sph__put_u64(o, (uint64_t)nb);
    sph__put_u32(o, w->next_id);
    sph__put_u32(o, w->b_next_id);
    sph__put_u32(o, (uint32_t)(w->m != NULL));
    sph__put_u32(o, (uint32_t)w->priv.have_mass);
    sph__put(o, &w->mass, sizeof w->mass);
    sph__put(o, &w->stats, sizeof w->stats);
    na = sph__fluid_arrays(ww, arr);
    sph__put_u32(o, (uint32_t)na);
    for (k = 0; k < na; ++k) {
        sph__put_u32(o, (uint32_t)arr[k].elem);
        sph__put(o, *arr[k].ptr, n * arr[k].elem);
    }
    na = sph__boundary_arrays(ww, arr);
    sph__put_u32(o, (uint32_t)na);
    for (k = 0; k < na; ++k) {
        sph__put_u32(o, (uint32_t)arr[k].elem);
        sph__put(o, *arr[k].ptr, nb * arr[k].elem);
    }
    if (sph__soc_lists_saved(w)) {
        const sph_neighbors* nl = &w->priv.snl;
        const size_t DD = D * D;
        /* xref is the last block of the scheme's scratch (see sph__soc) */
        const sph_real* xref = w->priv.soc + w->capacity * (3 + 5 * D + DD);
        size_t i;
        sph__put_u32(o, 1);
        sph__put_u64(o, (uint64_t)nl->total);
        sph__put(o, xref, n * D * sizeof(sph_real));
        sph__put(o, nl->count, n * sizeof(uint32_t));
        for (i = 0; i < n; ++i) sph__put(o, nl->idx + nl->begin[i], nl->count[i] * sizeof(uint32_t));
    } else {
        sph__put_u32(o, 0);
    }
    /* def.neighbor_skin's candidate lists are state too (they decide when the particles are
       sorted next): the positions they were searched at, from which a load searches them again
       without sorting (sph__verlet_restore) */
    if (((w->priv.vl_valid && w->priv.vl_sorts == w->priv.sorts) || w->priv.vl_restore) &&
        w->priv.vl_n == n && w->priv.vl_nb == nb) {
        sph__put_u32(o, 1);
        sph__put(o, &w->priv.vl_radius, sizeof(sph_real));
        sph__put(o, w->priv.vl_x, n * D * sizeof(sph_real));
        sph__put(o, w->priv.vl_bx, nb * D * sizeof(sph_real));
    } else {
        sph__put_u32(o, 0);
    }
}

SPHDEF size_t sph_world_save_mem(const sph_world* w, void* buf, size_t cap) {
    sph__sink o;
    uint64_t h;
    if (!w) return 0;
    memset(&o, 0, sizeof o);
    sph__save(w, &o); /* size first: nothing is written unless all of it fits */
    if (!buf || cap < o.pos + 8) return o.pos + 8;
    memset(&o, 0, sizeof o);
    o.buf = (unsigned char*)buf;
    o.cap = cap;
    sph__save(w, &o);
    h = o.hash;
    memcpy(o.buf + o.pos, &h, 8);
    return o.pos + 8;
}

SPHDEF sph_status sph_world_save(const sph_world* w, const char* path) {
    sph__sink o;
    uint64_t h;
    if (!w || !path) return SPH_ERR_ARG;
    memset(&o, 0, sizeof o);
    o.f = fopen(path, "wb");
    if (!o.f) return SPH_ERR_IO;
    sph__save(w, &o);
    h = o.hash;
    if (fwrite(&h, 1, 8, o.f) != 8) o.err = 1;
    if (ferror(o.f)) o.err = 1;
    if (fclose(o.f) != 0) o.err = 1;
    return o.err ? SPH_ERR_IO : SPH_OK;
}

/* Reading: a bounds-checked cursor over the bytes. */
typedef struct sph__src {
    const unsigned char* p;
    size_t size, pos;
} sph__src;

static int sph__get(sph__src* in, void* dst, size_t n) {
    if (n > in->size - in->pos) return 0;
    if (n) memcpy(dst, in->p + in->pos, n);
    in->pos += n;
    return 1;
}

static sph_status sph__load_fail(sph_world* w, sph_status s, const char* fmt, ...) {
    char msg[SPH_ERROR_SIZE];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    sph_world_free(w);
    return sph__fail(w, s, -1, "sph_world_load: %s", msg);
}

/* A loaded world is checked field by field with the rules of the API that sets each field
   (sph_world_init for the def, sph_world_add_phase for the phases, sph_add_fluid_ex and
   sph_add_boundary for the particles, the step's input check for what the host may write): the
   checksum only catches accidents, a file written by another program (or edited) must not
   reach a step with values the API would have refused. On a failure the world is freed and the
   message of the failed rule kept, prefixed with `prefix` (which names the phase or array). */
static sph_status sph__load_reject(sph_world* w, const char* prefix) {
    char msg[SPH_ERROR_SIZE];
    const long index = w->error_index;
    const sph_status s = w->status;
    memcpy(msg, w->error, sizeof msg);
    sph_world_free(w);
    return sph__fail(w, s, index, "%s%s", prefix, msg);
}

static int sph__u32_cmp(const void* a, const void* b) {
    const uint32_t x = *(const uint32_t*)a, y = *(const uint32_t*)b;
    return x < y ? -1 : x > y;
}

/* Ids are unique and below the next id to hand out (else a later particle would share one). */
static sph_status sph__check_ids(sph_world* w, const char* what, const uint32_t* id, size_t n,
                                 uint32_t next) {
    uint32_t* sorted;
    size_t i;
    for (i = 0; i < n; ++i)
        if (id[i] >= next)
            return sph__fail(w, SPH_ERR_ARG, (long)i,
                             "sph_world_load: %s particle %zu has id %u, not below the next id %u",
                             what, i, (unsigned)id[i], (unsigned)next);
    if (n < 2) return SPH_OK;
    sorted = (uint32_t*)SPH_MALLOC(n * sizeof(uint32_t));
    if (!sorted) return sph__fail(w, SPH_ERR_NOMEM, -1, "sph_world_load: out of memory (ids)");
    memcpy(sorted, id, n * sizeof(uint32_t));
    qsort(sorted, n, sizeof(uint32_t), sph__u32_cmp);
    for (i = 1; i < n && sorted[i] != sorted[i - 1]; ++i) {}
    if (i < n) {
        const uint32_t dup = sorted[i];
        SPH_FREE(sorted);
        for (i = 0; id[i] != dup; ++i) {}
        return sph__fail(w, SPH_ERR_ARG, (long)i,
                         "sph_world_load: %s particle %zu has id %u, which another particle "
                         "has too", what, i, (unsigned)dup);
    }
    SPH_FREE(sorted);
    return SPH_OK;
}

/* Every value of a real array finite (name: the array, for the message). */
static sph_status sph__check_loaded_finite(sph_world* w, const char* name, const sph_real* a,
                                           size_t count, size_t stride) {
    size_t bad = 0;
    if (count && !sph__all_finite(a, count, &bad))
        return sph__fail(w, SPH_ERR_ARG, (long)(bad / stride),
                         "sph_world_load: %s of particle %zu is not finite (%g)", name,
                         bad / stride, (double)a[bad]);
    return SPH_OK;
}

/* The fields of a loaded world beyond the def and the phases (which the loader checks as it
   reads them). */
static sph_status sph__check_loaded(sph_world* w) {
    const size_t D = (size_t)w->dim, n = w->n, nb = w->nb;
    const double* st[10];
    size_t i;
    sph_status s;
    int k;
    if (!sph__finite(w->time))
        return sph__fail(w, SPH_ERR_ARG, -1, "sph_world_load: time = %g: must be finite", w->time);
    if (!sph__finite(w->step_time_total) || w->step_time_total < 0)
        return sph__fail(w, SPH_ERR_ARG, -1, "sph_world_load: step_time_total = %g: must be "
                         "finite and >= 0", w->step_time_total);
    for (k = 0; k < SPH_STAGE_COUNT; ++k)
        if (!sph__finite(w->stage_time_total[k]) || w->stage_time_total[k] < 0)
            return sph__fail(w, SPH_ERR_ARG, -1, "sph_world_load: stage_time_total[%d] = %g: must "
                             "be finite and >= 0", k, w->stage_time_total[k]);
    /* the statistics: sph_stable_dt reads a_max (the force limit) */
    st[0] = &w->stats.dt; st[1] = &w->stats.solver_error; st[2] = &w->stats.density_error_avg;
    st[3] = &w->stats.density_error_max; st[4] = &w->stats.compression_avg;
    st[5] = &w->stats.v_max; st[6] = &w->stats.a_max; st[7] = &w->stats.kinetic_energy;
    st[8] = &w->stats.step_time; st[9] = &w->stats.potential_energy;
    for (k = 0; k < 10; ++k)
        if (!sph__finite(*st[k]) || (k >= 5 && k < 9 && *st[k] < 0))
            return sph__fail(w, SPH_ERR_ARG, -1, "sph_world_load: stats field %d = %g: must be "
                             "finite%s", k, *st[k], k >= 5 && k < 9 ? " and >= 0" : "");
    if (n > 0 && !w->priv.have_mass)
        return sph__fail(w, SPH_ERR_ARG, -1, "sph_world_load: %zu fluid particles but no mass", n);
    if (w->priv.have_mass && (!sph__finite((double)w->mass) || !(w->mass > 0)))
        return sph__fail(w, SPH_ERR_ARG, -1, "sph_world_load: mass = %g: must be finite and > 0",
                         (double)w->mass);
    /* the rules of sph_add_fluid_ex: positions (finite, near enough to the origin), velocities,
       masses, densities */
    if ((s = sph__check_fluid(w, "sph_world_load", n, w->x, w->v, w->m, w->rho)) != SPH_OK)
        return s;
    for (i = 0; i < n; ++i)
        if (w->phase[i] >= w->nphase)
            return sph__fail(w, SPH_ERR_ARG, (long)i, "sph_world_load: particle %zu has phase %u: "
                             "phase %u does not exist (the world has %d phases)", i,
                             (unsigned)w->phase[i], (unsigned)w->phase[i], w->nphase);
    if ((s = sph__check_loaded_finite(w, "pressure", w->p, n, 1)) != SPH_OK ||
        (s = sph__check_loaded_finite(w, "density rate", w->drho, n, 1)) != SPH_OK ||
        (s = sph__check_loaded_finite(w, "acceleration", w->a, n * D, D)) != SPH_OK ||
        (w->e && (s = sph__check_loaded_finite(w, "internal energy", w->e, n, 1)) != SPH_OK))
        return s;
    if ((s = sph__check_ids(w, "fluid", w->id, n, w->next_id)) != SPH_OK) return s;
    /* the rules of sph_add_boundary (body tags are 16 bits: always in range) */
    if ((s = sph__check_boundary(w, "sph_world_load", nb, w->b_x, w->b_vol, 0)) != SPH_OK ||
        (s = sph__check_loaded_finite(w, "boundary velocity", w->b_v, nb * D, D)) != SPH_OK ||
        (s = sph__check_loaded_finite(w, "boundary acceleration", w->b_a, nb * D, D)) != SPH_OK ||
        (s = sph__check_loaded_finite(w, "boundary b_x0", w->b_x0, nb * D, D)) != SPH_OK ||
        (s = sph__check_loaded_finite(w, "boundary pressure", w->b_p, nb, 1)) != SPH_OK ||
        (s = sph__check_loaded_finite(w, "boundary density", w->b_rho, nb, 1)) != SPH_OK ||
        (s = sph__check_loaded_finite(w, "boundary b_vw", w->b_vw, nb * D, D)) != SPH_OK ||
        (s = sph__check_loaded_finite(w, "boundary b_sw", w->priv.b_sw, nb, 1)) != SPH_OK)
        return s;
    return sph__check_ids(w, "boundary", w->b_id, nb, w->b_next_id);
}

SPHDEF sph_status sph_world_load_mem(sph_world* w, const void* buf, size_t size,
                                     const sph_world_def* callbacks) {
    sph__src in;
    sph_world_def def;
    sph__array arr[16];
    char magic[8];
    uint32_t u[8], nphase, has_m, have_mass, na, soc;
    uint64_t h, n64, nb64, steps;
    size_t n, nb, i;
    sph_status s;
    int k;
    if (!w) return SPH_ERR_ARG;
    memset(w, 0, sizeof *w);
    w->error_index = -1;
    if (!buf) return sph__load_fail(w, SPH_ERR_ARG, "buffer is NULL");
    in.p = (const unsigned char*)buf;
    in.size = size;
    in.pos = 0;
    if (!sph__get(&in, magic, 8) || memcmp(magic, "SPHWORLD", 8) != 0)
        return sph__load_fail(w, SPH_ERR_IO, "not an sph.h world file (no SPHWORLD magic)");
    if (!sph__get(&in, u, sizeof u)) return sph__load_fail(w, SPH_ERR_IO, "truncated header");
    if (u[0] != SPH__SAVE_VERSION)
        return sph__load_fail(w, SPH_ERR_IO, "format version %u, this sph.h reads version %u",
                              (unsigned)u[0], SPH__SAVE_VERSION);
    if (u[1] != 0x01020304u)
        return sph__load_fail(w, SPH_ERR_IO, "written on a machine of the other byte order");
    if (u[2] != sizeof(sph_real))
        return sph__load_fail(w, SPH_ERR_IO, "written with %u-byte reals, this build has %u (%s)",
                              (unsigned)u[2], (unsigned)sizeof(sph_real),
                              sizeof(sph_real) == 4 ? "SPH_FLOAT" : "double");
    if (u[3] != sizeof(sph_world_def) || u[4] != sizeof(sph_phase) || u[5] != sizeof(sph_stats) ||
        u[6] != SPH_MAX_PHASES || u[7] != SPH_STAGE_COUNT)
        return sph__load_fail(w, SPH_ERR_IO, "written by a different build of sph.h (struct sizes "
                              "or SPH_MAX_PHASES differ)");
    if (size < 8 + sizeof u + 8) return sph__load_fail(w, SPH_ERR_IO, "truncated");
    memcpy(&h, in.p + size - 8, 8);
    if (sph__fnv(SPH__FNV_OFFSET, in.p, size - 8) != h)
        return sph__load_fail(w, SPH_ERR_IO, "checksum mismatch (truncated or corrupted file)");
    in.size = size - 8;
    if (!sph__get(&in, &def, sizeof def)) return sph__load_fail(w, SPH_ERR_IO, "truncated def");
    def.force = callbacks ? callbacks->force : NULL;
    def.force_user = callbacks ? callbacks->force_user : NULL;
    def.boundary_motion = callbacks ? callbacks->boundary_motion : NULL;
    def.boundary_user = callbacks ? callbacks->boundary_user : NULL;
    s = sph_world_init(w, &def); /* validates every field */
    if (s != SPH_OK) {
        char msg[SPH_ERROR_SIZE];
        memcpy(msg, w->error, sizeof msg);
        return sph__load_fail(w, s, "the saved def is invalid: %s", msg);
    }
    if (!sph__get(&in, &nphase, 4) || nphase > SPH_MAX_PHASES)
        return sph__load_fail(w, SPH_ERR_IO, "bad phase count");
    if (!sph__get(&in, w->phases, nphase * sizeof(sph_phase)))
        return sph__load_fail(w, SPH_ERR_IO, "truncated phases");
    w->nphase = (int)nphase;
    for (k = 0; k < w->nphase; ++k) {
        sph_phase P = w->phases[k];
        if (sph__check_phase_fields(w, &P, 1) != SPH_OK) {
            char prefix[48];
            snprintf(prefix, sizeof prefix, "sph_world_load: phase %d: ", k);
            return sph__load_reject(w, prefix);
        }
        if (P.eos == SPH_EOS_IDEAL_GAS || P.eos == SPH_EOS_STIFFENED_GAS) w->priv.has_energy = 1;
    }
    if (!sph__get(&in, &w->time, sizeof w->time) || !sph__get(&in, &steps, 8) ||
        !sph__get(&in, &w->step_time_total, sizeof w->step_time_total) ||
        !sph__get(&in, w->stage_time_total, sizeof w->stage_time_total) ||
        !sph__get(&in, &n64, 8) || !sph__get(&in, &nb64, 8) || !sph__get(&in, &w->next_id, 4) ||
        !sph__get(&in, &w->b_next_id, 4) || !sph__get(&in, &has_m, 4) ||
        !sph__get(&in, &have_mass, 4) || !sph__get(&in, &w->mass, sizeof w->mass) ||
        !sph__get(&in, &w->stats, sizeof w->stats))
        return sph__load_fail(w, SPH_ERR_IO, "truncated state");
    w->steps = steps;
    w->priv.have_mass = have_mass != 0;
    /* every array must be in the file, so the counts are bounded by its size */
    if (n64 > in.size || nb64 > in.size) return sph__load_fail(w, SPH_ERR_IO, "bad particle count");
    n = (size_t)n64;
    nb = (size_t)nb64;
    if (has_m && !sph__grow((void**)&w->m, 1, sizeof(sph_real)))
        return sph__load_fail(w, SPH_ERR_NOMEM, "out of memory");
    if ((s = sph__reserve(w, 0, n)) != SPH_OK || (s = sph__reserve(w, 1, nb)) != SPH_OK)
        return sph__load_fail(w, s, "out of memory for %zu + %zu particles", n, nb);
    for (k = 0; k < 2; ++k) {
        const size_t count = k ? nb : n;
        const int narr = k ? sph__boundary_arrays(w, arr) : sph__fluid_arrays(w, arr);
        int a;
        if (!sph__get(&in, &na, 4) || na != (uint32_t)narr)
            return sph__load_fail(w, SPH_ERR_IO, "the %s arrays do not match this build",
                                  k ? "boundary" : "fluid");
        for (a = 0; a < narr; ++a) {
            uint32_t elem;
            if (!sph__get(&in, &elem, 4) || elem != arr[a].elem)
                return sph__load_fail(w, SPH_ERR_IO, "array element size mismatch");
            if (count && !sph__get(&in, *arr[a].ptr, count * elem))
                return sph__load_fail(w, SPH_ERR_IO, "truncated particle arrays");
        }
    }
    w->n = n;
    w->nb = nb;
    if (sph__check_loaded(w) != SPH_OK) return sph__load_reject(w, "");
    w->priv.b_dirty = nb > 0; /* the boundary grid (and Akinci volumes) are rebuilt */
    w->priv.vl_valid = 0;
    if (!sph__get(&in, &soc, 4)) return sph__load_fail(w, SPH_ERR_IO, "truncated");
    if (soc) {
        sph_neighbors* nl = &w->priv.snl;
        sph__soc S;
        uint64_t total;
        size_t off = 0;
        if (def.scheme != SPH_SCHEME_SECOND_ORDER || !sph__get(&in, &total, 8) || total > in.size)
            return sph__load_fail(w, SPH_ERR_IO, "bad second-order lists");
        if ((s = sph__soc_scratch(w, &S)) != SPH_OK)
            return sph__load_fail(w, s, "out of memory");
        if (!sph__grow((void**)&nl->begin, n, sizeof(size_t)) ||
            !sph__grow((void**)&nl->count, n, sizeof(uint32_t)) ||
            !sph__grow((void**)&nl->idx, (size_t)total, sizeof(uint32_t)))
            return sph__load_fail(w, SPH_ERR_NOMEM, "out of memory");
        nl->cap_n = n > 0 ? n : 1;
        nl->cap_idx = total > 0 ? (size_t)total : 1;
        if (!sph__get(&in, S.xref, n * (size_t)w->dim * sizeof(sph_real)) ||
            !sph__get(&in, nl->count, n * sizeof(uint32_t)))
            return sph__load_fail(w, SPH_ERR_IO, "truncated second-order lists");
        for (i = 0; i < n; ++i) {
            nl->begin[i] = off;
            off += nl->count[i];
            if (off > total) return sph__load_fail(w, SPH_ERR_IO, "bad second-order lists");
        }
        if (off != total || !sph__get(&in, nl->idx, (size_t)total * sizeof(uint32_t)))
            return sph__load_fail(w, SPH_ERR_IO, "bad second-order lists");
        for (i = 0; i < (size_t)total; ++i)
            if (nl->idx[i] >= n) return sph__load_fail(w, SPH_ERR_IO, "bad second-order lists");
        nl->n = n;
        nl->total = (size_t)total;
        w->priv.snl_valid = 1;
        w->priv.snl_sorts = w->priv.sorts;
    }
    if (!sph__get(&in, &soc, 4) || soc > 1) return sph__load_fail(w, SPH_ERR_IO, "truncated");
    if (soc) {
        const size_t D = (size_t)w->dim;
        sph_real r;
        if (!sph__get(&in, &r, sizeof r) || !(r > w->kernel.radius) ||
            !(r <= 2 * w->kernel.radius))
            return sph__load_fail(w, SPH_ERR_IO, "bad neighbour list radius");
        if (!sph__grow((void**)&w->priv.vl_x, w->capacity * D, sizeof(sph_real)) ||
            !sph__grow((void**)&w->priv.vl_bx, w->b_capacity * D, sizeof(sph_real)))
            return sph__load_fail(w, SPH_ERR_NOMEM, "out of memory");
        w->priv.vl_x_cap = (w->capacity > 0 ? w->capacity : 1) * D;
        w->priv.vl_bx_cap = (w->b_capacity > 0 ? w->b_capacity : 1) * D;
        if (!sph__get(&in, w->priv.vl_x, n * D * sizeof(sph_real)) ||
            !sph__get(&in, w->priv.vl_bx, nb * D * sizeof(sph_real)))
            return sph__load_fail(w, SPH_ERR_IO, "truncated neighbour list positions");
        for (i = 0; i < (n + nb) * D; ++i)
            if (!sph__finite((double)(i < n * D ? w->priv.vl_x[i] : w->priv.vl_bx[i - n * D])))
                return sph__load_fail(w, SPH_ERR_IO, "bad neighbour list positions");
        w->priv.vl_restore = 1;
        w->priv.vl_radius = r;
        w->priv.vl_n = n;
        w->priv.vl_nb = nb;
    }
    if (in.pos != in.size) return sph__load_fail(w, SPH_ERR_IO, "%zu unread bytes", in.size - in.pos);
    w->status = SPH_OK;
    w->error[0] = 0;
    return SPH_OK;
}

SPHDEF sph_status sph_world_load(sph_world* w, const char* path, const sph_world_def* callbacks) {
    FILE* f;
    long size;
    void* buf;
    sph_status s;
    if (!w) return SPH_ERR_ARG;
    memset(w, 0, sizeof *w);
    w->error_index = -1;
    if (!path) return sph__fail(w, SPH_ERR_ARG, -1, "sph_world_load: path is NULL");
    f = fopen(path, "rb");
    if (!f) return sph__fail(w, SPH_ERR_IO, -1, "sph_world_load: cannot open %s", path);
    if (fseek(f, 0, SEEK_END) != 0 || (size = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0) {
        fclose(f);
        return sph__fail(w, SPH_ERR_IO, -1, "sph_world_load: cannot read %s", path);
    }
    buf = SPH_MALLOC(size > 0 ? (size_t)size : 1);
    if (!buf) {
        fclose(f);
        return sph__fail(w, SPH_ERR_NOMEM, -1, "sph_world_load: out of memory for %ld bytes", size);
    }
    if (fread(buf, 1, (size_t)size, f) != (size_t)size) {
        fclose(f);
        SPH_FREE(buf);
        return sph__fail(w, SPH_ERR_IO, -1, "sph_world_load: cannot read %s", path);
    }
    fclose(f);
    s = sph_world_load_mem(w, buf, (size_t)size, callbacks);
    SPH_FREE(buf);
    return s;
}

SPHDEF sph_status sph_world_copy(sph_world* dst, const sph_world* src) {
    size_t size;
    void* buf;
    sph_status s;
    if (!dst) return SPH_ERR_ARG;
    if (!src) {
        memset(dst, 0, sizeof *dst);
        dst->error_index = -1;
        return sph__fail(dst, SPH_ERR_ARG, -1, "sph_world_copy: src is NULL");
    }
    size = sph_world_save_mem(src, NULL, 0);
    buf = SPH_MALLOC(size);
    if (!buf) {
        memset(dst, 0, sizeof *dst);
        dst->error_index = -1;
        return sph__fail(dst, SPH_ERR_NOMEM, -1, "sph_world_copy: out of memory (%zu bytes)", size);
    }
    sph_world_save_mem(src, buf, size);
    s = sph_world_load_mem(dst, buf, size, &src->def);
    SPH_FREE(buf);
    if (s == SPH_OK) { /* the tank check's box (not in the file format) */
        memcpy(dst->priv.tank_lo, src->priv.tank_lo, sizeof dst->priv.tank_lo);
        memcpy(dst->priv.tank_hi, src->priv.tank_hi, sizeof dst->priv.tank_hi);
        dst->priv.tanks = src->priv.tanks;
    }
    return s;
}

#endif /* SPH__IMPLEMENTATION_ONCE */
#endif /* SPH_IMPLEMENTATION */

/*
------------------------------------------------------------------------------
MIT License

Copyright (c) 2026 the sph.h authors

Permission is hereby granted, free of charge, to any person obtaining a copy of
this software and associated documentation files (the "Software"), to deal in
the Software without restriction, including without limitation the rights to
use, copy, modify, merge, publish, distribute, sublicense, and/or sell copies
of the Software, and to permit persons to whom the Software is furnished to do
so, subject to the following conditions:

The above copyright notice and this permission notice shall be included in all
copies or substantial portions of the Software.

THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND, EXPRESS OR
IMPLIED, INCLUDING BUT NOT LIMITED TO THE WARRANTIES OF MERCHANTABILITY,
FITNESS FOR A PARTICULAR PURPOSE AND NONINFRINGEMENT. IN NO EVENT SHALL THE
AUTHORS OR COPYRIGHT HOLDERS BE LIABLE FOR ANY CLAIM, DAMAGES OR OTHER
LIABILITY, WHETHER IN AN ACTION OF CONTRACT, TORT OR OTHERWISE, ARISING FROM,
OUT OF OR IN CONNECTION WITH THE SOFTWARE OR THE USE OR OTHER DEALINGS IN THE
SOFTWARE.
------------------------------------------------------------------------------
*/
