// Registry plumbing shared by the methods that run on a problem's
// mechanical model (P::mechanical()). A method derived from it provides
// kName, kDescription, generic_params() and
//   template <class Model> static std::unique_ptr<Formulation> make_model(const Model&, const Params&);
// and may replace why_not_model / model_params / kNeedsFullRank (defaults below).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/params.hpp"
#include "core/problem.hpp"
#include "methods/contracts.hpp"
#include "methods/mechanical.hpp"
#include "methods/scalable.hpp"

namespace cstab {

// For methods that need full-rank constraint rows (kNeedsFullRank): the
// reason they do not apply to a model whose rows are redundant at the
// initial state, naming the rank; empty if the rows have full rank.
template <class Model>
std::string redundancy_why_not(const Model& model, const std::string& method) {
  int rows = 0;
  const int rank = initial_constraint_rank(model, &rows);
  if (rank == rows) return {};
  return "the constraint rows are redundant at the initial state (rank " + std::to_string(rank) + " of " +
         std::to_string(rows) + "); " + method +
         " needs full rank (braun-goldfarb, projection, post-stabilization, penalty and ali3p handle redundancy)";
}

template <class Derived>
struct MechanicalMethod {
  template <class P>
  static std::string why_not(const P& p) {
    static_assert(contracts::check_problem<P>());
    if constexpr (contracts::HasMechanical<P>) {
      std::string why = Derived::template why_not_model(p.mechanical());
      if (why.empty() && Derived::kNeedsFullRank) why = redundancy_why_not(p.mechanical(), Derived::kName);
      return why;
    } else if constexpr (contracts::HasScalable<P>) {
      if constexpr (runs_scalable()) {
        return {};
      } else {
        return "runs on fixed-size models only, and this problem's size is a runtime parameter (the runtime-size "
               "path runs none, baumgarte, projection, post-stabilization and ida-ggl: methods/scalable.hpp)";
      }
    } else {
      return "problem has no mechanical (M, Q, constraints) model";
    }
  }

  template <class P>
  static std::vector<ParamSpec> params(const P& p, const std::string& formulation) {
    static_assert(contracts::check_problem<P>());
    check_formulation(p, formulation);
    if constexpr (contracts::HasMechanical<P>) {
      return Derived::template model_params(p.mechanical());
    } else if constexpr (contracts::HasScalable<P>) {
      std::vector<ParamSpec> specs = Derived::generic_params();
      specs.push_back(scalable_kkt_param());
      return specs;
    } else {
      return {};
    }
  }

  template <class P>
  static std::unique_ptr<Formulation> make(const P& p, const std::string& formulation, const Params& params) {
    static_assert(contracts::check_problem<P>());
    check_formulation(p, formulation);
    if constexpr (contracts::HasMechanical<P>) {
      return Derived::template make_model(p.mechanical(), params);
    } else if constexpr (contracts::HasScalable<P> && runs_scalable()) {
      ScalableSettings settings = Derived::scalable_settings(params);
      read_scalable_kkt(params, settings);
      return make_scalable_formulation(p.scalable(), settings);
    } else {
      throw UsageError(std::string(Derived::kName) + ": problem has no mechanical model");
    }
  }

  // Default: applies to every mechanical model, redundant rows included.
  static constexpr bool kNeedsFullRank = false;
  // Methods that also run scalable models (methods/scalable.hpp) define
  //   static ScalableSettings scalable_settings(const Params&);
  // (A function, so that Derived is complete when it is asked.)
  template <class D = Derived>
  static constexpr bool runs_scalable() {
    return requires(const Params& params) {
      { D::scalable_settings(params) } -> std::same_as<ScalableSettings>;
    };
  }
  template <class Model>
  static std::string why_not_model(const Model&) { return {}; }
  template <class Model>
  static std::vector<ParamSpec> model_params(const Model&) { return Derived::generic_params(); }

 private:
  template <class P>
  static void check_formulation(const P& p, const std::string& formulation) {
    if constexpr (contracts::HasMechanical<P>) {
      if (!formulation.empty() && formulation != p.mechanical().formulation_name())
        throw UsageError("--formulation " + formulation + ": " + Derived::kName + " runs on '" +
                         p.mechanical().formulation_name() + "'");
    } else if constexpr (contracts::HasScalable<P>) {
      if (!formulation.empty() && formulation != p.scalable().formulation_name())
        throw UsageError("--formulation " + formulation + ": " + Derived::kName + " runs on '" +
                         p.scalable().formulation_name() + "'");
    }
  }
};

}  // namespace cstab
