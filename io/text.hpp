// Escaping text for the formats the report writes: HTML and gnuplot.
#pragma once

#include <string>

namespace cstab {

// HTML text or attribute value: & < > " escaped.
std::string html_escape(const std::string& s);

// A gnuplot string literal for a command (gnuplot -e): single-quoted, a
// quote doubled, nothing else special.
std::string gnuplot_string(const std::string& s);

// A block title in a gnuplot data file (read with columnheader): double-
// quoted; a double quote inside becomes a single quote (data files have no
// escapes).
std::string gnuplot_data_title(const std::string& s);

}  // namespace cstab
