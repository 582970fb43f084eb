// The message a bad input's UsageError carries, for the tests of bad input.
#pragma once

#include <string>

#include "core/params.hpp"

namespace cstab::testing {

// The UsageError message of `f`, "(no error)" if it throws none.
template <class F>
std::string usage_error(F f) {
  try {
    f();
  } catch (const UsageError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace cstab::testing
