"""Helpers shared by the end-to-end tests: run casca, read its history, record checks.

Every check prints its figure, the bound and the independent answer; the script ends with
the "N passed, M failed" line and a non-zero exit status if anything failed."""
import os
import re
import subprocess

import numpy as np

from casca_checks import Checks  # noqa: F401  (the tests take it from here)

ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1")


def run(args, np_ranks=1, cwd=None, timeout=3000):
    """Run casca (args[0] is the binary) on np_ranks ranks; returns the CompletedProcess."""
    cmd = list(args)
    if np_ranks > 1:
        cmd = ["mpirun", "-np", str(np_ranks)] + cmd
    return subprocess.run(cmd, cwd=cwd, env=ENV, capture_output=True, text=True, timeout=timeout)


def run_scene(casca, ck, work, name, text, quiet=True):
    """Write deck text to WORK/NAME.nml, run it into WORK/NAME and record that it ran to the end
    (exit 0). Returns the output folder (None on failure) and casca's standard output."""
    deck = os.path.join(work, name + ".nml")
    with open(deck, "w") as f:
        f.write(text)
    out = os.path.join(work, name)
    p = run([casca, "run", deck, "--out", out] + (["-q"] if quiet else []))
    ck.record("%s: runs to the end (exit 0)" % name, p.returncode == 0, p.stderr[-300:])
    return (out if p.returncode == 0 else None), p.stdout


def history(folder):
    """history.dat as a dict of columns (numpy arrays), keyed by the header's names."""
    path = os.path.join(folder, "history.dat")
    with open(path) as f:
        names = f.readline().lstrip("#").split()
    data = np.atleast_2d(np.loadtxt(path))
    return {n: data[:, i] for i, n in enumerate(names)}


def loaded(h):
    """A static run's history from its first load step on: its row 0 is the unloaded state
    (load factor 0), where ratios to the load are 0 / 0."""
    keep = h["t"] > 0
    return {k: v[keep] for k, v in h.items()}


def momentum_error(h):
    """Largest change of the total linear momentum over the run, relative to the initial."""
    p = np.stack([h["px"], h["py"], h["pz"]]).T
    return np.max(np.linalg.norm(p - p[0], axis=1)) / np.linalg.norm(p[0])


def angular_momentum(h):
    """The total angular momentum about the origin at each row, shape (rows, 3)."""
    return np.stack([h["Lx"], h["Ly"], h["Lz"]]).T


def angular_drift(h, scale=None):
    """Largest change of the total angular momentum over the run, max |L - L0|, over scale
    (default |L0|)."""
    L = angular_momentum(h)
    return np.max(np.linalg.norm(L - L[0], axis=1)) / (np.linalg.norm(L[0]) if scale is None else scale)


def deck_variant(src, dst, **changes):
    """Copy a deck, replacing `key = value` assignments (first occurrence of each key) and
    making relative mesh paths absolute so the copy can live elsewhere."""
    text = open(src).read()
    base = os.path.dirname(os.path.abspath(src))
    text = re.sub(r"file\s*=\s*'([^'/][^']*)'",
                  lambda m: "file = '%s'" % os.path.normpath(os.path.join(base, m.group(1))), text)
    for key, value in changes.items():
        text, n = re.subn(r"\b%s\s*=\s*[^,\n/]+" % key, "%s = %s" % (key, value), text, count=1)
        if n == 0:
            raise ValueError("%s has no %s" % (src, key))
    with open(dst, "w") as f:
        f.write(text)
    return dst


def tension_plate_deck(lx, ly, nx, ny, young, nu, h, force, load_steps=1, output=""):
    """A flat plate (lx x ly, nx x ny cells) pulled along x in statics by an edge force on its
    edge x = lx: held in x on x = 0, in y at the origin, in z everywhere (uniaxial plane
    stress). output: more &output settings (', key = value')."""
    return """&run
  analysis = 'static', load_steps = %d
/
&output
  interval = 1.0%s
/
&body
  name = 'plate', mesh = 'plate', lx = %r, ly = %r, nx = %d, ny = %d
  young = %r, poisson = %r, density = 1.0, thickness = %r
/
&restraint
  body = 'plate', box_max = 0.0, 1e9, 1e9, fix = 'x'
/
&restraint
  body = 'plate', box_max = 0.0, 0.0, 1e9, fix = 'y'
/
&restraint
  body = 'plate', fix = 'z'
/
&load
  body = 'plate', box_min = %r, -1e9, -1e9, force = %r, 0.0, 0.0, kind = 'edge'
/
""" % (load_steps, output, lx, ly, nx, ny, young, nu, h, lx, force)


def spinning_plate_deck(solver, run_extra=""):
    """A steel plate (1 m, h 10 mm, 9 x 9 cells) thrown at 0.2 m/s, spinning, onto a rigid
    plane under 100 m/s^2: several hundred contacts changing from step to step, 5 steps.
    solver: &contact solver; run_extra: more &run settings (', key = value')."""
    return """&run dt = 1e-4, t_end = 5e-4, gravity = 0.0, 0.0, -100.0%s /
&output interval = 5e-4, vtu = .false., plots = .false.,
  track = 0.5, 0.5, 0.0,  -0.5, -0.5, 0.0,  0.0, 0.0, 0.0 /
&body name = 'plate', mesh = 'plate', lx = 1.0, ly = 1.0, nx = 9, ny = 9,
  center = -0.5, -0.5, 0.005001, velocity = 0.0, 0.0, -0.2, omega = 0.5, 0.3, 0.0,
  young = 210e9, poisson = 0.3, density = 7800, thickness = 0.01 /
&obstacle name = 'floor', shape = 'plane', point = 0.0, 0.0, 0.0, normal = 0.0, 0.0, 1.0 /
&contact solver = '%s' /
""" % (run_extra, solver)


def svk_sphere_stretch(p, young, nu, h, radius):
    """r/R of a thin closed sphere of the 3D Saint Venant-Kirchhoff law with S33 = 0 under a
    mid-surface (follower) pressure p: p = 2 S11(lambda) h / (lambda R), by bisection"""
    lam_l = young * nu / ((1 + nu) * (1 - 2 * nu))
    mu = young / (2 * (1 + nu))

    def excess(s):
        e11 = (s * s - 1) / 2
        e33 = -lam_l * 2 * e11 / (lam_l + 2 * mu)
        s11 = lam_l * (2 * e11 + e33) + 2 * mu * e11
        return 2 * s11 * h / (s * radius) - p
    a, b = 1.0, 2.0
    for _ in range(200):
        m = (a + b) / 2
        a, b = (a, m) if excess(m) > 0 else (m, b)
    return (a + b) / 2


def blade_case(casca, ck, work, name, angle, contact=""):
    """A steel plate (0.2 x 0.1 m, 4 x 2 cells, h 2 mm) tilted angle degrees, its lower edge
    3 mm above a clamped steel plate (0.4 m, 6 x 6 cells, h 2 mm) listed first, dropped
    edge-first at 10 m/s (generalized-alpha 0.8, 10 us, 0.6 ms; contact: &contact's keys).
    Records that they touch, that the energy never rises in a step by more than 1e-3 E0, and
    that the blade's tracked edge node stays (h/2)(1 + cos angle) - 1e-4 m above the plate's
    node below it (the plate's half thickness and the blade's lower face corner)."""
    steel = "young = 210e9, poisson = 0.3, density = 7700, thickness = 0.002"
    out, _ = run_scene(casca, ck, work, name, f"""&run dt = 1.0e-5, t_end = 6.0e-4, rho_inf = 0.8 /
&output interval = 1.0e-4, vtu = .false., plots = .false.,
  track = 0.0, 0.0, 0.003,   0.0, 0.0, 0.0, track_body = 'blade', 'base' /
&body name = 'base', mesh = 'plate', lx = 0.4, ly = 0.4, nx = 6, ny = 6, center = -0.2, -0.2, 0,
  {steel} /
&body name = 'blade', mesh = 'plate', lx = 0.2, ly = 0.1, nx = 4, ny = 2,
  rotate_axis = 1, 0, 0, rotate_angle = {angle}, center = -0.1, 0, 0.003, velocity = 0, 0, -10,
  {steel} /
&restraint body = 'base', box_min = -1, -1, -1, box_max = 1, -0.19, 1, fix = 'clamped' /
&restraint body = 'base', box_min = -1, 0.19, -1, box_max = 1, 1, 1, fix = 'clamped' /
&contact {contact} /
""")
    if out is None:
        return
    h = history(out)
    ck.record("%s: the blade and the plate touch" % name, h["contacts"].max() > 0)
    ck.le("%s: largest rise of the total energy in a step / E0" % name,
          np.diff(h["total"]).max() / h["total"][0], 1e-3)
    least = 0.001 * (1 + np.cos(np.radians(angle)))
    ck.le("%s: the edge stays on the plate's face ((h/2)(1 + cos angle) - least height of the "
          "edge node over the plate's node below it) [m]" % name,
          least - (h["p1_z"] - h["p2_z"]).min(), 1e-4)
