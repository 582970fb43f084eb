// Small helpers shared by the tests that drive the cstab binary and its scripts.
#pragma once

#include <stdlib.h>
#include <sys/types.h>
#include <sys/wait.h>

#include <cstdio>
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

inline bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// What a shell command printed (stdout and stderr) and its exit code (-1 if
// it did not exit).
struct Outcome {
  int code = -1;
  std::string out;
};

inline Outcome run_shell(const std::string& command) {
  Outcome o;
  std::FILE* p = ::popen((command + " 2>&1").c_str(), "r");
  if (!p) return o;
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) o.out.append(buf, n);
  o.code = exit_code(::pclose(p));
  return o;
}

#ifdef CSTAB_BINARY
// The cstab binary under test with `args` (already quoted for the shell).
inline Outcome cstab_cmd(const std::string& args) { return run_shell(quote(CSTAB_BINARY) + " " + args); }
#endif

// The live (not zombie) processes whose parent is `parent` and whose
// executable is `binary`, from /proc.
inline std::vector<pid_t> children_running(pid_t parent, const std::filesystem::path& binary) {
  namespace fs = std::filesystem;
  std::vector<pid_t> found;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator("/proc", ec)) {
    const std::string name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream stat(e.path() / "stat");
    std::string line;
    std::getline(stat, line);
    // "pid (comm) state ppid ...": the ppid after the closing parenthesis.
    const size_t close = line.rfind(')');
    if (close == std::string::npos) continue;
    std::istringstream rest(line.substr(close + 1));
    std::string state;
    long ppid = 0;
    rest >> state >> ppid;
    if (ppid == parent && state != "Z" && fs::read_symlink(e.path() / "exe", ec) == binary)
      found.push_back(pid_t(std::stol(name)));
  }
  return found;
}

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
