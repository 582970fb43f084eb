#include "harness/alloc_count.hpp"

#include <link.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <new>
#include <string>
#include <vector>

namespace {
std::atomic<bool> g_armed{false};
std::atomic<long> g_allocations{0};
// Of those, the allocations whose immediate caller lies in GSL's or
// SUNDIALS' code (their own workspaces: GSL's LU decomposition inside
// msbdf, SUNDIALS' difference-quotient Jacobians), told apart by the return
// address against those libraries' executable segments, found when a
// window opens.
std::atomic<long> g_library_allocations{0};
constexpr int kMaxRanges = 32;
struct Range {
  std::uintptr_t begin, end;
};
Range g_ranges[kMaxRanges];
std::atomic<int> g_range_count{0};
// CSTAB_ALLOC_TRAP set (to anything): raise SIGTRAP at each counted
// allocation, so that a debugger shows where it comes from.
std::atomic<bool> g_trap{false};
}  // namespace

namespace cstab {

namespace {
// The executable segments of the shared objects whose allocations are
// counted apart (libgsl, libsundials_*).
int find_library_ranges(dl_phdr_info* info, std::size_t, void*) {
  const char* name = info->dlpi_name;
  if (!name || (!std::strstr(name, "libgsl") && !std::strstr(name, "libsundials"))) return 0;
  for (int i = 0; i < info->dlpi_phnum; ++i) {
    const auto& ph = info->dlpi_phdr[i];
    const int n = g_range_count.load(std::memory_order_relaxed);
    if (ph.p_type != PT_LOAD || !(ph.p_flags & PF_X) || n == kMaxRanges) continue;
    const std::uintptr_t begin = info->dlpi_addr + ph.p_vaddr;
    g_ranges[n] = {begin, begin + ph.p_memsz};
    g_range_count.store(n + 1, std::memory_order_relaxed);
  }
  return 0;
}
}  // namespace

AllocationWindow::AllocationWindow() {
  g_trap = std::getenv("CSTAB_ALLOC_TRAP") != nullptr;
  g_range_count = 0;
  dl_iterate_phdr(find_library_ranges, nullptr);
  g_allocations = 0;
  g_library_allocations = 0;
  g_armed = true;
}
AllocationWindow::~AllocationWindow() { g_armed = false; }
long AllocationWindow::count() const { return g_allocations.load() - g_library_allocations.load(); }
long AllocationWindow::library_count() const { return g_library_allocations.load(); }

StepAllocations count_step_allocations(Formulation& form, const std::string& integrator, const StepSettings& step,
                                       int warmup, int steps) {
  const IntegratorInfo& info = find_integrator(integrator);
  form.set_step_hint(info.fixed_step ? step.step : 0.0);
  auto integ = make_integrator(integrator, step);
  std::vector<double> y0(form.dimension());
  form.initial_state(y0.data());
  integ->start(form, 0.0, y0.data());
  auto one_step = [&]() {
    if (integ->step(1e300) != StepOutcome::kOk) return false;
    if (form.has_post_step() && !integ->applies_post_step() && form.post_step(integ->t(), integ->y()))
      return integ->notify_modified();
    return true;
  };
  // The integrator's Jacobian evaluations so far (its *_jac_evals counter;
  // -1 if it reports none), read outside the window: statistics() allocates.
  auto jacobian_evaluations = [&]() -> long {
    for (const auto& [name, value] : integ->statistics())
      if (name.size() > 10 && name.compare(name.size() - 10, 10, "_jac_evals") == 0) return std::stol(value);
    return -1;
  };
  StepAllocations out;
  for (int i = 0; i < warmup; ++i)
    if (!one_step()) {
      out.warmup_failed = true;
      out.failure = integ->failure_reason();
      return out;
    }
  const long jac_before = jacobian_evaluations();
  {
    AllocationWindow w;
    for (; out.taken < steps; ++out.taken)
      if (!one_step()) break;
    out.allocations = w.count();
    out.library_allocations = w.library_count();
  }
  if (jac_before >= 0) out.jacobian_evaluations = jacobian_evaluations() - jac_before;
  for (const auto& [name, value] : integ->statistics())
    if (name == "jacobian") out.system_jacobian = value == "system";
  if (out.taken < steps) out.failure = integ->failure_reason();
  return out;
}

}  // namespace cstab

// What is counted. With glibc and no sanitizer, the malloc family itself is
// interposed, so every heap allocation of the process is seen: operator new
// (libstdc++'s calls malloc, and aligned_alloc for over-aligned types),
// Eigen's dynamic-size storage (std::malloc), and C libraries (GSL,
// SUNDIALS, SuiteSparse). Each entry counts and forwards to glibc's own
// allocator (__libc_*), so free(), malloc_usable_size() and everything else
// of glibc's keep working untouched. Not interposed: pvalloc (obsolete; no
// __libc_ entry point). Under AddressSanitizer, which owns the malloc family,
// only operator new is replaced, as before.
#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define CSTAB_ALLOC_ASAN 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define CSTAB_ALLOC_ASAN 1
#endif

namespace {
bool in_library(std::uintptr_t caller) {
  const int n = g_range_count.load(std::memory_order_relaxed);
  for (int i = 0; i < n; ++i)
    if (caller >= g_ranges[i].begin && caller < g_ranges[i].end) return true;
  return false;
}
// `caller`: the allocating function's return address.
inline void count_one(const void* caller) {
  if (!g_armed.load(std::memory_order_relaxed)) return;
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (in_library(reinterpret_cast<std::uintptr_t>(caller))) g_library_allocations.fetch_add(1, std::memory_order_relaxed);
  if (g_trap.load(std::memory_order_relaxed)) std::raise(SIGTRAP);
}
#define CSTAB_COUNT_ONE() count_one(__builtin_return_address(0))
}  // namespace

#if defined(__GLIBC__) && !defined(CSTAB_ALLOC_ASAN)

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
void* __libc_valloc(std::size_t);

void* malloc(std::size_t n) noexcept {
  CSTAB_COUNT_ONE();
  return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t size) noexcept {
  CSTAB_COUNT_ONE();
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t n) noexcept {
  CSTAB_COUNT_ONE();
  return __libc_realloc(p, n);
}
void* memalign(std::size_t alignment, std::size_t n) noexcept {
  CSTAB_COUNT_ONE();
  return __libc_memalign(alignment, n);
}
void* aligned_alloc(std::size_t alignment, std::size_t n) noexcept {
  CSTAB_COUNT_ONE();
  return __libc_memalign(alignment, n);
}
void* valloc(std::size_t n) noexcept {
  CSTAB_COUNT_ONE();
  return __libc_valloc(n);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t n) noexcept {
  if (alignment % sizeof(void*) != 0 || (alignment & (alignment - 1)) != 0 || alignment == 0) return EINVAL;
  CSTAB_COUNT_ONE();
  void* p = __libc_memalign(alignment, n);
  if (!p) return ENOMEM;
  *out = p;
  return 0;
}
}  // extern "C"

#else  // no glibc, or a sanitizer owns malloc: count operator new

namespace {
void* counted_alloc(std::size_t n) {
  CSTAB_COUNT_ONE();
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void* counted_alloc_aligned(std::size_t n, std::align_val_t al) {
  CSTAB_COUNT_ONE();
  const std::size_t a = static_cast<std::size_t>(al);
  if (void* p = std::aligned_alloc(a, (n + a - 1) / a * a)) return p;
  throw std::bad_alloc();
}
}  // namespace

void* operator new(std::size_t n) { return counted_alloc(n); }
void* operator new[](std::size_t n) { return counted_alloc(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return counted_alloc(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return counted_alloc(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new(std::size_t n, std::align_val_t a) { return counted_alloc_aligned(n, a); }
void* operator new[](std::size_t n, std::align_val_t a) { return counted_alloc_aligned(n, a); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }

#endif  // the malloc family or operator new

bool cstab::AllocationWindow::counts_malloc_family() {
#if defined(__GLIBC__) && !defined(CSTAB_ALLOC_ASAN)
  return true;
#else
  return false;
#endif
}
