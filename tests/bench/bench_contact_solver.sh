#!/usr/bin/env bash
# Issue 18 (figures only; nothing is asserted), docs/performance.md "Linear algebra that
# scales with contacts".
# usage: tests/bench/bench_contact_solver.sh BUILD_DIR [REPEATS [OLD_BUILD_DIR]]
#   1. a plate (10 x 10 cells, 961 nodes) lying on a rigid plane and pressed onto it by
#      gravity (every node in contact): time per Newton iteration without contact and with
#      contact for each &contact solver, 1 rank, REPEATS rounds interleaved;
#   2. a plate (4 x 4 cells) tilted by 0.2 degrees, one edge on the plane, falling flat under
#      100 m/s^2 (the contacts sweep across it, the set changes at most iterations): wall
#      time and Newton iterations per solver;
#   3. with OLD_BUILD_DIR: the thesis decks, old default then new default ('auto'),
#      interleaved, REPEATS pairs each: wall time new/old.
# Per Newton iteration (the sum of history.dat's Newton column): the Newton loop's own work
# (casca's timers: elements + analysis + factorisation + solution) and the whole run's wall
# time (after set-up; it adds the contact search, rows and the velocity correction, once per
# step).
set -euo pipefail
NEW=$(cd "$1" && pwd); REP=${2:-3}; OLD=${3:+$(cd "$3" && pwd)}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT

plate() {  # plate.nml for: SOLVER ('off': no contact) TILT_DEGREES T_END CELLS GRAVITY
  local contact="&contact solver = '$1' /"
  [ "$1" = off ] && contact="&contact enabled = .false. /"
  cat > "$T/plate_$1_$2.nml" <<DECK
&run dt = 1e-4, t_end = $3, gravity = 0.0, 0.0, -$5 /
&output interval = $3, vtu = .false., plots = .false. /
&body name = 'plate', mesh = 'plate', lx = 1.0, ly = 1.0, nx = $4, ny = $4,
  center = -0.5, -0.5, $(python3 -c "import math; print(0.005001 + math.sin(math.radians($2)))"),
  rotate_axis = 0.0, 1.0, 0.0, rotate_angle = $2,
  young = 210e9, poisson = 0.3, density = 7800, thickness = 0.01 /
&obstacle name = 'floor', shape = 'plane', point = 0.0, 0.0, 0.0, normal = 0.0, 0.0, 1.0 /
$contact
DECK
  echo "$T/plate_$1_$2.nml"
}
per_iter() {  # BUILD DECK: "newton_ms wall_ms (per iteration) iterations contacts_last wall_s"
  local out="$T/o_$$"
  mpirun -np 1 "$1/casca" run "$2" --out "$out" > "$T/log"
  python3 - "$out/history.dat" "$T/log" <<'PY'
import re, sys, numpy as np
h = np.genfromtxt(sys.argv[1], names=True)
log = open(sys.argv[2]).read()
w = float(re.search(r"^done: .* in ([0-9.]+) s;", log, re.M).group(1))
t = {k: float(v) for k, v in re.findall(r"(\w+) ([0-9.]+) s \(", log.split("time:")[1].splitlines()[0])}
newton = t["elements"] + t["analysis"] + t["factorisation"] + t["solution"]
it = h['newton'].sum()
print(f"{1e3 * newton / it:8.2f} {1e3 * w / it:8.2f} {int(it):6d} {int(h['contacts'][-1]):6d} {w:8.2f}")
PY
  rm -rf "$out"
}

echo "== plate pressed flat on a rigid plane (961 nodes, 6,727 unknowns), 1 rank, 20 steps"
echo "   solver   newton_ms  wall_ms  iterations  contacts  wall_s  newton_ms/no_contact"
for r in $(seq "$REP"); do
  base=$(per_iter "$NEW" "$(plate off 0 2e-3 10 9.81)")
  echo "   off      $base"
  for s in schur saddle auto; do
    f=$(per_iter "$NEW" "$(plate $s 0 2e-3 10 9.81)")
    printf '   %-8s %s  %.2f\n' $s "$f" "$(echo "$f $base" | awk '{print $1 / $6}')"
  done
done

echo "== plate (4 x 4 cells) tilted by 0.2 degrees falling flat onto the plane, 1 rank, 12 ms"
echo "   solver   newton_ms  wall_ms  iterations  contacts  wall_s"
for r in $(seq "$REP"); do
  for s in schur saddle auto; do
    printf '   %-8s %s\n' $s "$(per_iter "$NEW" "$(plate $s 0.2 1.2e-2 4 100.0)")"
  done
done

if [ -n "$OLD" ]; then
  echo "== thesis decks, 1 rank: old default (OLD build) then 'auto' (new), interleaved"
  bash "$ROOT/tests/bench/bench_frictionless.sh" "$OLD/casca" "$ROOT/examples" "$NEW/casca" "$ROOT/examples" "$REP"
fi
