// The matrix keeps each case's series as series.csv.gz: gzip round-trips the
// harness's bytes exactly, the same bytes always compress the same way (the
// content hash in case.txt is stable), a damaged file is refused, and the
// results loader (which the report and the stress report read series
// through) gives the same table from series.csv.gz as from series.csv.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "io/gzip.hpp"
#include "matrix/matrix.hpp"
#include "matrix/results.hpp"

namespace fs = std::filesystem;

namespace {

std::string sample_series() {
  std::string s = "t,energy_drift,residual\n";
  for (int i = 0; i <= 5000; ++i) {
    const double t = i * 1e-3;
    s += std::to_string(t) + "," + std::to_string(1e-9 * i * i) + "," + std::to_string(-3.25e-12 * i) + "\n";
  }
  return s;
}

TEST(SeriesGz, RoundTripsExactlyAndDeterministically) {
  for (const std::string& text : {std::string(), std::string("t\n"), sample_series()}) {
    const std::string gz = cstab::gzip_compress(text);
    EXPECT_EQ(cstab::gzip_decompress(gz, size_t(1) << 30), text);
    EXPECT_EQ(cstab::gzip_compress(text), gz);
  }
  const std::string text = sample_series();
  EXPECT_LT(cstab::gzip_compress(text).size(), text.size() / 2);
}

TEST(SeriesGz, DamagedStreamsAreRefused) {
  const std::string gz = cstab::gzip_compress(sample_series());
  EXPECT_THROW(cstab::gzip_decompress(gz.substr(0, gz.size() / 2), size_t(1) << 30), std::runtime_error);
  std::string flipped = gz;
  flipped[gz.size() / 2] ^= 0x5a;
  EXPECT_THROW(cstab::gzip_decompress(flipped, size_t(1) << 30), std::runtime_error);
  EXPECT_THROW(cstab::gzip_decompress(gz, 1000), std::runtime_error);  // past the bound
}

TEST(SeriesGz, TheLoaderReadsTheSameTableFromGzAsFromPlain) {
  const fs::path dir = fs::temp_directory_path() / ("cstab_series_gz_" + std::to_string(getpid()));
  fs::remove_all(dir);
  cstab::CaseEntry entry;
  entry.id = "abc123";
  const fs::path cases = dir / "cases" / entry.id;
  fs::create_directories(cases);
  const std::string text = sample_series();
  std::ofstream(cases / "series.csv", std::ios::binary) << text;
  EXPECT_EQ(cstab::case_series_path(dir.string(), entry), (cases / "series.csv").string());
  const cstab::CsvTable plain = cstab::load_case_series(dir.string(), entry);
  ASSERT_EQ(plain.rows.size(), 5001u);
  fs::remove(cases / "series.csv");
  std::ofstream(cases / "series.csv.gz", std::ios::binary) << cstab::gzip_compress(text);
  EXPECT_EQ(cstab::case_series_path(dir.string(), entry), (cases / "series.csv.gz").string());
  const cstab::CsvTable gz = cstab::load_case_series(dir.string(), entry);
  EXPECT_EQ(gz.header, plain.header);
  EXPECT_EQ(gz.rows, plain.rows);
  // A damaged .gz reads as no series (as an unreadable series.csv does).
  fs::resize_file(cases / "series.csv.gz", 40);
  EXPECT_TRUE(cstab::load_case_series(dir.string(), entry).rows.empty());
  fs::remove_all(dir);
}

}  // namespace
