"""`casca check` prints each contact pair's initial gap and time to contact (issue 16).

usage: test_check_report.py CASCA MESH_DIR WORK_DIR

Scenes written for this test; every expected figure is the hand-computed geometry of the deck
(the meshes' nodes lie on the exact circles, printed with 8 significant digits, so exact
figures are compared to 1e-6 relative):
rings faces    two thesis rings (R 1, h 0.05), centres 2.1 m apart, ring1 at (10, 3, 0) m/s, ring2
               at (4, 0, 0) m/s: gap 2.1 - 2R - h = 0.05 m (node facing node), closing speed
               10 - 4 = 6 m/s (along x, the line of closest approach); time to contact no earlier
               than gap / 6 s (the nearest nodes' straight approach) and no later than the
               circles' rigid contact, |(2.1, 0) - (6, 3) t| = 2R + h, plus two chords' sagittas
               (60 nodes around) at 6 m/s.
rings mid      the same with surface = 'mid': gap 0.1 m, the circles touching at 2R.
rings between  ring2 turned by 3 degrees (half the 6-degree node spacing), so ring1's nearest node
               faces a chord of ring2's: the printed gap lies between the exact gap 0.05 m and
               0.05 + (R + h/2)(1 - cos 3 deg) (the chord's sagitta at the face: the accuracy the
               output states), and the time is that gap / 6 m/s.
obstacles      a ring (R 0.2, h 0.04) at (1, -2, 0) m/s above a floor plane 0.3 m below its centre:
               gap 0.3 - R - h/2 = 0.08 m, closing 2 m/s, time 0.04 s; a rigid sphere (radius 0.2)
               centred 0.5 m above it falling at 5 m/s: the ring's nodes across its width w = 0.05
               are at z = +-w/6, +-w/2, so its nearest node is at D = sqrt(0.3^2 + (w/6)^2) from
               the centre, off the vertical by c = 0.3 / D: gap D - 0.2 - (h/2) c (the face along
               the radial fibre, projected on the line to the centre, as a constraint measures
               it), closing speed 3 c m/s; time: the earliest at which a node, moving straight on
               at (1, 3, 0) m/s relative to the sphere, has its face ((h/2) |fibre . n|, the fibre
               radial, n the sphere's normal there) on the sphere, by the test's own bisection
               along each node's path (not the gap over the closing speed, which is exact for a
               plane only); the same sphere at rest: 'never' (the ring moves away from it).
inside sphere  a ball (R 0.05, h 2 mm) 0.1 m off the centre of a spherical container (radius 0.2)
               at (2, 3, 1) m/s: gap 0.2 - 0.15 - h/2; time by the same bisection to the inner
               wall (casca before 2026-11-29 printed its nearest node's gap over its closing
               speed: 21.3 ms for 18.6).
self-contact   the ring's pair with itself: time to contact 'never' (its rigid motion closes no gap).
rim edge-on    (with one pass the check also warns that a's edge, thinner than b's node spacing
               sqrt(0.4 x 0.5 / 13^2) = 0.034401 m, can pass between b's nodes: both figures to
               1e-4; no such warning with two passes)
               a plate (h_a 20 mm, 1 m square, 2 x 2 cells) in z = 0 and a finer plate (h_b 10 mm,
               0.4 x 0.5 m, 4 x 4 cells, the impactor) standing in x = 1.1, its mid row of nodes
               at z = 0, moving at (-2, 0, 0) m/s: its nodes meet plate a's rim, rounded by h_a/2
               all round, with their own face h_b/2 along x: gap 0.1 - h_b/2 - h_a/2 = 0.085 m,
               closing 2 m/s, time 0.0425 s (with passes = 2 the rim is not rounded all round:
               met edge-on, the edge's rounding is (h_a/2) 3/16 (method.md): 0.1 - h_b/2 -
               (h_a/2) 3/16 = 0.093125 m; b's nodes, moving along a's plane, meet none of its
               faces: 'never'; a's rim nodes meet b's face at 0.093125 / 2 s).
ring in ring   a small ring (R 0.08, 16 cells) at the centre of a big one (R 0.2, 40 cells), both
               h 2 mm, the small one at 20 m/s along x: its node at angle 0 meets the big ring's
               node there first, at (0.2 - 0.08 - h) / 20 s; the big ring's chords lie inside
               its circle, so the time printed is within that less the chord's sagitta at the
               face over 20 m/s. 0.06 m off the axis: the circles' rigid contact at
               sqrt(0.118^2 - 0.06^2) / 20 s, less the big ring's sagitta and plus the small
               one's over the closing speed along the wall's normal. (Before 2026-11-28 the time
               was the closest node's gap over its speed: the centred ring's nearest nodes moved
               sideways, and off the axis it came 19% late.)
spheres        two spheres head-on (R 0.1 and 0.15, h 2 and 3 mm, closing at 7 m/s, faces 2 mm
               apart): the time lies between 2 mm / 7 m/s and that plus what the meshes' faceting
               can add (the nearest node off the axis by a sub-triangle's circumradius, and the
               target's chord sagitta) over 7 m/s.
denser target  a thin tube (R 40 mm, width 120 mm, 16 x 3 cells) listed as the target of a plate
               (0.3 m, 8 x 8 cells): the warning gives the plate's area per node over the tube's,
               (0.3^2 / 25^2) / (2 pi R w / (48 x 10)) = 2.29, within 1%; listed the other way
               round, or with passes = 2, no such warning.
run time      `casca check`'s run time against the CPU time of the run itself (one rank; CPU, not
               wall, so that other jobs on the machine do not move it), within a factor of 3 (the
               line says about 2): a ball (R 50 mm, h 2 mm, 180 elements) let go at rest in a
               rough rigid bowl (R 0.3 m) under gravity and tolerance 1e-4, 20 ms (7.4 s measured;
               before 2026-12 the estimate was 0.11 to 0.29 s: t_end / dt = 20 steps at 0.03 to
               0.08 ms an element, where the run took 94 steps of 5 to 6 Newton iterations and a
               factorisation nearly every step), and the thesis rings' impact (examples/two_rings.nml), its
               first 10 ms.
"""
import math
import os
import re
import resource
import sys

from casca_testlib import Checks, run

casca, meshdir, work = [os.path.abspath(a) for a in sys.argv[1:4]]
os.makedirs(work, exist_ok=True)
ck = Checks()
STEEL = "young = 210e9, poisson = 0.3, density = 7700"
LINE = re.compile(r"pair '([^']*)' -> '([^']*)'[^:]*: gap\s+(\S+) m, closing speed\s+(\S+) m/s, "
                  r"time to contact (never|\S+ s)")


STDERR = {}


def check(name, text):
    """run casca check on the deck text: {(impactor, target): (gap, speed, time or None)}"""
    deck = os.path.join(work, name + ".nml")
    with open(deck, "w") as f:
        f.write(text)
    p = run([casca, "check", deck])
    ck.record("%s: casca check exit 0" % name, p.returncode == 0, p.stderr[-300:])
    STDERR[name] = p.stderr
    pairs = {}
    for m in LINE.finditer(p.stdout):
        t = None if m.group(5) == "never" else float(m.group(5).split()[0])
        pairs[(m.group(1), m.group(2))] = (float(m.group(3)), float(m.group(4)), t)
    print(p.stdout.strip())
    return pairs


def close(name, value, expected, rtol=1e-6):
    if value is None:
        ck.record(name, False, "not printed")
    else:
        ck.close(name, value, expected, rtol)


ring = os.path.join(meshdir, "ring_20x1.msh")
R, h = 1.0, 0.05


def rings(surface, turn=0.0):
    return f"""&run dt = 5.0e-5, t_end = 1.0e-3 /
&body name = 'ring1', mesh = 'file', file = '{ring}', velocity = 10.0, 3.0, 0.0, {STEEL}, thickness = {h} /
&body name = 'ring2', mesh = 'file', file = '{ring}', center = 2.1, 0.0, 0.0, velocity = 4.0, 0.0, 0.0,
  rotate_axis = 0.0, 0.0, 1.0, rotate_angle = {turn}, {STEEL}, thickness = {h} /
&contact surface = '{surface}' /
"""


sag6 = R * (1 - math.cos(math.radians(3.0)))   # (a chord's sagitta: 60 nodes around)
for surface, gap in (("faces", 2.1 - 2 * R - h), ("mid", 2.1 - 2 * R)):
    pr = check("rings_" + surface, rings(surface)).get(("ring1", "ring2"), (None,) * 3)
    close("rings %s: gap [m]" % surface, pr[0], gap)
    close("rings %s: closing speed [m/s]" % surface, pr[1], 6.0)
    # the circles' rigid contact: |(2.1, 0) - (6, 3) t| = 2.1 - gap
    a, b, cc = 45.0, -25.2, 2.1**2 - (2.1 - gap) ** 2
    t_c = (-b - math.sqrt(b * b - 4 * a * cc)) / (2 * a)
    t = pr[2]
    ck.record("rings %s: time to contact within [gap / 6 m/s, the circles' rigid contact + two "
              "chords' sagittas / 6 m/s]" % surface,
              t is not None and gap / 6 * (1 - 1e-6) <= t <= (t_c + 2 * sag6 / 6) * (1 + 1e-6),
              "%s in [%.8g, %.8g]" % (t, gap / 6, t_c + 2 * sag6 / 6))

pr = check("rings_between", rings("faces", 3.0)).get(("ring1", "ring2"), (None,) * 3)
exact, sag = 2.1 - 2 * R - h, (R + h / 2) * (1 - math.cos(math.radians(3.0)))
if pr[0] is None:
    ck.record("rings between nodes: printed", False)
else:
    ck.record("rings between nodes: exact gap <= printed <= exact + the chord's sagitta at the face",
              exact * (1 - 1e-6) <= pr[0] <= (exact + sag) * (1 + 1e-6),
              "%.8g in [%.8g, %.8g]" % (pr[0], exact, exact + sag))
    close("rings between nodes: time = printed gap / 6 m/s", pr[2], pr[0] / 6.0)

small = os.path.join(work, "ring_r02.msh")
run([casca, "mesh", "ring", "--radius", "0.2", "--width", "0.05", "--n-around", "20", "--n-across", "1", "-o", small])
r, hr = 0.2, 0.04


def face_time(mesh, fibre, w, centre, radius, half, inside):
    """The earliest time at which a node of the mesh, moving straight on at w relative to a
    rigid sphere, has its face, half x |fibre . n| off its mid-surface along the sphere's normal
    n there, on the sphere (inside: on its inner wall); bisection on each node's path"""
    import meshio
    import numpy as np
    x = meshio.read(mesh).points
    w, c = np.array(w), np.array(centre)

    def excess(p, f):   # > 0: clear of the wall
        d = np.linalg.norm(p - c)
        off = half * abs(np.dot(f, (p - c) / d))
        return (radius - off - d) if inside else (d - radius - off)

    best = math.inf
    for xn in x:
        f = fibre(xn)
        f = f / np.linalg.norm(f)
        ts = np.linspace(0.0, 1.0, 2001)
        ex = [excess(xn + w * t, f) for t in ts]
        k = next((i for i in range(len(ts) - 1) if ex[i] > 0 >= ex[i + 1]), None)
        if k is None:
            continue
        a, b = ts[k], ts[k + 1]
        for _ in range(60):
            m = (a + b) / 2
            a, b = (m, b) if excess(xn + w * m, f) > 0 else (a, m)
        best = min(best, b)
    return best


def ring_obstacles(ball_v):
    return f"""&run dt = 2.0e-5, t_end = 1.0e-3 /
&body name = 'ring', mesh = 'ring', radius = 0.2, width = 0.05, n_around = 20, n_across = 1,
  velocity = 1.0, -2.0, 0.0, {STEEL}, thickness = {hr} /
&obstacle name = 'floor', shape = 'plane', point = 0.0, -0.3, 0.0, normal = 0.0, 1.0, 0.0 /
&obstacle name = 'ball', shape = 'sphere', point = 0.0, 0.5, 0.0, radius = 0.2, velocity = 0.0, {ball_v}, 0.0 /
&contact pairs = 'ring', 'ring' /
"""


got = check("obstacles", ring_obstacles(-5.0))
fl, ball, own = (got.get(k, (None,) * 3) for k in (("ring", "floor"), ("ring", "ball"), ("ring", "ring")))
close("floor: gap [m]", fl[0], 0.3 - r - hr / 2)
close("floor: closing speed [m/s]", fl[1], 2.0)
close("floor: time to contact [s]", fl[2], (0.3 - r - hr / 2) / 2.0)
D = math.hypot(0.5 - r, 0.05 / 6)
c = (0.5 - r) / D
close("falling sphere: gap [m]", ball[0], D - 0.2 - hr / 2 * c)
close("falling sphere: closing speed [m/s]", ball[1], 3.0 * c)
close("falling sphere: time to contact [s]", ball[2],
      face_time(small, lambda x: x * [1, 1, 0], [1.0, 3.0, 0.0], [0.0, 0.5, 0.0], 0.2, hr / 2, False))
ck.record("self-contact: printed, time to contact 'never'", ("ring", "ring") in got and own[2] is None, str(own))
got = check("sphere_at_rest", ring_obstacles(0.0))
ball = got.get(("ring", "ball"), (None,) * 3)
ck.record("sphere at rest above a ring moving down: 'never'", ("ring", "ball") in got and ball[2] is None
          and ball[1] is not None and ball[1] < 0, str(ball))
ball_mesh = os.path.join(work, "ball_r005.msh")
run([casca, "mesh", "sphere", "--radius", "0.05", "--n-div", "2", "-o", ball_mesh])
got = check("inside_sphere", f"""&run dt = 1.0e-5, t_end = 1.0e-3 /
&body name = 'ball', mesh = 'sphere', radius = 0.05, n_div = 2, center = 0.1, 0.0, 0.0, velocity = 2.0, 3.0, 1.0,
  {STEEL}, thickness = 0.002 /
&obstacle name = 'shell', shape = 'sphere', point = 0.0, 0.0, 0.0, radius = 0.2, inside = .true. /
""")
inner = got.get(("ball", "shell"), (None,) * 3)
close("ball inside a spherical shell: gap [m]", inner[0], 0.2 - 0.15 - 0.001)
close("ball inside a spherical shell: time to contact [s]", inner[2],
      face_time(ball_mesh, lambda x: x, [2.0, 3.0, 1.0], [-0.1, 0.0, 0.0], 0.2, 0.001, True))
for passes, gap in ((1, 0.1 - 0.005 - 0.01), (2, 0.1 - 0.005 - 0.01 * 3 / 16)):
    got = check("rim_edge_on_%d" % passes, f"""&run dt = 1e-5, t_end = 1e-3 /
&body name = 'a', mesh = 'plate', lx = 1.0, ly = 1.0, nx = 2, ny = 2, {STEEL}, thickness = 0.02 /
&body name = 'b', mesh = 'plate', lx = 0.4, ly = 0.5, nx = 4, ny = 4, rotate_axis = 0, 1, 0,
  rotate_angle = 90, center = 1.1, 0.25, 0.2, velocity = -2, 0, 0, {STEEL}, thickness = 0.01 /
&contact passes = {passes} /
""")
    ba = got.get(("b", "a"), (None,) * 3)
    close("rim met edge-on, passes = %d: gap [m]" % passes, ba[0], gap)
    if passes == 1:
        close("rim met edge-on, passes = 1: time to contact [s]", ba[2], gap / 2.0)
    # the edge (h_a 20 mm) is thinner than b's node spacing, sqrt(0.4 x 0.5 / 13^2) = 0.034401 m
    m = re.search(r"'b' -> 'a': the contact foreseen first is at the target's free edge.*?thinner "
                  r"\((\S+) m\) than the impactor's node spacing \(about (\S+) m\)", STDERR["rim_edge_on_%d" % passes])
    if passes == 1:
        ck.record("rim met edge-on, passes = 1: warned that the edge can pass between b's nodes", m is not None,
                  STDERR["rim_edge_on_1"][-400:])
        if m:
            close("rim met edge-on, passes = 1: the warning's edge thickness [m]", float(m.group(1)), 0.02, 1e-4)
            close("rim met edge-on, passes = 1: the warning's node spacing [m]", float(m.group(2)),
                  math.sqrt(0.4 * 0.5 / 13**2), 1e-4)
    else:   # (b's nodes move along a's plane: a's rim nodes meet b's face)
        ck.record("rim met edge-on, passes = 2: no warning of an edge passing between nodes", m is None,
                  STDERR["rim_edge_on_2"][-400:])
        ck.record("rim met edge-on, passes = 2: b's nodes meet no face of a: 'never'", ba[2] is None, str(ba))
        close("rim met edge-on, passes = 2: a's nodes meet b's face at [s]",
              got.get(("a", "b"), (None,) * 3)[2], gap / 2.0)
def ring_in_ring(name, y):
    return check(name, f"""&run dt = 2e-5, t_end = 1e-3 /
&body name = 'big', mesh = 'ring', radius = 0.2, width = 0.02, n_around = 40, n_across = 1, {STEEL},
  thickness = 0.002 /
&body name = 'small', mesh = 'ring', radius = 0.08, width = 0.02, n_around = 16, n_across = 1,
  center = 0, {y}, 0, velocity = 20, 0, 0, {STEEL}, thickness = 0.002 /
&contact pairs = 'small', 'big' /
""").get(("small", "big"), (None,) * 3)


sb = ring_in_ring("ring_in_ring", 0.0)
t_lead = (0.2 - 0.08 - 0.002) / 20
sag = (0.2 - 0.001) * (1 - math.cos(math.radians(1.5)))
ck.record("ring in ring: time to contact within [(gap - sagitta) / v, gap / v] of the leading node",
          sb[2] is not None and (t_lead - sag / 20) * (1 - 1e-6) <= sb[2] <= t_lead * (1 + 1e-6), str(sb))
# 0.06 m off the axis: the centres (20 t, 0.06) are 0.118 m apart at t = sqrt(0.118^2 - 0.06^2) / 20,
# the wall's normal there 30.6 degrees from the path; the big ring's chords lie inside its circle
# (up to 0.199 (1 - cos 1.5 deg) nearer), the small one's inside its own (0.081 (1 - cos 3.75 deg))
sb = ring_in_ring("ring_in_ring_off", 0.06)
t_c = math.sqrt(0.118**2 - 0.06**2) / 20
vn = 20 * t_c * 20 / 0.118   # (the closing speed along the normal at contact)
lo_t, hi_t = t_c - sag / vn, t_c + 0.081 * (1 - math.cos(math.radians(3.75))) / vn
ck.record("ring in ring off the axis: time to contact within the circles' rigid contact less the big "
          "ring's sagitta, plus the small one's, over the normal closing speed",
          sb[2] is not None and lo_t * (1 - 1e-6) <= sb[2] <= hi_t * (1 + 1e-6),
          "%s in [%.8g, %.8g]" % (sb[2], lo_t, hi_t))
# two spheres head-on (a: R 0.1, h 2 mm at 5 m/s; b: R 0.15, h 3 mm at -2 m/s; centres 0.2545
# apart): the smooth spheres' faces are 2 mm apart, so the time is at least 2 mm / 7 m/s. The
# meshes put no node on the axis: a's nearest node is off it by at most its sub-triangle's
# circumradius rho = e_a / sqrt 3, and along x its path meets b's sphere later by
# rho^2 / 2 (1 / R_a + 1 / R_b), and b's chords (sagitta e_b^2 / (8 R_b)) later still; e is
# the icosahedron's edge R / sin 72 deg over 3 n_div, stretched by up to 1 / 0.7947 (its
# inradius over its circumradius) where projected onto the sphere. (Before 2026-11-28 the
# path, aimed at the chord between two of b's nodes, missed both triangles' offset planes: 4.9e-4 s.)
def sphere_edge(rs):
    return rs / math.sin(math.radians(72)) / 9 / 0.7947


ra, rb = 0.1, 0.15
rho = sphere_edge(ra) / math.sqrt(3)
lo_t = (0.2545 - ra - rb - 0.0025) / 7
hi_t = lo_t + (rho**2 / 2 * (1 / ra + 1 / rb) + sphere_edge(rb) ** 2 / (8 * rb)) / 7
sp = check("spheres_head_on", f"""&run dt = 1e-5, t_end = 2e-3 /
&body name = 'a', mesh = 'sphere', radius = {ra}, n_div = 3, velocity = 5, 0, 0, {STEEL}, thickness = 0.002 /
&body name = 'b', mesh = 'sphere', radius = {rb}, n_div = 3, center = 0.2545, 0, 0, velocity = -2, 0, 0,
  {STEEL}, thickness = 0.003 /
""").get(("a", "b"), (None,) * 3)
ck.record("spheres head-on: time to contact within [the smooth faces' 2 mm / 7 m/s, plus the meshes' "
          "offsets from the axis and b's sagitta over 7 m/s]",
          sp[2] is not None and lo_t <= sp[2] <= hi_t, "%s in [%.6g, %.6g]" % (sp[2], lo_t, hi_t))

# a thin tube (R 40 mm, 120 mm, 16 x 3 cells) listed as the target of a coarse plate (0.3 m,
# 8 x 8 cells): the tube's area per node, 2 pi R w / (3*16 (3*3 + 1)), is the plate's
# 0.3^2 / 25^2 over 2.29; with one pass the warning names that ratio, listed the other way
# round or with passes = 2 there is none
Rt, wt = 0.04, 0.12
ratio = (0.3**2 / 25**2) / (2 * math.pi * Rt * wt / (48 * 10))
for name, contact, warned in (("coarse_impactor", "pairs = 'plate', 'tube'", True),
                              ("fine_impactor", "pairs = 'tube', 'plate'", False),
                              ("two_passes", "pairs = 'plate', 'tube', passes = 2", False)):
    deck = os.path.join(work, name + ".nml")
    with open(deck, "w") as f:
        f.write(f"""&run dt = 1.0e-5, t_end = 2.0e-3 /
&body name = 'plate', mesh = 'plate', lx = 0.3, ly = 0.3, nx = 8, ny = 8, center = -0.15, -0.15, 0,
  young = 70e9, poisson = 0.33, density = 2700, thickness = 0.003 /
&body name = 'tube', mesh = 'ring', radius = {Rt}, width = {wt}, n_around = 16, n_across = 3,
  rotate_axis = 1, 0, 0, rotate_angle = 90, center = 0, 0, 0.0435, velocity = 0, 0, -15,
  young = 210e9, poisson = 0.3, density = 7800, thickness = 0.001 /
&contact {contact} /
""")
    p = run([casca, "check", deck])
    m = re.search(r"the target's nodes are (\S+) times denser", p.stderr)
    if warned:
        ck.record("%s: warned that the target's nodes are denser" % name, m is not None, p.stderr[-300:])
        if m:
            ck.close("%s: the ratio of the areas per node" % name, float(m.group(1)), ratio, 0.01)
    else:
        ck.record("%s: no warning of denser target nodes" % name, m is None and p.returncode == 0,
                  p.stderr[-300:])

# --- the run time casca check gives against the run's own CPU time
def cpu_of_children():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


for name, text in (("bowl_rolling", """&run dt = 1.0e-3, t_end = 0.02, tolerance = 1.0e-4, gravity = 0.0, 0.0, -9.81 /
&output interval = 0.01, vtu = .false., plots = .false. /
&body name = 'ball', mesh = 'sphere', radius = 0.05, n_div = 3, center = 0.0851288, 0.0, -0.2338895,
  young = 210e9, poisson = 0.3, density = 7850, thickness = 0.002 /
&obstacle name = 'bowl', shape = 'sphere', point = 0.0, 0.0, 0.0, radius = 0.3, inside = .true.,
  friction = 0.3 /
"""), ("rings_impact", f"""&run dt = 5.0e-5, t_end = 1.0e-2, beta = 1.0, gamma = 1.5 /
&output vtu = .false., plots = .false. /
&body name = 'ring1', mesh = 'file', file = '{ring}', velocity = 10.0, 0.0, 0.0, {STEEL}, thickness = {h} /
&body name = 'ring2', mesh = 'file', file = '{ring}', center = 2.01, 0.0, 0.0, {STEEL}, thickness = {h} /
&contact surface = 'mid', pairs = 'ring1', 'ring2' /
""")):
    deck = os.path.join(work, name + ".nml")
    with open(deck, "w") as f:
        f.write(text)
    m = re.search(r"^run time: ~\s*(\S+)", run([casca, "check", deck]).stdout, re.M)
    cpu = cpu_of_children()
    p = run([casca, "run", deck, "--out", os.path.join(work, name), "-q"])
    cpu = cpu_of_children() - cpu
    ok = m is not None and p.returncode == 0
    ck.record("%s: casca check's run time %s s against the run's CPU time %.3g s, within a factor 3"
              % (name, m.group(1) if m else "(none)", cpu),
              ok and 1 / 3 <= float(m.group(1)) / cpu <= 3, "" if ok else p.stderr[-300:])
ck.finish()
