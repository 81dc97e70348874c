#!/usr/bin/env python3
"""Check casca's VTU/PVD writer (src/output/vtu_writer.f90) from the outside.

Usage:
    python3 tests/test_vtu.py TEST_VTU [OUTDIR [CASCA]]

TEST_VTU is the test_vtu executable built from tests/test_vtu.f90, or the folder holding it.
OUTDIR (created if missing; a fresh temporary folder if omitted) receives the files.
CASCA, the casca program: the frames of runs are checked too (below); without it, not.

The program writes two frames of a two-element mesh plus a .pvd; here they are read back with
meshio and checked: cell type, sizes, connectivity, exact field values, and -- independently of
the writer -- the node ORDER: the cubic Lagrange map built from the points in file order must
reproduce the cylinder the curved element was sampled from, and the affine map of the flat one.
If the `vtk` Python module is importable, VTK's own vtkLagrangeTriangle evaluates the cells too.

With CASCA, the frames of runs (their expected values from geometry and elasticity, never from
casca's output):
  - obstacles: a ring dropped towards a plane floor (normal +y) beside a sphere moving at
    v = (5, 0, 0) m/s and a fixed cylinder along z. Each frame of run.pvd (part 0) has its
    obstacles' file listed as part 1 at the same timestep, and it exists; the field data name
    the obstacles by their number, the cell array `obstacle`; the floor's points lie on the
    plane (|(x - p).n| < 1e-12 of the scene's size, the ring's diameter), as a square patch
    covering the bodies' extent in the plane (its side 1.5 times their larger extent, to
    1e-12); the sphere's at |x - (c + v t)| = R to 1e-12 relative, t the frame's timestep,
    and its points at t displaced from those at 0 by exactly v t (to 1e-12 of the scene),
    their point array `velocity` = v; the cylinder's at distance R from its axis to 1e-12
    relative, over the bodies' extent along the axis. A restart (the run to half its end, its
    checkpoint taken on to the end) lists every frame once with its obstacles (0, 1, 2, 3 ms
    and the first run's end, 1.5 ms); a run of the
    same folder without obstacles leaves no obstacles_* file and no part 1.
  - thickness: the point array `thickness` is the shell's thickness h |G| (the faces at
    Y + (h/2)(+-1 + A) G, h |G| apart along the fibre). At t = 0 it is h at every node to
    1e-12. A plate L x B x h (E, nu) held at x = 0 in x only (free to narrow), z = 0 at every
    node, pulled at x = L by the dead edge force F along x (statics): uniaxial stress, the
    first Piola-Kirchhoff stress P = F / (B h), and in Saint-Venant-Kirchhoff S = E E11 with
    E22 = E33 = -nu E11 (the material law's inverse; exact, S linear in E), P = lambda1 S,
    lambda1 = sqrt(1 + 2 E11): E11 solves E E11 sqrt(1 + 2 E11) = F / (B h), and the
    thickness is h lambda3, lambda3 = sqrt(1 - 2 nu E11) (the small-strain h (1 - nu eps) is
    4e-4 off at this load: it would fail). The frame's thickness must be that at every node
    to 1e-10 (a uniform state the element holds exactly; Newton's tolerance: 1e-14 found),
    and, as checks of the state itself, the loaded end's displacement (lambda1 - 1) L and the
    width's (lambda3 - 1) B to 1e-10.
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
from casca_testlib import Checks, run, tension_plate_deck  # noqa: E402

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


RING_DECK = """&run
  dt = 2.0e-4, t_end = %(t_end)r
/
&output
  interval = 1.0e-3
/
&body
  name = 'ring', mesh = 'ring', radius = 0.2, width = 0.05, element_size = 0.04
  center = 0.0, 0.0, 0.0, velocity = 0.0, -3.0, 0.0
  young = 2e9, poisson = 0.3, density = 1000, thickness = %(h)r
/
"""
OBSTACLES = """&obstacle
  name = 'floor', shape = 'plane', point = 0.3, -0.21, 0.1, normal = 0.0, 1.0, 0.0
/
&obstacle
  name = 'ball', shape = 'sphere', point = 0.6, 0.05, 0.01, radius = 0.1, velocity = 5.0, 0.0, 0.0
/
&obstacle
  name = 'post', shape = 'cylinder', point = -0.5, 0.0, 0.3, axis = 0.0, 0.0, 2.0, radius = 0.05
/
"""
RING_H = 0.004
FLOOR_P, FLOOR_N = np.array([0.3, -0.21, 0.1]), np.array([0.0, 1.0, 0.0])
BALL_C, BALL_R, BALL_V = np.array([0.6, 0.05, 0.01]), 0.1, np.array([5.0, 0.0, 0.0])
POST_P, POST_A, POST_R = np.array([-0.5, 0.0, 0.3]), np.array([0.0, 0.0, 1.0]), 0.05

PLATE_L, PLATE_B, PLATE_H, PLATE_E, PLATE_NU, PLATE_F = 1.0, 0.5, 0.01, 1.0e6, 0.3, 250.0
PLATE_DECK = tension_plate_deck(PLATE_L, PLATE_B, 4, 2, PLATE_E, PLATE_NU, PLATE_H, PLATE_F, load_steps=4)


def casca_run(casca, deck_text, work, name, out=None, extra=()):
    """Run deck_text (written to WORK/NAME.nml) into out (WORK/NAME); True if it exits 0."""
    deck = os.path.join(work, name + ".nml")
    with open(deck, "w") as f:
        f.write(deck_text)
    out = out or os.path.join(work, name)
    p = run([casca, "run", deck, "--out", out, "-q"] + list(extra))
    return check(p.returncode == 0, f"{name}: casca runs it (exit {p.returncode}) {p.stderr[-300:]}")


def datasets(folder):
    """run.pvd's (timestep, part, file) in order"""
    root = ET.parse(os.path.join(folder, "run.pvd")).getroot()
    return [(float(d.get("timestep")), d.get("part"), d.get("file")) for d in root.iter("DataSet")]


def frames_and_obstacles(folder, name):
    """[(t, frame file, obstacle file or None)]; checks that each frame (part 0) is followed
    by its obstacles (part 1) at the same timestep, and that every listed file exists"""
    sets = datasets(folder)
    out = []
    for t, part, f in sets:
        if part == "0":
            out.append([t, f, None])
        elif part == "1" and out and out[-1][0] == t and out[-1][2] is None:
            out[-1][2] = f
        else:
            check(False, f"{name}: run.pvd's part {part} {f} at t = {t} follows its frame")
    missing = [f for _, f, o in out for f in (f, o) if f and not os.path.exists(os.path.join(folder, f))]
    check(not missing, f"{name}: every file run.pvd lists exists (missing {missing})")
    return out


def check_obstacle_frames(folder, name):
    """The obstacles' files of the run in folder against the obstacles' geometry"""
    listed = frames_and_obstacles(folder, name)
    check(len(listed) >= 3 and all(o is not None for _, _, o in listed),
          f"{name}: {len(listed)} frames (>= 3), each with its obstacles as part 1 "
          f"({[o for _, _, o in listed]})")
    if not listed or any(o is None for _, _, o in listed):
        return
    first = None
    for t, frame, obst in listed:
        bodies = meshio.read(os.path.join(folder, frame)).points
        lo, hi = bodies.min(axis=0), bodies.max(axis=0)
        scene = 0.4   # (the ring's diameter)
        m = meshio.read(os.path.join(folder, obst))
        which = np.concatenate(m.cell_data["obstacle"]).reshape(-1).astype(int)
        tris = np.concatenate([c.data for c in m.cells if c.type == "triangle"])
        check(len(tris) == len(which) and len(which) <= 1500,
              f"{name} t={t:g}: linear triangles only, a few hundred ({len(which)})")
        check({k: int(v[0]) for k, v in m.field_data.items()} == {"floor": 1, "ball": 2, "post": 3},
              f"{name} t={t:g}: field data name the obstacles 1, 2, 3 ({m.field_data})")
        pts = {k: m.points[np.unique(tris[which == k])] for k in (1, 2, 3)}
        check(all(len(p) > 20 for p in pts.values()), f"{name} t={t:g}: each obstacle has its points")
        # floor: on the plane, a square about the bodies covering them
        floor = pts[1]
        off = np.max(np.abs((floor - FLOOR_P) @ FLOOR_N)) / scene
        check(off < 1e-12, f"{name} t={t:g}: the floor's points on its plane ({off:.1e} of the scene < 1e-12)")
        side = floor.max(axis=0) - floor.min(axis=0)   # (x, z: the plane's axes)
        want = 1.5 * max(hi[0] - lo[0], hi[2] - lo[2])
        check(abs(side[0] - want) < 1e-12 * scene and abs(side[2] - want) < 1e-12 * scene,
              f"{name} t={t:g}: the floor a square of side 1.5 x the bodies' larger extent in it "
              f"({side[0]:.6g} x {side[2]:.6g}, {want:.6g})")
        centre = 0.5 * (floor.max(axis=0) + floor.min(axis=0))
        box_centre = 0.5 * (lo + hi)
        check(abs(centre[0] - box_centre[0]) < 1e-12 * scene and abs(centre[2] - box_centre[2]) < 1e-12 * scene,
              f"{name} t={t:g}: the floor centred under the bodies' box")
        # ball: on the sphere where it has moved to, displaced by v t from frame 0's
        c = BALL_C + BALL_V * t
        r = np.linalg.norm(pts[2] - c, axis=1)
        err = np.max(np.abs(r - BALL_R)) / BALL_R
        check(err < 1e-12, f"{name} t={t:g}: the ball's points at |x - (c + v t)| = R ({err:.1e} < 1e-12)")
        if first is None:
            first = pts[2]
        elif len(first) == len(pts[2]):
            moved = np.max(np.linalg.norm(pts[2] - first - BALL_V * t, axis=1)) / scene
            check(moved < 1e-12, f"{name} t={t:g}: the ball's points moved by v t from t = 0 "
                  f"({moved:.1e} of the scene < 1e-12)")
        else:
            check(False, f"{name} t={t:g}: the ball has as many points as at t = 0")
        vel = m.point_data["velocity"][np.unique(tris[which == 2])]
        check(np.array_equal(vel, np.tile(BALL_V, (len(vel), 1))), f"{name} t={t:g}: the ball's velocity = v")
        # post: at R from its axis, along the bodies' extent on it
        d = pts[3] - POST_P
        radial = np.linalg.norm(d - np.outer(d @ POST_A, POST_A), axis=1)
        err = np.max(np.abs(radial - POST_R)) / POST_R
        check(err < 1e-12, f"{name} t={t:g}: the post's points at R from its axis ({err:.1e} < 1e-12)")
        check(pts[3][:, 2].min() <= lo[2] and pts[3][:, 2].max() >= hi[2],
              f"{name} t={t:g}: the post spans the bodies along its axis")


def check_runs(casca, outdir):
    work = os.path.join(outdir, "runs")
    os.makedirs(work, exist_ok=True)
    ring = os.path.join(work, "ring_floor")
    if casca_run(casca, RING_DECK % dict(t_end=0.003, h=RING_H) + OBSTACLES, work, "ring_floor"):
        check_obstacle_frames(ring, "ring_floor")
        t0 = meshio.read(os.path.join(ring, "frame_00000.vtu")).point_data.get("thickness")
        check(t0 is not None and np.max(np.abs(t0 - RING_H)) < 1e-12 * RING_H,
              f"ring_floor: thickness = h at t = 0 to 1e-12 "
              f"({'none' if t0 is None else np.max(np.abs(t0 - RING_H)) / RING_H:.1e})")

    # a restart: to half the end, then on from its checkpoint in the same folder
    restart = os.path.join(work, "restart")
    if casca_run(casca, RING_DECK % dict(t_end=0.0015, h=RING_H) + OBSTACLES, work, "restart_a",
                 out=restart) and \
            casca_run(casca, RING_DECK % dict(t_end=0.003, h=RING_H) + OBSTACLES, work, "restart_b",
                      out=restart, extra=["--restart", os.path.join(restart, "checkpoint.h5")]):
        listed = frames_and_obstacles(restart, "restart")
        times = [t for t, _, _ in listed]
        # the frames of the run straight through (0, 1, 2, 3 ms) and the first run's last
        want = [0.0, 0.001, 0.0015, 0.002, 0.003]
        check(len(times) == len(want) and np.allclose(times, want, rtol=1e-12, atol=0)
              and len({o for _, _, o in listed}) == len(want),
              f"restart: run.pvd lists the frames at {want} s once each, each with its own "
              f"obstacles ({listed})")
        check_obstacle_frames(restart, "restart")

    # the same folder without obstacles: none left from the run before
    if casca_run(casca, RING_DECK % dict(t_end=0.001, h=RING_H), work, "no_obstacles", out=ring):
        left = [f for f in os.listdir(ring) if f.startswith("obstacles_")]
        check(not left, f"no_obstacles: the earlier run's obstacle files deleted ({left})")
        check(all(part == "0" for _, part, _ in datasets(ring)), "no_obstacles: run.pvd has no part 1")

    # the stretched plate's thickness against Saint-Venant-Kirchhoff's uniaxial stress
    if casca_run(casca, PLATE_DECK, work, "plate"):
        P = PLATE_F / (PLATE_B * PLATE_H)
        e11 = P / PLATE_E
        for _ in range(50):   # Newton on E e11 sqrt(1 + 2 e11) = P
            f = PLATE_E * e11 * np.sqrt(1 + 2 * e11) - P
            df = PLATE_E * (np.sqrt(1 + 2 * e11) + e11 / np.sqrt(1 + 2 * e11))
            e11 -= f / df
        lam1, lam3 = np.sqrt(1 + 2 * e11), np.sqrt(1 - 2 * PLATE_NU * e11)
        folder = os.path.join(work, "plate")
        last = datasets(folder)[-1]
        check(last[0] == 1.0, f"plate: the last frame at load factor 1 ({last[0]})")
        m = meshio.read(os.path.join(folder, last[2]))
        x0, u = m.points - m.point_data["displacement"], m.point_data["displacement"]
        end = np.isclose(x0[:, 0], PLATE_L)
        side = np.isclose(x0[:, 1], PLATE_B)
        err_u = np.max(np.abs(u[end, 0] - (lam1 - 1) * PLATE_L)) / ((lam1 - 1) * PLATE_L)
        check(err_u < 1e-10, f"plate: end displacement (lambda1 - 1) L = {(lam1 - 1) * PLATE_L:.9g} "
              f"to 1e-10 ({err_u:.1e}; E11 = {e11:.6g})")
        err_w = np.max(np.abs(u[side, 1] - (lam3 - 1) * PLATE_B)) / abs((lam3 - 1) * PLATE_B)
        check(err_w < 1e-10, f"plate: width change (lambda3 - 1) B = {(lam3 - 1) * PLATE_B:.9g} "
              f"to 1e-10 ({err_w:.1e})")
        th = m.point_data.get("thickness")
        want = PLATE_H * lam3
        err_t = None if th is None else np.max(np.abs(th - want)) / want
        check(th is not None and err_t < 1e-10,
              f"plate: thickness h sqrt(1 - 2 nu E11) = {want:.9g} at every node to 1e-10 "
              f"({err_t if err_t is None else f'{err_t:.1e}'}; h (1 - nu eps) = "
              f"{PLATE_H * (1 - PLATE_NU * (lam1 - 1)):.9g})")


def main():
    if len(sys.argv) not in (2, 3, 4):
        print(__doc__)
        return 2
    exe = os.path.abspath(sys.argv[1])
    if os.path.isdir(exe):
        exe = os.path.join(exe, "test_vtu")
    outdir = os.path.abspath(sys.argv[2]) if len(sys.argv) >= 3 else tempfile.mkdtemp(
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

    if len(sys.argv) == 4:
        check_runs(os.path.abspath(sys.argv[3]), outdir)
    print(f"{CK.passed} passed, {CK.failed} failed")
    return 0 if CK.failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
