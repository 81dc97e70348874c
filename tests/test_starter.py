"""`casca check` as a starter: per-body figures, warnings and `&body flip_normals` (issue 17).

usage: test_starter.py CASCA MESH_DIR WORK_DIR

Every expected figure is computed here from the deck's geometry, not taken from casca:
plate          a generated plate 0.3 x 0.2 m, 3 x 2 cells, h 0.01 m, steel (rho 7800, E 210e9,
               nu 0.3): mass = rho lx ly h and area = lx ly to 1e-10 (a flat element's mass
               is exact: the mass rule is of degree 6, the integrand of degree 6); l_min = 0.1 m
               (the cells' shorter side); quality 1 (straight-sided elements, nodes at thirds);
               c = sqrt(E / (rho (1 - nu^2))), the fibre-stretch frequency 2 sqrt(3) c_d / h
               (c_d = sqrt((lambda + 2 mu) / rho); tests/test_starter_freq.f90 holds it against
               the element's eigenvalues) and the explicit step 2 / (the larger of it and the
               membrane 2 c / l_min): these are the formulas, evaluated here; unknowns 7 x 70
               nodes and matrix entries 12 elements x 70 x 71 / 2 (each element's lower
               triangle, nothing held); printed to 5 digits: 1e-4. No warning.
sphere         a generated sphere R 1, h 0.05, rho 7700: mass against rho times the shell's
               volume 4 pi / 3 ((R + h/2)^3 - (R - h/2)^3) (4 pi R^2 h + pi h^3 / 3: the
               mass integrates the thickness along the fibres) within 2e-5, the cubic
               surface's area error, fourth order in the element size: the error falls by
               16 from n_div 3 to 6 (asserted between 12 and 20); its mesh is closed with
               normals outwards. No warning.
inward sphere  mesh/sphere_6.msh with every element reversed here (vertices 1 and 2 swapped,
               edge nodes moved with them): 'normals point inwards' warned (exit 0); with
               flip_normals = .true. no warning. A plate 0.02 m above its pole node impacting
               it between mid-surfaces (one-sided): refused as overlapping (exit 2) with the
               inward normals; with flip_normals its gap is 0.02 m (1e-6).
one flipped    mesh/strip_20x1.msh with element 6 reversed: refused (exit 2), the message names
               element 6 and the number of edges it shares with other elements (counted here
               from the file).
T-junction     three flat elements on one edge (two in a plane, alike, one across): accepted
               (a branching edge has no orientation to agree on), its 6 boundary edges and
               1 branching edge reported as built.
distorted      one straight-sided element, legs 0.1 m, its centroid node moved by
               (d, d) in the plane: the area Jacobian is 1 + grad(phi_10) . (d, d) / 0.1 at
               each point (phi_10 = 27 L1 L2 L3; the determinant of a rank-one update), so
               the quality (min/max over the 7 Radon points) is computed here: d = 0.005 m
               gives 0.38 (warned: below 0.5), d = 0 gives 1 (not warned); 1e-4.
never          two rings closing at 6 m/s: no 'never meets' warning; ring1 moving away
               (-10 m/s against ring2's 4): warned; the same under gravity: not warned (it
               may bring them together); four rings in a row, pairs 1-2, 2-3, 3-4 listed, the
               first thrown at the three at rest: no warning (each, once hit, meets the next;
               pair 3-4 was warned of).
large dt       the closing rings with dt 5e-5 s (3e-4 m per step): no warning; dt 0.05 s
               (0.3 m per step, beyond the band 1.25 h + half a sub-triangle edge < 0.13 m):
               warned, the per-step travel printed as 6 dt (1e-4).
tracked        ring2 placed at x = 2.1 with the track point (0, 1, 0) given in its mesh's own
               coordinates (1.33 m from ring2, beyond 5% of its size and its longest edge): warned, the printed distance equal to the nearest node's, computed
               here from the mesh file's nodes moved by the center (1e-4), and the percentage of
               the body's bounding-box diagonal; the placed point (2.1, 1, 0): no warning.
seam           two unit squares of 2 x 2 cells each, side by side along x = 1, written here: as
               two separately numbered meshes (a Gmsh seam: 3 x 2 + 1 = 7 coincident node
               pairs along x = 1) casca check and a (linear) casca run warn, exit 0, naming the
               body, 7 pairs, one pair's numbers and its coordinates (x = 1 there); with the
               nodes merged, no warning; nor for the shipped examples and meshes.
bad value      flip_normals = 3: exit 2, the message names the deck, its line and the field.
element_size   generated ring (R 1, width 0.2), sphere (R 0.5) and plate (1 x 0.35) with
               element_size 0.1: element counts equal those counted from the geometry here
               (2 ceil(2 pi R / s) ceil(w / s); 20 ceil(R / sin 72deg / s)^2; 2 ceil(lx / s)
               ceil(ly / s)), and every l_min <= s; with a mesh file: exit 2 naming the key.
"""
import math
import os
import re
import sys

from casca_testlib import Checks, run

casca, meshdir, work = [os.path.abspath(a) for a in sys.argv[1:4]]
os.makedirs(work, exist_ok=True)
ck = Checks()
STEEL = "young = 210e9, poisson = 0.3, density = 7800"
BODY = re.compile(r"body '([^']*)': (\d+) nodes?, (\d+) elements?, thickness (\S+) m, area (\S+) m\^2, "
                  r"mass (\S+) kg\n.*mesh (open|closed)[^\n]*\n\s+l_min (\S+) m, quality (\S+) "
                  r"\(element (\d+)\); c (\S+) m/s.* 2 sqrt\(3\) c_d / h = (\S+) rad/s; "
                  r"explicit stable step ~ 2 / omega_max = (\S+) s")
EQS = re.compile(r"equations: (\d+) unknowns, (\S+) matrix entries")
REVERSED = [2, 1, 3, 5, 4, 9, 8, 7, 6, 10]   # vertices 1, 2 swapped (Gmsh TRI10 order)


def check(name, text):
    """casca check on the deck text: (exit code, stdout, stderr, {body: figures})"""
    deck = os.path.join(work, name + ".nml")
    with open(deck, "w") as f:
        f.write(text)
    p = run([casca, "check", deck])
    print(p.stdout.strip())
    print(p.stderr.strip())
    bodies = {}
    for m in BODY.finditer(p.stdout):
        bodies[m.group(1)] = dict(nodes=int(m.group(2)), elements=int(m.group(3)), area=float(m.group(5)),
                                  mass=float(m.group(6)), closed=m.group(7) == "closed",
                                  l_min=float(m.group(8)), quality=float(m.group(9)),
                                  c=float(m.group(11)), omega_t=float(m.group(12)),
                                  step=float(m.group(13)))
    return p.returncode, p.stdout, p.stderr, bodies


def warnings(err):
    return [line for line in err.splitlines() if line.startswith("warning:")]


def reverse_elements(src, dst, which):
    """Copy the MSH 4.1 file src to dst with the 10-node triangles k (0-based) for which
    which(k) holds reversed; returns the reversed elements' vertex triples (old order)"""
    lines = open(src).read().split("\n")
    i = lines.index("$Elements")
    j, k, tris = i + 2, 0, []
    for _ in range(int(lines[i + 1].split()[0])):
        n, typ = int(lines[j].split()[3]), int(lines[j].split()[2])
        j += 1
        for _ in range(n):
            w = lines[j].split()
            if typ == 21:
                tris.append(w[1:4])
                if which(k):
                    lines[j] = " ".join([w[0]] + [w[p] for p in REVERSED])
                k += 1
            j += 1
    with open(dst, "w") as f:
        f.write("\n".join(lines))
    return tris


def write_msh(path, nodes, conn):
    """an ASCII MSH 4.1 file of the points nodes [(x, y, z)] and 10-node triangles conn
    (1-based node numbers, Gmsh TRI10 order) on one surface entity"""
    with open(path, "w") as f:
        f.write("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 %d 1 %d\n2 1 0 %d\n" % ((len(nodes),) * 3))
        f.write("".join("%d\n" % (k + 1) for k in range(len(nodes))))
        f.write("".join("%.17g %.17g %.17g\n" % p for p in nodes))
        f.write("$EndNodes\n$Elements\n1 %d 1 %d\n2 1 21 %d\n" % ((len(conn),) * 3))
        f.write("".join("%d %s\n" % (e + 1, " ".join(map(str, c))) for e, c in enumerate(conn)))
        f.write("$EndElements\n")


# plate: mass, area, sizes, equations against the deck's geometry
lx, ly, h, rho, E, nu = 0.3, 0.2, 0.01, 7800.0, 210e9, 0.3
code, out, err, b = check("plate", f"""&run dt = 1.0e-5, t_end = 1.0e-3 /
&body name = 'plate', mesh = 'plate', lx = {lx}, ly = {ly}, nx = 3, ny = 2, {STEEL}, thickness = {h} /
""")
ck.record("plate: exit 0", code == 0, err[-300:])
pl = b.get("plate")
if pl is None:
    ck.record("plate: body line printed", False)
else:
    c = math.sqrt(E / (rho * (1 - nu ** 2)))
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    omega_t = 2 * math.sqrt(3 * (lam + 2 * mu) / rho) / h
    ck.close("plate: mass = rho lx ly h [kg]", pl["mass"], rho * lx * ly * h, 1e-10)
    ck.close("plate: area = lx ly [m^2]", pl["area"], lx * ly, 1e-4)
    ck.close("plate: l_min = the cells' shorter side [m]", pl["l_min"], 0.1, 1e-4)
    ck.close("plate: quality of straight-sided elements", pl["quality"], 1.0, 1e-4)
    ck.close("plate: c = sqrt(E / (rho (1 - nu^2))) [m/s]", pl["c"], c, 1e-4)
    ck.close("plate: thickness stretch 2 sqrt(3) c_d / h [rad/s]", pl["omega_t"], omega_t, 1e-4)
    ck.close("plate: explicit step 2 / max(2 c / l_min, 2 sqrt(3) c_d / h) [s]", pl["step"],
             2 / max(2 * c / 0.1, omega_t), 1e-4)
    ck.record("plate: open mesh", not pl["closed"])
m = EQS.search(out)
ck.record("plate: equations line printed", m is not None)
if m:
    ck.close("plate: unknowns = 7 x 70 nodes", float(m.group(1)), 7 * 70, 1e-12)
    ck.close("plate: matrix entries = 12 x 70 x 71 / 2", float(m.group(2)), 12 * 70 * 71 / 2, 1e-4)
ck.record("plate: no warning", warnings(err) == [], str(warnings(err)))

# sphere: mass against the shell's volume, its error fourth order in the element size
R, hs, rs = 1.0, 0.05, 7700.0
exact = rs * 4 * math.pi / 3 * ((R + hs / 2) ** 3 - (R - hs / 2) ** 3)
errs = {}
for n in (3, 6):
    code, out, err, b = check("sphere_%d" % n, f"""&run dt = 1.0e-5, t_end = 1.0e-3 /
&body name = 'ball', mesh = 'sphere', radius = {R}, n_div = {n}, young = 210e9, density = {rs}, thickness = {hs} /
""")
    sp = b.get("ball")
    ck.record("sphere n_div %d: exit 0, body line printed" % n, code == 0 and sp is not None, err[-300:])
    if sp is not None:
        errs[n] = sp["mass"] / exact - 1
        ck.record("sphere n_div %d: closed, normals outwards" % n, sp["closed"] and "normals outwards" in out)
    ck.record("sphere n_div %d: no warning" % n, warnings(err) == [], str(warnings(err)))
if 6 in errs:
    ck.close("sphere n_div 6: mass = rho 4 pi/3 ((R + h/2)^3 - (R - h/2)^3) [kg]", exact * (1 + errs[6]), exact, 2e-5)
if 3 in errs and 6 in errs:
    ratio = errs[3] / errs[6]
    ck.record("sphere: mass error falls 12..20 times from n_div 3 to 6 (fourth order: 16)",
              12 <= ratio <= 20, "%.4g (errors %.3g, %.3g)" % (ratio, errs[3], errs[6]))

# a closed mesh with inward normals, and flip_normals
inward = os.path.join(work, "sphere_inward.msh")
reverse_elements(os.path.join(meshdir, "sphere_6.msh"), inward, lambda k: True)


def sphere_and_lid(flip, lid=True):
    text = f"""&run dt = 1.0e-5, t_end = 1.0e-3 /
&body name = 'shell', mesh = 'file', file = '{inward}', flip_normals = {flip}, {STEEL}, thickness = 0.01 /
"""
    if lid:
        text += f"""&body name = 'lid', mesh = 'plate', lx = 0.4, ly = 0.4, nx = 2, ny = 2, center = -0.2, -0.2, 1.02,
  velocity = 0.0, 0.0, -1.0, {STEEL}, thickness = 0.01 /
&contact surface = 'mid', pairs = 'lid', 'shell' /
"""
    return text


code, out, err, b = check("inward", sphere_and_lid(".false.", lid=False))
ck.record("inward normals: exit 0, warned 'normals point inwards'",
          code == 0 and any("'shell'" in w and "normals point inwards" in w for w in warnings(err)), err[-400:])
code, out, err, b = check("inward_flipped", sphere_and_lid(".true.", lid=False))
ck.record("inward normals, flip_normals: exit 0, no warning", code == 0 and warnings(err) == [], err[-400:])
ck.record("inward normals, flip_normals: the mesh is closed with normals outwards", "normals outwards" in out)
code, out, err, b = check("inward_lid", sphere_and_lid(".false."))
ck.record("inward normals, lid 0.02 m above between mid-surfaces: refused as overlapping (exit 2)",
          code == 2 and "overlap" in err, err[-300:])
code, out, err, b = check("inward_lid_flipped", sphere_and_lid(".true."))
m = re.search(r"pair 'lid' -> 'shell'[^:]*: gap\s+(\S+) m", out)
ck.record("flip_normals, lid: exit 0 and the pair's gap printed", code == 0 and m is not None, err[-300:])
if m:
    ck.close("flip_normals, lid: gap = 0.02 m (node above the pole node)", float(m.group(1)), 0.02, 1e-6)

# one element reversed among its neighbours: refused, naming it
strip = os.path.join(work, "strip_one_flipped.msh")
tris = reverse_elements(os.path.join(meshdir, "strip_20x1.msh"), strip, lambda k: k == 5)
mine = {frozenset(p) for p in ((tris[5][0], tris[5][1]), (tris[5][1], tris[5][2]), (tris[5][2], tris[5][0]))}
shared = sum(1 for k, t in enumerate(tris) if k != 5
             for p in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])) if frozenset(p) in mine)
code, out, err, b = check("one_flipped", f"""&run dt = 1.0e-5, t_end = 1.0e-3 /
&body name = 'strip', mesh = 'file', file = '{strip}', {STEEL}, thickness = 0.01 /
""")
m = re.search(r"not consistently oriented: elements (\d+) and (\d+) .*\((\d+) such edges?\)", err)
ck.record("one element reversed: refused (exit 2), the message names element 6",
          code == 2 and m is not None and "6" in m.groups()[:2], err[-400:])
if m:
    ck.close("one element reversed: disagreeing edges = its edges shared with others (%d)" % shared,
             float(m.group(3)), shared, 1e-12)


def tjunction(path):
    """three flat cubic triangles sharing the edge (0,0,0)-(0.1,0,0): two in the plane z = 0
    (apexes at y = +-0.1, oriented alike), one in y = 0 (apex at z = 0.1)"""
    L = 0.1
    nodes = [(0, 0, 0), (L, 0, 0), (L / 3, 0, 0), (2 * L / 3, 0, 0)]   # the shared edge
    conn = []
    def lerp(p, q, t):
        return tuple(p[i] + t * (q[i] - p[i]) for i in range(3))
    for apex, reverse in (((0, L, 0), False), ((0, -L, 0), True), ((0, 0, L), False)):
        k = len(nodes)
        v1, v2 = nodes[0], nodes[1]
        nodes += [apex, lerp(v2, apex, 1 / 3), lerp(v2, apex, 2 / 3), lerp(apex, v1, 1 / 3),
                  lerp(apex, v1, 2 / 3), tuple((v1[i] + v2[i] + apex[i]) / 3 for i in range(3))]
        c = [1, 2, k + 1, 3, 4, k + 2, k + 3, k + 4, k + 5, k + 6]   # Gmsh TRI10 order, 1-based
        if reverse:   # vertices 1, 2 swapped
            c = [c[p - 1] for p in REVERSED]
        conn.append(c)
    write_msh(path, nodes, conn)

tj = os.path.join(work, "tjunction.msh")
tjunction(tj)
code, out, err, b = check("tjunction", f"""&run dt = 1.0e-5, t_end = 1.0e-3 /
&body name = 't', mesh = 'file', file = '{tj}', {STEEL}, thickness = 0.001 /
""")
ck.record("T-junction (3 elements on one edge, the plane pair alike): accepted (exit 0), one "
          "warning: 1 edge shared by three or more elements, normal to none of them",
          code == 0 and len(warnings(err)) == 1 and "1 edge is shared by three or more" in err, err[-300:])
ck.record("T-junction: 6 boundary edges and 1 edge of three elements reported",
          "open (6 boundary edges, 1 edge of three or more elements)" in out)


# a distorted element: the quality from the determinant of a rank-one update
def expected_quality(eta):
    r15 = math.sqrt(15)
    pts = [(1 / 3, 1 / 3)]
    for a in ((6 - r15) / 21, (6 + r15) / 21):
        pts += [(a, a), (1 - 2 * a, a), (a, 1 - 2 * a)]
    j = []
    for x1, x2 in pts:
        l1, l2, l3 = 1 - x1 - x2, x1, x2
        g1, g2 = 27 * l3 * (l1 - l2), 27 * l2 * (l1 - l3)   # grad of 27 L1 L2 L3
        j.append(1 + g1 * eta + g2 * eta)
    return min(j) / max(j)


def one_element(d):
    """a MSH 4.1 file of one straight-sided element, legs 0.1 m, centroid node moved by (d, d)"""
    xi = [(0, 0), (1, 0), (0, 1), (1 / 3, 0), (2 / 3, 0), (2 / 3, 1 / 3), (1 / 3, 2 / 3), (0, 2 / 3),
          (0, 1 / 3), (1 / 3, 1 / 3)]
    x = [(0.1 * a, 0.1 * b) for a, b in xi]
    x[9] = (x[9][0] + d, x[9][1] + d)
    path = os.path.join(work, "one_%g.msh" % d)
    write_msh(path, [(a, b, 0.0) for a, b in x], [list(range(1, 11))])
    return path


for d, warned in ((0.005, True), (0.0, False)):
    code, out, err, b = check("distorted_%g" % d, f"""&run dt = 1.0e-5, t_end = 1.0e-3 /
&body name = 'p', mesh = 'file', file = '{one_element(d)}', {STEEL}, thickness = 0.001 /
""")
    q = expected_quality(d / 0.1)
    p = b.get("p")
    ck.record("centroid node moved by %g m: exit 0, body line printed" % d, code == 0 and p is not None, err[-300:])
    if p is not None:
        ck.close("centroid node moved by %g m: quality [min/max area Jacobian]" % d, p["quality"], q, 1e-4)
    ck.record("centroid node moved by %g m (quality %.3f): %s" % (d, q, "warned 'distorted'" if warned
                                                                     else "no warning"),
              any("distorted" in w for w in warnings(err)) == warned and (warned or warnings(err) == []),
              str(warnings(err)))

# pairs that never meet, and a dt that crosses the contact band in one step
ring = os.path.join(meshdir, "ring_20x1.msh")


def rings(v1, dt, t_end, gravity="0.0, 0.0, 0.0"):
    return f"""&run dt = {dt}, t_end = {t_end}, gravity = {gravity} /
&body name = 'ring1', mesh = 'file', file = '{ring}', velocity = {v1}, 0.0, 0.0, {STEEL}, thickness = 0.05 /
&body name = 'ring2', mesh = 'file', file = '{ring}', center = 2.1, 0.0, 0.0, velocity = 4.0, 0.0, 0.0,
  {STEEL}, thickness = 0.05 /
"""


code, out, err, b = check("closing", rings(10.0, 5.0e-5, 1.0e-3))
ck.record("rings closing at 6 m/s, dt 5e-5 s: exit 0, no warning", code == 0 and warnings(err) == [],
          str(warnings(err)))
code, out, err, b = check("apart", rings(-10.0, 5.0e-5, 1.0e-3))
ck.record("ring1 moving away: warned 'never meets'", code == 0 and any(
    "'ring1' -> 'ring2' never meets" in w for w in warnings(err)), str(warnings(err)))
code, out, err, b = check("apart_gravity", rings(-10.0, 5.0e-5, 1.0e-3, "0.0, -9.81, 0.0"))
ck.record("ring1 moving away under gravity (it may bring them together): no warning",
          code == 0 and warnings(err) == [], str(warnings(err)))
row = rings(10.0, 5.0e-5, 1.0e-3).replace("velocity = 4.0, 0.0, 0.0", "velocity = 0.0, 0.0, 0.0") + "".join(
    f"&body name = 'ring{k}', mesh = 'file', file = '{ring}', center = {2.1 * (k - 1):.1f}, 0.0, 0.0, {STEEL}, "
    "thickness = 0.05 /\n" for k in (3, 4)) + \
    "&contact pairs = 'ring1', 'ring2', 'ring2', 'ring3', 'ring3', 'ring4' /\n"
code, out, err, b = check("row", row)
ck.record("four rings in a row, the first thrown at the three at rest: no 'never meets' warning",
          code == 0 and not any("never meets" in w for w in warnings(err)), str(warnings(err)))
code, out, err, b = check("large_dt", rings(10.0, 0.05, 0.1))
m = re.search(r"'ring1' -> 'ring2' closes (\S+) m in one step", err)
ck.record("rings closing at 6 m/s, dt 0.05 s: exit 0, warned", code == 0 and m is not None, str(warnings(err)))
if m:
    ck.close("dt 0.05 s: the travel in one step = 6 dt [m]", float(m.group(1)), 6 * 0.05, 1e-4)

# a track point given in the mesh's coordinates instead of the placed scene's
def tracked(point):
    return rings(10.0, 5.0e-5, 1.0e-3) + f"""&output track = {point}, track_body = 'ring2' /
"""


import meshio  # noqa: E402
xr = meshio.read(ring).points + [2.1, 0.0, 0.0]
dist = min(math.dist(x, (0.0, 1.0, 0.0)) for x in xr)
diag = math.dist(xr.min(axis=0), xr.max(axis=0))
code, out, err, b = check("track_far", tracked("0.0, 1.0, 0.0"))
m = re.search(r"&output track 1: the nearest node of 'ring2' is (\S+) m from .*, (\d+)% of the body's size", err)
ck.record("track point (0, 1, 0) with ring2 at x = 2.1: exit 0, warned", code == 0 and m is not None,
          str(warnings(err)))
if m:
    ck.close("the warned distance = the nearest node's, from the mesh file [m]", float(m.group(1)), dist, 1e-4)
    ck.record("the warned percentage = 100 distance / bounding-box diagonal (%d)" % round(100 * dist / diag),
              int(m.group(2)) == round(100 * dist / diag), m.group(2))
code, out, err, b = check("track_near", tracked("2.1, 1.0, 0.0"))
ck.record("track point (2.1, 1, 0) on the placed ring2: no warning", code == 0 and warnings(err) == [],
          str(warnings(err)))

# a bad value of the new key
code, out, err, b = check("bad_flip", f"""&run dt = 1.0e-5, t_end = 1.0e-3 /
&body name = 'p', mesh = 'plate',
  flip_normals = 3, {STEEL}, thickness = 0.01 /
""")
ck.record("flip_normals = 3: exit 2, the message names the deck, line 3 and flip_normals",
          code == 2 and re.search(r"bad_flip\.nml:3:.*flip_normals", err) is not None, err[-300:])

# element_size (issue 18): the generators' counts for edges of at most that size, counted here
# from the geometry (two triangles a cell; a sphere's icosahedron edge R / sin(72 deg))
SIZE = 0.1
code, out, err, b = check("element_size", f"""&run dt = 1.0e-4, t_end = 1.0e-3 /
&body name = 'r', mesh = 'ring', radius = 1.0, width = 0.2, element_size = {SIZE}, {STEEL}, thickness = 0.05 /
&body name = 's', mesh = 'sphere', radius = 0.5, element_size = {SIZE}, center = 5.0, 0.0, 0.0,
  {STEEL}, thickness = 0.05 /
&body name = 'p', mesh = 'plate', lx = 1.0, ly = 0.35, element_size = {SIZE}, center = 0.0, 5.0, 0.0,
  {STEEL}, thickness = 0.05 /
&contact enabled = .false. /
""")
expected = {"r": 2 * math.ceil(2 * math.pi * 1.0 / SIZE) * math.ceil(0.2 / SIZE),
            "s": 20 * math.ceil(0.5 / math.sin(0.4 * math.pi) / SIZE) ** 2,
            "p": 2 * math.ceil(1.0 / SIZE) * math.ceil(0.35 / SIZE)}
for name, n in expected.items():
    ck.record("element_size %g: body '%s' has %d elements" % (SIZE, name, n),
              name in b and b[name]["elements"] == n, str(b.get(name, {}).get("elements")))
    if name in b:
        ck.le("element_size %g: body '%s' l_min [m]" % (SIZE, name), b[name]["l_min"], SIZE)
code, out, err, b = check("element_size_file", f"""&run dt = 1.0e-4, t_end = 1.0e-3 /
&body name = 'r', mesh = 'file', file = '{ring}', element_size = 0.1, {STEEL}, thickness = 0.05 /
""")
ck.record("element_size with a mesh file: exit 2 naming element_size", code == 2 and "element_size" in err,
          err[-300:])

# a seam: two squares meshed separately, coincident nodes along x = 1 (3 n + 1 pairs)
def two_squares(path, n, merged):
    """two unit squares [0, 1] x [0, 1] and [1, 2] x [0, 1] of n x n cells, two cubic triangles
    a cell, on a lattice of thirds; merged: one node per lattice point, else each square
    numbers its own (the seam's nodes twice)"""
    nodes, conn, index = [], [], {}
    def node(sq, i, j):
        key = (0 if merged else sq, i, j)
        if key not in index:
            index[key] = len(nodes) + 1
            nodes.append((i / (3 * n), j / (3 * n), 0.0))
        return index[key]
    for sq in (0, 1):
        for ci in range(n):
            for cj in range(n):
                i0, j0 = 3 * (sq * n + ci), 3 * cj
                for a, b, c in (((0, 0), (3, 0), (3, 3)), ((0, 0), (3, 3), (0, 3))):
                    pts = [a, b, c]
                    for p, q in ((a, b), (b, c), (c, a)):
                        pts += [tuple(p[k] + (q[k] - p[k]) // 3 for k in (0, 1)),
                                tuple(p[k] + 2 * (q[k] - p[k]) // 3 for k in (0, 1))]
                    pts.append(((a[0] + b[0] + c[0]) // 3, (a[1] + b[1] + c[1]) // 3))
                    conn.append([node(sq, i0 + u, j0 + v) for u, v in pts])
    write_msh(path, nodes, conn)
    return nodes

SEAM = re.compile(r"warning: body 'sq': its mesh has (\d+) pairs of distinct nodes at the same "
                  r"position \(within \S+ m\), e\.g\. nodes (\d+) and (\d+) at \((\S+), (\S+), (\S+)\): "
                  r"the surfaces there are not connected")
for merged in (False, True):
    path = os.path.join(work, "squares_%s.msh" % ("merged" if merged else "seam"))
    xs = two_squares(path, 2, merged)
    deck_text = f"""&run analysis = 'linear' /
&output dir = '{work}/out_squares_{merged}' /
&body name = 'sq', mesh = 'file', file = '{path}', {STEEL}, thickness = 0.01 /
&restraint body = 'sq', box_max = 0.0, 9.0, 9.0, fix = 'clamped' /
&restraint body = 'sq', box_min = 2.0, -9.0, -9.0, fix = 'clamped' /
&load body = 'sq', kind = 'pressure', pressure = 1000.0 /
"""
    code, out, err, b = check("squares_" + str(merged), deck_text)
    p = run([casca, "run", os.path.join(work, "squares_%s.nml" % merged)])
    for what, code, err in (("check", code, err), ("run", p.returncode, p.stderr)):
        m = SEAM.search(err)
        if merged:
            ck.record("two squares, nodes merged: casca %s exit 0, no seam warning" % what,
                      code == 0 and "distinct nodes" not in err, err[-300:])
            continue
        ck.record("two squares meshed apart: casca %s exit 0, warned of 7 coincident pairs on body 'sq'"
                  % what, code == 0 and m is not None and int(m.group(1)) == 7, err[-400:])
        if m:
            a, c = int(m.group(2)), int(m.group(3))
            ck.record("seam (%s): the named nodes %d and %d are distinct, both at the printed point on "
                      "x = 1" % (what, a, c), a != c and xs[a - 1] == xs[c - 1] and xs[a - 1][0] == 1.0
                      and all(abs(float(m.group(4 + k)) - xs[a - 1][k]) < 1e-4 for k in range(3)),
                      m.group(0)[-120:])
# the shipped examples and meshes have none
examples = os.path.join(os.path.dirname(meshdir), "examples")
for name in sorted(os.listdir(examples)):
    if name.endswith(".nml"):
        p = run([casca, "check", name], cwd=examples)
        ck.record("examples/%s: casca check exit 0, no seam warning" % name,
                  p.returncode == 0 and "distinct nodes" not in p.stderr, p.stderr[-300:])
for name in sorted(os.listdir(meshdir)):
    if name.endswith(".msh"):
        code, out, err, b = check("mesh_" + name[:-4], f"""&run dt = 1.0e-4, t_end = 1.0e-3 /
&body name = 'm', mesh = 'file', file = '{os.path.join(meshdir, name)}', {STEEL}, thickness = 0.001 /
""")
        ck.record("mesh/%s: casca check exit 0, no seam warning" % name,
                  code == 0 and "distinct nodes" not in err, err[-300:])
ck.finish()
