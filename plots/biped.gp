# Plots of one biped run (Braun-Goldfarb Part II, Fig. 3) from its series.csv:
#
#   gnuplot -e "series='DIR/series.csv'; outdir='DIR'" plots/biped.gp
#
# e.g. after
#   cstab run --problem biped --method braun-goldfarb --integrator rk4 --step 1e-2 \
#             --t-end 100 --sample-every 1e-2 --out DIR
# (a fine --sample-every resolves the transient from the inconsistent start,
# which lasts a few steps).
#
# Writes into outdir:
#   biped_stroboscopic.png  stick figures every `strobe` seconds (default 0.1) over the
#                           whole run, overlaid: the motion is 2 s periodic and symmetric
#                           in time about t = 1 s, so all cycles fall onto 11 poses; colour
#                           = drive phase (1 - cos(pi t))/2                    (Fig. 3a)
#   biped_phase.png         phase plots theta_i' against theta_i, and y' against y (Fig. 3b)
#   biped_residuals.png     |residual| of the 9 constraints against t, log scale, the whole
#                           run and its first 0.5 s                            (Fig. 3c)
# Optional: -e "title='...'" prefixes every plot title; strobe (s) sets the
# stroboscope interval (a multiple of the series' sampling); the geometry (H, lc,
# l1, l2, h, a, b, hat) defaults to problems/biped/biped.hpp (H = 1.78 m) and may be
# overridden the same way.
#
# Columns are looked up by name (header written by `cstab run`): t, x, y,
# theta, theta1..theta6, their *dot velocities, residual_<constraint>.

if (!exists("series") || !exists("outdir")) {
  print "usage: gnuplot -e \"series='DIR/series.csv'; outdir='DIR'\" plots/biped.gp"
  exit status 2
}
if (!exists("title")) title = "biped"
if (!exists("strobe")) strobe = 0.1
if (!exists("H")) H = 1.78
if (!exists("l1")) l1 = 0.245 * H
if (!exists("l2")) l2 = 0.246 * H
if (!exists("hat")) hat = (0.818 - 0.530) * H
if (!exists("lc")) lc = 0.626 * hat
if (!exists("h")) h = 0.039 * H
if (!exists("b")) b = 0.039 * H
if (!exists("a")) a = 0.152 * H - b

set datafile separator ","
set datafile columnheaders
set datafile missing "nan"

cairo = (strstrt(GPVAL_TERMINALS, "pngcairo") > 0)
if (cairo) {
  set terminal pngcairo enhanced size 1100,800 font "DejaVu Sans,12"
} else {
  set terminal png size 1100,800
}
set grid xtics ytics lc rgb "#dddddd"
set border lw 1.2
set key noenhanced
# Nine distinguishable colours for the nine constraints.
set linetype 1 lc rgb "#0072B2" lw 1.5
set linetype 2 lc rgb "#D55E00" lw 1.5
set linetype 3 lc rgb "#009E73" lw 1.5
set linetype 4 lc rgb "#CC79A7" lw 1.5
set linetype 5 lc rgb "#E69F00" lw 1.5
set linetype 6 lc rgb "#56B4E9" lw 1.5
set linetype 7 lc rgb "#000000" lw 1.5
set linetype 8 lc rgb "#999933" lw 1.5
set linetype 9 lc rgb "#882255" lw 1.5

# --- points of the stick figure (problems/biped/biped.hpp) -------------------------
hipx(x, th) = x - lc * cos(th)
hipy(y, th) = y - lc * sin(th)
# Knee and ankle relative to the hip, the foot points relative to the ankle.
kneedx(t1) = -l1 * cos(t1)
kneedy(t1) = -l1 * sin(t1)
ankdx(t1, t2) = kneedx(t1) - l2 * cos(t2)
ankdy(t1, t2) = kneedy(t1) - l2 * sin(t2)
# foot frame point (p, q) rotated by the foot angle f
rotx(p, q, f) = p * cos(f) - q * sin(f)
roty(p, q, f) = p * sin(f) + q * cos(f)

# --- Fig. 3a: stroboscopic stick figure -----------------------------------------
set output outdir."/biped_stroboscopic.png"
set title title.sprintf(": stroboscopic view, every %g s of the whole run", strobe) noenhanced
set size ratio -1
set xlabel "x  [m]"
set ylabel "y  [m]"
set xrange [-0.6:0.9]
set yrange [-0.05:1.85]
set cbrange [0:1]
set cblabel "drive phase (1 - cos(pi t))/2"
set palette defined (0 "#0072B2", 0.5 "#009E73", 1 "#D55E00")
set key top left box opaque
# Rows on the stroboscope grid get their phase, the others NaN (not drawn).
on(t) = abs(t / strobe - floor(t / strobe + 0.5)) < 1e-6
ph(t) = (1 - cos(pi * t)) / 2
hx(t, x, th) = on(t) ? hipx(x, th) : NaN
# HAT: hip -> shoulder; legs: hip -> knee -> ankle -> heel -> toe -> ankle.
plot 0 with lines lc rgb "#777777" lw 3 title "ground", \
     series using (hx($1,$2,$4)):(hipy($3,$4)):(hat*cos($4)):(hat*sin($4)):(ph($1)) \
       with vectors nohead lw 3 lc palette notitle, \
     series using (on($1) ? $2 : NaN):3:(ph($1)) with points pt 7 ps 1.2 lc palette title "HAT centre of mass (x, y)", \
     series using (hx($1,$2,$4)):(hipy($3,$4)):(kneedx($5)):(kneedy($5)):(ph($1)) \
       with vectors nohead lw 2.5 lc palette notitle, \
     series using (hx($1,$2,$4)+kneedx($5)):(hipy($3,$4)+kneedy($5)):(-l2*cos($6)):(-l2*sin($6)):(ph($1)) \
       with vectors nohead lw 2.5 lc palette notitle, \
     series using (hx($1,$2,$4)+ankdx($5,$6)):(hipy($3,$4)+ankdy($5,$6)):(rotx(-b,-h,$7)):(roty(-b,-h,$7)):(ph($1)) \
       with vectors nohead lw 2.5 lc palette notitle, \
     series using (hx($1,$2,$4)+ankdx($5,$6)+rotx(-b,-h,$7)):(hipy($3,$4)+ankdy($5,$6)+roty(-b,-h,$7)):(rotx(a+b,0,$7)):(roty(a+b,0,$7)):(ph($1)) \
       with vectors nohead lw 2.5 lc palette notitle, \
     series using (hx($1,$2,$4)+ankdx($5,$6)):(hipy($3,$4)+ankdy($5,$6)):(rotx(a,-h,$7)):(roty(a,-h,$7)):(ph($1)) \
       with vectors nohead lw 1 lc palette notitle, \
     series using (hx($1,$2,$4)):(hipy($3,$4)):(kneedx($8)):(kneedy($8)):(ph($1)) \
       with vectors nohead lw 1 lc palette notitle, \
     series using (hx($1,$2,$4)+kneedx($8)):(hipy($3,$4)+kneedy($8)):(-l2*cos($9)):(-l2*sin($9)):(ph($1)) \
       with vectors nohead lw 1 lc palette notitle, \
     series using (hx($1,$2,$4)+ankdx($8,$9)):(hipy($3,$4)+ankdy($8,$9)):(rotx(-b,-h,$10)):(roty(-b,-h,$10)):(ph($1)) \
       with vectors nohead lw 1 lc palette notitle, \
     series using (hx($1,$2,$4)+ankdx($8,$9)+rotx(-b,-h,$10)):(hipy($3,$4)+ankdy($8,$9)+roty(-b,-h,$10)):(rotx(a+b,0,$10)):(roty(a+b,0,$10)):(ph($1)) \
       with vectors nohead lw 1 lc palette notitle, \
     series using (hx($1,$2,$4)+ankdx($8,$9)):(hipy($3,$4)+ankdy($8,$9)):(rotx(a,-h,$10)):(roty(a,-h,$10)):(ph($1)) \
       with vectors nohead lw 0.7 lc palette notitle, \
     NaN with lines lw 2.5 lc rgb "#444444" title "leg 1 (forward, heel on the ground): thick", \
     NaN with lines lw 1 lc rgb "#444444" title "leg 2 (backward, toe on the ground): thin"
set size noratio
set size 1,1
unset colorbox
set autoscale
unset cblabel

# --- Fig. 3b: phase plots --------------------------------------------------------
set output outdir."/biped_phase.png"
set multiplot layout 2,4 title title.": phase plots" noenhanced
set key off
names = "theta theta1 theta2 theta3 theta4 theta5 theta6"
do for [i = 1:7] {
  n = word(names, i)
  stats series using n nooutput
  # about three labelled ticks, whatever the range
  span = STATS_max - STATS_min
  step = 10**floor(log10(span / 3))
  step = (span / step > 15) ? 5 * step : (span / step > 6) ? 2 * step : step
  set xtics step
  set title n noenhanced
  set xlabel n." [rad]" noenhanced
  set ylabel n."dot [rad/s]" noenhanced
  plot series using n:n."dot" with lines lt 1 lc rgb "#0072B2"
}
set title "y" noenhanced
stats series using "y" nooutput
span = STATS_max - STATS_min
step = 10**floor(log10(span / 3))
step = (span / step > 15) ? 5 * step : (span / step > 6) ? 2 * step : step
set xtics step
set xlabel "y [m]"
set ylabel "ydot [m/s]"
plot series using "y":"ydot" with lines lc rgb "#0072B2"
unset multiplot
set xtics autofreq

# --- Fig. 3c: residuals --------------------------------------------------------
set output outdir."/biped_residuals.png"
pos(v) = (abs(v) > 0 ? abs(v) : NaN)
rnames = "heel1 toe2 knee1 knee2 trunk foot1 foot2 heel1_fixed toe2_fixed"
set multiplot layout 2,1 title title.": constraint residuals from the inconsistent start" noenhanced
set logscale y
set format y "10^{%L}"
set xlabel "t  [s]"
set ylabel "|residual|"
set key outside right top box opaque noenhanced
set title "whole run" noenhanced
plot for [i = 1:9] series using "t":(pos(column("residual_".word(rnames, i)))) with lines lt i lw 1.5 \
     title word(rnames, i)
set title "first 0.5 s" noenhanced
set xrange [0:0.5]
plot for [i = 1:9] series using "t":(pos(column("residual_".word(rnames, i)))) with linespoints lt i lw 1.5 ps 0.6 \
     title word(rnames, i)
unset multiplot
