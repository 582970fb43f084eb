# The ball in a bowl (Braun-Goldfarb Part II, Figs. 1 and 2) from one run's
# series.csv:
#
#   gnuplot -e "series='DIR/series.csv'; outdir='DIR'" plots/ball.gp
#   (optional: label='braun-goldfarb, rk4, h = 1e-2' for the titles)
#
# Writes
#   outdir/ball_motion.png     (Fig. 1) stroboscopic top view: the path of
#                              the centre rho e_rho projected on (x, y) with
#                              a dot every 1 s, the ball's outline every
#                              0.5 s over the first 10 s; rho, alpha, beta vs t;
#   outdir/ball_errors.png     (Fig. 2) holonomic and rolling residuals,
#                              |E(t) - E(0)|, |eps(t) - eps(0)| and
#                              |spin(t) - spin(0)|, log scale.
# Columns are read by name (see `cstab list` for the coordinate names).
if (!exists("series") || !exists("outdir")) {
  print "usage: gnuplot -e \"series='DIR/series.csv'; outdir='DIR'\" plots/ball.gp"
  exit status 2
}
if (!exists("label")) label = ""
load system("dirname '".ARG0."'")."/style.gp"

set datafile separator comma
set datafile columnheaders
R_bowl = 8.0
r_ball = 1.0

# time step between series rows (for the 1 s stroboscope)
stats series using 1 nooutput
t_end = STATS_max
n_rows = STATS_records
dt_row = t_end / (n_rows > 1 ? n_rows - 1 : 1)
every_s = int(1.0 / dt_row + 0.5)
if (every_s < 1) every_s = 1
every_h = int(0.5 / dt_row + 0.5)
if (every_h < 1) every_h = 1
stats series using "rho" nooutput
rho_lo = STATS_min
rho_hi = STATS_max
rho_pad = (rho_hi - rho_lo > 1e-12 ? 0.1 * (rho_hi - rho_lo) : 0.05)

cx(a, b, rho) = rho * cos(a) * cos(b)
cy(a, b, rho) = rho * cos(a) * sin(b)
pos(x) = (abs(x) > 0 ? abs(x) : 1/0)

title_suffix = (label eq "" ? "" : " (".label.")")

# ---------------------------------------------------------------- Fig. 1
set terminal pngcairo enhanced size 1400,700 font "DejaVu Sans,11"
set output outdir."/ball_motion.png"
set multiplot title "ball in a bowl: motion".title_suffix noenhanced

set origin 0, 0
set size 0.5, 0.95
set size ratio -1
set xlabel "x [m]"
set ylabel "y [m]"
set title "(a) stroboscopic top view: centre path (dot every 1 s), ball every 0.5 s for t <= 10 s"
set xrange [-R_bowl:R_bowl]
set yrange [-R_bowl:R_bowl]
set key below font ",9"
set object 1 circle at 0,0 size R_bowl fs empty border lc rgb "#999999" lw 1.5 back
set object 2 circle at 0,0 size R_bowl - r_ball fs empty border lc rgb "#cccccc" dt 2 back
set cbrange [0:t_end]
set cblabel "t [s]"
set palette defined (0 "#0072B2", 1 "#009E73", 2 "#E69F00", 3 "#D55E00")
plot series using (column(1) <= 10 ? cx(column("alpha"), column("beta"), column("rho")) : 1/0):(cy(column("alpha"), column("beta"), column("rho"))):(r_ball) \
       every every_h with circles fs transparent solid 0.05 border lc rgb "#aaaaaa" title "ball outline (top view)", \
     series using (cx(column("alpha"), column("beta"), column("rho"))):(cy(column("alpha"), column("beta"), column("rho"))):1 \
       with lines lw 1.2 lc palette title "centre", \
     series using (cx(column("alpha"), column("beta"), column("rho"))):(cy(column("alpha"), column("beta"), column("rho"))):1 \
       every every_s with points pt 7 ps 0.5 lc palette notitle
unset object 1
unset object 2
unset colorbox
set key default
unset size
set size noratio
set autoscale
unset key

set xlabel "t [s]"
set origin 0.5, 0.63
set size 0.5, 0.32
set title "(b) rho, alpha, beta against time"
set ylabel "rho [m]"
set yrange [rho_lo - rho_pad:rho_hi + rho_pad]
set format y "%.10g"
plot series using 1:"rho" with lines lt 1
set autoscale y
set format y "%g"
set origin 0.5, 0.32
set size 0.5, 0.31
set title ""
set ylabel "alpha [rad]"
plot series using 1:"alpha" with lines lt 2
set origin 0.5, 0.0
set size 0.5, 0.31
set ylabel "beta [rad]"
plot series using 1:"beta" with lines lt 3
unset multiplot

# ---------------------------------------------------------------- Fig. 2
set terminal pngcairo enhanced size 1400,1000 font "DejaVu Sans,11"
set output outdir."/ball_errors.png"
set multiplot layout 2,2 title "ball in a bowl: constraint, energy and first-integral errors".title_suffix noenhanced
set logscale y
set format y "10^{%L}"
set xlabel "t [s]"
set key inside top right horizontal font ",10" box opaque samplen 2 width 1
max6(a, b, c, d, e, f) = (x1 = abs(a) > abs(b) ? abs(a) : abs(b), x2 = abs(c) > abs(d) ? abs(c) : abs(d), \
                          x3 = abs(e) > abs(f) ? abs(e) : abs(f), x1 = x1 > x2 ? x1 : x2, x1 > x3 ? x1 : x3)
orth_max = 'max6(column("residual_orth11"), column("residual_orth12"), column("residual_orth13"), column("residual_orth22"), column("residual_orth23"), column("residual_orth33"))'

set title "(a) holonomic residuals"
set ylabel "|residual|"
plot series using 1:(pos(column("residual_radius"))) with lines lt 1 title "|{/Symbol r} - (R - r)| [m] (exact zeros not drawn)", \
     series using 1:(pos(@orth_max)) with lines lt 2 title "max_{i<=j} |e_i.e_j - {/Symbol d}_{ij}|"

set title "(b) rolling (non-holonomic) residuals"
set ylabel "|residual| [m/s]"
plot series using 1:(pos(column("residual_roll_alpha"))) with lines lt 3 title "|e_{/Symbol a} . v_P|", \
     series using 1:(pos(column("residual_roll_beta"))) with lines lt 4 title "|e_{/Symbol b} . v_P|"

set title "(c) energy error"
set ylabel "|E(t) - E(0)| [J]"
plot series using 1:(pos(column("energy_drift"))) with lines lt 5 title "|E(t) - E(0)|"

set title "(d) first integrals: {/Symbol e} = {/Symbol b}' cos^2{/Symbol a} + 2r/(7(R-r)) {/Symbol w}_{/Symbol r} sin{/Symbol a}, spin = {/Symbol w}.e_{/Symbol r}"
set ylabel "|I(t) - I(0)|"
plot series using 1:(pos(column("eps_drift"))) with lines lt 1 title "|{/Symbol e}(t) - {/Symbol e}(0)| [rad/s]", \
     series using 1:(pos(column("spin_drift"))) with lines lt 6 title "|spin(t) - spin(0)| [rad/s]"
unset multiplot
