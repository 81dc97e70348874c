#!/usr/bin/env python3
"""Work-precision of the three spheres over the whole scene: step, scheme and mesh (issue 18).

usage: whole_scene.py CASCA WORK_DIR [--ranks N] [--quick] [--only steps,mesh,t2] [--fresh]
                      [--mesh-run SCHEME:DT] [--meshes 4,6,8,10] [--mesh-ranks N]
                      [--t2 SCHEME:DT:N_DIV,...] [--repeat NAME,...]

The scene is examples/three_spheres.nml (sphere 1 at 10 m/s into spheres 2 and 3 at rest,
mid-surface contact, 10 ms), written out with the mesh, scheme and step changed and
`vtu = .false., plots = .false.` (history only; frames every 0.2 ms as in the deck).

Quantities, from history.dat (one row a step):
  v      each sphere's centre-of-mass velocity along x at t_end, from the pair impulses:
         v1 = v0 - I12/m, v2 = (I12 - I23)/m, v3 = I23/m (m: each body's mass as `casca check`
         prints it, the consistent mass matrix); error: the largest of the three, relative to
         the impact speed v0 = 10 m/s
  int    contact intervals of each pair: first and last step end with contacts_<pair> > 0 and
         the total time in contact (the steps ending in contact); error: the largest of the six
         (two pairs x start, end, total) relative to the reference's interval (last - first)
         of that pair
  F      peak total contact force of each pair (fcontact_<pair>); error: the larger of the
         two relative errors
  x      tracked x(t) of the four tracked points (poles on the axis) over the whole run: the
         largest distance from the reference (interpolated at the run's step ends), relative
         to the reference's peak deflection of sphere 2: max |(x3 - x2)(t) - (x3 - x2)(0)|,
         the largest change of the distance between its two poles

Runs:
  steps  n_div 6 (the thesis mesh) on 1 rank: Newmark (beta 1, gamma 1.5) at 3, 6, 12, 24,
         48 us; generalized-alpha (rho_inf 0.8) at 6, 12, 24, 48, 96 us; generalized-alpha 0.8
         with &run tolerance 1e-3, 1e-4, 1e-5 (first step and step at a contact onset 6 us);
         the cheapest run within 1% on v, int and F, again with factor_precision = 'single'
  ref6   the n_div 6 answer for dt -> 0: Richardson extrapolation of generalized-alpha's two
         finest steps (6 and 12 us) at its order 2, checked against the same of Newmark's
         (3 and 6 us) at its order 1 (their difference printed); the cheapest run (CPU time)
         within 1% on v, int and F is run again with factor_precision = 'single'
  mesh   n_div 4, 6, 8, 10 (--meshes) at one scheme and step (--mesh-run, default
         alpha:12e-6) on --mesh-ranks ranks (default 1: the answer is the same on any number;
         n_div 6 on 1 rank is then the step ladder's run); reference by Richardson in the
         element size (h ~ 1/n_div) from the three finest meshes with their observed order,
         quantity by quantity (the finest mesh, with the difference to the next as its
         uncertainty, where the three do not give an order)
  t2     on --ranks ranks (default 2): the thesis' run (Newmark 3 us, n_div 6) and the runs
         of --t2 (scheme:dt:n_div, scheme newmark or alpha), against the mesh reference
Every run records its wall time (casca's `done:` line), the load average before it, steps and
Newton iterations. Finished runs of the same deck are reused (--fresh: run again); --repeat
runs the named runs once more into NAME_r2 and prints both walls. Writes WORK_DIR/whole_scene.dat
(the table) and WORK_DIR/whole_scene.png (log-log, gnuplot; whole_scene.gp).
--quick: n_div 4 only, t_end 3 ms, five runs (a test that the script works, about a minute)."""
import argparse
import json
import os
import re
import resource
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from casca_testlib import ENV, history  # noqa: E402

ap = argparse.ArgumentParser()
ap.add_argument("casca")
ap.add_argument("work")
ap.add_argument("--ranks", type=int, default=2, help="ranks of the thesis run and the --t2 runs")
ap.add_argument("--mesh-ranks", type=int, default=1, help="ranks of the mesh ladder (the same answer on any)")
ap.add_argument("--quick", action="store_true")
ap.add_argument("--fresh", action="store_true", help="run again even where a finished run exists")
ap.add_argument("--repeat", default="", help="runs to repeat once more (comma-separated names)")
ap.add_argument("--mesh-run", default="alpha:12e-6", help="scheme:dt of the mesh ladder")
ap.add_argument("--meshes", default="4,6,8,10", help="n_div of the ladder; n_div@dt: at another step")
ap.add_argument("--t2", default="", help="runs on --ranks ranks against the mesh reference, scheme:dt:n_div,...")
ap.add_argument("--no-run", action="store_true", help="tables from the finished runs only")
ap.add_argument("--only", default="steps,mesh,t2", help="parts to run: steps, mesh, t2 (the thesis run and --t2 runs on --ranks ranks)")
args = ap.parse_args()
casca = os.path.abspath(args.casca)
work = os.path.abspath(args.work)
os.makedirs(work, exist_ok=True)
V0 = 10.0
T_END = 3e-3 if args.quick else 1e-2
PAIRS = ("sphere1_sphere2", "sphere2_sphere3")
SCHEMES = {"newmark": "beta = 1.0, gamma = 1.5", "alpha": "rho_inf = 0.8"}


def mesh(k):
    path = os.path.join(work, "sphere_%d.msh" % k)
    if not os.path.exists(path):
        subprocess.run([casca, "mesh", "sphere", "--radius", "1", "--n-div", str(k), "-o", path],
                       env=ENV, check=True, capture_output=True)
    return path


def deck(k, scheme, dt, extra=""):
    m = mesh(k)
    body = "young = 210e9, poisson = 0.3, density = 7700, thickness = 0.05"
    return f"""&run dt = {dt:.6e}, t_end = {T_END}, {scheme}{', ' + extra if extra else ''} /
&output interval = 2.0e-4, vtu = .false., plots = .false.,
  track = 1.0, 0.0, 0.0,   1.01, 0.0, 0.0,   3.01, 0.0, 0.0,   3.02, 0.0, 0.0
  track_body = 'sphere1', 'sphere2', 'sphere2', 'sphere3' /
&body name = 'sphere1', mesh = 'file', file = '{m}', velocity = 10.0, 0.0, 0.0,
  {body} /
&body name = 'sphere2', mesh = 'file', file = '{m}', center = 2.01, 0.0, 0.0,
  {body} /
&body name = 'sphere3', mesh = 'file', file = '{m}', center = 4.02, 0.0, 0.0,
  {body} /
&contact surface = 'mid', pairs = 'sphere1', 'sphere2',   'sphere2', 'sphere3' /
"""


_mass = {}


def masses(k, path):
    """the bodies' masses as `casca check` prints them (consistent mass matrix)"""
    if k not in _mass:
        p = subprocess.run([casca, "check", path], env=ENV, capture_output=True, text=True)
        ms = [float(x) for x in re.findall(r"mass\s+([0-9.Ee+-]+)\s+kg", p.stdout)]
        if len(ms) != 3:
            sys.exit("casca check %s: no masses in its output\n%s" % (path, p.stdout[-500:]))
        _mass[k] = ms
    return _mass[k]


def loadavg():
    with open("/proc/loadavg") as f:
        return float(f.read().split()[0])


def run(name, k, scheme, dt, extra="", ranks=1, fresh=False):
    """run the deck into WORK/NAME (reused when finished with the same deck); returns a dict
    with the history, wall time, load, steps and Newton iterations, or None"""
    path = os.path.join(work, name + ".nml")
    out = os.path.join(work, name)
    info = os.path.join(out, "run.json")
    text = deck(k, scheme, dt, extra)
    same = os.path.exists(path) and open(path).read() == text
    if not (same and os.path.exists(info) and not fresh and not args.fresh):
        if args.no_run:
            return None
        with open(path, "w") as f:
            f.write(text)
        cmd = [casca, "run", path, "--out", out]
        if ranks > 1:
            cmd = ["mpirun", "-np", str(ranks)] + cmd
        load = loadavg()
        t0 = time.time()
        c0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        p = subprocess.run(cmd, env=ENV, capture_output=True, text=True)
        c1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        outer = time.time() - t0
        if p.returncode != 0:
            print("%s failed (exit %d): %s" % (name, p.returncode, p.stderr[-800:]), flush=True)
            return None
        done = re.search(r"done: (\d+) steps in\s+([0-9.]+) s", p.stdout)
        timing = re.search(r"^time: .*$", p.stdout, re.M)
        os.makedirs(out, exist_ok=True)
        with open(info, "w") as f:
            json.dump({"wall": float(done.group(2)) if done else outer, "outer": outer,
                       "cpu": (c1.ru_utime + c1.ru_stime) - (c0.ru_utime + c0.ru_stime),
                       "load": load, "load_after": loadavg(), "ranks": ranks,
                       "when": time.strftime("%Y-%m-%d %H:%M:%S"),
                       "time_line": timing.group(0) if timing else ""}, f)
    with open(info) as f:
        r = json.load(f)
    h = history(out)
    r.update(name=name, k=k, scheme=scheme, dt=dt, extra=extra, h=h, steps=len(h["t"]) - 1,
             newton=int(np.sum(h["newton"])), mass=masses(k, path))
    print("%-22s n_div %2d  %-40s ranks %d  steps %5d  newton %6d  wall %7.1f s  cpu %7.1f s  load %.2f"
          % (name, k, (scheme + " " + extra).strip(), ranks, r["steps"], r["newton"], r["wall"], r.get("cpu", np.nan),
             r["load"]),
          flush=True)
    return r


def quantities(r):
    """the scalars of a run (velocities, contact intervals, peak forces) and x(t)"""
    h = r["h"]
    t = h["t"]
    m1, m2, m3 = r["mass"]
    i12, i23 = h["impulse_" + PAIRS[0]][-1], h["impulse_" + PAIRS[1]][-1]
    q = {"v1": V0 - i12 / m1, "v2": (i12 - i23) / m2, "v3": i23 / m3}
    dts = np.diff(t)
    for p in PAIRS:
        on = h["contacts_" + p] > 0
        k = np.nonzero(on)[0]
        q["start_" + p] = t[k[0]] if len(k) else np.nan
        q["end_" + p] = t[k[-1]] if len(k) else np.nan
        q["total_" + p] = np.sum(dts[on[1:]])
        q["F_" + p] = np.max(h["fcontact_" + p])
    q["t"] = t
    q["x"] = np.stack([h["p%d_x" % i] for i in range(1, 5)]).T
    return q


SCALARS = ["v1", "v2", "v3"] + ["%s_%s" % (a, p) for p in PAIRS for a in ("start", "end", "total", "F")]


def extrapolate(fine, coarse, factor):
    """Richardson: fine + (fine - coarse) / factor, factor = r^p - 1; x(t) on fine's times"""
    e = {s: fine[s] + (fine[s] - coarse[s]) / factor for s in SCALARS}
    xc = np.stack([np.interp(fine["t"], coarse["t"], coarse["x"][:, i]) for i in range(4)]).T
    e["t"] = fine["t"]
    e["x"] = fine["x"] + (fine["x"] - xc) / factor
    return e


def deflection(q):
    d = q["x"][:, 2] - q["x"][:, 1]
    return np.max(np.abs(d - d[0]))


def errors(q, ref):
    """relative errors (v, int, F, x) of quantities q against the reference"""
    ev = max(abs(q[s] - ref[s]) for s in ("v1", "v2", "v3")) / V0
    ei, ef = 0.0, 0.0
    for p in PAIRS:
        if not ref["F_" + p] > 0:      # (a pair that never touches in the reference: --quick)
            continue
        length = ref["end_" + p] - ref["start_" + p]
        ei = max([ei] + [abs(q[a + "_" + p] - ref[a + "_" + p]) / length for a in ("start", "end", "total")])
        ef = max(ef, abs(q["F_" + p] - ref["F_" + p]) / ref["F_" + p])
    xr = np.stack([np.interp(q["t"], ref["t"], ref["x"][:, i]) for i in range(4)]).T
    ex = np.max(np.abs(q["x"] - xr)) / deflection(ref)
    return ev, ei, ef, ex


def x_distance(a, b):
    """largest distance of x(t) between two runs, on a's times, in metres"""
    xb = np.stack([np.interp(a["t"], b["t"], b["x"][:, i]) for i in range(4)]).T
    return np.max(np.abs(a["x"] - xb))


def show_values(label, q):
    print("  %-26s v %.4f %.4f %.4f m/s | 1-2: %.4f-%.4f ms (%.4f) F %.3f MN | 2-3: %.4f-%.4f ms (%.4f) F %.3f MN | defl %.3f mm"
          % (label, q["v1"], q["v2"], q["v3"],
             1e3 * q["start_" + PAIRS[0]], 1e3 * q["end_" + PAIRS[0]], 1e3 * q["total_" + PAIRS[0]], 1e-6 * q["F_" + PAIRS[0]],
             1e3 * q["start_" + PAIRS[1]], 1e3 * q["end_" + PAIRS[1]], 1e3 * q["total_" + PAIRS[1]], 1e-6 * q["F_" + PAIRS[1]],
             1e3 * deflection(q)), flush=True)


rows = []   # (part, name, n_div, scheme, dt/tol, ranks, steps, newton, wall, load, ev, ei, ef, ex)


def label(r):
    if "tolerance" in r["extra"]:
        return "alpha0.8 tol", re.search(r"tolerance = ([0-9.e+-]+)", r["extra"]).group(1)
    s = "newmark" if "beta" in r["scheme"] else "alpha0.8"
    if "single" in r["extra"]:
        s += " single"
    return s, "%.3g us" % (r["dt"] * 1e6)


def record(part, r, ref, series="ladder"):
    e = errors(quantities(r), ref)
    s, d = label(r)
    rows.append((part, r["name"], r["k"], s, d, r["ranks"], r["steps"], r["newton"], r["wall"], r.get("cpu", np.nan),
                 r["load"]) + e + (series,))


def print_table(part):
    print("\n| run | n_div | scheme | dt / tol | ranks | steps | Newton | wall [s] | CPU [s] | load | v | int | F | x(t) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for row in rows:
        if row[0] == part:
            print("| %s | %d | %s | %s | %d | %d | %d | %.1f | %.1f | %.2f | %.2g%% | %.2g%% | %.2g%% | %.2g%% |"
                  % (row[1:11] + tuple(100 * v for v in row[11:15])))
    print(flush=True)


def orders(series, ref):
    """observed orders between successive halvings of one ladder, per error measure"""
    out = []
    errs = [errors(quantities(r), ref) for r in series]
    for a, b in zip(errs, errs[1:]):
        out.append(tuple(np.log(y / x) / np.log(2) if x > 0 and y > 0 else np.nan for x, y in zip(a, b)))
    return out


def mesh_order(h, q):
    """order p from three meshes of sizes h (coarse to fine) and values q (None: inconsistent)"""
    d1, d2 = q[0] - q[1], q[1] - q[2]
    if d1 == 0 or d2 == 0 or d1 * d2 < 0:
        return None
    ratio = d1 / d2

    def f(p):
        return (h[0] ** p - h[1] ** p) / (h[1] ** p - h[2] ** p) - ratio
    lo, hi = 0.05, 12.0
    if f(lo) * f(hi) > 0:
        return None
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if f(lo) * f(mid) <= 0:
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


# ---------------------------------------------------------------- step ladder, n_div 6, 1 rank
K0 = 4 if args.quick else 6
ref6 = None
step_runs = []
if "steps" in args.only:
    if args.quick:
        ladders = {"newmark": [24e-6, 48e-6], "alpha": [48e-6]}
        tols = [1e-4]
    else:
        ladders = {"newmark": [3e-6, 6e-6, 12e-6, 24e-6, 48e-6], "alpha": [6e-6, 12e-6, 24e-6, 48e-6, 96e-6]}
        tols = [1e-3, 1e-4, 1e-5]
    runs = {}
    for s, dts in ladders.items():
        runs[s] = [r for r in (run("%s_%d_%g" % (s, K0, dt * 1e6), K0, SCHEMES[s], dt) for dt in dts) if r]
    adaptive = [r for r in (run("tol_%d_%g" % (K0, tol), K0, SCHEMES["alpha"], 6e-6, "tolerance = %g" % tol)
                            for tol in tols) if r]
    nm = [quantities(r) for r in runs["newmark"]]
    al = [quantities(r) for r in runs["alpha"]]
    ref_nm = extrapolate(nm[0], nm[1], 1.0)                     # order 1: 2 q(dt) - q(2 dt)
    ref_al = extrapolate(al[0], al[1], 3.0) if len(al) > 1 else al[0]   # order 2
    ref6 = ref_al    # Newmark's peak force converges below order 1 (see the values): the check
    print("\nn_div %d, values (the two references are Richardson extrapolations):" % K0)
    for r, q in zip(runs["newmark"], nm):
        show_values(r["name"], q)
    for r, q in zip(runs["alpha"], al):
        show_values(r["name"], q)
    for r in adaptive:
        show_values(r["name"], quantities(r))
    show_values("ref Newmark (order 1)", ref_nm)
    show_values("ref alpha (order 2)", ref_al)
    print("the two references apart: v %.2g%%, int %.2g%%, F %.2g%%, x(t) %.2g%% (errors of ref Newmark against ref alpha)"
          % tuple(100 * e for e in errors(ref_nm, ref_al)))
    step_runs = runs["newmark"] + runs["alpha"] + adaptive
    for r in step_runs:
        record("steps", r, ref6)
    # the cheapest run within 1% on v, int and F, again with single-precision factors
    ok = [row for row in rows if row[0] == "steps" and max(row[11:14]) <= 0.01]
    best = min(ok, key=lambda row: row[9]) if ok else None     # (by CPU time: the wall is the load's)
    if best and not args.quick:
        b = next(r for r in runs["newmark"] + runs["alpha"] + adaptive if r["name"] == best[1])
        rs = run(b["name"] + "_single", K0, b["scheme"], b["dt"],
                 (b["extra"] + ", " if b["extra"] else "") + "factor_precision = 'single'")
        if rs:
            record("steps", rs, ref6)
            step_runs.append(rs)
    print_table("steps")
    print("observed orders in dt (v, int, F, x(t)), successive halvings:")
    for s in runs:
        for (a, b), o in zip(zip(runs[s], runs[s][1:]), orders(runs[s], ref6)):
            print("  %-8s %s -> %s: %s" % (s, label(b)[1], label(a)[1], "  ".join("%.2f" % v for v in o)))
    # orders of x(t) from the runs alone (no reference): distance of successive pairs
    for s in runs:
        qs = [quantities(r) for r in runs[s]]
        d = [x_distance(a, b) for a, b in zip(qs, qs[1:])]
        print("  %-8s x(t) distance between successive steps [mm]: %s; orders %s"
              % (s, " ".join("%.3g" % (1e3 * v) for v in d),
                 " ".join("%.2f" % (np.log(b / a) / np.log(2)) for a, b in zip(d, d[1:]))))

# ---------------------------------------------------------------- mesh ladder and the 2-rank runs
def mesh_name(s, k, dt, ranks):
    return "%s_%d_%g" % (s, k, dt * 1e6) + ("_np%d" % ranks if ranks > 1 else "")


if "mesh" in args.only or "t2" in args.only:
    s, dt = args.mesh_run.split(":")
    dt = float(dt)
    # n_div, or n_div@dt for a mesh run at another step than --mesh-run's
    ks = [(4, dt)] if args.quick else [(int(k.split("@")[0]), float(k.split("@")[1]) if "@" in k else dt)
                                       for k in args.meshes.split(",")]
    ladder = [r for r in (run(mesh_name(s, k, dk, args.mesh_ranks), k, SCHEMES[s], dk, ranks=args.mesh_ranks)
                          for k, dk in ks) if r]
    ladder.sort(key=lambda r: r["k"])
    extra = []
    if "t2" in args.only and not args.quick:
        thesis = run("thesis_6_np%d" % args.ranks, 6, SCHEMES["newmark"], 3e-6, ranks=args.ranks)
        if thesis:
            extra.append(thesis)
        for spec in filter(None, args.t2.split(",")):
            s2, dt2, k2 = spec.split(":")
            r = run(mesh_name(s2, int(k2), float(dt2), args.ranks), int(k2), SCHEMES[s2], float(dt2),
                    ranks=args.ranks)
            if r:
                extra.append(r)
    qs = [quantities(r) for r in ladder]
    print("\nmesh ladder (%s, at %g us unless its name says otherwise), values:" % (s, dt * 1e6))
    for r, q in zip(ladder, qs):
        show_values("%s (%d elements)" % (r["name"], 20 * r["k"] ** 2), q)
    for r in extra:
        show_values(r["name"], quantities(r))
    if len(ladder) >= 3:
        hs = [1.0 / r["k"] for r in ladder[-3:]]
        refm = dict(t=qs[-1]["t"])
        print("observed orders in the element size (three finest meshes) and the extrapolated values:")
        for name in SCALARS:
            p = mesh_order(hs, [q[name] for q in qs[-3:]])
            # the order of the three coarser meshes must agree (within a quarter), else the
            # ladder is not in its asymptotic range and Richardson is not used
            pc = mesh_order([1.0 / r["k"] for r in ladder[-4:-1]], [q[name] for q in qs[-4:-1]]) \
                if len(ladder) >= 4 else p
            if p is not None and (pc is None or abs(pc - p) > 0.25 * p):
                print("  %-24s orders %.2f (three finest) and %s (three coarsest) disagree"
                      % (name, p, "none" if pc is None else "%.2f" % pc))
                p = None
            if p is None:
                refm[name] = qs[-1][name]
                print("  %-24s no consistent order (%s): finest %.5g, uncertainty %.2g"
                      % (name, " ".join("%.5g" % q[name] for q in qs), qs[-1][name], abs(qs[-1][name] - qs[-2][name])))
            else:
                refm[name] = qs[-1][name] + (qs[-1][name] - qs[-2][name]) / ((hs[1] / hs[2]) ** p - 1)
                print("  %-24s order %.2f: %s -> %.5g (finest %.2g%% from it)"
                      % (name, p, " ".join("%.5g" % q[name] for q in qs), refm[name],
                         100 * abs(qs[-1][name] - refm[name]) / max(abs(refm[name]), 1e-30)))
        # x(t): the same extrapolation at the order of sphere 2's peak deflection, if any
        dfl = [deflection(q) for q in qs[-3:]]
        p = mesh_order(hs, dfl)
        if len(ladder) >= 4:
            pc = mesh_order([1.0 / r["k"] for r in ladder[-4:-1]], [deflection(q) for q in qs[-4:-1]])
            if p is not None and (pc is None or abs(pc - p) > 0.25 * p):
                p = None
        if p is None:
            refm["x"] = qs[-1]["x"]
            print("  x(t): the peak deflections %s give no order: the finest mesh's x(t)" % " ".join("%.4g" % d for d in dfl))
        else:
            refm["x"] = extrapolate(qs[-1], qs[-2], (hs[1] / hs[2]) ** p - 1)["x"]
            print("  x(t): extrapolated at the peak deflection's order %.2f" % p)
        show_values("reference (mesh)", refm)
        print("the finest mesh against the reference: v %.2g%%, int %.2g%%, F %.2g%%, x(t) %.2g%%"
              % tuple(100 * e for e in errors(qs[-1], refm)))
        names = set(r["name"] for r in ladder + extra)
        for r in ladder:
            record("mesh", r, refm, "ladder")
        for r in extra:
            record("mesh", r, refm, "ranks%d" % r["ranks"])
        for r in step_runs:
            if r["name"] not in names:
                record("mesh", r, refm, "n_div%d" % r["k"])
        print_table("mesh")


def cheapest(part, what):
    """for each error measure and 10%, 3%, 1%: the 1-rank run of least CPU time within it"""
    print("\ncheapest 1-rank run (CPU time) within 10%%, 3%%, 1%% against %s:" % what)
    for i, name in enumerate(("v", "int", "F", "x(t)")):
        line = []
        for level in (0.1, 0.03, 0.01):
            ok = [row for row in rows if row[0] == part and row[5] == 1 and row[11 + i] <= level
                  and max(row[11:15]) > 0]      # (not the reference run itself)
            best = min(ok, key=lambda row: row[9]) if ok else None
            line.append("%g%%: %s" % (100 * level, "none measured" if best is None else "%s (n_div %d, %s %s, %d rank%s, CPU %.0f s, wall %.0f s, %.2g%%)"
                        % (best[1], best[2], best[3], best[4], best[5], "s" if best[5] > 1 else "", best[9], best[8], 100 * best[11 + i])))
        print("  %-5s %s" % (name, "; ".join(line)))


if any(row[0] == "steps" for row in rows):
    cheapest("steps", "the n_div %d answer for dt -> 0" % K0)
if any(row[0] == "mesh" for row in rows):
    cheapest("mesh", "the finest mesh / the mesh-extrapolated answer")

# ---------------------------------------------------------------- repeats
for name in filter(None, args.repeat.split(",")):
    info = json.load(open(os.path.join(work, name, "run.json")))
    path = os.path.join(work, name + "_r2.nml")
    out = os.path.join(work, name + "_r2")
    with open(path, "w") as f:
        f.write(open(os.path.join(work, name + ".nml")).read())
    cmd = [casca, "run", path, "--out", out]
    if info["ranks"] > 1:
        cmd = ["mpirun", "-np", str(info["ranks"])] + cmd
    load = loadavg()
    c0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.run(cmd, env=ENV, capture_output=True, text=True)
    c1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    done = re.search(r"done: (\d+) steps in\s+([0-9.]+) s", p.stdout)
    wall = float(done.group(2)) if done else float("nan")
    cpu = (c1.ru_utime + c1.ru_stime) - (c0.ru_utime + c0.ru_stime)
    same = "failed"
    if p.returncode == 0:
        h1, h2 = history(out), history(os.path.join(work, name))
        same = "different steps"
        if len(h1["t"]) == len(h2["t"]):
            same = "same steps, tracked x within %.2g m" % max(np.max(np.abs(h1["p%d_x" % i] - h2["p%d_x" % i]))
                                                               for i in range(1, 5))
    with open(os.path.join(work, "repeats.txt"), "a") as f:
        f.write("%s %s wall %.1f s cpu %.1f s load %.2f | first: wall %.1f s cpu %.1f s load %.2f | %s\n"
                % (time.strftime("%Y-%m-%d %H:%M:%S"), name, wall, cpu, load, info["wall"], info.get("cpu", np.nan),
                   info["load"], same))
    print("repeat %-22s wall %.1f s, CPU %.1f s (load %.2f) against %.1f s, CPU %.1f s (load %.2f) first; %s"
          % (name, wall, cpu, load, info["wall"], info.get("cpu", np.nan), info["load"], same), flush=True)

# ---------------------------------------------------------------- table and plot
if not rows:
    sys.exit(0)
with open(os.path.join(work, "whole_scene.dat"), "w") as f:
    f.write("# part run n_div scheme dt_or_tol ranks steps newton wall_s cpu_s load err_v err_int err_F err_x series\n")
    for row in rows:
        f.write("%s %s %d %s %s %d %d %d %.2f %.2f %.2f %.4e %.4e %.4e %.4e %s\n"
                % ((row[0], row[1], row[2], '"%s"' % row[3], '"%s"' % row[4]) + row[5:]))
gp = os.path.join(work, "whole_scene.gp")
with open(gp, "w") as f:
    f.write("""set terminal pngcairo size 1100,850 font ",10"
set output 'whole_scene.png'
set multiplot layout 2,2 title "three spheres, whole scene (10 ms): error against CPU time (1 rank unless marked)"
set logscale xy
set grid
set format y "%g"
set xlabel "CPU time [s]"
f = 'whole_scene.dat'
do for [c in "12 13 14 15"] {
  n = c + 0
  if (n == 12) { set key top right font ",8"; set yrange [1e-5:3] } else { unset key; set autoscale y }
  set ylabel (n == 12 ? "velocities (of 10 m/s)" : n == 13 ? "contact intervals" : n == 14 ? "peak force" : "x(t) (of peak deflection)")
  plot 0.01 w l dt 2 lc rgb "gray" t "1%", \\
       f u (strcol(1) eq "steps" && strstrt(strcol(4), "newmark") == 1 ? $10 : 1/0):n w lp pt 7 lc 1 t "n\\\\_div 6, Newmark 1, 1.5 (vs its dt->0)", \\
       f u (strcol(1) eq "steps" && strcol(4) eq "alpha0.8" ? $10 : 1/0):n w lp pt 5 lc 2 t "n\\\\_div 6, gen-alpha 0.8 (vs its dt->0)", \\
       f u (strcol(1) eq "steps" && strcol(4) eq "alpha0.8 tol" ? $10 : 1/0):n w lp pt 9 lc 3 t "n\\\\_div 6, gen-alpha 0.8 with tolerance", \\
       f u (strcol(1) eq "steps" && strstrt(strcol(4), "single") > 0 ? $10 : 1/0):n w p pt 3 ps 2 lc 4 t "n\\\\_div 6, single-precision factors", \\
       f u (strcol(1) eq "mesh" && strcol(16) eq "ladder" ? $10 : 1/0):n w lp pt 13 ps 1.5 lc 7 t "mesh ladder 4..12 (vs n\\\\_div 12)", \\
       f u (strcol(1) eq "mesh" && strstrt(strcol(16), "ranks") == 1 ? $10 : 1/0):n w p pt 11 ps 2 lc 6 t "2 ranks (vs n\\\\_div 12)", \\
       f u (strcol(1) eq "mesh" && strstrt(strcol(16), "n_div") == 1 ? $10 : 1/0):n w p pt 1 lc rgb "gray" t "n\\\\_div 6 runs (vs n\\\\_div 12)"
}
unset multiplot
""")
if subprocess.run(["gnuplot", "whole_scene.gp"], cwd=work).returncode == 0:
    print("table: %s/whole_scene.dat, plot: %s/whole_scene.png" % (work, work))
