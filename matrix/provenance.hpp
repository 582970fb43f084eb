// Provenance of a results folder: which binary, built how, from which
// source, on which machine, when. `cstab matrix` writes it to
// DIR/provenance.txt ("key: value" lines) and the report shows it.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace cstab {

using Provenance = std::vector<std::pair<std::string, std::string>>;

// Identity of the running executable: its size and a hash of its bytes.
// Part of every case's cache key: a rebuilt binary reruns the matrix.
const std::string& binary_identity();

// Date, host, OS, CPU, git revision of the source tree, compiler and flags,
// library versions (Eigen, GSL, SUNDIALS, gnuplot), binary path and identity.
Provenance collect_provenance();

std::string format_provenance(const Provenance& p);  // "key: value\n" lines
Provenance parse_provenance(const std::string& text);

// Output of a shell command (trailing newline removed), "" on failure.
std::string command_output(const std::string& command);

}  // namespace cstab
