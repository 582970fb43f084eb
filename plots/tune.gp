# cstab tune: cost against gain. Each gain's cheapest setting that reached
# the target (one point per gain, coloured by log10 of its step or
# tolerance), the best one circled, and the band within 20 % of the best
# cost. usage: gnuplot -e "dir='DIR'" plots/tune.gp
if (!exists("dir")) dir = "."
set datafile separator ","
best_cost = real(system("awk -F, 'NR==2{print $13}' " . dir . "/best.csv"))
best_gain = real(system("awk -F, 'NR==2{print $8}' " . dir . "/best.csv"))
meta = system("awk -F, 'NR==2{print $1\" / \"$2\" / \"$3\": \"$4\" <= \"$5}' " . dir . "/best.csv")
gname = system("awk -F, 'NR==2{print $7}' " . dir . "/best.csv")
lname = system("awk -F, 'NR==1{print $6}' " . dir . "/tune.csv")
ckind = system("awk -F, 'NR==2{print $14}' " . dir . "/best.csv")
set logscale xy
set xlabel "gain " . gname
set ylabel (ckind eq "rhs" ? "cost (RHS evaluations)" : "cost (median wall seconds)")
set cblabel "log10 " . lname
set key outside bottom center horizontal
set title "cstab tune: " . meta
set grid
set terminal pngcairo size 900,650 font ",10"
set output dir . "/tune.png"
plot dir . "/tune.csv" using (strcol(10) eq "yes" ? $5 : 1/0):15:(log10($6)) with points pt 7 ps 1.4 palette title "cheapest setting that reaches the target, per gain", \
     "+" using (best_gain):(best_cost) every ::0::0 with points pt 6 ps 3 lw 2 lc rgb "black" title "best", \
     1.2 * best_cost with lines dt 2 lc rgb "gray40" title "best + 20 %"
