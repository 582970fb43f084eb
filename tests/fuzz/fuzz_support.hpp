// A stand-in catalog for the matrix fuzz targets: problems and methods with
// the shapes expand_matrix has to handle (a method that does not apply, one
// whose parameters depend on the formulation, bounds of every kind), without
// linking the real models. The real registry is covered by tests/unit/test_matrix.cpp.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "matrix/matrix.hpp"

namespace cstab::fuzz {

class StandInProblem final : public Problem {
 public:
  StandInProblem(std::string name, double reference_time, bool has_minimal) : has_minimal_(has_minimal) {
    info_.name = std::move(name);
    info_.description = "fuzzing stand-in";
    info_.coordinates = {"x", "v"};
    info_.formulations = {{"mechanical", "", {}}, {"state-space", "", {}}};
    info_.default_t_end = 2;
    info_.reference_time = reference_time;
  }
  const ProblemInfo& info() const override { return info_; }
  std::vector<ParamSpec> method_params(const std::string& method, const std::string& formulation) const override {
    if (!why_not(method).empty()) throw UsageError("--method " + method + ": " + why_not(method));
    if (!formulation.empty() && formulation != "mechanical" && formulation != "state-space")
      throw UsageError("--formulation " + formulation + ": unknown");
    if (method == "pesterev") return {{"lambda", 1500, Bound::kPositive, ""}};
    if (method == "baumgarte")
      return {{"alpha", 10, Bound::kNonNegative, ""}, {"beta", 10, Bound::kNonNegative, ""}};
    if (method == "shift") return {{"offset", 0, Bound::kAny, ""}};
    return {};
  }
  std::unique_ptr<Formulation> make(const std::string&, const std::string&, const Params&) const override {
    return nullptr;  // never run
  }
  std::string why_not(const std::string& method) const override {
    if (method == "minimal" && !has_minimal_) return "no minimal-coordinate model";
    return "";
  }

 private:
  ProblemInfo info_;
  bool has_minimal_;
};

inline const MatrixCatalog& catalog() {
  static const StandInProblem wheel("wheel", 5, true), ball("ball", 0, false), biped("biped", 1, false);
  static const MatrixCatalog c = [] {
    MatrixCatalog out;
    out.problems = {&wheel, &ball, &biped};
    for (const char* m : {"pesterev", "baumgarte", "shift", "none", "minimal"}) {
      MethodInfo info;
      info.name = m;
      info.params = wheel.method_params(m, "");
      out.methods.push_back(info);
    }
    return out;
  }();
  return c;
}

}  // namespace cstab::fuzz
