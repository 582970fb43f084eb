# Trajectories of one problem: each selected coordinate against time, one
# panel per coordinate, one representative run per method overlaid.
#
#   gnuplot -e "data='DIR/plots/data/wheel_trajectory.dat.gz'; out='DIR/plots/wheel_trajectory'; \
#               problem='wheel'; names='x z theta phi alpha'; lcs='1 2 3'" plots/trajectory.gp
#
# data (written by `cstab report`): one block per run, blocks separated by
# two blank lines, each starting with a header line whose first field is the
# run's label. Columns: 1 t, then one column per name in `names`.
# lcs: per block, the linetype (colour). Writes out.png and out.svg; formats = "png"
# (what `cstab report` passes unless --svg) writes out.png alone.
if (!exists("data") || !exists("out") || !exists("names")) {
  print "usage: gnuplot -e \"data='tr.dat'; out='basename'; names='x y'\" trajectory.gp"
  exit status 2
}
if (!exists("problem")) problem = ""
load system("dirname '".ARG0."'")."/style.gp"

stats data using 1 nooutput
n = STATS_blocks
if (!exists("lcs")) { lcs = ""; do for [i=1:n] { lcs = lcs." ".i } }
lc(i) = int(word(lcs, i + 1))
k = words(names)
cols = (k < 3 ? k : 3)
rows = int((k + cols - 1) / cols)
# The legend takes a free panel slot, or a row of its own.
slots = (rows * cols > k ? rows : rows + 1)

if (!exists("formats")) formats = "png svg"
do for [fmt in formats] {
  if (fmt eq "png") { set terminal pngcairo enhanced size 1600,(120 + 330 * slots) font "DejaVu Sans,11" } \
  else { set terminal svg enhanced size 1600,(120 + 330 * slots) font "DejaVu Sans,11" dynamic background "#ffffff" }
  set output out.".".fmt
  set multiplot layout slots, cols title sprintf("%s: trajectories, one run per method", problem) noenhanced
  unset logscale
  set format x "%g"
  set format y "%g"
  set xlabel "t  [time units of the problem]"
  unset key
  do for [c=1:k] {
    set title word(names, c) noenhanced
    set ylabel word(names, c)."  [problem units]" noenhanced
    plot for [i=0:n-1] data index i using 1:(column(c + 1)) with lines lt lc(i) lw 1.5 notitle
  }
  # Legend panel: empty axes, only the key.
  unset title
  unset xlabel
  unset ylabel
  unset border
  unset tics
  unset grid
  set key center center font ",10" samplen 3 spacing 1.3 noopaque nobox title "run (method/integrator setting)" noenhanced
  set xrange [-2:-1]
  set yrange [0:1]
  plot for [i=0:n-1] data index i using 1:(-1) with lines lt lc(i) lw 2 title columnheader(1) noenhanced
  set border
  set tics
  set grid
  set autoscale
  unset multiplot
  set output
}
