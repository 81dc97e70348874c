#!/usr/bin/env python3
"""Surface stresses in the VTU frames against beam theory (issue 17).

Usage:
    python3 tests/test_stresses.py CASCA OUTDIR

A cantilever strip (L = 10, b = 1, h = 0.1, E = 1.2e6, poisson = 0) clamped at x = 0 carries a
tip shear F = 1e-3 along +z (the side the initial fibre points to, so "top" is z > 0), as a
uniform edge load, in one static load step. The tip deflection F L^3 / (3 E I) = 3.3e-3 is
3.3e-4 L: small-deflection bending, where Euler-Bernoulli theory gives the axial stress at a
section x as sigma_xx = -+ M c / I on the top and bottom faces, M = F (L - x), c = h/2,
I = b h^3 / 12 (upward tip load: top in compression), and 0 on the mid-surface. With
poisson = 0 the plate's bending stiffness equals the beam's (no anticlastic term).

Asserted, for every element whose centroid lies in L/4 <= x <= L/2 (away from the clamp and
the loaded tip, so that Saint-Venant effects are gone), from the cell data at the centroid:
  - stress_top[xx] = -M c / I and stress_bottom[xx] = +M c / I within 2% (the cubic element
    reproduces the linear moment exactly, so what remains is the shell's transverse shear
    and the geometric non-linearity at w/L = 3e-4, both far below 2%);
  - stress_mid[xx] = 0 within 1% of M c / I (membrane stress of a bent strip: second order
    in the rotations, 1e-7 of it here);
  - von_mises_top and von_mises_bottom = M c / I within 2% (uniaxial stress: the transverse
    shear F / (b h) is 2e-3 of the bending stress and enters squared);
  - stress_mid[xz] = F / (b h) within 5%: equilibrium of the section with the shell's
    transverse shear uniform through the thickness (straight fibres, no shear correction);
    5% because the cubic element's shear, one derivative less smooth than its bending,
    scatters by a few per cent about that value from element to element;
  - von_mises (mid-surface, the field older frames had) = sqrt(3) F / (b h) within 5%
    (pure shear there: sigma_xx = 0);
  - the tensors have 6 components (xx yy zz xy yz xz: ParaView's symmetric tensor) and are
    declared Float32 in the file.
and from the point data (tensors at each node averaged over the elements around it), for the
top-face nodes in the same span: stress_top[xx] = -M c / I within 2%, M at the node's x.
The cell data strain_energy summed over the cells equals the beam's F^2 L^3 / (6 E I)
within 1% (bending; the transverse shear's share, 3 E I / (G A L^2) of it, is 5e-5).
The expected values come from beam theory, never from casca's output.
"""
import os
import sys
import xml.etree.ElementTree as ET

import numpy as np
import meshio
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from casca_testlib import Checks, run_scene  # noqa: E402

L, B, H, E, F = 10.0, 1.0, 0.1, 1.2e6, 1.0e-3
I = B * H**3 / 12
C = H / 2
XX, XZ = 0, 5   # indices of s_xx and s_xz in the 6 components xx yy zz xy yz xz

DECK = """&run
  analysis = 'static', load_steps = 1
/
&output
  interval = 1.0
/
&body
  name = 'strip', mesh = 'strip', lx = %(L)r, ly = %(B)r, nx = 10, ny = 1
  young = %(E)r, poisson = 0.0, density = 1.0, thickness = %(H)r
/
&restraint
  body = 'strip', box_max = 0.0, 1e9, 1e9, fix = 'clamped'
/
&load
  body = 'strip', box_min = %(L)r, -1e9, -1e9, force = 0.0, 0.0, %(F)r, kind = 'edge'
/
""" % dict(L=L, B=B, H=H, E=E, F=F)


def last_frame(folder):
    """The last frame listed in run.pvd, read with meshio."""
    sets = ET.parse(os.path.join(folder, "run.pvd")).getroot().iter("DataSet")
    return meshio.read(os.path.join(folder, list(sets)[-1].get("file")))


def cell_array(mesh, name):
    return np.concatenate(mesh.cell_data[name])


def main():
    casca, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    ck = Checks()
    out, _ = run_scene(casca, ck, work, "cantilever_bending", DECK)
    if out is None:
        ck.finish()
    mesh = last_frame(out)
    x0 = mesh.points - mesh.point_data["displacement"]     # initial positions
    conn = np.concatenate([c.data for c in mesh.cells])
    xc = x0[conn[:, :3]].mean(axis=1)[:, 0]                # centroid x of every cell
    span = (xc >= L / 4) & (xc <= L / 2)
    ck.record("elements with centroids in L/4..L/2", span.sum() >= 4, "%d" % span.sum())
    ref = F * (L - xc[span]) * C / I                       # M c / I at the centroids

    top = cell_array(mesh, "stress_top")[span]
    mid = cell_array(mesh, "stress_mid")[span]
    bot = cell_array(mesh, "stress_bottom")[span]
    header = open(os.path.join(out, "frame_00000.vtu"), "rb").read(20000).split(b"<AppendedData")[0]
    for name, s in (("top", top), ("mid", mid), ("bottom", bot)):
        ck.record("stress_%s has 6 components" % name, s.shape[1] == 6, str(s.shape))
        ck.record("stress_%s is Float32 (cell and point data)" % name,
                  header.count(b'type="Float32" Name="stress_%s"' % name.encode()) == 2)
    ck.le("stress_top[xx] = -M c/I: worst relative error", np.max(np.abs(top[:, XX] / -ref - 1)), 0.02)
    ck.le("stress_bottom[xx] = +M c/I: worst relative error", np.max(np.abs(bot[:, XX] / ref - 1)), 0.02)
    ck.le("stress_mid[xx] / (M c/I): worst", np.max(np.abs(mid[:, XX] / ref)), 0.01)
    for name in ("von_mises_top", "von_mises_bottom"):
        vm = cell_array(mesh, name).ravel()[span]
        ck.le("%s = M c/I: worst relative error" % name, np.max(np.abs(vm / ref - 1)), 0.02)
    tau = F / (B * H)
    ck.le("stress_mid[xz] = F/(b h): worst relative error", np.max(np.abs(mid[:, XZ] / tau - 1)), 0.05)
    vm_mid = cell_array(mesh, "von_mises").ravel()[span]
    ck.le("von_mises (mid-surface) = sqrt(3) F/(b h): worst relative error",
          np.max(np.abs(vm_mid / (np.sqrt(3) * tau) - 1)), 0.05)

    ck.close("strain_energy summed over the cells = F^2 L^3 / (6 E I) [J]",
             float(np.sum(cell_array(mesh, "strain_energy"))), F**2 * L**3 / (6 * E * I), 0.01)

    # nodal averages: top-face tensors at the nodes of the span
    nodes = np.unique(conn[span])
    nodes = nodes[(x0[nodes, 0] >= L / 4) & (x0[nodes, 0] <= L / 2)]
    ref_n = F * (L - x0[nodes, 0]) * C / I
    top_n = mesh.point_data["stress_top"][nodes]
    ck.le("point stress_top[xx] = -M c/I at %d nodes: worst relative error" % len(nodes),
          np.max(np.abs(top_n[:, XX] / -ref_n - 1)), 0.02)
    ck.finish()


if __name__ == "__main__":
    main()
