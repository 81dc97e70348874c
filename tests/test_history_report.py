"""The history's per-body and per-pair columns and the closing energy balance (issue 16).

usage: test_history_report.py CASCA EXAMPLES_DIR WORK_DIR

The shipped two-ring deck (examples/two_rings.nml) is run for 4 ms (contact from about 1 ms)
on 1 rank and on 2 ranks (one ring each). It asserts:
  - the header: the columns of the earlier versions first, in their order, then
    kinetic_ring1 kinetic_ring2 strain_ring1 strain_ring2 fcontact_ring1_ring2
    contacts_ring1_ring2 impulse_ring1_ring2 contact_loss_ring1_ring2; history.h5 has the same
    names and values (1e-14 relative);
  - contact_loss_ring1_ring2, the kinetic energy the velocity corrections took out, starts at
    0, never falls (a projection in the mass metric onto the contacts takes energy out, never
    in), and is not zero once contact is reached;
  - on every row: kinetic_ring1 + kinetic_ring2 = kinetic and strain_ring1 + strain_ring2 =
    strain to 1e-12 relative (the totals are the sums; the margin is the 16 printed digits);
    with the one pair, contacts_ring1_ring2 = contacts exactly and fcontact_ring1_ring2 =
    fcontact to 1e-12 relative; contact is reached (the comparison is not of zeros);
  - at t = 0: kinetic_ring1 = 1/2 rho h (2 pi R W) v0^2 (rho 7700, h 0.05, R 1, W 0.2,
    v0 10 m/s) to 1e-5 relative (the mesh's cubic geometry and the element quadrature differ
    from the exact cylinder by less: measured 5e-7); kinetic_ring2 = 0 exactly (at rest);
  - the printed `energy balance:` line: E0, kinetic, strain, work and the velocity
    corrections' term equal the history's first total and last kinetic, strain, work and
    contact_loss_ring1_ring2 to the 5 printed digits (5e-5 relative), the remainder equals
    total[0] - total[-1] less that loss to the same, and its percentage of E0 equals
    100 (1 - E/E0 - loss/E0) from the history to 1e-3 (3 printed decimals);
  - on 2 ranks (each ring's elements on its own rank, summed in one reduction) the per-body
    and per-pair columns equal the 1-rank run's to 1e-8 of each column's largest value (the
    bound test_scenes uses for the tracked nodes on 1 and 2 ranks);
  - bodies named 'left ring' and 'right-ring': the columns are kinetic_left_ring,
    kinetic_right_ring, ..., contact_loss_left_ring_right_ring (single words of letters, digits
    and '_'), and every row has as many numbers as the header has names.
"""
import math
import os
import re
import sys

import h5py
import numpy as np

from casca_testlib import Checks, deck_variant, history, run

casca, examples, work = [os.path.abspath(a) for a in sys.argv[1:4]]
os.makedirs(work, exist_ok=True)
ck = Checks()

OLD = ("t step kinetic strain work total px py pz Lx Ly Lz contacts fcontact newton penetration "
       "neg_pivots lambda_max gap_max p1_x p1_y p1_z p1_vx p1_vy p1_vz p2_x p2_y p2_z p2_vx p2_vy "
       "p2_vz").split()
NEW = ("kinetic_ring1 kinetic_ring2 strain_ring1 strain_ring2 fcontact_ring1_ring2 "
       "contacts_ring1_ring2 impulse_ring1_ring2 contact_loss_ring1_ring2").split()

deck = deck_variant(os.path.join(examples, "two_rings.nml"), os.path.join(work, "rings4.nml"),
                    t_end="0.004")


def rel(a, b):
    """max over rows of |a - b| / |b| (0 where both are 0)"""
    return float(np.max(np.abs(a - b) / np.maximum(np.abs(b), 1e-300)))


outs = {}
for n in (1, 2):
    out = os.path.join(work, "rings4_np%d" % n)
    p = run([casca, "run", deck, "--out", out], np_ranks=n)
    ck.record("two rings 4 ms on %d rank(s): exit 0" % n, p.returncode == 0,
              "" if p.returncode == 0 else p.stderr[-300:])
    outs[n] = (out, p)
out, p = outs[1]
h = history(out)
names = list(h.keys())
ck.record("history.dat header: the earlier columns in their order, then the per-body and "
          "per-pair ones", names == OLD + NEW, " ".join(names[len(OLD):]))
with h5py.File(os.path.join(out, "history.h5"), "r") as f:
    table = f["history"][()]
    h5names = [c.decode() if isinstance(c, bytes) else str(c) for c in f["history"].attrs["columns"]]
ck.record("history.h5 has the columns of history.dat", h5names == names)
if h5names == names:
    ck.le("history.h5 equals history.dat (max relative difference)",
          max(rel(table[:, i], h[c]) for i, c in enumerate(names)), 1e-14)

if all(c in h for c in NEW):
    ck.le("kinetic_ring1 + kinetic_ring2 = kinetic (max relative, every row)",
          rel(h["kinetic_ring1"] + h["kinetic_ring2"], h["kinetic"]), 1e-12)
    ck.le("strain_ring1 + strain_ring2 = strain (max relative, every row)",
          rel(h["strain_ring1"] + h["strain_ring2"], h["strain"]), 1e-12)
    ck.record("contact is reached in the 4 ms (rows with contacts: %d of %d)"
              % (np.count_nonzero(h["contacts"]), len(h["t"])), h["contacts"].max() > 0)
    ck.record("contacts_ring1_ring2 = contacts on every row (one pair)",
              np.array_equal(h["contacts_ring1_ring2"], h["contacts"]),
              "max %d" % h["contacts"].max())
    ck.le("fcontact_ring1_ring2 = fcontact (max relative, every row)",
          rel(h["fcontact_ring1_ring2"], h["fcontact"]), 1e-12)
    ke0 = 0.5 * 7700 * 0.05 * (2 * math.pi * 1.0 * 0.2) * 10.0 ** 2
    ck.close("kinetic_ring1 at t = 0 vs 1/2 rho h 2 pi R W v0^2 [J]", h["kinetic_ring1"][0], ke0, 1e-5)
    ck.record("kinetic_ring2 at t = 0 is 0 (at rest)", h["kinetic_ring2"][0] == 0,
              "%g" % h["kinetic_ring2"][0])

# --- the closing energy balance
num = r"(-?\d\.\d+E[+-]\d+)"
m = re.search(r"energy balance: E0 = %s J, kinetic %s, strain %s, work of loads %s, taken out by the "
              r"velocity corrections %s, removed by the time integrator and contact %s "
              r"\((-?[\d.]+)%% of E0\)" % ((num,) * 6), p.stdout)
ck.record("the run prints the energy balance line", m is not None,
          m.group(0) if m else p.stdout[-400:])
if m:
    e0, kin, strain, work_, loss, rest = (float(m.group(i)) for i in range(1, 7))
    pct = float(m.group(7))
    loss_h = h["contact_loss_ring1_ring2"][-1]
    for label, printed, ref in (("E0", e0, h["total"][0]), ("kinetic", kin, h["kinetic"][-1]),
                                ("strain", strain, h["strain"][-1]), ("velocity corrections", loss, loss_h)):
        ck.close("energy balance: %s = history's" % label, printed, ref, 5e-5)
    ck.le("energy balance: work of loads = history's (none: 0)", abs(work_ - h["work"][-1]), 0)
    ck.close("energy balance: remainder = total[0] - total[-1] - contact_loss of the history", rest,
             h["total"][0] - h["total"][-1] - loss_h, 5e-5)
    ck.le("energy balance: percentage - 100 (1 - E/E0 - loss/E0) of the history",
          abs(pct - 100 * (1 - (h["total"][-1] + loss_h) / h["total"][0])), 1e-3)
if "contact_loss_ring1_ring2" in h:
    cl = h["contact_loss_ring1_ring2"]
    ck.record("contact_loss_ring1_ring2 starts at 0 and never falls (to 1e-12 of its end)",
              cl[0] == 0 and np.all(np.diff(cl) >= -1e-12 * cl[-1]), "end %.6g J, least step %.3g J"
              % (cl[-1], np.diff(cl).min()))
    ck.record("contact_loss_ring1_ring2 is not zero once contact is reached", cl[-1] > 0 and h["contacts"].max() > 0,
              "%.6g J" % cl[-1])

# --- 2 ranks: the same per-body and per-pair columns
h2 = history(outs[2][0])
if all(c in h2 for c in NEW) and len(h2["t"]) == len(h["t"]):
    ck.le("2 ranks: per-body and per-pair columns vs 1 rank (max diff / column's max)",
          max(np.max(np.abs(h2[c] - h[c])) / max(np.max(np.abs(h[c])), 1e-300) for c in NEW), 1e-8)
else:
    ck.record("2 ranks: the per-body and per-pair columns, as many rows", False)

# --- names with a blank and a hyphen become single words
text = open(deck).read().replace("ring1", "left ring").replace("ring2", "right-ring")
named = os.path.join(work, "named.nml")
with open(named, "w") as f:
    f.write(text)
deck_variant(named, named, t_end="0.0005")
out = os.path.join(work, "named")
p = run([casca, "run", named, "--out", out, "-q"])
ck.record("bodies 'left ring' and 'right-ring': exit 0", p.returncode == 0,
          "" if p.returncode == 0 else p.stderr[-300:])
if p.returncode == 0:
    head = open(os.path.join(out, "history.dat")).readline().lstrip("#").split()
    want = ("kinetic_left_ring kinetic_right_ring strain_left_ring strain_right_ring "
            "fcontact_left_ring_right_ring contacts_left_ring_right_ring impulse_left_ring_right_ring "
            "contact_loss_left_ring_right_ring").split()
    ck.record("their columns: %s" % " ".join(want), head[len(OLD):] == want, " ".join(head[len(OLD):]))
    rows = np.atleast_2d(np.loadtxt(os.path.join(out, "history.dat")))
    ck.record("every row has as many numbers as the header has names (%d)" % len(head),
              rows.shape[1] == len(head), str(rows.shape))
ck.finish()
