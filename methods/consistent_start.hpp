// Consistent initial values for the schemes that need them before their
// first step: the DAE formulations (methods/ida.hpp), the self-stepping
// schemes (generalized-alpha and its kin, ali3p, rattle, the symmetric
// projection). Free of any formulation class, so that a scheme using them
// does not instantiate the DAE formulation (its residual and the rest of its
// virtual functions) in its own pair unit.
#pragma once

#include <Eigen/Dense>

#include "linalg/dense.hpp"
#include "linalg/weighted_pinv.hpp"
#include "methods/mechanical.hpp"

namespace cstab {

template <class Model>
struct ConsistentStart : MechanicalSizes<Model> {
  CSTAB_MECHANICAL_SIZES(MechanicalSizes<Model>);
  static constexpr int nk = nq + nc;  // the KKT system's size

  // The problem's q(0), v(0), moved onto the constraints if they violate
  // them (some problems' published initial data do): GGL has no solution
  // through an inconsistent point, IDACalcIC never changes differential
  // components, and index 1 would carry the violation along unchanged.
  // Positions follow the correction flow
  //     dq/dtau = -M^-1 J^T (J M^-1 J^T)^-1 Phi(t0, q)   (Phi decays like e^-tau)
  // to its end point, the limit every stabilization's transient tends to
  // (RK4 in tau, then Gauss-Newton to polish; a single Gauss-Newton
  // projection lands elsewhere on the manifold, by 1.8e-5 on the biped's
  // 4.9e-3 m inconsistency). Velocities then take the least change in the
  // mass norm (affine constraints: one correction). Consistent data are left
  // untouched.
  static void state(const Model& model, double t0, VecQ& q, VecQ& v);

  // x = (a, lambda) from the KKT system [M -A^T; A 0] x = [Q; -gamma] at
  // (t0, q, v): exact accelerations and multipliers for consistent q, v.
  // Where the system is singular (redundant rows), a = M^-1 Q and lambda = 0,
  // left to the scheme.
  static void accelerations(const Model& model, double t0, const VecQ& q, const VecQ& v, Vec<double, nk>& x);

  // Defined below, out of line: a problem instantiates them once for its
  // model (cstab_model, methods/model_templates.hpp). Member
  // functions defined in the class are inline, and an inline function is
  // compiled again in every unit despite an extern declaration.
};

template <class Model>
void ConsistentStart<Model>::state(const Model& model, double t0, VecQ& q, VecQ& v) {
  model.initial_state(q, v);
  if constexpr (nc > 0) {
    constexpr double kTol = 1e-14;
    MechanicalTerms<Model> terms;
    Eigen::Matrix<double, nq, nq> M;
    if constexpr (nh > 0) {
      MassFactor<nq> mass;
      WeightedPinv<nh, nq> pinv;
      // -dq/dtau at q; false if M is singular.
      auto flow = [&](const VecQ& at, VecQ& direction) {
        terms.evaluate_position(model, t0, at);
        model.mass(t0, at, M);
        if (!mass.factor(M)) return false;
        pinv.set_rows(mass, terms.A.template topRows<nh>());
        direction = pinv.correction(terms.phi);
        return true;
      };
      terms.evaluate_position(model, t0, q);
      if (terms.phi.template lpNorm<Eigen::Infinity>() > kTol) {
        constexpr double kDtau = 0.25, kTauEnd = 30;  // e^-30 ~ 1e-13
        VecQ k1, k2, k3, k4;
        for (double tau = 0; tau < kTauEnd; tau += kDtau) {
          if (!flow(q, k1) || !flow(q - 0.5 * kDtau * k1, k2) || !flow(q - 0.5 * kDtau * k2, k3) ||
              !flow(q - kDtau * k3, k4))
            break;
          q -= kDtau / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
        }
        for (int it = 0; it < 5; ++it) {
          terms.evaluate_position(model, t0, q);
          if (terms.phi.template lpNorm<Eigen::Infinity>() <= kTol) break;
          VecQ step;
          if (!flow(q, step)) break;
          q -= step;
        }
      }
    }
    terms.evaluate_velocity(model, t0, q, v);
    if (terms.velocity.template lpNorm<Eigen::Infinity>() > kTol) {
      model.mass(t0, q, M);
      MassFactor<nq> velocity_mass;
      WeightedPinv<nc, nq> velocity_pinv;
      if (velocity_mass.factor(M)) {
        velocity_pinv.set_rows(velocity_mass, terms.A);
        v -= velocity_pinv.correction(terms.velocity);
      }
    }
  }
}

template <class Model>
void ConsistentStart<Model>::accelerations(const Model& model, double t0, const VecQ& q, const VecQ& v,
                                           Vec<double, nk>& x) {
  MechanicalTerms<Model> terms;
  terms.evaluate(model, t0, q, v, false);
  Eigen::Matrix<double, nk, nk> K = Eigen::Matrix<double, nk, nk>::Zero();
  Vec<double, nk> b;
  K.template topLeftCorner<nq, nq>() = terms.M;
  b.template head<nq>() = terms.Q;
  if constexpr (nc > 0) {
    K.template topRightCorner<nq, nc>() = -terms.A.transpose();
    K.template bottomLeftCorner<nc, nq>() = terms.A;
    b.template tail<nc>() = -terms.gamma;
  }
  // The solve stays fixed-size (its result seeds IDA, whose step sequence
  // is sensitive to the last bit); the condition estimate is the cold
  // dynamic-size one.
  const Eigen::PartialPivLU<Eigen::Matrix<double, nk, nk>> lu(K);
  x = lu.solve(b);
  if (!(linalg::lu_rcond_of(K) > 1e-15) || !x.allFinite()) {
    // Leave the multipliers to IDACalcIC.
    x.setZero();
    linalg::ldlt_solve(terms.M.data(), nq, terms.Q.data(), x.data());
  }
}

}  // namespace cstab
