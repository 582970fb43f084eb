#include "matrix/provenance.hpp"

#include <sys/utsname.h>
#include <unistd.h>

#include <Eigen/Core>
#include <array>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <gsl/gsl_version.h>
#include <sundials/sundials_config.h>
#include <thread>

#include "io/hash.hpp"
#include "matrix/matrix.hpp"
#include "plugin/loader.hpp"

#ifndef CSTAB_SOURCE_ROOT
#define CSTAB_SOURCE_ROOT ""
#endif
#ifndef CSTAB_CXX_FLAGS
#define CSTAB_CXX_FLAGS "unknown"
#endif
#ifndef CSTAB_BUILD_TYPE
#define CSTAB_BUILD_TYPE "unknown"
#endif

namespace cstab {

namespace {

std::string self_path() {
  std::array<char, 4096> buf{};
  const ssize_t n = ::readlink("/proc/self/exe", buf.data(), buf.size() - 1);
  return n > 0 ? std::string(buf.data(), size_t(n)) : std::string();
}

std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) {
      const size_t colon = line.find(':');
      if (colon != std::string::npos) return line.substr(line.find_first_not_of(" \t", colon + 1));
    }
  }
  return "unknown";
}

}  // namespace

std::string command_output(const std::string& command) {
  std::FILE* p = ::popen((command + " 2>/dev/null").c_str(), "r");
  if (!p) return "";
  std::string out;
  std::array<char, 4096> buf{};
  size_t n;
  while ((n = std::fread(buf.data(), 1, buf.size(), p)) > 0) out.append(buf.data(), n);
  ::pclose(p);
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  return out;
}

std::string binary_identity_of(const std::string& path) {
  try {
    const std::string bytes = read_text_file(path);
    return std::to_string(bytes.size()) + "-" + hash_hex(bytes);
  } catch (const std::exception&) {
    return "unknown";
  }
}

const std::string& binary_identity() {
  static const std::string id = binary_identity_of(self_path());
  return id;
}

Provenance collect_provenance() {
  Provenance p;
  char date[64];
  const std::time_t now = std::time(nullptr);
  std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  p.emplace_back("date", date);
  char host[256] = {};
  ::gethostname(host, sizeof host - 1);
  p.emplace_back("host", host);
  struct utsname u {};
  if (::uname(&u) == 0) p.emplace_back("os", std::string(u.sysname) + " " + u.release + " " + u.machine);
  p.emplace_back("cpu", cpu_model());
  p.emplace_back("cpu_threads", std::to_string(std::thread::hardware_concurrency()));

  const std::string src = CSTAB_SOURCE_ROOT;
  std::string rev = src.empty() ? "" : command_output("git -C " + shell_quote(src) + " rev-parse HEAD");
  if (rev.empty()) {
    rev = "unknown (source tree not found)";
  } else {
    const std::string changes =
        command_output("git -C " + shell_quote(src) + " status --porcelain --untracked-files=no | wc -l");
    if (!changes.empty() && changes != "0") rev += " (+ " + changes + " uncommitted changed files)";
  }
  p.emplace_back("git_revision", rev);
  p.emplace_back("source_tree", src);
#if defined(__clang__)
  p.emplace_back("compiler", std::string("clang ") + __clang_version__);
#elif defined(__GNUC__)
  p.emplace_back("compiler", std::string("g++ ") + __VERSION__);
#else
  p.emplace_back("compiler", "unknown");
#endif
  p.emplace_back("build_type", CSTAB_BUILD_TYPE);
  p.emplace_back("cxx_flags", CSTAB_CXX_FLAGS);
  p.emplace_back("eigen", std::to_string(EIGEN_WORLD_VERSION) + "." + std::to_string(EIGEN_MAJOR_VERSION) + "." +
                              std::to_string(EIGEN_MINOR_VERSION));
  p.emplace_back("gsl", GSL_VERSION);
  p.emplace_back("sundials", SUNDIALS_VERSION);
  const std::string gp = command_output("gnuplot --version");
  p.emplace_back("gnuplot", gp.empty() ? "not found" : gp);
  p.emplace_back("binary", self_path());
  p.emplace_back("binary_identity", binary_identity());
  // Each loaded plugin (plugin/loader.hpp): its path, content identity and
  // what it added.
  std::string plugins;
  for (const auto& pl : loaded_plugins()) {
    std::string names;
    for (const auto& m : pl.methods) names += (names.empty() ? "method " : ", method ") + m;
    for (const auto& q : pl.problems) names += (names.empty() ? "problem " : ", problem ") + q;
    plugins += (plugins.empty() ? "" : "; ") + pl.path + " (" + pl.identity + ": " + names + ")";
  }
  p.emplace_back("plugins", plugins.empty() ? "none" : plugins);
  return p;
}

std::string format_provenance(const Provenance& p) {
  std::string out;
  for (const auto& [k, v] : p) {
    std::string value = v;
    for (char& c : value)
      if (c == '\n') c = ' ';
    out += k + ": " + value + "\n";
  }
  return out;
}

Provenance parse_provenance(const std::string& text) {
  Provenance p;
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    const std::string line = text.substr(start, end - start);
    const size_t colon = line.find(": ");
    if (colon != std::string::npos) p.emplace_back(line.substr(0, colon), line.substr(colon + 2));
    start = end + 1;
  }
  return p;
}

}  // namespace cstab
