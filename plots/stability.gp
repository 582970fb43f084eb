# Stability map: h x rate, coloured by log10(max residual); blown-up runs as
# crosses; the integrator's theoretical real stability boundary h*rate = c
# as a line. usage: gnuplot -e "dir='DIR'" plots/stability.gp
if (!exists("dir")) dir = "."
set datafile separator ","
theory = real(system("awk -F, 'NR==2{print $9}' " . dir . "/boundary.csv"))
meta = system("awk -F, 'NR==2{print $1\" / \"$2\" / \"$3\" (gain: \"$4\")\"}' " . dir . "/stability.csv")
set logscale xy
set format x "10^{%L}"
set format y "10^{%L}"
set xlabel "step h (s)"
set ylabel "decay rate of the residual dynamics (1/s)"
set cblabel "log10 max residual"
set palette defined (0 "#1a9850", 0.5 "#fee08b", 1 "#d73027")
set cbrange [-16:0]
set key outside bottom center horizontal
set title "stability map: " . meta
set grid
do for [fmt in "png svg"] {
  if (fmt eq "png") { set terminal pngcairo size 900,650 font ",10" } else { set terminal svg size 900,650 font ",10" }
  set output dir . "/stability." . fmt
  plot dir . "/stability.csv" using (strcol(9) eq "ok" ? $5 : 1/0):7:(log10($10 + 1e-300)) with points pt 5 ps 1.6 palette title "stable (colour: log10 max residual)", \
       "" using (strcol(9) ne "ok" ? $5 : 1/0):7 with points pt 2 ps 1.6 lc rgb "black" title "blew up", \
       theory / x with lines lw 2 lc rgb "blue" title sprintf("theory: h rate = %.4g", theory)
}
