// Content hashes for case ids, cache keys, provenance and plot stamps.
#pragma once

#include <string>

namespace cstab {

// 64-bit FNV-1a as 16 hex digits.
std::string hash_hex(const std::string& data);

}  // namespace cstab
