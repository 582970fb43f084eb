// libFuzzer target: the matrix-file parser (toml++ and the mapping of its
// tree onto MatrixFile). Any input either parses into sections and entries
// that expansion can rely on, or throws MatrixError whose message starts
// with "file:line:column: ".
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <utility>

#include "matrix/matrix.hpp"

namespace {

bool bare_key_part(const std::string& part) {
  if (part.empty()) return false;
  for (char c : part)
    if (!((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-'))
      return false;
  return true;
}

bool sane_value(const cstab::MatrixValue& v, bool in_array) {
  using Kind = cstab::MatrixValue::Kind;
  if (v.where.line < 1 || v.where.column < 1) return false;
  if (v.kind == Kind::kNumber) return std::isfinite(v.number) && !v.text.empty();
  if (v.kind != Kind::kArray) return v.items.empty();
  if (in_array) return false;  // never nested
  for (const auto& item : v.items)
    if (!sane_value(item, true)) return false;
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const cstab::MatrixFile f = cstab::parse_matrix(text, "fuzz.toml");
    if (f.text != text) std::abort();
    std::pair<int, int> last_section{0, 0};
    int defaults = 0;
    for (const auto& sec : f.sections) {
      if (sec.kind != "sweep" && sec.kind != "defaults") std::abort();
      defaults += sec.kind == "defaults";
      const std::pair<int, int> at{sec.where.line, sec.where.column};
      if (at < last_section) std::abort();  // file order
      last_section = at;
      std::pair<int, int> last_entry{0, 0};
      for (const auto& e : sec.entries) {
        if (e.where.line < 1 || e.where.column < 1) std::abort();
        const std::pair<int, int> e_at{e.where.line, e.where.column};
        if (e_at < last_entry) std::abort();
        last_entry = e_at;
        // Dotted keys: parts of letters, digits, '_' and '-', joined with '.'.
        size_t start = 0;
        for (size_t dot; (dot = e.key.find('.', start)) != std::string::npos; start = dot + 1)
          if (!bare_key_part(e.key.substr(start, dot - start))) std::abort();
        if (!bare_key_part(e.key.substr(start))) std::abort();
        if (!sane_value(e.value, false)) std::abort();
      }
    }
    if (defaults > 1) std::abort();  // toml++ refuses a second [defaults]
  } catch (const cstab::MatrixError& e) {
    if (std::string(e.what()).rfind("fuzz.toml:", 0) != 0) std::abort();
  }
  return 0;
}
