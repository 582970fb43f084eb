// The method list at run time: the built-in catalog, then the methods
// plugins add (plugin/loader.cpp), with the pairs each plugin built.
#include <map>

#include "methods/pair.hpp"

namespace cstab {

namespace {

struct MethodRegistry {
  std::vector<MethodInfo> methods = builtin_methods();
  std::vector<std::string> origins = std::vector<std::string>(methods.size());
  std::map<std::pair<std::string, int>, PairOps> pairs;  // (class key, method index)
};

MethodRegistry& registry() {
  static MethodRegistry r;
  return r;
}

}  // namespace

const std::vector<MethodInfo>& all_methods() { return registry().methods; }

int method_index(const std::string& method) {
  const auto& list = all_methods();
  for (std::size_t i = 0; i < list.size(); ++i)
    if (list[i].name == method) return int(i);
  std::string known;
  for (const auto& m : list) known += (known.empty() ? "" : ", ") + m.name;
  throw UsageError("--method " + method + ": unknown method (known: " + known + ")");
}

void add_method(MethodInfo info, const std::string& origin,
                const std::vector<std::pair<std::string, PairOps>>& pairs) {
  MethodRegistry& r = registry();
  if (info.name.empty()) throw UsageError("a method without a name");
  for (std::size_t i = 0; i < r.methods.size(); ++i)
    if (r.methods[i].name == info.name)
      throw UsageError("method '" + info.name + "' is already defined (" +
                       (r.origins[i].empty() ? std::string("built in") : "by " + r.origins[i]) + ")");
  const int index = int(r.methods.size());
  r.methods.push_back(std::move(info));
  r.origins.push_back(origin);
  for (const auto& [key, ops] : pairs) r.pairs[{key, index}] = ops;
}

const std::string& method_origin(const std::string& method) {
  static const std::string none;
  const MethodRegistry& r = registry();
  for (std::size_t i = 0; i < r.methods.size(); ++i)
    if (r.methods[i].name == method) return r.origins[i];
  return none;
}

const PairOps* plugin_pair(const std::string& class_key, int index) {
  const MethodRegistry& r = registry();
  const auto it = r.pairs.find({class_key, index});
  return it == r.pairs.end() ? nullptr : &it->second;
}

}  // namespace cstab
