// The list of methods. Adding a method: one header in methods/ and one entry
// in MethodList.
#pragma once

#include "methods/baumgarte.hpp"
#include "methods/braun_goldfarb.hpp"
#include "methods/ida.hpp"
#include "methods/index1.hpp"
#include "methods/minimal.hpp"
#include "methods/pesterev.hpp"

namespace cstab {

template <class... Ms>
struct TypeList {};

using MethodList = TypeList<PesterevMethod, BaumgarteMethod, BraunGoldfarbMethod, ProjectionMethod, NoneMethod,
                            MinimalMethod, IdaIndexOneMethod, IdaGglMethod>;

}  // namespace cstab
