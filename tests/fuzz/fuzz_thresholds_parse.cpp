// libFuzzer target: the gate's thresholds-file parser. Any input either
// parses into rows whose lines and bounds are sane and whose rewrite parses
// back to the same rows, or throws UsageError naming the file.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "gate/gate.hpp"

namespace {

bool sane_bound(double v) { return std::isnan(v) || (std::isfinite(v) && v >= 0); }

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const cstab::ThresholdsFile f = cstab::parse_thresholds(text, "fuzz.csv");
    for (const auto& r : f.rows) {
      if (r.line < 2 || r.problem.empty() || r.method.empty() || r.integrator.empty() || r.setting.empty())
        std::abort();
      for (double v : {r.max_residual, r.max_final_residual, r.max_energy_drift, r.max_integral_drift,
                       r.max_ref_error, r.min_ref_scd, r.max_recovery_time, r.max_time_ratio})
        if (!sane_bound(v)) std::abort();
      if (r.fields.size() != f.columns.size()) std::abort();
    }
    // What --update writes must read back as the same cases.
    const cstab::ThresholdsFile again = cstab::parse_thresholds(cstab::thresholds_text(f), "fuzz.csv");
    if (again.rows.size() != f.rows.size()) std::abort();
    for (size_t i = 0; i < f.rows.size(); ++i)
      if (again.rows[i].label() != f.rows[i].label()) std::abort();
  } catch (const cstab::UsageError& e) {
    if (std::string(e.what()).rfind("fuzz.csv", 0) != 0) std::abort();
  }
  return 0;
}
