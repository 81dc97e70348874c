"""casca as a hostile or unlucky user meets it (issue 15): crashes and restarts, a full disk,
two runs in one folder, foreign checkpoints, shell injection, non-finite numbers, an error on
one of two MPI ranks. Each case asserts exit codes and file contents against an independent
answer (an uninterrupted run, the file system, the deck's own numbers). Among them: a run
into a finished run's folder, stopped by SIGTERM, leaves none of that run's plots (plots.gp,
gnuplot.log, PNGs), while a restart in place keeps them; a SIGTERM during a static load step
ends the run within a small part of that step at the last converged one (exit 4); on a full disk (as root only: a
small tmpfs is mounted, else skipped) the restart hint is printed exactly when a checkpoint is
left, and stopped.txt, written where there is room for it (at one size at least), names the
failed write.

usage: test_faults.py CASCA MESH_DIR WORK_DIR
"""
import os
import re
import shutil
import signal
import subprocess
import sys
import time

import h5py
import numpy as np

from casca_testlib import ENV, Checks, history, run

casca, meshdir, work = [os.path.abspath(a) for a in sys.argv[1:4]]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
ck = Checks()
ring = os.path.join(meshdir, "ring_20x1.msh")

# two rings meeting at 10 m/s; 200 steps, a checkpoint every 10 steps
deck_text = """&run
  dt = 5.0e-5, t_end = T_END
/
&output
  dir = 'DIR'
  interval = 5.0e-4, checkpoint_interval = 5.0e-4
  track = 1.0, 0.0, 0.0,   1.06, 0.0, 0.0
  track_body = 'ring1', 'ring2'
/
&body
  name = 'ring1', mesh = 'file', file = 'RING'
  velocity = 10.0, 0.0, 0.0
  young = 210e9, poisson = 0.3, density = 7700, thickness = 0.05
/
&body
  name = 'ring2', mesh = 'file', file = 'RING', center = 2.06, 0.0, 0.0
  young = 210e9, poisson = 0.3, density = 7700, thickness = 0.05
/
""".replace("RING", ring)


def deck(name, t_end="1.0e-2", out="out", extra=""):
    path = os.path.join(work, name + ".nml")
    with open(path, "w") as f:
        f.write(deck_text.replace("T_END", t_end).replace("DIR", out) + extra)
    return path


def clean(p):
    """exit with a code of casca's (never a signal, a backtrace or a runtime error)"""
    return (p.returncode in (0, 2, 3) and "Backtrace" not in p.stderr
            and "Fortran runtime error" not in p.stderr and "Error termination" not in p.stderr)


def first_line(p):
    lines = [l for l in p.stderr.splitlines() if l.startswith("error")]
    return "exit %d: %s" % (p.returncode, lines[0] if lines else p.stderr.strip()[-200:])


def ckpt_step(path):
    try:
        with h5py.File(path, "r") as f:
            return int(f["step"][()])
    except (OSError, KeyError):
        return -1


def max_rel(h, ref):
    """The largest difference of two histories relative to each of ref's columns' size (inf
    when their shapes differ)"""
    if h.shape != ref.shape:
        return np.inf
    return np.max(np.abs(h - ref) / np.maximum(np.max(np.abs(ref), axis=0), 1e-300))


def table(folder):
    with h5py.File(os.path.join(folder, "history.h5"), "r") as f:
        return f["history"][()]


# --- kill and restart: a run killed (kill -9) at several moments (right after a checkpoint,
# between two, during contact) and restarted each time from its own checkpoint in the same
# folder ends with the history of the uninterrupted run, in both files, to 1e-12
ref_out = os.path.join(work, "uninterrupted")
p = run([casca, "run", deck("ref", out=ref_out), "-q"])
ck.record("uninterrupted run (exit 0)", p.returncode == 0, first_line(p))
ref = np.loadtxt(os.path.join(ref_out, "history.dat"))
kill_out = os.path.join(work, "killed")
kdeck = deck("killed", out=kill_out)
ckpt = os.path.join(kill_out, "checkpoint.h5")
moments = [(10, 0.0, signal.SIGKILL), (40, 0.03, signal.SIGKILL), (70, 0.11, signal.SIGKILL),
           (110, 0.07, signal.SIGKILL), (150, 0.0, signal.SIGKILL)]
killed_at, restarts_ok, whole = [], True, []


def whole_rows(path):
    """Every line of a history.dat ends, and has the header's number of fields."""
    text = open(path).read()
    lines = text.splitlines()
    n = len(lines[0].lstrip("#").split())
    return text.endswith("\n") and all(len(line.split()) == n for line in lines[1:])


for i, (after, wait, sig) in enumerate(moments):
    args = [casca, "run", kdeck, "-q"] + (["--restart", ckpt] if i > 0 else [])
    proc = subprocess.Popen(args, env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    while proc.poll() is None and ckpt_step(ckpt) < after:
        time.sleep(0.01)
    time.sleep(wait)
    if proc.poll() is None:
        proc.send_signal(sig)
    out_, err_ = proc.communicate()
    killed_at.append((ckpt_step(ckpt), proc.returncode))
    if proc.returncode != 0:
        whole.append(whole_rows(os.path.join(kill_out, "history.dat")))
    if i > 0 and not (proc.returncode < 0 or proc.returncode == 0):
        restarts_ok = False
        print("restart %d: exit %d: %s" % (i, proc.returncode, err_[-300:]))
p = run([casca, "run", kdeck, "-q", "--restart", ckpt])
ck.record("restarts after kill -9 at %d moments accepted, the last ends with exit 0"
          % len(moments), restarts_ok and p.returncode == 0,
          "checkpoint step and exit per kill %s; %s" % (killed_at, first_line(p)))
ck.record("the runs were killed at different checkpoints (really interrupted)",
          len(set(s for s, c in killed_at if c < 0)) >= 3, str(killed_at))
ck.record("each killed run's history.dat holds whole rows only (every line ends, with the "
          "header's number of fields)", len(whole) >= 3 and all(whole), str(whole))
h = np.loadtxt(os.path.join(kill_out, "history.dat"))
ck.record("history.dat after the restarts has the uninterrupted run's steps",
          h.shape == ref.shape and np.array_equal(h[:, 1], ref[:, 1]), "%s vs %s" % (h.shape, ref.shape))
if h.shape == ref.shape:
    ck.le("history.dat equals the uninterrupted run's (max relative to each column's size)",
          max_rel(h, ref), 1e-12)
    ck.le("history.h5 after the restarts equals the uninterrupted run's history.dat",
          max_rel(table(kill_out), ref), 1e-12)
ck.record("the folder's lock is gone after the last run", not os.path.exists(os.path.join(kill_out, "casca.lock")))

# --- a stop signal (a batch system's time limit, Ctrl-C, SIGUSR1 sent to mpirun): the step
# under way ends, its state is written as checkpoint and frame, stopped.txt names the signal,
# exit 4; the restart from there ends with the uninterrupted run's history bit for bit (both
# with reuse_factorisation = .false.: kept factors would be fresh at the restart only, and the
# two runs would then agree to Newton's tolerance instead)
sig_text = deck_text.replace("t_end = T_END", "t_end = 5.0e-3, reuse_factorisation = .false.")
sig_deck = os.path.join(work, "signalled.nml")
with open(sig_deck, "w") as f:
    f.write(sig_text.replace("DIR", "out"))
for ranks, sig in ((1, signal.SIGTERM), (2, signal.SIGUSR1)):
    name = signal.Signals(sig).name
    sig_ref = os.path.join(work, "signal_ref_%d" % ranks)
    p = run([casca, "run", sig_deck, "-q", "--out", sig_ref], np_ranks=ranks)
    ck.record("%s: the uninterrupted run on %d rank(s) (exit 0)" % (name, ranks), p.returncode == 0,
              first_line(p))
    sig_out = os.path.join(work, "signalled_%d" % ranks)
    cmd = [casca, "run", sig_deck, "-q", "--out", sig_out]
    if ranks > 1:   # (mpirun kills its ranks a second after a SIGTERM, and passes SIGUSR1 on)
        cmd = ["mpirun", "-np", str(ranks)] + cmd
    proc = subprocess.Popen(cmd, env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    hist = os.path.join(sig_out, "history.dat")
    while proc.poll() is None and (not os.path.exists(hist) or open(hist).read().count("\n") < 25):
        time.sleep(0.01)
    proc.send_signal(sig)
    out_, err_ = proc.communicate(timeout=120)
    stopped = os.path.join(sig_out, "stopped.txt")
    said = open(stopped).read() if os.path.exists(stopped) else ""
    ck.record("%s on %d rank(s): exit 4, stopped.txt names it" % (name, ranks),
              proc.returncode == 4 and name in said, "exit %d; %r" % (proc.returncode, said[:120]))
    rows = np.loadtxt(hist)
    with h5py.File(os.path.join(sig_out, "checkpoint.h5"), "r") as f:
        ck_step, ck_t = int(f["step"][()]), float(f["t"][()])
    last_frame = float(re.findall(r'timestep="([^"]+)"', open(os.path.join(sig_out, "run.pvd")).read())[-1])
    ck.record("%s: the checkpoint is the last history row's step (the regular ones are every "
              "10 steps), and the last frame is at its time" % name,
              ck_step == int(rows[-1, 1]) and abs(last_frame - ck_t) <= 1e-12 * ck_t,
              "checkpoint step %d t %.17g, last row step %d, last frame t %.17g"
              % (ck_step, ck_t, rows[-1, 1], last_frame))
    ck.record("%s: the folder's lock is gone" % name, not os.path.exists(os.path.join(sig_out, "casca.lock")))
    p = run([casca, "run", sig_deck, "-q", "--out", sig_out, "--restart",
             os.path.join(sig_out, "checkpoint.h5")], np_ranks=ranks)
    h, ref_h = np.loadtxt(hist), np.loadtxt(os.path.join(sig_ref, "history.dat"))
    ck.record("%s: the restart ends with exit 0 and no stopped.txt" % name,
              p.returncode == 0 and not os.path.exists(stopped), first_line(p))
    ck.le("%s: the restarted history.dat equals the uninterrupted run's on as many ranks (max "
          "relative to each column's size)" % name, max_rel(h, ref_h), 1e-12)

# --- statics: a stop signal during a load step is served between Newton solves, not at the
# step's end: a load step can take minutes (a plate held by friction, halved and stabilised
# 190 s past a SIGTERM, validator S33 F4). The strip rolled up in three load steps, the third
# of them ~3/4 of the run (Newton halves it again and again), SIGTERM half a second into it:
# exit 4 within a quarter of the uninterrupted run's time, stopped.txt names the signal, the
# checkpoint and the history end at the last converged load step (2/3), the lock is gone, and
# the restart from there ends where the uninterrupted run does (to Newton's tolerance). Past
# twice the bound a second SIGTERM ends the process at once (README), leaving no stopped.txt and its
# lock (which a later run takes over).
static_text = """&run
  analysis = 'static', load_steps = 3, reuse_factorisation = .false.
/
&output
  dir = 'out', track = 12.0, 0.5, 0.0
/
&body
  name = 'strip', mesh = 'strip', lx = 12.0, ly = 1.0, nx = 8, ny = 1
  young = 1.2e6, poisson = 0.0, density = 1.0, thickness = 0.1
/
&restraint
  body = 'strip', box_max = 0.0, 1e9, 1e9, fix = 'clamped'
/
&load
  body = 'strip', box_min = 12.0, -1e9, -1e9, kind = 'edge', moment = 0.0, -52.35987755982988, 0.0
/
"""
static_deck = os.path.join(work, "static_signalled.nml")
with open(static_deck, "w") as f:
    f.write(static_text)


def tip(folder):
    """The tracked tip's position (x, z) in the last row of folder's history.dat"""
    names = open(os.path.join(folder, "history.dat")).readline().lstrip("#").split()
    last = np.atleast_2d(np.loadtxt(os.path.join(folder, "history.dat")))[-1]
    return np.array([last[names.index("p1_x")], last[names.index("p1_z")]])


static_ref = os.path.join(work, "static_ref")
t0 = time.time()
p = run([casca, "run", static_deck, "-q", "--out", static_ref])
t_ref = time.time() - t0
ck.record("statics: the uninterrupted run (exit 0)", p.returncode == 0, first_line(p))
static_out = os.path.join(work, "static_signalled")
proc = subprocess.Popen([casca, "run", static_deck, "-q", "--out", static_out], env=ENV,
                        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
hist = os.path.join(static_out, "history.dat")
while proc.poll() is None and (not os.path.exists(hist) or open(hist).read().count("\n") < 4):
    time.sleep(0.01)   # (the header and the rows of factors 0, 1/3 and 2/3)
time.sleep(0.5)
t_sig = time.time()
proc.send_signal(signal.SIGTERM)
try:   # (past twice the bound a second SIGTERM, as a batch system's SIGKILL after its grace period)
    proc.communicate(timeout=t_ref / 2)
except subprocess.TimeoutExpired:
    proc.send_signal(signal.SIGTERM)
    proc.communicate(timeout=600)
t_stop = time.time() - t_sig
stopped = os.path.join(static_out, "stopped.txt")
said = open(stopped).read() if os.path.exists(stopped) else ""
ck.record("statics: SIGTERM during a load step: exit 4 and stopped.txt names it",
          proc.returncode == 4 and "SIGTERM" in said, "exit %d; %r" % (proc.returncode, said[:120]))
ck.le("statics: seconds from the (first) SIGTERM to the exit (bound: a quarter of the uninterrupted run's "
      "%.1f s, most of which is the last load step)" % t_ref, t_stop, t_ref / 4)
ck_step, ck_t = -1, np.nan
if os.path.exists(os.path.join(static_out, "checkpoint.h5")):
    with h5py.File(os.path.join(static_out, "checkpoint.h5"), "r") as f:
        ck_step, ck_t = int(f["step"][()]), float(f["t"][()])
rows = np.atleast_2d(np.loadtxt(hist))
ck.record("statics: the checkpoint and history.dat end at the last converged load step (2 of 3, "
          "factor 2/3)", ck_step == 2 and abs(ck_t - 2 / 3) <= 1e-12 and int(rows[-1, 1]) == 2,
          "checkpoint step %d factor %.17g, last row step %d" % (ck_step, ck_t, rows[-1, 1]))
ck.record("statics: the folder's lock is gone", not os.path.exists(os.path.join(static_out, "casca.lock")))
p = run([casca, "run", static_deck, "-q", "--out", static_out, "--restart",
         os.path.join(static_out, "checkpoint.h5")])
gap = np.max(np.abs(tip(static_out) - tip(static_ref))) if p.returncode == 0 else np.inf
ck.record("statics: the restart from the checkpoint at factor 2/3 ends (exit 0, no stopped.txt) at the "
          "uninterrupted run's tip, to 1e-6 of the strip's length",
          ck_step == 2 and p.returncode == 0 and not os.path.exists(stopped) and gap <= 1e-6 * 12.0,
          "%s; tip off by %.3g" % (first_line(p), gap))

# --- a restart from a finished run's own checkpoint: its time is t_end but for the rounding
# of a sum of 80 steps (4.0000000000000036e-3), and it is accepted, takes no step and leaves
# the history as it was (it was refused as 'outside [0, t_end]', validator 2026-11-29)
done_out = os.path.join(work, "finished")
p = run([casca, "run", deck("finished", t_end="4.0e-3", out=done_out), "-q"])
before = open(os.path.join(done_out, "history.dat")).read() if p.returncode == 0 else ""
p = run([casca, "run", deck("finished", t_end="4.0e-3", out=done_out), "-q",
         "--restart", os.path.join(done_out, "checkpoint.h5")])
ck.record("restart from a finished run's checkpoint (t_end + rounding): exit 0, history.dat unchanged",
          p.returncode == 0 and before != "" and open(os.path.join(done_out, "history.dat")).read() == before,
          first_line(p))

# --- a run into the folder of a finished run removes that run's plots (plots.gp, gnuplot.log,
# the PNGs) as it starts: stopped (SIGTERM) early, it left them beside its own history as its
# own (validator 2026-11-29). A restart in place carries on the history they were drawn from
# and keeps them.
plot_names = ["plots.gp", "gnuplot.log", "positions_x.png", "energy.png", "momentum.png", "contact.png",
              "newton.png", "displacements.png"]


def stopped_in(folder, extra_args=()):
    """casca run of a 10 ms deck into folder, SIGTERM once it holds the folder's lock: exit code"""
    proc = subprocess.Popen([casca, "run", deck("replot", out=folder), "-q"] + list(extra_args), env=ENV,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    while proc.poll() is None and not os.path.exists(os.path.join(folder, "casca.lock")):
        time.sleep(0.01)
    proc.send_signal(signal.SIGTERM)
    proc.communicate(timeout=120)
    return proc.returncode


had = [n for n in plot_names if os.path.exists(os.path.join(done_out, n))]
replot_out, keep_out = os.path.join(work, "replot"), os.path.join(work, "replot_restart")
shutil.copytree(done_out, replot_out)
shutil.copytree(done_out, keep_out)
code = stopped_in(replot_out)
left = [n for n in plot_names if os.path.exists(os.path.join(replot_out, n))]
ck.record("a new run into a finished run's folder, stopped by SIGTERM (exit 4): none of the earlier "
          "run's plots left (it had plots.gp at least)",
          code == 4 and "plots.gp" in had and not left,
          "exit %d, had %s, left %s" % (code, had, left))
code = stopped_in(keep_out, ["--restart", os.path.join(keep_out, "checkpoint.h5")])
kept = [n for n in plot_names if os.path.exists(os.path.join(keep_out, n))]
ck.record("a restart in place, stopped by SIGTERM (exit 4): the run's plots kept",
          code == 4 and kept == had, "exit %d, kept %s of %s" % (code, kept, had))

# --- a restart into a new folder (--out elsewhere): it carries on the checkpoint folder's
# history, which ends as the uninterrupted run's (1e-12), and leaves the old folder as it was
part_out, new_out = os.path.join(work, "part"), os.path.join(work, "moved")
p = run([casca, "run", deck("part", t_end="5.0e-3", out=part_out), "-q"])
before = open(os.path.join(part_out, "history.dat")).read()


def restart_into(name, label, out):
    """Restart the part run's checkpoint into folder out; record exit 0 and that out's
    history.dat ends as the uninterrupted run's (1e-12 of each column's size)."""
    p = run([casca, "run", deck(name, out=part_out), "-q", "--out", out,
             "--restart", os.path.join(part_out, "checkpoint.h5")])
    ck.record("%s: exit 0" % label, p.returncode == 0, first_line(p))
    if p.returncode == 0:
        h = np.loadtxt(os.path.join(out, "history.dat"))
        ck.le("%s: its history.dat vs the uninterrupted run's (max relative to each column's size)" % label,
              max_rel(h, ref), 1e-12)
    return p.returncode == 0


if restart_into("moved", "restart into a new folder", new_out):
    ck.record("restart into a new folder: the checkpoint's folder keeps its history",
              open(os.path.join(part_out, "history.dat")).read() == before)

# --- a restart in place whose history.dat is gone: refused (exit 2), its frames untouched
gone_out = os.path.join(work, "history_gone")
shutil.copytree(part_out, gone_out)
os.remove(os.path.join(gone_out, "history.dat"))
with open(os.path.join(gone_out, "stopped.txt"), "w") as f:
    f.write("this run stopped at t = 1 s of t_end = 2 s: a record the refusal must keep\n")


def folder(path):
    return {n: open(os.path.join(path, n), "rb").read() for n in sorted(os.listdir(path))}


held = folder(gone_out)
p = run([casca, "run", deck("gone", out=gone_out), "-q", "--restart", os.path.join(gone_out, "checkpoint.h5")])
ck.record("restart in place with history.dat gone: refused (exit 2, 'is missing'), the folder as it was "
          "(every file's name and bytes, its stopped.txt too)",
          p.returncode == 2 and "history.dat is missing" in p.stderr and clean(p) and folder(gone_out) == held,
          first_line(p) + " " + str(sorted(set(held) ^ set(folder(gone_out)))))

# --- a restart into a folder that holds another run's results: the history before the
# checkpoint is the checkpoint folder's, not the folder's own (the stale rows, here the
# earlier run's scaled by 1.5, were kept as this run's), and run.pvd lists no stale frame
stale_out = os.path.join(work, "stale")
shutil.copytree(part_out, stale_out)
os.remove(os.path.join(stale_out, "checkpoint.h5"))
with open(os.path.join(stale_out, "history.dat")) as f:
    head = f.readline()
rows = np.loadtxt(os.path.join(stale_out, "history.dat"))
rows[:, 2:] *= 1.5
np.savetxt(os.path.join(stale_out, "history.dat"), rows, header=head.lstrip("#").strip(), comments="#")
if restart_into("stale", "restart into a folder of another run", stale_out):
    pvd = os.path.join(stale_out, "run.pvd")
    times = [float(t) for t in re.findall(r'timestep="([^"]+)"', open(pvd).read() if os.path.exists(pvd) else "")]
    ck.record("restart into a folder of another run: run.pvd lists only frames from the restart on "
              "(t >= 5 ms)", len(times) > 0 and min(times) >= 5.0e-3 * (1 - 1e-9), str(times[:3]))

# --- two runs into one folder: the second is refused (exit 2) while the first runs, and the
# first ends as if alone (its history equals the uninterrupted run's, no NUL byte)
lock_out = os.path.join(work, "locked")
ldeck = deck("locked", out=lock_out)
first = subprocess.Popen([casca, "run", ldeck, "-q"], env=ENV, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
while first.poll() is None and ckpt_step(os.path.join(lock_out, "checkpoint.h5")) < 10:
    time.sleep(0.01)
second = run([casca, "run", ldeck, "-q"])
first.communicate()
ck.record("a second run into a folder in use: exit 2, the lock named",
          second.returncode == 2 and "in use by another casca run" in second.stderr and clean(second),
          first_line(second))
ck.record("the first run still ends with exit 0", first.returncode == 0, "exit %d" % first.returncode)
raw = open(os.path.join(lock_out, "history.dat"), "rb").read()
hl = np.loadtxt(os.path.join(lock_out, "history.dat"))
ck.record("the first run's history.dat has no NUL byte and all %d rows" % len(ref),
          b"\0" not in raw and hl.shape == ref.shape, str(hl.shape))
if hl.shape == ref.shape:
    ck.le("the first run's history equals the uninterrupted run's (relative)",
          max_rel(hl, ref), 1e-12)
dead = subprocess.Popen(["true"])
dead.wait()
with open(os.path.join(lock_out, "casca.lock"), "w") as f:
    f.write("%d\n" % dead.pid)
p = run([casca, "run", deck("stale", t_end="5.0e-4", out=lock_out), "-q"])
ck.record("a lock left by a dead process is taken over, with a warning (exit 0)",
          p.returncode == 0 and "took over" in p.stderr and str(dead.pid) in p.stderr
          and not os.path.exists(os.path.join(lock_out, "casca.lock")), first_line(p))
zombie = subprocess.Popen(["true"])   # (not waited for: dead, not yet reaped, as a run just killed)
time.sleep(0.5)
with open(os.path.join(lock_out, "casca.lock"), "w") as f:
    f.write("%d\n" % zombie.pid)
p = run([casca, "run", deck("zombie", t_end="5.0e-4", out=lock_out), "-q"])
ck.record("a lock left by a zombie process (dead, not reaped) is taken over, with a warning (exit 0)",
          p.returncode == 0 and "took over" in p.stderr and str(zombie.pid) in p.stderr, first_line(p))
zombie.wait()

# --- shell injection: folder names from the deck and from --out and body names are only
# names: no command runs, the folder is made with the literal name, the plots are drawn
inj = os.path.join(work, "inj")
os.makedirs(inj)
for i, name in enumerate(["d_$(touch M1)", 'd";touch M2;"', "--help", "d`touch M3`"]):
    p = run([casca, "run", deck("inj%d" % i, t_end="5.0e-4", out=name), "-q"], cwd=inj)
    ck.record("dir = %r: exit 0 and the output in a folder of that name" % name,
              p.returncode == 0 and os.path.isfile(os.path.join(inj, name, "history.dat")), first_line(p))
p = run([casca, "run", deck("inj_out", t_end="5.0e-4"), "-q", "--out", "o$(touch M4)"], cwd=inj)
ck.record("--out 'o$(touch M4)': exit 0, folder of that name",
          p.returncode == 0 and os.path.isfile(os.path.join(inj, "o$(touch M4)", "history.dat")), first_line(p))
body = "it''s `touch M5` $(touch M6) a''''b"   # in the deck's quotes: it's ... a''b
named = deck("inj_name", t_end="5.0e-4")
text = open(named).read().replace("'ring1'", "'%s'" % body)
with open(named, "w") as f:
    f.write(text)
p = run([casca, "run", named, "-q", "--out", "named"], cwd=inj)
folder = os.path.join(inj, "named")
pngs = [f for f in os.listdir(folder) if f.endswith(".png")] if os.path.isdir(folder) else []
ck.record("a body name with quotes, backquotes and $(...): exit 0 and all 8 plots",
          p.returncode == 0 and len(pngs) == 8 and "warning" not in p.stderr,
          "%s, %d plots" % (first_line(p), len(pngs)))
marks = [m for m in ("M1", "M2", "M3", "M4", "M5", "M6") if os.path.exists(os.path.join(inj, m))]
ck.record("no injected command ran (no marker file)", not marks, "markers: %s" % marks)

# --- foreign and damaged checkpoints are refused (exit 2) before anything is written
good_ckpt = os.path.join(ref_out, "checkpoint.h5")


def refused(name, deck_path, ckpt_path, needle):
    out = os.path.join(work, "foreign_" + name.split()[0])
    p = run([casca, "run", deck_path, "-q", "--out", out, "--restart", ckpt_path])
    ck.record("checkpoint %s: refused (exit 2, '%s')" % (name, needle),
              p.returncode == 2 and needle in p.stderr and clean(p)
              and not os.path.exists(os.path.join(out, "history.dat")), first_line(p))


def variant(name, old, new):
    path = deck(name)
    text = open(path).read().replace(old, new, 1)
    with open(path, "w") as f:
        f.write(text)
    return path


refused("of another mesh with the same count", variant("moved", "center = 2.06", "center = 2.07"),
        good_ckpt, "another model")
refused("of another material", variant("soft", "young = 210e9", "young = 70e9"), good_ckpt,
        "another model")


def tampered(name, change, needle):
    path = os.path.join(work, "tampered_%s.h5" % name.split()[0])
    shutil.copy(good_ckpt, path)
    with h5py.File(path, "r+") as f:
        change(f)
    refused(name, deck("plain"), path, needle)


def set_ds(f, name, value):
    del f[name]
    f[name] = value


tampered("step-cut level 60", lambda f: set_ds(f, "ints", np.array([60, 0], dtype=np.int32)), "step-cut level")
tampered("contact count 1e8", lambda f: set_ds(f, "ints", np.array([0, 100000000], dtype=np.int32)),
         "contact count")
tampered("time past t_end", lambda f: set_ds(f, "t", np.float64(1.0)), "outside [0, t_end]")
tampered("NaN state", lambda f: f["qd"].__setitem__(5, np.nan), "not finite")
tampered("without fingerprint", lambda f: f.__delitem__("fingerprint"), "no model fingerprint")


def flip_bit(f, name, i, bit):
    a = f[name][...]
    w = a.view(np.uint64)
    w[i] ^= np.uint64(1) << np.uint64(bit)
    f[name][...] = a


tampered("one bit of q flipped", lambda f: flip_bit(f, "q", 100, 50), "do not match their checksum")
tampered("one bit of qdd flipped (lowest)", lambda f: flip_bit(f, "qdd", 7, 0), "do not match their checksum")

# --- an error on rank 0 only (the output folder cannot be made) ends both ranks, exit 2
blocker = os.path.join(work, "a_file")
open(blocker, "w").close()
t0 = time.time()
try:
    p = run([casca, "run", deck("np2", t_end="5.0e-4"), "-q", "--out", os.path.join(blocker, "sub")],
            np_ranks=2, timeout=60)
    ck.record("2 ranks, output folder cannot be made: exit 2, the message once",
              p.returncode == 2 and p.stderr.count("cannot create the output folder") == 1,
              "%s in %.1f s" % (first_line(p), time.time() - t0))
except subprocess.TimeoutExpired:
    ck.record("2 ranks, output folder cannot be made: exit 2", False, "hung for 60 s")

# --- a full disk (small tmpfs, filled at different moments by its size): a message and a
# non-zero exit, never a signal; no file under its final name is cut short, no .part is left
import xml.etree.ElementTree as ET
import meshio


def complete_outputs(folder):
    """names of the files in folder that are not complete and readable ([] if all are)"""
    bad = [f for f in os.listdir(folder) if f.endswith(".part")]
    for f in os.listdir(folder):
        path = os.path.join(folder, f)
        try:
            if f.endswith(".vtu"):
                meshio.read(path)
            elif f.endswith(".h5"):
                with h5py.File(path, "r") as g:
                    list(g)
            elif f == "run.pvd":
                for d in ET.parse(path).getroot().iter("DataSet"):
                    if not os.path.exists(os.path.join(folder, d.get("file"))):
                        bad.append(d.get("file"))
            elif f == "history.dat":
                text = open(path).read()
                ncol = len(text.splitlines()[0].split()) - 1
                if not text.endswith("\n") or any(len(l.split()) != ncol for l in text.splitlines()[1:]):
                    bad.append(f)
        except Exception as e:
            bad.append("%s (%s)" % (f, str(e)[:60]))
    return bad


disk = os.path.join(work, "disk")
os.makedirs(disk)
mounted = False
if os.geteuid() != 0:
    print("SKIP full disk: not root, cannot mount a small tmpfs")
else:
    m = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=600k", "tmpfs", disk], capture_output=True, text=True)
    mounted = m.returncode == 0
    if not mounted:
        print("SKIP full disk: mount -t tmpfs failed: " + m.stderr.strip())
stopped_said = []
try:
    for size in (["100k", "200k", "300k", "420k", "600k"] if mounted else []):
        out = os.path.join(disk, "o")
        shutil.rmtree(out, ignore_errors=True)
        subprocess.run(["mount", "-o", "remount,size=" + size, disk], check=True)
        p = run([casca, "run", deck("disk", t_end="3.0e-3", out=out), "-q"])
        ok = p.returncode in (2, 3) and clean(p) and "disk full" in p.stderr
        bad = complete_outputs(out) if os.path.isdir(out) else []
        ck.record("disk of %s filled by the run: non-zero exit (no signal), a message" % size, ok, first_line(p))
        ck.record("disk of %s: every file under its final name complete, no .part left" % size, not bad,
                  "incomplete: %s" % bad)
        # (README: exit 3 leaves stopped.txt; it had none, nor a restart hint)
        ckpt = os.path.join(out, "checkpoint.h5")
        hint = "restart: casca run %s --restart %s" % (deck("disk", t_end="3.0e-3", out=out), ckpt)
        ck.record("disk of %s: the restart hint printed if and only if a checkpoint is left (%s)"
                  % (size, "one is" if ckpt_step(ckpt) >= 0 else "none is"),
                  (hint in p.stderr) == (ckpt_step(ckpt) >= 0), p.stderr.strip()[-300:])
        stopped = os.path.join(out, "stopped.txt")
        said = open(stopped).read() if os.path.exists(stopped) else ""
        if said:
            stopped_said.append(size)
        ck.record("disk of %s: stopped.txt, if there was room for it, names the failed write" % size,
                  not os.path.exists(stopped) or ("this run stopped at t = " in said and "disk full" in said),
                  said[:200])
    if mounted:
        ck.record("a full disk left stopped.txt where there was room for it (at %s)" % stopped_said,
                  len(stopped_said) > 0)
    if mounted:   # casca mesh writes its file the same way
        shutil.rmtree(os.path.join(disk, "o"), ignore_errors=True)   # (a tmpfs shrinks only when empty)
        subprocess.run(["mount", "-o", "remount,size=100k", disk], check=True)
        msh = os.path.join(disk, "s.msh")
        p = run([casca, "mesh", "sphere", "--n-div", "12", "-o", msh])
        ck.record("casca mesh onto a full disk: exit 2, a message, no file left",
                  p.returncode == 2 and clean(p) and "disk full" in p.stderr
                  and not os.path.exists(msh) and not os.path.exists(msh + ".part"), first_line(p))
finally:
    if mounted:
        subprocess.run(["umount", disk])

# --- bad numbers and names: refused with exit 2 before anything is allocated, the file and
# line named (lines counted in the deck text above: &run on line 1, ring1's &body on line 10)
lines = open(ring).read().split("\n")
first_xyz = lines.index("$Nodes") + 3 + 240   # MSH 4.1: summary, block header, 240 tags
bad_meshes = {}
for name, value in (("nan", "nan 0 0"), ("inf", "1.0 inf 0"), ("huge", "1e308 0 0")):
    path = os.path.join(work, "coord_%s.msh" % name)
    with open(path, "w") as f:
        f.write("\n".join(lines[:first_xyz] + [value] + lines[first_xyz + 1:]))
    bad_meshes[name] = path
fifo = os.path.join(work, "mesh.fifo")
os.mkfifo(fifo)
one_ring = "'ring1', mesh = 'file', file = '%s'" % ring
cases = [  # (name, old, new, substrings of the message)
    ("t_end = Infinity", "t_end = 1.0e-2", "t_end = Infinity", [":2:", "t_end", "below 1e30"]),
    ("dt = NaN", "dt = 5.0e-5", "dt = NaN", [":2:", "dt", "> 0"]),
    ("young = 1e308", "young = 210e9", "young = 1e308", [":13:", "young", "below 1e30"]),
    ("velocity NaN", "velocity = 10.0", "velocity = NaN", [":12:", "velocity", "finite"]),
    ("n_around = 1e9", one_ring, "'ring1', mesh = 'ring', n_around = 1000000000", [":10:", "elements"]),
    ("n_div = 1e5", one_ring, "'ring1', mesh = 'sphere', n_div = 100000", [":10:", "elements"]),
    ("newton_max_iter = 200", "dt = 5.0e-5", "dt = 5.0e-5, newton_max_iter = 200", [":2:", "newton_max_iter", "1..100"]),
    ("max_step_cuts = 60", "dt = 5.0e-5", "dt = 5.0e-5, max_step_cuts = 60", [":2:", "max_step_cuts", "0..30"]),
    ("checkpoint_interval = -Infinity", "checkpoint_interval = 5.0e-4", "checkpoint_interval = -Infinity",
     [":6:", "checkpoint_interval"]),
    ("302-character dir", "dir = 'x'", "dir = '%s'" % ("d" * 302), [":5:", "dir", "longer than 256"]),
    ("200-character body name", "'ring1', mesh", "'%s', mesh" % ("r" * 200), [":11:", "name", "longer than 64"]),
    ("5000-character line", "/\n&body", "/\n!%s\n&body" % ("c" * 5000), [":10:", "line longer than 4096"]),
    ("unknown contact surface", "young = 210e9, poisson = 0.3, density = 7700, thickness = 0.05\n/\n&body",
     "young = 210e9, poisson = 0.3, density = 7700, thickness = 0.05\n/\n&contact\n surface = 'top'\n/\n&body",
     ["&contact", "surface", "faces"]),
    ("FIFO as mesh", one_ring, "'ring1', mesh = 'file', file = '%s'" % fifo, [":11:", "mesh.fifo", "not a regular file"]),
] + [("%s coordinate in the mesh" % n, one_ring, "'ring1', mesh = 'file', file = '%s'" % p,
      ["coord_%s.msh:%d:" % (n, first_xyz + 1), "finite"]) for n, p in bad_meshes.items()]
for name, old, new, needles in cases:
    path = deck("badnum", out="x")
    text = open(path).read()
    assert old in text, old
    with open(path, "w") as f:
        f.write(text.replace(old, new, 1))
    try:
        p = run([casca, "check", path], timeout=30)
        ok = p.returncode == 2 and clean(p) and all(n in p.stderr for n in needles)
        ck.record("%s: exit 2, message with %s" % (name, needles), ok, first_line(p)[:200])
    except subprocess.TimeoutExpired:
        ck.record("%s: exit 2" % name, False, "hung for 30 s")

# --- a restart in the step where contacts are released (issue 16): the trapezoidal rule
# pushes a released constraint back along its row of the step before with lambda - mu
# (newmark.f90), so the checkpoint keeps each constraint's point, side, faces and mu. Two
# rings meeting at their faces, dt = 2^-14 s (times exact in binary: a run stopped at step k
# takes the same steps as one passing through it); restarted from the checkpoint of the step
# before a release, the run ends with the uninterrupted run's history to 1e-6 (measured 0
# before 2026-11-28; since the rings' rim nodes meet each other's rounded rim, 0 from one
# checkpoint and 5e-9 from the other: the first difference is one ulp of a normal in the
# second step after the restart, grown over 60 steps; its source was not found);
# the same checkpoint with only (node, pair, lambda), as casca wrote before, is still read
# (exit 0) and shows what was lost (measured: up to 14% of a column's largest value).
dt2 = 2.0 ** -14
trap_text = f"""&run dt = {dt2!r}, t_end = T_END, beta = 0.25, gamma = 0.5 /
&output dir = 'DIR', vtu = .false., plots = .false., interval = {10 * dt2!r}, checkpoint_interval = {dt2!r},
  track = 1.0, 0.0, 0.0, track_body = 'ring1' /
&body name = 'ring1', mesh = 'file', file = '{ring}', velocity = 10.0, 0.0, 0.0,
  young = 210e9, poisson = 0.3, density = 7700, thickness = 0.05 /
&body name = 'ring2', mesh = 'file', file = '{ring}', center = 2.06, 0.0, 0.0,
  young = 210e9, poisson = 0.3, density = 7700, thickness = 0.05 /
"""


def trap_deck(name, steps, out):
    path = os.path.join(work, name + ".nml")
    with open(path, "w") as f:
        f.write(trap_text.replace("T_END", repr(steps * dt2)).replace("DIR", out))
    return path


trap_ref = os.path.join(work, "trap_ref")
p = run([casca, "run", trap_deck("trap_ref", 80, trap_ref), "-q"])
ck.record("trapezoidal rings, uninterrupted (exit 0)", p.returncode == 0, first_line(p))
tref = np.loadtxt(os.path.join(trap_ref, "history.dat"))
names = open(os.path.join(trap_ref, "history.dat")).readline().lstrip("#").split()
cont = tref[:, names.index("contacts")]
released = [k for k in range(1, len(cont)) if cont[k] < cont[k - 1]]
ck.record("trapezoidal rings: contacts are released at some steps", len(released) >= 2, str(released))
phys = [names.index(n) for n in ("kinetic", "strain", "total", "p1_x", "p1_y", "p1_vx", "p1_vy")]
tscale = np.max(np.abs(tref[:, phys]), axis=0)
for k in released[:2]:
    part = os.path.join(work, "trap_%d" % k)
    p = run([casca, "run", trap_deck("trap_part", k - 1, part), "-q"])
    diffs = {}
    for kind in ("full", "old"):
        ck_path = os.path.join(work, "trap_%d_%s.h5" % (k, kind))
        shutil.copy(os.path.join(part, "checkpoint.h5"), ck_path)
        if kind == "old":   # as casca wrote it before: (node, pair) and lambda per constraint
            with h5py.File(ck_path, "r+") as f:
                ints, reals = f["ints"][()], f["reals"][()]
                nact = int(ints[1])
                old_ints = np.concatenate([ints[:2], ints[2:].reshape(nact, 7)[:, :2].ravel()])
                del f["ints"], f["reals"], f["checksum"]
                f["ints"] = old_ints.astype(np.int32)
                f["reals"] = reals[:nact]
        out = os.path.join(work, "trap_%d_%s_out" % (k, kind))
        shutil.copytree(part, out)
        p = run([casca, "run", trap_deck("trap_rest", 80, out), "-q", "--restart", ck_path])
        h = np.loadtxt(os.path.join(out, "history.dat")) if p.returncode == 0 else None
        ok = h is not None and h.shape == tref.shape
        diffs[kind] = np.max(np.abs(h[:, phys] - tref[:, phys]) / tscale) if ok else np.inf
        ck.record("restart before release step %d from a %s checkpoint: exit 0, all steps" % (k, kind), ok,
                  first_line(p))
        if kind == "old":
            ck.record("restart from an old checkpoint (no checksum): a warning says it cannot be checked",
                      "has no checksum" in p.stderr, p.stderr[-300:])
    ck.le("restart before release step %d: largest difference from the uninterrupted run / column's "
          "largest value (checkpoint without point, side, faces, mu: %.3g)" % (k, diffs["old"]), diffs["full"], 1e-6)

ck.finish()
