#include "plugin/loader.hpp"

#include <dlfcn.h>
#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <climits>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <set>

#include "io/hash.hpp"
#include "plugin/api.hpp"
#include "problems/registry.hpp"

namespace cstab {

namespace {

std::vector<LoadedPlugin>& plugins() {
  static std::vector<LoadedPlugin> list;
  return list;
}

// Collects what a plugin registers; the host's lists change only after the
// whole registration succeeded and every name was checked.
class CollectingRegistrar final : public PluginRegistrar {
 public:
  struct Method {
    MethodInfo info;
    std::vector<std::pair<std::string, PairOps>> pairs;
  };
  void add_method(MethodInfo info, std::vector<std::pair<std::string, PairOps>> pairs) override {
    methods.push_back({std::move(info), std::move(pairs)});
  }
  void add_problem(std::unique_ptr<Problem> problem) override { problems.push_back(std::move(problem)); }

  std::vector<Method> methods;
  std::vector<std::unique_ptr<Problem>> problems;
};

std::string file_identity(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return std::to_string(bytes.size()) + "-" + hash_hex(bytes);
}

// A method or problem name becomes a CSV cell, a case folder and a plot
// file name: letters, digits and . _ + -, starting with a letter or digit.
std::string name_problem(const std::string& what, const std::string& name) {
  if (name.empty()) return "a " + what + " without a name";
  const bool first_ok = std::isalnum(static_cast<unsigned char>(name[0]));
  const bool rest_ok = std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '+' || c == '-';
  });
  if (!first_ok || !rest_ok)
    return what + " name '" + name + "': use letters, digits and . _ + - (starting with a letter or digit)";
  return "";
}

// Why what a plugin registered cannot be added ("" if it can): a missing
// or malformed name, a name given twice or already taken, nothing at all.
std::string refusal_of(const CollectingRegistrar& r) {
  std::set<std::string> names;
  for (const auto& m : r.methods) {
    if (std::string why = name_problem("method", m.info.name); !why.empty()) return why;
    if (!names.insert("m:" + m.info.name).second) return "method '" + m.info.name + "' registered twice";
    for (const auto& known : all_methods())
      if (known.name == m.info.name) {
        const std::string& o = method_origin(known.name);
        return "method '" + m.info.name + "' is already defined (" +
               (o.empty() ? std::string("built in") : "by " + o) + ")";
      }
  }
  for (const auto& p : r.problems) {
    if (!p) return "registers a null problem";
    const std::string name = p->info().name;
    if (std::string why = name_problem("problem", name); !why.empty()) return why;
    if (!names.insert("p:" + name).second) return "problem '" + name + "' registered twice";
    for (const auto& known : all_problems())
      if (known->info().name == name) {
        const std::string& o = problem_origin(name);
        return "problem '" + name + "' is already defined (" + (o.empty() ? std::string("built in") : "by " + o) + ")";
      }
  }
  if (r.methods.empty() && r.problems.empty()) return "registers no method and no problem";
  return "";
}

template <class F>
F symbol(void* handle, const char* name) {
  return reinterpret_cast<F>(::dlsym(handle, name));
}

}  // namespace

void load_plugin(const std::string& given) {
  const std::string who = "plugin " + given + ": ";
  struct stat st {};
  if (given.empty()) throw UsageError("--plugin: empty path");
  if (::stat(given.c_str(), &st) != 0) throw UsageError(who + "no such file");
  if (!S_ISREG(st.st_mode)) throw UsageError(who + "not a regular file");
  char resolved[PATH_MAX];
  if (!::realpath(given.c_str(), resolved)) throw UsageError(who + "cannot resolve the path");
  const std::string path = resolved;
  for (const auto& p : plugins())
    if (p.path == path) return;

  // RTLD_LOCAL: each plugin's three entry points stay its own.
  void* handle = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) {
    const char* err = ::dlerror();
    std::string why = err ? err : "unknown error";
    // dlerror repeats the path; keep what follows it.
    if (why.rfind(path + ": ", 0) == 0) why = why.substr(path.size() + 2);
    throw UsageError(who + "cannot be loaded: " + why);
  }
  const auto abi = symbol<int (*)()>(handle, "cstab_plugin_abi");
  const auto build_id = symbol<const char* (*)()>(handle, "cstab_plugin_build_id");
  const auto do_register = symbol<void (*)(PluginRegistrar*)>(handle, "cstab_plugin_register");
  if (!abi || !build_id || !do_register) {
    ::dlclose(handle);
    throw UsageError(who + "not a cstab plugin (it does not define cstab_plugin_abi, cstab_plugin_build_id "
                           "and cstab_plugin_register)");
  }
  if (abi() != CSTAB_PLUGIN_ABI) {
    const int theirs = abi();
    ::dlclose(handle);
    throw UsageError(who + "built for plugin ABI " + std::to_string(theirs) + ", this cstab has ABI " +
                     std::to_string(CSTAB_PLUGIN_ABI) + ": rebuild it against this installation");
  }
  const std::string theirs = build_id() ? build_id() : "";
  if (theirs != CSTAB_PLUGIN_BUILD) {
    ::dlclose(handle);
    throw UsageError(who + "built against another cstab (build id " + theirs + ", this one is " +
                     CSTAB_PLUGIN_BUILD + "): rebuild it against this installation");
  }
  // From here the plugin's code runs in the host. On any refusal its
  // objects (the registrar's, the exception's) are gone before the handle
  // is closed, and nothing of it has been added.
  LoadedPlugin loaded{path, file_identity(path), {}, {}};
  std::string refusal;
  {
    CollectingRegistrar r;
    try {
      do_register(&r);
      refusal = refusal_of(r);
    } catch (const std::exception& e) {
      refusal = e.what();
    } catch (...) {
      refusal = "its registration threw something that is not a std::exception";
    }
    if (refusal.empty()) {
      // Every name checked: these cannot be refused.
      for (auto& m : r.methods) {
        loaded.methods.push_back(m.info.name);
        add_method(std::move(m.info), path, m.pairs);
      }
      for (auto& p : r.problems) {
        loaded.problems.push_back(p->info().name);
        add_problem(std::move(p), path);
      }
      plugins().push_back(std::move(loaded));  // the handle stays open for the process
      return;
    }
  }
  ::dlclose(handle);
  throw UsageError(who + refusal);
}

void load_plugins_from_environment() {
  const char* env = std::getenv("CSTAB_PLUGIN_PATH");
  if (!env) return;
  const std::string list = env;
  size_t start = 0;
  while (start <= list.size()) {
    const size_t end = list.find(':', start);
    const std::string item = list.substr(start, end == std::string::npos ? std::string::npos : end - start);
    if (!item.empty()) {
      try {
        load_plugin(item);
      } catch (const UsageError& e) {
        throw UsageError(std::string("CSTAB_PLUGIN_PATH: ") + e.what());
      }
    }
    if (end == std::string::npos) break;
    start = end + 1;
  }
}

const std::vector<LoadedPlugin>& loaded_plugins() { return plugins(); }

std::string origin_identity(const std::string& origin) {
  if (origin.empty()) return "";
  for (const auto& p : plugins())
    if (p.path == origin) return p.identity;
  return "";
}

std::vector<std::string> take_plugin_flags(std::vector<std::string>& args) {
  std::vector<std::string> paths, rest;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--") {  // what follows is not ours
      rest.insert(rest.end(), args.begin() + long(i), args.end());
      break;
    }
    if (a == "--plugin") {
      if (i + 1 >= args.size()) throw UsageError("--plugin: missing value");
      paths.push_back(args[++i]);
    } else if (a.rfind("--plugin=", 0) == 0) {
      paths.push_back(a.substr(9));
    } else {
      rest.push_back(a);
    }
  }
  args = std::move(rest);
  return paths;
}

}  // namespace cstab
