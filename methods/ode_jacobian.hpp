// The Jacobian of the acceleration-level (index-1) right-hand sides
// (none, projection, post-stabilization, baumgarte, penalty), by AD, for
// the implicit integrators (cvode-bdf, cvode-projection, ark-dirk-*,
// msbdf): OdeSystem::jacobian in core/formulation.hpp.
//
// Those methods find the accelerations a (and multipliers lambda) from
//     r(q, v)  = M(q) a - Q(q, v) - A(q)^T lambda = 0
//     g(q, v)  = A(q) a + gamma(q, v) + stab(q, v) = 0
// (penalty: lambda = -p g instead of g = 0). Differentiating at the solution
// (implicit function theorem): with r_x, g_x the partial derivatives at fixed
// (a, lambda), x = q or v,
//     M a_x - A^T lambda_x = -r_x,   A a_x = -g_x
// which is the same KKT system as the right-hand side's, with other
// right-hand sides: each column of da/dx costs one solve with the
// factorization the method already has. r_x are NewtonTerms' K and C (the
// self-stepping schemes' Newton terms, methods/newton_terms.hpp); g_x needs
// the derivatives of the acceleration-level rows A a + gamma at fixed a,
// which AccelerationRowTerms computes by AD:
//     holonomic      d^2/ds^2 Phi(t + s, q + s v + s^2 a / 2) at s = 0,
//     non-holonomic  d/ds     Psi(t + s, q + s v, v + s a)     at s = 0,
// in second-order jets in s (core/jet.hpp) with duals on (q, v) on top. The stabilization terms' derivatives come
// from NewtonTerms' rows: d(phi)/dq = J, d(vel)/dq = Av, d(vel)/dv = A.
//
// AccelerationRowTerms<Model> is compiled once per model, in a unit of its
// own (cstab_model, methods/model_templates.hpp), like NewtonTerms.
#pragma once

#include "core/autodiff.hpp"
#include "core/jet.hpp"
#include "core/vec.hpp"
#include "methods/mechanical.hpp"
#include "methods/newton_terms.hpp"

namespace cstab {

template <class Model>
struct AccelerationRowTerms : MechanicalSizes<Model> {
  CSTAB_MECHANICAL_SIZES(MechanicalSizes<Model>);

  // d(A a + gamma)/dq and d(A a + gamma)/dv at (t, q, v) and fixed a.
  Eigen::Matrix<double, nc, nq> Eq, Ev;
  void evaluate(const Model& model, double t, const VecQ& q, const VecQ& v, const VecQ& a);
};

template <class Model>
void AccelerationRowTerms<Model>::evaluate(const Model& model, double t, const VecQ& q, const VecQ& v, const VecQ& a) {
  // Each coordinate a jet in s along the path, with 2 nq directions on top:
  // d/dq_j moves the jet's value, d/dv_j its first coefficient (positions)
  // or its value (velocities).
  using D = ad::Dual<2 * nq, ad::Jet>;
  using Der = Eigen::Matrix<ad::Jet, 2 * nq, 1>;
  const D td(ad::Jet(t, 1, 0), Der::Zero());
  Vec<D, nq> qd;
  for (int i = 0; i < nq; ++i) {
    Der dq = Der::Zero();
    dq(i) = ad::Jet(1, 0, 0);
    dq(nq + i) = ad::Jet(0, 1, 0);
    qd(i) = D(ad::Jet(q(i), v(i), a(i)), dq);
  }
  if constexpr (nh > 0) {
    Vec<D, nh> f;
    model.holonomic(td, qd, f);
    for (int i = 0; i < nh; ++i)
      for (int j = 0; j < nq; ++j) {
        Eq(i, j) = f(i).derivatives()(j).f2;
        Ev(i, j) = f(i).derivatives()(nq + j).f2;
      }
  }
  if constexpr (nn > 0) {
    Vec<D, nq> vd;
    for (int i = 0; i < nq; ++i) {
      Der dv = Der::Zero();
      dv(nq + i) = ad::Jet(1, 0, 0);
      vd(i) = D(ad::Jet(v(i), a(i), 0), dv);
    }
    Vec<D, nn> psi;
    model.nonholonomic(td, qd, vd, psi);
    for (int i = 0; i < nn; ++i)
      for (int j = 0; j < nq; ++j) {
        Eq(nh + i, j) = psi(i).derivatives()(j).f1;
        Ev(nh + i, j) = psi(i).derivatives()(nq + j).f1;
      }
  }
}

// The derivatives an index-1 method's Jacobian is assembled from, at a
// solution (a, lambda) of its right-hand side, for stabilized rows
//     A a + gamma + [c1 vel_h + c0 phi; cn vel_n] = 0
// (none and projection: all c = 0; baumgarte: c1 = 2 alpha, c0 = beta^2,
// cn = gamma; penalty: 2 xi omega, omega^2, omega).
template <class Model>
class IndexOneJacobian : public MechanicalSizes<Model> {
 public:
  CSTAB_MECHANICAL_SIZES(MechanicalSizes<Model>);
  using VecC = Vec<double, nc>;

  void evaluate(const Model& model, double t, const VecQ& q, const VecQ& v, const VecQ& a, const VecC& lambda,
                double c1, double c0, double cn) {
    newton_.evaluate(model, t, q, v, a, lambda);
    if constexpr (nc > 0) {
      rows_.evaluate(model, t, q, v, a);
      Gq_ = rows_.Eq;
      Gv_ = rows_.Ev;
      if constexpr (nh > 0) {
        Gq_.template topRows<nh>() += c1 * newton_.Av.template topRows<nh>() + c0 * newton_.A.template topRows<nh>();
        Gv_.template topRows<nh>() += c1 * newton_.A.template topRows<nh>();
      }
      if constexpr (nn > 0) {
        Gq_.template bottomRows<nn>() += cn * newton_.Av.template bottomRows<nn>();
        Gv_.template bottomRows<nn>() += cn * newton_.A.template bottomRows<nn>();
      }
    }
  }

  // The rows r_x (dr/dx at fixed a, lambda) and g_x of one column x_j of
  // (q, v), j < 2 nq.
  auto r_column(int j) const { return j < nq ? newton_.K.col(j) : newton_.C.col(j - nq); }
  VecC g_column(int j) const {
    if constexpr (nc > 0) return j < nq ? VecC(Gq_.col(j)) : VecC(Gv_.col(j - nq));
    return VecC();
  }
  const Eigen::Matrix<double, nc, nq>& A() const { return newton_.A; }

  // J (column-major, 2 nq square) of y' = (v, a(q, v)): the top half
  // [0 I], the bottom half column by column, da/dx_j = solve(r_x, g_x).
  template <class Solve>
  void fill(double* J, Solve&& solve) const {
    constexpr int n = 2 * nq;
    for (int j = 0; j < n; ++j) {
      double* col = J + j * n;
      for (int i = 0; i < nq; ++i) col[i] = (j == nq + i) ? 1.0 : 0.0;
      const VecQ da = solve(VecQ(r_column(j)), g_column(j));
      for (int i = 0; i < nq; ++i) col[nq + i] = da(i);
    }
  }

 private:
  NewtonTerms<Model> newton_;
  AccelerationRowTerms<Model> rows_;
  Eigen::Matrix<double, nc, nq> Gq_, Gv_;
};

}  // namespace cstab
