"""Named node sets from Gmsh physical groups, and the consistent edge load (issue 17).

usage: test_sets_loads.py CASCA EXAMPLES_DIR DATA_DIR WORK_DIR

The mesh files are tests/data/strip_sets_v41.msh and strip_sets_v22.msh (written by
tests/data/make_strip_sets.py): the 10 x 1 cantilever strip of examples/cantilever.nml with the
physical groups 'clamped' (4-node line at x = 0), 'tip' (4-node line at x = 10) and 'strip'
(the surface).

sets      examples/cantilever.nml on the file mesh, clamped by set = 'clamped' and loaded by
          set = 'tip', against the same deck with the shipped boxes (box_max x = 0, box_min
          x = 10): the tracked tip displacement (x, z) at P = 4 is the same to 1e-12 relative,
          for the MSH 4.1 and the MSH 2.2 file (the set and the box select the same nodes, so
          the two runs are the same computation).
gmsh      the same for a file Gmsh itself wrote: tests/data/gmsh_tri10_v22.msh (a closed
          cylinder's wall, radius 1, z in [-0.5, 0.5], saved through its physical groups
          'wall' and 'rims', the rims as 4-node lines) clamped by set = 'rims' vs by two boxes
          z <= -0.5 + 1e-9 and z >= 0.5 - 1e-9, statics under a radial point load at mid-height:
          the loaded point's displacement is the same to 1e-12 relative (the file's rims are
          2 x 11 cubic lines, 66 nodes, all at z = +-0.5: a node missed or added by the set
          would change the answer).
missing   set = 'tp' in &load: exit 2, and the message names the deck file and the line of
          the &load group, the group, the set and the body's groups:
          "FILE:LINE: &load: set 'tp' is not a physical group of body 'strip' (its groups:
          clamped, tip, strip)".
edge      cantilever.nml with kind = 'edge' on the tip: Sze, Liu & Lo (2004), Finite Elements
          in Analysis and Design 40, 1551-1569, test 3.1, last row of the table (P/P_max = 1):
          W_tip = 6.698, -U_tip = 3.286 (the figures test_robustness.py cites, as reproduced in
          MBDyn's tests/plates/sze2004/sze31/sze31_ref.dat); bound 1% (Sze's 16 x 1 S4R
          solution; the elastica is within 0.1% of it). The difference from the equal shares
          (kind = 'nodal', the shipped deck) is printed, not asserted.
patch     the membrane patch test of the edge load: the strip (nu = 0) clamped at x = 0 and
          pulled along x by F = 1.2 N as kind = 'edge' on set 'tip' (sigma = F/(b h) = 12 Pa,
          sigma/E = 1e-5), one load step, newton_tol 1e-14. A uniform traction gives a uniform
          uniaxial state, which the cubic elements hold exactly; the material is Saint-Venant-
          Kirchhoff (nu = 0: lambda = 0, no lateral or thickness strain), so the stretch
          l = 1 + e solves E e (1 + e/2)(1 + e) = sigma (first Piola stress of a dead load):
          e = 0.99998500040e-5. Each of the 4 tip nodes must move by e L, to 1e-8 relative
          (the equal shares of kind = 'nodal' miss this by 4.5% at the corners: printed).
sum       the nodal forces of an edge load add up to the given force: a free strip (no
          restraint, no gravity, trapezoidal Newmark beta 1/4, gamma 1/2) under an edge load
          F = (0, 0, 0.5) N on set 'tip': from step 1 to step N its linear momentum changes by
          F (t_N - t_1), to 1e-12 relative (the internal forces sum to zero; every step adds
          dt times the total dead load). The shares are one scalar per node, so the z
          component checks their sum for every direction. px and py stay below 1e-8 of pz: the
          in-plane momentum balance of a free strip holds to about 3e-9 only (so an in-plane
          force is not used for the 1e-12 check), equally for kind = 'nodal': a property of
          the solve, not of the load.
gravity   per-body gravity (&body gravity, added to &run's): two free rings 10 m apart (no
          contact between them), ring 'a' thrown at 1 m/s along x with its own gravity
          (0, -9.81, 0), ring 'b' at rest with none, thesis Newmark, 100 steps: the momentum
          changes by m_a g t along y (m_a = px(0) / 1 m/s) to 1e-10 relative (a constant force
          on a free body, from its first step: gravity's start acceleration), and ring 'b'
          never moves (kinetic_b = 0 at every step).
torque    a moment load (&load moment; the shipped examples/rollup.nml, Sze's cantilever rolled
          up, is test_robustness.py's): a free strip (1 x 0.1, h 0.01, steel; no restraint)
          under an end moment M = 50 N m
          about y (kind = 'edge'), implicit midpoint rule (rho_inf = 1), 200 steps of 1e-4 s: no
          other load acts, so its angular momentum is M t (dL/dt = M) at every step, to 1e-6 of
          M t_end, with the linear momentum zero (1e-6 N s) and Lx, Lz within 1e-4 of M t_end
          (the moment turns the fibres about y; where the strip's triangles, not symmetric
          about its centre line, tilt a fibre off the xz plane, the torque it takes has a part
          along the fibre: measured 1.5e-6);
          the energy balance kinetic + strain - work stays at its start within 1e-3 of the
          moment's work (the midpoint rule's drift under a nonlinear load; measured 1.6e-5).
          The same deck with the moment (0, 50, 3) N m, 6% of it along the strip's normal z:
          exit 2, the message names the deck's line of the &load and the word drilling. And
          `casca check` of it under the thesis' Newmark (no rho_inf) warns that the fibres
          start at the acceleration of their rotary inertia; with rho_inf it does not.
"""

import os
import re
import sys

from casca_testlib import Checks, deck_variant, history, run

casca, examples, data, work = [os.path.abspath(a) for a in sys.argv[1:5]]
os.makedirs(work, exist_ok=True)
ck = Checks()
SZE_W, SZE_U = 6.698, 3.286


def run_deck(name, text):
    """Write text to WORK/name.nml and run it; returns (history or None, process)."""
    deck = os.path.join(work, name + ".nml")
    with open(deck, "w") as f:
        f.write(text)
    p = run([casca, "run", deck, "--out", os.path.join(work, name), "-q"])
    h = history(os.path.join(work, name)) if p.returncode == 0 else None
    return h, p, deck


def cantilever(mesh_file, restraint, load):
    """examples/cantilever.nml on mesh_file, with restraint and load selections replaced."""
    src = deck_variant(os.path.join(examples, "cantilever.nml"), os.path.join(work, "cantilever_src.nml"))
    text = open(src).read()
    text = re.sub(r"mesh = 'strip'.*?ny = 1",
                  "mesh = 'file', file = '%s'" % os.path.join(data, mesh_file), text)
    text = text.replace("box_max = 0.0, 1e9, 1e9", restraint)
    text = text.replace("box_min = 10.0, -1e9, -1e9", load)
    text = text.replace("&output\n", "&output\n  vtu = .false., plots = .false.\n")
    return text


BOX_R, BOX_L = "box_max = 0.0, 1e9, 1e9", "box_min = 10.0, -1e9, -1e9"

# sets
for ver in ("v41", "v22"):
    f = "strip_sets_%s.msh" % ver
    hb, pb, _ = run_deck("box_" + ver, cantilever(f, BOX_R, BOX_L))
    hs, ps, _ = run_deck("set_" + ver, cantilever(f, "set = 'clamped'", "set = 'tip'"))
    ck.record("sets %s: box deck runs (exit 0)" % ver, pb.returncode == 0, pb.stderr[-300:])
    ck.record("sets %s: set deck runs (exit 0)" % ver, ps.returncode == 0, ps.stderr[-300:])
    if hb is not None and hs is not None:
        ck.close("sets %s: tip z by set vs by box" % ver, hs["p1_z"][-1], hb["p1_z"][-1], 1e-12)
        ck.close("sets %s: tip x by set vs by box" % ver, hs["p1_x"][-1], hb["p1_x"][-1], 1e-12)

# gmsh
CYL = """&run analysis = 'static', load_steps = 2 /
&output vtu = .false., plots = .false., track = 1.0, 0.0, 0.0 /
&body name = 'cyl', mesh = 'file', file = '%s'
  young = 1e6, poisson = 0.3, density = 1.0, thickness = 0.02 /
%s
&load body = 'cyl', box_min = 0.999, -0.05, -0.05, box_max = 1.001, 0.05, 0.05, force = -0.01, 0.0, 0.0 /
""" % (os.path.join(data, "gmsh_tri10_v22.msh"), "%s")
hs, ps, _ = run_deck("gmsh_set", CYL % "&restraint body = 'cyl', set = 'rims' /")
hb, pb, _ = run_deck("gmsh_box", CYL % ("&restraint body = 'cyl', box_max = 9, 9, -0.499999999 /\n"
                                        "&restraint body = 'cyl', box_min = -9, -9, 0.499999999 /"))
ck.record("gmsh: set deck runs (exit 0)", ps.returncode == 0, ps.stderr[-300:])
ck.record("gmsh: box deck runs (exit 0)", pb.returncode == 0, pb.stderr[-300:])
if hs is not None and hb is not None:
    ck.close("gmsh: loaded point x by set 'rims' vs by boxes", hs["p1_x"][-1], hb["p1_x"][-1], 1e-12)
    ck.record("gmsh: the load moves the point (x < 1)", hs["p1_x"][-1] < 1.0, "%.10g" % hs["p1_x"][-1])

# missing
text = cantilever("strip_sets_v41.msh", "set = 'clamped'", "set = 'tp'")
_, p, deck = run_deck("missing", text)
line = 1 + next(i for i, l in enumerate(text.splitlines()) if "set = 'tp'" in l)   # (the key's line)
want = "%s:%d: &load: set 'tp' is not a physical group of body 'strip' (its groups: clamped, tip, strip)" \
    % (deck, line)
ck.record("missing: exit 2", p.returncode == 2, "exit %d" % p.returncode)
ck.record("missing: message names file, line, group, set and groups", want in p.stderr,
          "wanted %r in %r" % (want, p.stderr[-400:]))
ck.record("missing: no backtrace", "Backtrace" not in p.stderr and "Error termination" not in p.stderr)

# edge
he, pe, _ = run_deck("edge", cantilever("strip_sets_v41.msh", BOX_R, BOX_L + ", kind = 'edge'"))
hn, pn, _ = run_deck("nodal", cantilever("strip_sets_v41.msh", BOX_R, BOX_L))
ck.record("edge: runs (exit 0)", pe.returncode == 0, pe.stderr[-300:])
if he is not None:
    ck.close("edge: load factor at the end", he["t"][-1], 1.0, 1e-12)
    ck.close("edge: tip W at P = 4 vs Sze et al. 2004 (6.698)", he["p1_z"][-1], SZE_W, 0.01)
    ck.close("edge: tip -U at P = 4 vs Sze et al. 2004 (3.286)", 10.0 - he["p1_x"][-1], SZE_U, 0.01)
    if hn is not None:
        for key, label in (("p1_z", "W"), ("p1_x", "x")):
            print("INFO edge vs equal shares: tip %s %.10g (edge) vs %.10g (nodal), difference %.3g "
                  "(%.3g%%)" % (label, he[key][-1], hn[key][-1], he[key][-1] - hn[key][-1],
                                100 * (he[key][-1] - hn[key][-1]) / he[key][-1]))
        print("INFO edge vs Sze: W off by %.3g%%, -U off by %.3g%%; nodal vs Sze: W off by %.3g%%, "
              "-U off by %.3g%%" % (100 * (he["p1_z"][-1] / SZE_W - 1), 100 * ((10 - he["p1_x"][-1]) / SZE_U - 1),
                                   100 * (hn["p1_z"][-1] / SZE_W - 1), 100 * ((10 - hn["p1_x"][-1]) / SZE_U - 1)))

# patch
def stretch(sig_over_e):
    """e with e (1 + e/2)(1 + e) = sigma/E (Newton from e = sigma/E)."""
    e = sig_over_e
    for _ in range(50):
        e -= (e * (1 + e) * (1 + e / 2) - sig_over_e) / ((1 + e) * (1 + e / 2) + e * (1 + e / 2) + e * (1 + e) / 2)
    return e


PATCH = """&run analysis = 'static', load_steps = 1, newton_tol = 1e-14 /
&output vtu = .false., plots = .false.,
  track = 10,0,0, 10,0.3333333333333333,0, 10,0.6666666666666666,0, 10,1,0 /
&body name = 'strip', mesh = 'file', file = '%s'
  young = 1.2e6, poisson = 0.0, density = 1.0, thickness = 0.1 /
&restraint body = 'strip', set = 'clamped', fix = 'clamped' /
&load body = 'strip', set = 'tip', kind = '%s', force = 1.2, 0.0, 0.0 /
""" % (os.path.join(data, "strip_sets_v41.msh"), "%s")
u_exact = 10.0 * stretch(1.2 / (1.0 * 0.1) / 1.2e6)
for kind in ("edge", "nodal"):
    hp, pp, _ = run_deck("patch_" + kind, PATCH % kind)
    ck.record("patch %s: runs (exit 0)" % kind, pp.returncode == 0, pp.stderr[-300:])
    if hp is None:
        continue
    for i, y in enumerate(("0", "1/3", "2/3", "1")):
        u = hp["p%d_x" % (i + 1)][-1] - 10.0
        if kind == "edge":
            ck.close("patch edge: tip node y = %s stretch vs SVK uniaxial e L" % y, u, u_exact, 1e-8)
        else:
            print("INFO patch nodal (equal shares): tip node y = %s moves %.10g, %.3g%% from e L"
                  % (y, u, 100 * (u / u_exact - 1)))

# sum
FZ = 0.5
free = """&run analysis = 'dynamic', dt = 1e-3, t_end = 5e-3, beta = 0.25, gamma = 0.5, newton_tol = 1e-12 /
&output vtu = .false., plots = .false. /
&body name = 'strip', mesh = 'file', file = '%s'
  young = 1.2e6, poisson = 0.0, density = 1.0, thickness = 0.1 /
&load body = 'strip', set = 'tip', kind = 'edge', force = 0.0, 0.0, %r /
&contact enabled = .false. /
""" % (os.path.join(data, "strip_sets_v22.msh"), FZ)
hf, pf, _ = run_deck("sum", free)
ck.record("sum: free strip runs (exit 0)", pf.returncode == 0, pf.stderr[-300:])
if hf is not None:
    ck.close("sum: pz(t_N) - pz(t_1) vs Fz (t_N - t_1)", hf["pz"][-1] - hf["pz"][1],
             FZ * (hf["t"][-1] - hf["t"][1]), 1e-12)
    ck.le("sum: max |px|, |py| / |pz(t_N)|", max(abs(hf["px"]).max(), abs(hf["py"]).max()) / abs(hf["pz"][-1]),
          1e-8)

# --- per-body gravity
h = None
gdeck = os.path.join(work, "body_gravity.nml")
with open(gdeck, "w") as f:
    f.write("""&run dt = 1e-4, t_end = 1e-2 /
&output vtu = .false., plots = .false. /
&body name = 'a', mesh = 'ring', radius = 0.5, width = 0.1, n_around = 12, young = 210e9,
  density = 7700, thickness = 0.02, velocity = 1.0, 0.0, 0.0, gravity = 0.0, -9.81, 0.0 /
&body name = 'b', mesh = 'ring', radius = 0.5, width = 0.1, n_around = 12, young = 210e9,
  density = 7700, thickness = 0.02, center = 10.0, 0.0, 0.0 /
""")
gout = os.path.join(work, "body_gravity")
p = run([casca, "run", gdeck, "--out", gout, "-q"])
ck.record("gravity: runs (exit 0)", p.returncode == 0, p.stderr[-300:])
if p.returncode == 0:
    hg = history(gout)
    m_a = hg["px"][0] / 1.0
    ck.close("gravity: momentum change along y [N s] vs -m_a g t", hg["py"][-1] - hg["py"][0],
             -m_a * 9.81 * hg["t"][-1], 1e-10)
    ck.le("gravity: largest kinetic energy of ring b [J]", hg["kinetic_b"].max(), 0.0)

# --- a moment on a free body: dL/dt = M
MOM, T_END = 50.0, 0.02
ht, pt, _ = run_deck("torque", """&run dt = 1e-4, t_end = %g, rho_inf = 1.0 /
&output vtu = .false., plots = .false. /
&body name = 'strip', mesh = 'strip', lx = 1.0, ly = 0.1, nx = 8, ny = 1
  young = 2.0e11, poisson = 0.3, density = 7800.0, thickness = 0.01 /
&load body = 'strip', box_min = 1.0, -1e9, -1e9, kind = 'edge', moment = 0.0, %g, 0.0 /
""" % (T_END, MOM))
ck.record("torque: runs (exit 0)", pt.returncode == 0, pt.stderr[-300:])
if ht is not None:
    ck.le("torque: largest |Ly - M t| / (M t_end)", max(abs(ht["Ly"] - MOM * ht["t"])) / (MOM * T_END), 1e-6)
    ck.le("torque: largest |Lx|, |Lz| / (M t_end)",
          max(abs(ht["Lx"]).max(), abs(ht["Lz"]).max()) / (MOM * T_END), 1e-4)
    ck.le("torque: largest |p| [N s]", max(abs(ht["px"]).max(), abs(ht["py"]).max(), abs(ht["pz"]).max()), 1e-6)
    ck.le("torque: largest |total - total(0)| / work at t_end",
          max(abs(ht["total"] - ht["total"][0])) / ht["work"][-1], 1e-3)

TORQUE = open(os.path.join(work, "torque.nml")).read()
hd, pd, dd = run_deck("drilling", TORQUE.replace("moment = 0.0, 50, 0.0", "moment = 0.0, 50, 3.0"))
line = TORQUE.splitlines().index([l for l in TORQUE.splitlines() if l.startswith("&load")][0]) + 1
ck.record("drilling: a moment along the normal is refused (exit 2, %s:%d, 'drilling')" % (dd, line),
          pd.returncode == 2 and ("%s:%d:" % (dd, line)) in pd.stderr and "drilling" in pd.stderr, pd.stderr[-300:])

for name, text, warned in (("thesis_newmark", TORQUE.replace(", rho_inf = 1.0", ""), True),
                           ("midpoint", TORQUE, False)):
    deck = os.path.join(work, "moment_" + name + ".nml")
    with open(deck, "w") as f:
        f.write(text)
    p = run([casca, "check", deck])
    ck.record("moment under the %s: exit 0, %s of the fibres' rotary inertia" % (name, "warned" if warned else "no word"),
              p.returncode == 0 and ("rotary inertia" in p.stderr) == warned, p.stderr[-300:])

ck.finish()
