// The contracts between the suite and what plugs into it, as C++20 concepts
// checked at compile time (docs/extending.md lists every function with its
// signature, whether it is required and what happens when it is absent):
//
//   MechanicalModel<M>  M(t,q) a = Q(t,q,v) + A^T lambda    (methods/mechanical.hpp)
//   AffineModel<M>      X' = F(t,X) + B(t,X) N, outputs f   (methods/affine.hpp)
//   MinimalModel<M>     the problem's own constraint-free ODE (methods/minimal.hpp)
//   HasScalable<P>      P's scalable() is a runtime-size ScalableModel: a class
//                       with virtual functions, checked by the compiler as such
//                       (methods/scalable.hpp)
//   ProblemClass<P>     a class in problems/<name>/ (or a test-local one)
//   MethodType<M>       a method of the catalog (methods/pair.hpp)
//   MethodFor<M, P>     M's why_not / params / make callable on P
//
// The concepts say yes or no. For a readable error the entry points (pair_ops,
// method_info, ProblemAdapter, MechanicalMethod) call check_problem<P>(),
// check_method<M>() ...: one static_assert per broken rule, each one line
// naming the function and the signature expected, before anything else is
// instantiated (the concepts also guard those bodies, so a broken model gives
// these messages and not a page about AutoDiffScalar).
//
// Model functions templated on the scalar S are checked with S = double and
// with the AD scalars the methods call them with (ad::Dual<...>; the
// holonomic rows also with the hyper-dual ad::Nest<ad::Dual<1>>). Only
// declarations are checked: a body that does not compile for an AD scalar is
// still a compiler error of its own, at the call.
//
// Optional functions (a problem's energy, first_integrals, reference; a
// model's closed forms) are used when declared with the exact signature; a
// member NAMED like one with another signature or constness is an error
// (methods/contract_detail.hpp), never a silent skip.
#pragma once

#include <array>
#include <concepts>
#include <cstddef>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "core/autodiff.hpp"
#include "core/formulation.hpp"
#include "core/params.hpp"
#include "core/problem.hpp"
#include "core/vec.hpp"
#include "methods/affine.hpp"
#include "methods/contract_detail.hpp"
#include "methods/mechanical.hpp"
#include "methods/scalable.hpp"

namespace cstab::contracts {

namespace detail {

template <class T>
concept StringLike = std::convertible_to<T, std::string>;

template <class T>
concept ConstraintList = std::convertible_to<T, std::vector<ConstraintInfo>>;

// The observables every model provides.
template <class M>
inline constexpr bool has_formulation_name = requires(const M& m) {
  { m.formulation_name() } -> StringLike;
};
template <class M>
inline constexpr bool has_constraints = requires(const M& m) {
  { m.constraints() } -> ConstraintList;
};

// ---------------------------------------------------------------- mechanical
template <class M>
concept MechanicalSizes = requires {
  typename std::integral_constant<int, M::kCoords>;
  typename std::integral_constant<int, M::kHolonomic>;
  typename std::integral_constant<int, M::kNonholonomic>;
  typename std::integral_constant<bool, M::kHasEnergy>;
} && (M::kCoords > 0) && (M::kHolonomic >= 0) && (M::kNonholonomic >= 0);

// The AD scalars MechanicalTerms evaluates the model with.
template <class M>
using MechanicalDual = ad::Dual<M::kCoords + 1>;
using HyperDual = ad::Nest<ad::Dual<1>>;

template <class M, class S, int nq = M::kCoords>
inline constexpr bool mass_with =
    requires(const M& m, const S& t, const Vec<S, nq>& q, Eigen::Matrix<S, nq, nq>& out) { m.mass(t, q, out); };
template <class M, class S, int nq = M::kCoords>
inline constexpr bool forces_with =
    requires(const M& m, const S& t, const Vec<S, nq>& q, const Vec<S, nq>& v, Vec<S, nq>& out) {
      m.forces(t, q, v, out);
    };
template <class M, class S, int nq = M::kCoords, int nh = M::kHolonomic>
inline constexpr bool holonomic_with =
    requires(const M& m, const S& t, const Vec<S, nq>& q, Vec<S, nh>& out) { m.holonomic(t, q, out); };
template <class M, class S, int nq = M::kCoords, int nn = M::kNonholonomic>
inline constexpr bool nonholonomic_with =
    requires(const M& m, const S& t, const Vec<S, nq>& q, const Vec<S, nq>& v, Vec<S, nn>& out) {
      m.nonholonomic(t, q, v, out);
    };
template <class M, class S, int nq = M::kCoords>
inline constexpr bool energy_with = requires(const M& m, const S& t, const Vec<S, nq>& q, const Vec<S, nq>& v) {
  { m.energy(t, q, v) } -> std::convertible_to<S>;
};
// Callable with double but not with an AD scalar: written without a template.
template <bool with_double, bool with_ad>
inline constexpr bool not_templated = with_double && !with_ad;

template <class M, int nq = M::kCoords>
inline constexpr bool mechanical_initial_state =
    requires(const M& m, Vec<double, nq>& q, Vec<double, nq>& v) { m.initial_state(q, v); };
template <class M, int nq = M::kCoords>
inline constexpr bool mechanical_to_canonical =
    requires(const M& m, double t, const Vec<double, nq>& q, const Vec<double, nq>& v, double* c) {
      m.to_canonical(t, q, v, c);
    };

template <class M>
inline constexpr bool mass_ok = mass_with<M, double> && mass_with<M, MechanicalDual<M>>;
template <class M>
inline constexpr bool forces_ok = forces_with<M, double> && forces_with<M, MechanicalDual<M>>;
template <class M>
inline constexpr bool holonomic_ok =
    M::kHolonomic == 0 ||
    (holonomic_with<M, double> && holonomic_with<M, MechanicalDual<M>> && holonomic_with<M, HyperDual>);
template <class M>
inline constexpr bool nonholonomic_ok =
    M::kNonholonomic == 0 || (nonholonomic_with<M, double> && nonholonomic_with<M, MechanicalDual<M>>);
template <class M>
inline constexpr bool energy_ok = !M::kHasEnergy || (energy_with<M, double> && energy_with<M, MechanicalDual<M>>);
template <class M>
inline constexpr bool closed_form_holonomic_ok = closed_form_holonomic_exact<M> || !names_closed_form_holonomic<M>;
template <class M>
inline constexpr bool closed_form_nonholonomic_ok =
    closed_form_nonholonomic_exact<M> || !names_closed_form_nonholonomic<M>;

template <class M>
inline constexpr bool mechanical_ok = has_formulation_name<M> && has_constraints<M> &&
                                      mechanical_initial_state<M> && mechanical_to_canonical<M> && mass_ok<M> &&
                                      forces_ok<M> && holonomic_ok<M> && nonholonomic_ok<M> && energy_ok<M> &&
                                      closed_form_holonomic_ok<M> && closed_form_nonholonomic_ok<M>;

// ---------------------------------------------------------------- affine
template <class M>
concept AffineSizes = requires {
  typename std::integral_constant<int, M::kStates>;
  typename std::integral_constant<int, M::kInputs>;
  requires std::same_as<std::remove_cv_t<decltype(M::kRelativeDegree)>, std::array<int, std::size_t(M::kInputs)>>;
} && (M::kStates > 0) && (M::kInputs > 0) && [] {
  for (int r : M::kRelativeDegree)
    if (r < 1) return false;
  return true;
}();

// The AD scalar LieJet evaluates the model with (before nesting).
template <class M>
using AffineDual = ad::Dual<M::kInputs + 1>;

template <class M, class S, int n = M::kStates>
inline constexpr bool drift_with =
    requires(const M& m, const S& t, const Vec<S, n>& X, Vec<S, n>& F) { m.drift(t, X, F); };
template <class M, class S, int n = M::kStates, int k = M::kInputs>
inline constexpr bool outputs_with =
    requires(const M& m, const S& t, const Vec<S, n>& X, Vec<S, k>& f) { m.outputs(t, X, f); };
template <class M, int n = M::kStates, int k = M::kInputs>
inline constexpr bool input_matrix_ok = requires(const M& m, double t, const Vec<double, n>& X,
                                                 Eigen::Matrix<double, n, k>& B) { m.input_matrix(t, X, B); };
template <class M, int n = M::kStates>
inline constexpr bool state_initial_state = requires(const M& m, Vec<double, n>& X) { m.initial_state(X); };
template <class M, int n = M::kStates>
inline constexpr bool state_to_canonical =
    requires(const M& m, double t, const Vec<double, n>& X, double* c) { m.to_canonical(t, X, c); };

template <class M>
inline constexpr bool drift_ok = drift_with<M, double> && drift_with<M, AffineDual<M>>;
template <class M>
inline constexpr bool outputs_ok = outputs_with<M, double> && outputs_with<M, AffineDual<M>>;
template <class M>
inline constexpr bool closed_form_jet_ok = closed_form_jet_exact<M> || !names_closed_form_jet<M>;

template <class M>
inline constexpr bool affine_ok = has_formulation_name<M> && has_constraints<M> && state_initial_state<M> &&
                                  state_to_canonical<M> && drift_ok<M> && input_matrix_ok<M> && outputs_ok<M> &&
                                  closed_form_jet_ok<M>;

// ---------------------------------------------------------------- minimal
template <class M>
concept MinimalSizes = requires { typename std::integral_constant<int, M::kStates>; } && (M::kStates > 0);

template <class M, int n = M::kStates>
inline constexpr bool minimal_rhs = requires(const M& m, double t, const Vec<double, n>& y, Vec<double, n>& dy) {
  { m.rhs(t, y, dy) } -> std::convertible_to<bool>;
};
template <class M, int n = M::kStates>
inline constexpr bool minimal_residuals =
    requires(const M& m, double t, const Vec<double, n>& y, double* out) { m.residuals(t, y, out); };

template <class M>
inline constexpr bool minimal_ok = has_formulation_name<M> && has_constraints<M> && state_initial_state<M> &&
                                   state_to_canonical<M> && minimal_rhs<M> && minimal_residuals<M>;

}  // namespace detail

template <class M>
concept MechanicalModel = detail::MechanicalSizes<M> && detail::mechanical_ok<M>;

template <class M>
concept AffineModel = detail::AffineSizes<M> && detail::affine_ok<M>;

template <class M>
concept MinimalModel = detail::MinimalSizes<M> && detail::minimal_ok<M>;

// ---------------------------------------------------------------- problem
namespace detail {

template <class P>
inline constexpr bool info_ok = requires(const P& p) {
  { p.info() } -> std::convertible_to<ProblemInfo>;
};

// The model accessors: absent (and nothing of that name), or callable on a
// const problem and giving a model of the right kind: <name>_const<P>,
// <name>_accessor_ok<P>().
#define CSTAB_CONTRACT_MODEL_ACCESSOR(name, ModelConcept)                             \
  template <class P>                                                                 \
  inline constexpr bool name##_const = requires(const P& p) { p.name(); };           \
  template <class P>                                                                 \
  consteval bool name##_accessor_ok() {                                              \
    if constexpr (name##_const<P>)                                                   \
      return ModelConcept<std::decay_t<decltype(std::declval<const P&>().name())>>; \
    else                                                                             \
      return !names_##name<P>;                                                       \
  }
CSTAB_CONTRACT_MODEL_ACCESSOR(mechanical, MechanicalModel)
CSTAB_CONTRACT_MODEL_ACCESSOR(state_space, AffineModel)
CSTAB_CONTRACT_MODEL_ACCESSOR(minimal, MinimalModel)
#undef CSTAB_CONTRACT_MODEL_ACCESSOR

// The optional observables, with the exact calls ProblemAdapter makes.
template <class P>
inline constexpr bool energy_exact = requires(const P& p, double t, const double* c) {
  { p.energy(t, c) } -> std::convertible_to<double>;
};
template <class P>
inline constexpr bool first_integrals_exact =
    requires(const P& p, double t, const double* c, double* out) { p.first_integrals(t, c, out); };
template <class P>
inline constexpr bool reference_exact = requires(const P& p, double t, double* c) {
  { p.reference(t, c) } -> std::convertible_to<bool>;
};

// Problem parameters: both functions or neither.
template <class P>
inline constexpr bool problem_params_exact = requires(const P& p, const Params& params) {
  { p.problem_params() } -> std::same_as<std::vector<ParamSpec>>;
  { p.with_params(params) } -> std::same_as<P>;
};
template <class P>
inline constexpr bool problem_params_ok =
    problem_params_exact<P> || (!names_problem_params<P> && !names_with_params<P>);

template <class P>
inline constexpr bool problem_ok = info_ok<P> && mechanical_accessor_ok<P>() && state_space_accessor_ok<P>() &&
                                   minimal_accessor_ok<P>() && (energy_exact<P> || !names_energy<P>) &&
                                   (first_integrals_exact<P> || !names_first_integrals<P>) &&
                                   (reference_exact<P> || !names_reference<P>) && problem_params_ok<P>;

}  // namespace detail

template <class P>
concept ProblemClass = std::copy_constructible<P> && detail::problem_ok<P>;

// What the methods test for: the problem has a model of that kind (and it
// satisfies its concept; a broken one is an error at the entry points).
template <class P>
concept HasMechanical = detail::mechanical_const<P> && detail::mechanical_accessor_ok<P>();
template <class P>
concept HasStateSpace = detail::state_space_const<P> && detail::state_space_accessor_ok<P>();
template <class P>
concept HasMinimal = detail::minimal_const<P> && detail::minimal_accessor_ok<P>();

// A runtime-size model (methods/scalable.hpp): a class derived from ScalableModel.
template <class P>
concept HasScalable = requires(const P& p) {
  { p.scalable() } -> std::convertible_to<const ScalableModel&>;
};

template <class P>
concept HasEnergy = detail::energy_exact<P>;
template <class P>
concept HasFirstIntegrals = detail::first_integrals_exact<P>;
template <class P>
concept HasReference = detail::reference_exact<P>;
template <class P>
concept HasProblemParams = detail::problem_params_exact<P>;

// ---------------------------------------------------------------- method
namespace detail {
template <class M>
inline constexpr bool name_ok = requires {
  { M::kName } -> std::convertible_to<const char*>;
};
template <class M>
inline constexpr bool description_ok = requires {
  { M::kDescription } -> std::convertible_to<const char*>;
};
template <class M>
inline constexpr bool generic_params_ok = requires {
  { M::generic_params() } -> std::convertible_to<std::vector<ParamSpec>>;
};
template <class M, class P>
inline constexpr bool why_not_ok = requires(const P& p) {
  { M::why_not(p) } -> std::convertible_to<std::string>;
};
template <class M, class P>
inline constexpr bool params_ok = requires(const P& p, const std::string& f) {
  { M::params(p, f) } -> std::convertible_to<std::vector<ParamSpec>>;
};
template <class M, class P>
inline constexpr bool make_ok = requires(const P& p, const std::string& f, const Params& prm) {
  { M::make(p, f, prm) } -> std::convertible_to<std::unique_ptr<Formulation>>;
};
}  // namespace detail

template <class M>
concept MethodType = detail::name_ok<M> && detail::description_ok<M> && detail::generic_params_ok<M>;

template <class M, class P>
concept MethodFor = MethodType<M> && detail::why_not_ok<M, P> && detail::params_ok<M, P> && detail::make_ok<M, P>;

// ---------------------------------------------------------------- diagnostics
// Each returns true; a broken rule is a static_assert failing inside, one
// line each. Call them where a type enters the suite.

template <class M>
constexpr bool check_mechanical_model() {
  if constexpr (!detail::MechanicalSizes<M>) {
    static_assert(detail::MechanicalSizes<M>,
                  "cstab contract: a mechanical model needs `static constexpr int kCoords (> 0), kHolonomic, "
                  "kNonholonomic (>= 0); static constexpr bool kHasEnergy;`");
  } else {
    using D = detail::MechanicalDual<M>;
    static_assert(detail::has_formulation_name<M>,
                  "cstab contract: mechanical model: missing `std::string formulation_name() const`");
    static_assert(detail::has_constraints<M>,
                  "cstab contract: mechanical model: missing `std::vector<ConstraintInfo> constraints() const` "
                  "(holonomic rows first)");
    static_assert(detail::mechanical_initial_state<M>,
                  "cstab contract: mechanical model: missing `void initial_state(Vec<double, kCoords>& q, "
                  "Vec<double, kCoords>& v) const`");
    static_assert(detail::mechanical_to_canonical<M>,
                  "cstab contract: mechanical model: missing `void to_canonical(double t, const Vec<double, kCoords>& "
                  "q, const Vec<double, kCoords>& v, double* canonical) const`");
    constexpr bool mass_d = detail::mass_with<M, double>, mass_ad = detail::mass_with<M, D>;
    static_assert(!detail::not_templated<mass_d, mass_ad>,
                  "cstab contract: mechanical model: mass must be a template on the scalar type (it is called with "
                  "double and with AD scalars): `template <class S> void mass(const S& t, const Vec<S, kCoords>& q, "
                  "Eigen::Matrix<S, kCoords, kCoords>& M) const`");
    static_assert(mass_d,
                  "cstab contract: mechanical model: missing `template <class S> void mass(const S& t, const Vec<S, "
                  "kCoords>& q, Eigen::Matrix<S, kCoords, kCoords>& M) const`");
    constexpr bool forces_d = detail::forces_with<M, double>, forces_ad = detail::forces_with<M, D>;
    static_assert(!detail::not_templated<forces_d, forces_ad>,
                  "cstab contract: mechanical model: forces must be a template on the scalar type (it is called with "
                  "double and with AD scalars): `template <class S> void forces(const S& t, const Vec<S, kCoords>& q, "
                  "const Vec<S, kCoords>& v, Vec<S, kCoords>& Q) const`");
    static_assert(forces_d,
                  "cstab contract: mechanical model: missing `template <class S> void forces(const S& t, const Vec<S, "
                  "kCoords>& q, const Vec<S, kCoords>& v, Vec<S, kCoords>& Q) const`");
    if constexpr (M::kHolonomic > 0) {
      constexpr bool d = detail::holonomic_with<M, double>;
      constexpr bool all_ad = detail::holonomic_with<M, D> && detail::holonomic_with<M, detail::HyperDual>;
      static_assert(!detail::not_templated<d, all_ad>,
                    "cstab contract: mechanical model: holonomic must be a template on the scalar type (it is called "
                    "with double and with AD scalars): `template <class S> void holonomic(const S& t, const Vec<S, "
                    "kCoords>& q, Vec<S, kHolonomic>& phi) const`");
      static_assert(d,
                    "cstab contract: mechanical model with kHolonomic > 0: missing `template <class S> void "
                    "holonomic(const S& t, const Vec<S, kCoords>& q, Vec<S, kHolonomic>& phi) const`");
    }
    if constexpr (M::kNonholonomic > 0) {
      constexpr bool d = detail::nonholonomic_with<M, double>, a = detail::nonholonomic_with<M, D>;
      static_assert(!detail::not_templated<d, a>,
                    "cstab contract: mechanical model: nonholonomic must be a template on the scalar type (it is "
                    "called with double and with AD scalars): `template <class S> void nonholonomic(const S& t, "
                    "const Vec<S, kCoords>& q, const Vec<S, kCoords>& v, Vec<S, kNonholonomic>& psi) const`");
      static_assert(d,
                    "cstab contract: mechanical model with kNonholonomic > 0: missing `template <class S> void "
                    "nonholonomic(const S& t, const Vec<S, kCoords>& q, const Vec<S, kCoords>& v, Vec<S, "
                    "kNonholonomic>& psi) const`");
    }
    if constexpr (M::kHasEnergy) {
      constexpr bool d = detail::energy_with<M, double>, a = detail::energy_with<M, D>;
      static_assert(!detail::not_templated<d, a>,
                    "cstab contract: mechanical model: energy must be a template on the scalar type (it is called "
                    "with AD scalars): `template <class S> S energy(const S& t, const Vec<S, kCoords>& q, const "
                    "Vec<S, kCoords>& v) const`");
      static_assert(d,
                    "cstab contract: mechanical model with kHasEnergy = true: missing `template <class S> S "
                    "energy(const S& t, const Vec<S, kCoords>& q, const Vec<S, kCoords>& v) const`");
    }
    static_assert(detail::closed_form_holonomic_ok<M>, CSTAB_CONTRACT_MSG_CLOSED_FORM_HOLONOMIC);
    static_assert(detail::closed_form_nonholonomic_ok<M>, CSTAB_CONTRACT_MSG_CLOSED_FORM_NONHOLONOMIC);
  }
  return true;
}

template <class M>
constexpr bool check_affine_model() {
  if constexpr (!detail::AffineSizes<M>) {
    static_assert(detail::AffineSizes<M>,
                  "cstab contract: an affine model needs `static constexpr int kStates, kInputs (> 0); static "
                  "constexpr std::array<int, kInputs> kRelativeDegree (each >= 1);`");
  } else {
    using D = detail::AffineDual<M>;
    static_assert(detail::has_formulation_name<M>,
                  "cstab contract: affine model: missing `std::string formulation_name() const`");
    static_assert(detail::has_constraints<M>,
                  "cstab contract: affine model: missing `std::vector<ConstraintInfo> constraints() const` (one per "
                  "output)");
    static_assert(detail::state_initial_state<M>,
                  "cstab contract: affine model: missing `void initial_state(Vec<double, kStates>& X) const`");
    static_assert(detail::state_to_canonical<M>,
                  "cstab contract: affine model: missing `void to_canonical(double t, const Vec<double, kStates>& X, "
                  "double* canonical) const`");
    constexpr bool drift_d = detail::drift_with<M, double>, drift_ad = detail::drift_with<M, D>;
    static_assert(!detail::not_templated<drift_d, drift_ad>,
                  "cstab contract: affine model: drift must be a template on the scalar type (it is called with "
                  "double and with AD scalars): `template <class S> void drift(const S& t, const Vec<S, kStates>& X, "
                  "Vec<S, kStates>& F) const`");
    static_assert(drift_d,
                  "cstab contract: affine model: missing `template <class S> void drift(const S& t, const Vec<S, "
                  "kStates>& X, Vec<S, kStates>& F) const`");
    static_assert(detail::input_matrix_ok<M>,
                  "cstab contract: affine model: missing `void input_matrix(double t, const Vec<double, kStates>& X, "
                  "Eigen::Matrix<double, kStates, kInputs>& B) const`");
    constexpr bool out_d = detail::outputs_with<M, double>, out_ad = detail::outputs_with<M, D>;
    static_assert(!detail::not_templated<out_d, out_ad>,
                  "cstab contract: affine model: outputs must be a template on the scalar type (it is called with "
                  "double and with AD scalars): `template <class S> void outputs(const S& t, const Vec<S, kStates>& "
                  "X, Vec<S, kInputs>& f) const`");
    static_assert(out_d,
                  "cstab contract: affine model: missing `template <class S> void outputs(const S& t, const Vec<S, "
                  "kStates>& X, Vec<S, kInputs>& f) const`");
    static_assert(detail::closed_form_jet_ok<M>, CSTAB_CONTRACT_MSG_CLOSED_FORM_JET);
  }
  return true;
}

template <class M>
constexpr bool check_minimal_model() {
  if constexpr (!detail::MinimalSizes<M>) {
    static_assert(detail::MinimalSizes<M>, "cstab contract: a minimal model needs `static constexpr int kStates (> 0);`");
  } else {
    static_assert(detail::has_formulation_name<M>,
                  "cstab contract: minimal model: missing `std::string formulation_name() const`");
    static_assert(detail::has_constraints<M>,
                  "cstab contract: minimal model: missing `std::vector<ConstraintInfo> constraints() const`");
    static_assert(detail::state_initial_state<M>,
                  "cstab contract: minimal model: missing `void initial_state(Vec<double, kStates>& y) const`");
    static_assert(detail::minimal_rhs<M>,
                  "cstab contract: minimal model: missing `bool rhs(double t, const Vec<double, kStates>& y, "
                  "Vec<double, kStates>& dy) const`");
    static_assert(detail::state_to_canonical<M>,
                  "cstab contract: minimal model: missing `void to_canonical(double t, const Vec<double, kStates>& y, "
                  "double* canonical) const`");
    static_assert(detail::minimal_residuals<M>,
                  "cstab contract: minimal model: missing `void residuals(double t, const Vec<double, kStates>& y, "
                  "double* out) const`");
  }
  return true;
}

template <class P>
constexpr bool check_problem() {
  static_assert(std::copy_constructible<P>, "cstab contract: a problem class must be copy-constructible");
  static_assert(detail::info_ok<P>, "cstab contract: problem: missing `ProblemInfo info() const`");
  if constexpr (detail::mechanical_const<P>) {
    check_mechanical_model<std::decay_t<decltype(std::declval<const P&>().mechanical())>>();
  } else {
    static_assert(!detail::names_mechanical<P>,
                  "cstab contract: problem declares mechanical, but not as `const Model& mechanical() const`");
  }
  if constexpr (detail::state_space_const<P>) {
    check_affine_model<std::decay_t<decltype(std::declval<const P&>().state_space())>>();
  } else {
    static_assert(!detail::names_state_space<P>,
                  "cstab contract: problem declares state_space, but not as `const Model& state_space() const`");
  }
  if constexpr (detail::minimal_const<P>) {
    check_minimal_model<std::decay_t<decltype(std::declval<const P&>().minimal())>>();
  } else {
    static_assert(!detail::names_minimal<P>,
                  "cstab contract: problem declares minimal, but not as `const Model& minimal() const`");
  }
  static_assert(detail::energy_exact<P> || !detail::names_energy<P>,
                "cstab contract: problem declares energy, but not as `double energy(double t, const double* "
                "canonical) const` (wrong signature or not const)");
  static_assert(detail::first_integrals_exact<P> || !detail::names_first_integrals<P>,
                "cstab contract: problem declares first_integrals, but not as `void first_integrals(double t, const "
                "double* canonical, double* out) const` (wrong signature or not const)");
  static_assert(detail::reference_exact<P> || !detail::names_reference<P>,
                "cstab contract: problem declares reference, but not as `bool reference(double t, double* "
                "canonical) const` (wrong signature or not const)");
  static_assert(detail::problem_params_ok<P>,
                "cstab contract: problem parameters need both `std::vector<ParamSpec> problem_params() const` and "
                "`P with_params(const Params& params) const` (the problem with those values)");
  return true;
}

template <class M>
constexpr bool check_method() {
  static_assert(detail::name_ok<M>,
                "cstab contract: method: missing `static constexpr const char* kName` (its name in the catalog)");
  static_assert(detail::description_ok<M>,
                "cstab contract: method: missing `static constexpr const char* kDescription`");
  static_assert(detail::generic_params_ok<M>,
                "cstab contract: method: missing `static std::vector<ParamSpec> generic_params()`");
  return true;
}
template <class M, class P>
constexpr bool check_method_for() {
  check_method<M>();
  static_assert(detail::why_not_ok<M, P>,
                "cstab contract: method: missing `template <class P> static std::string why_not(const P& problem)` "
                "(\"\" = applies)");
  static_assert(detail::params_ok<M, P>,
                "cstab contract: method: missing `template <class P> static std::vector<ParamSpec> params(const P& "
                "problem, const std::string& formulation)`");
  static_assert(detail::make_ok<M, P>,
                "cstab contract: method: missing `template <class P> static std::unique_ptr<Formulation> make(const "
                "P& problem, const std::string& formulation, const Params& params)`");
  return true;
}

// Declared in methods/pair.hpp (pair_ops, method_info).
template <class M, class P>
constexpr bool check_pair() {
  check_problem<P>();
  check_method_for<M, P>();
  return true;
}
template <class M, class P>
constexpr bool pair_ok() {
  return ProblemClass<P> && MethodFor<M, P>;
}
template <class M>
constexpr bool method_ok() {
  return MethodType<M>;
}

}  // namespace cstab::contracts
