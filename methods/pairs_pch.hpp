// The headers every pair, model and problem unit includes (Eigen, the AD
// scalar, the model contracts and the methods' shared code), precompiled once
// per target: cstab_problems, cstab_methods (the MethodInfo units) and a
// test's own problem class (CSTAB_PCH in CMakeLists.txt, cstab_pch in cmake/cstab_catalog.cmake).
// It saves each unit parsing them again: 1.1 to 1.6 s of the 2.4 to 11 s a
// pair takes (docs/build.md). Only headers that every pair includes anyway
// belong here: a method's or a problem's own header would make touching it
// rebuild every unit of the target.
#pragma once

#include <Eigen/Dense>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/autodiff.hpp"
#include "core/format.hpp"
#include "core/jet.hpp"
#include "core/params.hpp"
#include "core/problem.hpp"
#include "linalg/small_linalg.hpp"
#include "methods/consistent_start.hpp"
#include "methods/contracts.hpp"
#include "methods/mechanical_method.hpp"
#include "methods/model_templates.hpp"
#include "methods/newton_terms.hpp"
#include "methods/ode_jacobian.hpp"
#include "methods/pair.hpp"
