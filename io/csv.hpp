// Atomic CSV output: rows go to a temporary file beside the target, which is
// renamed into place only by commit(). A writer destroyed without commit()
// removes its temporary file, so no half-written CSV is ever left behind.
#pragma once

#include <cstdio>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace cstab {

// A failure of the machine, not of the input or the simulation: a file
// that cannot be created, written or renamed (disk full, I/O error).
struct IoError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class AtomicFile {
 public:
  explicit AtomicFile(std::string path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::FILE* stream() { return file_; }
  void write(const std::string& text);
  void commit();  // flush, fsync-free close, rename; throws on I/O error
  const std::string& path() const { return path_; }

 private:
  std::string path_, temp_path_;
  std::FILE* file_ = nullptr;
  bool committed_ = false;
  int slot_ = -1;  // in the table remove_temporary_files() reads
};

// Removes the temporary files of every AtomicFile alive in this process.
// Async-signal-safe (unlink only): for a SIGINT/SIGTERM handler, so an
// interrupted command leaves neither a half-written file nor a temporary.
void remove_temporary_files();

// Quote a CSV field if it needs it (RFC 4180).
std::string csv_field(const std::string& s);

// One CSV line (with the newline) from cells, each quoted if it needs it.
std::string csv_line(const std::vector<std::string>& cells);

// Rows of ordered (column, value) pairs whose columns may differ -> one CSV:
// the union of the columns in order of first appearance; a row without a
// column has an empty cell there.
std::string rows_to_csv(const std::vector<std::vector<std::pair<std::string, std::string>>>& rows);

// Header line + data row text from ordered (column, value) pairs.
std::string key_value_csv(const std::vector<std::pair<std::string, std::string>>& row);

// One header line and one data row from ordered (column, value) pairs.
void write_key_value_csv(const std::string& path,
                         const std::vector<std::pair<std::string, std::string>>& row);

// Write `content` to `path` atomically.
void write_file_atomic(const std::string& path, const std::string& content);

// A CSV text without quoted cells (a series.csv) with only its first column
// and the columns whose header names are in `names`, in their order; every
// column if `names` is empty. A row's missing cells stay missing.
std::string csv_select_columns(const std::string& csv, const std::set<std::string>& names);

}  // namespace cstab
