#!/usr/bin/env python3
"""tests/check_vtk.py - reads sph.h's ParaView files with VTK (Debian python3-vtk9), an
independent reader, and compares them with the values tests/vtk_export.c expected.

Usage (from the repository root; `make check-vtk` runs it for the double and the float build):

    ./build/vtk_export build/vtk && /usr/bin/python3 tests/check_vtk.py build/vtk

For every NAME.pvd in the directory it parses the collection (xml.etree), checks that the
timesteps increase, and reads each listed .vtu with vtkXMLUnstructuredGridReader; for every
.vtu it compares, against NAME_XXXX.txt (C99 hex floats, exact):
  - the number of points and cells, every cell a VTK_VERTEX with the point of the same index;
  - positions, velocity, density, pressure, internal_energy (if present): bit for bit (the
    file stores sph_real's precision; the hex text was printed from the same values);
  - id, phase, kind, body: exactly; the array types (Float32/Float64 by precision);
  - the TimeValue field and the .pvd timestep: the expected time exactly.
It also reads NAME_last.vtk (legacy ASCII) with vtkUnstructuredGridReader and compares it to
9 significant digits. Prints one "vtk ok" line per file and exits non-zero on any mismatch.
"""

import glob
import os
import sys
import xml.etree.ElementTree as ET

try:
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy
except ImportError as exc:  # pragma: no cover - reported, not hidden
    print("check_vtk: cannot import vtk (install python3-vtk9 and run /usr/bin/python3): %s" % exc)
    sys.exit(2)

import numpy as np


class CheckError(Exception):
    pass


def load_expected(path):
    with open(path) as f:
        head = f.readline().split()
        t = float.fromhex(head[0])
        nf, nb, dim, has_e, real_size = (int(v) for v in head[1:6])
        rows = [line.split() for line in f if line.strip()]
    if len(rows) != nf + nb:
        raise CheckError("%s: %d rows for %d points" % (path, len(rows), nf + nb))
    ints = np.array([[int(v) for v in r[:4]] for r in rows], dtype=np.int64)
    reals = np.array([[float.fromhex(v) for v in r[4:]] for r in rows], dtype=np.float64)
    return dict(time=t, nf=nf, nb=nb, dim=dim, has_e=has_e, real_size=real_size, ints=ints,
                reals=reals)


def point_array(grid, name):
    arr = grid.GetPointData().GetArray(name)
    if arr is None:
        raise CheckError("no point array %r" % name)
    return arr


def same_bits(got, want, real_size, what):
    """got: numpy array as VTK stored it; want: float64 values printed from sph_real."""
    dtype = np.float32 if real_size == 4 else np.float64
    if got.dtype != dtype:
        raise CheckError("%s stored as %s, expected %s" % (what, got.dtype, dtype))
    want = want.astype(dtype)  # exact: the values were sph_real to begin with
    if got.shape != want.shape:
        raise CheckError("%s shape %s, expected %s" % (what, got.shape, want.shape))
    diff = got.view(np.uint32 if real_size == 4 else np.uint64) != want.view(
        np.uint32 if real_size == 4 else np.uint64)
    if diff.any():
        k = int(np.argmax(diff.reshape(diff.shape[0], -1).any(axis=1)))
        raise CheckError("%s differs at point %d: %r vs %r (%d values differ)" %
                         (what, k, got[k], want[k], int(diff.sum())))


def check_vtu(path, exp):
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    if reader.GetErrorCode() != 0:
        raise CheckError("reader error code %d" % reader.GetErrorCode())
    grid = reader.GetOutput()
    n = exp["nf"] + exp["nb"]
    if grid.GetNumberOfPoints() != n or grid.GetNumberOfCells() != n:
        raise CheckError("%d points, %d cells; expected %d" %
                         (grid.GetNumberOfPoints(), grid.GetNumberOfCells(), n))
    # one vertex cell per point, in order
    types = vtk_to_numpy(grid.GetCellTypesArray())
    if not (types == vtk.VTK_VERTEX).all():
        raise CheckError("a cell is not a VTK_VERTEX")
    cells = grid.GetCells()
    conn = vtk_to_numpy(cells.GetConnectivityArray())
    offs = vtk_to_numpy(cells.GetOffsetsArray())
    if not (conn == np.arange(n)).all() or not (offs == np.arange(n + 1)).all():
        raise CheckError("cell connectivity is not point i for cell i")
    rs = exp["real_size"]
    reals, ints = exp["reals"], exp["ints"]
    same_bits(vtk_to_numpy(grid.GetPoints().GetData()), reals[:, 0:3], rs, "positions")
    same_bits(vtk_to_numpy(point_array(grid, "velocity")), reals[:, 3:6], rs, "velocity")
    same_bits(vtk_to_numpy(point_array(grid, "density")), reals[:, 6], rs, "density")
    same_bits(vtk_to_numpy(point_array(grid, "pressure")), reals[:, 7], rs, "pressure")
    has_e = grid.GetPointData().GetArray("internal_energy") is not None
    if has_e != bool(exp["has_e"]):
        raise CheckError("internal_energy present: %s, expected %s" % (has_e, bool(exp["has_e"])))
    if has_e:
        same_bits(vtk_to_numpy(point_array(grid, "internal_energy")), reals[:, 8], rs,
                  "internal_energy")
    for col, name, dtype in ((0, "kind", np.uint8), (1, "id", np.uint32), (2, "phase", np.int32),
                             (3, "body", np.int32)):
        got = vtk_to_numpy(point_array(grid, name))
        if got.dtype != dtype:
            raise CheckError("%s stored as %s, expected %s" % (name, got.dtype, dtype))
        if not (got.astype(np.int64) == ints[:, col]).all():
            raise CheckError("%s differs" % name)
    if int((ints[:, 0] == 0).sum()) != exp["nf"]:
        raise CheckError("fluid count by kind differs")
    tv = grid.GetFieldData().GetArray("TimeValue")
    if tv is None or tv.GetValue(0) != exp["time"]:
        raise CheckError("TimeValue %r, expected %r" % (tv and tv.GetValue(0), exp["time"]))
    return n


def check_pvd(pvd):
    base = pvd[:-4]
    root = ET.parse(pvd).getroot()
    if root.tag != "VTKFile" or root.get("type") != "Collection":
        raise CheckError("not a VTK collection")
    sets = root.find("Collection").findall("DataSet")
    if not sets:
        raise CheckError("empty collection")
    last = None
    for k, ds in enumerate(sets):
        fname = ds.get("file")
        if fname != os.path.basename(base) + "_%04d.vtu" % k:
            raise CheckError("entry %d names %r" % (k, fname))
        t = float(ds.get("timestep"))
        exp = load_expected(os.path.join(os.path.dirname(pvd), fname[:-4] + ".txt"))
        if t != exp["time"]:
            raise CheckError("entry %d timestep %r, expected %r" % (k, t, exp["time"]))
        if last is not None and not t > last:
            raise CheckError("timesteps do not increase at entry %d" % k)
        last = t
        path = os.path.join(os.path.dirname(pvd), fname)
        try:
            n = check_vtu(path, exp)
        except CheckError as e:
            raise CheckError("%s: %s" % (path, e))
        print("vtk ok: %s  %d points (%d fluid, %d boundary), %dD, t = %.4f s, %s%s" %
              (path, n, exp["nf"], exp["nb"], exp["dim"], t,
               "Float32" if exp["real_size"] == 4 else "Float64",
               ", internal_energy" if exp["has_e"] else ""))
    return len(sets)


def check_legacy(path, txt):
    exp = load_expected(txt)
    reader = vtk.vtkUnstructuredGridReader()
    reader.SetFileName(path)
    reader.ReadAllScalarsOn()
    reader.ReadAllVectorsOn()
    reader.Update()
    grid = reader.GetOutput()
    n = exp["nf"] + exp["nb"]
    if grid.GetNumberOfPoints() != n or grid.GetNumberOfCells() != n:
        raise CheckError("%s: %d points, expected %d" % (path, grid.GetNumberOfPoints(), n))
    reals = exp["reals"]

    def close(got, want, what):
        got = np.asarray(got, dtype=np.float64)
        scale = np.maximum(np.abs(want), 1e-300)
        err = np.abs(got - want) / scale
        err[np.abs(want) < 1e-12] = np.abs(got - want)[np.abs(want) < 1e-12]
        if err.max() > 1e-8:
            raise CheckError("%s: %s off by %.3g (relative)" % (path, what, err.max()))

    close(vtk_to_numpy(grid.GetPoints().GetData()), reals[:, 0:3], "positions")
    close(vtk_to_numpy(point_array(grid, "velocity")), reals[:, 3:6], "velocity")
    close(vtk_to_numpy(point_array(grid, "density")), reals[:, 6], "density")
    close(vtk_to_numpy(point_array(grid, "pressure")), reals[:, 7], "pressure")
    ids = vtk_to_numpy(point_array(grid, "id")).astype(np.int64)
    if not (ids == exp["ints"][:, 1]).all():
        raise CheckError("%s: ids differ" % path)
    print("vtk ok: %s  legacy ASCII, %d points, values to 9 digits" % (path, n))


def main(argv):
    if len(argv) != 2:
        print(__doc__)
        return 2
    d = argv[1]
    pvds = sorted(glob.glob(os.path.join(d, "*.pvd")))
    if not pvds:
        print("check_vtk: no .pvd files in %s" % d)
        return 1
    failures = 0
    for pvd in pvds:
        try:
            check_pvd(pvd)
        except (CheckError, ET.ParseError, OSError, ValueError) as e:
            print("check_vtk: FAILED: %s: %s" % (pvd, e))
            failures += 1
    for vtkf in sorted(glob.glob(os.path.join(d, "*_last.vtk"))):
        try:
            check_legacy(vtkf, vtkf[:-4] + ".txt")
        except (CheckError, OSError, ValueError) as e:
            print("check_vtk: FAILED: %s" % e)
            failures += 1
    print("check_vtk (VTK %s): %d collection(s), %s" %
          (vtk.vtkVersion.GetVTKVersion(), len(pvds), "FAILED" if failures else "all ok"))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
