#!/usr/bin/env python3
"""tests/fuzz_seeds.py - writes the seed inputs of tests/fuzz_world.c to tests/fuzz_corpus/.

The byte layout mirrors fz_def / fz_phases / fz_op / fz_steps in tests/fuzz_world.c (a byte 0
keeps a default there, so a seed only sets what it needs). Run from the repository root:
    python3 tests/fuzz_seeds.py [outdir]
Check what a seed does with FUZZ_VERBOSE=1 build/fuzz_replay tests/fuzz_corpus/seed-*.bin.
"""
import os
import struct
import sys

# one-byte def fields, in order (offsets 0..19)
BYTE_FIELDS = ["dim", "preset", "solver", "scheme", "integrator", "density", "pressure_grad",
               "boundary_pressure", "boundary_volume", "kernel", "clamp", "viscosity_form", "wall",
               "pcisph_factor", "periodic", "force", "motion", "min_iterations", "max_iterations",
               "shift_every"]
# real def fields with the harness's (lo, hi) ranges, in order
REAL_FIELDS = [("spacing", 1e-3, 0.5), ("h_factor", 0.5, 4), ("g0", -20, 20), ("g1", -20, 20),
               ("g2", -20, 20), ("delta", 0, 1), ("alpha", 0, 10), ("beta", 0, 10),
               ("boundary_gamma", 0, 10), ("cfl", 0, 1), ("cfl_viscous", 0, 1),
               ("cfl_force", 0, 1), ("cfl_velocity", 0, 1), ("max_dt", 0, 0.01),
               ("tolerance", 0, 0.1), ("omega", 0, 1), ("warm_start", 0, 1),
               ("tolerance_max", 0, 0.5), ("pcisph_gain", 0, 4), ("pressure_smoothing", 0, 1),
               ("max_compression", 0, 2), ("max_speed", 0, 100)]
for k in range(3):
    REAL_FIELDS += [("domain_lo%d" % k, -30, 10), ("domain_len%d" % k, 0, 60)]
for k in range(3):
    REAL_FIELDS += [("force_a%d" % k, -50, 50), ("motion_amp%d" % k, -0.05, 0.05)]
REAL_FIELDS += [("force_k", -100, 100), ("omega_cb", 0, 200)]
RANGES = dict((name, (lo, hi)) for name, lo, hi in REAL_FIELDS)
PHASE_REALS = [("rest_density", 0, 3000), ("viscosity", 0, 0.01), ("sound_speed", 0, 100),
               ("gamma", 1, 20), ("back_pressure", -100, 1e5), ("mass", 0, 10)]
SPECIAL = {"zero": 0, "-1": 1, "nan": 2, "inf": 3, "-inf": 4, "1e300": 5, "-1e300": 6,
           "4.9e-324": 8, "3.5e38": 13, "1e6": 16}


def real(value, lo, hi):
    """Three bytes giving value (clamped into [lo, hi]), or a special by name."""
    if value is None:
        return bytes(3)
    if isinstance(value, str):
        return bytes([224 + SPECIAL[value], 0, 0])
    t = (value - lo) / (hi - lo)
    q = max(0, min(65535, int(round(t * 65535))))
    return bytes([128, q >> 8, q & 255])


def enum(v):
    return bytes([0]) if v is None else bytes([128 + v])


def seed(defs=None, phases=None, ops=None, steps=None):
    """defs: byte fields as raw bytes (enum fields take 128 + value) and real fields as values;
    phases: list of dicts (eos plus PHASE_REALS names); ops: list of op byte strings or None for
    the default scene; steps: list of step byte strings."""
    defs = defs or {}
    out = bytearray()
    for name in BYTE_FIELDS:
        out.append(defs.get(name, 0))
    for name, lo, hi in REAL_FIELDS:
        out += real(defs.get(name), lo, hi)
    out += bytes([defs.get("motion_body", 0), defs.get("bad_call", 0)])
    phases = phases if phases is not None else [{}]
    out.append({1: 0, 2: 1, 3: 2, 0: 3}[len(phases)])
    for slot in range(3):
        ph = phases[slot] if slot < len(phases) else {}
        out += enum(ph.get("eos"))
        for name, lo, hi in PHASE_REALS:
            out += real(ph.get(name), lo, hi)
    if ops is None:
        out.append(0)
    else:
        out.append(len(ops))
        for op in ops:
            out += op
    steps = steps if steps is not None else [b""] * 3
    out.append(len(steps) - 1 if len(steps) > 0 else 0)  # 1 + b % 10 steps
    for st in steps:
        out += st
    return bytes(out)


def box(lo, ext):
    """A box in spacings: lo[3], extent[3] (fz_box reads them interleaved)."""
    b = b""
    for k in range(3):
        b += real(lo[k], -20, 20) + real(ext[k], 0, 40)
    return b


def fill(phase, lo, ext):
    return bytes([0, phase]) + box(lo, ext)


def wall(lo, ext, layers=None, open_faces=None):
    lb = 0 if layers is None else 128 + layers + 1
    fb = 0 if open_faces is None else 128 + open_faces
    return bytes([3, lb, fb]) + box(lo, ext)


def points(base, scale=None):
    b = b""
    for k in range(3):
        b += real(base[k], -20, 20)
    return b + real(scale, 0, 2)


def add_fluid(phase, n, base, v0=(None, None, None), ex=False, m=None, rho=None, flags=0):
    """sph_add_fluid(_ex) of n lattice points; flags: 1 v NULL, 2 m NULL, 4 rho NULL, 8 x NULL."""
    b = bytes([2 if ex else 1, phase, n, flags]) + points(base) + bytes([0])  # no pokes in x
    for k in range(3):
        b += real(v0[k], -5, 5)
    b += real(m, 0, 3) + real(rho, 0, 3)
    if not flags & 1:
        b += bytes([0])  # no pokes in v
    if ex and not flags & 2:
        b += bytes([0])
    if ex and not flags & 4:
        b += bytes([0])
    return b


def add_boundary(n, base, flags=0, body=0):
    return bytes([4, n, flags, body]) + points(base) + bytes([0]) + real(None, 0, 3) + \
        (bytes([0]) if flags & 1 else b"")


def step(act, arg=0, f=None, extra=b""):
    return bytes([act, arg]) + real(f, 0, 2) + extra


def main():
    outdir = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__),
                                                                 "fuzz_corpus")
    os.makedirs(outdir, exist_ok=True)
    S = {}
    S["wcsph-2d"] = seed()
    S["wcsph-3d"] = seed(defs={"dim": 1, "spacing": 0.05})
    S["wcsph-1d-summation-verlet"] = seed(defs={"dim": 2, "g0": -9.81, "density": 128 + 1,
                                                "integrator": 128 + 1})
    S["iisph-2d"] = seed(defs={"solver": 128 + 1}, steps=[step(0)] * 4)
    S["pcisph-original"] = seed(defs={"preset": 128, "max_iterations": 128 + 20},
                                steps=[step(0)] * 3)
    S["pcisph-enhanced-2phase"] = seed(
        defs={"preset": 129, "max_iterations": 128 + 20},
        phases=[{}, {"rest_density": 500}],
        ops=[fill(0, (0, 0, 0), (8, 4, 4)), fill(1, (0, 4, 0), (8, 4, 4)),
             wall((0, 0, 0), (16, 12, 8))], steps=[step(0)] * 3)
    # 1D shock tube: two ideal-gas halves, per-particle densities on the right
    S["compressible-gas-1d"] = seed(
        defs={"dim": 2, "solver": 128 + 3, "g0": 0},
        phases=[{"eos": 2, "rest_density": 1, "back_pressure": 1e5},
                {"eos": 3, "rest_density": 1000, "sound_speed": 50}],
        ops=[fill(0, (0, 0, 0), (30, 1, 1)), add_fluid(1, 30, (30, 0, 0), ex=True, m=1, rho=1),
             add_fluid(0, 10, (-12, 0, 0), v0=(2, 0, 0))],
        steps=[step(0), step(5), step(7, 3)])
    S["second-order-periodic"] = seed(
        defs={"scheme": 128 + 1, "periodic": 3, "kernel": 128 + 2, "g1": 0,
              "domain_lo0": 0, "domain_len0": 20, "domain_lo1": 0, "domain_len1": 20,
              "shift_every": 128 + 2},
        phases=[{"sound_speed": 10}],
        ops=[add_fluid(0, 64, (0, 0, 0), v0=(0.5, 0.2, 0)), fill(0, (8, 8, 0), (12, 12, 1))],
        steps=[step(0)] * 3)
    S["moving-wall-force"] = seed(
        defs={"force": 128 + 1, "motion": 128 + 1, "motion_amp0": 0.02, "omega_cb": 50},
        steps=[step(0)] * 3)
    S["verlet-akinci-noslip"] = seed(
        defs={"integrator": 128 + 1, "boundary_volume": 128 + 1, "wall": 128 + 1,
              "viscosity_form": 128 + 1, "alpha": 0.1},
        phases=[{"viscosity": 0.001}],
        ops=[fill(0, (0, 0, 0), (6, 6, 1)), add_boundary(40, (-2, -2, 0)),
             wall((0, 0, 0), (6, 8, 1), layers=1)],
        steps=[step(0)] * 3)
    S["advance-and-bad-dt"] = seed(
        defs={"solver": 128 + 1},
        steps=[step(5, 0, 1.0), step(4, 0, None, real("nan", 0, 0.01)),
               step(4, 0, None, real("zero", 0, 0.01)), step(5, 0, "-1"), step(0)])
    S["poke-nan"] = seed(
        steps=[step(0), step(6, 0, None, bytes([3, 1]) + real("nan", -20, 20)), step(0),
               step(6, 1, None, bytes([3, 1]) + real(1.0, -20, 20)), step(0)])
    S["motion-writes-nan"] = seed(
        defs={"motion": 128 + 3, "bad_call": 1, "integrator": 128 + 1},
        steps=[step(0), step(0)])
    S["bad-phase-and-box"] = seed(
        phases=[{"rest_density": "nan"}, {}],
        ops=[fill(0, (0, 0, 0), ("-1", 4, 4)), fill(3, (0, 0, 0), (4, 4, 4)),
             fill(0, (0, 0, 0), (4, 4, 4)), add_fluid(0, 4, ("nan", 0, 0))],
        steps=[step(0), step(7, 3)])
    S["huge-boxes"] = seed(
        defs={"dim": 1},
        ops=[wall((0, 0, 0), ("1e6", "1e6", 2)), fill(0, (0, 0, 0), ("1e6", "1e6", "1e6")),
             wall((0, 0, 0), ("1e300", 4, 4)), fill(0, (0, 0, 0), (4, 4, 4))])
    for name, data in S.items():
        with open(os.path.join(outdir, "seed-%s.bin" % name), "wb") as f:
            f.write(data)
    print("wrote %d seeds to %s" % (len(S), outdir))
    # Regressions rebuilt by hand in the current layout (the fuzzer's own inputs for these two
    # bugs predate a change of the special values): a PCISPH step limit that rounds to 0 with
    # no error, and a wall box whose span (3.5e38 spacings) overflowed the size_t conversion.
    R = {}
    R["stable-dt-underflow-no-error"] = seed(defs={"solver": 128 + 2, "cfl_force": "4.9e-324"})
    R["wall-box-span-overflow-cast"] = seed(ops=[wall((0, 0, 0), ("3.5e38", 4, 4))])
    rdir = os.path.join(outdir, "regressions")
    os.makedirs(rdir, exist_ok=True)
    for name, data in R.items():
        with open(os.path.join(rdir, "%s.bin" % name), "wb") as f:
            f.write(data)
    print("wrote %d regressions to %s" % (len(R), rdir))


if __name__ == "__main__":
    main()
