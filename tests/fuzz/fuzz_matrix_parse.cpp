// libFuzzer target: the matrix-file parser. Any input either parses or
// throws MatrixError whose message starts with "file:line:column: ".
#include <cstdint>
#include <cstdlib>
#include <string>

#include "matrix/matrix.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const cstab::MatrixFile f = cstab::parse_matrix(text, "fuzz.toml");
    if (f.text != text) std::abort();
    for (const auto& sec : f.sections)
      for (const auto& e : sec.entries)
        if (e.where.line < 1 || e.where.column < 1 || e.key.empty()) std::abort();
  } catch (const cstab::MatrixError& e) {
    if (std::string(e.what()).rfind("fuzz.toml:", 0) != 0) std::abort();
  }
  return 0;
}
