// Adding a problem: a class in problems/, a register_<name>.cpp beside it
// (one line: its ProblemAdapter), and one line in each list below.
#include "problems/registry.hpp"

#include "methods/dispatch.hpp"

namespace cstab {

std::unique_ptr<Problem> make_wheel_problem();
std::unique_ptr<Problem> make_ball_problem();
std::unique_ptr<Problem> make_biped_problem();
std::unique_ptr<Problem> make_slider_crank_problem();
std::unique_ptr<Problem> make_andrews_problem();
std::unique_ptr<Problem> make_car_axis_problem();
std::unique_ptr<Problem> make_wheel_sharp_problem();

const std::vector<std::unique_ptr<Problem>>& all_problems() {
  static const std::vector<std::unique_ptr<Problem>> list = [] {
    std::vector<std::unique_ptr<Problem>> v;
    v.push_back(make_wheel_problem());
    v.push_back(make_ball_problem());
    v.push_back(make_biped_problem());
    v.push_back(make_slider_crank_problem());
    v.push_back(make_andrews_problem());
    v.push_back(make_car_axis_problem());
    v.push_back(make_wheel_sharp_problem());
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
