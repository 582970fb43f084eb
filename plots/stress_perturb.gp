# Inconsistent starts: peak residual and recovery time against the
# perturbation delta, log-log, one curve per method.
#
#   gnuplot -e "data='DIR/plots/data/stress_perturb_wheel.dat.gz'; out='DIR/plots/stress_perturb_wheel'; \
#               problem='wheel'; lcs='1 2 3'" plots/stress_perturb.gp
#
# data (written by `cstab report`): one block per method, blocks separated
# by two blank lines, each starting with a header line whose first field is
# the label. Columns: 1 delta  2 initial residual  3 peak residual
# 4 recovery time to 1e-10 ("?": never recovered, or the run diverged).
# Writes out.png and out.svg; formats = "png"
# (what `cstab report` passes unless --svg) writes out.png alone.
if (!exists("data") || !exists("out")) {
  print "usage: gnuplot -e \"data='p.dat'; out='basename'\" stress_perturb.gp"
  exit status 2
}
if (!exists("problem")) problem = ""
load system("dirname '".ARG0."'")."/style.gp"
stats data using 1 nooutput
n = STATS_blocks
if (!exists("lcs")) { lcs = ""; do for [i=1:n] { lcs = lcs." ".i } }
lc(i) = int(word(lcs, i + 1))

if (!exists("formats")) formats = "png svg"
do for [fmt in formats] {
  if (fmt eq "png") { set terminal pngcairo enhanced size 1600,700 font "DejaVu Sans,11" } \
  else { set terminal svg enhanced size 1600,700 font "DejaVu Sans,11" dynamic background "#ffffff" }
  set output out.".".fmt
  set multiplot layout 1,2 title sprintf("%s: recovery from an inconsistent start (perturbation delta)", problem) noenhanced
  set logscale xy
  set format x "10^{%L}"
  set format y "10^{%L}"
  set xlabel "perturbation delta"
  set ylabel "peak residual (max over constraints and time)"
  set title "peak residual"
  set key top left font ",10" box opaque noenhanced
  plot for [i=0:n-1] data index i using 1:3 with linespoints lt lc(i) lw 1.5 title columnheader(1), \
       data index 0 using 1:2 with lines dt 2 lc rgb "#777777" title "initial residual"
  set ylabel "time to recover to residual <= 1e-10"
  set title "recovery time (missing: never)"
  unset logscale y
  set logscale y
  plot for [i=0:n-1] data index i using 1:4 with linespoints lt lc(i) lw 1.5 title columnheader(1)
  unset multiplot
  set output
}
