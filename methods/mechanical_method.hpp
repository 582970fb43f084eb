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
    } else {
      throw UsageError(std::string(Derived::kName) + ": problem has no mechanical model");
    }
  }

  // Default: applies to every mechanical model, redundant rows included.
  static constexpr bool kNeedsFullRank = false;
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
    }
  }
};

}  // namespace cstab
