"""Contact as engineers model it (issue 16): shell faces, rigid obstacles, deck errors.

usage: test_contact_models.py CASCA MESH_DIR WORK_DIR

Each case is a scene written for this test, not a shipped one. It asserts:
faces      a strip (h1 10 mm) falls flat at v = 5 m/s onto a fixed plate (h2 20 mm), mid-surfaces
           d = 50 mm apart (trapezoidal rule, dt 50 us): the first step with contacts ends within
           one step after (d - (h1 + h2)/2) / v = 7 ms (and none before it).
equivalent two thesis rings (h 0.05) with contact at the faces and 0.06 m between mid-surfaces
           against the same rings with contact between mid-surfaces 0.01 m apart (the gap
           widened by h): the same motion. Contact starts in the same step; the struck ring's
           kinetic energy and the total strain energy agree at every step within 0.5% of their
           largest value and the impactor's tracked node within 1e-4 m (the faces' offset moves
           with the fibre's tilt and the thickness strain, which the mid-surface model lacks).
floor      a free ring (R 0.2, h 40 mm) thrown at 2 m/s onto a fixed rigid plane under gravity
           (thesis Newmark): its momentum change equals the floor's impulse (impulse_ring_floor,
           the history's running sum of the impulses the integrator applied) less m g t, the
           weight's impulse (m = p0 / v0), within 1e-8 relative; momentum along the plane stays
           below 1e-9 of the initial; no tensile multiplier, largest active gap 1e-9 m; the ring
           leaves upwards; the energy never rises (1e-9 relative).
bounce     the same ring dropped under the trapezoidal rule at dt and dt/2: the energy never rises (1e-9
           relative) and ends within 2% of the initial; the rebound speed of the centre of mass
           (just after contact over just before) is a property of the elastic ring, not 1: its
           ovalisation keeps the rest of the energy (0.78 here; 0.93 at h 80 mm, at three steps
           and 40 elements around: docs/method.md), so it is asserted converged: the two steps
           agree within 1%.
bar        a bar (strip 0.5 x 0.05 m, h 10 mm, nu 0) falling end-on at 2 m/s under gravity onto
           a rigid plane, trapezoidal, dt 1 us: 1D wave theory gives a contact of 2 L / c and a
           rebound at the impact speed: rebound within 2% of the impact speed (just before and
           after contact), contact duration within 2% + 2 steps of 2 L / c.
pusher     the same ring at rest, struck by a plane moving at V = 2 m/s: the mid-surface of the
           tracked lowest node stays h/2 above the moving plane (within 2e-5 m: the face moves
           with the thickness strain, below 1e-3 here) and after contact the ring moves at least
           at V (it cannot be overtaken by the plane that pushes it). The plane's work in the
           history (obstacle_work) equals V times the ring's momentum change, the plane's force
           being the only force on it (1e-8 relative), and so does the printed energy
           balance's 'taken from moving obstacles' (1e-4: printed to 5 digits; it was printed
           with the opposite sign before 2026-11-26).
drum       a steel ring (R 0.2, h 10 mm) thrown at 3 m/s spinning at 200 rad/s inside a
           frictionless rigid cylinder (R 0.3, axis z through the origin), the midpoint rule
           (rho_inf 1) at 20 us, 12 ms: every contact force points through the axis, so the
           angular momentum about it, Lz, is kept within 1e-8 of its value while the ring
           bounces round the drum (casca before 2026-11-27 took the force's normal at the
           step's end, half a step's slide from where the scheme takes the force: 2.8e-4);
           the energy never rises by more than 1e-4.
oblique    a ball (R 0.05, h 2 mm) striking a fixed rigid sphere off-centre at 20 m/s under
           generalized-alpha 0.8: once it has left, | |p - p0| - impulse | within 1e-8 of the
           impulse (exact accounting of the released constraints' forces).
resting    two steel plates (0.1 x 0.1 m, h 10 mm) stacked on a rigid floor under gravity,
           thesis Newmark and generalized-alpha 0.8, 10 ms: the floor's impulse is |pz + 2 m g t|
           (the momentum balance; m = rho A h) within 1e-8 relative, and the top pair's is m g t
           within sqrt(2 m K_top) (a bound on the top plate's momentum) + 1e-8 relative.
lift       one such plate carried up by a floor rising at V = 0.5 m/s: obstacle_work is
           m g V t within 1e-8 relative.
bad input  unknown obstacle shape, a sphere without radius, contact surface 'top', passes 3:
           exit 2 naming the file, the group and the field.
"""
import os
import re
import sys

import numpy as np

from casca_testlib import Checks, history, run, run_scene

casca, meshdir, work = [os.path.abspath(a) for a in sys.argv[1:4]]
os.makedirs(work, exist_ok=True)
ck = Checks()
STEEL = "young = 210e9, poisson = 0.3, density = 7700"


def go(name, text):
    out, _ = run_scene(casca, ck, work, name, text)
    return history(out) if out else None


# --- faces: first contact of a strip falling flat
strip = os.path.join(work, "strip.msh")
plate = os.path.join(work, "plate.msh")
run([casca, "mesh", "strip", "--lx", "0.5", "--ly", "0.1", "--nx", "10", "--ny", "2", "-o", strip])
run([casca, "mesh", "plate", "--lx", "0.8", "--ly", "0.4", "--nx", "4", "--ny", "2", "-o", plate])
dt, v, d, h1, h2 = 5e-5, 5.0, 0.05, 0.01, 0.02
h = go("faces", f"""&run dt = {dt}, t_end = 8.0e-3, beta = 0.25, gamma = 0.5 /
&output vtu = .false., plots = .false. /
&body name = 'strip', mesh = 'file', file = '{strip}', center = -0.25, -0.05, {d},
  velocity = 0.0, 0.0, {-v}, {STEEL}, thickness = {h1} /
&body name = 'plate', mesh = 'file', file = '{plate}', center = -0.4, -0.2, 0.0,
  {STEEL}, thickness = {h2} /
&restraint body = 'plate', fix = 'all' /
""")
if h is not None:
    t_touch = (d - (h1 + h2) / 2) / v
    first = h["t"][np.nonzero(h["contacts"] > 0)[0][0]]
    ck.record("faces: first contact within one step after (d - (h1+h2)/2)/v = %.4g s" % t_touch,
              t_touch <= first + 1e-12 and first <= t_touch + dt + 1e-12, "first step with contacts ends at %.6g s" % first)

# --- faces against mid-surfaces with the gap widened by h
ring = os.path.join(meshdir, "ring_20x1.msh")
runs = {}
for surface, centre in (("faces", 2.06), ("mid", 2.01)):
    runs[surface] = go("rings_" + surface, f"""&run dt = 5.0e-5, t_end = 3.0e-2 /
&output vtu = .false., plots = .false., track = 1.0, 0.0, 0.0, track_body = 'ring1' /
&body name = 'ring1', mesh = 'file', file = '{ring}', velocity = 10.0, 0.0, 0.0,
  {STEEL}, thickness = 0.05 /
&body name = 'ring2', mesh = 'file', file = '{ring}', center = {centre}, 0.0, 0.0,
  {STEEL}, thickness = 0.05 /
&contact surface = '{surface}' /
""")
a, b = runs["faces"], runs["mid"]
if a is not None and b is not None:
    ck.record("equivalent: contact starts in the same step",
              a["t"][a["contacts"] > 0][0] == b["t"][b["contacts"] > 0][0],
              "%.6g vs %.6g s" % (a["t"][a["contacts"] > 0][0], b["t"][b["contacts"] > 0][0]))
    for col in ("kinetic_ring2", "strain"):
        ck.le("equivalent: %s, largest difference / largest value" % col,
              np.max(np.abs(a[col] - b[col])) / np.max(np.abs(b[col])), 5e-3)
    ck.le("equivalent: tracked node of ring1, largest difference [m]", np.max(np.abs(a["p1_x"] - b["p1_x"])), 1e-4)

# --- a ring spinning in a frictionless drum: the forces point through its axis
h = go("drum", """&run dt = 2.0e-5, t_end = 0.012, rho_inf = 1.0 /
&output vtu = .false., plots = .false. /
&body name = 'ring', mesh = 'ring', radius = 0.2, width = 0.05, n_around = 24, n_across = 1,
  center = 0.08, 0.0, 0.0, velocity = 3.0, 1.0, 0.0, omega = 0.0, 15.0, 200.0,
  young = 210e9, poisson = 0.3, density = 7800, thickness = 0.01 /
&obstacle name = 'drum', shape = 'cylinder', point = 0.0, 0.0, 0.0, axis = 0.0, 0.0, 1.0,
  radius = 0.3, inside = .true. /
""")
if h is not None:
    ck.record("drum: the ring touches the drum (at least 100 steps in contact)",
              np.count_nonzero(h["contacts"]) >= 100, "%d" % np.count_nonzero(h["contacts"]))
    ck.le("drum: angular momentum about the axis kept (max |Lz - Lz0| / Lz0)",
          np.abs(h["Lz"] - h["Lz"][0]).max() / h["Lz"][0], 1e-8)
    ck.le("drum: largest E/E0 - 1", h["total"].max() / h["total"][0] - 1, 1e-4)

# --- a rigid floor
ring2 = os.path.join(work, "ring_r02.msh")
run([casca, "mesh", "ring", "--radius", "0.2", "--width", "0.05", "--n-around", "20", "--n-across", "1", "-o", ring2])
hr, dt, v0, g = 0.04, 2e-5, 2.0, 9.81
floor = f"""&output vtu = .false., plots = .false. /
&body name = 'ring', mesh = 'file', file = '{ring2}', velocity = 0.0, {-v0}, 0.0, {STEEL}, thickness = {hr} /
&obstacle name = 'floor', shape = 'plane', point = 0.0, -0.23, 0.0, normal = 0.0, 1.0, 0.0 /
"""
h = go("floor", f"&run dt = {dt}, t_end = 1.2e-2, gravity = 0.0, {-g}, 0.0 /\n" + floor)
if h is not None:
    f = h["fcontact_ring_floor"]
    ck.record("floor: contact happens and ends", f.max() > 0 and f[-1] == 0)
    m = abs(h["py"][0]) / v0
    ck.close("floor: momentum change [N s] vs the floor's impulse less the weight's m g t",
             h["py"][-1] - h["py"][0], h["impulse_ring_floor"][-1] - m * g * h["t"][-1], 1e-8)
    p0 = abs(h["py"][0])
    ck.le("floor: momentum along the plane / initial", max(np.abs(h["px"]).max(), np.abs(h["pz"]).max()) / p0, 1e-9)
    ck.le("floor: most tensile multiplier [N]", h["lambda_max"].max(), 0.0)
    ck.le("floor: largest active gap [m]", h["gap_max"].max(), 1e-9)
    ck.record("floor: the ring leaves upwards", h["py"][-1] > 0, "py %.4g" % h["py"][-1])
    ck.le("floor: largest E/E0 - 1", h["total"].max() / h["total"][0] - 1, 1e-9)

# --- the impulse columns account exactly for the momentum contact gives (README: impulse_I_T)
# a ball striking a fixed rigid sphere off-centre under generalized-alpha 0.8: after it leaves,
# its momentum change is the obstacle's impulse (a released constraint's force was taken out
# of the accounting's start share at 1, not 1/(1 - alpha_m): 8.4e-4 off before 2026-11-27)
h = go("oblique", """&run dt = 2.0e-5, t_end = 3.0e-3, rho_inf = 0.8 /
&output vtu = .false., plots = .false. /
&body name = 'ball', mesh = 'sphere', radius = 0.05, n_div = 3, center = -0.26, 0.05, 0.0,
  velocity = 20.0, 0.0, 0.0, omega = 0.0, 0.0, 80.0, young = 70e9, poisson = 0.33, density = 2700,
  thickness = 0.002 /
&obstacle name = 'post', shape = 'sphere', point = 0.0, 0.0, 0.0, radius = 0.2 /
""")
if h is not None:
    p = np.stack([h["px"], h["py"], h["pz"]], axis=1)
    free = np.nonzero(h["contacts"] == 0)[0]
    free = free[free > np.argmax(h["contacts"])]
    ck.record("oblique: the ball strikes and leaves", len(free) > 10)
    if len(free):
        ck.le("oblique: max over the steps after it leaves of | |p - p0| - impulse_ball_post | / impulse",
              np.abs(np.linalg.norm(p[free] - p[0], axis=1) - h["impulse_ball_post"][free]).max()
              / h["impulse_ball_post"][-1], 1e-8)
# plates resting on a floor, and on each other, under gravity from the start (they start with
# a = 0, their contacts holding their weight): each pair's impulse is the weight it holds,
# m g t, m = rho A h (a flat plate's consistent mass is exact); the floor under the stack holds
# both plates. A rising floor (V) does the work m g V t on the plate it carries. Before
# 2026-11-27 the first step's share of the weight was left out: 5% high at 10 steps (Newmark)
pl = "mesh = 'plate', lx = 0.1, ly = 0.1, nx = 2, ny = 2, young = 210e9, poisson = 0.3, density = 7800, thickness = 0.01"
m_pl, t_end = 7800 * 0.1 * 0.1 * 0.01, 0.01
for scheme in ("beta = 1.0, gamma = 1.5", "rho_inf = 0.8"):
    h = go("resting_" + scheme.split()[0], f"""&run dt = 1.0e-3, t_end = {t_end}, gravity = 0.0, 0.0, -9.81, {scheme} /
&output vtu = .false., plots = .false. /
&body name = 'low', {pl}, center = 0.0, 0.0, 0.005 /
&body name = 'top', {pl}, center = 0.0, 0.0, 0.015 /
&obstacle name = 'floor', shape = 'plane', point = 0.0, 0.0, 0.0, normal = 0.0, 0.0, 1.0 /
""")
    if h is not None:
        # the floor's: the momentum balance |pz + 2 m g t| (the start rings the stack a little:
        # |pz| up to 1e-7 N s); the top pair's: m g t within the top plate's momentum at the end,
        # |p| <= sqrt(2 m K) (Cauchy-Schwarz in the mass's metric)
        ck.close("resting, %s: impulse_low_floor [N s] vs |pz + 2 m g t|" % scheme, h["impulse_low_floor"][-1],
                 abs(h["pz"][-1] + 2 * m_pl * 9.81 * t_end), 1e-8)
        top = "impulse_low_top" if "impulse_low_top" in h else "impulse_top_low"
        ck.le("resting, %s: |%s - m g t| [N s], bound sqrt(2 m K_top) + 1e-8 m g t" % (scheme, top),
              abs(h[top][-1] - m_pl * 9.81 * t_end),
              np.sqrt(2 * m_pl * h["kinetic_top"][-1]) + 1e-8 * m_pl * 9.81 * t_end)
h = go("lift", f"""&run dt = 1.0e-3, t_end = {t_end}, gravity = 0.0, 0.0, -9.81 /
&output vtu = .false., plots = .false. /
&body name = 'pl', {pl}, center = 0.0, 0.0, 0.005, velocity = 0.0, 0.0, 0.5 /
&obstacle name = 'floor', shape = 'plane', point = 0.0, 0.0, 0.0, normal = 0.0, 0.0, 1.0, velocity = 0.0, 0.0, 0.5 /
""")
if h is not None:
    ck.close("lift: obstacle_work [J] vs m g V t", h["obstacle_work"][-1], m_pl * 9.81 * 0.5 * t_end, 1e-8)

# --- the same ring bouncing under the trapezoidal rule: energy kept, rebound converged
rebound = []
for k, step in enumerate((dt, dt / 2)):
    h = go("bounce%d" % k, f"&run dt = {step}, t_end = 1.2e-2, beta = 0.25, gamma = 0.5, gravity = 0.0, {-g}, 0.0 /\n"
           + floor)
    if h is None:
        continue
    ck.le("bounce, dt %g: largest E/E0 - 1" % step, h["total"].max() / h["total"][0] - 1, 1e-9)
    ck.le("bounce, dt %g: 1 - final E/E0" % step, 1 - h["total"][-1] / h["total"][0], 0.02)
    ck.record("bounce, dt %g: contact happens and ends" % step,
              h["contacts_ring_floor"].max() > 0 and h["contacts_ring_floor"][-1] == 0)
    on = np.nonzero(h["contacts_ring_floor"])[0]
    if len(on) and on[-1] + 1 < len(h["t"]):
        rebound.append(-h["py"][on[-1] + 1] / h["py"][on[0] - 1])   # (just after / just before)
if len(rebound) == 2:
    ck.close("bounce: rebound / impact speed at dt/2 vs at dt (converged)", rebound[1], rebound[0], 0.01)

# --- a bar falling end-on: 1D wave theory, rebound at the impact speed
bar = os.path.join(work, "bar.msh")
run([casca, "mesh", "strip", "--lx", "0.5", "--ly", "0.05", "--nx", "20", "--ny", "1", "-o", bar])
dtb, L, c0 = 1e-6, 0.5, np.sqrt(210e9 / 7700)
h = go("bar", f"""&run dt = {dtb}, t_end = 1.2e-3, beta = 0.25, gamma = 0.5, gravity = {-g}, 0.0, 0.0 /
&output vtu = .false., plots = .false. /
&body name = 'bar', mesh = 'file', file = '{bar}', center = 0.001, 0.0, 0.0, velocity = {-v0}, 0.0, 0.0,
  young = 210e9, poisson = 0.0, density = 7700, thickness = 0.01 /
&obstacle name = 'floor', shape = 'plane', point = 0.0, 0.0, 0.0, normal = 1.0, 0.0, 0.0 /
""")
if h is not None:
    on = np.nonzero(h["contacts_bar_floor"])[0]
    if len(on) and on[-1] + 1 < len(h["t"]):
        ck.close("bar: rebound speed vs impact speed", h["px"][on[-1] + 1], -h["px"][on[0] - 1], 0.02)
        ck.le("bar: |contact duration - 2 L / c| [s]", abs(h["t"][on[-1]] - h["t"][on[0] - 1] - 2 * L / c0),
              0.02 * 2 * L / c0 + 2 * dtb)
        ck.le("bar: largest E/E0 - 1", h["total"].max() / h["total"][0] - 1, 1e-9)
    else:
        ck.record("bar: contact happens and ends", False)

# --- a moving plane
V = 2.0
out, stdout = run_scene(casca, ck, work, "pusher", f"""&run dt = {dt}, t_end = 1.5e-2 /
&output vtu = .false., plots = .false., track = 0.0, -0.2, 0.0, track_body = 'ring' /
&body name = 'ring', mesh = 'file', file = '{ring2}', {STEEL}, thickness = {hr} /
&obstacle name = 'pusher', shape = 'plane', point = 0.0, -0.221, 0.0, normal = 0.0, 1.0, 0.0,
  velocity = 0.0, {V}, 0.0 /
""", quiet=False)
h = history(out) if out else None
if h is not None:
    m = 7700 * hr * 0.05 * 2 * np.pi * 0.2
    gap = h["p1_y"] - hr / 2 - (-0.221 + V * h["t"])
    ck.le("pusher: deepest the lowest node's nominal face goes behind the plane [m]", -gap.min(), 2e-5)
    ck.record("pusher: contact happens", h["contacts"].max() > 0)
    ck.record("pusher: after contact the ring moves at least at V", h["contacts"][-1] == 0 and h["py"][-1] / m >= V,
              "vy %.4g m/s" % (h["py"][-1] / m))
    ck.close("pusher: the plane's work [J] vs V times the ring's momentum change (its only force)",
             h["obstacle_work"][-1], V * (h["py"][-1] - h["py"][0]), 1e-8)
    m = re.search(r"taken from moving obstacles ([-+.0-9Ee]+)", stdout)
    ck.close("pusher: the energy balance's 'taken from moving obstacles' [J] vs V times the ring's "
             "momentum change (the energy the plane gave)", float(m.group(1)) if m else float("nan"),
             V * (h["py"][-1] - h["py"][0]), 1e-4)

# --- bad input
base = f"""&run dt = 1e-5, t_end = 1e-4 /
&body name = 'ring', mesh = 'file', file = '{ring2}', {STEEL}, thickness = {hr} /
"""
for name, extra, needles in (
        ("unknown obstacle shape", "&obstacle name = 'w', shape = 'cone' /\n", ["&obstacle", "shape", "cone"]),
        ("sphere without radius", "&obstacle name = 'w', shape = 'sphere' /\n", ["&obstacle", "radius", "missing"]),
        ("contact surface 'top'", "&contact surface = 'top' /\n", ["&contact", "surface", "faces"]),
        ("passes = 3", "&contact passes = 3 /\n", ["&contact", "passes"])):
    deck = os.path.join(work, "bad.nml")
    with open(deck, "w") as f:
        f.write(base + extra)
    p = run([casca, "check", deck])
    ck.record("bad input, %s: exit 2 naming the file and field" % name,
              p.returncode == 2 and "bad.nml" in p.stderr and all(n in p.stderr for n in needles), p.stderr[-300:])
ck.finish()
