"""Slit annular plate of Sze, Liu & Lo (2004), test 3.3, as 10-node cubic triangles (Gmsh MSH 2.2).

    python3 tests/data/make_slit_annular_plate.py [--nr 4] [--nt 32] [-o FILE]

The plate lies in z = 0: inner radius 6, outer radius 10, cut along the positive x axis. The
edge at theta = 0 is meant to be clamped, the edge at theta = 2 pi loaded by a line force in z;
the two edges have the same coordinates but distinct nodes. nr x nt cells in (r, theta), each
split into two triangles along the diagonal that alternates from cell to cell. Nodes are the
points of the (3 nr + 1) x (3 nt + 1) grid in (r, theta), mapped by x = r cos(theta),
y = r sin(theta): the vertices, the two nodes of every edge at 1/3 and 2/3 and the centroid of
every triangle (in (r, theta)) all fall on that grid. Node number (1-based, also the Gmsh tag)
of grid point (i, j), i radial from r = 6, j around from theta = 0: 1 + i + j (3 nr + 1).
Triangles are counter-clockwise in (r, theta), so their normal is +z. Node order within a
triangle: Gmsh's TRI10 (vertices; edge 1-2 at 1/3 and 2/3 from vertex 1; edge 2-3 from 2; edge
3-1 from 3; centroid).
"""
import argparse
import math

R_IN, R_OUT = 6.0, 10.0


def node(i, j, nr):
    return 1 + i + j * (3 * nr + 1)


def grid(nr, nt):
    """Node coordinates, (3 nr + 1) (3 nt + 1) rows in node-number order."""
    xs = []
    for j in range(3 * nt + 1):
        th = 2 * math.pi * j / (3 * nt)
        for i in range(3 * nr + 1):
            r = R_IN + (R_OUT - R_IN) * i / (3 * nr)
            y = 0.0 if j in (0, 3 * nt) else r * math.sin(th)
            xs.append((r * math.cos(th), y, 0.0))
    return xs


def tri10(a, b, c, nr):
    """The TRI10 connectivity of the triangle with grid vertices a, b, c (each (i, j))."""
    def at(p, q, s):  # grid point a + s (q - p) / 3 along p -> q
        return (p[0] + (q[0] - p[0]) * s // 3, p[1] + (q[1] - p[1]) * s // 3)
    cen = ((a[0] + b[0] + c[0]) // 3, (a[1] + b[1] + c[1]) // 3)
    pts = [a, b, c, at(a, b, 1), at(a, b, 2), at(b, c, 1), at(b, c, 2), at(c, a, 1), at(c, a, 2), cen]
    return [node(i, j, nr) for i, j in pts]


def elements(nr, nt):
    els = []
    for jc in range(nt):
        for ic in range(nr):
            i, j = 3 * ic, 3 * jc
            p00, p10, p01, p11 = (i, j), (i + 3, j), (i, j + 3), (i + 3, j + 3)
            if (ic + jc) % 2 == 0:   # diagonal p00-p11
                els += [tri10(p00, p10, p11, nr), tri10(p00, p11, p01, nr)]
            else:                    # diagonal p10-p01
                els += [tri10(p00, p10, p01, nr), tri10(p10, p11, p01, nr)]
    return els


def clamped_edge(nr):
    """Node numbers on the edge theta = 0, from r = 6 to r = 10."""
    return [node(i, 0, nr) for i in range(3 * nr + 1)]


def loaded_edge(nr, nt):
    """Node numbers on the edge theta = 2 pi, from r = 6 (point A) to r = 10 (point B)."""
    return [node(i, 3 * nt, nr) for i in range(3 * nr + 1)]


def edge_loads(nr, q):
    """Consistent nodal forces of a uniform line force q along the loaded edge, in its node
    order: each cubic segment of length (R_OUT - R_IN) / nr gives 1/8, 3/8, 3/8, 1/8 of its
    q L (the integrals of the cubic Lagrange functions over the segment)."""
    seg = q * (R_OUT - R_IN) / nr
    f = [0.0] * (3 * nr + 1)
    for s in range(nr):
        for k, w in enumerate((1 / 8, 3 / 8, 3 / 8, 1 / 8)):
            f[3 * s + k] += w * seg
    return f


def write_msh22(path, nr, nt):
    xs, els = grid(nr, nt), elements(nr, nt)
    with open(path, "w") as f:
        f.write("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n%d\n" % len(xs))
        for k, (x, y, z) in enumerate(xs):
            f.write("%d %.17g %.17g %.17g\n" % (k + 1, x, y, z))
        f.write("$EndNodes\n$Elements\n%d\n" % len(els))
        for k, c in enumerate(els):
            f.write("%d 21 2 1 1 %s\n" % (k + 1, " ".join(map(str, c))))
        f.write("$EndElements\n")
    return len(xs), len(els)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--nr", type=int, default=4)
    ap.add_argument("--nt", type=int, default=32)
    ap.add_argument("-o", default="slit_annular_plate.msh")
    a = ap.parse_args()
    n, e = write_msh22(a.o, a.nr, a.nt)
    print("%s: %d nodes, %d cubic triangles" % (a.o, n, e))
