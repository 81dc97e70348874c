"""Single-precision factors (&run factor_precision = 'single') give the double answer (issue 18).

usage: test_factor_precision.py CASCA EXAMPLES_DIR WORK_DIR

K is factorised and solved by SMUMPS; Newton's residual stays in double, so its iterations
refine the single-precision solves and the run converges to the answer of the double factors,
within Newton's tolerances. It asserts, against the same deck with the default 'double':
rings      the two rings of the thesis (examples/two_rings.nml) to 30 ms (the whole impact),
           on 1 rank and on 2 ranks (one ring per rank; the Schur path): the same steps and
           the same active contacts at every step, Newton iterations within 2% of the double
           run's, tracked positions within Newton's tolerance (newton_tol x the scene size,
           1e-9 x 4 m; measured: 7e-11 m), kinetic energy within 1e-6 relative at
           every step.
saddle     a plate thrown onto a rigid plane with about 640 contacts through the saddle-point
           matrix (&contact solver = 'saddle': the multipliers inside the single-precision
           factors), 5 steps: the same contacts, positions within 1e-9 m, the contact force
           within 1e-6 of the largest.
bad value  factor_precision = 'half': exit 2 naming the file, the line and the field.
"""
import os
import sys

import numpy as np

from casca_testlib import Checks, history, run, spinning_plate_deck

casca, examples, work = [os.path.abspath(a) for a in sys.argv[1:4]]
os.makedirs(work, exist_ok=True)
ck = Checks()


def run_deck(name, text, np_ranks=1):
    deck = os.path.join(work, name + ".nml")
    with open(deck, "w") as f:
        f.write(text)
    out = os.path.join(work, name)
    p = run([casca, "run", deck, "--out", out, "-q"], np_ranks=np_ranks)
    ck.record("%s: runs to the end (exit 0)" % name, p.returncode == 0, p.stderr[-300:])
    return history(out) if p.returncode == 0 else None


def compare(name, h, ref, pos_tol, newton_rel):
    if h is None or ref is None:
        return
    same = len(h["t"]) == len(ref["t"]) and np.array_equal(h["t"], ref["t"])
    ck.record("%s: the same steps as double" % name, same, "%d vs %d rows" % (len(h["t"]), len(ref["t"])))
    if not same:
        return
    ck.record("%s: the same active contacts at every step" % name, np.array_equal(h["contacts"], ref["contacts"]))
    ck.le("%s: Newton iterations, relative difference from double" % name,
          abs(h["newton"].sum() - ref["newton"].sum()) / ref["newton"].sum(), newton_rel)
    pos = [n for n in ref if n.startswith("p") and n[1:2].isdigit() and n[-2:] in ("_x", "_y", "_z")]
    ck.le("%s: tracked positions, largest difference from double [m]" % name,
          max(np.max(np.abs(h[n] - ref[n])) for n in pos), pos_tol)
    ck.le("%s: kinetic energy, largest difference / largest" % name,
          np.max(np.abs(h["kinetic"] - ref["kinetic"])) / np.max(ref["kinetic"]), 1e-6)
    if np.max(np.abs(ref["fcontact"])) > 0:
        ck.le("%s: contact force, largest difference / largest" % name,
              np.max(np.abs(h["fcontact"] - ref["fcontact"])) / np.max(np.abs(ref["fcontact"])), 1e-6)


# --- the two rings, 1 and 2 ranks
rings = open(os.path.join(examples, "two_rings.nml")).read()
rings = rings.replace("'../mesh/", "'" + os.path.join(os.path.dirname(examples), "mesh") + "/")
rings = rings.replace("t_end = 0.04", "t_end = 0.03")
rings = rings.replace("interval = 1.0e-3", "interval = 1.0e-3, vtu = .false., plots = .false.")
assert "t_end = 0.03" in rings and "vtu = .false." in rings
single = rings.replace("beta = 1.0, gamma = 1.5", "beta = 1.0, gamma = 1.5, factor_precision = 'single'")
assert single != rings
for np_ranks in (1, 2):
    ref = run_deck("rings_double_np%d" % np_ranks, rings, np_ranks)
    h = run_deck("rings_single_np%d" % np_ranks, single, np_ranks)
    if ref is not None:
        ck.record("rings_double_np%d: the rings touch" % np_ranks, ref["contacts"].max() > 0)
    compare("rings, %d rank(s), single" % np_ranks, h, ref, 4e-9, 0.02)

# --- the saddle-point matrix in single precision
ref = run_deck("plate_double", spinning_plate_deck("saddle"))
h = run_deck("plate_single", spinning_plate_deck("saddle", ", factor_precision = 'single'"))
if ref is not None:
    ck.record("plate_double: several hundred contacts", ref["contacts"][1:].min() >= 400,
              "%d" % ref["contacts"][1:].min())
compare("plate, saddle, single", h, ref, 1e-9, 0.1)

# --- bad value
text = spinning_plate_deck("saddle", ", factor_precision = 'half'")
deck = os.path.join(work, "half.nml")
with open(deck, "w") as f:
    f.write(text)
p = run([casca, "check", deck])
ck.record("factor_precision = 'half': exit 2 naming the file, the line and the field",
          p.returncode == 2 and "half.nml:1:" in p.stderr and "&run: factor_precision" in p.stderr,
          p.stderr[-300:])
ck.finish()
