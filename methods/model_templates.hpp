// The code every method shares for one mechanical model, compiled once per
// problem instead of once per problem x method pair (docs/build.md):
//   MechanicalTerms<Model>   M, Q, the constraint rows, gamma, energy terms
//                            (methods/mechanical.hpp), by AD or closed forms;
//   NewtonTerms<Model>       the nested-AD Jacobians of the self-stepping
//                            schemes' Newton iterations
//                            (methods/newton_terms.hpp);
//   ConsistentStart<Model>   consistent q, v and the KKT accelerations and
//                            multipliers at t0 (methods/consistent_start.hpp);
//   AccelerationRowTerms<Model>  the derivatives of the acceleration-level
//                            rows, for the index-1 methods' AD Jacobians
//                            (methods/ode_jacobian.hpp).
// A problem's header declares them after its model class, inside namespace
// cstab, with CSTAB_EXTERN_MODEL_TEMPLATES(Model); its CMakeLists.txt has
// them instantiated with cstab_model(Model HEADER) (cmake/cstab_catalog.cmake).
// Without the two lines the problem still builds, each pair unit compiling
// this code itself.
#pragma once

#include "methods/consistent_start.hpp"
#include "methods/mechanical.hpp"
#include "methods/newton_terms.hpp"
#include "methods/ode_jacobian.hpp"

#define CSTAB_EXTERN_MODEL_TEMPLATES(Model)               \
  extern template struct ::cstab::MechanicalTerms<Model>; \
  extern template struct ::cstab::NewtonTerms<Model>;     \
  extern template struct ::cstab::ConsistentStart<Model>; \
  extern template struct ::cstab::AccelerationRowTerms<Model>
