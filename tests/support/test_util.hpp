// Small helpers shared by the tests that drive the cstab binary and its scripts.
#pragma once

#include <stdlib.h>
#include <sys/wait.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "matrix/matrix.hpp"

namespace cstab::testing {

// Single-quoted for /bin/sh.
inline std::string quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    if (c == '\'') out += "'\\''";
    else out += c;
  }
  return out + "'";
}

// A whole file (binary-safe).
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

inline int exit_code(int status) { return WIFEXITED(status) ? WEXITSTATUS(status) : -1; }

// A scratch folder per test, removed afterwards.
class Scratch {
 public:
  explicit Scratch(const std::string& prefix = "cstab_test") {
    std::string tmpl = (std::filesystem::temp_directory_path() / (prefix + "_XXXXXX")).string();
    if (!::mkdtemp(tmpl.data())) throw std::runtime_error("mkdtemp failed");
    dir_ = tmpl;
  }
  ~Scratch() {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;
  const std::filesystem::path& dir() const { return dir_; }

 private:
  std::filesystem::path dir_;
};

// A summary.csv without its timing columns (wall_seconds, observe_seconds):
// what two runs of the same cases must agree on.
inline std::string summary_without_timing(const std::filesystem::path& path) {
  const CsvTable t = read_csv(path.string());
  std::vector<size_t> keep;
  for (size_t i = 0; i < t.header.size(); ++i)
    if (t.header[i] != "wall_seconds" && t.header[i] != "observe_seconds") keep.push_back(i);
  std::string out;
  for (size_t i : keep) out += t.header[i] + ",";
  out += "\n";
  for (const auto& row : t.rows) {
    for (size_t i : keep) out += (i < row.size() ? row[i] : "") + ",";
    out += "\n";
  }
  return out;
}

}  // namespace cstab::testing
