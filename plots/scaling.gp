# Scaling: cost per step and wall time at a fixed accuracy against a
# problem's size parameter, log-log, one curve per method/integrator.
#
#   gnuplot -e "data='DIR/plots/data/n-four-bar_scaling.dat.gz'; out='DIR/plots/n-four-bar_scaling'; param='N'; level='0.001'" plots/scaling.gp
#
# data (written by `cstab report`): one block per curve, blocks separated by
# two blank lines, each starting with a header line whose first field is the
# label (with its fitted exponents). Columns: 1 size  2 wall seconds per
# step  3 wall seconds of the fastest case within the level ("?": none).
# level = "" draws the left panel alone.
# Writes out.png and out.svg; formats = "png"
# (what `cstab report` passes unless --svg) writes out.png alone.
if (!exists("data") || !exists("out")) {
  print "usage: gnuplot -e \"data='s.dat'; out='basename'\" scaling.gp"
  exit status 2
}
if (!exists("param")) param = "N"
if (!exists("problem")) problem = ""
if (!exists("level")) level = ""
load system("dirname '".ARG0."'")."/style.gp"
stats data using 1 nooutput
n = STATS_blocks
if (!exists("lcs")) { lcs = ""; do for [i=1:n] { lcs = lcs." ".i } }
lc(i) = int(word(lcs, i + 1))
panels = (level eq "") ? 1 : 2
w = 0.72 / panels

if (!exists("formats")) formats = "png svg"
do for [fmt in formats] {
  if (fmt eq "png") { set terminal pngcairo enhanced size 1600,750 font "DejaVu Sans,11" } \
  else { set terminal svg enhanced size 1600,750 font "DejaVu Sans,11" dynamic background "#ffffff" }
  set output out.".".fmt
  set multiplot title "scaling of ".problem.": cost against ".param noenhanced
  set logscale xy
  set format y "10^{%L}"
  set xlabel param noenhanced
  set origin 0, 0
  set size w, 0.93
  set ylabel "wall time per step (s)"
  set title "cost per step"
  unset key
  if (panels == 1) { set key at screen 0.735, 0.9 left top Left reverse font ",9" box opaque noenhanced }
  plot for [i=0:n-1] data index i using 1:2 with linespoints lt lc(i) lw 1.5 title columnheader(1)
  if (panels == 2) {
    set origin w, 0
    set size w, 0.93
    set ylabel "wall time (s)"
    set title "wall time at error <= ".level noenhanced
    set key at screen 0.735, 0.9 left top Left reverse font ",9" box opaque noenhanced
    plot for [i=0:n-1] data index i using 1:3 with linespoints lt lc(i) lw 1.5 title columnheader(1)
  }
  unset multiplot
  set output
}
