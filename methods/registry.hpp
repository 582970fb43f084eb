// The list of methods. Adding a method: one header in methods/ and one entry
// in MethodList.
#pragma once

#include "methods/minimal.hpp"
#include "methods/pesterev.hpp"

namespace cstab {

template <class... Ms>
struct TypeList {};

using MethodList = TypeList<PesterevMethod, MinimalMethod>;

}  // namespace cstab
