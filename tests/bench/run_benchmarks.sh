#!/usr/bin/env bash
# The benchmarks of docs/performance.md (figures only; nothing is asserted).
# usage: tests/bench/run_benchmarks.sh [BUILD_DIR]     (from the repository root)
set -euo pipefail
B=$(cd "${1:-build}" && pwd)
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
echo "== kernel and one Newton iteration, closed sphere (720 elements), 1 rank"
"$B/tests/bench_solver" 6
echo "== the same on 2 ranks"
mpirun -np 2 "$B/tests/bench_solver" 6
echo "== orderings (factorisation per iteration, 1 rank): 7 = MUMPS automatic, 1 = METIS ND"
for o in 7 1 4 0; do echo "ICNTL(7)=$o: $("$B/tests/bench_solver" 6 $o | grep factorisation)"; done
echo "== whole scenes"
cd examples
for np in 1 2; do
  /usr/bin/time -f "two_rings, $np rank(s): %e s wall" mpirun -np $np "$B/casca" run two_rings.nml --out /tmp/bench_rings -q
done
for np in 1 2; do
  /usr/bin/time -f "three_rings, $np rank(s): %e s wall" mpirun -np $np "$B/casca" run three_rings.nml --out /tmp/bench_3rings -q
done
