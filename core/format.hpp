// Number formatting shared by CSV writers and tables.
#pragma once

#include <string>

namespace cstab {

// Round-trip exact ("%.17g"), for CSV data.
std::string format_exact(double v);
// Shortest form that reads back to the same double, for labels and keys.
std::string format_short(double v);
// Three significant digits ("%.3g"), for tables people read; "" for NaN.
std::string format_3g(double v);

}  // namespace cstab
