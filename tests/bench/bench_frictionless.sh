#!/bin/bash
# The frictionless path against an older build: wall time of the thesis decks (contact
# between mid-surfaces, no friction), old and new interleaved in one sitting.
# usage: tests/bench/bench_frictionless.sh OLD_CASCA OLD_EXAMPLES NEW_CASCA NEW_EXAMPLES [REPEATS]
old=$1; old_ex=$2; new=$3; new_ex=$4; rep=${5:-5}
out=$(mktemp -d)
for deck in two_rings three_rings; do
  for r in $(seq "$rep"); do
    a=$( { /usr/bin/time -f %e "$old" run "$old_ex/$deck.nml" --out "$out/o" -q >/dev/null; } 2>&1 | tail -1)
    b=$( { /usr/bin/time -f %e "$new" run "$new_ex/$deck.nml" --out "$out/n" -q >/dev/null; } 2>&1 | tail -1)
    echo "$deck $r: old $a s, new $b s, new/old $(python3 -c "print(round($b / $a, 3))")"
  done
done
rm -rf "$out"
