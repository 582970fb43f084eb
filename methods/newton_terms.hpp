// The terms of a Newton iteration on a mechanical model (M a = Q + A^T
// lambda), by AD of the model functions: shared by the implicit schemes that
// step themselves (methods/generalized_alpha.hpp, methods/ali3p.hpp).
#pragma once

#include "core/autodiff.hpp"
#include "core/vec.hpp"

namespace cstab {

template <class Model>
struct NewtonTerms {
  static constexpr int nq = Model::kCoords;
  static constexpr int nh = Model::kHolonomic;
  static constexpr int nn = Model::kNonholonomic;
  static constexpr int nc = nh + nn;
  using VecQ = Vec<double, nq>;

  Eigen::Matrix<double, nq, nq> M, K, C;
  VecQ r;
  Eigen::Matrix<double, nc, nq> A, Av;
  Vec<double, nc> vel;
  Vec<double, nh> phi;

  // At (t, q, v, vdot, lambda), by AD with the 2 nq directions (q, v):
  // r = M vdot - Q - A^T lambda with K = dr/dq, C = dr/dv; M; Phi; the rows
  // A = [Phi_q; dPsi/dv]; vel = [Phi_q v + Phi_t; Psi] and Av = dvel/dq.
  // The constraint rows inside r are themselves derivatives: a second,
  // inner level of duals on top of the first.
  void evaluate(const Model& model, double t, const VecQ& q, const VecQ& v, const VecQ& vdot,
                const Vec<double, nc>& lambda) {
    using D = ad::Dual<2 * nq>;
    Vec<D, nq> qd, vd;
    for (int i = 0; i < nq; ++i) {
      qd(i) = D(q(i), 2 * nq, i);
      vd(i) = D(v(i), 2 * nq, nq + i);
    }
    const D td(t);
    Eigen::Matrix<D, nq, nq> Md;
    model.mass(td, qd, Md);
    Vec<D, nq> Qd;
    model.forces(td, qd, vd, Qd);
    Vec<D, nq> rd = Md * vdot.template cast<D>() - Qd;
    Vec<D, nc> veld;
    if constexpr (nh > 0) {
      // Inner duals: the nq positions and time, on top of D.
      using T = Eigen::AutoDiffScalar<Eigen::Matrix<D, nq + 1, 1>>;
      using DerT = Eigen::Matrix<D, nq + 1, 1>;
      Vec<T, nq> qt;
      for (int i = 0; i < nq; ++i) {
        DerT e = DerT::Constant(D(0.0));
        e(i) = D(1.0);
        qt(i) = T(qd(i), e);
      }
      DerT et = DerT::Constant(D(0.0));
      et(nq) = D(1.0);
      const T tt(td, et);
      Vec<T, nh> phit;
      model.holonomic(tt, qt, phit);
      for (int i = 0; i < nh; ++i) {
        D row_v = phit(i).derivatives()(nq);  // Phi_t
        for (int j = 0; j < nq; ++j) {
          const D& dij = phit(i).derivatives()(j);
          rd(j) -= dij * lambda(i);
          row_v += dij * vd(j);
          A(i, j) = dij.value();
        }
        veld(i) = row_v;
        phi(i) = phit(i).value().value();
      }
    }
    if constexpr (nn > 0) {
      // Inner duals: the nq velocities (Psi is affine in v: G = dPsi/dv).
      using T = Eigen::AutoDiffScalar<Eigen::Matrix<D, nq, 1>>;
      using DerT = Eigen::Matrix<D, nq, 1>;
      const DerT zero = DerT::Constant(D(0.0));
      Vec<T, nq> qt, vt;
      for (int i = 0; i < nq; ++i) {
        qt(i) = T(qd(i), zero);
        DerT e = zero;
        e(i) = D(1.0);
        vt(i) = T(vd(i), e);
      }
      const T tt(td, zero);
      Vec<T, nn> psi;
      model.nonholonomic(tt, qt, vt, psi);
      for (int i = 0; i < nn; ++i) {
        for (int j = 0; j < nq; ++j) {
          const D& gij = psi(i).derivatives()(j);
          rd(j) -= gij * lambda(nh + i);
          A(nh + i, j) = gij.value();
        }
        veld(nh + i) = psi(i).value();
      }
    }
    for (int i = 0; i < nq; ++i) {
      r(i) = rd(i).value();
      K.row(i) = rd(i).derivatives().template head<nq>().transpose();
      C.row(i) = rd(i).derivatives().template tail<nq>().transpose();
      for (int j = 0; j < nq; ++j) M(i, j) = Md(i, j).value();
    }
    for (int i = 0; i < nc; ++i) {
      vel(i) = veld(i).value();
      Av.row(i) = veld(i).derivatives().template head<nq>().transpose();
    }
  }
};

}  // namespace cstab
