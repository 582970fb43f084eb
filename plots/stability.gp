# Stability map, coloured by log10(max residual); blown-up runs as crosses.
# mode 'rate' (a gain on rk4/adams/euler): h x decay rate, and the
# integrator's theoretical real stability boundary h*rate = c as a line.
# mode 'step' (any other parameter, or a method's own scheme): h x the
# parameter's value, and the largest stable step per value as a line.
# usage: gnuplot -e "dir='DIR'; mode='rate'" plots/stability.gp
if (!exists("dir")) dir = "."
if (!exists("mode")) mode = "rate"
set datafile separator ","
meta = system("awk -F, 'NR==2{print $1\" / \"$2\" / \"$3\" (swept: \"$4\")\"}' " . dir . "/stability.csv")
set logscale x
set format x "10^{%L}"
set xlabel "step h (s)"
set cblabel "log10 max residual"
set palette defined (0 "#1a9850", 0.5 "#fee08b", 1 "#d73027")
set cbrange [-16:0]
set key outside bottom center horizontal
set title "stability map: " . meta
set grid
if (mode eq "rate") {
  theory = real(system("awk -F, 'NR==2{print $9}' " . dir . "/boundary.csv"))
  set logscale y
  set format y "10^{%L}"
  set ylabel "decay rate of the residual dynamics (1/s)"
} else {
  set ylabel system("awk -F, 'NR==2{print $4}' " . dir . "/stability.csv")
  set offsets 0, 0, graph 0.05, graph 0.05
}
do for [fmt in "png svg"] {
  if (fmt eq "png") { set terminal pngcairo size 900,650 font ",10" } else { set terminal svg size 900,650 font ",10" }
  set output dir . "/stability." . fmt
  if (mode eq "rate") {
    plot dir . "/stability.csv" using (strcol(9) eq "ok" ? $5 : 1/0):7:(log10($10 + 1e-300)) with points pt 5 ps 1.6 palette title "stable (colour: log10 max residual)", \
         "" using (strcol(9) ne "ok" ? $5 : 1/0):7 with points pt 2 ps 1.6 lc rgb "black" title "blew up", \
         theory / x with lines lw 2 lc rgb "blue" title sprintf("theory: h rate = %.4g", theory)
  } else {
    plot dir . "/stability.csv" using (strcol(9) eq "ok" ? $5 : 1/0):6:(log10($10 + 1e-300)) with points pt 5 ps 1.6 palette title "stable (colour: log10 max residual)", \
         "" using (strcol(9) ne "ok" ? $5 : 1/0):6 with points pt 2 ps 1.6 lc rgb "black" title "blew up or failed", \
         dir . "/boundary.csv" using 6:5 with linespoints lw 2 pt 7 lc rgb "blue" title "largest stable step"
  }
}
