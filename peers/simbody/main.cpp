// cstab-peer-simbody: cstab's problems modelled in Simbody 3.7, integrated by
// one of Simbody's integrators at a given accuracy and constraint tolerance,
// and written as a trajectory `cstab score` reads (docs/peers-simbody.md).
//
//   cstab-peer-simbody --problem pendulum|slider-crank|bricard|andrews|car-axis|n-four-bar
//       [--problem-param k=v[,k=v]] [--closure redundant|independent]
//       --integrator rk3|rkmerson|rkfeldberg|verlet|euler|cpodes --accuracy A
//       [--constraint-tolerance C] [--t-end T] [--every DT] --out FILE.csv
//
// The program is deliberately independent of cstab's code: it restates the
// problems' parameters (problems/pendulum/pendulum.hpp,
// problems/slider_crank/slider_crank.hpp, problems/bricard/bricard.hpp,
// problems/andrews/andrews.hpp, problems/car_axis/car_axis.hpp,
// problems/n_four_bar/n_four_bar.hpp) the way an outside user would, and
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
  std::string closure;     // bricard only: redundant (default) or independent
  double accuracy = 1e-3;  // Simbody's default accuracy
  double constraint_tolerance = std::nan("");
  double t_end = 10;
  double every = 0.01;
  std::string out;
};

const char* kUsage =
    "usage: cstab-peer-simbody --problem pendulum|slider-crank|bricard|andrews|car-axis|n-four-bar "
    "[--problem-param k=v[,k=v] (pendulum: length, angle; n-four-bar: N)] "
    "--integrator rk3|rkmerson|rkfeldberg|verlet|euler|cpodes [--accuracy A (1e-3)] "
    "[--closure redundant|independent (bricard; redundant)] "
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
    } else if (a == "--closure") {
      o.closure = v;
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
  if (o.problem.empty())
    bad("--problem is required (pendulum, slider-crank, bricard, andrews, car-axis or n-four-bar)");
  if (o.problem != "pendulum" && o.problem != "slider-crank" && o.problem != "bricard" && o.problem != "andrews" &&
      o.problem != "car-axis" && o.problem != "n-four-bar")
    bad("--problem: '" + o.problem +
        "' is not modelled (pendulum, slider-crank, bricard, andrews, car-axis, n-four-bar)");
  if (!o.closure.empty() && o.problem != "bricard") bad("--closure: only bricard has a choice of loop closure");
  if (o.closure.empty() && o.problem == "bricard") o.closure = "redundant";
  if (o.problem == "bricard" && o.closure != "redundant" && o.closure != "independent")
    bad("--closure: '" + o.closure + "' is not redundant or independent");
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
  // d/dt of the canonical velocities at s (realized to Acceleration), for the
  // test against cstab's; empty where a model does not report them.
  virtual std::vector<double> accelerations(const State&) const { return {}; }
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

// cstab's `bricard` (IFToMM A04, problems/bricard/bricard.hpp): five rods of
// length L and mass m joined end to end by revolute joints, from P0 on the
// ground through P1..P4 back to P5 on the ground; gravity g along -y; released
// at rest. cstab's coordinates are the rods' ends P1..P4 and their velocities.
//
// In Simbody: a tree of five Pin mobilizers, Ground -> rod 1 -> ... -> rod 5,
// the loop closed at P5 by a Constraint::Ball (rod 5's end on the ground
// point) plus two Constraint::ConstantAngle rows holding rod 5's joint axis
// perpendicular to two ground directions that are perpendicular to the ground
// joint's axis (what a revolute adds to a ball). Five mobilities, five closure
// rows: Grubler's count is 0, the mechanism moves with 1, so one closure row
// is redundant and Simbody's projection and multipliers have to cope with a
// rank-4 constraint Jacobian. `--closure independent` leaves the second
// ConstantAngle out: four rows, of rank 4 along the motion (the redundancy
// removed by hand; docs/peers-simbody.md shows what it changes).
//
// Every pose is written in the starting configuration: each joint's frame has
// its z axis on the joint axis (the axis at Pj is d_j x d_{j+1}, d_k = Pk -
// P(k-1), the ground closing the loop with d_0 = d_6 = P0 - P5), each rod's
// body frame has its origin at the rod's start and its x axis along the rod,
// and every Pin's two frames coincide there, so every q = 0 at t = 0.
//
// Rods are slender: centre of mass at (L/2, 0, 0), inertia m L^2/12 about the
// two axes perpendicular to the rod through its centre and 0 about the rod's
// own axis, i.e. (0, m L^2/3, m L^2/3) about the rod's start (the body
// origin). Simbody accepts that singular inertia: it satisfies the triangle
// inequality (0 + I >= I) its Inertia checks, and the tree's mass matrix stays
// positive definite because each Pin's axis is fixed in, and perpendicular
// to, its own rod, so every mobility moves mass (a rod's spin about its own
// axis, carried in from the rods before it, has no inertia and does no work).
// Gravity's potential is zero at y = 0, as cstab's m g (y1 + y2 + y3 + y4).
struct BricardModel : Model {
  double m = 1.0, L = 1.0, g = 9.81;  // as BricardParameters
  MobilizedBody::Pin rods[5];

  BricardModel(const std::map<std::string, std::string>& params, bool redundant) {
    if (!params.empty()) bad("--problem-param: bricard has no parameters ('" + params.begin()->first + "')");
    Force::UniformGravity(forces, matter, Vec3(0, -g, 0));
    // The joints P0..P5 and the rods' directions d[1..5]; d[0] = d[6] is the
    // ground's side of the loop, P0 - P5.
    const Vec3 P[6] = {Vec3(0, 0, 0), Vec3(L, 0, 0), Vec3(L, -L, 0), Vec3(L, -L, L), Vec3(0, -L, L), Vec3(0, 0, L)};
    Vec3 d[7];
    for (int k = 1; k <= 5; ++k) d[k] = P[k] - P[k - 1];
    d[0] = d[6] = P[0] - P[5];
    // X_GJ[j]: joint j at Pj, z along its axis d_j x d_{j+1}.
    Transform X_GJ[6];
    for (int j = 0; j <= 5; ++j) X_GJ[j] = Transform(Rotation(UnitVec3(d[j] % d[j + 1]), ZAxis), P[j]);
    // X_GB[k]: rod k's body frame, origin P(k-1), x along the rod, y along
    // the axis of its inboard joint (perpendicular to the rod).
    Transform X_GB[6];  // X_GB[0]: Ground
    for (int k = 1; k <= 5; ++k) X_GB[k] = Transform(Rotation(UnitVec3(d[k]), XAxis, X_GJ[k - 1].z(), YAxis), P[k - 1]);
    const Body::Rigid rod(MassProperties(m, Vec3(L / 2, 0, 0), Inertia(0, m * L * L / 3, m * L * L / 3)));
    MobilizedBody parent = matter.Ground();
    for (int k = 1; k <= 5; ++k) {
      // Joint k-1 joins the parent (Ground or rod k-1) and rod k.
      rods[k - 1] = MobilizedBody::Pin(parent, ~X_GB[k - 1] * X_GJ[k - 1], rod, ~X_GB[k] * X_GJ[k - 1]);
      parent = rods[k - 1];
    }
    // The closure at P5: rod 5's end on the ground point, and rod 5's axis of
    // joint 5 (fixed in rod 5) kept perpendicular to the ground joint frame's
    // x and y, i.e. along its z: 3 + 2 rows (3 + 1 if not redundant).
    MobilizedBody::Pin& rod5 = rods[4];
    Constraint::Ball(matter.Ground(), P[5], rod5, Vec3(L, 0, 0));
    const UnitVec3 axis5_in_rod5(~X_GB[5].R() * X_GJ[5].z());
    Constraint::ConstantAngle(matter.Ground(), UnitVec3(X_GJ[5].x()), rod5, axis5_in_rod5, Pi / 2);
    if (redundant) Constraint::ConstantAngle(matter.Ground(), UnitVec3(X_GJ[5].y()), rod5, axis5_in_rod5, Pi / 2);
  }
  std::vector<std::string> columns() const override {
    std::vector<std::string> c;
    for (const char* suffix : {"", "dot"})
      for (int k = 1; k <= 4; ++k)
        for (const char* axis : {"x", "y", "z"}) c.push_back(axis + std::to_string(k) + suffix);
    return c;
  }
  void initial_state(State& s) const override {
    // The benchmark's start is the configuration the frames were laid out in.
    for (const auto& r : rods) {
      r.setOneQ(s, 0, 0);
      r.setOneU(s, 0, 0);
    }
  }
  void canonical(const State& s, double* c) const override {
    system.realize(s, Stage::Velocity);
    for (int k = 0; k < 4; ++k) {
      // Pk+1 is rod k+1's far end.
      const Vec3 p = rods[k].findStationLocationInGround(s, Vec3(L, 0, 0));
      const Vec3 v = rods[k].findStationVelocityInGround(s, Vec3(L, 0, 0));
      for (int i = 0; i < 3; ++i) c[3 * k + i] = p[i], c[12 + 3 * k + i] = v[i];
    }
  }
};

// cstab's `andrews` (Andrews' squeezing mechanism as the IVP Test Set
// defines it, problems/andrews/andrews.hpp; Hairer & Wanner II, VII.7):
// seven bodies in the plane, no gravity, a constant torque mom on the crank
// and a spring c0 (free length l0) from the ground point C to the point D of
// body 3. The Test Set's coordinates are the angles
// (beta, Theta, gamma, Phi, delta, Omega, epsilon): beta, gamma, delta and
// epsilon absolute, Theta, Phi and Omega relative to the body carrying the
// joint. In Simbody each is one Pin's q, every rotation about z:
//   Ground -O- body 1 (beta) -[rr, 0]- body 2 (Theta)
//   Ground -B- body 3 (gamma)
//   Ground -A- body 5 (delta) -[zt, 0]- body 4 (Phi)
//   Ground -A- body 7 (epsilon) -[0, -u]- body 6 (Omega)
// and the loop closes where all three chains meet the point F: F on body 2
// at (-d, 0), on body 3 at (0, -ss), on body 4 at (0, -e), on body 6 at
// (zf, 0) in their frames (read off the Test Set's g1..g6). Three
// Constraint::PointOnLine, each holding body 2's F on the z line through
// another body's F, give the six rows of g (planar coincidences, as for the
// slider crank); 7 mobilities, 6 independent rows, 1 degree of freedom.
//
// Masses and inertias: each body's central inertia i_k about z (the only
// axis that turns; (i/2, i/2, i) makes a valid 3-D inertia) at its centre of
// mass, which sits where the Test Set's mass matrix puts it: body 2 at
// (-da, 0), body 4 at (0, -(e - ea)), body 6 at (zf - fa, 0) (the joint
// terms of M(q)), and bodies 1, 3, 5, 7, which turn about a ground point, at
// (ra, 0), (sa, sb), (ta, tb), (ua, ub) (only the distance enters M).
struct AndrewsModel : Model {
  // As AndrewsParameters (the Test Set's values).
  double m1 = .04325, m2 = .00365, m3 = .02373, m4 = .00706, m5 = .07050, m6 = .00706, m7 = .05498;
  double xa = -.06934, ya = -.00227, xb = -.03635, yb = .03273, xc = .014, yc = .072;
  double c0 = 4530;
  double i1 = 2.194e-6, i2 = 4.410e-7, i3 = 5.255e-6, i4 = 5.667e-7, i5 = 1.169e-5, i6 = 5.667e-7, i7 = 1.912e-5;
  double d = 28e-3, da = 115e-4, e = 2e-2, ea = 1421e-5, rr = 7e-3, ra = 92e-5, l0 = 7785e-5;
  double ss = 35e-3, sa = 1874e-5, sb = 1043e-5, sc = 18e-3, sd = 2e-2;
  double ta = 2308e-5, tb = 916e-5, u = 4e-2, ua = 1228e-5, ub = 449e-5;
  double zf = 2e-2, zt = 4e-2, fa = 1421e-5, mom = 33e-3;
  // In the Test Set's order beta, Theta, gamma, Phi, delta, Omega, epsilon.
  MobilizedBody::Pin joints[7];

  static Body::Rigid body(double m, const Vec3& com, double i) {
    return Body::Rigid(MassProperties(m, com, Inertia(i / 2, i / 2, i).shiftFromMassCenter(com, m)));
  }

  explicit AndrewsModel(const std::map<std::string, std::string>& params) {
    if (!params.empty()) bad("--problem-param: andrews has no parameters ('" + params.begin()->first + "')");
    auto& G = matter.Ground();
    auto at = [](double x, double y) { return Transform(Vec3(x, y, 0)); };
    MobilizedBody::Pin b1(G, Transform(), body(m1, Vec3(ra, 0, 0), i1), Transform());
    MobilizedBody::Pin b2(b1, at(rr, 0), body(m2, Vec3(-da, 0, 0), i2), Transform());
    MobilizedBody::Pin b3(G, at(xb, yb), body(m3, Vec3(sa, sb, 0), i3), Transform());
    MobilizedBody::Pin b5(G, at(xa, ya), body(m5, Vec3(ta, tb, 0), i5), Transform());
    MobilizedBody::Pin b4(b5, at(zt, 0), body(m4, Vec3(0, -(e - ea), 0), i4), Transform());
    MobilizedBody::Pin b7(G, at(xa, ya), body(m7, Vec3(ua, ub, 0), i7), Transform());
    MobilizedBody::Pin b6(b7, at(0, -u), body(m6, Vec3(zf - fa, 0, 0), i6), Transform());
    joints[0] = b1, joints[1] = b2, joints[2] = b3, joints[3] = b4, joints[4] = b5, joints[5] = b6, joints[6] = b7;
    const Vec3 f2(-d, 0, 0);
    Constraint::PointOnLine(b3, UnitVec3(ZAxis), Vec3(0, -ss, 0), b2, f2);
    Constraint::PointOnLine(b4, UnitVec3(ZAxis), Vec3(0, -e, 0), b2, f2);
    Constraint::PointOnLine(b6, UnitVec3(ZAxis), Vec3(zf, 0, 0), b2, f2);
    Force::MobilityConstantForce(forces, b1, 0, mom);
    Force::TwoPointLinearSpring(forces, G, Vec3(xc, yc, 0), b3, Vec3(sd, -sc, 0), c0, l0);
  }
  std::vector<std::string> columns() const override {
    std::vector<std::string> c;
    for (const char* suffix : {"", "dot"})
      for (const char* name : {"beta", "Theta", "gamma", "Phi", "delta", "Omega", "epsilon"})
        c.push_back(name + std::string(suffix));
    return c;
  }
  void initial_state(State& s) const override {
    // The Test Set's consistent initial values (its y1..y7), at rest.
    const double q0[7] = {-0.0617138900142764496358948458001, 0.0,
                          0.455279819163070380255912382449,   0.222668390165885884674473185609,
                          0.487364979543842550225598953530,   -0.222668390165885884674473185609,
                          1.23054744454982119249735015568};
    for (int k = 0; k < 7; ++k) {
      joints[k].setOneQ(s, 0, q0[k]);
      joints[k].setOneU(s, 0, 0);
    }
  }
  void canonical(const State& s, double* c) const override {
    for (int k = 0; k < 7; ++k) c[k] = joints[k].getOneQ(s, 0), c[7 + k] = joints[k].getOneU(s, 0);
  }
};

// cstab's `car-axis` (the IVP Test Set's caraxis, problems/car_axis/car_axis.hpp):
// two wheel points l = (xl, yl) and r = (xr, yr) of mass k = M eps^2 / 2 in the
// plane, joined by an axle of length L; a spring (stiffness 1, free length
// L0) from the origin to l and another from the moving bump
// b(t) = (xb, yb), yb = r sin(w t), xb = sqrt(L^2 - yb^2), to r; gravity g
// along -y. Constraints: Phi1 = xb(t) xl + yb(t) yl = 0 (l stays on the line
// through the origin normal to b(t)) and the axle's length.
//
// In Simbody each wheel point moves on a Cartesian pair of sliders as the
// pendulum's bob (x carriage massless, the y slider carrying k). The axle is
// a Constraint::Rod of length L between the two points; Phi1, which moves
// with time, is a Constraint::Custom on the left pair's q (RoadConstraint:
// its position error is Phi1 itself, its first and second time derivatives
// include the explicit ones through b(t), its force is lambda dPhi1/dq as
// Simbody's own CoordinateCoupler and PrescribedMotion apply theirs). The
// left spring is a Force::TwoPointLinearSpring from the ground origin; the
// right one, anchored at the moving bump, a Force::Custom (BumpSpring).
struct CarAxisParams {
  double eps = 1e-2, M = 10, L = 1, L0 = 0.5, r = 0.1, w = 10, g = 1;  // as CarAxisParameters
  double k() const { return M * eps * eps / 2; }
  // b(t) and its first two time derivatives.
  void bump(double t, double& xb, double& yb, double& xb1, double& yb1, double& xb2, double& yb2) const {
    yb = r * std::sin(w * t);
    xb = std::sqrt(L * L - yb * yb);
    yb1 = r * w * std::cos(w * t);
    xb1 = -yb * yb1 / xb;
    yb2 = -w * w * yb;
    xb2 = -(xb1 * xb1 + yb1 * yb1 + yb * yb2) / xb;
  }
};

class RoadConstraint : public Constraint::Custom::Implementation {
 public:
  RoadConstraint(SimbodyMatterSubsystem& matter, const CarAxisParams& p, const MobilizedBody& x, const MobilizedBody& y)
      : Implementation(matter, 1, 0, 0), p_(p), x_(addConstrainedMobilizer(x)), y_(addConstrainedMobilizer(y)) {}
  Implementation* clone() const override { return new RoadConstraint(*this); }

  void calcPositionErrors(const State& s, const Array_<Transform, ConstrainedBodyIndex>&,
                          const Array_<Real, ConstrainedQIndex>& q, Array_<Real>& perr) const override {
    double xb, yb, xb1, yb1, xb2, yb2;
    p_.bump(s.getTime(), xb, yb, xb1, yb1, xb2, yb2);
    perr[0] = xb * getOneQ(s, q, x_, kQ) + yb * getOneQ(s, q, y_, kQ);
  }
  void calcPositionDotErrors(const State& s, const Array_<SpatialVec, ConstrainedBodyIndex>&,
                             const Array_<Real, ConstrainedQIndex>& qdot, Array_<Real>& pverr) const override {
    double xb, yb, xb1, yb1, xb2, yb2;
    p_.bump(s.getTime(), xb, yb, xb1, yb1, xb2, yb2);
    const double xl = getOneQFromState(s, x_, kQ), yl = getOneQFromState(s, y_, kQ);
    pverr[0] = xb1 * xl + yb1 * yl + xb * getOneQDot(s, qdot, x_, kQ) + yb * getOneQDot(s, qdot, y_, kQ);
  }
  void calcPositionDotDotErrors(const State& s, const Array_<SpatialVec, ConstrainedBodyIndex>&,
                                const Array_<Real, ConstrainedQIndex>& qdotdot, Array_<Real>& paerr) const override {
    double xb, yb, xb1, yb1, xb2, yb2;
    p_.bump(s.getTime(), xb, yb, xb1, yb1, xb2, yb2);
    const double xl = getOneQFromState(s, x_, kQ), yl = getOneQFromState(s, y_, kQ);
    const double vx = getOneQDotFromState(s, x_, kQ), vy = getOneQDotFromState(s, y_, kQ);
    paerr[0] = xb2 * xl + yb2 * yl + 2 * (xb1 * vx + yb1 * vy) + xb * getOneQDotDot(s, qdotdot, x_, kQ) +
               yb * getOneQDotDot(s, qdotdot, y_, kQ);
  }
  void addInPositionConstraintForces(const State& s, const Array_<Real>& multipliers,
                                     Array_<SpatialVec, ConstrainedBodyIndex>&,
                                     Array_<Real, ConstrainedQIndex>& qForces) const override {
    double xb, yb, xb1, yb1, xb2, yb2;
    p_.bump(s.getTime(), xb, yb, xb1, yb1, xb2, yb2);
    addInOneQForce(s, x_, kQ, multipliers[0] * xb, qForces);
    addInOneQForce(s, y_, kQ, multipliers[0] * yb, qForces);
  }

 private:
  static const MobilizerQIndex kQ;
  CarAxisParams p_;
  ConstrainedMobilizerIndex x_, y_;
};

const MobilizerQIndex RoadConstraint::kQ(0);  // a Slider's only q

class BumpSpring : public Force::Custom::Implementation {
 public:
  BumpSpring(const CarAxisParams& p, const MobilizedBody& wheel) : p_(p), wheel_(wheel) {}
  void calcForce(const State& s, Vector_<SpatialVec>& bodyForces, Vector_<Vec3>&, Vector&) const override {
    Vec3 d;
    double len;
    stretch(s, d, len);
    wheel_.applyForceToBodyPoint(s, Vec3(0), (p_.L0 - len) / len * d, bodyForces);
  }
  Real calcPotentialEnergy(const State& s) const override {
    Vec3 d;
    double len;
    stretch(s, d, len);
    return 0.5 * (len - p_.L0) * (len - p_.L0);
  }

 private:
  // The wheel point less the bump point, and its length.
  void stretch(const State& s, Vec3& d, double& len) const {
    double xb, yb, xb1, yb1, xb2, yb2;
    p_.bump(s.getTime(), xb, yb, xb1, yb1, xb2, yb2);
    d = wheel_.getBodyOriginLocation(s) - Vec3(xb, yb, 0);
    len = d.norm();
  }
  CarAxisParams p_;
  MobilizedBody wheel_;
};

struct CarAxisModel : Model {
  CarAxisParams p;
  MobilizedBody::Slider sxl, syl, sxr, syr;

  explicit CarAxisModel(const std::map<std::string, std::string>& params) {
    if (!params.empty()) bad("--problem-param: car-axis has no parameters ('" + params.begin()->first + "')");
    Force::UniformGravity(forces, matter, Vec3(0, -p.g, 0));
    const Transform along_y(Rotation(Pi / 2, ZAxis));
    const Body::Rigid wheel(MassProperties(p.k(), Vec3(0), Inertia(0)));
    sxl = MobilizedBody::Slider(matter.Ground(), Transform(), Body::Massless(), Transform());
    syl = MobilizedBody::Slider(sxl, along_y, wheel, along_y);
    sxr = MobilizedBody::Slider(matter.Ground(), Transform(), Body::Massless(), Transform());
    syr = MobilizedBody::Slider(sxr, along_y, wheel, along_y);
    Constraint::Custom(new RoadConstraint(matter, p, sxl, syl));
    Constraint::Rod(syl, Vec3(0), syr, Vec3(0), p.L);
    Force::TwoPointLinearSpring(forces, matter.Ground(), Vec3(0), syl, Vec3(0), 1.0, p.L0);
    Force::Custom(forces, new BumpSpring(p, syr));
  }
  std::vector<std::string> columns() const override {
    return {"xl", "yl", "xr", "yr", "xldot", "yldot", "xrdot", "yrdot"};
  }
  void initial_state(State& s) const override {
    // The Test Set's consistent initial values.
    const double q0[4] = {0, p.L0, p.L, p.L0}, u0[4] = {-p.L0 / p.L, 0, -p.L0 / p.L, 0};
    const MobilizedBody::Slider* m[4] = {&sxl, &syl, &sxr, &syr};
    for (int i = 0; i < 4; ++i) {
      m[i]->setOneQ(s, 0, q0[i]);
      m[i]->setOneU(s, 0, u0[i]);
    }
  }
  void canonical(const State& s, double* c) const override {
    const MobilizedBody::Slider* m[4] = {&sxl, &syl, &sxr, &syr};
    for (int i = 0; i < 4; ++i) c[i] = m[i]->getOneQ(s, 0), c[4 + i] = m[i]->getOneU(s, 0);
  }
  std::vector<double> accelerations(const State& s) const override {
    system.realize(s, Stage::Acceleration);
    return {sxl.getOneUDot(s, 0), syl.getOneUDot(s, 0), sxr.getOneUDot(s, 0), syr.getOneUDot(s, 0)};
  }
};

// cstab's `n-four-bar` (IFToMM A02, problems/n_four_bar/n_four_bar.hpp): N
// four-bar loops sharing their bars, 2N + 1 uniform bars of length L and mass
// m, gravity g along -y. Cranks A_i B_i (i = 0..N) turn about the ground
// points A_i = (i L, 0); couplers B_i B_(i+1) (i = 0..N-1) join their tips.
// Starts with every crank vertical (B_i = (i L, L)) and B0 moving at `speed`
// along +x: every crank turns at -speed / L and the couplers translate.
//
// In Simbody: crank i is a MobilizedBody::Pin from Ground at A_i whose body
// frame has its origin at A_i and x along the crank, so its q is the crank's
// angle from +x (pi/2 at the start, u = -speed / L); coupler i is a Pin on
// crank i's tip (L, 0, 0), its body frame's origin at B_i and x along the
// coupler, its q the coupler's angle relative to crank i (-pi/2 at the
// start, u = +speed / L, so that it translates). Loop i is closed by a
// Constraint::PointOnLine holding coupler i's far end (L, 0, 0) on the z
// line through crank i+1's tip: two rows, the planar coincidence (as for the
// slider crank; a Constraint::Ball would add a z row that is identically
// zero, since every Pin turns about z, i.e. a redundant row everywhere).
// 2N + 1 mobilities, 2N closure rows, one degree of freedom; the rows are
// independent except at the singular positions, where every bar is
// horizontal and each loop's x row loses rank (docs/peers-simbody.md).
//
// Every Pin turns about z, so the motion is planar by construction: no body
// can leave the plane z = 0 or turn about x or y, and only the z inertia
// enters the dynamics. Bars are uniform thin rods: centre of mass at
// (L/2, 0, 0), m L^2/12 about the two transverse axes through it and 0 about
// the bar's own axis, i.e. (0, m L^2/3, m L^2/3) about the bar's start (the
// body origin), as Bricard's rods. Gravity's potential is m g y_centre per
// bar, zero at y = 0, cstab's m g / 2 (y at each bar end) summed.
struct NFourBarModel : Model {
  int N = 40;  // as NFourBarParameters
  double m = 1.0, L = 1.0, g = 9.81, speed = 1.0;
  std::vector<MobilizedBody::Pin> cranks, couplers;

  explicit NFourBarModel(const std::map<std::string, std::string>& params) {
    for (const auto& [k, v] : params) {
      if (k != "N") bad("--problem-param: n-four-bar has no parameter '" + k + "' (N)");
      const double n = number("--problem-param N", v);
      if (!(n >= 1 && n <= 1000) || n != std::floor(n)) bad("--problem-param N: must be an integer in [1, 1000]");
      N = int(n);
    }
    Force::UniformGravity(forces, matter, Vec3(0, -g, 0));
    const Body::Rigid bar(MassProperties(m, Vec3(L / 2, 0, 0), Inertia(0, m * L * L / 3, m * L * L / 3)));
    for (int i = 0; i <= N; ++i)
      cranks.push_back(MobilizedBody::Pin(matter.Ground(), Transform(Vec3(i * L, 0, 0)), bar, Transform()));
    for (int i = 0; i < N; ++i) {
      couplers.push_back(MobilizedBody::Pin(cranks[i], Transform(Vec3(L, 0, 0)), bar, Transform()));
      Constraint::PointOnLine(cranks[i + 1], UnitVec3(ZAxis), Vec3(L, 0, 0), couplers[i], Vec3(L, 0, 0));
    }
  }
  std::vector<std::string> columns() const override {
    std::vector<std::string> c;
    for (const char* suffix : {"", "dot"})
      for (int i = 0; i <= N; ++i)
        for (const char* axis : {"x", "y"}) c.push_back(axis + std::string(suffix) + "_B" + std::to_string(i));
    return c;
  }
  void initial_state(State& s) const override {
    const double half_pi = std::acos(-1.0) / 2;
    for (const auto& crank : cranks) {
      crank.setOneQ(s, 0, half_pi);
      crank.setOneU(s, 0, -speed / L);
    }
    for (const auto& coupler : couplers) {
      coupler.setOneQ(s, 0, -half_pi);
      coupler.setOneU(s, 0, speed / L);
    }
  }
  void canonical(const State& s, double* c) const override {
    system.realize(s, Stage::Velocity);
    const int n = 2 * (N + 1);
    for (int i = 0; i <= N; ++i) {
      // B0 is crank 0's tip; B_i (i >= 1) coupler i-1's far end, which the
      // closure holds on crank i's tip to within the constraint tolerance
      // (with the cranks' tips instead, the rows cstab scores would only see
      // whether the cranks stay parallel, which they do by symmetry to
      // round-off, and not Simbody's closure error).
      const MobilizedBody& body = i == 0 ? cranks[0] : couplers[i - 1];
      const Vec3 p = body.findStationLocationInGround(s, Vec3(L, 0, 0));
      const Vec3 v = body.findStationVelocityInGround(s, Vec3(L, 0, 0));
      c[2 * i] = p[0], c[2 * i + 1] = p[1], c[n + 2 * i] = v[0], c[n + 2 * i + 1] = v[1];
    }
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
    else if (o.problem == "slider-crank")
      model = std::make_unique<SliderCrankModel>(o.params);
    else if (o.problem == "bricard")
      model = std::make_unique<BricardModel>(o.params, o.closure == "redundant");
    else if (o.problem == "andrews")
      model = std::make_unique<AndrewsModel>(o.params);
    else if (o.problem == "car-axis")
      model = std::make_unique<CarAxisModel>(o.params);
    else
      model = std::make_unique<NFourBarModel>(o.params);
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
  std::vector<double> accelerations0, accelerations_end;
  double accuracy_in_use = std::nan(""), tolerance_in_use = std::nan("");
  long steps = 0, attempts = 0, q_projections = 0, u_projections = 0, realizations = 0;
  std::unique_ptr<Integrator> integ;
  State initial, last;
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
      last = integ->getState();
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
      accelerations0 = model->accelerations(initial);
      // And of the last row's state, after a complete run.
      if (error.empty()) accelerations_end = model->accelerations(last);
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
  if (!o.closure.empty()) out << "# simbody_closure = " << o.closure << "\n";
  out << "# simbody_integrator = " << o.integrator << " (" << (integ ? integ->getMethodName() : "?") << ")\n";
  out << "# simbody_accuracy = " << g17(accuracy_in_use) << "\n";
  out << "# simbody_constraint_tolerance = " << g17(tolerance_in_use) << "\n";
  out << "# simbody_steps = " << steps << "\n";
  out << "# simbody_steps_attempted = " << attempts << "\n";
  out << "# simbody_q_projections = " << q_projections << "\n";
  out << "# simbody_u_projections = " << u_projections << "\n";
  out << "# simbody_realizations = " << realizations << "\n";
  out << "# simbody_initial_energy = " << g17(energy0) << "\n";
  auto list = [&](const char* key, const std::vector<double>& values) {
    if (values.empty()) return;
    out << "# " << key << " =";
    for (size_t i = 0; i < values.size(); ++i) out << (i ? "," : " ") << g17(values[i]);
    out << "\n";
  };
  list("simbody_initial_accelerations", accelerations0);
  list("simbody_final_accelerations", accelerations_end);
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
