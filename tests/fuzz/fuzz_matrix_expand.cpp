// libFuzzer target: parse + expand a matrix file against the stand-in
// catalog. Every outcome is a MatrixError (file:line:column) or a set of
// cases whose settings are valid run configurations.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "harness/integrator.hpp"
#include "tests/fuzz/fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const cstab::Expansion ex = cstab::expand_matrix(cstab::parse_matrix(text, "fuzz.toml"), cstab::fuzz::catalog());
    for (const auto& c : ex.cases) {
      const auto& cfg = c.config;
      const bool fixed = cstab::find_integrator(cfg.integrator).fixed_step;
      if (!(cfg.t_end > 0) || !std::isfinite(cfg.t_end)) std::abort();
      if (fixed && !(cfg.step.step > 0 && cfg.step.step <= cfg.t_end)) std::abort();
      if (!fixed && !(cfg.step.rtol > 0 && cfg.step.atol > 0)) std::abort();
      if (c.entry.repeats < 1 || c.entry.id.size() != 16) std::abort();
      if (cstab::hash_hex(c.config_text) != c.entry.id) std::abort();
    }
  } catch (const cstab::MatrixError& e) {
    if (std::string(e.what()).rfind("fuzz.toml:", 0) != 0) std::abort();
  }
  return 0;
}
