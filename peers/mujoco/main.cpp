// cstab-peer-mujoco: cstab's problems modelled in MuJoCo (issue 20, item 3),
// writing trajectories in the problems' canonical coordinates for
// `cstab score` (docs/cli-score.md). What is modelled and how, and the
// parameter mapping: docs/peers-mujoco.md.
//
//   cstab-peer-mujoco --problem pendulum|slider-crank|n-four-bar [--problem-param k=v[,k=v]]
//                     --integrator euler|rk4|implicit --timestep H
//                     [--solref T,D] [--solimp D0,D1,W[,MID,POW]]
//                     --t-end T --every DT --out FILE.csv
//
// Exit 0: the run finished; 1: MuJoCo failed to load the model, warned
// during the run (bad qacc/qpos/qvel, singular inertia) or the state went
// non-finite: the rows simulated until then are written and the warning is
// printed; 2: bad input, one line.
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace {

const char* kProgram = "cstab-peer-mujoco";

[[noreturn]] void usage_error(const std::string& what) {
  std::fprintf(stderr, "%s: %s (see --help)\n", kProgram, what.c_str());
  std::exit(2);
}

const char* kHelp =
    "usage: cstab-peer-mujoco --problem pendulum|slider-crank|n-four-bar [--problem-param k=v[,k=v...]]\n"
    "                         --integrator euler|rk4|implicit --timestep H\n"
    "                         [--solref T,D] [--solimp D0,D1,W[,MID,POW]]\n"
    "                         --t-end T --every DT --out FILE.csv\n"
    "  pendulum params: length (m, default 1), angle (degrees from the downward vertical, default 90)\n"
    "  slider-crank: no params (SUNDIALS idasSlCrank_dns)\n"
    "  n-four-bar params: N (the number of four-bar loops, an integer in [1, 1000], default 40; IFToMM A02)\n"
    "  solref/solimp default to MuJoCo's (0.02,1) and (0.9,0.95,0.001,0.5,2), set on the loop/rod equalities\n"
    "  t-end and every must be whole multiples of the timestep; rows are t = n * H\n"
    "  the first line of FILE is '# wall_seconds = S' (mj_step loop only, file writing excluded)\n";

double parse_number(const std::string& text, const std::string& what) {
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(v))
    usage_error(what + ": '" + text + "' is not a finite number");
  return v;
}

std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> out;
  size_t start = 0;
  while (true) {
    const size_t at = text.find(sep, start);
    out.push_back(text.substr(start, at == std::string::npos ? std::string::npos : at - start));
    if (at == std::string::npos) break;
    start = at + 1;
  }
  return out;
}

std::vector<double> parse_list(const std::string& text, const std::string& what, size_t min_n, size_t max_n) {
  std::vector<double> out;
  for (const auto& item : split(text, ',')) out.push_back(parse_number(item, what));
  if (out.size() < min_n || out.size() > max_n)
    usage_error(what + ": expected " + std::to_string(min_n) +
                (min_n == max_n ? "" : ".." + std::to_string(max_n)) + " comma-separated numbers, got '" + text +
                "'");
  return out;
}

// %.17g: every double the model is built from survives the XML round trip.
std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

struct Options {
  std::string problem, integrator, out;
  std::vector<std::pair<std::string, std::string>> params;
  double timestep = NAN, t_end = NAN, every = NAN;
  std::vector<double> solref = {0.02, 1.0};                   // MuJoCo's default
  std::vector<double> solimp = {0.9, 0.95, 0.001, 0.5, 2.0};  // MuJoCo 2.2's default
  bool solref_given = false, solimp_given = false;
};

Options parse_args(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::fputs(kHelp, stdout);
      std::exit(0);
    }
    if (arg.rfind("--", 0) != 0) usage_error("unexpected argument '" + arg + "'");
    if (i + 1 >= argc) usage_error(arg + " needs a value");
    const std::string value = argv[++i];
    if (arg == "--problem") {
      o.problem = value;
    } else if (arg == "--problem-param") {
      for (const auto& kv : split(value, ',')) {
        const size_t eq = kv.find('=');
        if (eq == std::string::npos || eq == 0) usage_error("--problem-param: expected k=v, got '" + kv + "'");
        o.params.emplace_back(kv.substr(0, eq), kv.substr(eq + 1));
      }
    } else if (arg == "--integrator") {
      o.integrator = value;
    } else if (arg == "--timestep") {
      o.timestep = parse_number(value, "--timestep");
    } else if (arg == "--t-end") {
      o.t_end = parse_number(value, "--t-end");
    } else if (arg == "--every") {
      o.every = parse_number(value, "--every");
    } else if (arg == "--out") {
      o.out = value;
    } else if (arg == "--solref") {
      o.solref = parse_list(value, "--solref", 2, 2);
      o.solref_given = true;
    } else if (arg == "--solimp") {
      o.solimp = parse_list(value, "--solimp", 3, 5);
      o.solimp_given = true;
    } else {
      usage_error("unknown option '" + arg + "'");
    }
  }
  if (o.problem.empty()) usage_error("--problem is required (pendulum, slider-crank or n-four-bar)");
  if (o.problem != "pendulum" && o.problem != "slider-crank" && o.problem != "n-four-bar")
    usage_error("unknown problem '" + o.problem + "' (pendulum, slider-crank or n-four-bar)");
  if (o.integrator.empty()) usage_error("--integrator is required (euler, rk4 or implicit)");
  if (o.integrator != "euler" && o.integrator != "rk4" && o.integrator != "implicit")
    usage_error("unknown integrator '" + o.integrator + "' (euler, rk4 or implicit)");
  if (std::isnan(o.timestep)) usage_error("--timestep is required");
  if (!(o.timestep > 0)) usage_error("--timestep must be > 0");
  if (std::isnan(o.t_end)) usage_error("--t-end is required");
  if (!(o.t_end > 0)) usage_error("--t-end must be > 0");
  if (std::isnan(o.every)) usage_error("--every is required");
  if (!(o.every > 0)) usage_error("--every must be > 0");
  if (o.out.empty()) usage_error("--out is required");
  // MuJoCo reads solref (T, D) with T > 0 as a time constant and damping
  // ratio; negative values mean (-stiffness, -damping), which we also pass on.
  if (o.solref[0] == 0 || o.solref[1] == 0 || (o.solref[0] > 0) != (o.solref[1] > 0))
    usage_error("--solref: expected T,D both > 0 (time constant, damping ratio) or both < 0");
  if (!(o.solimp[0] > 0 && o.solimp[0] < 1 && o.solimp[1] > 0 && o.solimp[1] < 1 && o.solimp[2] >= 0))
    usage_error("--solimp: expected 0 < D0, D1 < 1 and width >= 0");
  return o;
}

long long whole_multiple(double span, double h, const char* what) {
  const double n = span / h;
  const long long k = std::llround(n);
  if (k < 1 || std::abs(n - double(k)) > 1e-9 * std::max(1.0, n))
    usage_error(std::string(what) + " = " + num(span) + " is not a whole multiple of --timestep " + num(h));
  return k;
}

// ---------------------------------------------------------------------------
// The models. Each is an MJCF string, built with the problem's parameters,
// and the map from MuJoCo's qpos/qvel to cstab's canonical coordinates.

// cstab's pendulum (problems/pendulum/pendulum.hpp): point mass m = 1 on a
// massless rod L = 1 pivoted at the origin, g = 9.81 along -y, released at
// rest at `angle` degrees from the downward vertical. cstab's (x, y) plane
// with y up is MuJoCo's (x, z) plane with z up; gravity is MuJoCo's -z.
// The mass is a body on two slide joints (world x and world z), so its mass
// matrix is m I exactly (its rotational inertia enters no equation; MuJoCo
// needs one, so it is 1e-6). The rod is a spatial tendon from a world site
// at the pivot to a site at the mass, held at its length at qpos0 (= L) by a
// tendon equality: the constraint |r| - L = 0, cstab's x^2 + y^2 - L^2 = 0
// on the same manifold, and the one MuJoCo keeps softly (solref, solimp).
struct PendulumParams {
  double m = 1.0, L = 1.0, g = 9.81, angle = 90.0;
};

PendulumParams pendulum_params(const Options& o) {
  PendulumParams p;
  for (const auto& [k, v] : o.params) {
    if (k == "length") {
      p.L = parse_number(v, "--problem-param length");
      if (!(p.L > 0)) usage_error("--problem-param length must be > 0");
    } else if (k == "angle") {
      p.angle = parse_number(v, "--problem-param angle");
    } else {
      usage_error("pendulum has no parameter '" + k + "' (length, angle)");
    }
  }
  return p;
}

std::string solattrs(const Options& o) {
  std::string s = " solref=\"" + num(o.solref[0]) + " " + num(o.solref[1]) + "\" solimp=\"";
  for (size_t i = 0; i < o.solimp.size(); ++i) {
    if (i) s += ' ';
    s += num(o.solimp[i]);
  }
  return s + "\"";
}

std::string option_block(const Options& o, const std::string& gravity) {
  const char* integ = o.integrator == "euler" ? "Euler" : o.integrator == "rk4" ? "RK4" : "implicit";
  return "  <compiler angle=\"radian\" inertiafromgeom=\"false\"/>\n"
         "  <option timestep=\"" + num(o.timestep) + "\" integrator=\"" + integ + "\" gravity=\"" + gravity +
         "\">\n"
         "    <flag contact=\"disable\"/>\n"
         "  </option>\n";
}

std::string pendulum_xml(const Options& o, const PendulumParams& p) {
  // The same expressions as PendulumMechanical::initial_state.
  const double theta0 = p.angle * std::acos(-1.0) / 180;
  const double x0 = p.L * std::sin(theta0), y0 = -p.L * std::cos(theta0);
  return "<mujoco model=\"cstab-pendulum\">\n" + option_block(o, "0 0 " + num(-p.g)) +
         "  <worldbody>\n"
         "    <site name=\"pivot\" pos=\"0 0 0\"/>\n"
         "    <body name=\"mass\" pos=\"" + num(x0) + " 0 " + num(y0) + "\">\n"
         "      <inertial pos=\"0 0 0\" mass=\"" + num(p.m) + "\" diaginertia=\"1e-6 1e-6 1e-6\"/>\n"
         "      <joint name=\"x\" type=\"slide\" axis=\"1 0 0\" ref=\"" + num(x0) + "\"/>\n"
         "      <joint name=\"y\" type=\"slide\" axis=\"0 0 1\" ref=\"" + num(y0) + "\"/>\n"
         "      <site name=\"tip\" pos=\"0 0 0\"/>\n"
         "    </body>\n"
         "  </worldbody>\n"
         "  <tendon>\n"
         "    <spatial name=\"rod\">\n"
         "      <site site=\"pivot\"/>\n"
         "      <site site=\"tip\"/>\n"
         "    </spatial>\n"
         "  </tendon>\n"
         "  <equality>\n"
         "    <tendon name=\"rod\" tendon1=\"rod\" polycoef=\"0 1 0 0 0\"" + solattrs(o) + "/>\n"
         "  </equality>\n"
         "</mujoco>\n";
}

// cstab's slider-crank (problems/slider_crank/slider_crank.hpp, SUNDIALS'
// idasSlCrank_dns): crank angle q, slider location x, rod angle p; kinetic
// energy (J1 q'^2 + m2 x'^2 + J2 p'^2) / 2; joint x - cos p - a cos q = 0,
// -sin p - a sin q = 0; spring-damper (k, c, l0) from the crank midpoint to
// the rod midpoint; force F along +x whose generalized force is
// (0, F, -F sin p). In MuJoCo (x-y plane, no gravity):
//  * crank: body at the origin, hinge about z (q), centre of mass at the
//    pivot with inertia J1 about z (its mass, 1, enters no equation);
//  * rod: one body with a slide along world x (x) then a hinge about z (p)
//    at its origin, the slider end (x, 0); mass m2 there, inertia J2 about
//    z: the example's M = diag(J1, m2, J2) exactly. Its other end is local
//    (-1, 0, 0), i.e. (x - cos p, -sin p);
//  * the loop is closed by a `connect` equality at the crank tip, local
//    (a, 0, 0) of the crank; MuJoCo puts the matching point of the rod
//    where it is at qpos0, the consistent initial configuration, so it is
//    the rod's end (-1, 0, 0) to round-off;
//  * spring-damper: a spatial tendon from (a/2, 0, 0) on the crank to
//    (-1/2, 0, 0) on the rod, stiffness k, damping c, springlength l0;
//  * F: added to qfrc_passive by mjcb_passive as (0, F, -F sin p), the
//    example's generalized force, at every force evaluation (RK4 stages
//    included).
// Joint refs are the initial values, and the bodies are built in the
// initial configuration, so qpos is the canonical (q, x, p) itself.
struct SliderCrankParams {
  double a = 0.5, J1 = 1.0, m2 = 1.0, J2 = 2.0, k = 1.0, c = 1.0, l0 = 1.0, F = 1.0;
};

std::string slider_crank_xml(const Options& o, const SliderCrankParams& p) {
  // The same expressions as SliderCrankMechanical::initial_state.
  const double pi = 4 * std::atan(1.0);
  const double q0 = pi / 2, p0 = std::asin(-p.a), x0 = std::cos(p0);
  return "<mujoco model=\"cstab-slider-crank\">\n" + option_block(o, "0 0 0") +
         "  <worldbody>\n"
         "    <body name=\"crank\" pos=\"0 0 0\" euler=\"0 0 " + num(q0) + "\">\n"
         "      <inertial pos=\"0 0 0\" mass=\"1\" diaginertia=\"" + num(p.J1) + " " + num(p.J1) + " " + num(p.J1) +
         "\"/>\n"
         "      <joint name=\"q\" type=\"hinge\" axis=\"0 0 1\" pos=\"0 0 0\" ref=\"" + num(q0) + "\"/>\n"
         "      <site name=\"crank_mid\" pos=\"" + num(p.a / 2) + " 0 0\"/>\n"
         "    </body>\n"
         // Slide axis in the rod's (rotated by p0) frame: world x.
         "    <body name=\"rod\" pos=\"" + num(x0) + " 0 0\" euler=\"0 0 " + num(p0) + "\">\n"
         "      <inertial pos=\"0 0 0\" mass=\"" + num(p.m2) + "\" diaginertia=\"" + num(p.J2) + " " + num(p.J2) +
         " " + num(p.J2) + "\"/>\n"
         "      <joint name=\"x\" type=\"slide\" axis=\"" + num(std::cos(p0)) + " " + num(-std::sin(p0)) +
         " 0\" ref=\"" + num(x0) + "\"/>\n"
         "      <joint name=\"p\" type=\"hinge\" axis=\"0 0 1\" pos=\"0 0 0\" ref=\"" + num(p0) + "\"/>\n"
         "      <site name=\"rod_mid\" pos=\"-0.5 0 0\"/>\n"
         "    </body>\n"
         "  </worldbody>\n"
         "  <tendon>\n"
         "    <spatial name=\"spring\" stiffness=\"" + num(p.k) + "\" damping=\"" + num(p.c) +
         "\" springlength=\"" + num(p.l0) + "\">\n"
         "      <site site=\"crank_mid\"/>\n"
         "      <site site=\"rod_mid\"/>\n"
         "    </spatial>\n"
         "  </tendon>\n"
         "  <equality>\n"
         "    <connect name=\"loop\" body1=\"crank\" body2=\"rod\" anchor=\"" + num(p.a) + " 0 0\"" + solattrs(o) +
         "/>\n"
         "  </equality>\n"
         "</mujoco>\n";
}

// The slider crank's force F, as the example's generalized force.
double g_F = 0;
int g_dof_x = -1, g_dof_p = -1, g_qpos_p = -1;
void slider_crank_force(const mjModel*, mjData* d) {
  d->qfrc_passive[g_dof_x] += g_F;
  d->qfrc_passive[g_dof_p] += -g_F * std::sin(d->qpos[g_qpos_p]);
}

// cstab's n-four-bar (problems/n_four_bar/n_four_bar.hpp, IFToMM A02): N
// four-bar loops sharing their bars, 2N + 1 uniform bars (L = 1 m,
// m = 1 kg), g = 9.81 along -y. In MuJoCo's x-y plane, which is cstab's
// (gravity "0 -9.81 0", every hinge about z):
//  * crank i (0..N): a body at A_i = (i L, 0), built at the initial angle
//    theta0 = pi/2 (pi = acos(-1), as NFourBarMinimal) so its local x runs
//    along the bar, with a hinge `A<i>` about z at its origin (ref theta0, so
//    its qpos is the crank angle from +x);
//  * coupler i (0..N-1): a child body of crank i at its tip B_i, local
//    (L, 0, 0), built at -theta0 relative to the crank (horizontal), with a
//    hinge `B<i>` about z there (ref -theta0: qpos is the angle relative to
//    the crank); its far end, local (L, 0, 0), is joined to the tip of crank
//    i + 1 by a `connect` equality (MuJoCo places the matching point on the
//    crank where it is at qpos0: the crank's tip, to round-off). N loops:
//    2N + 1 hinges, 2N independent equality rows (the z rows vanish), one
//    degree of freedom, as in cstab;
//  * each bar: `inertial` mass m at its midpoint, local (L/2, 0, 0),
//    diaginertia (kAxial, m L^2/12, m L^2/12): a uniform thin bar. Every
//    joint is a hinge about z, so only the z inertia m L^2/12 enters the
//    mass matrix; the axial one enters no equation (MuJoCo needs it > 0);
//  * the canonical B_i is crank i's tip from its hinge: (i L + L cos q,
//    L sin q), velocity (-L sin q, L cos q) q'. The cranks' hinges are exact
//    joints, so the crank rows are round-off and the coupler rows measure
//    the soft connects' gap along the coupler;
//  * start: cranks vertical at q' = -speed / L (B0's x velocity +speed), the
//    couplers' relative rate +speed / L (they translate): qvel, set before
//    the first step; the velocity constraints hold exactly there.
struct NFourBarParams {
  int N = 40;
  double m = 1.0, L = 1.0, g = 9.81, speed = 1.0;
};

NFourBarParams n_four_bar_params(const Options& o) {
  NFourBarParams p;
  for (const auto& [k, v] : o.params) {
    if (k == "N") {
      const double n = parse_number(v, "--problem-param N");
      if (!(n >= 1 && n <= 1000 && n == std::floor(n)))
        usage_error("--problem-param N must be an integer in [1, 1000], got '" + v + "'");
      p.N = int(n);
    } else {
      usage_error("n-four-bar has no parameter '" + k + "' (N)");
    }
  }
  return p;
}

// The axial inertia of a thin bar (zero for a line): enters no equation.
constexpr double kAxial = 1e-9;

std::string n_four_bar_xml(const Options& o, const NFourBarParams& p) {
  const double theta0 = std::acos(-1.0) / 2;
  const double Iz = p.m * p.L * p.L / 12;
  const std::string bar = "      <inertial pos=\"" + num(p.L / 2) + " 0 0\" mass=\"" + num(p.m) + "\" diaginertia=\"" +
                          num(kAxial) + " " + num(Iz) + " " + num(Iz) + "\"/>\n";
  std::string xml =
      "<mujoco model=\"cstab-n-four-bar\">\n" + option_block(o, "0 " + num(-p.g) + " 0") + "  <worldbody>\n";
  for (int i = 0; i <= p.N; ++i) {
    const std::string s = std::to_string(i);
    xml += "    <body name=\"crank" + s + "\" pos=\"" + num(i * p.L) + " 0 0\" euler=\"0 0 " + num(theta0) + "\">\n" +
           bar + "      <joint name=\"A" + s + "\" type=\"hinge\" axis=\"0 0 1\" pos=\"0 0 0\" ref=\"" + num(theta0) +
           "\"/>\n";
    if (i < p.N)
      xml += "      <body name=\"coupler" + s + "\" pos=\"" + num(p.L) + " 0 0\" euler=\"0 0 " + num(-theta0) +
             "\">\n  " + bar + "        <joint name=\"B" + s + "\" type=\"hinge\" axis=\"0 0 1\" pos=\"0 0 0\" ref=\"" +
             num(-theta0) +
             "\"/>\n"
             "      </body>\n";
    xml += "    </body>\n";
  }
  xml += "  </worldbody>\n  <equality>\n";
  for (int i = 0; i < p.N; ++i)
    xml += "    <connect name=\"loop" + std::to_string(i) + "\" body1=\"coupler" + std::to_string(i) +
           "\" body2=\"crank" + std::to_string(i + 1) + "\" anchor=\"" + num(p.L) + " 0 0\"" + solattrs(o) + "/>\n";
  return xml + "  </equality>\n</mujoco>\n";
}

// MuJoCo's warnings and errors: kept for the one-line report, not written
// to MUJOCO_LOG.TXT.
std::string g_warning;
void on_warning(const char* msg) {
  if (g_warning.empty()) g_warning = msg;
}
void on_error(const char* msg) {
  std::fprintf(stderr, "%s: MuJoCo error: %s\n", kProgram, msg);
  std::exit(1);
}

mjModel* load_from_string(const std::string& xml) {
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  const char* name = "cstab-model.xml";
  if (mj_makeEmptyFileVFS(vfs.get(), name, int(xml.size())) != 0) {
    std::fprintf(stderr, "%s: could not make the model file in MuJoCo's VFS\n", kProgram);
    std::exit(1);
  }
  const int i = mj_findFileVFS(vfs.get(), name);
  std::memcpy(vfs->filedata[i], xml.data(), xml.size());
  char error[1000] = "";
  mjModel* m = mj_loadXML(name, vfs.get(), error, sizeof error);
  mj_deleteVFS(vfs.get());
  if (!m) {
    std::fprintf(stderr, "%s: MuJoCo could not load the generated model: %s\n", kProgram, error);
    std::exit(1);
  }
  return m;
}

int id_of(const mjModel* m, int type, const char* name) {
  const int id = mj_name2id(m, type, name);
  if (id < 0) {
    std::fprintf(stderr, "%s: internal: no %s in the model\n", kProgram, name);
    std::exit(1);
  }
  return id;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse_args(argc, argv);
  const long long steps = whole_multiple(o.t_end, o.timestep, "--t-end");
  const long long every = whole_multiple(o.every, o.timestep, "--every");

  std::string xml;
  std::vector<std::string> columns;
  NFourBarParams four_bar;
  if (o.problem == "pendulum") {
    xml = pendulum_xml(o, pendulum_params(o));
    columns = {"x", "y", "xdot", "ydot"};
  } else if (o.problem == "n-four-bar") {
    four_bar = n_four_bar_params(o);
    xml = n_four_bar_xml(o, four_bar);
    for (const char* d : {"", "dot"})
      for (int i = 0; i <= four_bar.N; ++i)
        for (const char* c : {"x", "y"}) columns.push_back(c + std::string(d) + "_B" + std::to_string(i));
  } else {
    if (!o.params.empty()) usage_error("slider-crank has no parameters (got '" + o.params.front().first + "')");
    xml = slider_crank_xml(o, SliderCrankParams{});
    columns = {"q", "x", "p", "qdot", "xdot", "pdot"};
  }
  if (const char* dump = std::getenv("CSTAB_PEER_MUJOCO_DUMP_XML")) {
    if (FILE* f = std::fopen(dump, "w")) {
      std::fputs(xml.c_str(), f);
      std::fclose(f);
    }
  }

  // An --out that cannot be written is bad input, found before the run.
  FILE* f = std::fopen(o.out.c_str(), "w");
  if (!f) usage_error("--out: cannot write " + o.out + ": " + std::strerror(errno));

  mju_user_warning = on_warning;
  mju_user_error = on_error;
  mjModel* m = load_from_string(xml);
  mjData* d = mj_makeData(m);

  // qpos/qvel addresses of the canonical coordinates, in canonical order.
  std::vector<int> qadr, vadr;
  if (o.problem == "pendulum") {
    for (const char* j : {"x", "y"}) {
      const int id = id_of(m, mjOBJ_JOINT, j);
      qadr.push_back(m->jnt_qposadr[id]);
      vadr.push_back(m->jnt_dofadr[id]);
    }
    mjcb_passive = nullptr;
  } else if (o.problem == "n-four-bar") {
    // qadr/vadr: the cranks' hinges A0..AN; the canonical B_i comes from them.
    for (int i = 0; i <= four_bar.N; ++i) {
      const std::string index = std::to_string(i), crank = "A" + index, coupler = "B" + index;
      const int id = id_of(m, mjOBJ_JOINT, crank.c_str());
      qadr.push_back(m->jnt_qposadr[id]);
      vadr.push_back(m->jnt_dofadr[id]);
      d->qvel[m->jnt_dofadr[id]] = -four_bar.speed / four_bar.L;
      if (i < four_bar.N) d->qvel[m->jnt_dofadr[id_of(m, mjOBJ_JOINT, coupler.c_str())]] = four_bar.speed / four_bar.L;
    }
    mjcb_passive = nullptr;
  } else {
    for (const char* j : {"q", "x", "p"}) {
      const int id = id_of(m, mjOBJ_JOINT, j);
      qadr.push_back(m->jnt_qposadr[id]);
      vadr.push_back(m->jnt_dofadr[id]);
    }
    g_F = SliderCrankParams{}.F;
    g_dof_x = vadr[1];
    g_dof_p = vadr[2];
    g_qpos_p = qadr[2];
    mjcb_passive = slider_crank_force;
  }
  const size_t width = 1 + columns.size();

  std::vector<double> rows;
  rows.reserve(size_t(steps / every + 2) * width);
  auto record = [&](long long n) {
    rows.push_back(double(n) * o.timestep);
    if (o.problem == "n-four-bar") {
      // B_i, crank i's tip, from its hinge: the expressions of
      // NFourBarMinimal::to_canonical.
      const double L = four_bar.L;
      for (size_t i = 0; i < qadr.size(); ++i) {
        const double q = d->qpos[qadr[i]];
        rows.push_back(double(i) * L + L * std::cos(q));
        rows.push_back(L * std::sin(q));
      }
      for (size_t i = 0; i < qadr.size(); ++i) {
        const double q = d->qpos[qadr[i]], w = d->qvel[vadr[i]];
        rows.push_back(-L * std::sin(q) * w);
        rows.push_back(L * std::cos(q) * w);
      }
      return;
    }
    for (int a : qadr) rows.push_back(d->qpos[a]);
    for (int a : vadr) rows.push_back(d->qvel[a]);
  };
  auto finite_state = [&] {
    for (int i = 0; i < m->nq; ++i)
      if (!std::isfinite(d->qpos[i])) return false;
    for (int i = 0; i < m->nv; ++i)
      if (!std::isfinite(d->qvel[i])) return false;
    return true;
  };
  auto warned = [&] {
    for (int w : {mjWARN_INERTIA, mjWARN_BADQPOS, mjWARN_BADQVEL, mjWARN_BADQACC})
      if (d->warning[w].number > 0) return true;
    return false;
  };

  // mj_makeData leaves qpos = qpos0 (the joint refs: the initial state) and
  // qvel = 0 (the pendulum and slider crank start at rest; n-four-bar's qvel
  // is set above).
  std::string failure;
  long long n = 0;
  const auto start = std::chrono::steady_clock::now();
  record(0);
  for (n = 1; n <= steps; ++n) {
    mj_step(m, d);
    // A warning (MuJoCo resets the state after a bad qacc) or a non-finite
    // state ends the run; its rows so far are what was simulated.
    if (warned() || !finite_state()) {
      failure = !g_warning.empty() ? g_warning : "non-finite state";
      break;
    }
    if (n % every == 0 || n == steps) record(n);
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  std::fprintf(f, "# wall_seconds = %.9g\n", wall);
  std::fprintf(f, "# MuJoCo %s, %s, integrator %s, timestep %s, solref %s,%s, solimp", mj_versionString(),
               o.problem.c_str(), o.integrator.c_str(), num(o.timestep).c_str(), num(o.solref[0]).c_str(),
               num(o.solref[1]).c_str());
  for (size_t i = 0; i < o.solimp.size(); ++i) std::fprintf(f, "%s%s", i ? "," : " ", num(o.solimp[i]).c_str());
  std::fprintf(f, "\n");
  std::fprintf(f, "t");
  for (const auto& c : columns) std::fprintf(f, ",%s", c.c_str());
  std::fprintf(f, "\n");
  const size_t nrows = rows.size() / width;
  for (size_t r = 0; r < nrows; ++r) {
    for (size_t c = 0; c < width; ++c) std::fprintf(f, c ? ",%.17g" : "%.17g", rows[r * width + c]);
    std::fprintf(f, "\n");
  }
  const bool write_ok = std::fclose(f) == 0;
  mj_deleteData(d);
  mj_deleteModel(m);
  if (!write_ok) {
    std::fprintf(stderr, "%s: error writing %s\n", kProgram, o.out.c_str());
    return 1;
  }
  if (!failure.empty()) {
    std::fprintf(stderr, "%s: %s / %s / h = %s: MuJoCo failed at step %lld (t = %s): %s; wrote the %zu rows before it to %s\n",
                 kProgram, o.problem.c_str(), o.integrator.c_str(), num(o.timestep).c_str(), n,
                 num(double(n) * o.timestep).c_str(), failure.c_str(), nrows, o.out.c_str());
    return 1;
  }
  std::fprintf(stderr, "%s: %s / %s / h = %s: %lld steps in %.3g s, wrote %zu rows to %s\n", kProgram,
               o.problem.c_str(), o.integrator.c_str(), num(o.timestep).c_str(), steps, wall, nrows, o.out.c_str());
  return 0;
}
