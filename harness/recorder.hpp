// The observer of a run: every observed state's residuals per constraint,
// energy and first-integral drift, recovery from an inconsistent start and
// the checkpoints of the drift-growth fit, and the series rows. Shared by
// `cstab run` (harness/run.cpp, states from an integrator) and `cstab score`
// (harness/score.cpp, states read from a trajectory file), so both record
// the same numbers from the same states.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <limits>
#include <string>
#include <vector>

#include "core/format.hpp"
#include "core/problem.hpp"
#include "harness/run.hpp"
#include "io/csv.hpp"

namespace cstab {

using RunClock = std::chrono::steady_clock;

inline double seconds_since(RunClock::time_point start) {
  return std::chrono::duration<double>(RunClock::now() - start).count();
}

// Everything recorded along a run, reused at every observation.
class Recorder {
 public:
  Recorder(const Problem& problem, Formulation& form, RunResult& result, AtomicFile* series,
           double sample_every, double fit_from, double t_end)
      : problem_(problem), form_(form), result_(result), series_(series),
        sample_every_(sample_every) {
    // Checkpoints of the running max drift for the growth fit (energy, then
    // each first integral), allocated here, filled during the run.
    if (fit_from > 0 && t_end >= 4 * fit_from) {
      fit_from_ = fit_from;
      fit_ratio_ = std::pow(t_end / fit_from, 1.0 / (kCheckpoints - 1));
      next_checkpoint_ = fit_from;
      const size_t quantities = 1 + problem.info().first_integrals.size();
      checkpoint_t_.reserve(kCheckpoints);
      checkpoint_max_.assign(quantities, {});
      for (auto& v : checkpoint_max_) v.reserve(kCheckpoints);
    }
    const auto& info = problem.info();
    const auto& cons = form.constraints();
    canonical_.assign(info.coordinates.size(), 0);
    residuals_.assign(cons.size(), 0);
    integrals_.assign(info.first_integrals.size(), 0);
    integrals0_.assign(info.first_integrals.size(), 0);
    for (const auto& c : cons) result_.constraints.push_back({c.name, 0, 0});
    result_.has_energy = info.has_energy;
    for (const auto& name : info.first_integrals) result_.max_integral_drift.emplace_back(name, 0.0);
    if (series_) {
      std::string header = "t";
      for (const auto& name : info.coordinates) header += "," + name;
      for (const auto& c : cons) header += ",residual_" + c.name;
      if (info.has_energy) header += ",energy_drift";
      for (const auto& name : info.first_integrals) header += "," + name + "_drift";
      if (form.has_condition_number()) header += ",cond";
      series_->write(header + "\n");
    }
  }

  // Returns false if the state diverged (reason set in result).
  bool observe(double t, const double* y, bool series_row, double blowup) {
    const auto start = RunClock::now();
    const bool ok = observe_impl(t, y, series_row, blowup);
    result_.observe_seconds += seconds_since(start);
    return ok;
  }

  bool due_for_sample(double t) const { return series_ && t >= next_sample_; }
  const std::vector<double>& canonical() const { return canonical_; }

 private:
  bool observe_impl(double t, const double* y, bool series_row, double blowup) {
    const int n = form_.dimension();
    for (int i = 0; i < n; ++i) {
      if (!std::isfinite(y[i])) {
        result_.status = "diverged";
        result_.reason = "non-finite state";
        result_.fail_time = t;
        return false;
      }
    }
    form_.to_canonical(t, y, canonical_.data());
    form_.residuals(t, y, residuals_.data());
    double max_now = 0;
    for (size_t i = 0; i < residuals_.size(); ++i) {
      const double r = std::abs(residuals_[i]);
      auto& m = result_.constraints[i];
      m.max_abs = std::max(m.max_abs, r);
      m.final_abs = r;
      max_now = std::max(max_now, r);
    }
    result_.final_residual = max_now;
    if (first_) result_.initial_residual = max_now;
    if (!(max_now <= result_.recovery_threshold))
      result_.recovery_time = std::numeric_limits<double>::quiet_NaN();
    else if (std::isnan(result_.recovery_time))
      result_.recovery_time = t;
    result_.max_residual = std::max(result_.max_residual, max_now);
    double energy_drift = 0;
    if (result_.has_energy) {
      const double e = problem_.energy(t, canonical_.data());
      if (first_) energy0_ = e;
      energy_drift = e - energy0_;
      result_.final_energy_drift = std::abs(energy_drift);
      result_.max_energy_drift = first_ ? 0.0 : std::max(result_.max_energy_drift, std::abs(energy_drift));
    }
    if (!integrals_.empty()) {
      problem_.first_integrals(t, canonical_.data(), integrals_.data());
      if (first_) integrals0_ = integrals_;
      for (size_t i = 0; i < integrals_.size(); ++i)
        result_.max_integral_drift[i].second =
            std::max(result_.max_integral_drift[i].second, std::abs(integrals_[i] - integrals0_[i]));
    }
    first_ = false;
    result_.t_reached = t;
    if (fit_from_ > 0 && t >= next_checkpoint_ && checkpoint_t_.size() < kCheckpoints) {
      checkpoint_t_.push_back(t);
      checkpoint_max_[0].push_back(result_.has_energy ? result_.max_energy_drift : 0.0);
      for (size_t i = 0; i < integrals_.size(); ++i) checkpoint_max_[i + 1].push_back(result_.max_integral_drift[i].second);
      while (next_checkpoint_ <= t) next_checkpoint_ *= fit_ratio_;
    }
    if (series_ && (series_row || t >= next_sample_)) {
      if (t >= next_sample_)
        next_sample_ = sample_every_ * (std::floor(t / sample_every_ + 1e-9) + 1);
      line_ = format_exact(t);
      for (double c : canonical_) append(c);
      for (double r : residuals_) append(r);
      if (result_.has_energy) append(energy_drift);
      for (size_t i = 0; i < integrals_.size(); ++i) append(integrals_[i] - integrals0_[i]);
      if (form_.has_condition_number()) {
        const double cond = form_.condition_number(t, y);
        append(cond);
        if (std::isfinite(cond))
          result_.max_condition = std::isnan(result_.max_condition)
                                      ? cond
                                      : std::max(result_.max_condition, cond);
      }
      line_ += '\n';
      series_->write(line_);
    }
    if (!(max_now <= blowup)) {
      result_.status = "diverged";
      result_.reason = std::isfinite(max_now)
                           ? "residual " + format_short(max_now) + " above blow-up threshold " +
                                 format_short(blowup)
                           : "non-finite residual";
      result_.fail_time = t;
      return false;
    }
    return true;
  }

  // Growth exponents from the checkpoints (after the run).
 public:
  void fit_drift_growth() {
    auto slope = [&](const std::vector<double>& m) {
      double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
      for (size_t k = 0; k < checkpoint_t_.size(); ++k) {
        if (!(m[k] > 0) || !std::isfinite(m[k])) continue;
        const double x = std::log(checkpoint_t_[k]), y = std::log(m[k]);
        n += 1, sx += x, sy += y, sxx += x * x, sxy += x * y;
      }
      const double den = n * sxx - sx * sx;
      return n >= 5 && den > 0 ? (n * sxy - sx * sy) / den : std::numeric_limits<double>::quiet_NaN();
    };
    const bool fitted = !checkpoint_t_.empty();
    if (result_.has_energy && fitted) result_.energy_drift_exponent = slope(checkpoint_max_[0]);
    for (size_t i = 0; i < integrals_.size(); ++i)
      result_.integral_drift_exponent.emplace_back(
          problem_.info().first_integrals[i],
          fitted ? slope(checkpoint_max_[i + 1]) : std::numeric_limits<double>::quiet_NaN());
  }

 private:

  void append(double v) {
    line_ += ',';
    line_ += format_exact(v);
  }

  const Problem& problem_;
  Formulation& form_;
  RunResult& result_;
  AtomicFile* series_;
  double sample_every_;
  double next_sample_ = 0;
  bool first_ = true;
  double energy0_ = 0;
  std::vector<double> canonical_, residuals_, integrals_, integrals0_;
  std::string line_;
  static constexpr size_t kCheckpoints = 40;
  double fit_from_ = 0, fit_ratio_ = 1, next_checkpoint_ = 0;
  std::vector<double> checkpoint_t_;
  std::vector<std::vector<double>> checkpoint_max_;
};

// A run's two output files in `out_dir` (nothing if it is empty), opened
// before anything is computed so that a folder that cannot be written is
// bad input (UsageError) and nothing is written; commit() writes the
// summary row last, and removes a series.csv of an earlier run into the
// folder when this one writes none.
class RunOutputs {
 public:
  RunOutputs(const std::string& out_dir, bool write_series) : dir_(out_dir) {
    if (dir_.empty()) return;
    std::error_code ec;
    std::filesystem::create_directories(dir_, ec);
    if (ec) throw UsageError("--out " + dir_ + ": cannot create folder: " + ec.message());
    try {
      summary_ = std::make_unique<AtomicFile>(dir_ + "/summary.csv");
      if (write_series) series_ = std::make_unique<AtomicFile>(dir_ + "/series.csv");
    } catch (const std::exception& e) {
      throw UsageError(std::string("--out ") + dir_ + ": " + e.what());
    }
  }
  AtomicFile* series() { return series_.get(); }
  void commit(const RunResult& result) {
    if (dir_.empty()) return;
    if (series_) series_->commit();
    summary_->write(key_value_csv(result.summary_row()));
    summary_->commit();
    if (!series_) std::remove((dir_ + "/series.csv").c_str());
  }

 private:
  std::string dir_;
  std::unique_ptr<AtomicFile> series_, summary_;
};

}  // namespace cstab
