"""The three ways of solving the contact saddle point give one answer (issue 18).

usage: test_contact_solvers.py CASCA WORK_DIR

It asserts:
same       a plate (9 x 9 cells, 784 nodes, h 10 mm) lying on a rigid plane, thrown down onto it
           at 0.2 m/s while spinning slowly under 100 m/s^2 of gravity (about 640 active
           contacts, a few released and added at each step; 5 steps), run with &contact solver =
           'schur', 'saddle' and 'auto' (which takes the saddle-point matrix here, from the
           first contact on: docs/performance.md): the same steps, the same contacts at every
           step, tracked positions within Newton's tolerance (newton_tol x the scene size =
           1e-9 m), the contact force and the kinetic energy within Newton's force tolerance
           (1e-6 relative) at every step.
bad value  solver = 'fast': exit 2 naming the file, the line and the field.
"""
import os
import sys

import numpy as np

from casca_testlib import Checks, history, run, run_scene, spinning_plate_deck

casca, work = [os.path.abspath(a) for a in sys.argv[1:3]]
os.makedirs(work, exist_ok=True)
ck = Checks()

runs = {}
for solver in ("schur", "saddle", "auto"):
    out, _ = run_scene(casca, ck, work, solver, spinning_plate_deck(solver))
    runs[solver] = history(out) if out else None

ref = runs["schur"]
if ref is not None:
    ck.record("schur: several hundred contacts at every step after the first",
              ref["contacts"][1:].min() >= 400, "%d to %d" % (ref["contacts"][1:].min(), ref["contacts"].max()))
    pos = [n for n in ref if n.startswith("p") and n[1:2].isdigit() and n[-2:] in ("_x", "_y", "_z")]
    for solver in ("saddle", "auto"):
        h = runs[solver]
        if h is None:
            continue
        same = len(h["t"]) == len(ref["t"]) and np.array_equal(h["t"], ref["t"])
        ck.record("%s: the same steps as schur" % solver, same, "%d vs %d rows" % (len(h["t"]), len(ref["t"])))
        if not same:
            continue
        ck.record("%s: the same active contacts at every step" % solver,
                  np.array_equal(h["contacts"], ref["contacts"]))
        ck.le("%s vs schur: tracked positions, largest difference [m]" % solver,
              max(np.max(np.abs(h[n] - ref[n])) for n in pos), 1e-9)
        ck.le("%s vs schur: contact force, largest difference / largest force" % solver,
              np.max(np.abs(h["fcontact"] - ref["fcontact"])) / np.max(np.abs(ref["fcontact"])), 1e-6)
        ck.le("%s vs schur: kinetic energy, largest difference / largest" % solver,
              np.max(np.abs(h["kinetic"] - ref["kinetic"])) / np.max(ref["kinetic"]), 1e-6)

# --- bad value
deck = os.path.join(work, "fast.nml")
with open(deck, "w") as f:
    f.write(spinning_plate_deck("fast"))
line = 1 + spinning_plate_deck("fast").splitlines().index("&contact solver = 'fast' /")
p = run([casca, "check", deck])
ck.record("solver = 'fast': exit 2 naming the file, the line and the field",
          p.returncode == 2 and ("fast.nml:%d:" % line) in p.stderr and "&contact: solver" in p.stderr,
          p.stderr[-300:])
ck.finish()
