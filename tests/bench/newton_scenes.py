"""Newton's work on impact scenes written from the README (not tuned for casca), for two builds
run one after the other on each deck (interleaved, the same sitting): steps, Newton iterations,
factorisations, step cuts, CPU time, E/E0 at the end. The decks are written here:

ringwall   a steel ring (R 0.1 m, h 3 mm, 24 x 2 cells) at 100 m/s into a rigid wall at 30
           degrees, generalized-alpha 0.8, dt 10 us, 0.6 ms (the impact; --long: 4 ms)
spheres    two aluminium spheres (R 0.2 m, h 3 mm, n_div 3), one at 20 m/s struck off-centre
           (0.15 m), friction 0.3, between faces, generalized-alpha 0.8, dt 25 us, 8 ms
trapezoid  the same spheres with the trapezoidal rule (beta 1/4, gamma 1/2)
pile       three steel tubes (R 50 mm, h 2 mm) dropped as a pyramid at 3 m/s onto a floor,
           friction 0.2, generalized-alpha 0.8, dt 20 us, 20 ms
spin       a ring spinning at 10 rad/s while it flies at 10 m/s, generalized-alpha 0.8, dt
           1.25 ms, 0.3 s (no contact: the predictor alone)
rings      the thesis' two rings (examples/two_rings.nml's scene, its Newmark beta 1)
tumble     an aluminium plate (0.3 x 0.2 m, h 1 mm, 6 x 4 cells) flying at 2 m/s and tumbling at
           (0.5, 30, 0.3) rad/s, tolerance 1e-4, 0.1 s (no contact: kept factors on a turning body)
bowl       a steel ball (R 50 mm, h 1 mm, n_div 3) thrown spinning at 30 rad/s inside a rough
           rigid spherical bowl (friction 0.3), gravity, tolerance 1e-4, 20 ms
tube       a steel tube (R 50 mm, 0.3 m long, h 2 mm, 16 x 4 cells) spinning at 30 rad/s, thrown
           onto a plane tilted 0.1 rad, friction 0.3, gravity, tolerance 1e-4, 40 ms

usage: python3 tests/bench/newton_scenes.py OLD_CASCA NEW_CASCA WORK [--only a,b] [--long]
"""
import os
import re
import subprocess
import sys

import numpy as np

old, new, work = [os.path.abspath(a) for a in sys.argv[1:4]]
only = None
if "--only" in sys.argv:
    only = sys.argv[sys.argv.index("--only") + 1].split(",")
os.makedirs(work, exist_ok=True)
ring = os.path.join(work, "ring_20x1.msh")
subprocess.run([new, "mesh", "ring", "--radius", "1", "--width", "0.2", "--n-around", "20",
                "--n-across", "1", "-o", ring], check=True, capture_output=True)
STEEL = "young = 210e9, poisson = 0.3, density = 7850"
ALU = "young = 70e9, poisson = 0.33, density = 2700"
OUT = "&output interval = {iv}, vtu = .false., plots = .false. /\n"
spheres = f"""&body name = 'a', mesh = 'sphere', radius = 0.2, n_div = 3, velocity = 20.0, 0.0, 0.0,
  {ALU}, thickness = 0.003 /
&body name = 'b', mesh = 'sphere', radius = 0.2, n_div = 3, center = 0.42, 0.15, 0.0,
  {ALU}, thickness = 0.003 /
&contact friction = 0.3 /
"""
tube = """&body name = '{n}', mesh = 'ring', radius = 0.05, width = 0.1, n_around = 16, n_across = 2,
  rotate_axis = 1.0, 0.0, 0.0, rotate_angle = 90.0, center = {c}, velocity = 0.0, 0.0, -3.0,
  {m}, thickness = 0.002 /
"""
decks = {
    "ringwall": f"""&run dt = 1e-5, t_end = {0.004 if '--long' in sys.argv else 0.0006}, rho_inf = 0.8 /
{OUT.format(iv=1e-4)}&body name = 'ring', mesh = 'ring', radius = 0.1, width = 0.05, n_around = 24, n_across = 2,
  velocity = 86.6, -50.0, 0.0, {STEEL}, thickness = 0.003 /
&obstacle name = 'wall', shape = 'plane', point = 0.1035, 0.0, 0.0, normal = -1.0, 0.0, 0.0 /
""",
    "spheres": "&run dt = 2.5e-5, t_end = 0.008, rho_inf = 0.8 /\n" + OUT.format(iv=2e-4) + spheres,
    "trapezoid": "&run dt = 2.5e-5, t_end = 0.008, beta = 0.25, gamma = 0.5 /\n" + OUT.format(iv=2e-4) + spheres,
    "pile": "&run dt = 2e-5, t_end = 0.02, rho_inf = 0.8 /\n" + OUT.format(iv=5e-4)
            + tube.format(n="r1", c="-0.052, 0.0, 0.052", m=STEEL)
            + tube.format(n="r2", c="0.052, 0.0, 0.052", m=STEEL)
            + tube.format(n="r3", c="0.0, 0.0, 0.150", m=STEEL)
            + "&obstacle name = 'floor', shape = 'plane', point = 0.0, 0.0, 0.0, normal = 0.0, 0.0, 1.0 /\n"
            + "&contact friction = 0.2 /\n",
    "spin": f"""&run rho_inf = 0.8, dt = 1.25e-3, t_end = 0.3 /
{OUT.format(iv=0.01)}&body name = 'ring', mesh = 'file', file = '{ring}', velocity = 10.0, 0.0, 0.0,
  omega = 0.0, 0.0, 10.0, young = 210e9, poisson = 0.3, density = 7700, thickness = 0.05 /
""",
    "tumble": f"""&run dt = 1e-4, t_end = 0.1, tolerance = 1e-4 /
{OUT.format(iv=5e-3)}&body name = 'plate', mesh = 'plate', lx = 0.3, ly = 0.2, nx = 6, ny = 4,
  velocity = 2.0, 0.0, 0.0, omega = 0.5, 30.0, 0.3, {ALU}, thickness = 0.001 /
""",
    "bowl": f"""&run dt = 1e-4, t_end = 0.02, tolerance = 1e-4, gravity = 0.0, 0.0, -9.81 /
{OUT.format(iv=2e-3)}&body name = 'ball', mesh = 'sphere', radius = 0.05, n_div = 3, center = 0.0, 0.0, -0.1,
  velocity = 4.0, 1.0, -2.0, omega = 0.0, 30.0, 0.0, young = 200e9, poisson = 0.3, density = 7800,
  thickness = 0.001 /
&obstacle name = 'bowl', shape = 'sphere', point = 0.0, 0.0, 0.0, radius = 0.2, inside = .true.,
  friction = 0.3 /
""",
    "tube": f"""&run dt = 1e-4, t_end = 0.04, tolerance = 1e-4, gravity = 0.0, 0.0, -9.81 /
{OUT.format(iv=2e-3)}&body name = 'tube', mesh = 'ring', radius = 0.05, width = 0.3, n_around = 16, n_across = 4,
  rotate_axis = 0.0, 1.0, 0.0, rotate_angle = 80.0, center = 0.0, 0.0, 0.2,
  velocity = 1.0, 0.0, -4.0, omega = 0.0, 0.0, 30.0, {STEEL}, thickness = 0.002 /
&obstacle name = 'slope', shape = 'plane', point = 0.0, 0.0, 0.0, normal = -0.0998, 0.0, 0.995,
  friction = 0.3 /
""",
    "rings": f"""&run dt = 5.0e-5, t_end = 0.04, beta = 1.0, gamma = 1.5 /
{OUT.format(iv=1e-3)}&body name = 'ring1', mesh = 'file', file = '{ring}', velocity = 10.0, 0.0, 0.0,
  young = 210e9, poisson = 0.3, density = 7700, thickness = 0.05 /
&body name = 'ring2', mesh = 'file', file = '{ring}', center = 2.01, 0.0, 0.0,
  young = 210e9, poisson = 0.3, density = 7700, thickness = 0.05 /
&contact surface = 'mid', pairs = 'ring1', 'ring2' /
""",
}


def run(casca, name, tag):
    deck = os.path.join(work, name + ".nml")
    with open(deck, "w") as f:
        f.write(decks[name])
    out = os.path.join(work, name + "_" + tag)
    p = subprocess.run(["/usr/bin/time", "-f", "CPU %U %S", casca, "run", deck, "--out", out],
                       capture_output=True, text=True)
    cpu = sum(float(x) for x in re.search(r"CPU (\S+) (\S+)", p.stderr).groups())
    fact = re.search(r"factorisation [^(]*\([^,]*, (\d+) times", p.stdout)
    h = np.atleast_2d(np.loadtxt(os.path.join(out, "history.dat")))
    names = open(os.path.join(out, "history.dat")).readline().lstrip("#").split()
    col = {n: i for i, n in enumerate(names)}
    return dict(rc=p.returncode, steps=len(h) - 1, newton=int(h[:, col["newton"]].sum()),
                fact=int(fact.group(1)) if fact else -1, cuts=p.stdout.count("step cut"),
                warn=p.stderr.count("warning"), cpu=cpu, e=h[-1, col["total"]] / h[0, col["total"]])


print("| scene | build | steps | Newton | factorisations | cuts | warnings | CPU [s] | E/E0 |")
print("|---|---|---|---|---|---|---|---|---|")
for name in decks:
    if only and name not in only:
        continue
    for tag, casca in (("old", old), ("new", new)):
        r = run(casca, name, tag)
        print("| %s | %s | %d | %d | %d | %d | %d | %.1f | %.5f |%s" % (
            name, tag, r["steps"], r["newton"], r["fact"], r["cuts"], r["warn"], r["cpu"], r["e"],
            "" if r["rc"] == 0 else " exit %d" % r["rc"]), flush=True)
