// Counting heap allocations while a window is armed (one relaxed atomic
// load per allocation otherwise). With glibc, harness/alloc_count.cpp
// interposes the malloc family for the whole process, so operator new,
// Eigen's dynamic storage and the C libraries (GSL, SUNDIALS) are all seen;
// under AddressSanitizer, which owns malloc, it replaces operator new only.
// The object comes from the static library to any program that references
// malloc and links the harness (the cstab executable, for `cstab check`;
// tests/unit/test_alloc.cpp; the other tests and benchmarks), which all then
// allocate through the counter; it forwards to glibc's own allocator.
#pragma once

#include <string>

#include "core/formulation.hpp"
#include "harness/integrator.hpp"

namespace cstab {

// Counts heap allocations while alive. count(): those of cstab's code,
// plugins, Eigen and the C++ runtime; library_count(): those GSL and
// SUNDIALS make for their own workspaces (the allocating call returns into
// their code), which cstab can bound but not remove.
class AllocationWindow {
 public:
  AllocationWindow();
  ~AllocationWindow();
  long count() const;
  long library_count() const;
  // True where the malloc family is counted (glibc, no AddressSanitizer);
  // otherwise only operator new is, and library_count() stays 0.
  static bool counts_malloc_family();
};

struct StepAllocations {
  int taken = 0;         // steps taken in the window (< steps: one failed)
  long allocations = 0;          // heap allocations in them (AllocationWindow::count)
  long library_allocations = 0;  // and GSL's or SUNDIALS' own (library_count)
  long jacobian_evaluations = -1;  // the integrator's, in the window (-1: it reports none)
  bool system_jacobian = false;    // the integrator used the system's Jacobian ("jacobian" = "system")
  std::string failure;   // why a step failed (warm-up or window)
  bool warmup_failed = false;
};

// `warmup` steps of `form` with `integrator` (the post-step hook applied as
// the run loop does), then `steps` more inside an AllocationWindow.
StepAllocations count_step_allocations(Formulation& form, const std::string& integrator, const StepSettings& step,
                                       int warmup, int steps);

}  // namespace cstab
