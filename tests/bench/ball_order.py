"""The order through contact: a ball dropped on a floor, a ladder of steps per scheme.

usage: ball_order.py CASCA WORK [SCHEME ...] [stiffness=K]
       (SCHEME: 'newmark', 'alpha0.8', 'alpha0', 'alpha1'; the first three by default;
       stiffness=K: compliant contact, &contact stiffness = K [Pa/m]; default hard)

An aluminium ball R 0.3 m, h 4 mm, 320 elements, its lowest face 1 mm above a rigid plane, at
8 m/s, 4 ms. Prints per run: the largest error of the lowest (contact) and highest (free)
node's z at the 41 frames against generalized-alpha 0.8 at 3.125 us, the highest node's largest
difference from the run at twice the step, the final pz's error, E/E0 and the wall time
(docs/performance.md, "The order through contact").
"""
import os
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from casca_testlib import history  # noqa: E402

casca, work = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
args = sys.argv[3:]
CONTACT = "".join("&contact stiffness = %s /\n" % a.split("=")[1] for a in args if a.startswith("stiffness="))
schemes = [a for a in args if not a.startswith("stiffness=")] or ["newmark", "alpha0.8", "alpha0"]
KEYS = {"newmark": "beta = 1.0, gamma = 1.5", "alpha0.8": "rho_inf = 0.8", "alpha0": "rho_inf = 0.0",
        "alpha1": "rho_inf = 1.0"}
STEPS = [1e-4, 5e-5, 2.5e-5, 1.25e-5, 6.25e-6]
os.makedirs(work, exist_ok=True)
mesh = os.path.join(work, "ball.msh")
subprocess.run([casca, "mesh", "sphere", "--radius", "0.3", "--n-div", "4", "-o", mesh], check=True,
               capture_output=True)


def run(scheme, dt):
    name = "%s_%g" % (scheme, dt)
    out = os.path.join(work, name)
    deck = out + ".nml"
    with open(deck, "w") as f:
        f.write(f"""&run dt = {dt}, t_end = 0.004, {KEYS[scheme]} /
&output dir = '{out}', interval = 1.0e-4, vtu = .false., plots = .false.,
  track = 0.0, 0.0, 0.0,   0.0, 0.0, 0.603 /
&body name = 'ball', mesh = 'file', file = '{mesh}', center = 0.0, 0.0, 0.303,
  velocity = 0.0, 0.0, -8.0, young = 70e9, poisson = 0.33, density = 2700, thickness = 0.004 /
&obstacle name = 'floor', shape = 'plane', point = 0.0, 0.0, 0.0, normal = 0.0, 0.0, 1.0 /
{CONTACT}""")
    t0 = time.time()
    subprocess.run([casca, "run", deck, "-q"], check=True)
    wall = time.time() - t0
    h = history(out)
    frames = [np.argmin(abs(h["t"] - k * 1e-4)) for k in range(41)]
    return dict(lo=h["p1_z"][frames], hi=h["p2_z"][frames], pz=h["pz"][-1], e=h["total"][-1] / h["total"][0],
                wall=wall)


ref = run("alpha0.8", 3.125e-6)
print("%-10s %9s %10s %10s %11s %9s %7s %7s" % ("scheme", "dt [us]", "low [mm]", "high [mm]", "succ. [mm]",
                                                 "pz [%]", "E/E0", "wall"))
for scheme in schemes:
    prev = None
    for dt in STEPS:
        r = run(scheme, dt)
        succ = np.abs(r["hi"] - prev["hi"]).max() * 1e3 if prev else float("nan")
        print("%-10s %9.3f %10.4f %10.4f %11.4f %9.4f %7.4f %7.1f" % (
            scheme, dt * 1e6, np.abs(r["lo"] - ref["lo"]).max() * 1e3, np.abs(r["hi"] - ref["hi"]).max() * 1e3,
            succ, abs(r["pz"] / ref["pz"] - 1) * 100, r["e"], r["wall"]))
        prev = r
