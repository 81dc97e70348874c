"""The thesis' two rings with compliant contact: a ladder of steps, and whether x(t) converges.

usage: rings_order.py CASCA WORK STIFFNESS [RHO_INF]

examples/two_rings.nml (20 elements around each ring, mid-surface contact, 10 m/s, 40 ms)
with &contact stiffness = STIFFNESS [Pa/m] and generalized-alpha (RHO_INF, default 0.8) at
100, 50, 25, 12.5 and 6.25 us, 1 rank. Prints per run: steps, Newton iterations, wall, the
largest distance of the two tracked nodes at the 41 frames from the 6.25 us run and from the
run at twice the step ("succ."), E/E0 at the end, ring 2's final impulse and the deepest
penetration (docs/performance.md, "Compliant contact: the order through contact").
"""
import os
import re
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from casca_testlib import history  # noqa: E402

casca, work, kp = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2]), sys.argv[3]
rho = sys.argv[4] if len(sys.argv) > 4 else "0.8"
here = os.path.dirname(os.path.abspath(__file__))
examples = os.path.join(here, "..", "..", "examples")
os.makedirs(work, exist_ok=True)
text = open(os.path.join(examples, "two_rings.nml")).read()
text = text.replace("'../mesh/", "'" + os.path.join(examples, "..", "mesh") + "/")
text = re.sub(r"beta = 1\.0, gamma = 1\.5", "rho_inf = " + rho, text)
text = text.replace("surface = 'mid'", "surface = 'mid', stiffness = " + kp)


def run(dt):
    out = os.path.join(work, "rings_%s_%g" % (kp, dt))
    deck = out + ".nml"
    with open(deck, "w") as f:
        f.write(text.replace("dt = 5.0e-5", "dt = %g" % dt).replace("dir = 'out/two_rings'", "dir = '%s'" % out))
    t0 = time.time()
    subprocess.run([casca, "run", deck, "-q"], check=True)
    wall = time.time() - t0
    h = history(out)
    frames = [np.argmin(abs(h["t"] - k * 1e-3)) for k in range(41)]
    return dict(x=np.stack([h["p1_x"][frames], h["p2_x"][frames]]), steps=int(h["step"][-1]),
                newton=int(h["newton"].sum()), e=h["total"][-1] / h["total"][0],
                impulse=h["impulse_ring1_ring2"][-1], pen=h["gap_max"].max(), wall=wall)


runs = [(dt, run(dt)) for dt in (1e-4, 5e-5, 2.5e-5, 1.25e-5, 6.25e-6)]
ref = runs[-1][1]
print("%9s %6s %7s %7s %13s %11s %7s %10s %10s" % ("dt [us]", "steps", "newton", "wall", "vs 6.25 [mm]",
                                                     "succ. [mm]", "E/E0", "impulse", "pen [mm]"))
prev = None
for dt, r in runs:
    succ = np.abs(r["x"] - prev["x"]).max() * 1e3 if prev else float("nan")
    print("%9.3f %6d %7d %7.1f %13.4f %11.4f %7.4f %10.2f %10.3f" % (
        dt * 1e6, r["steps"], r["newton"], r["wall"], np.abs(r["x"] - ref["x"]).max() * 1e3, succ, r["e"],
        r["impulse"], r["pen"] * 1e3))
    prev = r
