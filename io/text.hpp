// Escaping text for the formats the report writes: HTML, URLs and gnuplot.
#pragma once

#include <string>

namespace cstab {

// HTML text or attribute value: & < > " escaped.
std::string html_escape(const std::string& s);

// A relative URL's path segment (an <img src> of the report): every byte
// but letters, digits and - . _ ~ percent-encoded ("a b#1" -> "a%20b%231").
std::string url_path_escape(const std::string& s);

// A gnuplot string literal for a command (gnuplot -e): single-quoted, a
// quote doubled, nothing else special.
std::string gnuplot_string(const std::string& s);

// A block title in a gnuplot data file (read with columnheader): double-
// quoted; a double quote inside becomes a single quote (data files have no
// escapes).
std::string gnuplot_data_title(const std::string& s);

}  // namespace cstab
