"""The command line, the deck checks and the output files (issue: scenes in, results out).

Asserted about the command line itself (issue 17):
- `casca run|check|mesh|plot --help` and `-h`: exit 0, nothing on stderr, stdout begins with
  "usage:" and names the command (`casca run ...`); `casca help CMD` prints the same text;
  `casca help nosuch` exits 2 naming it;
- `casca --help` holds each command's synopsis lines exactly as that command's own help
  prints them (one text, reused);
- `casca --version`: exit 0 without mpirun; lines commit (equal to `git rev-parse` of the
  source tree's HEAD, with -dirty allowed, when the source is a git checkout), build, compiler
  (GCC and the gfortran --version number), MPI, MUMPS, HDF5, METIS each with an x.y.z version,
  and MUMPS/METIS/HDF5 equal to the versions in the system headers dmumps_c.h, metis.h and
  H5public.h where those are found; under `mpirun -np 2` exit 0 and printed once;
- plurals: `casca check` of a one-body deck says "1 body," (never "1 bodies"), of a two-body
  deck "2 bodies,"; `casca mesh` says "N elements, M nodes";
- `casca mesh KIND --size H` (issue 18): the element counts equal those counted here from the
  geometry (ring ceil(2 pi R / H) x ceil(W / H) cells, sphere 20 ceil(R / (H sin 72 deg))^2
  triangles, plate ceil(A / H) x ceil(B / H) cells, two triangles a cell), also when counts
  are given beside it; a size that is not a positive number exits 2 naming --size;
  `casca mesh ring --radius 1e40` exits 2 with the mesh reader's bound ("below 1e15 m") and
  writes no file (the deck reader refused the mesh it wrote);
- gnuplot's messages stay off the terminal: `casca run` of the static cantilever example (flat
  energy curves, on which gnuplot warns "empty y range") and `casca plot` of its folder exit 0
  with no "empty y range" in their stdout or stderr, and the warning is in the folder's
  gnuplot.log instead (so the scene does provoke it). Its history's row 0 is load factor 0 with
  the tracked tip at (10, ., 0), frame 0 has no displacement, the tip's u_z from row 0 to the
  last is Sze's 6.698 (1%), and plots.gp plots against the load factor.
- a misspelt body name (in &restraint, in &contact pairs) or key is named with the nearest
  one: "(did you mean 'ring2'?)", "(did you mean 'tolerance'?)"; a key of another group with
  that group: a body's pressure, "(a key of &load)"; a list where one string goes (fix =
  'x', 'y') with how to write it.
- a run whose solver cannot go on exits 3 and leaves stopped.txt in its folder, with the
  stop time it printed and the deck's t_end; a finished run into the folder removes it.
- a `&restraint` or `&load` given a box and a node list exits 2 at its line (each selects on
  its own; the box was dropped); a run into a folder that holds another run's 7 frames
  leaves its own 2 there, exactly those its run.pvd lists, and their 2 obstacle files (its
  part 1).
- frames with fixed steps: an interval of 12.5 steps of dt is warned of by `casca check` (with
  the ratio, 12.500) and the run, whose frames are at the first step ends at or past 0, 0.5 and
  1 ms (0, 0.52, 1.0 ms); an interval of 12 steps is not warned of.
- text outside the groups (a group's name without its '&', stray words between groups, words
  after a group's '/' on its line) exits 2 at its line, from `casca run` and `casca check`
  alike (the namelist read skipped it: a restraint vanished); '!' comments and blank lines
  between groups and after a '/' are accepted. A degenerate element is named with its body's
  deck line and mesh file; t_end = 1e300 is shown as 1.0000E+300 (was 1.0000+300).
- `casca plot` of a history.dat whose last line is cut short (mid-row, or inside its last
  number's exponent) exits 0 naming that line on stderr, and gnuplot reads the whole rows
  before it alone (counted here); a field not a number or a short row mid-file, an empty file
  and a missing one exit 2 naming the file (and line), with no Fortran traceback.
Then the deck checks and a short run's output files (see the checks' names).

usage: test_cli.py CASCA EXAMPLES_DIR MESH_DIR WORK_DIR
"""
import glob
import math
import os
import re
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

import h5py
import meshio
import numpy as np

from casca_testlib import Checks, deck_variant, history, run

casca, examples, meshdir, work = [os.path.abspath(a) for a in sys.argv[1:5]]
os.makedirs(work, exist_ok=True)
ck = Checks()

# --- the command line itself
p = run([casca, "--help"])
ck.record("casca --help: exit 0 and usage", p.returncode == 0 and "casca run DECK" in p.stdout)
p = run([casca, "--version"])
ck.record("casca --version", p.returncode == 0 and re.match(r"casca \d+\.\d+\.\d+", p.stdout) is not None)

# --- help of each command: one text, printed by COMMAND --help, COMMAND -h and help COMMAND
top = run([casca, "--help"]).stdout
for cmd in ("run", "check", "mesh", "plot"):
    texts = []
    for flag in ("--help", "-h"):
        p = run([casca, cmd, flag])
        ok = (p.returncode == 0 and p.stderr == "" and p.stdout.startswith("usage:\n")
              and ("  casca %s " % cmd) in p.stdout)
        ck.record("casca %s %s: exit 0, its usage on stdout" % (cmd, flag), ok,
                  "exit %d, stderr %r" % (p.returncode, p.stderr[:120]))
        texts.append(p.stdout)
    p = run([casca, "help", cmd])
    ck.record("casca help %s prints the same text as casca %s --help" % (cmd, cmd),
              p.returncode == 0 and p.stdout == texts[0] == texts[1])
    synopsis = texts[0].split("\n\n")[0].splitlines()[1:]
    ck.record("casca --help holds the synopsis of casca %s --help (%d lines)" % (cmd, len(synopsis)),
              len(synopsis) > 0 and all(line in top.splitlines() for line in synopsis))
p = run([casca, "help", "nosuch"])
ck.record("casca help nosuch: exit 2 naming it", p.returncode == 2 and '"nosuch"' in p.stderr)

# --- version: casca's build and the libraries it was built with
p = run([casca, "--version"])
ver = dict(l.split(":", 1) for l in p.stdout.splitlines()[1:] if ":" in l)
ver = {k.strip(): v.strip() for k, v in ver.items()}
xyz = re.compile(r"\d+\.\d+\.\d+")
ck.record("casca --version: exit 0, nothing on stderr, the 7 lines",
          p.returncode == 0 and p.stderr == "" and
          set(ver) == {"commit", "build", "compiler", "MPI", "MUMPS", "HDF5", "METIS"}, "%s; %s" % (sorted(ver), p.stderr[-200:]))
for lib in ("MPI", "MUMPS", "HDF5", "METIS"):
    ck.record("casca --version: %s has a version number" % lib, xyz.search(ver.get(lib, "")) is not None,
              ver.get(lib, "(missing)"))
gf = subprocess.run(["gfortran", "--version"], capture_output=True, text=True).stdout
gfv = xyz.search(gf.splitlines()[0]) if gf else None
if gfv:
    ck.record("casca --version: compiler is GCC %s (gfortran --version)" % gfv.group(0),
              ver.get("compiler", "").startswith("GCC") and gfv.group(0) in ver.get("compiler", ""),
              ver.get("compiler", ""))
src = os.path.dirname(examples)
head = subprocess.run(["git", "-C", src, "rev-parse", "HEAD"], capture_output=True, text=True)
if head.returncode == 0:
    c = ver.get("commit", "")
    short = c[:-len("-dirty")] if c.endswith("-dirty") else c
    ck.record("casca --version: commit is the source tree's HEAD (%s)" % head.stdout.strip()[:12],
              len(short) >= 7 and head.stdout.strip().startswith(short), c)
ck.record("casca --version: build type named", ver.get("build", "") in ("Release", "Debug", "RelWithDebInfo",
                                                                       "MinSizeRel"), ver.get("build", ""))
for lib, header, pattern in (
        ("MUMPS", "/usr/include/dmumps_c.h", r'#define MUMPS_VERSION "([^"]+)"'),
        ("METIS", "/usr/include/metis.h", r"METIS_VER_MAJOR\s+(\d+).*?METIS_VER_MINOR\s+(\d+).*?METIS_VER_SUBMINOR\s+(\d+)"),
        ("HDF5", "/usr/include/hdf5/openmpi/H5public.h", r'#define H5_VERS_INFO\s+"HDF5 library version: ([\d.]+)')):
    if os.path.exists(header):
        m = re.search(pattern, open(header).read(), re.S)
        if m:
            want = ".".join(m.groups())
            ck.record("casca --version: %s %s as in %s" % (lib, want, header), ver.get(lib) == want, ver.get(lib, ""))
p = run([casca, "--version"], np_ranks=2)
ck.record("mpirun -np 2 casca --version: exit 0, printed once",
          p.returncode == 0 and p.stdout.count("casca ") == 1 and "MUMPS:" in p.stdout, p.stderr[-200:])

# --- counts with the noun in the number they ask for
p = run([casca, "check", os.path.join(examples, "cantilever.nml")])
ck.record("casca check of a one-body deck: '1 body,'", p.returncode == 0 and ": ok: 1 body, " in p.stdout
          and "1 bodies" not in p.stdout, p.stdout.strip()[:200])
p = run([casca, "check", os.path.join(examples, "two_rings.nml")])
ck.record("casca check of a two-body deck: '2 bodies,'", p.returncode == 0 and ": ok: 2 bodies, " in p.stdout,
          p.stdout.strip()[:200])
ck.record("casca check names the deck's &run title (two_rings.nml: 'two rings') beside the deck's path",
          p.returncode == 0 and "two_rings.nml: two rings\n" in p.stdout, p.stdout.strip()[-300:])
p = run([casca, "mesh", "plate", "--nx", "1", "--ny", "1", "-o", os.path.join(work, "one_cell.msh")])
ck.record("casca mesh: '2 elements, 16 nodes'", p.returncode == 0 and
          p.stdout.strip().endswith(": 2 elements, 16 nodes"), p.stdout.strip())
# --size: the counts from the geometry, as a deck's element_size
import math
for args, expect in ((["ring", "--radius", "1", "--width", "0.2", "--size", "0.1"],
                      2 * math.ceil(2 * math.pi / 0.1) * math.ceil(0.2 / 0.1)),
                     (["sphere", "--radius", "0.5", "--n-div", "2", "--size", "0.1"],
                      20 * math.ceil(0.5 / (0.1 * math.sin(math.radians(72)))) ** 2),
                     (["plate", "--lx", "2", "--ly", "0.5", "--size", "0.3"],
                      2 * math.ceil(2 / 0.3) * math.ceil(0.5 / 0.3))):
    p = run([casca, "mesh"] + args + ["-o", os.path.join(work, "sized.msh")])
    ck.record("casca mesh %s: %d elements" % (" ".join(args), expect), p.returncode == 0 and
              p.stdout.strip().split(": ")[-1].startswith("%d elements," % expect), p.stdout.strip())
for bad in ("-0.1", "big"):
    p = run([casca, "mesh", "sphere", "--size", bad, "-o", os.path.join(work, "sized.msh")])
    ck.record("casca mesh --size %s: exit 2 naming --size" % bad,
              p.returncode == 2 and "--size" in p.stderr, p.stderr.strip())
# (it was written, and a deck naming it refused it)
huge_msh = os.path.join(work, "huge.msh")
p = run([casca, "mesh", "ring", "--radius", "1e40", "-o", huge_msh])
ck.record("casca mesh ring --radius 1e40: exit 2 with the mesh reader's bound, no file written",
          p.returncode == 2 and "node coordinates must be finite numbers of size below 1e15 m" in p.stderr
          and not glob.glob(huge_msh + "*"), p.stderr.strip())

p = run([casca, "frobnicate"])
ck.record("unknown command: exit 2", p.returncode == 2 and "unknown command" in p.stderr)
p = run([casca, "run"])
ck.record("run without a deck: exit 2", p.returncode == 2 and "no deck" in p.stderr)
for deck in sorted(glob.glob(os.path.join(examples, "*.nml"))):
    p = run([casca, "check", deck])
    ck.record("casca check %s: exit 0" % os.path.basename(deck), p.returncode == 0, p.stderr[-200:])

# --- malformed decks: exit 2, a message naming the file, the line or group, and the field
ring = os.path.join(meshdir, "ring_20x1.msh")
good = """&run
  dt = 5.0e-5, t_end = 3.0e-3
/
&output
  interval = 5.0e-4
  track = 1.0, 0.0, 0.0,   1.06, 0.0, 0.0
  track_body = 'ring1', 'ring2'
/
&body
  name = 'ring1', mesh = 'file', file = '%s'
  velocity = 10.0, 0.0, 0.0
  young = 210e9, poisson = 0.3, density = 7700, thickness = 0.05
/
&body
  name = 'ring2', mesh = 'file', file = '%s', center = 2.06, 0.0, 0.0
  young = 210e9, poisson = 0.3, density = 7700, thickness = 0.05
/
""" % (ring, ring)
empty_msh = os.path.join(work, "empty.msh")
with open(empty_msh, "w") as f:   # a valid Gmsh file with no 10-node triangle
    f.write("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 1 1 1\n0 1 0 1\n1\n0 0 0\n"
            "$EndNodes\n$Elements\n1 1 1 1\n0 1 15 1\n1 1\n$EndElements\n")
flat_msh = os.path.join(work, "flat.msh")
with open(flat_msh, "w") as f:    # one element whose 10 nodes lie on a line: degenerate
    f.write("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 10 1 10\n2 1 0 10\n")
    f.write("".join("%d\n" % i for i in range(1, 11)))
    f.write("".join("%g 0 0\n" % (0.1 * i) for i in range(10)))
    f.write("$EndNodes\n$Elements\n1 1 1 1\n2 1 21 1\n1 1 2 3 4 5 6 7 8 9 10\n$EndElements\n")

mixed_msh = os.path.join(work, "mixed.msh")
with open(mixed_msh, "w") as f:   # one 10-node triangle and one 4-node quadrangle: half the shell
    f.write("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 11 1 11\n2 1 0 11\n")
    f.write("".join("%d\n" % i for i in range(1, 12)))
    xy = [(0, 0), (1, 0), (0, 1), (1 / 3, 0), (2 / 3, 0), (2 / 3, 1 / 3), (1 / 3, 2 / 3), (0, 2 / 3),
          (0, 1 / 3), (1 / 3, 1 / 3), (1, 1)]
    f.write("".join("%.17g %.17g 0\n" % p for p in xy))
    f.write("$EndNodes\n$Elements\n2 2 1 2\n2 1 21 1\n1 1 2 3 4 5 6 7 8 9 10\n"
            "2 1 3 1\n2 2 11 3 3\n$EndElements\n")

cases = [  # (name, text transformation, substrings the message must hold)
    ("missing deck file", None, ["no_such_deck.nml", "cannot open"]),
    ("unknown group", lambda s: s.replace("&output", "&outptu"), ["&outptu", ":4:"]),
    ("an unknown group and a bad value", lambda s: s.replace("&output", "&outptu").replace("young = 210e9", "young = -1.0", 1),
     ["&outptu", ":4:", "young must be > 0", "2 problems in the deck"]),
    ("a scheme given twice and an unknown body", lambda s: s.replace("dt = 5.0e-5", "dt = 5.0e-5, rho_inf = 0.8, beta = 0.3")
     + "&restraint\n body = 'ring9', fix = 'y'\n/\n",
     [":2:", "rho_inf (generalized-alpha) is given with beta or gamma", ":19:", "'ring9' is not a body", "2 problems"]),
    ("misspelt key", lambda s: s.replace("velocity", "velocty"), ["velocty", "velocity", ":11:"]),
    ("wrong type", lambda s: s.replace("dt = 5.0e-5", "dt = 'fast'"), ["dt", "not a number", ":2:"]),
    ("a key given twice", lambda s: s.replace("  young = 210e9, poisson = 0.3, density = 7700, thickness = 0.05\n",
                                              "  young = 210e9, poisson = 0.3, density = 7700, thickness = 0.05\n"
                                              "  thickness = 0.025\n", 1),
     ["&body", "thickness is given twice (lines 12 and 13)", "keep one", ":13:"]),
    # (a key given twice stopped the check there, and the deck's other problems went untold)
    ("a key given twice and a bad value", lambda s: s.replace("young = 210e9", "young = -1.0, young = -1.0", 1),
     ["young is given twice on this line", ":12:", "young must be > 0", "2 problems in the deck"]),
    ("an empty value", lambda s: s.replace("young = 210e9, poisson", "young = 210e9,, poisson", 1),
     ["&body", "young has an empty value", ":12:"]),
    ("a vector short of a number", lambda s: s.replace("velocity = 10.0, 0.0, 0.0", "velocity = 10.0, 0.0", 1),
     ["&body", "velocity takes 3 numbers (x, y, z), 2 given", ":11:"]),
    ("t_end far too large", lambda s: s.replace("t_end = 3.0e-3", "t_end = 1e300"), ["(got 1.0000E+300)", ":2:"]),
    # (text outside the groups: the namelist read skipped it, a restraint vanished)
    ("a group's name without its &", lambda s: s + "restraint\n body = 'ring2', fix = 'clamped'\n/\n",
     ["text outside a group: 'restraint' (a group starts with &)", ":18:", "1 problem in the deck"]),
    ("stray text between groups", lambda s: s.replace("/\n&output", "/\nthis is stray text dt = 1\n&output", 1),
     ["text outside a group: 'this is stray text dt = 1'", ":4:"]),
    ("text after a group's '/'", lambda s: s.replace("t_end = 3.0e-3\n/\n", "t_end = 3.0e-3\n/ t_end = 0.002\n", 1),
     ["text after the group's closing '/': 't_end = 0.002'", ":3:"]),
    ("E not positive", lambda s: s.replace("young = 210e9", "young = -1.0", 1), ["young", "> 0"]),
    ("rho not positive", lambda s: s.replace("density = 7700", "density = 0.0", 1), ["density", "> 0"]),
    ("thickness not positive", lambda s: s.replace("thickness = 0.05", "thickness = 0.0", 1), ["thickness", "> 0"]),
    ("dt not positive", lambda s: s.replace("dt = 5.0e-5", "dt = -1.0e-5"), ["dt", "> 0"]),
    ("nu out of range", lambda s: s.replace("poisson = 0.3", "poisson = 0.5", 1), ["poisson", "(-1, 0.5)"]),
    ("a velocity not a number", lambda s: s.replace("velocity = 10.0, 0.0, 0.0", "velocity = NaN, 0.0, 0.0", 1),
     ["&body ring1: velocity must be finite", "(got NaN)"]),
    ("three problems at once", lambda s: s.replace("dt = 5.0e-5", "dt = -1.0e-5")
     .replace("poisson = 0.3", "poisson = 0.5", 1).replace("1.06, 0.0, 0.0\n", "1.06, 0.0\n", 1),
     ["dt must be > 0", "poisson must be in (-1, 0.5)", "track needs 3 coordinates per point", "3 problems in the deck"]),
    ("missing mesh file", lambda s: s.replace(ring, "/no/such/ring.msh", 1), ["/no/such/ring.msh", "does not exist"]),
    ("empty mesh", lambda s: s.replace(ring, empty_msh, 1), ["empty.msh", "10-node triangles"]),
    ("degenerate element", lambda s: s.replace(ring, flat_msh, 1), ["&body ring1: %s: " % flat_msh, "degenerate", ":9:"]),
    ("quadrangles beside the triangles", lambda s: s.replace(ring, mixed_msh, 1),
     ["mixed.msh", "1 surface element that is not a 10-node triangle", "Gmsh type 3, line 35"]),
    ("restraint selects no node", lambda s: s + "&restraint\n body = 'ring2', box_min = 50.0, 50.0, 50.0, fix = 'y'\n/\n",
     ["&restraint", "no node", "ring2"]),
    ("node set out of range", lambda s: s + "&restraint\n body = 'ring2', nodes = 1, 2, 999, fix = 'y'\n/\n",
     ["&restraint", "nodes(3) = 999", "out of range 1..240"]),
    # (each selects on its own: given a box and a list, the box was dropped without a word)
    ("a restraint given a box and nodes", lambda s: s + "&restraint\n body = 'ring2', box_max = 1e9, 0.0, 1e9, "
     "nodes = 1, 2, fix = 'y'\n/\n", ["&restraint: give one of set, nodes or box_min/box_max", ":%d:" % (good.count("\n") + 1)]),
    ("a load given a box and nodes", lambda s: s + "&load\n body = 'ring2', box_min = 2.0, -1e9, -1e9, nodes = 1, "
     "force = 0.0, 1.0, 0.0\n/\n", ["&load: give one of set, nodes or box_min/box_max", ":%d:" % (good.count("\n") + 1)]),
    ("unknown body in a restraint", lambda s: s + "&restraint\n body = 'ring9', fix = 'y'\n/\n", ["ring9", "not a body"]),
    ("misspelt body in a restraint", lambda s: s + "&restraint\n body = 'rign2', fix = 'y'\n/\n",
     ["rign2", "not a body", "did you mean 'ring2'?"]),
    ("misspelt body in the pairs", lambda s: s + "&contact\n pairs = 'ring1', 'rings2'\n/\n",
     ["pairs(:, 1)", "rings2", "did you mean 'ring2'?"]),
    ("misspelt key in &contact", lambda s: s + "&contact\n tolerence = 1e-6\n/\n", ["&contact", "tolerence", "did you mean 'tolerance'?"]),
    # (a misspelt key is left out of the read, so the other values are still checked)
    ("a misspelt key beside bad values", lambda s: s.replace("dt = 5.0e-5", "dt = -1.0e-5")
     .replace("poisson = 0.3, density", "poisson = 0.5, densty", 1),
     ["unknown key 'densty' (did you mean 'density'?)", "dt must be > 0", "poisson must be in (-1, 0.5)",
      "density is missing", "4 problems in the deck"]),
    ("a key of another group", lambda s: s.replace("young = 210e9, ", "young = 210e9, pressure = 1e3, ", 1),
     ["&body", "unknown key 'pressure'", "(a key of &load)"]),
    ("a plane given inside", lambda s: s + "&obstacle\n name = 'floor', shape = 'plane', point = 0.0, -2.0, 0.0, "
     "normal = 0.0, 1.0, 0.0, inside = .true.\n/\n",
     ["&obstacle: inside is for a sphere or a cylinder", ":%d:" % (good.count("\n") + 2)]),   # (inside's line)
    ("bad fix", lambda s: s + "&restraint\n body = 'ring2', fix = 'sideways'\n/\n", ["fix", "sideways"]),
    ("fix given as a list", lambda s: s + "&restraint\n body = 'ring2', fix = 'x', 'y'\n/\n",
     ["&restraint", "fix takes one string, 2 given: its components in one, fix = 'x y z'", ":19:"]),
    ("a byte-order mark", lambda s: "\ufeff" + s, ["byte-order mark", ":1:"]),
    ("a group left open", lambda s: s.replace("  interval = 5.0e-4\n", "  interval = 5.0e-4,\n", 1)
     .replace("  track_body = 'ring1', 'ring2'\n/\n", "  track_body = 'ring1', 'ring2'\n", 1),
     ["&output is not closed with '/' before the next group, at line 8", ":4:"]),
    ("a quote left open", lambda s: s.replace("track_body = 'ring1', 'ring2'", "track_body = 'ring1, 'ring2'", 1),
     [":7:", "&output: the quote opened here (')", "is not closed, so the group's '/' is inside the string"]),
    ("groups closed with &end", lambda s: s.replace("/\n&output", "&end\n&output", 1),
     ["&run is closed with &end (line 3)", ":1:"]),
    ("names making one history column", lambda s: s.replace("'ring1'", "'ring 1'").replace("'ring2'", "'ring_1'"),
     ["name 'ring_1' and 'ring 1' make the same history column name 'ring_1'", ":15:"]),
    ("a thickness in another unit", lambda s: s.replace("thickness = 0.05", "thickness = 1.5", 1),
     ["&body ring1: thickness 1.5000E+00 m is more than half the body's size, 2.0000E+00 m", ":12:"]),
    # (judged before the elements are set up: past its radius a ring turns inside out
    # through its thickness, and was refused as a degenerate element, with no line)
    ("a ring's thickness past its radius, in another unit", lambda s: s.replace("thickness = 0.05", "thickness = 2.5", 1),
     ["&body ring1: thickness 2.5000E+00 m is more than half the body's size, 2.0000E+00 m", ":12:"]),
    ("a shell thicker than twice its radius of curvature", lambda s: s.replace(
        "name = 'ring1', mesh = 'file', file = '%s'" % ring,
        "name = 'ring1', mesh = 'ring', radius = 1.0, width = 10.0, n_around = 8, n_across = 2", 1)
     .replace("thickness = 0.05", "thickness = 4.5", 1),
     ["&body ring1: element", "turns inside out through its thickness, 4.5000E+00 m", ":9:"]),
    ("time-step keys in a static deck", lambda s: s.replace("  dt = 5.0e-5, t_end = 3.0e-3\n",
                                                            "  dt = 5.0e-5, t_end = 3.0e-3\n  analysis = 'static', tolerance = 1e-5\n", 1),
     ["&run: tolerance is for analysis = 'dynamic'; a static run steps its load by load_steps", ":3:"]),
    ("bodies overlapping at the start", lambda s: s.replace("center = 2.06", "center = 2.04"),
     ["overlap at the start", "ring1", "ring2"]),
    ("bodies outside their container", lambda s: s + "&obstacle\n name = 'jar', shape = 'sphere', point = 0.0, 0.0, 0.0,"
     " radius = 0.3, inside = .true.\n/\n",
     ["&obstacle jar is a container (inside = .true.), and body 'ring", "is not inside it at the start",
      "place the body within its radius", ":%d:" % (good.count("\n") + 1)]),
    ("missing required value", lambda s: s.replace("young = 210e9, ", "", 1), ["young", "missing"]),
    ("unknown mesh kind", lambda s: s.replace("mesh = 'file'", "mesh = 'torus'", 1), ["torus", "mesh"]),
    ("unknown contact normal", lambda s: s + "&contact\n normal = 'smooth'\n/\n", ["&contact", "normal", "nodal"]),
]
for name, change, needles in cases:
    deck = os.path.join(work, "bad_%s.nml" % re.sub(r"\W+", "_", name))
    if change is None:
        deck = os.path.join(work, "no_such_deck.nml")
    else:
        with open(deck, "w", encoding="utf-8") as f:
            f.write(change(good))
    p = run([casca, "run", deck, "--out", os.path.join(work, "bad_out")])
    msg = p.stderr
    ok = (p.returncode == 2 and all(n in msg for n in needles) and os.path.basename(deck) in msg
          and "Backtrace" not in msg and "Error termination" not in msg)
    ck.record("bad deck, %s: exit 2 and a message naming it" % name, ok,
              "exit %d: %s" % (p.returncode, msg.strip().splitlines()[0] if msg.strip() else ""))
    if "outside a group" in " ".join(needles) or "closing '/'" in " ".join(needles):
        c = run([casca, "check", deck])
        ck.record("bad deck, %s: casca check says the same (exit 2)" % name,
                  c.returncode == 2 and all(n in c.stderr for n in needles), c.stderr.strip()[:200])
ck.record("no output folder was made for bad decks", not os.path.exists(os.path.join(work, "bad_out")))
nodeset = os.path.join(work, "nodeset.nml")
with open(nodeset, "w") as f:
    f.write(good + "\n  ! a comment between groups\n&restraint\n body = 'ring2', nodes = 1, 2, 240, fix = 'y'\n/  ! and after\n\n")
p = run([casca, "check", nodeset])
ck.record("a node set within range, with comments and blank lines between groups, is accepted "
          "(casca check: exit 0, 3 fewer unknowns)",
          p.returncode == 0 and "3357 unknowns" in p.stdout, p.stdout.strip() + p.stderr.strip())

# --- a short two-ring run: frames, collection, history in two formats
deck = os.path.join(work, "good.nml")
with open(deck, "w") as f:
    f.write(good.replace("interval = 5.0e-4", "interval = 5.0e-4, checkpoint_interval = 1.5e-3"))
out = os.path.join(work, "good_out")
p = run([casca, "run", deck, "--out", out])
ck.record("good deck runs (exit 0)", p.returncode == 0, p.stderr[-300:])
ck.record("one progress line per output interval", len(re.findall(r"^step ", p.stdout, re.M)) == 6,
          "%d lines" % len(re.findall(r"^step ", p.stdout, re.M)))
pvd = ET.parse(os.path.join(out, "run.pvd")).getroot()
frames = [(float(d.get("timestep")), d.get("file")) for d in pvd.iter("DataSet")]
ck.record("run.pvd lists 7 frames (t = 0 and every 0.5 ms)", len(frames) == 7, str(len(frames)))
ok = True
for t, name in frames:
    m = meshio.read(os.path.join(out, name))
    ok &= (len(m.cells) == 1 and m.cells[0].type == "VTK_LAGRANGE_TRIANGLE"
           and m.cells[0].data.shape == (80, 10) and m.points.shape == (480, 3)
           and all(k in m.point_data for k in ("displacement", "velocity", "fibre", "thickness_param",
                                               "contact_force", "signed_distance"))
           and all(k in m.cell_data for k in ("body", "von_mises")))
ck.record("meshio reads every frame: cell type 69, 80 cells x 10, 480 points, all fields", ok)

# the frames' signed distance to a rigid obstacle: a plate (h 10 mm) whose lower face is 1 mm
# above a plane has every node at the gap 1 mm (until 2026-11-29 every node showed the search
# radius, 6.25 mm, as an obstacle's probe looked nowhere)
gap_deck = os.path.join(work, "gap_plane.nml")
with open(gap_deck, "w") as f:
    f.write("&run dt = 1e-4, t_end = 1e-4 /\n&output interval = 1e-4, plots = .false. /\n"
            "&body name = 'plate', mesh = 'plate', lx = 1.0, ly = 1.0, nx = 2, ny = 2, center = 0.0, 0.0, 0.006,\n"
            "  young = 210e9, poisson = 0.3, density = 7700, thickness = 0.01 /\n"
            "&obstacle name = 'floor', shape = 'plane', point = 0.0, 0.0, 0.0, normal = 0.0, 0.0, 1.0 /\n")
p = run([casca, "run", gap_deck, "--out", os.path.join(work, "gap_plane_out")])
if p.returncode == 0:
    m = meshio.read(os.path.join(work, "gap_plane_out", "frame_00000.vtu"))
    ck.le("signed_distance to a plane 1 mm below the plate's face: largest |sd - 1 mm| [m]",
          np.abs(np.asarray(m.point_data["signed_distance"]).ravel() - 1e-3).max(), 1e-12)
else:
    ck.record("a plate 1 mm above a plane runs (exit 0)", False, p.stderr[-300:])

# frames with fixed steps that do not divide the interval: written at the end of the first
# step at or past each frame's time, and casca check and the run say so (a helper's frames
# came at 0.52, 1.00, 1.52 ms for a 0.5 ms interval with no word, 2026-11-29)
for interval, dt in ((5.0e-4, 4.0e-5), (4.8e-4, 4.0e-5)):
    odd_deck = os.path.join(work, "odd_interval.nml")
    with open(odd_deck, "w") as f:
        f.write("&run dt = %g, t_end = 1.0e-3 /\n&output interval = %g, plots = .false. /\n"
                "&body name = 'plate', mesh = 'plate', lx = 1.0, ly = 1.0, nx = 1, ny = 1,\n"
                "  velocity = 0.0, 0.0, 1.0, young = 210e9, poisson = 0.3, density = 7700, thickness = 0.01 /\n"
                % (dt, interval))
    steps = interval / dt
    whole = abs(steps - round(steps)) < 1e-9
    p = run([casca, "check", odd_deck])
    said = re.search(r"&output interval \S+ s is (\S+) steps of dt", p.stderr)
    if whole:
        ck.record("interval %g = %d steps of dt %g: casca check does not warn" % (interval, round(steps), dt),
                  p.returncode == 0 and said is None, p.stderr[-300:])
        continue
    ck.record("interval %g = %.3f steps of dt %g: casca check warns with that ratio" % (interval, steps, dt),
              p.returncode == 0 and said is not None and abs(float(said.group(1)) - steps) < 1e-3, p.stderr[-300:])
    odd_out = os.path.join(work, "odd_interval_out")
    p = run([casca, "run", odd_deck, "--out", odd_out, "-q"])
    times = [float(d.get("timestep")) for d in ET.parse(os.path.join(odd_out, "run.pvd")).getroot().iter("DataSet")]
    expected = [math.ceil(k * interval / dt - 1e-9) * dt for k in range(3)]
    ck.record("the run warns too", "steps of dt" in p.stderr, p.stderr[-300:])
    ck.record("its frames are at the first step ends at or past 0, %g, %g s: %s" % (interval, 2 * interval, expected),
              len(times) == 3 and max(abs(a - b) for a, b in zip(times, expected)) < 1e-12, str(times))

# a run into a folder that holds a longer run's frames: only its own stay (before 2026-11-29
# frames 2..6 of the other run stayed beside its 2, and ParaView's frame_* series mixed them)
stale = os.path.join(work, "stale_out")
shutil.rmtree(stale, ignore_errors=True)
shutil.copytree(out, stale)
p = run([casca, "run", gap_deck, "--out", stale])
sets = list(ET.parse(os.path.join(stale, "run.pvd")).getroot().iter("DataSet"))
for part, prefix in ("0", "frame_"), ("1", "obstacles_"):   # (the bodies; the floor)
    left = sorted(f for f in os.listdir(stale) if f.startswith(prefix))
    listed = sorted(os.path.basename(d.get("file")) for d in sets if d.get("part") == part)
    ck.record("a run into a folder with another run's 7 frames leaves only its own 2 %s*, those run.pvd "
              "lists as part %s" % (prefix, part), p.returncode == 0 and
              left == listed == [prefix + "00000.vtu", prefix + "00001.vtu"], "%s, %s" % (left, listed))

# node order: the cubic map of the written frame 0 puts points on the ring's cylinder
m = meshio.read(os.path.join(out, frames[0][1]))


def shape(x1, x2):
    L = [1 - x1 - x2, x1, x2]
    v = [0.5 * l * (3 * l - 1) * (3 * l - 2) for l in L]
    pairs = [(0, 1), (1, 0), (1, 2), (2, 1), (2, 0), (0, 2)]
    e = [4.5 * L[a] * L[b] * (3 * L[a] - 1) for a, b in pairs]
    return np.array(v + e + [27 * L[0] * L[1] * L[2]])


rng = np.random.default_rng(1)
worst = 0.0
for cell in m.cells[0].data[:40]:            # ring 1, centred at the origin, axis z
    xe = m.points[cell]
    for _ in range(10):
        a, b = rng.random(2)
        if a + b > 1:
            a, b = 1 - a, 1 - b
        x = shape(a, b) @ xe
        worst = max(worst, abs(np.hypot(x[0], x[1]) - 1.0))
ck.le("frame geometry: interior points of the cubic cells on the cylinder r = 1 [m]", worst, 1e-4)

h = history(out)
with h5py.File(os.path.join(out, "history.h5"), "r") as f:
    table = f["history"][()]
    names = [c.decode() if isinstance(c, bytes) else str(c) for c in f["history"].attrs["columns"]]
ck.record("history.h5 has the columns of history.dat", names == list(h.keys()))
ck.le("history.h5 equals history.dat (max relative difference)",
      max(np.max(np.abs(table[:, i] - h[n]) / (np.abs(h[n]) + 1e-300)) for i, n in enumerate(names)), 1e-14)
needed = "t kinetic strain total px py pz Lx Ly Lz contacts newton".split()
ck.record("history.dat header names the required columns", all(n in h for n in needed))
for png in ("positions_x", "energy", "momentum", "contact"):
    path = os.path.join(out, png + ".png")
    ck.record("plot %s.png made after the run" % png,
              os.path.exists(path) and open(path, "rb").read(8) == b"\x89PNG\r\n\x1a\n")
shutil.rmtree(os.path.join(work, "replot"), ignore_errors=True)
shutil.copytree(out, os.path.join(work, "replot"))
for f in glob.glob(os.path.join(work, "replot", "*.png")):
    os.remove(f)
p = run([casca, "plot", os.path.join(work, "replot")])
ck.record("casca plot DIR remakes the plots", p.returncode == 0 and
          os.path.exists(os.path.join(work, "replot", "positions_x.png")))

# --- casca plot of a damaged history.dat. Cut short in its last line (a run killed while
# writing a row, a truncated copy): the whole rows are plotted, exit 0, and stderr names the
# line left out; a row cut inside its last number, the exponent's digits gone, is left out too.
# Anything else wrong (a field not a number, a short row mid-file, an empty file, none) is
# refused, exit 2, naming the file (and the line), without a Fortran traceback. (Before
# 2026-12: the cut row was plotted without a word, and a bad field mid-file too, exit 0.)
def plot_of(name, text):
    """casca plot of a folder holding text as its history.dat (none if text is None)."""
    d = os.path.join(work, "plot_" + name)
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(d)
    if text is not None:
        with open(os.path.join(d, "history.dat"), "w") as f:
            f.write(text)
    return d, run([casca, "plot", d])


def plotted_rows(d):
    """The rows gnuplot reads through the folder's plots.gp (its datafile and rows)."""
    g = subprocess.run(["gnuplot", "plots.gp", "-"], cwd=d, capture_output=True, text=True,
                       input="set print '-'\nstats datafile @rows using 1 nooutput\nprint STATS_records\n")
    return int(g.stdout.split()[-1]) if g.returncode == 0 and g.stdout.split() else -1


def clean_refusal(p):
    return p.returncode == 2 and "Backtrace" not in p.stderr and "Error termination" not in p.stderr


lines = open(os.path.join(out, "history.dat")).read().splitlines(True)
rows, n_last = len(lines) - 2, len(lines)   # whole rows before the last line, its line number
last = lines[-1].rstrip("\n")
for name, text in (("cut_mid_row", "".join(lines[:-1]) + last[:len(last) // 2]),
                   ("cut_exponent", "".join(lines[:-1]) + last[:-2])):
    d, p = plot_of(name, text)
    ck.record("casca plot, history.dat %s: exit 0, its line %d named as left out on stderr" % (name, n_last),
              p.returncode == 0 and "history.dat: line %d is cut short" % n_last in p.stderr
              and "left out" in p.stderr, p.stderr.strip())
    ck.record("casca plot, history.dat %s: gnuplot plots its %d whole rows" % (name, rows),
              plotted_rows(d) == rows and os.path.exists(os.path.join(d, "energy.png")), str(plotted_rows(d)))
bad = lines[3].split()
bad[2] = "abc"
d, p = plot_of("not_a_number", "".join(lines[:3]) + " ".join(bad) + "\n" + "".join(lines[4:]))
ck.record("casca plot, a field not a number on line 4: exit 2 naming the file, line and column",
          clean_refusal(p) and d + "/history.dat: line 4, column 3 (kinetic)" in p.stderr, p.stderr.strip())
d, p = plot_of("short_mid_row", "".join(lines[:2]) + lines[2][:40] + "\n" + "".join(lines[3:]))
ck.record("casca plot, a short row on line 3 of %d: exit 2 naming the file and line" % n_last,
          clean_refusal(p) and d + "/history.dat: line 3: " in p.stderr, p.stderr.strip())
d, p = plot_of("empty", "")
ck.record("casca plot, an empty history.dat: exit 2 naming it",
          clean_refusal(p) and d + "/history.dat is empty" in p.stderr, p.stderr.strip())
d, p = plot_of("missing", None)
ck.record("casca plot, no history.dat: exit 2 naming it",
          clean_refusal(p) and d + "/history.dat" in p.stderr, p.stderr.strip())

# --- gnuplot's warnings go to DIR/gnuplot.log, not the terminal
out_c = os.path.join(work, "cantilever_out")
shutil.rmtree(out_c, ignore_errors=True)
p = run([casca, "run", os.path.join(examples, "cantilever.nml"), "--out", out_c, "-q"])
log = os.path.join(out_c, "gnuplot.log")
ck.record("static cantilever run: exit 0, no 'empty y range' on the terminal",
          p.returncode == 0 and "empty y range" not in p.stdout + p.stderr, (p.stdout + p.stderr)[-300:])
ck.record("gnuplot's 'empty y range' warning is in DIR/gnuplot.log",
          os.path.exists(log) and "empty y range" in open(log).read())
p = run([casca, "plot", out_c])
ck.record("casca plot of it: exit 0, no 'empty y range' on the terminal",
          p.returncode == 0 and "empty y range" not in p.stdout + p.stderr, (p.stdout + p.stderr)[-300:])
# a static run starts at load factor 0, undeformed: its plots measure the displacement from
# there (before 2026-11-29 from the first load step: the tip's 6.70 plotted as 5.39) against
# the load factor
if p.returncode == 0:
    hc = history(out_c)
    ck.record("static cantilever: history row 0 is load factor 0 with the tip where the deck puts it",
              hc["t"][0] == 0 and hc["p1_x"][0] == 10.0 and hc["p1_z"][0] == 0.0,
              "t %g, tip (%g, %g)" % (hc["t"][0], hc["p1_x"][0], hc["p1_z"][0]))
    ck.close("static cantilever: the tip's u_z from row 0 to the last (displacements.png) against Sze's 6.698",
             hc["p1_z"][-1] - hc["p1_z"][0], 6.698, 0.01)
    m0 = meshio.read(os.path.join(out_c, "frame_00000.vtu"))
    ck.le("static cantilever: frame 0's largest |displacement| (undeformed) [m]",
          np.abs(m0.point_data["displacement"]).max(), 0.0)
    gp = open(os.path.join(out_c, "plots.gp")).read()
    ck.record("static cantilever: plots.gp plots against the load factor", "set xlabel 'load factor [-]'" in gp)

# --- restart: a run stopped at 1.5 ms and continued equals the uninterrupted run (both write
# a checkpoint at 1.5 ms: the step after a checkpoint starts with a new factorisation)
half = os.path.join(work, "half.nml")
with open(half, "w") as f:
    f.write(good.replace("t_end = 3.0e-3", "t_end = 1.5e-3").replace("interval = 5.0e-4", "interval = 5.0e-4, checkpoint_interval = 1.5e-3"))
out_r = os.path.join(work, "restart_out")
p1 = run([casca, "run", half, "--out", out_r, "-q"])
ckpt = os.path.join(work, "at_1.5ms.h5")
shutil.copy(os.path.join(out_r, "checkpoint.h5"), ckpt)
p2 = run([casca, "run", deck, "--out", out_r, "--restart", ckpt, "-q"])
ck.record("restart run (exit 0)", p1.returncode == 0 and p2.returncode == 0, p2.stderr[-300:])
hr = history(out_r)
ck.record("restarted history has the same rows", len(hr["t"]) == len(h["t"]), "%d vs %d" % (len(hr["t"]), len(h["t"])))
if len(hr["t"]) == len(h["t"]):
    rel = max(np.max(np.abs(hr[k] - h[k])) / max(np.max(np.abs(h[k])), 1e-300)
              for k in h if k.startswith("p") and "_" in k)
    ck.le("restart equals the uninterrupted run (tracked nodes, relative)", rel, 1e-12)
with h5py.File(os.path.join(out, "checkpoint.h5"), "r") as a, h5py.File(os.path.join(out_r, "checkpoint.h5"), "r") as b:
    qa, qb = a["q"][()], b["q"][()]
ck.le("restart: final positions equal (relative)", np.max(np.abs(qa - qb)) / np.max(np.abs(qa)), 1e-12)
m = meshio.read(os.path.join(out_r, ET.parse(os.path.join(out_r, "run.pvd")).getroot().findall(".//DataSet")[-1].get("file")))
ck.record("restarted run.pvd lists all 7 frames",
          len(ET.parse(os.path.join(out_r, "run.pvd")).getroot().findall(".//DataSet")) == 7)

# --- the solver cannot go on: exit 3, last good state and a restart file written
stuck = os.path.join(work, "stuck.nml")
with open(stuck, "w") as f:
    f.write(good.replace("dt = 5.0e-5, t_end = 3.0e-3",
                         "dt = 5.0e-5, t_end = 3.0e-3, newton_max_iter = 1, newton_tol = 1e-30, max_step_cuts = 1"))
out_s = os.path.join(work, "stuck_out")
p = run([casca, "run", stuck, "--out", out_s, "-q"])
ck.record("solver failure: exit 3 with a message", p.returncode == 3 and "cannot go on" in p.stderr, p.stderr[-200:])
ck.record("solver failure: checkpoint.h5 and a last frame written",
          os.path.exists(os.path.join(out_s, "checkpoint.h5")) and os.path.exists(os.path.join(out_s, "run.pvd")))
# the folder says the run stopped early (its history and frames are whole files), with the
# time and reason the run printed; a later run into the folder removes the mark
mark = os.path.join(out_s, "stopped.txt")
text = open(mark).read() if os.path.exists(mark) else ""
t_stop = re.search(r"cannot go on at t =\s*(\S+) s", p.stderr)
t_mark = re.search(r"stopped at t = (\S+) s of t_end = (\S+) s", text)
ck.record("solver failure: stopped.txt names the stop time and t_end", t_stop is not None and t_mark is not None
          and abs(float(t_mark.group(1)) - float(t_stop.group(1))) <= 1e-4 * float(t_stop.group(1))
          and float(t_mark.group(2)) == 3.0e-3, text)
p = run([casca, "run", deck, "--out", out_s, "-q"])
ck.record("a finished run into that folder removes stopped.txt", p.returncode == 0 and not os.path.exists(mark),
          p.stderr[-200:])
# the frame of a run that stops measures the last good state against the obstacles where they
# were then: a plate lying on a plane rising at 1 m/s, whose first step fails, shows 0 (before
# 2026-11-29 the obstacle stood where the failed step had put it: -v dt at the nodes)
stop_deck = os.path.join(work, "gap_stop.nml")
with open(stop_deck, "w") as f:
    f.write(open(gap_deck).read().replace("t_end = 1e-4 /", "t_end = 1e-3, newton_max_iter = 1, newton_tol = 1e-30, "
                                          "max_step_cuts = 1 /").replace("normal = 0.0, 0.0, 1.0 /",
                                                                         "normal = 0.0, 0.0, 1.0, velocity = 0.0, 0.0, 1.0 /")
            .replace("center = 0.0, 0.0, 0.006", "center = 0.0, 0.0, 0.005"))
p = run([casca, "run", stop_deck, "--out", os.path.join(work, "gap_stop_out"), "-q"])
last = sorted(glob.glob(os.path.join(work, "gap_stop_out", "frame_*.vtu")))
ok = p.returncode == 3 and len(last) > 0
ck.le("a stopped run's last frame: largest |signed_distance| of a plate lying on a rising plane [m]",
      np.abs(np.asarray(meshio.read(last[-1]).point_data["signed_distance"]).ravel()).max() if ok else 1.0, 1e-12)
ck.finish()
