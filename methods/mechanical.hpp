// The mechanical-system description every mechanical method uses:
//     M(t, q) a = Q(t, q, v) + A^T lambda,   q' = v,  v' = a,
//     holonomic      Phi(t, q) = 0                      (kHolonomic rows)
//     non-holonomic  Psi(t, q, v) = G(t, q) v + g(t, q) = 0 (kNonholonomic rows)
//     energy law     E(t, q, v) = E(0)                  (if kHasEnergy)
//
// A model type provides (sizes fixed at compile time; the concept
// contracts::MechanicalModel in methods/contracts.hpp checks it, with
// S = double and AD scalars):
//   static constexpr int kCoords, kHolonomic, kNonholonomic;
//   static constexpr bool kHasEnergy;
//   std::string formulation_name() const;
//   std::vector<ConstraintInfo> constraints() const;   // holonomic rows first
//   template <class S> void mass(const S& t, const Vec<S,nq>& q, Eigen::Matrix<S,nq,nq>& M) const;
//   template <class S> void forces(const S& t, const Vec<S,nq>& q, const Vec<S,nq>& v, Vec<S,nq>& Q) const;
//   template <class S> void holonomic(const S& t, const Vec<S,nq>& q, Vec<S,nh>& phi) const;        (nh > 0)
//   template <class S> void nonholonomic(const S& t, const Vec<S,nq>& q, const Vec<S,nq>& v, Vec<S,nn>& psi) const; (nn > 0)
//   template <class S> S energy(const S& t, const Vec<S,nq>& q, const Vec<S,nq>& v) const;         (kHasEnergy)
//   void initial_state(Vec<double,nq>& q, Vec<double,nq>& v) const;
//   void to_canonical(double t, const Vec<double,nq>& q, const Vec<double,nq>& v, double* c) const;
// Only what a model declares is evaluated: no holonomic terms for nh = 0, no
// non-holonomic terms for nn = 0, no energy terms without an energy law.
//
// Every derivative (Jacobians, the acceleration-level terms, the energy
// gradient) comes from forward-mode AD here; models write only the functions.
// A model may also give its holonomic rows' derivatives in closed form (a
// hand-derived fast path; tests/unit/test_closed_forms.cpp checks each against AD):
//   template <class Terms> void closed_form_holonomic(double t, const Vec<double,nq>& q,
//                                                    const Vec<double,nq>* v, Terms& terms) const;
// setting terms.phi, the first nh rows of terms.A (J = dPhi/dq), terms.phi_t
// and, when v is given, the first nh entries of terms.gamma (the second
// derivative of Phi(t + s, q + s v) at s = 0). Likewise for the
// non-holonomic rows,
//   template <class Terms> void closed_form_nonholonomic(double t, const Vec<double,nq>& q,
//                                                       const Vec<double,nq>& v, Terms& terms) const;
// setting the last nn entries of terms.velocity (Psi), rows nh.. of terms.A
// (G = dPsi/dv) and the last nn entries of terms.gamma (dPsi/dq v + dPsi/dt).
// A member named closed_form_holonomic / closed_form_nonholonomic that does
// not match these exactly (signature, constness) is a compile error, not a
// silent fall-back to AD.
#pragma once

#include <string>
#include <vector>

#include "core/autodiff.hpp"
#include "core/formulation.hpp"
#include "linalg/dense.hpp"
#include "methods/affine.hpp"
#include "methods/contract_detail.hpp"

namespace cstab {

// The sizes of a mechanical model, for classes that need nothing else of it.
template <class Model>
struct MechanicalSizes {
  static constexpr int nq = Model::kCoords;
  static constexpr int nh = Model::kHolonomic;
  static constexpr int nn = Model::kNonholonomic;
  static constexpr int nc = nh + nn;
  using VecQ = Vec<double, nq>;
};

// What a class template names of its base (MechanicalSizes, a
// MechanicalFormulationBase or a class derived from them): members of a
// dependent base are not found by plain lookup, so each formulation writes
//   using Base = MechanicalFormulationBase<Model>;
//  public:
//   CSTAB_MECHANICAL_SIZES(Base);
#define CSTAB_MECHANICAL_SIZES(Base) \
  using Base::nc;                    \
  using Base::nh;                    \
  using Base::nn;                    \
  using Base::nq;                    \
  using typename Base::VecQ

template <class Model>
struct MechanicalTerms;

namespace contracts::detail {
// The exact calls MechanicalTerms makes of the optional closed forms.
template <class M>
inline constexpr bool closed_form_holonomic_exact =
    requires(const M& m, double t, const Vec<double, M::kCoords>& q, MechanicalTerms<M>& terms) {
      m.closed_form_holonomic(t, q, &q, terms);
      m.closed_form_holonomic(t, q, static_cast<const Vec<double, M::kCoords>*>(nullptr), terms);
    };
template <class M>
inline constexpr bool closed_form_nonholonomic_exact =
    requires(const M& m, double t, const Vec<double, M::kCoords>& q, MechanicalTerms<M>& terms) {
      m.closed_form_nonholonomic(t, q, q, terms);
    };
}  // namespace contracts::detail

template <class Model>
struct MechanicalTerms : MechanicalSizes<Model> {
  CSTAB_MECHANICAL_SIZES(MechanicalSizes<Model>);
  using MatQ = Eigen::Matrix<double, nq, nq>;

  MatQ M;
  VecQ Q;
  // Rows: holonomic Jacobian J = dPhi/dq, then G = dPsi/dv. The constraint
  // rows at acceleration level read A a + gamma.
  Eigen::Matrix<double, nc, nq> A;
  Vec<double, nc> gamma;
  Vec<double, nh> phi;       // position-level residual
  Vec<double, nc> velocity;  // [J v + Phi_t; Psi]: velocity-level residual
  Vec<double, nh> phi_t;     // dPhi/dt
  // Energy law: E, dE/dv, and dE/dt with a = 0 (the part not through a).
  double energy = 0;
  VecQ energy_grad_v = VecQ::Zero();
  double energy_rate_free = 0;

  // Forces AD where the model has a closed form (tests compare the two).
  bool use_ad = false;
  // A member named like a closed form but callable otherwise is an error,
  // not a silent fall-back to AD (methods/contract_detail.hpp).
  static constexpr bool has_closed_form() {
    constexpr bool exact = contracts::detail::closed_form_holonomic_exact<Model>;
    static_assert(exact || !contracts::detail::names_closed_form_holonomic<Model>,
                  CSTAB_CONTRACT_MSG_CLOSED_FORM_HOLONOMIC);
    return exact;
  }
  static constexpr bool has_closed_form_nonholonomic() {
    constexpr bool exact = contracts::detail::closed_form_nonholonomic_exact<Model>;
    static_assert(exact || !contracts::detail::names_closed_form_nonholonomic<Model>,
                  CSTAB_CONTRACT_MSG_CLOSED_FORM_NONHOLONOMIC);
    return exact;
  }

  // The evaluations are defined below the class, out of line: a problem
  // instantiates them once for its model (cstab_model in its CMakeLists.txt,
  // CSTAB_EXTERN_MODEL_TEMPLATES in its header: methods/model_templates.hpp),
  // and the method units that include the header reuse that instance instead
  // of compiling the AD evaluations again (docs/build.md).

  // Positions only (projection needs no forces): phi, J (rows 0..nh), phi_t.
  void evaluate_position(const Model& model, double t, const VecQ& q);
  // Velocity rows only: A and the velocity residual (affine in v).
  void evaluate_velocity(const Model& model, double t, const VecQ& q, const VecQ& v);
  // Everything: M, Q, the constraint rows, gamma; the energy terms if asked.
  void evaluate(const Model& model, double t, const VecQ& q, const VecQ& v, bool with_energy);
  // dQ/dv at (t, q, v) by forward AD, in the duals every model's forces
  // compile with (contracts' MechanicalDual), into dQdv.
  static void force_velocity_jacobian(const Model& model, double t, const VecQ& q, const VecQ& v, MatQ& dQdv);

 private:
  // (t, q, v) as duals with nq + 1 directions: the nq velocities, then the
  // line (t + s, q + s v) with v frozen. A function f(t, q, v) evaluated on
  // them gives df/dv and df/dq v + df/dt (the part of df/dt not through a).
  using LineDual = ad::Dual<nq + 1>;
  struct LineDuals {
    LineDual t;
    Vec<LineDual, nq> q, v;
    LineDuals(double t0, const VecQ& q0, const VecQ& v0) : t(t0, nq + 1, nq) {
      for (int i = 0; i < nq; ++i) {
        Eigen::Matrix<double, nq + 1, 1> dq = Eigen::Matrix<double, nq + 1, 1>::Zero();
        dq(nq) = v0(i);
        q(i) = LineDual(q0(i), dq);
        v(i) = LineDual(v0(i), nq + 1, i);
      }
    }
  };

  // phi, J, phi_t, velocity and gamma of the holonomic rows by AD.
  void holonomic_terms_ad(const Model& model, double t, const VecQ& q, const VecQ& v);
  void nonholonomic_terms(const Model& model, double t, const VecQ& q, const VecQ& v);
};

template <class Model>
void MechanicalTerms<Model>::force_velocity_jacobian(const Model& model, double t, const VecQ& q, const VecQ& v,
                                                     MatQ& dQdv) {
  using D = ad::Dual<nq + 1>;
  Vec<D, nq> qd, vd, Qd;
  for (int i = 0; i < nq; ++i) {
    qd(i) = D(q(i));
    vd(i) = D(v(i), nq + 1, i);
  }
  model.forces(D(t), qd, vd, Qd);
  for (int i = 0; i < nq; ++i) dQdv.row(i) = Qd(i).derivatives().template head<nq>().transpose();
}

template <class Model>
void MechanicalTerms<Model>::evaluate_position(const Model& model, double t, const VecQ& q) {
  if constexpr (has_closed_form()) {
    if (!use_ad) {
      model.closed_form_holonomic(t, q, static_cast<const VecQ*>(nullptr), *this);
      return;
    }
  }
  if constexpr (nh > 0) {
    using D = ad::Dual<nq + 1>;
    Vec<D, nq> qd;
    for (int i = 0; i < nq; ++i) qd(i) = D(q(i), nq + 1, i);
    const D td(t, nq + 1, nq);
    Vec<D, nh> f;
    model.holonomic(td, qd, f);
    for (int i = 0; i < nh; ++i) {
      phi(i) = f(i).value();
      A.row(i) = f(i).derivatives().template head<nq>().transpose();
      phi_t(i) = f(i).derivatives()(nq);
    }
  }
}

template <class Model>
void MechanicalTerms<Model>::evaluate_velocity(const Model& model, double t, const VecQ& q, const VecQ& v) {
  evaluate_position(model, t, q);
  if constexpr (nh > 0) velocity.template head<nh>() = A.template topRows<nh>().lazyProduct(v) + phi_t;
  if constexpr (nn > 0) nonholonomic_terms(model, t, q, v);
}

template <class Model>
void MechanicalTerms<Model>::evaluate(const Model& model, double t, const VecQ& q, const VecQ& v,
                                      bool with_energy) {
  model.mass(t, q, M);
  model.forces(t, q, v, Q);
  if constexpr (nh > 0) {
    bool closed = false;
    if constexpr (has_closed_form()) closed = !use_ad;
    if (closed) {
      if constexpr (has_closed_form()) model.closed_form_holonomic(t, q, &v, *this);
      velocity.template head<nh>() = A.template topRows<nh>().lazyProduct(v) + phi_t;
    } else {
      holonomic_terms_ad(model, t, q, v);
    }
  }
  if constexpr (nn > 0) nonholonomic_terms(model, t, q, v);
  if constexpr (Model::kHasEnergy) {
    if (with_energy) {
      // Directions: the nq velocities, then the line (t + s, q + s v).
      LineDuals d(t, q, v);
      const auto& [td, qd, vd] = d;
      using D = LineDual;
      const D e = model.energy(td, qd, vd);
      energy = e.value();
      energy_grad_v = e.derivatives().template head<nq>();
      energy_rate_free = e.derivatives()(nq);
    }
  }
}

template <class Model>
void MechanicalTerms<Model>::holonomic_terms_ad(const Model& model, double t, const VecQ& q, const VecQ& v) {
  // (Guarded: an explicit instantiation compiles every member, and a model
  // without holonomic rows has no holonomic().)
  if constexpr (nh > 0) {
    evaluate_position(model, t, q);
    // Second derivative of Phi(t + s, q + s v) at s = 0 (hyper-dual):
    // gamma = d/dt (J v + Phi_t) with v frozen; the first derivative is J v + Phi_t.
    using D1 = ad::Dual<1>;
    using H = ad::Nest<D1>;
    Vec<H, nq> qh;
    for (int i = 0; i < nq; ++i)
      qh(i) = H(D1(q(i), Eigen::Matrix<double, 1, 1>(v(i))), Eigen::Matrix<D1, 1, 1>(D1(v(i), Eigen::Matrix<double, 1, 1>(0.0))));
    const H th(D1(t, Eigen::Matrix<double, 1, 1>(1.0)), Eigen::Matrix<D1, 1, 1>(D1(1.0, Eigen::Matrix<double, 1, 1>(0.0))));
    Vec<H, nh> f;
    model.holonomic(th, qh, f);
    for (int i = 0; i < nh; ++i) {
      velocity(i) = f(i).value().derivatives()(0);
      gamma(i) = f(i).derivatives()(0).derivatives()(0);
    }
  }
}

template <class Model>
void MechanicalTerms<Model>::nonholonomic_terms(const Model& model, double t, const VecQ& q, const VecQ& v) {
  if constexpr (nn == 0) {
    return;  // no non-holonomic rows (and no nonholonomic() to call)
  } else {
    if constexpr (has_closed_form_nonholonomic()) {
      if (!use_ad) {
        model.closed_form_nonholonomic(t, q, v, *this);
        return;
      }
    }
    LineDuals d(t, q, v);
    const auto& [td, qd, vd] = d;
    using D = LineDual;
    Vec<D, nn> psi;
    model.nonholonomic(td, qd, vd, psi);
    for (int i = 0; i < nn; ++i) {
      velocity(nh + i) = psi(i).value();
      A.row(nh + i) = psi(i).derivatives().template head<nq>().transpose();
      gamma(nh + i) = psi(i).derivatives()(nq);
    }
  }
}


// Shared parts of every formulation on y = [q; v].
template <class Model>
class MechanicalFormulationBase : public Formulation, public MechanicalSizes<Model> {
 public:
  CSTAB_MECHANICAL_SIZES(MechanicalSizes<Model>);

  explicit MechanicalFormulationBase(const Model& model) : model_(model), constraints_(model.constraints()) {}

  std::string formulation_name() const override { return model_.formulation_name(); }
  int dimension() const override { return 2 * nq; }
  void initial_state(double* y) const override {
    VecQ q, v;
    model_.initial_state(q, v);
    vmap<nq>(y) = q;
    vmap<nq>(y + nq) = v;
  }
  const std::vector<ConstraintInfo>& constraints() const override { return constraints_; }
  void residuals(double t, const double* y, double* out) const override {
    const VecQ q = vmap<nq>(y), v = vmap<nq>(y + nq);
    if constexpr (nh > 0) {
      Vec<double, nh> phi;
      model_.holonomic(t, q, phi);
      for (int i = 0; i < nh; ++i) out[i] = phi(i);
    }
    if constexpr (nn > 0) {
      Vec<double, nn> psi;
      model_.nonholonomic(t, q, v, psi);
      for (int i = 0; i < nn; ++i) out[nh + i] = psi(i);
    }
  }
  void to_canonical(double t, const double* y, double* c) const override {
    model_.to_canonical(t, vmap<nq>(y).eval(), vmap<nq>(y + nq).eval(), c);
  }
  const std::string& failure_reason() const override { return failure_; }

 protected:
  Model model_;
  std::vector<ConstraintInfo> constraints_;
  std::string failure_;
};

// Rank of the constraint rows at the initial state (for methods that need
// full rank to say so before running).
template <class Model>
int initial_constraint_rank(const Model& model, int* rows) {
  constexpr int nq = Model::kCoords;
  MechanicalTerms<Model> terms;
  Vec<double, nq> q, v;
  model.initial_state(q, v);
  terms.evaluate(model, 0.0, q, v, false);
  *rows = MechanicalTerms<Model>::nc;
  if constexpr (MechanicalTerms<Model>::nc == 0) {
    return 0;
  } else {
    return linalg::rank_of(terms.A);
  }
}

// The applicability check of the methods that run on P::mechanical() is
// contracts::HasMechanical (methods/contracts.hpp): a mechanical() whose
// model satisfies MechanicalModel.

}  // namespace cstab
