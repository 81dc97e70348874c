"""cmake --install, and the installed casca on an installed example (issue 17).

Installs the build into a fresh temporary prefix (WORK_DIR/prefix, removed first) and asserts:
- `cmake --install BUILD_DIR --prefix PREFIX` exits 0;
- PREFIX/bin/casca is an executable file;
- PREFIX/share/casca/examples holds every examples/*.nml of the source tree, and every mesh
  file an installed deck names (`file = '...'`, relative to the deck) exists there;
- PREFIX/share/doc/casca holds README.md, docs/method.md and docs/deck.md (the deck
  reference README.md links to), identical to the source's;
- the installed `casca --version` and `casca check` of every installed example exit 0;
- the installed `casca run` of a copy of the installed two_rings.nml, kept next to it (so its
  ../mesh/ring_20x1.msh is the installed mesh) with t_end = 2 ms and output every 1 ms, exits 0
  and leaves history.dat with a header and at least 2 rows, the last at t = 2 ms.
Nothing is written outside WORK_DIR.

usage: test_install.py CMAKE BUILD_DIR SOURCE_DIR WORK_DIR
"""
import filecmp
import glob
import os
import re
import shutil
import subprocess
import sys

from casca_testlib import Checks, history, run

cmake, build, source, work = sys.argv[1], *[os.path.abspath(a) for a in sys.argv[2:5]]
prefix = os.path.join(work, "prefix")
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
ck = Checks()

p = subprocess.run([cmake, "--install", build, "--prefix", prefix], capture_output=True, text=True)
ck.record("cmake --install into a temporary prefix: exit 0", p.returncode == 0, p.stderr[-300:])

casca = os.path.join(prefix, "bin", "casca")
ck.record("PREFIX/bin/casca is executable", os.path.isfile(casca) and os.access(casca, os.X_OK))
share = os.path.join(prefix, "share", "casca")
decks = sorted(os.path.basename(d) for d in glob.glob(os.path.join(source, "examples", "*.nml")))
installed = sorted(os.path.basename(d) for d in glob.glob(os.path.join(share, "examples", "*.nml")))
ck.record("every example deck installed (%d)" % len(decks), decks == installed and len(decks) > 0,
          "%s vs %s" % (decks, installed))
missing = []
for d in installed:
    deck = os.path.join(share, "examples", d)
    for f in re.findall(r"\bfile\s*=\s*'([^']+)'", open(deck).read()):
        if not os.path.isfile(os.path.join(os.path.dirname(deck), f)):
            missing.append("%s: %s" % (d, f))
ck.record("every mesh an installed deck names is installed at its relative path",
          len(installed) > 0 and not missing, ", ".join(missing))
doc = os.path.join(prefix, "share", "doc", "casca")
ck.record("README.md, docs/method.md and docs/deck.md installed under share/doc/casca, as in the source",
          all(os.path.isfile(os.path.join(doc, f)) and filecmp.cmp(os.path.join(doc, f), os.path.join(source, f),
                                                                    shallow=False)
              for f in ("README.md", os.path.join("docs", "method.md"), os.path.join("docs", "deck.md"))))

p = run([casca, "--version"], cwd=work)
ck.record("installed casca --version: exit 0", p.returncode == 0 and p.stdout.startswith("casca "),
          p.stderr[-200:])
for d in installed:
    p = run([casca, "check", os.path.join(share, "examples", d)], cwd=work)
    ck.record("installed casca check %s: exit 0" % d, p.returncode == 0, p.stderr[-200:])

# a short run of a copy next to the installed decks (the prefix is WORK_DIR's own)
src = os.path.join(share, "examples", "two_rings.nml")
short = os.path.join(share, "examples", "two_rings_short.nml")
text = open(src).read() if os.path.isfile(src) else ""
text, n1 = re.subn(r"t_end\s*=\s*[^,\n/]+", "t_end = 2.0e-3", text, count=1)
text, n2 = re.subn(r"\binterval\s*=\s*[^,\n/]+", "interval = 1.0e-3", text, count=1)
with open(short, "w") as f:
    f.write(text)
ck.record("two_rings.nml has t_end and interval to shorten", n1 == 1 and n2 == 1)
out = os.path.join(work, "two_rings_out")
p = run([casca, "run", short, "--out", out, "-q"], cwd=work)
ck.record("installed casca run of two_rings (t_end 2 ms): exit 0", p.returncode == 0, p.stderr[-300:])
path = os.path.join(out, "history.dat")
ok = os.path.isfile(path)
ck.record("history.dat written", ok)
if ok:
    h = history(out)
    ck.record("history.dat has rows up to t = 2 ms", len(h["t"]) >= 2 and abs(h["t"][-1] - 2.0e-3) < 1e-9,
              "%d rows, last t = %g" % (len(h["t"]), h["t"][-1] if len(h["t"]) else float("nan")))
ck.finish()
