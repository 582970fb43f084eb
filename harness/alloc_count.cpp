#include "harness/alloc_count.hpp"

#include <atomic>
#include <cstdlib>
#include <new>
#include <vector>

namespace {
std::atomic<bool> g_armed{false};
std::atomic<long> g_allocations{0};
}  // namespace

namespace cstab {

AllocationWindow::AllocationWindow() {
  g_allocations = 0;
  g_armed = true;
}
AllocationWindow::~AllocationWindow() { g_armed = false; }
long AllocationWindow::count() const { return g_allocations.load(); }

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
  StepAllocations out;
  for (int i = 0; i < warmup; ++i)
    if (!one_step()) {
      out.warmup_failed = true;
      out.failure = integ->failure_reason();
      return out;
    }
  {
    AllocationWindow w;
    for (; out.taken < steps; ++out.taken)
      if (!one_step()) break;
    out.allocations = w.count();
  }
  if (out.taken < steps) out.failure = integ->failure_reason();
  return out;
}

}  // namespace cstab

namespace {
void* counted_alloc(std::size_t n) {
  if (g_armed.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void* counted_alloc_aligned(std::size_t n, std::align_val_t al) {
  if (g_armed.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
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
