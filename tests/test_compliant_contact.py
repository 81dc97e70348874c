"""Compliant (penalty) contact, &contact stiffness: against a plate on a spring floor.

usage: test_compliant_contact.py CASCA WORK_DIR

A steel plate (0.2 x 0.2 m, h 5 mm, 8 elements) lies flat on a rigid plane, contact at the
faces, &contact stiffness k = 1e9 Pa/m: each contact node carries k times its area times its
penetration, so a flat plate moves as a mass rho h per unit area on a spring k per unit
area (the consistent mass's rows sum to rho h times the nodes' areas, as the stiffness is
shared), omega = sqrt(k / (rho h)) = 5064 rad/s.
rest      under gravity 9.81, steps of 1 ms (5 / omega) with rho_inf 0, which damps the bounce
          out: after 20 ms it has sunk by rho h g / k = 3.826e-7 m (the tracked node's z, 1e-4)
          and the contact force equals its weight (1e-6); the energy the pair's compliance
          holds (contact_energy_plate_floor) is (m g)^2 / (2 k A), A the plate's area (1e-4).
drop      dropped flat at 1 m/s from 0.1 mm, generalized-alpha 0.8, to 1 ms: it touches at
          0.1 ms, sinks by v0 / omega = 0.1975 mm and leaves after pi / omega = 0.620 ms at
          v0: the tracked node's z(t) against the analytic half sine at 20, 10 and 5 us:
          the error falls at second order through the contact (observed order >= 1.8 between
          each pair of steps; casca's hard contact stops such a plate dead within a step,
          and its contact force was taken at the step's end rather than at the scheme's
          alpha level in a first version of this option: first order, rebounding at 0.93 v0
          at 20 us); at 10 us the rebound speed is v0 within 1e-4 and the total energy (kinetic,
          strain and what the contact holds) is E0 within 1e-4 at every step, and the pair's
          contact energy peaks at 1/2 m v0^2 (1e-3: the plate stops on its springs).
          With solver 'schur' and 'saddle' the tracked z(t) agree within 1e-10 m. Stopped at
          0.4 ms (in contact) and restarted from its checkpoint, the 10 us run repeats the
          uninterrupted one (z to 1e-12 m).
tolerance the same drop with &run tolerance 1e-3 and 1e-5 (error-controlled steps, the contact
          force judged against its depth): from one to the other the z(t) error falls by at
          least 4 and the rebound speed's error by at least 10 (8.0 and 25 measured; judged
          against the scene's size alone, the contact nodes' error was a thousand times
          looser than asked, and 1e-3 to 1e-5 were one 10-step run: 1 and 1).
ranks     two rings (20 elements each) meeting at 10 m/s, 1.5e10 Pa/m, on 1 and 2 ranks: the
          tracked x(t) agree within 1e-9 m.
check     casca check prints the contact time pi sqrt(rho h / k) = 0.620 ms and the steps of
          dt in it (1e-4).
bad input stiffness = -1: exit 2 naming &contact: stiffness.
"""
import os
import sys

import numpy as np

from casca_testlib import Checks, history, run, run_scene

casca, work = [os.path.abspath(a) for a in sys.argv[1:3]]
os.makedirs(work, exist_ok=True)
ck = Checks()
RHO, H, K, V0, G = 7800.0, 0.005, 1e9, 1.0, 9.81
M = RHO * H * 0.04
W = np.sqrt(K / (RHO * H))


def plate(run_line, z, velocity="0.0", extra=""):
    return f"""{run_line}
&output vtu = .false., plots = .false., interval = 2.0e-5, track = 0.0, 0.0, {z} /
&body name = 'plate', mesh = 'plate', lx = 0.2, ly = 0.2, nx = 2, ny = 2, center = -0.1, -0.1, {z},
  velocity = 0.0, 0.0, {velocity}, young = 210e9, poisson = 0.3, density = {RHO}, thickness = {H} /
&obstacle name = 'floor', shape = 'plane', point = 0.0, 0.0, 0.0, normal = 0.0, 0.0, 1.0 /
&contact stiffness = {K:g} {extra}/
"""


# (resting: steps of 1 ms, five times 1 / omega, which rho_inf 0 damps out: the plate comes
# to rest on its springs within a few steps)
out, _ = run_scene(casca, ck, work, "rest", plate(f"&run dt = 1.0e-3, t_end = 0.02, rho_inf = 0.0, gravity = 0.0, 0.0, {-G} /",
                                                  H / 2))
if out:
    h = history(out)
    ck.close("rest: the plate sinks by rho h g / k [m]", H / 2 - h["p1_z"][-1], RHO * H * G / K, 1e-4)
    ck.close("rest: contact force vs the weight [N]", h["fcontact"][-1], M * G, 1e-6)
    ck.close("rest: the pair's contact energy [J] vs (m g)^2 / (2 k A)", h["contact_energy_plate_floor"][-1],
             (M * G)**2 / (2 * K * 0.04), 1e-4)


def analytic(t):
    t1 = 1e-4 / V0   # (0.1 mm above)
    z = H / 2 + 1e-4 - V0 * t
    inside = (t > t1) & (t < t1 + np.pi / W)
    z = np.where(inside, H / 2 - V0 / W * np.sin(W * (t - t1)), z)
    return np.where(t >= t1 + np.pi / W, H / 2 + V0 * (t - t1 - np.pi / W), z)


errors = []
for dt in (2e-5, 1e-5, 5e-6):
    name = "drop_%g" % dt
    out, _ = run_scene(casca, ck, work, name, plate(f"&run dt = {dt}, t_end = 1.0e-3, rho_inf = 0.8 /",
                                                    H / 2 + 1e-4, velocity=-V0))
    if not out:
        break
    h = history(out)
    errors.append(np.abs(h["p1_z"] - analytic(h["t"])).max())
    if dt == 1e-5:
        ck.le("drop: rebound speed at 10 us vs v0 (|v / v0 - 1|)", abs(h["pz"][-1] / M / V0 - 1), 1e-4)
        ck.le("drop: total energy (with the contact's) at 10 us vs E0 at every step (max |E / E0 - 1|)",
              np.abs(h["total"] / h["total"][0] - 1).max(), 1e-4)
        ck.close("drop: the pair's largest contact energy at 10 us [J] vs 1/2 m v0^2",
                 h["contact_energy_plate_floor"].max(), 0.5 * M * V0**2, 1e-3)
if len(errors) == 3:
    for i in range(2):
        ck.record("drop: z(t) error %.3g m at %g us, %.3g m at half the step: observed order %.2f >= 1.8"
                  % (errors[i], (20, 10)[i], errors[i + 1], np.log2(errors[i] / errors[i + 1])),
                  np.log2(errors[i] / errors[i + 1]) >= 1.8)

# the error control judges the contact force against its depth: the error follows the tolerance
tol_err = []
for tol in ("1e-3", "1e-5"):
    out, _ = run_scene(casca, ck, work, "tol_" + tol, plate(f"&run dt = 1.0e-4, t_end = 1.0e-3, rho_inf = 0.8, tolerance = {tol} /",
                                                            H / 2 + 1e-4, velocity=-V0))
    if out:
        h = history(out)
        tol_err.append((np.abs(h["p1_z"] - analytic(h["t"])).max(), abs(h["pz"][-1] / M / V0 - 1)))
if len(tol_err) == 2:
    (z3, v3), (z5, v5) = tol_err
    ck.record("tolerance: z(t) error %.3g m at 1e-3, %.3g m at 1e-5: falls by %.2f >= 4" % (z3, z5, z3 / z5),
              z3 / z5 >= 4)
    ck.record("tolerance: rebound speed error |v / v0 - 1| %.3g at 1e-3, %.3g at 1e-5: falls by %.1f >= 10"
              % (v3, v5, v3 / v5), v3 / v5 >= 10)

# restart mid-contact (0.4 ms): the step's start gaps and the multipliers come back from the
# checkpoint, and the run goes on as the uninterrupted one
part = os.path.join(work, "drop_part")
for name, t_end, extra in (("drop_part", "4.0e-4", []), ("drop_rest", "1.0e-3", ["--restart", os.path.join(part, "checkpoint.h5")])):
    deck = os.path.join(work, name + ".nml")
    with open(deck, "w") as f:
        f.write(plate(f"&run dt = 1.0e-5, t_end = {t_end}, rho_inf = 0.8 /", H / 2 + 1e-4, velocity=-V0))
    p = run([casca, "run", deck, "--out", part, "-q"] + extra)
    ck.record("restart: %s runs (exit 0)" % name, p.returncode == 0, p.stderr[-300:])
ref = os.path.join(work, "drop_1e-05")
if os.path.exists(os.path.join(part, "history.dat")) and os.path.exists(os.path.join(ref, "history.dat")):
    r, u = history(part), history(ref)
    ck.le("restart at 0.4 ms: largest difference of z(t) from the uninterrupted run [m]",
          np.abs(r["p1_z"] - u["p1_z"]).max() if len(r["t"]) == len(u["t"]) else np.inf, 1e-12)

# the two linear-algebra paths carry the compliance alike: the saddle-point matrix's (2, 2)
# block, and the Schur complement's diagonal
zs = {}
for solver in ("schur", "saddle"):
    out, _ = run_scene(casca, ck, work, "drop_" + solver, plate("&run dt = 1.0e-5, t_end = 1.0e-3, rho_inf = 0.8 /",
                                                               H / 2 + 1e-4, velocity=-V0, extra=f"solver = '{solver}' "))
    if out:
        zs[solver] = history(out)["p1_z"]
if len(zs) == 2:
    ck.le("drop: z(t) with solver 'schur' vs 'saddle' (largest difference) [m]",
          np.abs(zs["schur"] - zs["saddle"]).max(), 1e-10)

# two bodies on two ranks (a ring each; the Schur complement summed over the ranks, its
# compliant diagonal added once): the same as on one
rings = """&run dt = 5.0e-5, t_end = 0.01, rho_inf = 0.8 /
&output vtu = .false., plots = .false., track = 1.0, 0.0, 0.0,   1.01, 0.0, 0.0, track_body = 'a', 'b' /
&body name = 'a', mesh = 'ring', radius = 1.0, width = 0.1, n_around = 20, velocity = 10.0, 0.0, 0.0,
  young = 210e9, poisson = 0.3, density = 7700, thickness = 0.05 /
&body name = 'b', mesh = 'ring', radius = 1.0, width = 0.1, n_around = 20, center = 2.01, 0.0, 0.0,
  young = 210e9, poisson = 0.3, density = 7700, thickness = 0.05 /
&contact surface = 'mid', stiffness = 1.5e10 /
"""
deck = os.path.join(work, "rings.nml")
with open(deck, "w") as f:
    f.write(rings)
xs = []
for n in (1, 2):
    p = run([casca, "run", deck, "--out", os.path.join(work, "rings_np%d" % n), "-q"], np_ranks=n)
    ck.record("rings on %d rank(s): exit 0" % n, p.returncode == 0, p.stderr[-300:])
    if p.returncode == 0:
        h = history(os.path.join(work, "rings_np%d" % n))
        xs.append((np.stack([h["p1_x"], h["p2_x"]]), h["contacts"].max()))
if len(xs) == 2:
    ck.record("rings: in contact", xs[0][1] > 0)
    ck.le("rings: tracked x(t) on 2 ranks vs 1 (largest difference) [m]",
          np.abs(xs[0][0] - xs[1][0]).max() if xs[0][0].shape == xs[1][0].shape else np.inf, 1e-9)

# casca check states the contact time pi sqrt(rho h / k) and how many steps it is
p = run([casca, "check", os.path.join(work, "drop_1e-05.nml")])
line = [l for l in p.stdout.splitlines() if l.startswith("contact: stiffness")]
ck.record("check: prints the compliant contact's time", len(line) == 1, p.stdout[-300:])
if line:
    t_c = float(line[0].split("= ")[1].split(" s")[0])
    ck.close("check: contact time [s] vs pi sqrt(rho h / k)", t_c, np.pi / W, 1e-4)
    ck.close("check: steps of dt in it vs pi sqrt(rho h / k) / dt", float(line[0].split("), ")[1].split(" steps")[0]),
             np.pi / W / 1e-5, 1e-4)

deck = os.path.join(work, "bad.nml")
with open(deck, "w") as f:
    f.write(plate("&run dt = 1.0e-5, t_end = 1.0e-4 /", H / 2).replace(f"stiffness = {K:g}", "stiffness = -1.0"))
p = run([casca, "run", deck, "--out", os.path.join(work, "bad")])
ck.record("bad input: stiffness = -1 exits 2 naming &contact: stiffness",
          p.returncode == 2 and "&contact: stiffness" in p.stderr, p.stderr[-300:])
ck.finish()
