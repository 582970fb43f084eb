// Counting heap allocations in the cstab executable (`cstab check`'s
// allocation-free steps): cli/alloc_count.cpp replaces the global operator
// new, which counts while a window is armed (one relaxed atomic load per
// allocation otherwise). Not in a sanitized build: the sanitizers own
// operator new there, and counting_available() is false.
#pragma once

namespace cstab::cli {

bool counting_available();
// Counts operator new calls (plugins' included) while alive.
class AllocationWindow {
 public:
  AllocationWindow();
  ~AllocationWindow();
  long count() const;
};

}  // namespace cstab::cli
