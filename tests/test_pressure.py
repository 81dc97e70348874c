"""&load kind = 'pressure' end to end (issue 17): a closed sphere (radius R = 1 m, thickness
h = 5 mm, E = 200 GPa, nu = 0.3, n_div = 2: 80 cubic elements) under a follower internal
pressure, and an open cantilever strip under pressure (item 5). What is asserted, each
against an independent answer:

1. orientation: every element of `casca mesh sphere` has (x2 - x1) x (x3 - x1) pointing away
   from the centre, so p > 0 is an internal pressure (README's sign convention).
2. statics, p = 10 kPa (linear): the radial expansion of two tracked nodes equals the membrane
   answer w = p R^2 (1 - nu) / (2 E h) within 1%; the work of loads equals p dV = p 4 pi R^2 w
   within 1%; the strain energy is half of it (Clapeyron) within 1%.
3. statics, p = 300 MPa (11% stretch), 3 load steps, full Newton: the stretch r/R equals the
   thin-sphere answer of the 3D Saint-Venant-Kirchhoff law under plane stress,
   p = 2 S11(lambda) h / (lambda R), within 0.2% of the displacement; every load step
   converges in at most 5 iterations (quadratic convergence), and the same run without the
   load stiffness (&run load_stiffness = .false.) needs at least 1.5 times as many, to the same
   answer (1e-6). On 2 MPI ranks (the body's elements split by METIS) the answer is the 1-rank
   one (1e-9) in as many iterations.
4. dynamics, the 10 kPa pressure applied at t = 0 to the free sphere, trapezoidal rule: the
   peak expansion is twice the static one (a step load on the breathing mode) within 2%, at
   half the breathing period pi sqrt(rho R^2 (1 - nu) / (2 E)) within 3% (the run starts from
   zero acceleration, which delays it by about dt/2, 2%); kinetic + strain -
   work of loads is constant from the first step on within 1e-5 of the work (the pressure on
   a closed surface is conservative and the trapezoidal rule keeps its energy).
5. open surface, origin-free work: a cantilever strip (L = 10 m, b = 1 m, h = 0.1 m,
   E = 1.2 MPa, nu = 0, 10x1 cells, clamped at x = 0) under p = 1e-4 Pa (tip deflection 1e-4
   of L: linear), once at x in [0, L] and once moved by center = (-20, 0, 0), where p (V - V0)
   over the open strip would give -0.17 and 1.5 times the answer. Statics, one load step: the
   work of loads equals 2 x the strain energy (Clapeyron at the full load) within 1e-3 and the
   beam answer p^2 b^2 L^5 / (20 E I) within 1e-3, at both positions, which agree within 1e-6.
   Dynamics, the pressure applied at t = 0, generalized-alpha rho_inf = 0.8, dt = T1/280 (T1
   the first bending period) for two periods: kinetic + strain - work never exceeds 1e-6 of
   the largest work (no energy made) nor falls below -1e-3 of it (what the scheme removes of
   the first bending mode); the moved strip's work is the other's within 1e-6 of its
   largest; on 2 ranks the work is the 1-rank one within 1e-9; and the run cut at one period
   and restarted from its checkpoint ends with the uninterrupted run's work within 1e-9.
6. deck errors give exit 2 with file, line and field: force with kind 'pressure', pressure
   with kind 'nodal', a pressure that is not a number, a selection holding no whole element.

usage: test_pressure.py CASCA WORKDIR
"""
import math
import os
import sys

import numpy as np

from casca_testlib import Checks, history, run, run_scene, svk_sphere_stretch

E, NU, RHO, H, R = 2.0e11, 0.3, 7800.0, 0.005, 1.0

PHI = (1 + 5 ** 0.5) / 2
# the six restraints: icosahedron vertices (on the mesh) each held in one component that a
# uniform expansion leaves at zero; together they stop the six rigid motions
RESTRAINTS = [((0, 1, PHI), "x"), ((0, -1, -PHI), "x"), ((PHI, 0, 1), "y"),
              ((-PHI, 0, -1), "y"), ((1, PHI, 0), "z"), ((-1, -PHI, 0), "z")]



def two_ranks(casca, ck, work, name, deck, out):
    """the deck (in work) run again on 2 ranks into out: its history, None when it failed"""
    p = run([casca, "run", os.path.join(work, deck), "--out", os.path.join(work, out), "-q"], np_ranks=2)
    ck.record("%s on 2 ranks: runs to the end (exit 0)" % name, p.returncode == 0, p.stderr[-300:])
    return history(os.path.join(work, out)) if p.returncode == 0 else None

def sphere_deck(run_keys, pressure, restrained=True, output=""):
    lines = ["&run\n  %s\n/" % run_keys,
             "&output\n  vtu = .false., plots = .false.\n  track = 1.0, 0.0, 0.0,  0.0, 0.0, 1.0\n%s/"
             % output,
             "&body\n  name = 'ball', mesh = 'sphere', radius = %g, n_div = 2\n"
             "  young = %g, poisson = %g, density = %g, thickness = %g\n/" % (R, E, NU, RHO, H)]
    if restrained:
        for v, comp in RESTRAINTS:
            c = np.array(v) * R / np.linalg.norm(v)
            lines.append("&restraint body = 'ball', box_min = %s, box_max = %s, fix = '%s' /"
                         % (", ".join("%.4f" % x for x in c - 0.01),
                            ", ".join("%.4f" % x for x in c + 0.01), comp))
    lines.append("&load body = 'ball', kind = 'pressure', pressure = %g /" % pressure)
    return "\n".join(lines) + "\n"


def radii(h):
    """radii of the two tracked nodes at every row"""
    return [np.sqrt(h["p%d_x" % k] ** 2 + h["p%d_y" % k] ** 2 + h["p%d_z" % k] ** 2) for k in (1, 2)]


def svk_stretch(p):
    """r/R of this sphere under mid-surface pressure p (casca_testlib.svk_sphere_stretch)"""
    return svk_sphere_stretch(p, E, NU, H, R)


def orientation(casca, ck, work):
    import meshio
    path = os.path.join(work, "sphere.msh")
    p = run([casca, "mesh", "sphere", "--radius", str(R), "--n-div", "2", "-o", path])
    ck.record("casca mesh sphere writes the mesh (exit 0)", p.returncode == 0, p.stderr[-300:])
    if p.returncode != 0:
        return
    m = meshio.read(path)
    cells = np.concatenate([c.data for c in m.cells if c.type == "triangle10"])
    x = m.points[cells]
    n = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
    outward = np.einsum("ij,ij->i", n, x[:, :3].mean(axis=1))
    ck.record("sphere: all %d elements' normals point outwards" % len(cells),
              len(cells) == 80 and bool(np.all(outward > 0)))


def small_pressure(casca, ck, work):
    p = 1.0e4
    out, _ = run_scene(casca, ck, work, "small", sphere_deck("analysis = 'static', load_steps = 1", p))
    if out is None:
        return
    h = history(out)
    w = p * R * R * (1 - NU) / (2 * E * H)
    for k, r in enumerate(radii(h)):
        ck.close("small p: radial expansion of tracked node %d = p R^2 (1-nu)/(2 E h)" % (k + 1),
                 r[-1] - R, w, 0.01)
    ck.close("small p: work of loads = p 4 pi R^2 w", h["work"][-1], p * 4 * math.pi * R * R * w, 0.01)
    ck.close("small p: strain energy = work / 2 (Clapeyron)", h["strain"][-1], h["work"][-1] / 2, 0.01)


def large_pressure(casca, ck, work):
    p = 3.0e8
    keys = "analysis = 'static', load_steps = 3, reuse_factorisation = .false."
    out, _ = run_scene(casca, ck, work, "large", sphere_deck(keys, p))
    out_k, _ = run_scene(casca, ck, work, "large_no_k", sphere_deck(keys + ", load_stiffness = .false.", p))
    if out is None or out_k is None:
        return
    h, hk = history(out), history(out_k)
    s = svk_stretch(p)
    for k, r in enumerate(radii(h)):
        ck.close("large p: displacement of tracked node %d = thin-sphere SVK answer (stretch %.4f)"
                 % (k + 1, s), r[-1] - R, (s - 1) * R, 0.002)
    ck.le("large p: most Newton iterations of a load step (full Newton, load stiffness)",
          max(h["newton"]), 5)
    ck.le("large p: Newton iterations with the load stiffness x 1.5 <= without",
          1.5 * sum(h["newton"]), sum(hk["newton"]))
    ck.le("large p: the same answer without the load stiffness (rel)",
          abs(radii(hk)[0][-1] - radii(h)[0][-1]) / (radii(h)[0][-1] - R), 1e-6)
    h2 = two_ranks(casca, ck, work, "large p", "large.nml", "large_np2")
    if h2 is not None:
        ck.le("large p on 2 ranks: tracked radius as on 1 rank (rel)",
              abs(radii(h2)[0][-1] - radii(h)[0][-1]) / (radii(h)[0][-1] - R), 1e-9)
        ck.record("large p on 2 ranks: the same Newton iterations per load step",
                  list(h2["newton"]) == list(h["newton"]),
                  "%s vs %s" % ([int(n) for n in h2["newton"]], [int(n) for n in h["newton"]]))


def dynamic_step(casca, ck, work):
    p = 1.0e4
    period = 2 * math.pi * math.sqrt(RHO * R * R * (1 - NU) / (2 * E))
    dt = period / 50
    # (the motion is 1e-5 of the scene size, which Newton's default tolerance is relative to:
    # too loose for energy to 1e-5 of the work)
    keys = ("analysis = 'dynamic', dt = %.10g, t_end = %.10g, beta = 0.25, gamma = 0.5, "
            "newton_tol = 1e-13" % (dt, 38 * dt))
    out, _ = run_scene(casca, ck, work, "step", sphere_deck(keys, p, restrained=False))
    if out is None:
        return
    h = history(out)
    w = p * R * R * (1 - NU) / (2 * E * H)
    r = radii(h)[0] - R
    k = int(np.argmax(r))
    ck.close("step load: peak expansion = 2 x static", r[k], 2 * w, 0.02)
    # the peak between the steps (parabola through the three rows around the largest)
    t_peak = h["t"][k] + dt * 0.5 * (r[k - 1] - r[k + 1]) / (r[k - 1] - 2 * r[k] + r[k + 1])
    ck.close("step load: time of the peak = half the breathing period", t_peak, period / 2, 0.03)
    total = h["kinetic"] + h["strain"] - h["work"]
    ck.le("step load: drift of kinetic + strain - work after the first step / work",
          np.ptp(total[1:]) / np.max(h["work"]), 1e-5)


def strip_deck(run_keys, moved, output=""):
    """the cantilever strip of item 5: at x in [0, L], or moved by center = (-20, 0, 0)"""
    x0 = -20.0 if moved else 0.0   # (center translates the strip, from x = 0)
    centre = ", center = -20.0, 0.0, 0.0" if moved else ""
    return ("&run\n  %s\n/\n"
            "&output\n  plots = .false., vtu = .false.\n%s/\n"
            "&body\n  name = 'strip', mesh = 'strip', lx = %g, ly = %g, nx = 10, ny = 1\n"
            "  young = %g, poisson = 0.0, density = %g, thickness = %g%s\n/\n"
            "&restraint body = 'strip', box_max = %g, 1e9, 1e9, fix = 'clamped' /\n"
            "&load body = 'strip', kind = 'pressure', pressure = %g /\n"
            % (run_keys, output, STRIP_L, STRIP_B, STRIP_E, STRIP_RHO, STRIP_H, centre, x0, STRIP_P))


STRIP_L, STRIP_B, STRIP_H, STRIP_E, STRIP_RHO, STRIP_P = 10.0, 1.0, 0.1, 1.2e6, 1.0, 1.0e-4


def open_surface(casca, ck, work):
    ei = STRIP_E * STRIP_B * STRIP_H ** 3 / 12
    beam = (STRIP_P * STRIP_B) ** 2 * STRIP_L ** 5 / (20 * ei)
    works = {}
    for moved in (False, True):
        where = "moved" if moved else "origin"
        out, _ = run_scene(casca, ck, work, "strip_static_" + where,
                           strip_deck("analysis = 'static', load_steps = 1", moved))
        if out is None:
            continue
        h = history(out)
        works[where] = h["work"][-1]
        ck.close("strip statics (%s): work of the pressure = 2 x strain energy" % where,
                 h["work"][-1], 2 * h["strain"][-1], 1e-3)
        ck.close("strip statics (%s): work = beam answer p^2 b^2 L^5 / (20 E I)" % where,
                 h["work"][-1], beam, 1e-3)
    if len(works) == 2:
        ck.close("strip statics: the work moved = at the origin", works["moved"], works["origin"], 1e-6)

    period = 2 * math.pi / (1.875104 ** 2 * math.sqrt(ei / (STRIP_RHO * STRIP_B * STRIP_H * STRIP_L ** 4)))
    dt = period / 280
    keys = "dt = %.10g, t_end = %.10g, rho_inf = 0.8" % (dt, 560 * dt)
    # (a checkpoint at one period: it drops the factors there, as the restart starts anew)
    ckpt = "  checkpoint_interval = %.10g\n" % (280 * dt)
    h = {}
    for moved in (False, True):
        where = "moved" if moved else "origin"
        out, _ = run_scene(casca, ck, work, "strip_dynamic_" + where, strip_deck(keys, moved, ckpt))
        if out is None:
            continue
        h[where] = history(out)
        total = h[where]["kinetic"] + h[where]["strain"] - h[where]["work"]
        wmax = np.max(np.abs(h[where]["work"]))
        ck.le("strip dynamics (%s): largest (kinetic + strain - work) / largest work (made)"
              % where, np.max(total) / wmax, 1e-6)
        ck.le("strip dynamics (%s): -smallest (kinetic + strain - work) / largest work (removed)"
              % where, -np.min(total) / wmax, 1e-3)
    if len(h) < 2:
        return
    a, b = h["origin"], h["moved"]
    ck.le("strip dynamics: the moved strip's work = the other's (of the largest)",
          np.max(np.abs(a["work"] - b["work"])) / np.max(np.abs(a["work"])), 1e-6)
    deck = os.path.join(work, "strip_dynamic_moved.nml")
    h2 = two_ranks(casca, ck, work, "strip dynamics", "strip_dynamic_moved.nml", "strip_dynamic_np2")
    if h2 is not None:
        ck.le("strip dynamics on 2 ranks: the work as on 1 rank (of the largest)",
              np.max(np.abs(h2["work"] - b["work"])) / np.max(np.abs(b["work"])), 1e-9)
    half, _ = run_scene(casca, ck, work, "strip_half",
                        strip_deck("dt = %.10g, t_end = %.10g, rho_inf = 0.8" % (dt, 280 * dt), True))
    if half is None:
        return
    out3 = os.path.join(work, "strip_restarted")
    p3 = run([casca, "run", deck, "--out", out3, "-q", "--restart", os.path.join(half, "checkpoint.h5")])
    ck.record("strip dynamics restarted at one period: runs to the end (exit 0)", p3.returncode == 0,
              p3.stderr[-300:])
    if p3.returncode == 0:
        h3 = history(out3)
        ck.record("strip dynamics restarted: as many rows as the uninterrupted run",
                  len(h3["t"]) == len(b["t"]), "%d vs %d" % (len(h3["t"]), len(b["t"])))
        if len(h3["t"]) == len(b["t"]):
            ck.le("strip dynamics restarted: the work as the uninterrupted run's (of the largest)",
                  np.max(np.abs(h3["work"] - b["work"])) / np.max(np.abs(b["work"])), 1e-9)


def deck_errors(casca, ck, work):
    base = sphere_deck("analysis = 'static'", 1e4, restrained=False)
    cases = [
        ("force", base.replace("pressure = 10000 /", "pressure = 10000, force = 1.0, 0.0, 0.0 /"),
         ":%d: &load: kind = 'pressure' takes pressure"),
        ("nodal", base.replace("kind = 'pressure'", "kind = 'nodal'"),
         ":%d: &load: pressure needs kind = 'pressure'"),
        ("text", base.replace("pressure = 10000 /", "pressure = 'high' /"),
         ":%d: &load: pressure = 'high' is not a number"),
        ("none", base.replace("kind = 'pressure'", "nodes = 1, 2, 3, kind = 'pressure'"),
         ":%d: &load: kind = 'pressure' needs an element with its 10 nodes selected"),
    ]
    line = base.count("\n")   # the &load group is the last line
    for name, text, msg in cases:
        deck = os.path.join(work, "bad_%s.nml" % name)
        with open(deck, "w") as f:
            f.write(text)
        p = run([casca, "check", deck])
        ck.record("bad deck (%s): exit 2 and '%s'" % (name, msg % line),
                  p.returncode == 2 and (deck + msg % line) in p.stderr, p.stderr[-300:])


def main():
    casca, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    ck = Checks()
    orientation(casca, ck, work)
    small_pressure(casca, ck, work)
    large_pressure(casca, ck, work)
    dynamic_step(casca, ck, work)
    open_surface(casca, ck, work)
    deck_errors(casca, ck, work)
    ck.finish()


if __name__ == "__main__":
    main()
