#include "matrix/external.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "core/format.hpp"
#include "harness/score.hpp"

namespace cstab {

namespace {

std::string shell_quoted(const std::string& s) {
  std::string out = "'";
  for (char ch : s) out += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
  return out + "'";
}

// The last lines of the program's output, at most ~400 characters, on one line.
std::string output_tail(const std::string& log) {
  std::ifstream in(log, std::ios::binary);
  std::stringstream all;
  all << in.rdbuf();
  std::string text = all.str();
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
  if (text.size() > 400) text = "..." + text.substr(text.size() - 400);
  for (char& ch : text)
    if (ch == '\n' || ch == '\r' || ch == ',') ch = ch == ',' ? ';' : '|';
  return text.empty() ? "(no output)" : text;
}

}  // namespace

ExternalOutcome run_external(const MatrixCase& c, const Problem& problem, const std::string& dir,
                             const std::string& out_dir, double seconds_left) {
  const std::string trajectory = dir + "/external-trajectory.csv", log = dir + "/external-output.log";
  std::string command = c.external;
  for (size_t at = command.find("{out}"); at != std::string::npos; at = command.find("{out}", at + 1))
    command.replace(at, 5, shell_quoted(trajectory));
  std::remove(trajectory.c_str());
  ExternalOutcome o;
  const auto start = std::chrono::steady_clock::now();
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) {
    o.status = Status::kFailed;
    o.reason = "external: cannot fork";
    return o;
  }
  if (pid == 0) {
    ::setpgid(0, 0);
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);  // dies with the worker
    if (::getppid() != parent) ::_exit(127);
    const int out = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int in = ::open("/dev/null", O_RDONLY);
    if (out >= 0) ::dup2(out, 1), ::dup2(out, 2);
    if (in >= 0) ::dup2(in, 0);
    ::execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  ::setpgid(pid, pid);
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  int status = 0;
  bool timed_out = false;
  while (::waitpid(pid, &status, WNOHANG) == 0) {
    if (seconds_left > 0 && elapsed() > seconds_left) {
      ::kill(-pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      timed_out = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  const double process_seconds = elapsed();
  ::kill(-pid, SIGKILL);  // whatever the command left running in its group
  const std::string tail = output_tail(log);
  std::remove(log.c_str());
  auto fail = [&](Status s, const std::string& why) {
    std::remove(trajectory.c_str());
    o.status = s;
    o.reason = why;
    return o;
  };
  if (timed_out)
    return fail(Status::kTimeout, "external command still running after " + format_short(seconds_left) +
                                      " s: killed; its output: " + tail);
  if (WIFSIGNALED(status))
    return fail(Status::kFailed, "external command killed by signal " + std::to_string(WTERMSIG(status)) +
                                     "; its output: " + tail);
  if (WEXITSTATUS(status) != 0)
    return fail(Status::kFailed, "external command exited with code " + std::to_string(WEXITSTATUS(status)) +
                                     "; its output: " + tail);
  ScoreConfig sc;
  sc.problem = c.config.problem;
  sc.problem_params = c.config.problem_params;
  sc.label = c.config.method;
  sc.ref_time = c.config.ref_time;
  sc.blowup = c.config.blowup;
  sc.sample_every = c.config.sample_every;
  sc.write_series = c.config.write_series;
  try {
    o.result = score_trajectory(problem, sc, trajectory, out_dir);
  } catch (const UsageError& e) {
    return fail(Status::kFailed, std::string("external trajectory: ") + e.what());
  }
  std::remove(trajectory.c_str());
  RunResult& r = o.result;
  r.step = c.config.step;
  r.t_end = c.config.t_end;
  if (std::isnan(r.wall_seconds)) r.wall_seconds = process_seconds;
  r.extra.emplace_back("process_seconds", format_exact(process_seconds));
  if (r.status == "ok" && r.t_reached < c.config.t_end * (1 - 1e-12)) {
    r.status = "failed";
    r.reason = "external trajectory ends at t = " + format_short(r.t_reached) + ", before t_end = " +
               format_short(c.config.t_end);
  }
  return o;
}

}  // namespace cstab
