# made by tests/bench/work_precision.py (strip and rings on 1 rank, spheres on 2); gnuplot work_precision.gp
set terminal pngcairo size 1100,650 noenhanced
set output 'work_precision.png'
set logscale xy
set format y '%.0e'
set xlabel 'wall time [s]'
set ylabel 'error (strip: relative; rings, spheres: m)'
set grid
set key outside right
set title 'casca: error against wall time (ladders of dt for each mesh)'
plot for [s in "strip_wall:nx=10 strip_wall:nx=20 strip_wall:nx=40 two_rings:n_around=20 two_rings:n_around=40 three_spheres:n_div=4 three_spheres:n_div=6"] \
  'work_precision.dat' u ((strcol(1).':'.strcol(2)) eq s ? $6 : 1/0):5 w lp lw 2 t s
