# Residual and drift against time for one problem, all methods overlaid
# (one representative run per method, the same integrator where the matrix
# allows), log scale.
#
#   gnuplot -e "data='DIR/plots/data/wheel_overlay.dat.gz'; out='DIR/plots/wheel_overlay'; \
#               problem='wheel'; drift_label='|E(t) - E(0)|'; lcs='1 2 3'" plots/overlay.gp
#
# data (written by `cstab report`): one block per run, blocks separated by
# two blank lines, each starting with a header line whose first field is the
# run's label. Columns: 1 t [time units]  2 max_i |residual_i(t)|
# 3 |drift of energy or first integral|. "?" marks an exact zero.
# lcs: per block, the linetype (colour). has_drift = 0 omits the drift panel.
# Writes out.png and out.svg; formats = "png"
# (what `cstab report` passes unless --svg) writes out.png alone.
if (!exists("data") || !exists("out")) {
  print "usage: gnuplot -e \"data='ov.dat'; out='basename'\" overlay.gp"
  exit status 2
}
if (!exists("problem")) problem = ""
if (!exists("drift_label")) drift_label = "|E(t) - E(0)|"
if (!exists("has_drift")) has_drift = 1
load system("dirname '".ARG0."'")."/style.gp"

stats data using 1 nooutput
n = STATS_blocks
if (!exists("lcs")) { lcs = ""; do for [i=1:n] { lcs = lcs." ".i } }
lc(i) = int(word(lcs, i + 1))

if (!exists("formats")) formats = "png svg"
do for [fmt in formats] {
  if (fmt eq "png") { set terminal pngcairo enhanced size 1600,1000 font "DejaVu Sans,11" } \
  else { set terminal svg enhanced size 1600,1000 font "DejaVu Sans,11" dynamic background "#ffffff" }
  set output out.".".fmt
  set multiplot title sprintf("%s: constraint residual and drift against time, one run per method", problem) noenhanced
  set xlabel "t  [time units of the problem]"
  unset logscale x
  set format x "%g"
  set logscale y
  set format y "10^{%L}"
  set origin 0, (has_drift ? 0.47 : 0)
  set size 0.75, (has_drift ? 0.455 : 0.93)
  set ylabel "max_i |residual_i(t)|  [constraint units]"
  set title "constraint residual (largest over the constraints)"
  set key at screen 0.765, 0.93 left top font ",10" box opaque samplen 3 spacing 1.15 title "run (method/integrator setting)" noenhanced
  plot for [i=0:n-1] data index i using 1:2 with lines lt lc(i) lw 1.5 title columnheader(1) noenhanced
  if (has_drift) {
    unset key
    set origin 0, 0
    set ylabel drift_label."  [problem units]" noenhanced
    set title "drift of the conserved quantity"
    plot for [i=0:n-1] data index i using 1:3 with lines lt lc(i) lw 1.5 notitle
  }
  unset multiplot
  set output
}
