"""Contact pairs a deck does not list: the finer mesh's nodes are the ones tested.

usage: test_default_pairs.py CASCA WORK_DIR

With one pass (the default) only the impactor's nodes are held off the target's surface, so
the target's nodes can pass between them. Both scenes list the coarse body first, as a user
might, and list no pairs (scenes written from the README, not tuned):
ball   a steel ball (R 5 cm, h 2 mm, 320 elements) dropped at 5 m/s onto the middle of a
       clamped aluminium plate (0.3 m, h 4 mm) of 3 x 3 cells, which has no node where the
       ball lands, generalized-alpha 0.8 at 20 us, 1.6 ms. `casca check` names the ball as
       the impactor (its area per node, 4 pi R^2 / (90 n^2 + 2), is smaller than the plate's,
       lx ly / ((3 nx + 1)(3 ny + 1))); the ball's lowest node stays at least
       (h_ball + h_plate)/2 - 0.5 mm above the plate's node nearest below it (0.5 mm allows
       for the plate's sag between that node and the point under the ball); the energy never
       rises in a step by more than 1e-3 E0. casca until 2026-11-26 tested the plate's nodes
       against the ball in deck order: the ball's lowest node went 2.8 mm below that plate
       node, through the plate.
blade  test_hard_cases' blade at 60 degrees (casca_testlib.blade_case) with one pass: the
       energy never rises in a step by more than 1e-3 E0 and the blade's tracked edge node
       stays (h/2)(1 + cos 60) - 1e-4 m above the plate's node below it. casca until
       2026-11-26 (the plate's nodes tested) made 21% of E0 in the first step and let the
       edge 2 mm into the plate."""
import math
import os
import re
import sys

import numpy as np

from casca_testlib import Checks, blade_case, history, run, run_scene

casca, work = [os.path.abspath(a) for a in sys.argv[1:3]]
os.makedirs(work, exist_ok=True)
ck = Checks()


def case(name, text):
    out, _ = run_scene(casca, ck, work, name, text)
    return os.path.join(work, name + ".nml"), (history(out) if out else None)


R, n_div, lx, nx = 0.05, 4, 0.3, 3
deck, h = case("ball", f"""&run dt = 2.0e-5, t_end = 1.6e-3, rho_inf = 0.8 /
&output interval = 1.0e-4, vtu = .false., plots = .false.,
  track = 0.0, 0.0, 0.004,  0.0, 0.0, 0.0, track_body = 'ball', 'plate' /
&body name = 'plate', mesh = 'plate', lx = {lx}, ly = {lx}, nx = {nx}, ny = {nx},
  center = -0.15, -0.15, 0, young = 70e9, poisson = 0.33, density = 2700, thickness = 0.004 /
&body name = 'ball', mesh = 'sphere', radius = {R}, n_div = {n_div}, center = 0, 0, 0.0545,
  velocity = 0, 0, -5, young = 210e9, poisson = 0.3, density = 7800, thickness = 0.002 /
&restraint body = 'plate', box_min = -1, -1, -1, box_max = -0.149, 1, 1, fix = 'clamped' /
&restraint body = 'plate', box_min = 0.149, -1, -1, box_max = 1, 1, 1, fix = 'clamped' /
""")
per_node = {"ball": 4 * math.pi * R**2 / (90 * n_div**2 + 2), "plate": lx * lx / (3 * nx + 1)**2}
expected = min(per_node, key=per_node.get)
p = run([casca, "check", deck])
m = re.search(r"^pair '(\w+)' -> '(\w+)'", p.stdout, re.M)
ck.record("ball: casca check names '%s' (area per node %.3g against %.3g m^2) the impactor"
          % (expected, min(per_node.values()), max(per_node.values())),
          m is not None and m.group(1) == expected, p.stdout[:300])
if h is not None:
    ck.record("ball: the ball and the plate touch", h["contacts"].max() > 0)
    ck.le("ball: (h_ball + h_plate)/2 - 0.5 mm - least height of the ball's lowest node over "
          "the plate's node below it [m]", 0.0025 - (h["p1_z"] - h["p2_z"]).min(), 0.0)
    ck.le("ball: largest rise of the total energy in a step / E0",
          np.diff(h["total"]).max() / h["total"][0], 1e-3)

blade_case(casca, ck, work, "blade", 60)
ck.finish()
