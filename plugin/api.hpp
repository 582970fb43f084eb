// What a cstab plugin is: a shared object that adds methods or problems to
// the cstab it is loaded into (`--plugin PATH`, CSTAB_PLUGIN_PATH, a matrix
// file's `plugins` key). Its code calls the host's (core, linalg, methods,
// problems: the cstab executable exports them), so a plugin links none of
// cstab's libraries and there is one registry.
//
// A plugin defines the three functions below; cstab_add_method and
// cstab_add_problem (cmake/cstab_plugin.cmake, installed with the package)
// generate them, with one translation unit per problem class x method pair
// as in the built-in catalog. docs/plugins.md is the tutorial.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "core/problem.hpp"
#include "cstab/build_id.hpp"
#include "methods/pair.hpp"

// Raised whenever what a plugin and its host share changes shape (this
// header, PairOps, the registrar).
#define CSTAB_PLUGIN_ABI 1

// What a plugin reports as its build and the loader compares with its own:
// the installation's CSTAB_BUILD_ID, then what the compiler of each side
// says (its version, Eigen's static alignment: a problem class's layout
// depends on both, and a method plugin reads it through a pointer).
#define CSTAB_PLUGIN_STR2(x) #x
#define CSTAB_PLUGIN_STR(x) CSTAB_PLUGIN_STR2(x)
#define CSTAB_PLUGIN_BUILD \
  CSTAB_BUILD_ID "; " __VERSION__ "; Eigen static align " CSTAB_PLUGIN_STR(EIGEN_MAX_STATIC_ALIGN_BYTES)

namespace cstab {

// Handed to a plugin's cstab_plugin_register: what it adds. Nothing is
// added to the host's lists until the whole registration has succeeded.
class PluginRegistrar {
 public:
  virtual ~PluginRegistrar() = default;
  // A method and its pairs, one per problem class it was built for, each
  // keyed by typeid(Class).name().
  virtual void add_method(MethodInfo info, std::vector<std::pair<std::string, PairOps>> pairs) = 0;
  // A problem, adapted with the host's methods (ProblemAdapter; its pairs
  // in the order of builtin_methods()).
  virtual void add_problem(std::unique_ptr<Problem> problem) = 0;
};

}  // namespace cstab

extern "C" {
// CSTAB_PLUGIN_ABI of the headers the plugin was compiled with.
int cstab_plugin_abi(void);
// CSTAB_PLUGIN_BUILD as its compiler saw it: the cstab installation it was
// built against (the version, the method catalog and problem classes: a
// problem plugin's pairs are indexed by the catalog; the host's compiler and
// sanitizer setting), then its own compiler version and Eigen alignment.
const char* cstab_plugin_build_id(void);
// Adds the plugin's methods and problems; may throw cstab::UsageError.
void cstab_plugin_register(cstab::PluginRegistrar* registrar);
}
