// External cases of a matrix (key `external`, docs/matrix.md): the worker
// runs an outside program's command, times it as a whole process, and
// scores the trajectory it wrote with the observer of `cstab run`
// (harness/score.hpp). A program that fails, hangs or writes a trajectory
// cstab cannot read is a recorded result, never the end of the matrix.
#pragma once

#include <string>

#include "harness/run.hpp"
#include "matrix/matrix.hpp"
#include "matrix/results.hpp"

namespace cstab {

struct ExternalOutcome {
  Status status = Status::kOk;  // kOk: `result` holds the score
  std::string reason;           // otherwise why, with the tail of the program's output
  RunResult result;
};

// Runs c.external once with {out} a trajectory file in `dir` (removed
// afterwards, with the program's output log), in a process group of its
// own that is killed after `seconds_left` (<= 0: no limit) and whenever the
// worker dies. Scores the trajectory into `out_dir` (empty: nothing
// written). The summary's wall_seconds is the program's own time where the
// trajectory gives one (`# wall_seconds = S`), else the process's;
// process_seconds is always the process's.
ExternalOutcome run_external(const MatrixCase& c, const Problem& problem, const std::string& dir,
                             const std::string& out_dir, double seconds_left);

}  // namespace cstab
