#!/usr/bin/env python3
"""Work-precision benchmark: error against wall time for ladders of time steps and meshes.

usage: work_precision.py CASCA WORK_DIR [--ranks N] [--scenes strip,rings,spheres]

Errors:
  strip_wall    against the 1D bar answer: the largest relative error of the contact duration
                (2L/c), the mean contact force (rho c v0 b h) and the rebound speed (v0)
  two_rings     against a converged reference computed once (finest step and mesh): the
                largest distance between the tracked nodes' x(t) and the reference's, over
                the whole 40 ms, in metres
  three_spheres the same, over 2 ms (contact begins at 1 ms)
Writes WORK_DIR/work_precision.dat and work_precision.png (log-log, gnuplot) and prints the
table."""
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
ap.add_argument("--ranks", type=int, default=1)
ap.add_argument("--scenes", default="strip,rings,spheres")
args = ap.parse_args()
casca = os.path.abspath(args.casca)
work = os.path.abspath(args.work)
os.makedirs(work, exist_ok=True)
rows = []

STEEL = "young = 210e9, density = 7700"


def run(name, deck_text):
    deck = os.path.join(work, name + ".nml")
    with open(deck, "w") as f:
        f.write(deck_text)
    out = os.path.join(work, name)
    cmd = [casca, "run", deck, "--out", out, "-q"]
    if args.ranks > 1:
        cmd = ["mpirun", "-np", str(args.ranks)] + cmd
    t0 = time.time()
    p = subprocess.run(cmd, env=ENV, capture_output=True, text=True)
    wall = time.time() - t0
    if p.returncode != 0:
        print(name, "failed:", p.stderr[-500:])
        return None, wall
    return history(out), wall


def mesh_cmd(kind, path, **kw):
    if not os.path.exists(path):
        cmd = [casca, "mesh", kind] + sum([["--" + k.replace("_", "-"), str(v)] for k, v in kw.items()], []) + ["-o", path]
        subprocess.run(cmd, env=ENV, check=True, capture_output=True)
    return path


def track_error(h, ref, cols):
    """max over time and tracked columns of |x - x_ref| (reference interpolated in time)"""
    return max(np.max(np.abs(h[c] - np.interp(h["t"], ref["t"], ref[c]))) for c in cols)


def record(scene, label, dt, elems, err, wall, steps):
    rows.append((scene, label, dt, elems, err, wall, steps))
    print("%-13s %-22s dt %.2e  elements %5d  error %.3e  wall %8.2f s  steps %d"
          % (scene, label, dt, elems, err, wall, steps), flush=True)


if "strip" in args.scenes:
    E, rho, L, b, h, v0 = 210e9, 7700.0, 1.0, 0.1, 0.01, 1.0
    c = np.sqrt(E / rho)
    for nx in (10, 20, 40):
        strip = mesh_cmd("strip", os.path.join(work, "strip_%d.msh" % nx), lx=1, ly=0.1, nx=nx, ny=1)
        wall_m = mesh_cmd("plate", os.path.join(work, "wall.msh"), lx=0.2, ly=0.2, nx=2, ny=2)
        for dt in (8e-6, 4e-6, 2e-6, 1e-6):
            deck = f"""&run dt = {dt}, t_end = 6.0e-4, beta = 0.25, gamma = 0.5 /
&output interval = 1.0e-4, vtu = .false., plots = .false. /
&body name = 'strip', mesh = 'file', file = '{strip}', velocity = 1.0, 0.0, 0.0,
  {STEEL}, poisson = 0.0, thickness = 0.01 /
&body name = 'wall', mesh = 'file', file = '{wall_m}', rotate_axis = 0.0, 1.0, 0.0,
  rotate_angle = -90.0, center = 1.00001, -0.05, -0.1, {STEEL}, poisson = 0.0, thickness = 0.01 /
&restraint body = 'wall', fix = 'all' /
&contact pairs = 'strip', 'wall' /
"""
            hh, wall = run("strip_nx%d_dt%.0e" % (nx, dt), deck)
            if hh is None:
                continue
            on = np.nonzero(hh["contacts"] > 0)[0]
            dur = hh["t"][on[-1]] - hh["t"][on[0] - 1]
            imp = hh["px"][0] - hh["px"][-1]
            m = rho * L * b * h
            err = max(abs(dur / (2 * L / c) - 1), abs(imp / dur / (rho * c * v0 * b * h) - 1),
                      abs(-hh["px"][-1] / m / v0 - 1))
            record("strip_wall", "nx=%d" % nx, dt, 2 * nx + 8, err, wall, len(hh["t"]) - 1)


def rings_deck(msh, dt, t_end):
    return f"""&run dt = {dt}, t_end = {t_end}, beta = 1.0, gamma = 1.5 /
&output interval = 1.0e-3, vtu = .false., plots = .false.,
  track = 1.0, 0.0, 0.0,   1.01, 0.0, 0.0, track_body = 'ring1', 'ring2' /
&body name = 'ring1', mesh = 'file', file = '{msh}', velocity = 10.0, 0.0, 0.0,
  {STEEL}, poisson = 0.3, thickness = 0.05 /
&body name = 'ring2', mesh = 'file', file = '{msh}', center = 2.01, 0.0, 0.0,
  {STEEL}, poisson = 0.3, thickness = 0.05 /
&contact pairs = 'ring1', 'ring2' /
"""


if "rings" in args.scenes:
    meshes = {n: mesh_cmd("ring", os.path.join(work, "ring_%d.msh" % n), radius=1, width=0.2,
                          n_around=n, n_across=1) for n in (20, 40)}
    ref, _ = run("rings_ref", rings_deck(meshes[40], 6.25e-6, 0.04))
    for n in (20, 40):
        for dt in (2e-4, 1e-4, 5e-5, 2.5e-5):
            hh, wall = run("rings_n%d_dt%.1e" % (n, dt), rings_deck(meshes[n], dt, 0.04))
            if hh is not None:
                record("two_rings", "n_around=%d" % n, dt, 4 * n, track_error(hh, ref, ["p1_x", "p2_x"]),
                       wall, len(hh["t"]) - 1)


def spheres_deck(msh, dt, t_end):
    bodies = "".join(f"""&body name = 'sphere{i + 1}', mesh = 'file', file = '{msh}',
  center = {2.01 * i}, 0.0, 0.0, velocity = {10.0 if i == 0 else 0.0}, 0.0, 0.0,
  {STEEL}, poisson = 0.3, thickness = 0.05 /
""" for i in range(3))
    return f"""&run dt = {dt}, t_end = {t_end}, beta = 1.0, gamma = 1.5 /
&output interval = 2.0e-4, vtu = .false., plots = .false.,
  track = 1.0, 0.0, 0.0,   1.01, 0.0, 0.0, track_body = 'sphere1', 'sphere2' /
{bodies}&contact pairs = 'sphere1', 'sphere2',   'sphere2', 'sphere3' /
"""


if "spheres" in args.scenes:
    meshes = {n: mesh_cmd("sphere", os.path.join(work, "sphere_%d.msh" % n), radius=1, n_div=n)
              for n in (4, 6)}
    ref, _ = run("spheres_ref", spheres_deck(meshes[6], 1.5e-6, 2e-3))
    for n in (4, 6):
        for dt in (1.2e-5, 6e-6, 3e-6):
            hh, wall = run("spheres_n%d_dt%.1e" % (n, dt), spheres_deck(meshes[n], dt, 2e-3))
            if hh is not None:
                record("three_spheres", "n_div=%d" % n, dt, 60 * n * n, track_error(hh, ref, ["p1_x", "p2_x"]),
                       wall, len(hh["t"]) - 1)

with open(os.path.join(work, "work_precision.dat"), "w") as f:
    f.write("# scene mesh dt elements error wall_s steps\n")
    for r in rows:
        f.write("%s %s %.3e %d %.4e %.3f %d\n" % r)
scenes = sorted(set(r[0] for r in rows))
plot = ["set terminal pngcairo size 1000,650 noenhanced", "set output 'work_precision.png'", "set logscale xy",
        "set xlabel 'wall time [s]'", "set ylabel 'error (strip: relative; rings, spheres: m)'",
        "set grid", "set key outside right",
        "set title 'casca: error against wall time (%d rank%s)'" % (args.ranks, "s" if args.ranks > 1 else "")]
series = []
for s in scenes:
    for mesh in sorted(set(r[1] for r in rows if r[0] == s)):
        series.append("'work_precision.dat' u (strcol(1) eq '%s' && strcol(2) eq '%s' ? $6 : 1/0):5 w lp t '%s %s'"
                      % (s, mesh, s, mesh))
plot.append("plot " + ", ".join(series))
with open(os.path.join(work, "work_precision.gp"), "w") as f:
    f.write("\n".join(plot) + "\n")
subprocess.run(["gnuplot", "work_precision.gp"], cwd=work)
print("table: %s/work_precision.dat, plot: %s/work_precision.png" % (work, work))
