#include "cli/commands.hpp"

#include <CLI/CLI.hpp>

#include <iostream>
#include <memory>
#include <sstream>

#include "cli/args.hpp"
#include "cli/matrix_commands.hpp"
#include "core/format.hpp"
#include "harness/integrator.hpp"
#include "harness/run.hpp"
#include "methods/pair.hpp"
#include "plugin/loader.hpp"
#include "problems/registry.hpp"

namespace cstab::cli {

namespace {

// Names of the integrators that take --step (fixed) or --rtol/--atol.
std::string integrator_names(bool fixed_step) {
  std::string names;
  for (const auto& i : all_integrators())
    if (i.fixed_step == fixed_step) names += (names.empty() ? "" : ", ") + i.name;
  return names;
}

void declare_list(Args&) {}

int cmd_list(const Args&) {
  std::ostringstream out;
  out << "PROBLEMS\n";
  for (const auto& p : all_problems()) {
    const auto& info = p->info();
    out << "  " << info.name << ": " << info.description << "\n";
    if (!problem_origin(info.name).empty()) out << "    from plugin " << problem_origin(info.name) << "\n";
    for (const auto& s : p->problem_params()) out << "    --problem-param " << param_line(s) << "\n";
    out << "    coordinates: ";
    for (size_t i = 0; i < info.coordinates.size(); ++i) out << (i ? "," : "") << info.coordinates[i];
    out << "\n    first integrals: " << (info.has_energy ? "energy" : "none (no energy law)");
    for (const auto& fi : info.first_integrals) out << ", " << fi;
    out << "\n    reference: "
        << (info.reference_time > 0 ? info.reference_description + " (default at t = " +
                                          format_short(info.reference_time) + ")"
                                    : std::string("none"))
        << "\n";
    for (const auto& f : info.formulations) {
      out << "    formulation " << f.name << ": " << f.description << "\n";
      for (const auto& c : f.constraints)
        out << "      constraint " << c.name << " [" << c.kind << "]: " << c.description << "\n";
    }
    out << "    methods:";
    for (const auto& m : all_methods()) {
      const std::string why = p->why_not(m.name);
      out << " " << m.name << (why.empty() ? "" : " (n/a: " + why + ")");
    }
    out << "\n";
  }
  out << "METHODS\n";
  for (const auto& m : all_methods()) {
    out << "  " << m.name << ": " << m.description << "\n";
    if (!method_origin(m.name).empty()) out << "    from plugin " << method_origin(m.name) << "\n";
    for (const auto& s : m.params) out << "    --param " << param_line(s) << "\n";
  }
  out << "INTEGRATORS\n";
  for (const auto& i : all_integrators())
    out << "  " << i.name << ": " << i.description << (i.fixed_step ? "  [--step]" : "  [--rtol --atol]")
        << "\n";
  std::cout << out.str();
  return 0;
}

void declare_run(Args& a) {
  const RunConfig d;
  declare_case_options(a);
  a.value("--step", "H", "fixed step, for " + integrator_names(true))
      .value("--rtol", "R", "relative tolerance, for " + integrator_names(false))
      .value("--atol", "A", "absolute tolerance, with --rtol")
      .repeatable("--times", "T1,T2,...", "extra series rows at exactly these times, in (0, t_end]")
      .value("--sample-every", "DT", "one series row per DT of time (0: t_end/1000)", format_short(d.sample_every))
      .value("--ref-time", "T", "time of the error against the reference; 0: none (default: the problem's, if <= t_end)")
      .value("--blowup", "B", "residual above which the run is recorded as diverged", format_short(d.blowup))
      .value("--observe-every", "N", "evaluate the metrics every N steps (output rows always)",
             std::to_string(d.observe_every))
      .value("--perturb", "DELTA", "start off the constraint manifold by DELTA (README, Stress)",
             format_short(d.perturb))
      .value("--recovery-threshold", "R", "residual a perturbed run must return to and stay below",
             format_short(d.recovery_threshold))
      .value("--drift-fit-from", "T", "fit the drift growth exponent over [T, t_end] (if t_end >= 4 T; 0: no fit)",
             format_short(d.drift_fit_from))
      .value("--max-steps", "N",
             "most steps of the run: a fixed-step run needing more (t_end / step) is refused, an adaptive one "
             "stops there (status failed)",
             format_short(d.max_steps))
      .flag("--no-series", "write summary.csv only, no series.csv")
      .required("--out", "DIR", "output folder (created if missing)");
}

// --step, or --rtol and --atol, as the integrator needs.
StepSettings step_settings(const Args& args, const IntegratorInfo& integ) {
  StepSettings s;
  if (integ.fixed_step) {
    if (args.has("--rtol") || args.has("--atol"))
      throw UsageError("--rtol/--atol: integrator '" + integ.name + "' is fixed-step; give --step");
    s.step = parse_finite_double(args.require("--step"), "--step");
  } else {
    if (args.has("--step"))
      throw UsageError("--step: integrator '" + integ.name + "' is adaptive; give --rtol and --atol");
    s.rtol = parse_finite_double(args.require("--rtol"), "--rtol");
    s.atol = parse_finite_double(args.require("--atol"), "--atol");
  }
  return s;
}

int cmd_run(const Args& args) {
  RunConfig cfg;
  cfg.problem = args.require("--problem");
  cfg.problem_params = args.pairs("--problem-param");
  cfg.method = args.require("--method");
  cfg.formulation = args.get("--formulation");
  cfg.integrator = args.require("--integrator");
  const Problem& problem = find_problem(cfg.problem);
  const IntegratorInfo& integ = find_integrator(cfg.integrator);
  cfg.params = args.pairs("--param");
  cfg.step = step_settings(args, integ);
  cfg.t_end = args.end_time("--t-end", problem.info());
  cfg.times = args.number_list("--times");
  cfg.sample_every = args.number("--sample-every");
  if (args.has("--ref-time")) {
    cfg.ref_time = args.number("--ref-time");
    if (!(cfg.ref_time >= 0 && cfg.ref_time <= cfg.t_end))
      throw UsageError("--ref-time: must be in [0, t_end] (0: no reference error)");
  }
  cfg.blowup = args.number("--blowup");
  const long observe_every = args.integer("--observe-every");
  if (observe_every < 1 || observe_every > 1000000000) throw UsageError("--observe-every: must be in [1, 1e9]");
  cfg.observe_every = int(observe_every);
  cfg.write_series = !args.has("--no-series");
  cfg.perturb = args.number("--perturb");
  cfg.recovery_threshold = args.number("--recovery-threshold");
  cfg.drift_fit_from = args.number("--drift-fit-from");
  cfg.max_steps = args.number("--max-steps");
  const std::string out = args.require("--out");

  const RunResult r = run_case(problem, cfg, out);
  std::cout << r.problem << (r.problem_params.empty() ? "" : " (" + r.problem_params + ")") << " / "
            << r.formulation << " / " << r.method << " / " << r.integrator << ": "
            << r.status << (r.reason.empty() ? "" : " (" + r.reason + ")") << ", t = " << r.t_reached
            << ", steps " << r.steps << ", rhs " << r.rhs_evals << ", wall " << r.wall_seconds << " s"
            << ", max residual " << r.max_residual;
  if (r.has_energy) std::cout << ", max |dE| " << r.max_energy_drift;
  if (!std::isnan(r.ref_error)) std::cout << ", error at t=" << r.ref_time << " " << r.ref_error;
  std::cout << "\n  wrote " << out << "/summary.csv" << (cfg.write_series ? " and series.csv" : "") << "\n";
  return 0;
}

// ---------------------------------------------------------------- the table

struct Command {
  const char* name;
  const char* summary;  // one line, in `cstab --help` and atop `cstab NAME --help`
  const char* footer;   // after the options in `cstab NAME --help`; may be empty
  void (*declare)(Args&);
  int (*run)(const Args&);
};

const std::vector<Command>& commands() {
  static const std::vector<Command> table = {
      {"list",
       "List the problems (--problem-param defaults, formulations, constraints, reference), methods (--param "
       "defaults), integrators",
       "", declare_list, cmd_list},
      {"run", "Run one case; write DIR/summary.csv and DIR/series.csv (README.md: every column)",
       "A diverged run is a recorded result (exit 0; its status says so).", declare_run, cmd_run},
      {"stability", "Step x gain map of a method and its measured stability boundary",
       "Writes DIR/stability.csv, DIR/boundary.csv and, with gnuplot, DIR/stability.png/.svg. The boundary is in "
       "h * rate per step when the parameter is a gain and the integrator has a real stability interval (rk4, "
       "adams, euler), against that interval; otherwise (rho_inf, or --integrator own) it is the largest stable "
       "step per parameter value.",
       declare_stability,
       cmd_stability},
      {"score", "Score a trajectory computed elsewhere: the metrics of run, from a CSV of t and the coordinates",
       "Writes DIR/summary.csv and DIR/series.csv with run's columns (docs/score.md).", declare_score, cmd_score},
      {"tune", "Cheapest gain and step/tolerance of a method that reaches a target (harness/tune.hpp)",
       "Writes DIR/tune.csv, DIR/best.csv and, with gnuplot, DIR/tune.png. An unreachable target is a recorded "
       "result (exit 0; best.csv says unreachable).", declare_tune, cmd_tune},
      {"check", "Conformance checks on what --plugin adds (or on --problem / --method): a pass/fail table",
       "Exit 1 if any check fails. Checks: applies (why_not), derivatives (per problem), conformance, recovery, "
       "allocation (docs/plugins.md).", declare_check, cmd_check},
      {"matrix", "Run a benchmark matrix (default: the embedded one; docs/matrix.md)",
       "Exit 128+N if interrupted by signal N (finished cases are kept; run again to resume).", declare_matrix,
       cmd_matrix},
      {"merge", "Join the shard folders of one matrix into OUT and build its report",
       "Exit 3 if cases of the matrix are missing from the shards.", declare_merge, cmd_merge},
      {"report", "Rebuild the report (tables, plots, report.html) of a matrix results folder", "", declare_report,
       cmd_report},
      {"gate", "Check a matrix results folder against accuracy thresholds (docs/gate.md)",
       "Exit 1 if any check fails. --update and --init write thresholds instead of checking.", declare_gate,
       cmd_gate},
  };
  return table;
}

std::string command_names() {
  std::string names;
  for (const auto& c : commands()) names += (names.empty() ? "" : ", ") + std::string(c.name);
  return names;
}

bool known_command(const std::string& name) {
  if (name == "help") return true;
  for (const auto& c : commands())
    if (name == c.name) return true;
  return false;
}

// The whole command line: the top-level app, one subcommand per command
// (with its Args) and `help`.
struct CommandLine {
  CLI::App app{"cstab - benchmark and verification suite for constraint stabilization methods", "cstab"};
  std::vector<std::unique_ptr<Args>> args;  // in the order of commands()
  CLI::App* help = nullptr;
  std::string help_topic;

  CommandLine();
  // The subcommand being parsed or parsed, else the top-level app.
  const CLI::App& selected() const {
    const auto chosen = app.get_subcommands();
    return chosen.empty() ? app : *chosen.front();
  }
  // The options of the selected command; nullptr for `help` or none.
  const Args* selected_args() const {
    for (const auto& a : args)
      if (&a->app() == &selected()) return a.get();
    return nullptr;
  }
  int run() const;
};

CommandLine::CommandLine() {
  // Before the subcommands: they copy the formatter and the help flag.
  auto fmt = std::make_shared<CLI::Formatter>();
  fmt->label("Usage", "usage");
  fmt->label("SUBCOMMAND", "COMMAND");
  fmt->label("Positionals", "Arguments");
  fmt->column_width(34);
  app.formatter(fmt);
  app.set_help_flag("-h,--help", "Print this help and exit");
  app.require_subcommand(0, 1);
  app.footer(
      "Exit codes: 0 success, 2 bad input (one line naming what is wrong; nothing written), 1 internal error.\n"
      "Every command takes --plugin PATH (repeatable; CSTAB_PLUGIN_PATH lists more, ':'-separated): a shared\n"
      "object adding methods or problems (docs/plugins.md).\n"
      "`cstab COMMAND --help` or `cstab help COMMAND`: a command's options. docs/cli.md: all of them.");
  for (const auto& c : commands()) {
    CLI::App* sub = app.add_subcommand(c.name, c.summary);
    sub->group("Commands");
    sub->footer(c.footer);  // also when empty: a subcommand starts with the top-level footer
    args.push_back(std::make_unique<Args>(*sub));
    c.declare(*args.back());
  }
  help = app.add_subcommand("help", "Print the help of cstab or of one COMMAND");
  help->group("Commands");
  help->add_option("COMMAND", help_topic, "the command (" + command_names() + ")")->type_name("");
}

int CommandLine::run() const {
  if (help->parsed()) {
    std::cout << (help_topic.empty() ? usage() : command_help(help_topic));
    return 0;
  }
  for (size_t i = 0; i < commands().size(); ++i)
    if (args[i]->app().parsed()) {
      args[i]->check();
      return commands()[i].run(*args[i]);
    }
  std::cout << usage();  // options but no command ("cstab --")
  return 2;
}

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// "cstab merge [OPTIONS] OUT SHARD_DIR..."
std::string usage_line(const CLI::App& command) {
  CLI::Formatter fmt;
  fmt.label("Usage", "usage");
  const bool top = command.get_parent() == nullptr;
  std::string line = fmt.make_usage(&command, top ? "cstab" : "cstab " + command.get_name());
  while (!line.empty() && line.back() == '\n') line.pop_back();
  return line;
}

// CLI11's error, as one line in our words where we have them.
std::string parse_error_text(const CLI::ParseError& e, const CommandLine& cli) {
  const CLI::App& cmd = cli.selected();
  std::string what = e.what();
  for (char& c : what)
    if (c == '\n') c = ' ';
  // Arguments the parser did not take come first: a misspelled option is
  // the cause of the "required" error CLI11 would report before it.
  std::vector<std::string> rest = cmd.remaining();
  if (rest.empty()) rest = cli.app.remaining();
  if (!rest.empty()) {
    const std::string& first = rest.front();
    const std::string see = cmd.get_parent() ? "cstab " + cmd.get_name() + " --help" : "cstab --help";
    if (first.size() > 1 && first[0] == '-')
      return first.substr(0, first.find('=')) + ": unknown option (`" + see + "` lists them)";
    return "unexpected argument '" + first + "' (" + usage_line(cmd) + ")";
  }
  if (dynamic_cast<const CLI::RequiredError*>(&e) && ends_with(what, " is required")) {
    const std::string name = what.substr(0, what.size() - std::string(" is required").size());
    return name + ": required" + (name.rfind("-", 0) == 0 ? "" : " (" + usage_line(cmd) + ")");
  }
  if (ends_with(what, " was given a disallowed flag override"))
    return "--" + what.substr(0, what.find(' ')) + ": takes no value";
  if (what.rfind("-", 0) == 0 && ends_with(what, " missing") && what.find(" required ") != std::string::npos)
    return what.substr(0, what.find(':')) + ": missing value";
  return what;
}

}  // namespace

void declare_case_options(Args& a) {
  a.required("--problem", "P", "problem (`cstab list` lists them)")
      .repeatable("--problem-param", "NAME=VALUE", "problem parameter (`cstab list`: each with its default and range)")
      .required("--method", "M", "stabilization method (`cstab list`)")
      .value("--formulation", "F", "formulation of the problem (default: the method's own)")
      .repeatable("--param", "NAME=VALUE", "method parameter (`cstab list`: each with its default)")
      .required("--integrator", "I", "integrator (`cstab list`)")
      .required("--t-end", "T", "end time: a number, `ref` (the problem's reference time) or `default` (its horizon)");
}

std::string usage() {
  const CommandLine cli;
  return cli.app.help();
}

std::string command_help(const std::string& command) {
  if (!known_command(command))
    throw UsageError("unknown command '" + command + "' (known: " + command_names() + ")");
  const CommandLine cli;
  return cli.app.get_subcommand(command)->help("cstab");
}

int main_command(const std::vector<std::string>& given) {
  std::vector<std::string> argv = given;
  if (argv.empty()) {
    std::cout << usage();
    return 2;
  }
  // The --plugin flags out first (anywhere on the line), so that the
  // command is the first word left.
  std::vector<std::string> plugin_paths;
  try {
    plugin_paths = take_plugin_flags(argv);
  } catch (const UsageError& e) {
    std::cerr << "cstab: error: " << e.what() << "\n";
    return 2;
  }
  if (argv.empty()) {
    std::cout << usage();
    return 2;
  }
  const bool named = argv[0].rfind("-", 0) != 0;
  const std::string prefix = named ? "cstab " + argv[0] + ": error: " : "cstab: error: ";
  try {
    // Plugins before anything else: they add to the lists the commands and
    // their help read.
    load_plugins_from_environment();
    for (const auto& path : plugin_paths) load_plugin(path);
    if (named && !known_command(argv[0]))
      throw UsageError("unknown command '" + argv[0] + "' (known: " + command_names() + ")");
    CommandLine cli;
    try {
      cli.app.parse(std::vector<std::string>(argv.rbegin(), argv.rend()));
    } catch (const CLI::ParseError& e) {
      if (e.get_exit_code() != 0) {
        if (const Args* a = cli.selected_args()) a->check();
        throw UsageError(parse_error_text(e, cli));
      }
      std::cout << cli.app.help();  // --help: the selected command's
      return 0;
    }
    return cli.run();
  } catch (const UsageError& e) {
    std::cerr << prefix << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << prefix << e.what() << "\n";
    return 1;
  }
}

}  // namespace cstab::cli
