// Low-level pieces of the contracts (methods/contracts.hpp) that the model
// machinery itself needs (MechanicalTerms, LieJet find the optional closed
// forms): detectors for members NAMED like an optional function, and the
// messages of the static_asserts about them.
//
// The optional functions are found with `requires` on their exact call. A
// member with the right name but the wrong signature or constness would fail
// that test and be skipped without a word (a non-const energy() reported
// max |dE| = 0; a mistyped closed form fell back to AD). Detecting the name
// separately turns that case into a compile error naming the function and
// its expected signature.
//
// names_<f><T> is true when
//   * &T::f is valid (one non-template, non-overloaded member), or
//   * x.f(a...) is callable on a non-const T with 0..6 arguments of
//     AnyArgument, which converts to any parameter type (this finds member
//     templates such as `template <class Terms> ... (..., Terms&)` and
//     overload sets).
// Not found: a member template one of whose parameters is deduced from an
// Eigen type (`template <class S> f(const Vec<S, n>&)`): AnyArgument is not
// an Eigen matrix. No optional function of the contracts has that form.
#pragma once

namespace cstab::contracts::detail {

// Converts to any type and any reference (unevaluated use only).
struct AnyArgument {
  template <class T>
  operator T&() const;
};

}  // namespace cstab::contracts::detail

#define CSTAB_CONTRACT_NAME_DETECTOR(f)                                                   \
  namespace cstab::contracts::detail {                                                   \
  template <class T>                                                                     \
  inline constexpr bool names_##f =                                                      \
      requires { &T::f; } || requires(T& x) { x.f(); } ||                                \
      requires(T& x, AnyArgument a) { x.f(a); } ||                                       \
      requires(T& x, AnyArgument a) { x.f(a, a); } ||                                    \
      requires(T& x, AnyArgument a) { x.f(a, a, a); } ||                                 \
      requires(T& x, AnyArgument a) { x.f(a, a, a, a); } ||                              \
      requires(T& x, AnyArgument a) { x.f(a, a, a, a, a); } ||                           \
      requires(T& x, AnyArgument a) { x.f(a, a, a, a, a, a); };                          \
  }

CSTAB_CONTRACT_NAME_DETECTOR(energy)
CSTAB_CONTRACT_NAME_DETECTOR(first_integrals)
CSTAB_CONTRACT_NAME_DETECTOR(reference)
CSTAB_CONTRACT_NAME_DETECTOR(closed_form_holonomic)
CSTAB_CONTRACT_NAME_DETECTOR(closed_form_nonholonomic)
CSTAB_CONTRACT_NAME_DETECTOR(closed_form_jet)
CSTAB_CONTRACT_NAME_DETECTOR(mechanical)
CSTAB_CONTRACT_NAME_DETECTOR(state_space)
CSTAB_CONTRACT_NAME_DETECTOR(minimal)
CSTAB_CONTRACT_NAME_DETECTOR(problem_params)
CSTAB_CONTRACT_NAME_DETECTOR(with_params)

#undef CSTAB_CONTRACT_NAME_DETECTOR

// Messages of the optional functions' static_asserts (one line each).
#define CSTAB_CONTRACT_MSG_CLOSED_FORM_HOLONOMIC                                               \
  "cstab contract: the mechanical model declares closed_form_holonomic, but not as "           \
  "`template <class Terms> void closed_form_holonomic(double t, const Vec<double, kCoords>& q, " \
  "const Vec<double, kCoords>* v, Terms& terms) const` (wrong signature or not const)"
#define CSTAB_CONTRACT_MSG_CLOSED_FORM_NONHOLONOMIC                                              \
  "cstab contract: the mechanical model declares closed_form_nonholonomic, but not as "          \
  "`template <class Terms> void closed_form_nonholonomic(double t, const Vec<double, kCoords>& " \
  "q, const Vec<double, kCoords>& v, Terms& terms) const` (wrong signature or not const)"
#define CSTAB_CONTRACT_MSG_CLOSED_FORM_JET                                                     \
  "cstab contract: the affine model declares closed_form_jet, but not as `template <class Jet> " \
  "void closed_form_jet(double t, const Vec<double, kStates>& X, Jet& jet) const` (wrong "      \
  "signature or not const)"
