// cstab-peer-simbody: cstab's problems modelled in Simbody 3.7, integrated by
// one of Simbody's integrators at a given accuracy and constraint tolerance,
// and written as a trajectory `cstab score` reads (docs/peers-simbody.md).
//
//   cstab-peer-simbody --problem pendulum|slider-crank [--problem-param k=v[,k=v]]
//       --integrator rk3|rkmerson|rkfeldberg|verlet|euler|cpodes --accuracy A
//       [--constraint-tolerance C] [--t-end T] [--every DT] --out FILE.csv
//
// The program is deliberately independent of cstab's code: it restates the
// problems' parameters (problems/pendulum/pendulum.hpp,
// problems/slider_crank/slider_crank.hpp) the way an outside user would, and
// tests/peers/test_simbody.cpp checks that the two agree.
//
// Exit codes: 0 done; 1 Simbody failed during integration (the rows up to the
// failure are written, the error printed); 2 bad input (one line, nothing run).
#include <Simbody.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

using namespace SimTK;

namespace {

constexpr const char* kProgram = "cstab-peer-simbody";

struct BadInput {
  std::string message;
};

[[noreturn]] void bad(const std::string& message) { throw BadInput{message}; }

double number(const std::string& option, const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(v))
    bad(option + ": '" + text + "' is not a finite number");
  return v;
}

struct Options {
  std::string problem;
  std::map<std::string, std::string> params;
  std::string integrator;
  double accuracy = 1e-3;  // Simbody's default accuracy
  double constraint_tolerance = std::nan("");
  double t_end = 10;
  double every = 0.01;
  std::string out;
};

const char* kUsage =
    "usage: cstab-peer-simbody --problem pendulum|slider-crank [--problem-param k=v[,k=v]] "
    "--integrator rk3|rkmerson|rkfeldberg|verlet|euler|cpodes [--accuracy A (1e-3)] "
    "[--constraint-tolerance C (0.1 A)] [--t-end T (10)] [--every DT (0.01)] --out FILE.csv";

Options parse(int argc, char** argv) {
  Options o;
  bool have_accuracy = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      std::cout << kUsage << "\n";
      std::exit(0);
    }
    if (a.rfind("--", 0) != 0) bad("unexpected argument '" + a + "'");
    if (i + 1 >= argc) bad(a + ": needs a value");
    const std::string v = argv[++i];
    if (a == "--problem") {
      o.problem = v;
    } else if (a == "--problem-param") {
      std::stringstream ss(v);
      std::string item;
      while (std::getline(ss, item, ',')) {
        const size_t eq = item.find('=');
        if (eq == std::string::npos || eq == 0) bad("--problem-param: '" + item + "' is not k=v");
        o.params[item.substr(0, eq)] = item.substr(eq + 1);
      }
    } else if (a == "--integrator") {
      o.integrator = v;
    } else if (a == "--accuracy") {
      o.accuracy = number(a, v);
      have_accuracy = true;
    } else if (a == "--constraint-tolerance") {
      o.constraint_tolerance = number(a, v);
    } else if (a == "--t-end") {
      o.t_end = number(a, v);
    } else if (a == "--every") {
      o.every = number(a, v);
    } else if (a == "--out") {
      o.out = v;
    } else {
      bad("unknown option '" + a + "'");
    }
  }
  (void)have_accuracy;
  if (o.problem.empty()) bad("--problem is required (pendulum or slider-crank)");
  if (o.problem != "pendulum" && o.problem != "slider-crank")
    bad("--problem: '" + o.problem + "' is not modelled (pendulum, slider-crank)");
  if (o.integrator.empty()) bad("--integrator is required (rk3, rkmerson, rkfeldberg, verlet, euler, cpodes)");
  static const char* known[] = {"rk3", "rkmerson", "rkfeldberg", "verlet", "euler", "cpodes"};
  bool ok = false;
  for (const char* k : known) ok = ok || o.integrator == k;
  if (!ok) bad("--integrator: '" + o.integrator + "' is not one of rk3, rkmerson, rkfeldberg, verlet, euler, cpodes");
  if (!(o.accuracy > 0 && o.accuracy < 1)) bad("--accuracy: must be in (0, 1)");
  if (std::isnan(o.constraint_tolerance)) o.constraint_tolerance = 0.1 * o.accuracy;
  if (!(o.constraint_tolerance > 0 && o.constraint_tolerance < 1)) bad("--constraint-tolerance: must be in (0, 1)");
  if (!(o.t_end > 0)) bad("--t-end: must be > 0");
  if (!(o.every > 0) || o.t_end / o.every > 1e7) bad("--every: must be > 0 and give at most 1e7 rows");
  if (o.out.empty()) bad("--out FILE.csv is required");
  return o;
}

// ---------------------------------------------------------------------------
// The models. Each builds its System, sets the initial state and reads the
// canonical coordinates (cstab list) back from a State.

struct Model {
  MultibodySystem system;
  SimbodyMatterSubsystem matter{system};
  GeneralForceSubsystem forces{system};
  virtual ~Model() = default;
  virtual std::vector<std::string> columns() const = 0;
  virtual void initial_state(State& s) const = 0;
  virtual void canonical(const State& s, double* c) const = 0;
};

// cstab's `pendulum`: a point mass m on a massless rod of length L pivoted at
// the origin, gravity g along -y, released at rest at `angle` degrees from the
// downward vertical. In Simbody: the bob moves in the plane on a Cartesian
// pair of sliders (x, then y; the x carriage is massless), and a
// Constraint::Rod of length L ties it to the ground origin. The rod is the
// constraint Simbody's integrator projects onto.
struct PendulumModel : Model {
  double m = 1.0, L = 1.0, g = 9.81, angle = 90.0;  // as PendulumParameters
  MobilizedBody::Slider sx, sy;

  explicit PendulumModel(const std::map<std::string, std::string>& params) {
    for (const auto& [k, v] : params) {
      if (k == "length") {
        L = number("--problem-param length", v);
        if (!(L >= 0.01 && L <= 100)) bad("--problem-param length: must be in [0.01, 100]");
      } else if (k == "angle") {
        angle = number("--problem-param angle", v);
        if (!(angle >= -179 && angle <= 179)) bad("--problem-param angle: must be in [-179, 179]");
      } else {
        bad("--problem-param: pendulum has no parameter '" + k + "' (length, angle)");
      }
    }
    Force::UniformGravity(forces, matter, Vec3(0, -g, 0));
    sx = MobilizedBody::Slider(matter.Ground(), Transform(), Body::Massless(), Transform());
    const Transform along_y(Rotation(Pi / 2, ZAxis));
    sy = MobilizedBody::Slider(sx, along_y, Body::Rigid(MassProperties(m, Vec3(0), Inertia(0))), along_y);
    Constraint::Rod(matter.Ground(), Vec3(0), sy, Vec3(0), L);
  }
  std::vector<std::string> columns() const override { return {"x", "y", "xdot", "ydot"}; }
  void initial_state(State& s) const override {
    const double theta0 = angle * std::acos(-1.0) / 180;
    sx.setOneQ(s, 0, L * std::sin(theta0));
    sy.setOneQ(s, 0, -L * std::cos(theta0));
    sx.setOneU(s, 0, 0);
    sy.setOneU(s, 0, 0);
  }
  void canonical(const State& s, double* c) const override {
    c[0] = sx.getOneQ(s, 0);
    c[1] = sy.getOneQ(s, 0);
    c[2] = sx.getOneU(s, 0);
    c[3] = sy.getOneU(s, 0);
  }
};

// cstab's `slider-crank` (SUNDIALS' idasSlCrank_dns): crank of length a
// pinned at the origin (angle q, inertia J1 about the pivot), a slider on the
// x axis (position x, mass m2), and a connecting rod of length 1 pinned to
// the slider (absolute angle p, inertia J2, its own mass not translating:
// the example's M = diag(J1, m2, J2)). Tree: Ground -Pin- crank and Ground
// -Slider- slider -Pin- rod; the loop is closed by a Constraint::PointOnLine
// holding the crank's end on the rod's z line through the rod's far end,
// i.e. the two ends coincide in the plane (2 equations, the example's Phi1
// and Phi2 rotated; a Constraint::Ball would add a third, redundant row).
// Forces: a linear spring (k, free length l0) and damper (c) between the
// crank's midpoint and the rod's midpoint, and a constant force (F, 0) at
// the point of the rod's line one rod length beyond the slider,
// (x + cos p, sin p), whose generalized force is the example's (0, F, -F sin p).
// No gravity.
struct SliderCrankModel : Model {
  // As SliderCrankParameters.
  double a = 0.5, J1 = 1.0, m2 = 1.0, J2 = 2.0, k = 1.0, c = 1.0, l0 = 1.0, F = 1.0;
  MobilizedBody::Pin crank, rod;
  MobilizedBody::Slider slider;

  explicit SliderCrankModel(const std::map<std::string, std::string>& params) {
    if (!params.empty()) bad("--problem-param: slider-crank has no parameters ('" + params.begin()->first + "')");
    // Simbody stores a body's inertia per unit mass, so a body needs a mass
    // (mass 0 with an inertia gives NaN). Every rotation is about z, so only
    // the z inertia matters (planar discs: J/2, J/2, J). The crank gets 1 kg
    // at its pivot, where it does no work (no gravity; the pivot is fixed):
    // its kinetic energy stays J1 q'^2 / 2. The slider block is lumped into
    // the rod at the rod's slider end: the carriage is massless and the rod
    // carries m2 at its origin (the slider point, which moves with x') with
    // central inertia J2, so T = m2 x'^2 / 2 + J2 p'^2 / 2, the example's.
    crank = MobilizedBody::Pin(matter.Ground(), Transform(),
                               Body::Rigid(MassProperties(1, Vec3(0), Inertia(J1 / 2, J1 / 2, J1))), Transform());
    slider = MobilizedBody::Slider(matter.Ground(), Transform(), Body::Massless(), Transform());
    rod = MobilizedBody::Pin(slider, Transform(),
                             Body::Rigid(MassProperties(m2, Vec3(0), Inertia(J2 / 2, J2 / 2, J2))), Transform());
    // In the rod's frame the slider end is the origin and the crank end is
    // (-1, 0, 0): slider - crank end = (cos p, sin p).
    Constraint::PointOnLine(rod, UnitVec3(ZAxis), Vec3(-1, 0, 0), crank, Vec3(a, 0, 0));
    Force::TwoPointLinearSpring(forces, crank, Vec3(a / 2, 0, 0), rod, Vec3(-0.5, 0, 0), k, l0);
    Force::TwoPointLinearDamper(forces, crank, Vec3(a / 2, 0, 0), rod, Vec3(-0.5, 0, 0), c);
    Force::ConstantForce(forces, rod, Vec3(1, 0, 0), Vec3(F, 0, 0));
  }
  std::vector<std::string> columns() const override { return {"q", "x", "p", "qdot", "xdot", "pdot"}; }
  void initial_state(State& s) const override {
    // The example's setIC(): q = pi/2, p = asin(-a), x = cos p, at rest.
    const double pi = 4 * std::atan(1.0);
    const double p = std::asin(-a);
    crank.setOneQ(s, 0, pi / 2);
    slider.setOneQ(s, 0, std::cos(p));
    rod.setOneQ(s, 0, p);
    crank.setOneU(s, 0, 0);
    slider.setOneU(s, 0, 0);
    rod.setOneU(s, 0, 0);
  }
  void canonical(const State& s, double* out) const override {
    out[0] = crank.getOneQ(s, 0);
    out[1] = slider.getOneQ(s, 0);
    out[2] = rod.getOneQ(s, 0);
    out[3] = crank.getOneU(s, 0);
    out[4] = slider.getOneU(s, 0);
    out[5] = rod.getOneU(s, 0);
  }
};

std::unique_ptr<Integrator> make_integrator(const std::string& name, const System& system) {
  if (name == "rk3") return std::make_unique<RungeKutta3Integrator>(system);
  if (name == "rkmerson") return std::make_unique<RungeKuttaMersonIntegrator>(system);
  if (name == "rkfeldberg") return std::make_unique<RungeKuttaFeldbergIntegrator>(system);
  if (name == "verlet") return std::make_unique<VerletIntegrator>(system);
  // Simbody's error-controlled semi-explicit (symplectic) Euler; the
  // fixed-step SemiExplicitEulerIntegrator has no accuracy to sweep.
  if (name == "euler") return std::make_unique<SemiExplicitEuler2Integrator>(system);
  return std::make_unique<CPodesIntegrator>(system, CPodes::BDF, CPodes::Newton);
}

std::string one_line(std::string s) {
  for (char& ch : s)
    if (ch == '\n' || ch == '\r') ch = ' ';
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  std::unique_ptr<Model> model;
  std::ofstream out;
  try {
    o = parse(argc, argv);
    if (o.problem == "pendulum")
      model = std::make_unique<PendulumModel>(o.params);
    else
      model = std::make_unique<SliderCrankModel>(o.params);
    out.open(o.out);
    if (!out) bad("--out: cannot write '" + o.out + "'");
  } catch (const BadInput& e) {
    std::cerr << kProgram << ": " << e.message << "\n";
    return 2;
  }

  const std::vector<std::string> columns = model->columns();
  const size_t nc = columns.size();
  std::vector<double> rows;  // (t, canonical...) per report
  auto record = [&](const State& s) {
    rows.push_back(s.getTime());
    const size_t at = rows.size();
    rows.resize(at + nc);
    model->canonical(s, rows.data() + at);
  };

  std::string error;
  double wall = 0, energy0 = std::nan("");
  double accuracy_in_use = std::nan(""), tolerance_in_use = std::nan("");
  long steps = 0, attempts = 0, q_projections = 0, u_projections = 0, realizations = 0;
  std::unique_ptr<Integrator> integ;
  State initial;
  try {
    model->system.realizeTopology();
    State state = model->system.getDefaultState();
    model->initial_state(state);
    integ = make_integrator(o.integrator, model->system);
    integ->setAccuracy(o.accuracy);
    integ->setConstraintTolerance(o.constraint_tolerance);
    integ->setFinalTime(o.t_end);
    TimeStepper stepper(model->system, *integ);

    const auto start = std::chrono::steady_clock::now();
    auto stop_clock = [&] { wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
    try {
      stepper.initialize(state);
      initial = integ->getState();
      record(initial);
      // Reports at k * every, and at t_end exactly.
      for (long k = 1;; ++k) {
        double t = k * o.every;
        if (t >= o.t_end * (1 - 1e-12)) t = o.t_end;
        stepper.stepTo(t);
        record(integ->getState());
        if (integ->isSimulationOver() && integ->getState().getTime() < o.t_end)
          throw std::runtime_error("Simbody ended the simulation at t = " +
                                   std::to_string(integ->getState().getTime()) + ": " +
                                   Integrator::getTerminationReasonString(integ->getTerminationReason()));
        if (t == o.t_end) break;
      }
      stop_clock();
    } catch (...) {
      stop_clock();
      throw;
    }
  } catch (const std::exception& e) {
    error = one_line(e.what());
  }
  if (integ) {
    try {
      accuracy_in_use = integ->getAccuracyInUse();
      tolerance_in_use = integ->getConstraintToleranceInUse();
      steps = integ->getNumStepsTaken();
      attempts = integ->getNumStepsAttempted();
      q_projections = integ->getNumQProjections();
      u_projections = integ->getNumUProjections();
      realizations = integ->getNumRealizations();
    } catch (const std::exception&) {
    }
  }
  if (!rows.empty()) {
    // Simbody's own energy of the first written state (kinetic plus the
    // potential of its force elements), for the test against cstab's.
    try {
      model->system.realize(initial, Stage::Dynamics);
      energy0 = model->system.calcEnergy(initial);
    } catch (const std::exception&) {
    }
  }

  char buf[64];
  auto g17 = [&](double v) {
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return std::string(buf);
  };
  out << "# wall_seconds = " << g17(wall) << "\n";
  out << "# simbody_problem = " << o.problem << "\n";
  out << "# simbody_integrator = " << o.integrator << " (" << (integ ? integ->getMethodName() : "?") << ")\n";
  out << "# simbody_accuracy = " << g17(accuracy_in_use) << "\n";
  out << "# simbody_constraint_tolerance = " << g17(tolerance_in_use) << "\n";
  out << "# simbody_steps = " << steps << "\n";
  out << "# simbody_steps_attempted = " << attempts << "\n";
  out << "# simbody_q_projections = " << q_projections << "\n";
  out << "# simbody_u_projections = " << u_projections << "\n";
  out << "# simbody_realizations = " << realizations << "\n";
  out << "# simbody_initial_energy = " << g17(energy0) << "\n";
  if (!error.empty()) out << "# simbody_error = " << error << "\n";
  out << "t";
  for (const auto& name : columns) out << "," << name;
  out << "\n";
  for (size_t i = 0; i < rows.size(); i += nc + 1) {
    for (size_t j = 0; j <= nc; ++j) out << (j ? "," : "") << g17(rows[i + j]);
    out << "\n";
  }
  out.close();
  if (!out) {
    std::cerr << kProgram << ": cannot write '" << o.out << "'\n";
    return 2;
  }
  const size_t nrows = rows.size() / (nc + 1);
  if (!error.empty()) {
    std::cerr << kProgram << ": Simbody failed (" << o.problem << ", " << o.integrator << ", accuracy " << o.accuracy
              << "): " << error << "; wrote " << nrows << " rows to " << o.out << "\n";
    return 1;
  }
  std::cout << o.problem << " / simbody " << o.integrator << " accuracy " << o.accuracy << " constraint tolerance "
            << tolerance_in_use << ": t = " << o.t_end << ", " << steps << " steps, " << q_projections
            << " q-projections, wall " << wall << " s, wrote " << nrows << " rows to " << o.out << "\n";
  return 0;
}
