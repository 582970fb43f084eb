#include "methods/scalable.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>

#include "core/format.hpp"
#include "linalg/band.hpp"
#include "linalg/dense.hpp"

namespace cstab {

ParamSpec scalable_kkt_param() {
  return ranged_param("kkt", 0, 0, 1,
                      "the KKT solve: 0 band LU on rows ordered after their last coordinate (O(n) for a chain), "
                      "1 dense LU (O(n^3), the contrast)",
                      /*integer=*/true);
}

void read_scalable_kkt(const Params& params, ScalableSettings& settings) {
  const double kkt = params.get("kkt");
  if (kkt != 0 && kkt != 1) throw UsageError("--param kkt: must be 0 (band) or 1 (dense)");
  settings.dense = kkt == 1;
}

namespace {

// The KKT unknowns' order: each coordinate, then the rows whose last
// coordinate it is. pos_c[j], pos_r[i]: the places of coordinate j and row i.
struct KktOrder {
  std::vector<int> pos_c, pos_r;
  int bandwidth = 0;
};

KktOrder kkt_order(int n, int m, const std::vector<std::pair<int, int>>& pattern,
                   const std::vector<ScalableModel::Entry>& mass) {
  std::vector<int> last(size_t(m), -1);
  for (const auto& [r, c] : pattern) last[size_t(r)] = std::max(last[size_t(r)], c);
  std::vector<std::vector<int>> after(static_cast<size_t>(n));
  std::vector<int> empty_rows;
  for (int r = 0; r < m; ++r) (last[size_t(r)] < 0 ? empty_rows : after[size_t(last[size_t(r)])]).push_back(r);
  KktOrder o;
  o.pos_c.resize(size_t(n));
  o.pos_r.resize(size_t(m));
  int k = 0;
  for (int j = 0; j < n; ++j) {
    o.pos_c[size_t(j)] = k++;
    for (int r : after[size_t(j)]) o.pos_r[size_t(r)] = k++;
  }
  for (int r : empty_rows) o.pos_r[size_t(r)] = k++;
  for (const auto& e : mass)
    o.bandwidth = std::max(o.bandwidth, std::abs(o.pos_c[size_t(e.row)] - o.pos_c[size_t(e.col)]));
  for (const auto& [r, c] : pattern)
    o.bandwidth = std::max(o.bandwidth, std::abs(o.pos_r[size_t(r)] - o.pos_c[size_t(c)]));
  return o;
}

class ScalableFormulation : public Formulation {
  using Stab = ScalableSettings::Stabilization;

 public:
  ScalableFormulation(const ScalableModel& model, const ScalableSettings& settings)
      : model_(model.clone()),
        s_(settings),
        n_(model_->coords()),
        m_(model_->rows()),
        groups_(model_->constraint_groups()),
        pattern_(model_->jacobian_pattern()),
        mass_(model_->mass()),
        order_(kkt_order(n_, m_, pattern_, mass_)),
        k_(n_ + m_),
        jval_(pattern_.size()),
        phi_(size_t(m_)),
        gamma_(size_t(m_)),
        jv_(size_t(m_)),
        Q_(size_t(n_)),
        b_(size_t(k_)) {
    for (const auto& g : groups_) constraints_.push_back(g.info);
    if (s_.dense) {
      dense_.assign(size_t(k_) * size_t(k_), 0.0);
      lu_ = std::make_unique<linalg::Lu>(k_);
    } else {
      band_.resize(k_, order_.bandwidth, order_.bandwidth);
    }
  }

  std::string formulation_name() const override { return model_->formulation_name(); }
  int dimension() const override { return 2 * n_; }
  void initial_state(double* y) const override { model_->initial_state(y, y + n_); }
  const std::vector<ConstraintInfo>& constraints() const override { return constraints_; }
  void residuals(double, const double* y, double* out) const override {
    std::vector<double>& phi = observed_phi_;
    model_->holonomic(y, phi.data());
    for (size_t g = 0; g < groups_.size(); ++g) {
      double r = 0;
      for (int i = groups_[g].begin; i < groups_[g].end; ++i) r = std::max(r, std::abs(phi[size_t(i)]));
      out[g] = r;
    }
  }
  void to_canonical(double t, const double* y, double* c) const override { model_->to_canonical(t, y, y + n_, c); }
  const std::string& failure_reason() const override { return failure_; }

  bool rhs(double t, const double* y, double* dydt) override {
    const double* q = y;
    const double* v = y + n_;
    model_->forces(t, q, v, Q_.data());
    model_->jacobian(q, jval_.data());
    model_->gamma(q, v, gamma_.data());
    if (s_.stabilization == Stab::kBaumgarte) {
      model_->holonomic(q, phi_.data());
      jacobian_times(v, jv_.data());
      for (int i = 0; i < m_; ++i)
        gamma_[size_t(i)] += 2 * s_.alpha * jv_[size_t(i)] + s_.beta * s_.beta * phi_[size_t(i)];
    }
    if (!factor()) return singular(t);
    for (int j = 0; j < n_; ++j) b_[size_t(order_.pos_c[size_t(j)])] = Q_[size_t(j)];
    for (int i = 0; i < m_; ++i) b_[size_t(order_.pos_r[size_t(i)])] = -gamma_[size_t(i)];
    solve();
    for (int j = 0; j < n_; ++j) {
      dydt[j] = v[j];
      dydt[n_ + j] = b_[size_t(order_.pos_c[size_t(j)])];
      if (!std::isfinite(dydt[n_ + j])) return singular(t);
    }
    return true;
  }

  // a and lambda of M a = Q + J^T lambda, J a + gamma = 0 at (t, q, v)
  // (without stabilization terms); false if the KKT matrix is singular.
  bool accelerations(double t, const double* q, const double* v, double* a, double* lambda) {
    model_->forces(t, q, v, Q_.data());
    model_->jacobian(q, jval_.data());
    model_->gamma(q, v, gamma_.data());
    if (!factor()) return false;
    for (int j = 0; j < n_; ++j) b_[size_t(order_.pos_c[size_t(j)])] = Q_[size_t(j)];
    for (int i = 0; i < m_; ++i) b_[size_t(order_.pos_r[size_t(i)])] = -gamma_[size_t(i)];
    solve();
    for (int j = 0; j < n_; ++j) a[j] = b_[size_t(order_.pos_c[size_t(j)])];
    for (int i = 0; i < m_; ++i) lambda[i] = -b_[size_t(order_.pos_r[size_t(i)])];
    return true;
  }

  bool has_post_step() const override {
    return m_ > 0 && (s_.stabilization == Stab::kProjection || s_.stabilization == Stab::kPostStabilization);
  }

  bool post_step(double t, double* y) override {
    double* q = y;
    double* v = y + n_;
    bool factored = false;  // at the current q
    if (s_.stabilization == Stab::kProjection) {
      for (int it = 0; it < s_.max_iter; ++it) {
        model_->holonomic(q, phi_.data());
        if (max_abs(phi_) <= s_.tol) break;
        model_->jacobian(q, jval_.data());
        if (!factor()) return singular(t);
        correct_positions(q);
        factored = false;
      }
    } else {
      model_->holonomic(q, phi_.data());
      model_->jacobian(q, jval_.data());
      if (!factor()) return singular(t);
      jacobian_times(v, jv_.data());  // at the end point, before q moves
      correct_positions(q);
      factored = !s_.refactor;
    }
    if (!factored) {
      model_->jacobian(q, jval_.data());
      if (!factor()) return singular(t);
      jacobian_times(v, jv_.data());
    }
    // Velocity rows are linear in v: one solve is exact.
    std::fill(b_.begin(), b_.end(), 0.0);
    for (int i = 0; i < m_; ++i) b_[size_t(order_.pos_r[size_t(i)])] = -jv_[size_t(i)];
    solve();
    for (int j = 0; j < n_; ++j) v[j] += b_[size_t(order_.pos_c[size_t(j)])];
    return true;
  }

 protected:
  static double max_abs(const std::vector<double>& x) {
    double r = 0;
    for (double e : x) r = std::max(r, std::abs(e));
    return r;
  }

  // q += dq with [M J^T; J 0] [dq; mu] = [0; -phi] (the factorization made).
  void correct_positions(double* q) {
    std::fill(b_.begin(), b_.end(), 0.0);
    for (int i = 0; i < m_; ++i) b_[size_t(order_.pos_r[size_t(i)])] = -phi_[size_t(i)];
    solve();
    for (int j = 0; j < n_; ++j) q[j] += b_[size_t(order_.pos_c[size_t(j)])];
  }

  void jacobian_times(const double* v, double* out) const {
    std::fill(out, out + m_, 0.0);
    for (size_t k = 0; k < pattern_.size(); ++k) out[pattern_[k].first] += jval_[k] * v[pattern_[k].second];
  }

  // The KKT matrix from mass_ and jval_, factored.
  bool factor() {
    const auto& pc = order_.pos_c;
    const auto& pr = order_.pos_r;
    if (s_.dense) {
      std::fill(dense_.begin(), dense_.end(), 0.0);
      const size_t k = size_t(k_);
      for (const auto& e : mass_) dense_[size_t(pc[size_t(e.col)]) * k + size_t(pc[size_t(e.row)])] += e.value;
      for (size_t i = 0; i < pattern_.size(); ++i) {
        const size_t r = size_t(pr[size_t(pattern_[i].first)]), c = size_t(pc[size_t(pattern_[i].second)]);
        dense_[c * k + r] = jval_[i];
        dense_[r * k + c] = jval_[i];
      }
      lu_->compute(dense_.data());
      return lu_->pivot_ratio() > 0;
    }
    band_.set_zero();
    for (const auto& e : mass_) band_.at(pc[size_t(e.row)], pc[size_t(e.col)]) += e.value;
    for (size_t i = 0; i < pattern_.size(); ++i) {
      const int r = pr[size_t(pattern_[i].first)], c = pc[size_t(pattern_[i].second)];
      band_.at(r, c) = jval_[i];
      band_.at(c, r) = jval_[i];
    }
    // Only an exactly singular matrix (a zero or non-finite pivot) stops the
    // run: near a singular position the solve is ill-conditioned but the
    // integrators pass it at moderate tolerances, and a threshold on the
    // pivot ratio (tried: 1e-10 .. 1e-15) failed runs that pass without it
    // (docs/problems.md, n-four-bar).
    return band_.factor();  // false on a zero or non-finite pivot
  }

  void solve() {
    if (s_.dense)
      lu_->solve(b_.data(), b_.data());
    else
      band_.solve(b_.data());
  }

  bool singular(double t) {
    failure_ = std::string(s_.dense ? "dense" : "band") + " KKT matrix [M J^T; J 0] singular at t = " + format_3g(t) +
               " (the constraint rows lost rank: a singular position)";
    return false;
  }

  std::unique_ptr<ScalableModel> model_;
  ScalableSettings s_;
  int n_, m_;
  std::vector<ConstraintGroup> groups_;
  std::vector<ConstraintInfo> constraints_;
  std::vector<std::pair<int, int>> pattern_;
  std::vector<ScalableModel::Entry> mass_;
  KktOrder order_;
  int k_;
  std::vector<double> jval_, phi_, gamma_, jv_, Q_, b_;
  mutable std::vector<double> observed_phi_ = std::vector<double>(size_t(m_));
  linalg::BandLu band_;
  std::vector<double> dense_;
  std::unique_ptr<linalg::Lu> lu_;
  std::string failure_;
};

// The stabilized index-2 DAE of Gear, Gupta and Leimkuhler for SUNDIALS IDA
// (as ida-ggl on the fixed path, methods/ida.hpp):
//     q' - v - J^T mu      = 0
//     M v' - Q - J^T lambda = 0
//     Phi(q)               = 0
//     J v                  = 0
// with the unknowns interleaved in the KKT order (q_j, v_j at coordinate
// j's place; lambda_i, mu_i at row i's) and each equation at its unknown's
// place, so that the iteration matrix dF/dy + c dF/dy' is banded when the
// forces are local (half_bandwidth(); IDA then factors a band matrix).
// Starts from the model's q, v (on the rows), a and lambda from the KKT
// system, mu = 0.
class ScalableGglFormulation final : public ScalableFormulation, public DaeSystem {
 public:
  ScalableGglFormulation(const ScalableModel& model, const ScalableSettings& settings)
      : ScalableFormulation(model, settings),
        qv_(size_t(2 * n_)),
        r1_(size_t(n_)),
        r2_(size_t(n_)),
        y0_(size_t(2 * k_)),
        yp0_(size_t(2 * k_)) {
    std::vector<double> a(static_cast<size_t>(n_)), lambda(static_cast<size_t>(m_));
    model_->initial_state(qv_.data(), qv_.data() + n_);
    start_ok_ = accelerations(0, qv_.data(), qv_.data() + n_, a.data(), lambda.data());
    for (int j = 0; j < n_; ++j) {
      const size_t at = size_t(2 * order_.pos_c[size_t(j)]);
      y0_[at] = qv_[size_t(j)];
      y0_[at + 1] = qv_[size_t(n_ + j)];
      yp0_[at] = qv_[size_t(n_ + j)];
      yp0_[at + 1] = a[size_t(j)];
    }
    for (int i = 0; i < m_; ++i) y0_[size_t(2 * order_.pos_r[size_t(i)])] = lambda[size_t(i)];
    bandwidth_ = model_->local_forces() && !s_.dense ? ggl_bandwidth() : -1;
  }

  int dimension() const override { return 2 * k_; }
  int dae_dimension() const override { return 2 * k_; }
  int index() const override { return 2; }
  int half_bandwidth() const override { return bandwidth_; }

  bool rhs(double, const double*, double*) override {
    failure_ = "ida-ggl is a DAE formulation: it needs --integrator ida";
    return false;
  }
  bool has_post_step() const override { return false; }

  void initial_state(double* y) const override { std::copy(y0_.begin(), y0_.end(), y); }
  void initial_values(double, double* y, double* yp) const override {
    std::copy(y0_.begin(), y0_.end(), y);
    std::copy(yp0_.begin(), yp0_.end(), yp);
  }
  void component_ids(double* id) const override {
    for (int j = 0; j < n_; ++j) id[2 * order_.pos_c[size_t(j)]] = id[2 * order_.pos_c[size_t(j)] + 1] = 1.0;
    for (int i = 0; i < m_; ++i) id[2 * order_.pos_r[size_t(i)]] = id[2 * order_.pos_r[size_t(i)] + 1] = 0.0;
  }

  void residuals(double t, const double* y, double* out) const override {
    gather(y, observed_qv_.data());
    ScalableFormulation::residuals(t, observed_qv_.data(), out);
  }
  void to_canonical(double t, const double* y, double* c) const override {
    gather(y, observed_qv_.data());
    ScalableFormulation::to_canonical(t, observed_qv_.data(), c);
  }

  bool residual(double t, const double* y, const double* yp, double* r) override {
    if (!start_ok_) {
      failure_ = "KKT matrix singular at the start: no consistent initial values";
      return false;
    }
    gather(y, qv_.data());
    const double* q = qv_.data();
    const double* v = qv_.data() + n_;
    model_->forces(t, q, v, Q_.data());
    model_->jacobian(q, jval_.data());
    model_->holonomic(q, phi_.data());
    // r1 = J^T mu, r2 = J^T lambda; jv_ = J v.
    std::fill(r1_.begin(), r1_.end(), 0.0);
    std::fill(r2_.begin(), r2_.end(), 0.0);
    std::fill(jv_.begin(), jv_.end(), 0.0);
    for (size_t k = 0; k < pattern_.size(); ++k) {
      const auto [row, col] = pattern_[k];
      const size_t at = size_t(2 * order_.pos_r[size_t(row)]);
      r2_[size_t(col)] += jval_[k] * y[at];
      r1_[size_t(col)] += jval_[k] * y[at + 1];
      jv_[size_t(row)] += jval_[k] * v[col];
    }
    for (int j = 0; j < n_; ++j) {
      const size_t at = size_t(2 * order_.pos_c[size_t(j)]);
      r[at] = yp[at] - y[at + 1] - r1_[size_t(j)];
      r[at + 1] = -Q_[size_t(j)] - r2_[size_t(j)];
    }
    for (const auto& e : mass_)
      r[2 * order_.pos_c[size_t(e.row)] + 1] += e.value * yp[2 * order_.pos_c[size_t(e.col)] + 1];
    for (int i = 0; i < m_; ++i) {
      const size_t at = size_t(2 * order_.pos_r[size_t(i)]);
      r[at] = phi_[size_t(i)];
      r[at + 1] = jv_[size_t(i)];
    }
    for (int i = 0; i < 2 * k_; ++i)
      if (!std::isfinite(r[i])) return false;
    return true;
  }

 private:
  // (q, v) from the interleaved y.
  void gather(const double* y, double* qv) const {
    for (int j = 0; j < n_; ++j) {
      const size_t at = size_t(2 * order_.pos_c[size_t(j)]);
      qv[j] = y[at];
      qv[n_ + j] = y[at + 1];
    }
  }

  // The largest |place of an equation - place of an unknown it depends on|.
  int ggl_bandwidth() const {
    std::vector<std::vector<int>> cols_of_row(static_cast<size_t>(m_)), rows_of_col(static_cast<size_t>(n_));
    for (const auto& [row, col] : pattern_) {
      cols_of_row[size_t(row)].push_back(col);
      rows_of_col[size_t(col)].push_back(row);
    }
    int w = 1;  // q_j with v_j
    auto pc = [&](int j) { return 2 * order_.pos_c[size_t(j)]; };
    auto pr = [&](int i) { return 2 * order_.pos_r[size_t(i)]; };
    auto see = [&](int a, int b) { w = std::max(w, std::abs(a - b)); };
    for (const auto& e : mass_) see(pc(e.row) + 1, pc(e.col) + 1);
    for (int j = 0; j < n_; ++j)
      for (int row : rows_of_col[size_t(j)]) {
        see(pc(j), pr(row) + 1);      // J^T mu in q_j's equation
        see(pc(j) + 1, pr(row));      // J^T lambda in v_j's equation
        see(pr(row), pc(j));          // Phi_i in q_j
        see(pr(row) + 1, pc(j) + 1);  // J v in v_j
        for (int k : cols_of_row[size_t(row)]) {
          see(pc(j), pc(k));        // d(J^T mu)/dq
          see(pc(j) + 1, pc(k));    // d(J^T lambda)/dq
          see(pr(row) + 1, pc(k));  // d(J v)/dq
        }
      }
    return w;
  }

  std::vector<double> qv_, r1_, r2_, y0_, yp0_;
  mutable std::vector<double> observed_qv_ = std::vector<double>(size_t(2 * n_));
  bool start_ok_ = false;
  int bandwidth_ = -1;
};

}  // namespace

std::unique_ptr<Formulation> make_scalable_formulation(const ScalableModel& model, const ScalableSettings& settings) {
  if (settings.stabilization == ScalableSettings::Stabilization::kGgl)
    return std::make_unique<ScalableGglFormulation>(model, settings);
  return std::make_unique<ScalableFormulation>(model, settings);
}

int scalable_bandwidth(const ScalableModel& model) {
  return kkt_order(model.coords(), model.rows(), model.jacobian_pattern(), model.mass()).bandwidth;
}

}  // namespace cstab
