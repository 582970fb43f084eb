# Long horizons: running max |E(t) - E(0)| against t, log-log, one curve per
# method, with t^(1/2) and t^1 guides ending at the first curve's final value.
#
#   gnuplot -e "data='DIR/plots/data/stress_long-ball.dat.gz'; out='DIR/plots/stress_long-ball'; \
#               title='long-ball'; lcs='1 2 3'" plots/stress_long.gp
#
# data (written by `cstab report`): one block per run, blocks separated by
# two blank lines, each starting with a header line whose first field is the
# label. Columns: 1 t  2 running max |E - E(0)| ("?": exactly zero).
# Writes out.png and out.svg; formats = "png"
# (what `cstab report` passes unless --svg) writes out.png alone.
if (!exists("data") || !exists("out")) {
  print "usage: gnuplot -e \"data='l.dat'; out='basename'\" stress_long.gp"
  exit status 2
}
if (!exists("title")) title = ""
load system("dirname '".ARG0."'")."/style.gp"
stats data using 1 nooutput
n = STATS_blocks
if (!exists("lcs")) { lcs = ""; do for [i=1:n] { lcs = lcs." ".i } }
lc(i) = int(word(lcs, i + 1))
stats data using 1 nooutput
tmax = STATS_max
stats data index 0 using 2 nooutput
yend = STATS_max

if (!exists("formats")) formats = "png svg"
do for [fmt in formats] {
  if (fmt eq "png") { set terminal pngcairo enhanced size 1300,800 font "DejaVu Sans,11" } \
  else { set terminal svg enhanced size 1300,800 font "DejaVu Sans,11" dynamic background "#ffffff" }
  set output out.".".fmt
  set title sprintf("%s: growth of the energy error, running max |E(t) - E(0)|", title) noenhanced
  set logscale xy
  set format x "10^{%L}"
  set format y "10^{%L}"
  set xrange [1:tmax]
  set xlabel "t"
  set ylabel "max_{s <= t} |E(s) - E(0)|"
  set key outside right top font ",10" box opaque noenhanced
  plot for [i=0:n-1] data index i using 1:2 with lines lt lc(i) lw 1.8 title columnheader(1), \
       yend * (x / tmax) ** 0.5 with lines dt 2 lc rgb "#777777" title "t^{1/2}" enhanced, \
       yend * (x / tmax) with lines dt 3 lc rgb "#333333" title "t^1" enhanced
  set output
}
