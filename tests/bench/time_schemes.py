#!/usr/bin/env python3
"""Error against wall time of the time schemes, over a whole scene (issue 18).

usage: time_schemes.py CASCA WORK_DIR [--scene rings|oblique] [--quick]

The thesis' two rings (examples/two_rings.nml: ring 1 at 10 m/s into ring 2, 20 elements
around, contact between mid-surfaces, 40 ms) or the same with ring 2 0.4 m off-centre
(oblique). Error: the largest distance, over every output frame (1 ms apart, the whole 40 ms),
between the tracked nodes' x(t) and a reference run on the same mesh: generalized-alpha
(rho_inf 0.8) at dt = 3.125 us, whose own error is estimated by its distance to the same at
6.25 us (second order: a third of that distance). Series: the thesis' Newmark (beta 1,
gamma 1.5), generalized-alpha rho_inf 0.8 at fixed steps, and with steps chosen by
&run tolerance. Prints a table (wall, steps, Newton iterations, error, observed order) and
writes WORK_DIR/time_schemes.dat."""
import argparse
import os
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from casca_testlib import ENV, history  # noqa: E402

ap = argparse.ArgumentParser()
ap.add_argument("casca")
ap.add_argument("work")
ap.add_argument("--scene", default="rings")
ap.add_argument("--quick", action="store_true", help="fewer points")
args = ap.parse_args()
casca = os.path.abspath(args.casca)
work = os.path.abspath(args.work)
os.makedirs(work, exist_ok=True)
mesh = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "mesh", "ring_20x1.msh"))
offset = 0.4 if args.scene == "oblique" else 0.0


def deck(scheme, dt):
    return f"""&run dt = {dt}, t_end = 0.04, {scheme} /
&output interval = 1.0e-3, vtu = .false., plots = .false.,
  track = 1.0, 0.0, 0.0,   1.01, {offset}, 0.0, track_body = 'ring1', 'ring2' /
&body name = 'ring1', mesh = 'file', file = '{mesh}', velocity = 10.0, 0.0, 0.0,
  young = 210e9, poisson = 0.3, density = 7700, thickness = 0.05 /
&body name = 'ring2', mesh = 'file', file = '{mesh}', center = 2.01, {offset}, 0.0,
  young = 210e9, poisson = 0.3, density = 7700, thickness = 0.05 /
&contact surface = 'mid', pairs = 'ring1', 'ring2' /
"""


def run(name, scheme, dt, keep=False):
    """run the deck into WORK/NAME; keep: reuse a finished run of the same deck (the
    references: their wall time is not reported)"""
    path = os.path.join(work, name + ".nml")
    out = os.path.join(work, name)
    text = deck(scheme, dt)
    if keep and os.path.exists(os.path.join(out, "history.dat")) and open(path).read() == text:
        return history(out), 0.0
    with open(path, "w") as f:
        f.write(text)
    t0 = time.time()
    p = subprocess.run([casca, "run", path, "--out", out, "-q"], env=ENV, capture_output=True, text=True)
    wall = time.time() - t0
    if p.returncode != 0:
        print(name, "failed:", p.stderr[-300:], flush=True)
        return None, wall
    return history(out), wall


def frames(h):
    """the rows at the output frames (every 1 ms)"""
    k = np.nonzero(np.abs(h["t"] / 1e-3 - np.round(h["t"] / 1e-3)) < 1e-6)[0]
    k = k[np.unique(np.round(h["t"][k] / 1e-3), return_index=True)[1]]   # (one row a frame)
    return h["t"][k], np.stack([h["p1_x"][k], h["p1_y"][k], h["p2_x"][k], h["p2_y"][k]]).T


def error(h, ref):
    t, x = frames(h)
    tr, xr = frames(ref)
    if len(t) != len(tr) or np.max(np.abs(t - tr)) > 1e-9:
        return float("nan")
    return max(np.max(np.hypot(x[:, 0] - xr[:, 0], x[:, 1] - xr[:, 1])),
               np.max(np.hypot(x[:, 2] - xr[:, 2], x[:, 3] - xr[:, 3])))


ref, _ = run("ref", "rho_inf = 0.8, newton_tol = 1e-11", 3.125e-6, keep=True)
ref2, _ = run("ref2", "rho_inf = 0.8, newton_tol = 1e-11", 6.25e-6, keep=True)
print("reference: generalized-alpha 0.8 at 3.125 us; its distance to 6.25 us: %.3e m "
      "(its own error about a third of that)" % error(ref2, ref), flush=True)
series = {
    "newmark_thesis": [("beta = 1.0, gamma = 1.5", dt) for dt in (1e-4, 5e-5, 2.5e-5, 1.25e-5)],
    "alpha_0.8": [("rho_inf = 0.8", dt) for dt in (2e-4, 1e-4, 5e-5, 2.5e-5)],
    "alpha_0.8_tol": [("rho_inf = 0.8, tolerance = %g" % tol, 5e-5) for tol in (1e-3, 1e-4, 1e-5, 1e-6)],
}
if args.quick:
    series = {k: v[1:3] for k, v in series.items()}
rows = []
for name, runs in series.items():
    last = None
    for scheme, dt in runs:
        label = "%s_%s" % (name, scheme.split("=")[-1].strip() if "tol" in name else "%.3g" % dt)
        h, wall = run(label, scheme, dt)
        if h is None:
            continue
        err = error(h, ref)
        steps = len(h["t"]) - 1
        order = ""
        if last is not None and "tol" not in name:
            order = "%.2f" % (np.log(last / err) / np.log(2))
        last = err
        rows.append((name, scheme.replace(" ", ""), dt, steps, int(np.sum(h["newton"])), wall, err))
        print("%-16s %-34s dt %.3e  steps %6d  newton %6d  wall %7.2f s  error %.3e m  order %s"
              % (name, scheme, dt, steps, np.sum(h["newton"]), wall, err, order), flush=True)
with open(os.path.join(work, "time_schemes.dat"), "w") as f:
    f.write("# series scheme dt steps newton wall_s error_m\n")
    for r in rows:
        f.write("%s %s %.4e %d %d %.3f %.4e\n" % r)
