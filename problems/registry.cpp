// Adding a problem: a class in problems/ and one line in all_problems().
#include "problems/registry.hpp"

#include "methods/dispatch.hpp"
#include "problems/wheel.hpp"
#include "problems/ball.hpp"
#include "problems/biped.hpp"
#include "problems/slider_crank.hpp"
#include "problems/andrews.hpp"
#include "problems/car_axis.hpp"

namespace cstab {

const std::vector<std::unique_ptr<Problem>>& all_problems() {
  static const std::vector<std::unique_ptr<Problem>> list = [] {
    std::vector<std::unique_ptr<Problem>> v;
    v.push_back(std::make_unique<ProblemAdapter<Wheel>>(Wheel{}));
    v.push_back(std::make_unique<ProblemAdapter<Ball>>(Ball{}));
    v.push_back(std::make_unique<ProblemAdapter<Biped>>(Biped{}));
    v.push_back(std::make_unique<ProblemAdapter<SliderCrank>>(SliderCrank{}));
    v.push_back(std::make_unique<ProblemAdapter<Andrews>>(Andrews{}));
    v.push_back(std::make_unique<ProblemAdapter<CarAxis>>(CarAxis{}));
    return v;
  }();
  return list;
}

const Problem& find_problem(const std::string& name) {
  for (const auto& p : all_problems())
    if (p->info().name == name) return *p;
  std::string known;
  for (const auto& p : all_problems()) known += (known.empty() ? "" : ", ") + p->info().name;
  throw UsageError("--problem " + name + ": unknown problem (known: " + known + ")");
}

}  // namespace cstab
