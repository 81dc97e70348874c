set terminal pngcairo size 1100,850 font ",10"
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
  plot 0.01 w l dt 2 lc rgb "gray" t "1%", \
       f u (strcol(1) eq "steps" && strstrt(strcol(4), "newmark") == 1 ? $10 : 1/0):n w lp pt 7 lc 1 t "n\\_div 6, Newmark 1, 1.5 (vs its dt->0)", \
       f u (strcol(1) eq "steps" && strcol(4) eq "alpha0.8" ? $10 : 1/0):n w lp pt 5 lc 2 t "n\\_div 6, gen-alpha 0.8 (vs its dt->0)", \
       f u (strcol(1) eq "steps" && strcol(4) eq "alpha0.8 tol" ? $10 : 1/0):n w lp pt 9 lc 3 t "n\\_div 6, gen-alpha 0.8 with tolerance", \
       f u (strcol(1) eq "steps" && strstrt(strcol(4), "single") > 0 ? $10 : 1/0):n w p pt 3 ps 2 lc 4 t "n\\_div 6, single-precision factors", \
       f u (strcol(1) eq "mesh" && strcol(16) eq "ladder" ? $10 : 1/0):n w lp pt 13 ps 1.5 lc 7 t "mesh ladder 4..12 (vs n\\_div 12)", \
       f u (strcol(1) eq "mesh" && strstrt(strcol(16), "ranks") == 1 ? $10 : 1/0):n w p pt 11 ps 2 lc 6 t "2 ranks (vs n\\_div 12)", \
       f u (strcol(1) eq "mesh" && strstrt(strcol(16), "n_div") == 1 ? $10 : 1/0):n w p pt 1 lc rgb "gray" t "n\\_div 6 runs (vs n\\_div 12)"
}
unset multiplot
