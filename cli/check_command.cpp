// cstab check: the conformance checks on what plugins add (or on chosen
// built-in problems and methods), as a pass/fail table. Each pair of a
// plugin's method with every problem (or a plugin's problem with every
// method) is checked for:
//   applies      a method that does not apply says why in words and refuses to build;
//   derivatives  (per problem) the model's Jacobians and gamma against its
//                constraint functions, by central differences along the flow;
//   conformance  the method's declared run (harness/conformance.hpp): residual,
//                energy drift and reference error within its promise;
//   recovery     (stabilizing ODE methods) from a start 1e-4 off the manifold,
//                the residual falls by 1e3;
//   allocation   no heap allocation in 200 steps after a warm-up.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <set>
#include <sstream>

#include "cli/args.hpp"
#include "cli/commands.hpp"
#include "core/format.hpp"
#include "harness/alloc_count.hpp"
#include "harness/conformance.hpp"
#include "harness/integrator.hpp"
#include "methods/pair.hpp"
#include "plugin/loader.hpp"
#include "problems/registry.hpp"

namespace cstab::cli {

namespace {

struct Row {
  std::string problem, method, check, result, detail;
};

std::string g3(double v) { return format_3g(v); }

void check_applies(const Problem& p, const MethodInfo& m, std::vector<Row>& rows) {
  const std::string why = p.why_not(m.name);
  bool refused = false;
  try {
    p.make(m.name, "", Params{});
  } catch (const UsageError&) {
    refused = true;
  } catch (const std::exception&) {
  }
  const bool ok = why.size() >= 10 && refused;
  rows.push_back({p.info().name, m.name, "applies", ok ? "n/a" : "FAIL",
                  ok ? why : "does not apply but " + std::string(why.size() < 10 ? "gives no reason in words" : "") +
                                 (why.size() < 10 && !refused ? " and " : "") +
                                 (refused ? "" : "make() did not refuse with a UsageError")});
}

void check_derivatives(const Problem& p, std::vector<Row>& rows) {
  std::string detail;
  const double worst = derivative_consistency(p, &detail);
  if (std::isnan(worst)) {
    rows.push_back({p.info().name, "none", "derivatives", "n/a", detail});
    return;
  }
  constexpr double kBound = 1e-5;
  rows.push_back({p.info().name, "none", "derivatives", worst <= kBound ? "pass" : "FAIL",
                  detail + (worst <= kBound ? " <= " : " > ") + g3(kBound)});
}

void check_conformance(const Problem& p, const MethodInfo& m, std::vector<Row>& rows) {
  const ConformanceSettings& promise = m.conformance;
  const ConformanceRun run = run_conformance(p, m);
  const double t_end = run.t_end, r0 = run.start_residual;
  const bool consistent = run.consistent_start;
  const RunConfig& cfg = run.config;
  const RunResult& r = run.result;
  std::vector<std::string> failed, seen;
  auto bound = [&](const std::string& what, double value, double limit) {
    seen.push_back(what + " " + g3(value) + (value < limit ? " < " : " >= ") + g3(limit));
    if (!(value < limit)) failed.push_back(seen.back());
  };
  if (r.status != "ok") {
    rows.push_back({p.info().name, m.name, "conformance", "FAIL", r.status + ": " + r.reason});
    return;
  }
  if (promise.stabilizes) {
    bound("final residual", r.final_residual, promise.residual_bound);
    if (consistent) bound("max residual", r.max_residual, promise.residual_bound);
  } else if (consistent) {
    bound("max residual", r.max_residual, promise.drift_bound);
  }
  if (p.info().has_energy && consistent) bound("max |dE|", r.max_energy_drift, promise.stabilizes ? 1e-5 : 1e-2);
  if (!r.ref_state.empty() && consistent)
    bound("error at t = " + format_short(t_end), r.ref_error, promise.stabilizes ? 1e-5 : 1e-2);
  std::string detail = cfg.integrator + (cfg.step.step > 0 ? " h = " + g3(cfg.step.step) : " tol " + g3(cfg.step.rtol));
  for (const auto& s : failed.empty() ? seen : failed) detail += "; " + s;
  if (!consistent) detail += "; inconsistent start (" + g3(r0) + "): accuracy not checked";
  rows.push_back({p.info().name, m.name, "conformance", failed.empty() ? "pass" : "FAIL", detail});
}

void check_recovery(const Problem& p, const MethodInfo& m, std::vector<Row>& rows) {
  if (m.kind != MethodKind::kOde || !m.conformance.stabilizes) return;
  const double t_end = std::min(2.0, p.info().default_t_end);
  RunConfig cfg = conformance_config(p, m, t_end, false);
  {
    auto f = p.make(m.name, cfg.formulation, Params::resolve(p.method_params(m.name, cfg.formulation), cfg.params,
                                                              m.name));
    if (f->constraints_hold_by_construction()) return;
  }
  cfg.perturb = 1e-4;
  cfg.ref_time = 0;
  const RunResult r = run_case(p, cfg, "");
  if (r.status != "ok") {
    rows.push_back({p.info().name, m.name, "recovery", "FAIL", r.status + ": " + r.reason});
    return;
  }
  const bool ok = r.final_residual < 1e-3 * r.initial_residual;
  rows.push_back({p.info().name, m.name, "recovery", ok ? "pass" : "FAIL",
                  "start 1e-4 off: residual " + g3(r.initial_residual) + " -> " + g3(r.final_residual) + " at t = " +
                      format_short(t_end) + (ok ? " (< 1e-3 x)" : " (not below 1e-3 x the start)")});
}

void check_allocation(const Problem& p, const MethodInfo& m, std::vector<Row>& rows) {
  const double t_end = std::min(2.0, p.info().default_t_end);
  const RunConfig cfg = conformance_config(p, m, t_end, false);
  auto form = p.make(m.name, cfg.formulation,
                     Params::resolve(p.method_params(m.name, cfg.formulation), cfg.params, m.name));
  constexpr int kWarmup = 20, kSteps = 200;
  const StepAllocations a = count_step_allocations(*form, cfg.integrator, cfg.step, kWarmup, kSteps);
  Row row{p.info().name, m.name, "allocation", "FAIL", ""};
  if (a.warmup_failed) {
    row.detail = "a warm-up step failed: " + a.failure;
  } else if (a.taken < kSteps) {
    row.detail = "step " + std::to_string(a.taken) + " failed (" + a.failure + ")";
  } else {
    row.result = a.allocations == 0 ? "pass" : "FAIL";
    row.detail = std::to_string(a.allocations) + " heap allocations in " + cfg.integrator + ", " +
                 std::to_string(a.taken) + " steps";
    if (a.library_allocations > 0)
      row.detail += " (and " + std::to_string(a.library_allocations) + " in GSL's or SUNDIALS' own workspaces)";
  }
  rows.push_back(row);
}

std::string pad(const std::string& s, size_t width) { return s.size() >= width ? s + " " : s + std::string(width - s.size(), ' '); }

}  // namespace

void declare_check(Args& a) {
  a.repeatable("--problem", "P", "check this problem (with every method, or those of --method)")
      .repeatable("--method", "M", "check this method (on every problem, or those of --problem)");
}

int cmd_check(const Args& args) {
  std::vector<std::string> problems = args.all("--problem"), methods = args.all("--method");
  for (const auto& name : problems) find_problem(name);
  for (const auto& name : methods) check_method_known(name);
  // What plugins added, unless chosen by name.
  std::set<std::string> plugin_problems, plugin_methods;
  for (const auto& pl : loaded_plugins()) {
    plugin_problems.insert(pl.problems.begin(), pl.problems.end());
    plugin_methods.insert(pl.methods.begin(), pl.methods.end());
  }
  if (problems.empty() && methods.empty() && plugin_problems.empty() && plugin_methods.empty())
    throw UsageError("nothing to check: give --plugin PATH (or --problem / --method)");
  auto chosen_problem = [&](const std::string& name) {
    return problems.empty() || std::find(problems.begin(), problems.end(), name) != problems.end();
  };
  auto chosen_method = [&](const std::string& name) {
    return methods.empty() || std::find(methods.begin(), methods.end(), name) != methods.end();
  };
  const bool by_name = !problems.empty() || !methods.empty();

  std::vector<Row> rows;
  for (const auto& p : all_problems()) {
    const std::string& pname = p->info().name;
    if (!chosen_problem(pname)) continue;
    const bool plugin_problem = plugin_problems.count(pname) > 0;
    bool derivatives_done = false;
    for (const auto& m : all_methods()) {
      if (!chosen_method(m.name)) continue;
      if (!by_name && !plugin_problem && !plugin_methods.count(m.name)) continue;
      // A check that throws (a plugin's model or method refusing, or
      // failing) is that check's FAIL row, not bad input.
      auto guarded = [&](const char* check, const std::string& method, auto&& run) {
        try {
          run();
        } catch (const std::exception& e) {
          rows.push_back({pname, method, check, "FAIL", std::string("threw: ") + e.what()});
        }
      };
      if ((plugin_problem || by_name) && !derivatives_done) {
        guarded("derivatives", "none", [&] { check_derivatives(*p, rows); });
        derivatives_done = true;
      }
      if (!p->why_not(m.name).empty()) {
        guarded("applies", m.name, [&] { check_applies(*p, m, rows); });
        continue;
      }
      guarded("conformance", m.name, [&] { check_conformance(*p, m, rows); });
      guarded("recovery", m.name, [&] { check_recovery(*p, m, rows); });
      guarded("allocation", m.name, [&] { check_allocation(*p, m, rows); });
    }
  }
  if (rows.empty()) throw UsageError("nothing to check: no problem and method match --problem / --method");

  size_t wp = 8, wm = 7;
  for (const auto& r : rows) wp = std::max(wp, r.problem.size() + 2), wm = std::max(wm, r.method.size() + 2);
  std::ostringstream out;
  out << pad("PROBLEM", wp) << pad("METHOD", wm) << pad("CHECK", 13) << pad("RESULT", 7) << "DETAIL\n";
  int pass = 0, na = 0, fail = 0;
  for (const auto& r : rows) {
    out << pad(r.problem, wp) << pad(r.method, wm) << pad(r.check, 13) << pad(r.result, 7) << r.detail << "\n";
    (r.result == "pass" ? pass : r.result == "n/a" ? na : fail)++;
  }
  out << "check: " << rows.size() << " checks: " << pass << " pass, " << na << " n/a, " << fail << " FAIL\n";
  std::cout << out.str();
  return fail > 0 ? 1 : 0;
}

}  // namespace cstab::cli
