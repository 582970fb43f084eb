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
// "unknown" if it cannot be read (execute-only, deleted or replaced while
// starting); then the matrix reuses no cached result (MatrixRunOptions).
const std::string& binary_identity();
// The identity of the executable at `path` ("<size>-<hash>"), "unknown"
// if it cannot be read: binary_identity() of /proc/self/exe's target.
std::string binary_identity_of(const std::string& path);

// Date, host, OS, CPU, git revision of the source tree, compiler and flags,
// library versions (Eigen, GSL, SUNDIALS, gnuplot), binary path and identity.
Provenance collect_provenance();

std::string format_provenance(const Provenance& p);  // "key: value\n" lines
Provenance parse_provenance(const std::string& text);

// Output of a shell command (trailing newline removed), "" on failure.
std::string command_output(const std::string& command);

}  // namespace cstab
