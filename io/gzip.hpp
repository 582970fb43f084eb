#pragma once
// gzip (RFC 1952) files through zlib: the matrix stores each case's series
// as series.csv.gz (results/README.md). Lossless: gunzip gives back the
// exact bytes the harness wrote.
#include <string>

namespace cstab {

// `bytes` as a gzip member (zlib level 6, no file name, mtime 0: the same
// input always gives the same output, so content hashes are stable).
std::string gzip_compress(const std::string& bytes);
// The content of a gzip file's bytes. Throws std::runtime_error on a
// corrupt or truncated stream, or one that inflates past `max_bytes`.
std::string gzip_decompress(const std::string& gz, size_t max_bytes);

}  // namespace cstab
