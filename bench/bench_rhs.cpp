// Micro-benchmarks: the cost of one stabilized right-hand side and of one
// RK4 step, for every problem x method, beside the bare dynamics (M^-1 Q,
// or F(X) for the state-space wheel) and the minimal-coordinate ODE where a
// problem has one. After the Google Benchmark table, a ratio table divides
// each median by its problem's bare-dynamics median and by its
// minimal-coordinate right-hand side's median (same run), in CPU time.
//   build/release/bench/cstab_bench --benchmark_repetitions=5
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/formulation.hpp"
#include "harness/integrator.hpp"
#include "methods/pair.hpp"
#include "problems/registry.hpp"

namespace {

using namespace cstab;

std::unique_ptr<Formulation> make_formulation(const Problem& p, const std::string& method,
                                              const std::string& formulation) {
  std::vector<std::pair<std::string, std::string>> given;
  const auto specs = p.method_params(method, formulation);
  if (method == "braun-goldfarb") given.emplace_back("dt", "1e-2");
  auto f = p.make(method, formulation, Params::resolve(specs, given, method));
  f->set_step_hint(1e-3);
  return f;
}

void bench_rhs(benchmark::State& state, std::shared_ptr<Formulation> f) {
  std::vector<double> y(f->dimension()), dy(f->dimension());
  f->initial_state(y.data());
  for (auto _ : state) {
    f->rhs(0.0, y.data(), dy.data());
    benchmark::DoNotOptimize(dy.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations());
}

// h = 1e-3, or 1/1000 of the reference horizon if shorter (andrews: 3e-5;
// RK4 diverges on it at 1e-3 and the step would time a failure).
void bench_step(benchmark::State& state, std::shared_ptr<Formulation> f, double h) {
  std::vector<double> y0(f->dimension());
  f->initial_state(y0.data());
  auto integ = make_integrator("rk4", StepSettings{h, 0, 0});
  integ->start(*f, 0.0, y0.data());
  long steps = 0;
  for (auto _ : state) {
    if (++steps % 1000 == 0) integ->start(*f, 0.0, y0.data());  // stay near the initial state
    if (integ->step(1e300) != StepOutcome::kOk) {
      state.SkipWithError("step failed");
      break;
    }
    if (f->has_post_step() && f->post_step(integ->t(), integ->y())) integ->notify_modified();
    benchmark::DoNotOptimize(integ->y());
  }
  state.SetItemsProcessed(state.iterations());
}

// Collects medians (or single runs) for the ratio table.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const auto& r : runs) {
      const std::string name = r.run_name.str();
      const bool aggregate = !r.aggregate_name.empty();
      if (aggregate && r.aggregate_name != "median") continue;
      if (!aggregate && medians_.count(name)) continue;
      medians_[name] = r.GetAdjustedCPUTime();  // CPU time: robust on a loaded machine
    }
  }
  const std::map<std::string, double>& medians() const { return medians_; }

 private:
  std::map<std::string, double> medians_;
};

}  // namespace

int main(int argc, char** argv) {
  // rhs/<problem>/<label> and step/<problem>/<label>; label "bare" is the baseline.
  std::vector<std::pair<std::string, std::string>> rows;  // problem, label
  for (const auto& p : all_problems()) {
    const std::string pname = p->info().name;
    std::vector<std::pair<std::string, std::shared_ptr<Formulation>>> forms;
    if (auto bare = p->make_unconstrained()) forms.emplace_back("bare", std::move(bare));
    for (const auto& m : all_methods()) {
      if (!p->why_not(m.name).empty()) continue;
      for (const auto& f : p->info().formulations) {
        if (f.name == "minimal" && m.name != "minimal") continue;
        std::shared_ptr<Formulation> form;
        try {
          form = make_formulation(*p, m.name, f.name);
        } catch (const UsageError&) {
          continue;  // this method does not run on this formulation
        }
        if (dynamic_cast<DaeSystem*>(form.get())) continue;  // DAE: no right-hand side
        forms.emplace_back(m.name + "@" + form->formulation_name(), form);
      }
    }
    const double ref = p->info().reference_time;
    const double step = ref > 0 ? std::min(1e-3, ref / 1000) : 1e-3;
    std::sort(forms.begin(), forms.end(), [](auto& a, auto& b) { return a.first < b.first; });
    forms.erase(std::unique(forms.begin(), forms.end(), [](auto& a, auto& b) { return a.first == b.first; }),
                forms.end());
    for (auto& [label, form] : forms) {
      benchmark::RegisterBenchmark(("rhs/" + pname + "/" + label).c_str(), bench_rhs, form);
      benchmark::RegisterBenchmark(("step/" + pname + "/" + label).c_str(), bench_step, form, step);
      rows.emplace_back(pname, label);
    }
  }
  benchmark::Initialize(&argc, argv);
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  const auto& med = reporter.medians();
  std::printf("\n%-12s %-28s %10s %9s %9s %12s %10s\n", "problem", "formulation", "rhs_ns", "rhs/bare", "rhs/min",
              "rk4_step_ns", "step/bare");
  for (const auto& row : rows) {
    // Named, not a structured binding: clang before 16 does not let a lambda capture one.
    const std::string& pname = row.first;
    const std::string& label = row.second;
    auto get = [&](const std::string& kind, const std::string& l) {
      auto it = med.find(kind + "/" + pname + "/" + l);
      return it == med.end() ? -1.0 : it->second;
    };
    const double rhs = get("rhs", label), bare = get("rhs", "bare");
    double minimal = -1;  // the minimal-coordinate ODE's right-hand side, if the problem has one
    for (const auto& [p2, l2] : rows)
      if (p2 == pname && l2.rfind("minimal@", 0) == 0) minimal = get("rhs", l2);
    const double step = get("step", label), bare_step = get("step", "bare");
    if (rhs < 0) continue;
    std::printf("%-12s %-28s %10.1f %9.2f %9.2f %12.1f %10.2f\n", pname.c_str(), label.c_str(), rhs,
                bare > 0 ? rhs / bare : NAN, minimal > 0 ? rhs / minimal : NAN, step,
                bare_step > 0 ? step / bare_step : NAN);
  }
  benchmark::Shutdown();
  return 0;
}
