// Numbers in the text files of a results folder: written in one form, read
// back by one parser.
#pragma once

#include <string>

namespace cstab {

// A cell for a value that may be missing: "" for NaN, else round-trip
// exact (format_exact).
std::string number_cell(double v);

// A count cell: "" for a negative count (not recorded), else the integer.
std::string count_cell(long n);

// A value in a gnuplot data file: 7 significant digits (a relative 1e-7,
// far below a pixel of any picture, and about half the bytes of a
// round-trip exact number), "?" (gnuplot's missing value) if not finite.
std::string plot_cell(double v);
// The same for a log-scale axis: "?" unless finite and > 0.
std::string log_plot_cell(double v);

// A CSV text (a series.csv) with every finite number of its rows after the
// header at plot precision (plot_cell: 7 significant digits); other cells
// (empty, text, "nan", "inf") and the header unchanged. plot_cell of a cell
// read back is the plot_cell of the exact number: a picture drawn from the
// result is the one drawn from the exact series.
std::string csv_at_plot_precision(const std::string& csv);

// The number a whole cell holds ("1e-3", "0.001", "inf", "nan"); NaN if the
// cell is empty or is not entirely a number (leading/trailing blanks aside).
double parse_number(const std::string& text);

// As parse_number, but says whether the cell was a number at all.
bool try_parse_number(const std::string& text, double& value);

}  // namespace cstab
