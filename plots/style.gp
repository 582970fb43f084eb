# Shared style for the cstab plots (loaded by the other scripts): a
# colour-blind-safe palette and the PNG/SVG terminal settings; a `data`
# file whose name ends in .gz (`cstab report` writes plots/data/NAME.dat.gz)
# is read through gzip -dc.
set linetype 1 lc rgb "#0072B2" lw 2 pt 7 ps 1.1
set linetype 2 lc rgb "#D55E00" lw 2 pt 5 ps 1.1
set linetype 3 lc rgb "#009E73" lw 2 pt 9 ps 1.3
set linetype 4 lc rgb "#CC79A7" lw 2 pt 11 ps 1.3
set linetype 5 lc rgb "#E69F00" lw 2 pt 13 ps 1.3
set linetype 6 lc rgb "#56B4E9" lw 2 pt 4 ps 1.1
set linetype 7 lc rgb "#000000" lw 2 pt 6 ps 1.1
set linetype 8 lc rgb "#999933" lw 2 pt 8 ps 1.2
set linetype 9 lc rgb "#882255" lw 2 pt 10 ps 1.2
set linetype 10 lc rgb "#44AA99" lw 2 pt 12 ps 1.2
set linetype 11 lc rgb "#117733" lw 2 pt 14 ps 1.2
set linetype 12 lc rgb "#AA4499" lw 2 pt 3 ps 1.2
set linetype cycle 12
set datafile missing "?"
set grid xtics ytics mxtics mytics lc rgb "#dddddd" lw 1
set border lw 1.2
# data = 'a.dat.gz' -> "< gzip -dc 'a.dat.gz' 2>/dev/null", a quote in the
# name as '\''; gzip's complaint when gnuplot stops reading is not an error.
if (exists("data") && strlen(data) > 3 && data[strlen(data) - 2:] eq ".gz") {
  gz_rest = data; gz_quoted = ""
  while (strstrt(gz_rest, "'") > 0) {
    gz_at = strstrt(gz_rest, "'")
    gz_quoted = gz_quoted . gz_rest[1:gz_at - 1] . "'\\''"
    gz_rest = gz_rest[gz_at + 1:]
  }
  data = "< gzip -dc '" . gz_quoted . gz_rest . "' 2>/dev/null"
}
