# Plots of one wheel run (Pesterev-Matrosov-Morozov's figures) from its
# series.csv:
#
#   gnuplot -e "series='DIR/series.csv'; outdir='DIR'" plots/wheel.gp
#
# Writes into outdir:
#   wheel_residuals.png  |f1|, |f2|, |f3| and |E - E(0)| against t, log scale (paper Fig. 5)
#   wheel_xz.png         wheel centre x(t) and z(t)                        (Fig. 2)
#   wheel_phi.png        pendulum angle phi(t)                             (Fig. 4)
#   wheel_pendulum.png   pendulum mass path (x + l sin phi, z - l cos phi), l = 0.14,
#                        over the curve z = p(x)                            (Fig. 3)
# Optional: -e "title='...'" prefixes every plot title; l (pendulum length)
# may be overridden the same way.
#
# The series' sampling (cstab run --sample-every, default t_end/1000) sets
# the resolution of the curves; use a finer one for the trajectory plot of a
# long run. Columns are looked up by name (header written by `cstab run`): t, x, z,
# phi, residual_contact, residual_rolling, residual_tangency, energy_drift.

if (!exists("series") || !exists("outdir")) {
  print "usage: gnuplot -e \"series='DIR/series.csv'; outdir='DIR'\" plots/wheel.gp"
  exit status 2
}
if (!exists("title")) title = "wheel"
if (!exists("l")) l = 0.14

set datafile separator ","
set datafile columnheaders
set datafile missing "nan"

cairo = (strstrt(GPVAL_TERMINALS, "pngcairo") > 0)
if (cairo) {
  set terminal pngcairo enhanced size 1100,700 font "DejaVu Sans,12"
} else {
  set terminal png size 1100,700
}

set grid xtics ytics lc rgb "#dddddd"
set border lw 1.2
set linetype 1 lc rgb "#0072B2" lw 1.5
set linetype 2 lc rgb "#D55E00" lw 1.5
set linetype 3 lc rgb "#009E73" lw 1.5
set linetype 4 lc rgb "#000000" lw 1.5
set key outside right top box opaque noenhanced

# |v| for a log axis: exact zeros (t = 0, round-off hits) are left out.
pos(v) = (abs(v) > 0 ? abs(v) : NaN)

# --- Fig. 5: residuals and energy drift -----------------------------------
set output outdir."/wheel_residuals.png"
set title title.": constraint residuals and energy drift" noenhanced
set xlabel "t"
set ylabel "absolute value (log scale)"
set logscale y
set format y "10^{%L}"
plot series using "t":(pos(column("residual_contact")))  with lines lt 1 title "|f_1| contact", \
     series using "t":(pos(column("residual_rolling")))  with lines lt 2 title "|f_2| rolling", \
     series using "t":(pos(column("residual_tangency"))) with lines lt 3 title "|f_3| tangency", \
     series using "t":(pos(column("energy_drift")))      with lines lt 4 title "|E(t) - E(0)|"
unset logscale y
set format y "%g"

# --- Fig. 2: x(t), z(t) ----------------------------------------------------
set output outdir."/wheel_xz.png"
set title title.": wheel centre coordinates" noenhanced
set xlabel "t"
set ylabel "x, z"
plot series using "t":"x" with lines lt 1 title "x(t)", \
     series using "t":"z" with lines lt 2 title "z(t)"

# --- Fig. 4: phi(t) --------------------------------------------------------
set output outdir."/wheel_phi.png"
set title title.": pendulum angle" noenhanced
set xlabel "t"
set ylabel "phi  [rad]"
plot series using "t":"phi" with lines lt 1 title "phi(t)"

# --- Fig. 3: pendulum mass trajectory over the curve ------------------------
# A wide canvas: the path is about 4 times wider than tall at equal scales.
if (cairo) {
  set terminal pngcairo enhanced size 1400,620 font "DejaVu Sans,12"
} else {
  set terminal png size 1400,620
}
set output outdir."/wheel_pendulum.png"
set title title.sprintf(": trajectory of the pendulum mass (l = %g)", l) noenhanced
set xlabel "x + l sin(phi)"
set ylabel "z - l cos(phi)"
set size ratio -1
set key outside center top horizontal box opaque
p(x) = x**4 + 0.13*x**3 - 0.5*x**2 - 0.13*x + 0.5
set samples 400
plot series using (column("x") + l*sin(column("phi"))):(column("z") - l*cos(column("phi"))) \
            with lines lt 1 lw 0.8 title "pendulum mass", \
     [-1:1] p(x) with lines lt 4 lw 2 title "curve z = p(x)"
set size noratio

set output
