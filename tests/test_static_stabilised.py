"""Statics of bodies that only contact holds (the load step's stabilised path, casca_statics).

usage: test_static_stabilised.py CASCA WORK_DIR

Each body below has rigid motions that nothing but its contacts stops, so the first Newton
tangent is singular (casca before this path stopped at load factor 0.0125 or 0.00625 on each).
ring      a steel ring (R 0.5 m, width 0.2 m, h 10 mm, poisson 0), its top line held
          sideways only and pushed down by 200 N, resting on a rigid floor 5 mm below its
          mid-surface (contact at the faces): the floor's force equals the load (1e-9) at
          both load steps; the lowest node rests on the floor's surface, z = -0.5 (1e-7 of the
          scene size); the vertical diameter shortens by the thin ring's diametral
          compression, (pi/4 - 2/pi) P R^3 / (E I), I = b h^3 / 12 (Roark; 0.5%, a
          deflection of 0.2% of R, where the linear answer holds). On 2 ranks the tracked
          positions agree with 1 rank within 1e-10 m.
plate     a steel plate (1 x 1 m, h 10 mm) 3 mm above a rigid floor, held in-plane at two
          edges, under a pressure of 1e5 Pa: the floor's force is p A at each load step (1e-6,
          Newton's force tolerance: the residual's entries are within 1e-6 of the scene's
          force, and the floor's force sums 196 of them) and the plate's mid-surface rests
          h / 2 above the floor (1e-7 of the scene size).
free      the same plate with no restraint at all: sideways nothing holds it, and nothing
          pushes it; the floor's force is p A (1e-6, as above) and the plate has not slid
          (tracked x, y within 1e-7 of the scene size: a motion nothing stiffens, which only
          the stabilising damping fixed).
cup       a sphere (R 0.2 m) under gravity inside a rigid spherical cup 0.1 m below it, held
          by nothing else (free to spin about the contact): the cup's force is the sphere's
          weight, m g with m from `casca check` (1e-6).
crash     the ring in 6 load steps, a checkpoint every 0.3 of the load, killed once load
          step 3 is printed and restarted from its checkpoint: the history holds the six load
          factors once each, with the uninterrupted run's tracked z (1e-12 m); a restart from
          the finished run's checkpoint adds no load step (statics wrote their load steps
          again from the first before, and made no checkpoint before the end).
sphere    a closed steel sphere (R 1 m, h 5 mm, 80 elements) with no restraint at all under
          an internal pressure of 300 MPa in 3 load steps (its load is in equilibrium by
          itself, its six rigid motions free): the stretch r/R of two tracked nodes is the
          thin SVK sphere's, p = 2 S11(lambda) h / (lambda R), within 0.2% of the
          displacement, as the restrained sphere of test_pressure; its centre has not moved
          (the two nodes' radii agree within 1e-9 m).
stick     the free plate laid on the floor (gap 0) under 1e4 Pa and pushed sideways by
          1500 N (nodal shares), friction 0.3 (mu N = 3000 N): the floor's friction force is
          the push at every load step (1e-6, Newton's force tolerance) and the plate has not
          slid: its tracked node moves less than F / (E h), the stretch such a push gives
          (nodes where the load's share exceeds mu times their own normal force slip a little).
          Statics had no friction before: the plate slid away.
slide     the same pushed by 4500 N, over mu N: no equilibrium, exit 3 naming the plate.
moving    a static deck whose obstacle has a velocity is warned that statics keep it where it
          is (and a fixed one is not).
unheld    the free plate pushed sideways as well as down (frictionless): no equilibrium.
          casca exits 3 with a message naming the body and the cause. A restart from the
          checkpoint it leaves (load step 0) is taken and meets the same cause (casca refused
          it before: "history.dat ends at step -1, before the checkpoint's step 0").
"""
import os
import subprocess
import sys

import h5py
import numpy as np

from casca_testlib import ENV, Checks, history, loaded, run, run_scene, svk_sphere_stretch

casca, work = [os.path.abspath(a) for a in sys.argv[1:3]]
os.makedirs(work, exist_ok=True)
ck = Checks()

E, R, B, H, P = 2e11, 0.5, 0.2, 0.01, 200.0
RING = f"""&run analysis = 'static', load_steps = 2 /
&output vtu = .false., plots = .false., track = 0, 0, 0.5,  0, 0, -0.5 /
&body name = 'ring', mesh = 'ring', radius = {R}, width = {B}, n_around = 24, n_across = 2,
  rotate_axis = 1, 0, 0, rotate_angle = 90, young = {E:g}, poisson = 0.0, density = 7800, thickness = {H} /
&restraint body = 'ring', box_min = -1e9, -1e9, 0.499, fix = 'x y' /
&load body = 'ring', box_min = -1e9, -1e9, 0.499, force = 0, 0, {-P} /
&obstacle name = 'floor', shape = 'plane', point = 0, 0, -0.505, normal = 0, 0, 1 /
"""
length = np.sqrt(1 + 0.2**2 + 1)   # the ring's bounding-box diagonal
out, _ = run_scene(casca, ck, work, "ring", RING)
if out:
    h = loaded(history(out))
    ck.le("ring: floor's force vs the load, largest relative difference",
          np.max(np.abs(h["fcontact_ring_floor"] / (P * h["t"]) - 1)), 1e-9)
    ck.le("ring: lowest node vs the floor's surface z = -0.5 [m]", np.max(np.abs(h["p2_z"] + 0.5)), 1e-7 * length)
    delta = (0.5 - h["p1_z"]) + (h["p2_z"] + 0.5)
    exact = (np.pi / 4 - 2 / np.pi) * P * R**3 / (E * B * H**3 / 12)
    ck.close("ring: shortening of the vertical diameter at the full load vs Roark [m]", delta[-1], exact, 5e-3)
    p = run([casca, "run", os.path.join(work, "ring.nml"), "--out", os.path.join(work, "ring_np2"), "-q"], np_ranks=2)
    ck.record("ring on 2 ranks: exit 0", p.returncode == 0, p.stderr[-300:])
    if p.returncode == 0:
        h2 = loaded(history(os.path.join(work, "ring_np2")))
        ck.le("ring: tracked z on 2 ranks vs 1 [m]",
              max(np.abs(h2["p1_z"] - h["p1_z"]).max(), np.abs(h2["p2_z"] - h["p2_z"]).max()), 1e-10)

PRESSURE, HP = 1e5, 0.01


def plate(name, restraints, load, gap=0.003):
    return f"""&run analysis = 'static', load_steps = 3 /
&output vtu = .false., plots = .false., track = 0.333333333333, 0.333333333333, 0.0 /
&body name = 'plate', mesh = 'plate', lx = 1.0, ly = 1.0, nx = 3, ny = 3,
  young = 2e11, poisson = 0.3, density = 7800, thickness = {HP} /
{restraints}
{load}
&obstacle name = 'floor', shape = 'plane', point = 0, 0, {-HP / 2 - gap}, normal = 0, 0, 1 /
"""


HELD = """&restraint body = 'plate', box_max = 0.0, 1e9, 1e9, fix = 'x y' /
&restraint body = 'plate', box_max = 1e9, 0.0, 1e9, fix = 'x y' /"""
PRESS = f"&load body = 'plate', kind = 'pressure', pressure = {-PRESSURE:g} /"
out, _ = run_scene(casca, ck, work, "plate", plate("plate", HELD, PRESS))
if out:
    h = loaded(history(out))
    ck.le("plate: floor's force vs p A, largest relative difference",
          np.max(np.abs(h["fcontact_plate_floor"] / (PRESSURE * h["t"]) - 1)), 1e-6)
    ck.le("plate: mid-surface vs h/2 above the floor [m]", np.max(np.abs(h["p1_z"] + 0.003)), 1e-7 * np.sqrt(2))
out, _ = run_scene(casca, ck, work, "free", plate("free", "", PRESS))
if out:
    h = loaded(history(out))
    ck.le("free: floor's force vs p A, largest relative difference",
          np.max(np.abs(h["fcontact_plate_floor"] / (PRESSURE * h["t"]) - 1)), 1e-6)
    ck.le("free: sideways drift of the tracked node [m]",
          max(np.abs(h["p1_x"] - 1 / 3).max(), np.abs(h["p1_y"] - 1 / 3).max()), 1e-7 * np.sqrt(2))

CUP = """&run analysis = 'static', load_steps = 2, gravity = 0, 0, -9.81 /
&output vtu = .false., plots = .false. /
&body name = 'ball', mesh = 'sphere', radius = 0.2, n_div = 2,
  young = 2e9, poisson = 0.4, density = 1200, thickness = 0.005 /
&obstacle name = 'cup', shape = 'sphere', point = 0, 0, 0.3, radius = 0.6, inside = .true. /
"""
out, _ = run_scene(casca, ck, work, "cup", CUP)
if out:
    h = loaded(history(out))
    p = run([casca, "check", os.path.join(work, "cup.nml")])
    mass = [float(l.split("mass ")[1].split()[0]) for l in p.stdout.splitlines() if "body 'ball'" in l]
    ck.record("cup: casca check states the mass", len(mass) == 1, p.stdout[-300:])
    if mass:
        ck.close("cup: the cup's force at the full load vs m g [N]", h["fcontact_ball_cup"][-1], mass[0] * 9.81, 1e-6)

# a crash mid-statics: the ring in 6 load steps with a checkpoint every 0.3 of the load,
# killed (SIGKILL) once load step 3 is printed, restarted from its checkpoint
deck = os.path.join(work, "crash.nml")
with open(deck, "w") as f:
    f.write(RING.replace("load_steps = 2", "load_steps = 6").replace("plots = .false.,",
            "plots = .false., checkpoint_interval = 0.3,"))
whole, _ = run_scene(casca, ck, work, "whole", open(deck).read())
crashed = os.path.join(work, "crashed")
proc = subprocess.Popen([casca, "run", deck, "--out", crashed], stdout=subprocess.PIPE, text=True,
                        env=dict(ENV, GFORTRAN_UNBUFFERED_PRECONNECTED="y"))
for line in proc.stdout:
    if line.startswith("load step   3"):
        proc.kill()
        break
proc.wait()
step = -1
if os.path.exists(os.path.join(crashed, "checkpoint.h5")):
    with h5py.File(os.path.join(crashed, "checkpoint.h5"), "r") as f:
        step = int(np.array(f["step"]).ravel()[0])
ck.record("crash: killed after the checkpoint of load step 2 (of 6) and before the end", step == 2, "step %d" % step)
p = run([casca, "run", deck, "--out", crashed, "--restart", os.path.join(crashed, "checkpoint.h5"), "-q"])
ck.record("crash: the restart runs to the end (exit 0)", p.returncode == 0, p.stderr[-300:])
if whole and p.returncode == 0:
    a, b = history(whole), history(crashed)
    ck.record("crash: the restarted history has the uninterrupted run's load factors, once each",
              np.array_equal(a["t"], b["t"]), "%s vs %s" % (b["t"], a["t"]))
    if np.array_equal(a["t"], b["t"]):
        ck.le("crash: restarted tracked z vs the uninterrupted run [m]",
              max(np.abs(a["p1_z"] - b["p1_z"]).max(), np.abs(a["p2_z"] - b["p2_z"]).max()), 1e-12)
    p = run([casca, "run", deck, "--out", os.path.join(work, "again"), "--restart",
             os.path.join(whole, "checkpoint.h5"), "-q"])
    ck.record("crash: a restart from the finished run's checkpoint adds no load step",
              p.returncode == 0 and np.array_equal(history(os.path.join(work, "again"))["t"], a["t"]),
              p.stderr[-300:])

ES, NUS, HS = 2e11, 0.3, 0.005




SPHERE = f"""&run analysis = 'static', load_steps = 3 /
&output vtu = .false., plots = .false., track = 1.0, 0.0, 0.0,  0.0, 0.0, 1.0 /
&body name = 'ball', mesh = 'sphere', radius = 1.0, n_div = 2,
  young = {ES:g}, poisson = {NUS}, density = 7800, thickness = {HS} /
&load body = 'ball', kind = 'pressure', pressure = 3e8 /
"""
out, _ = run_scene(casca, ck, work, "sphere", SPHERE)
if out:
    h = loaded(history(out))
    r = [np.sqrt(h["p%d_x" % k] ** 2 + h["p%d_y" % k] ** 2 + h["p%d_z" % k] ** 2) for k in (1, 2)]
    s = np.array([svk_sphere_stretch(3e8 * t, ES, NUS, HS, 1.0) for t in h["t"]])
    ck.le("sphere: stretch of tracked node 1 vs SVK, largest error / displacement",
          np.max(np.abs(r[0] - s) / (s - 1)), 2e-3)
    ck.le("sphere: the two tracked nodes' radii [m]", np.max(np.abs(r[0] - r[1])), 1e-9)

# Coulomb friction in statics: the free plate on the floor (gap 0) under 1e4 Pa, pushed
# sideways by F (nodal), mu 0.3: mu N = 3000 N
def pushed(name, force):
    return plate(name, "", f"""&load body = 'plate', kind = 'pressure', pressure = -1e4 /
&load body = 'plate', force = {force}, 0, 0 /""", gap=0.0) + "&contact friction = 0.3 /\n"


out, _ = run_scene(casca, ck, work, "stick", pushed("stick", 1500.0))
if out:
    h = loaded(history(out))
    ck.le("stick: the floor's friction force vs the sideways load F t, largest relative difference",
          np.max(np.abs(h["ftangent_plate_floor"] / (1500.0 * h["t"]) - 1)), 1e-6)
    ck.le("stick: the plate has not slid: tracked x, y within F / (E h), the push's stretch [m]",
          max(np.abs(h["p1_x"] - 1 / 3).max(), np.abs(h["p1_y"] - 1 / 3).max()), 1500.0 / (2e11 * HP))
deck = os.path.join(work, "slide.nml")
with open(deck, "w") as f:
    f.write(pushed("slide", 4500.0))
p = run([casca, "run", deck, "--out", os.path.join(work, "slide"), "-q"])
ck.record("slide: F over mu N: exit 3, no equilibrium, naming the plate",
          p.returncode == 3 and "no equilibrium: body 'plate' keeps moving" in p.stderr, p.stderr[-300:])
deck = os.path.join(work, "moving.nml")
with open(deck, "w") as f:
    f.write(plate("moving", HELD, PRESS).replace("normal = 0, 0, 1 /", "normal = 0, 0, 1, velocity = 0, 0, 1 /"))
p = run([casca, "check", deck])
ck.record("moving: casca check warns that statics keep the obstacles where they are",
          p.returncode == 0 and "has a velocity, but in statics the obstacles stay" in p.stderr, p.stderr[-300:])
p = run([casca, "check", os.path.join(work, "plate.nml")])
ck.record("moving: no warning for a fixed obstacle", p.returncode == 0 and "warning" not in p.stderr,
          p.stderr[-300:])

deck = os.path.join(work, "unheld.nml")
with open(deck, "w") as f:
    f.write(plate("unheld", "", "&load body = 'plate', force = 100, 0, -1e4 /"))
p = run([casca, "run", deck, "--out", os.path.join(work, "unheld"), "-q"])
ck.record("unheld: exit 3 naming the body and the cause",
          p.returncode == 3 and "no equilibrium: body 'plate' keeps moving" in p.stderr
          and "is every body held against every load" in p.stderr, "exit %d: %s" % (p.returncode, p.stderr[-400:]))
# its checkpoint is of load step 0 (statics write no row for the unloaded state): a restart
# from it is taken and meets the same cause, not refused as another run's history
p = run([casca, "run", deck, "--out", os.path.join(work, "unheld"), "--restart",
         os.path.join(work, "unheld", "checkpoint.h5"), "-q"])
ck.record("unheld: a restart from its step-0 checkpoint runs and meets the same cause (exit 3)",
          p.returncode == 3 and "no equilibrium: body 'plate' keeps moving" in p.stderr,
          "exit %d: %s" % (p.returncode, p.stderr[-300:]))
ck.finish()
