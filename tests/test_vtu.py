#!/usr/bin/env python3
"""Check casca's VTU/PVD writer (src/output/vtu_writer.f90) from the outside.

Usage:
    python3 tests/test_vtu.py TEST_VTU [OUTDIR]

TEST_VTU is the test_vtu executable built from tests/test_vtu.f90, or the folder holding it.
OUTDIR (created if missing; a fresh temporary folder if omitted) receives the files.

The program writes two frames of a two-element mesh plus a .pvd; here they are read back with
meshio and checked: cell type, sizes, connectivity, exact field values, and -- independently of
the writer -- the node ORDER: the cubic Lagrange map built from the points in file order must
reproduce the cylinder the curved element was sampled from, and the affine map of the flat one.
If the `vtk` Python module is importable, VTK's own vtkLagrangeTriangle evaluates the cells too.
Exits non-zero on any failure.
"""
import os
import re
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

import numpy as np
import meshio
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from casca_testlib import Checks  # noqa: E402

NEN = 10
# Must match tests/test_vtu.f90.
PERM = [7, 13, 2, 19, 11, 5, 16, 1, 20, 9, 4, 14, 18, 3, 10, 17, 6, 12, 15, 8]
P0, P1, P2 = np.array([2.0, 0.0, 0.0]), np.array([3.0, 0.0, 0.0]), np.array([2.0, 1.0, 0.5])
TIMES = [0.0, 1.5e-3]
FILES = ["cyl_0000.vtu", "cyl_0001.vtu"]
# Reference coordinates of the 10 nodes in casca order.
XI_REF = [(0, 0), (1, 0), (0, 1), (1 / 3, 0), (2 / 3, 0), (2 / 3, 1 / 3), (1 / 3, 2 / 3),
          (0, 2 / 3), (0, 1 / 3), (1 / 3, 1 / 3)]

CK = Checks()


def check(ok, what):
    CK.record(what, ok)
    return ok


def shape_functions(xi1, xi2):
    """Cubic triangle shapes in casca order (vertices, edge 1-2, 2-3, 3-1, centroid)."""
    l1, l2, l3 = 1.0 - xi1 - xi2, xi1, xi2

    def vert(a):
        return 0.5 * a * (3 * a - 1) * (3 * a - 2)

    def edge(a, b):  # node on edge a-b nearer a
        return 4.5 * a * b * (3 * a - 1)

    return np.array([vert(l1), vert(l2), vert(l3),
                     edge(l1, l2), edge(l2, l1),
                     edge(l2, l3), edge(l3, l2),
                     edge(l3, l1), edge(l1, l3),
                     27 * l1 * l2 * l3])


def expected_point_data(scale):
    k = np.arange(1, 21, dtype=float)
    disp = scale * np.stack([k / 3, -1.0 / (k + 7), k * 1.0e-3], axis=1)
    thick = 0.5 + k / 100
    return disp, thick


def cylinder_point(xi1, xi2):
    return np.array([np.cos(0.6 * xi1), np.sin(0.6 * xi1), 0.4 * xi2])


def cylinder_error(xe, samples):
    """Largest distance from the cylinder, and from the exact image point, over samples."""
    off_surface = exact = 0.0
    for xi1, xi2 in samples:
        p = shape_functions(xi1, xi2) @ xe
        off_surface = max(off_surface, abs(np.hypot(p[0], p[1]) - 1.0))
        exact = max(exact, np.linalg.norm(p - cylinder_point(xi1, xi2)))
    return off_surface, exact


def flat_error(xe, samples):
    return max(np.linalg.norm(shape_functions(a, b) @ xe - (P0 + a * (P1 - P0) + b * (P2 - P0)))
               for a, b in samples)


def random_samples(n, rng):
    pts = []
    while len(pts) < n:
        a, b = rng.random(2)
        if a + b <= 1.0:
            pts.append((a, b))
    return pts + [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)]


def check_vtu(path, scale, samples):
    name = os.path.basename(path)
    # meshio finds each raw block's DataArray by its offset after rewriting the earlier ones'
    # to base64 positions: the blocks must be appended in the reverse order of the header
    # (vtu_writer.f90), so that a rewritten offset never shadows a later block's
    header = open(path, "rb").read().split(b"<AppendedData")[0].decode()
    offsets = [int(o) for o in re.findall(r'offset="(\d+)"', header)]
    check(len(offsets) > 4 and offsets[-1] == 0 and offsets == sorted(offsets, reverse=True),
          f"{name}: offsets fall down the header to 0 (blocks appended last to first): {offsets}")
    try:
        mesh = meshio.read(path)
    except Exception as exc:  # any reader failure is a test failure, not a crash
        check(False, f"{name}: meshio reads it ({type(exc).__name__}: {exc})")
        return
    check(len(mesh.cells) == 1 and mesh.cells[0].type == "VTK_LAGRANGE_TRIANGLE",
          f"{name}: one cell block of type VTK_LAGRANGE_TRIANGLE "
          f"(got {[c.type for c in mesh.cells]})")
    conn = mesh.cells[0].data
    check(conn.shape == (2, NEN), f"{name}: 2 cells x 10 points (got {conn.shape})")
    check(mesh.points.shape == (20, 3), f"{name}: 20 points (got {mesh.points.shape})")
    if conn.shape != (2, NEN) or mesh.points.shape != (20, 3):
        return
    check(np.array_equal(conn.ravel() + 1, PERM), f"{name}: connectivity as written")

    disp, thick = expected_point_data(scale)
    got_disp = mesh.point_data.get("displacement")
    got_thick = mesh.point_data.get("thickness_param")
    check(got_disp is not None and got_disp.shape == (20, 3)
          and np.array_equal(got_disp, disp), f"{name}: displacement round-trips exactly")
    check(got_thick is not None and np.asarray(got_thick).reshape(-1).shape == (20,)
          and np.array_equal(np.asarray(got_thick).reshape(-1), thick),
          f"{name}: thickness_param round-trips exactly")
    body = mesh.cell_data.get("body")
    check(body is not None and len(body) == 1
          and np.array_equal(np.asarray(body[0]).reshape(-1), [1.0, 2.0]),
          f"{name}: cell field body round-trips exactly")

    # Node order, checked through geometry alone: points in file order.
    x1, x2 = mesh.points[conn[0]], mesh.points[conn[1]]
    off, exact = cylinder_error(x1, samples)
    check(off < 1e-3, f"{name}: curved element stays on the cylinder (max |r-1| = {off:.2e})")
    check(exact < 1e-3, f"{name}: curved element matches (cos 0.6xi1, sin 0.6xi1, 0.4xi2) "
          f"(max error {exact:.2e})")
    ferr = flat_error(x2, samples)
    check(ferr < 1e-12, f"{name}: flat element reproduces its affine map (max error {ferr:.1e})")

    if scale == 1:
        # Negative controls: the order check must notice plausible wrong orders. (Edge 3-1
        # lies on a straight generator of the cylinder, so swapping its nodes keeps every
        # point on the surface; only the comparison with the exact image point catches it.)
        wrong_orders = {
            "edge nodes reversed": [0, 1, 2, 4, 3, 6, 5, 8, 7, 9],
            "edges rotated": [0, 1, 2, 8, 7, 3, 4, 5, 6, 9],
            "edge 1-2 nodes swapped": [0, 1, 2, 4, 3, 5, 6, 7, 8, 9],
            "edge 3-1 nodes swapped": [0, 1, 2, 3, 4, 5, 6, 8, 7, 9],
        }
        for label, order in wrong_orders.items():
            off_w, exact_w = cylinder_error(x1[order], samples)
            check(max(off_w, exact_w) > 1e-2, f"{name}: order check detects '{label}' "
                  f"(|r-1| = {off_w:.1e}, error {exact_w:.1e})")

    check_with_vtk(path, samples)


def check_with_vtk(path, samples):
    """Optional: let VTK itself read the file and evaluate its Lagrange triangles."""
    try:
        from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader
        from vtkmodules.vtkCommonCore import vtkVersion, reference
    except ImportError:
        try:
            import vtk
            vtkXMLUnstructuredGridReader = vtk.vtkXMLUnstructuredGridReader
            vtkVersion, reference = vtk.vtkVersion, vtk.reference
        except (ImportError, AttributeError):
            return
    name = os.path.basename(path)
    reader = vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    grid = reader.GetOutput()
    ver = vtkVersion.GetVTKVersion()
    check(grid.GetNumberOfCells() == 2 and grid.GetNumberOfPoints() == 20,
          f"{name}: VTK {ver} reads 2 cells, 20 points")
    if grid.GetNumberOfCells() != 2:
        return
    check(all(grid.GetCellType(i) == 69 for i in range(2)), f"{name}: VTK cell type 69")
    cell = grid.GetCell(0)
    pc = cell.GetParametricCoords()
    got = [(pc[3 * i], pc[3 * i + 1]) for i in range(NEN)]
    check(np.allclose(got, XI_REF), f"{name}: VTK's parametric node coordinates equal casca's")
    weights = [0.0] * NEN
    worst = 0.0
    for xi1, xi2 in samples:
        p = [0.0, 0.0, 0.0]
        cell.EvaluateLocation(reference(0), [xi1, xi2, 0.0], p, weights)
        worst = max(worst, float(np.linalg.norm(np.array(p) - cylinder_point(xi1, xi2))))
    check(worst < 1e-3, f"{name}: vtkLagrangeTriangle maps (r,s) onto the cylinder "
          f"(max error {worst:.2e})")
    disp = grid.GetPointData().GetArray("displacement")
    check(disp is not None and disp.GetNumberOfComponents() == 3,
          f"{name}: VTK sees a 3-component displacement")


def main():
    if len(sys.argv) not in (2, 3):
        print(__doc__)
        return 2
    exe = os.path.abspath(sys.argv[1])
    if os.path.isdir(exe):
        exe = os.path.join(exe, "test_vtu")
    outdir = os.path.abspath(sys.argv[2]) if len(sys.argv) == 3 else tempfile.mkdtemp(
        prefix="casca_vtu_")
    os.makedirs(outdir, exist_ok=True)
    for f in FILES + ["cyl.pvd"]:
        if os.path.exists(os.path.join(outdir, f)):
            os.remove(os.path.join(outdir, f))

    run = subprocess.run([exe, outdir], capture_output=True, text=True, timeout=60)
    sys.stdout.write(run.stdout)
    sys.stderr.write(run.stderr)
    if not check(run.returncode == 0, f"{os.path.basename(exe)} exits 0 (got {run.returncode})"):
        print(f"{CK.passed} passed, {CK.failed} failed")
        return 1

    leftovers = [f for f in os.listdir(outdir) if f.endswith(".part")]
    check(not leftovers, f"no .part files left behind (found {leftovers})")
    for bad in ["bad_conn.vtu", "bad_field.vtu", "bad.pvd"]:
        check(not os.path.exists(os.path.join(outdir, bad)), f"failed write left no {bad}")

    rng = np.random.default_rng(20240611)
    samples = random_samples(20, rng)

    pvd = os.path.join(outdir, "cyl.pvd")
    try:
        root = ET.parse(pvd).getroot()
    except (OSError, ET.ParseError) as exc:
        check(False, f"cyl.pvd parses as XML ({exc})")
        root = ET.Element("none")
    check(root.get("type") == "Collection", "cyl.pvd: VTKFile type=Collection")
    datasets = root.findall("./Collection/DataSet")
    check([d.get("file") for d in datasets] == FILES, f"cyl.pvd lists {FILES}")
    check([float(d.get("timestep")) for d in datasets] == TIMES,
          f"cyl.pvd times are exactly {TIMES}")
    # Frame i has its displacement scaled by i+1 (see test_vtu.f90).
    for i, d in enumerate(datasets):
        check_vtu(os.path.join(outdir, d.get("file")), i + 1, samples)

    print(f"{CK.passed} passed, {CK.failed} failed")
    return 0 if CK.failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
