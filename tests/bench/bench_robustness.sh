#!/usr/bin/env bash
# Issue-14 benchmarks (figures only; nothing is asserted), docs/performance.md "Robust Newton
# and contact: cost".
# usage: tests/bench/bench_robustness.sh NEW_BUILD_DIR [OLD_BUILD_DIR [REPEATS]]
#   1. the thesis scenes, old and new interleaved (ratio new/old of the wall times);
#   2. a thin sphere striking a clamped plate (issue 14): wall time per step in each output
#      interval against the active contacts, 2 ranks.
set -euo pipefail
NEW=$(cd "$1" && pwd); OLD=${2:+$(cd "$2" && pwd)}; REP=${3:-3}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
T=$(mktemp -d)
wall() {  # wall seconds of: casca run DECK on NP ranks
  local b=$1 np=$2 deck=$3 s
  s=$(date +%s.%N)
  (cd "$ROOT/examples" && mpirun -np "$np" "$b/casca" run "$deck" --out "$T/o" -q > /dev/null)
  echo "$(date +%s.%N) - $s" | bc
}
if [ -n "$OLD" ]; then
  for scene in "two_rings.nml 1" "three_rings.nml 1" "three_spheres.nml 2"; do
    set -- $scene
    n=$REP; [ "$1" = three_spheres.nml ] && n=1
    for i in $(seq "$n"); do
      o=$(wall "$OLD" "$2" "$1"); w=$(wall "$NEW" "$2" "$1")
      printf '%-18s %s rank(s): old %7.2f s  new %7.2f s  new/old %.3f\n' "$1" "$2" "$o" "$w" \
        "$(echo "$w / $o" | bc -l)"
    done
  done
fi
cat > "$T/plate.nml" <<DECK
&run dt = 5e-6, t_end = 2.0e-3, beta = 1.0, gamma = 1.5 /
&output interval = 1e-4, vtu = .false., plots = .false. /
&body name = 'sphere', mesh = 'sphere', radius = 0.5, n_div = 4, center = 0.0, 0.0, 0.501,
  velocity = 0.0, 0.0, -20.0, young = 210e9, poisson = 0.3, density = 7800, thickness = 0.005 /
&body name = 'plate', mesh = 'plate', lx = 1.5, ly = 1.5, nx = 8, ny = 8,
  center = -0.75, -0.75, 0.0, young = 210e9, poisson = 0.3, density = 7800, thickness = 0.01 /
&restraint body = 'plate', box_min = -1.0, -1.0, -1.0, box_max = -0.74, 1.0, 1.0, fix = 'clamped' /
&restraint body = 'plate', box_min = 0.74, -1.0, -1.0, box_max = 1.0, 1.0, 1.0, fix = 'clamped' /
&restraint body = 'plate', box_min = -1.0, -1.0, -1.0, box_max = 1.0, -0.74, 1.0, fix = 'clamped' /
&restraint body = 'plate', box_min = -1.0, 0.74, -1.0, box_max = 1.0, 1.0, 1.0, fix = 'clamped' /
DECK
echo "== sphere (h 5 mm, 20 m/s) onto a clamped plate, 2 ranks: per output interval (20 steps)"
echo "   t_end_ms  contacts  ms_per_step"
mpirun -np 2 "$NEW/casca" run "$T/plate.nml" --out "$T/p" | awk '
  /^step/ { for (i = 1; i <= NF; i++) { if ($i == "t") t = $(i+1); if ($i == "contacts") c = $(i+1);
            if ($i == "elapsed") e = $(i+1); if ($i == "step") s = $(i+1) }
            if (s0 != "") printf "   %8.3f  %8d  %11.1f\n", 1e3*t, c, 1e3*(e - e0)/(s - s0)
            s0 = s; e0 = e }'
rm -rf "$T"
