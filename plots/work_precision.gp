# Work-precision diagram of one problem: error against wall time (median of
# the repeats), log-log, one curve per method/integrator, error measured
# four ways (panels): against the reference solution, as significant
# correct digits, as the largest constraint residual, as the largest energy
# (or first-integral) drift. Colour = method, point and dash = integrator.
#
#   gnuplot -e "data='DIR/plots/data/wheel_work_precision.dat.gz'; out='DIR/plots/wheel_work_precision'; \
#               problem='wheel'; drift_label='max |E(t) - E(0)|'; ref_label='t = 5'; \
#               lcs='1 2 1'; pts='7 7 5'; dts='1 1 2'" plots/work_precision.gp
#
# data (written by `cstab report`): one block per curve, blocks separated by
# two blank lines; a block's first line is a header whose first field is the
# curve's name. Columns:
#   1 wall time [s], median of repeats      2 max_i |y_i - y_ref,i| at the reference time
#   3 significant correct digits (mescd)    4 max |constraint residual| over the run
#   5 max |energy or first-integral drift|  6 step size or tolerance
# "?" marks a value that does not exist (no reference, exact zero on a log axis).
# lcs, pts, dts: per block, the linetype (colour), point type and dash type.
# ncstab: the first ncstab blocks are cstab's; the rest are other engines'
# (external cases), listed in the key under the heading "other engines".
# has_ref, has_drift = 0: the run has no reference error / no drift; the
# panel says so instead of plotting.
# Writes out.png and out.svg; formats = "png"
# (what `cstab report` passes unless --svg) writes out.png alone.
if (!exists("data") || !exists("out")) {
  print "usage: gnuplot -e \"data='wp.dat'; out='basename'\" work_precision.gp"
  exit status 2
}
if (!exists("problem")) problem = ""
if (!exists("drift_label")) drift_label = "max |E(t) - E(0)|"
if (!exists("ref_label")) ref_label = "the reference time"
load system("dirname '".ARG0."'")."/style.gp"

stats data using 1 nooutput
n = STATS_blocks
if (!exists("lcs")) { lcs = ""; do for [i=1:n] { lcs = lcs." ".i } }
if (!exists("pts")) { pts = ""; do for [i=1:n] { pts = pts." 7" } }
if (!exists("dts")) { dts = ""; do for [i=1:n] { dts = dts." 1" } }
if (!exists("has_ref")) has_ref = 1
if (!exists("has_drift")) has_drift = 1
if (!exists("ncstab")) ncstab = n
# The key's heading before the other engines' curves (none without them).
heading = (ncstab < n) ? 1 : 0
# (Guarded: gnuplot evaluates a plot's options even for an empty iteration.)
lc(i) = i < words(lcs) ? int(word(lcs, i + 1)) : 1
pt(i) = i < words(pts) ? int(word(pts, i + 1)) : 7
dt(i) = i < words(dts) ? int(word(dts, i + 1)) : 1
# An empty panel with a message, for a quantity the runs do not have.
empty_panel(msg) = sprintf("set label 99 '%s' at graph 0.5, 0.5 center noenhanced; unset logscale y; set yrange [0:1]; set ytics format ''; plot -1 notitle; unset label 99; set autoscale y; set ytics format '%%g'", msg)

# Four panels in the left 80 %, the legend in the right strip.
W = 0.40; H = 0.455
if (!exists("formats")) formats = "png svg"
do for [fmt in formats] {
  if (fmt eq "png") { set terminal pngcairo enhanced size 1600,1100 font "DejaVu Sans,11" } \
  else { set terminal svg enhanced size 1600,1100 font "DejaVu Sans,11" dynamic background "#ffffff" }
  set output out.".".fmt
  set multiplot title sprintf("%s: work-precision (one point per step size or tolerance; wall time = median of repeats)", problem) noenhanced
  set logscale x
  set format x "10^{%L}"
  set xlabel "wall time [s] (integration only)"

  set origin 0, 0.47
  set size W, H
  set logscale y
  set format y "10^{%L}"
  set ylabel sprintf("max_i |y_i - y_{ref,i}| at %s  [problem units]", ref_label)
  set title "error against the reference solution"
  set key at screen 0.815, 0.93 left top font ",10" box opaque samplen 3 spacing 1.15 title "method/integrator" noenhanced
  if (has_ref) {
    plot for [i=0:ncstab-1] data index i using 1:2 with linespoints lt lc(i) pt pt(i) dt dt(i) title columnheader(1) noenhanced, \
         for [j=1:heading] keyentry with points pt -1 title "other engines:", \
         for [i=ncstab:n-1] data index i using 1:2 with linespoints lt lc(i) pt pt(i) dt dt(i) title columnheader(1) noenhanced
  } else {
    # The key still lists the curves: plotted out of range.
    set label 99 "no reference solution within the horizon" at graph 0.5, 0.5 center noenhanced
    set yrange [1:10]
    plot for [i=0:ncstab-1] data index i using 1:(1e-3) with linespoints lt lc(i) pt pt(i) dt dt(i) title columnheader(1) noenhanced, \
         for [j=1:heading] keyentry with points pt -1 title "other engines:", \
         for [i=ncstab:n-1] data index i using 1:(1e-3) with linespoints lt lc(i) pt pt(i) dt dt(i) title columnheader(1) noenhanced
    set autoscale y
    unset label 99
  }

  unset key
  set origin W, 0.47
  unset logscale y
  set format y "%g"
  set ylabel "-log_{10} max_i |y_i - y_{ref,i}| / (1 + |y_{ref,i}|)"
  set title "significant correct digits (higher is better)"
  if (has_ref) {
    plot for [i=0:n-1] data index i using 1:3 with linespoints lt lc(i) pt pt(i) dt dt(i) notitle
  } else {
    eval empty_panel("no reference solution within the horizon")
  }

  set origin 0, 0
  set logscale y
  set format y "10^{%L}"
  set ylabel "max_t |constraint residual|  [constraint units]"
  set title "largest constraint residual over the run"
  plot for [i=0:n-1] data index i using 1:4 with linespoints lt lc(i) pt pt(i) dt dt(i) notitle

  set origin W, 0
  set ylabel drift_label." over the run  [problem units]" noenhanced
  set title "largest drift of the conserved quantity"
  if (has_drift) {
    plot for [i=0:n-1] data index i using 1:5 with linespoints lt lc(i) pt pt(i) dt dt(i) notitle
  } else {
    eval empty_panel("no energy law or first integral")
  }
  unset multiplot
  set output
}
