// Makes a pointer observable to the optimiser, so that the allocation behind
// it cannot be elided: clang removes a new/delete or malloc/free pair whose
// memory is never looked at (GCC 12 does not), and a test that checks its
// allocation counter sees an allocation would then see none.
#pragma once

namespace cstab::testing {

inline void escape(const void* p) { asm volatile("" : : "g"(p) : "memory"); }

}  // namespace cstab::testing
