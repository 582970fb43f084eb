// Counting heap allocations: harness/alloc_count.cpp replaces the global
// operator new of the program that links it (the cstab executable, for
// `cstab check`; tests/unit/test_alloc.cpp), counting while a window is
// armed (one relaxed atomic load per allocation otherwise; under the
// sanitizers too, which then see malloc/free). Only a program that uses
// this file gets the replacement (the object is pulled from the static
// library by use).
#pragma once

#include <string>

#include "core/formulation.hpp"
#include "harness/integrator.hpp"

namespace cstab {

// Counts operator new calls (of plugins too) while alive.
class AllocationWindow {
 public:
  AllocationWindow();
  ~AllocationWindow();
  long count() const;
};

struct StepAllocations {
  int taken = 0;         // steps taken in the window (< steps: one failed)
  long allocations = 0;  // heap allocations in them
  std::string failure;   // why a step failed (warm-up or window)
  bool warmup_failed = false;
};

// `warmup` steps of `form` with `integrator` (the post-step hook applied as
// the run loop does), then `steps` more inside an AllocationWindow.
StepAllocations count_step_allocations(Formulation& form, const std::string& integrator, const StepSettings& step,
                                       int warmup, int steps);

}  // namespace cstab
