# Stiffness: wall time and error against the feedback gain, log-log, one
# curve per method[formulation]/integrator setting.
#
#   gnuplot -e "data='DIR/plots/data/stress_stiff.dat.gz'; out='DIR/plots/stress_stiff'; lcs='1 2'" plots/stress_stiff.gp
#
# data (written by `cstab report`): one block per curve, blocks separated by
# two blank lines, each starting with a header line whose first field is the
# label. Columns: 1 gain (lambda)  2 wall seconds  3 error at the reference
# time  4 largest residual (plotted instead of 3 when has_ref = 0) ("?": diverged, failed or timed out).
# Writes out.png and out.svg; formats = "png"
# (what `cstab report` passes unless --svg) writes out.png alone.
if (!exists("data") || !exists("out")) {
  print "usage: gnuplot -e \"data='s.dat'; out='basename'\" stress_stiff.gp"
  exit status 2
}
if (!exists("has_ref")) has_ref = 1
load system("dirname '".ARG0."'")."/style.gp"
stats data using 1 nooutput
n = STATS_blocks
if (!exists("lcs")) { lcs = ""; do for [i=1:n] { lcs = lcs." ".i } }
lc(i) = int(word(lcs, i + 1))

if (!exists("formats")) formats = "png svg"
do for [fmt in formats] {
  if (fmt eq "png") { set terminal pngcairo enhanced size 1600,750 font "DejaVu Sans,11" } \
  else { set terminal svg enhanced size 1600,750 font "DejaVu Sans,11" dynamic background "#ffffff" }
  set output out.".".fmt
  set multiplot title "stiffness: cost and accuracy against the feedback gain" noenhanced
  set logscale xy
  set format x "10^{%L}"
  set format y "10^{%L}"
  set xlabel "gain lambda (1/s)"
  set origin 0, 0
  set size 0.36, 0.93
  set ylabel "wall time (s, integration only)"
  set title "cost"
  unset key
  plot for [i=0:n-1] data index i using 1:2 with linespoints lt lc(i) lw 1.5 notitle
  set origin 0.36, 0
  set size 0.36, 0.93
  if (has_ref) { set ylabel "max |y - y_{ref}| at the reference time" enhanced; col = 3 } \
  else { set ylabel "largest constraint residual"; col = 4 }
  set title "accuracy"
  set key at screen 0.73, 0.9 left top font ",9" box opaque noenhanced
  plot for [i=0:n-1] data index i using 1:col with linespoints lt lc(i) lw 1.5 title columnheader(1)
  unset multiplot
  set output
}
