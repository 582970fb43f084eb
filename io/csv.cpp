#include "io/csv.hpp"

#include <sys/statvfs.h>
#include <unistd.h>

#include <cerrno>
#include <algorithm>
#include <csignal>
#include <cstring>
#include <map>
#include <stdexcept>

namespace cstab {

namespace {

// Temporary paths of the live AtomicFiles, readable from a signal handler:
// fixed storage, a slot is used while its flag is set.
constexpr int kTempSlots = 32;
constexpr size_t kTempPathMax = 4096;
char g_temp_paths[kTempSlots][kTempPathMax];
volatile std::sig_atomic_t g_temp_used[kTempSlots];

int claim_slot(const std::string& path) {
  if (path.size() >= kTempPathMax) return -1;
  for (int i = 0; i < kTempSlots; ++i) {
    if (g_temp_used[i]) continue;
    std::memcpy(g_temp_paths[i], path.c_str(), path.size() + 1);
    g_temp_used[i] = 1;
    return i;
  }
  return -1;  // more than kTempSlots open at once: not cleaned on a signal
}

void release_slot(int slot) {
  if (slot >= 0) g_temp_used[slot] = 0;
}

// "a write failed", and the space left on the file system of `fd` when it
// is nearly full (the usual reason).
std::string space_note(int fd) {
  struct statvfs fs {};
  if (::fstatvfs(fd, &fs) != 0) return "a write failed";
  const unsigned long long free_bytes = static_cast<unsigned long long>(fs.f_bavail) * fs.f_frsize;
  if (free_bytes >= (1ull << 20)) return "a write failed";
  return "a write failed with " + std::to_string(free_bytes) + " bytes free on its file system (disk full)";
}

}  // namespace

void remove_temporary_files() {
  for (int i = 0; i < kTempSlots; ++i)
    if (g_temp_used[i]) ::unlink(g_temp_paths[i]);
}

AtomicFile::AtomicFile(std::string path) : path_(std::move(path)) {
  temp_path_ = path_ + ".tmp." + std::to_string(::getpid());
  slot_ = claim_slot(temp_path_);
  file_ = std::fopen(temp_path_.c_str(), "w");
  if (!file_) {
    release_slot(slot_);
    throw IoError("cannot write " + path_ + ": " + std::strerror(errno));
  }
}

AtomicFile::~AtomicFile() {
  if (file_) std::fclose(file_);
  if (!committed_) std::remove(temp_path_.c_str());
  release_slot(slot_);
}

void AtomicFile::write(const std::string& text) {
  std::fwrite(text.data(), 1, text.size(), file_);
}

void AtomicFile::commit() {
  const bool write_error = std::ferror(file_) != 0;
  // Why, as far as is known: the errno of a failed close (its flush), else
  // for an earlier failed write (whose errno is gone) the space left.
  std::string why = write_error ? space_note(::fileno(file_)) : std::string();
  errno = 0;
  const bool close_error = std::fclose(file_) != 0;
  if (close_error && errno) why = std::strerror(errno);
  file_ = nullptr;
  if (write_error || close_error)
    throw IoError("error writing " + path_ + (why.empty() ? std::string() : ": " + why));
  if (std::rename(temp_path_.c_str(), path_.c_str()) != 0)
    throw IoError("cannot rename into " + path_ + ": " + std::strerror(errno));
  committed_ = true;
  release_slot(slot_);
  slot_ = -1;
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

std::string csv_line(const std::vector<std::string>& cells) {
  std::string line;
  for (size_t i = 0; i < cells.size(); ++i) {
    if (i) line += ',';
    line += csv_field(cells[i]);
  }
  return line + "\n";
}

std::string rows_to_csv(const std::vector<std::vector<std::pair<std::string, std::string>>>& rows) {
  std::vector<std::string> columns;
  std::map<std::string, size_t> position;
  for (const auto& row : rows)
    for (const auto& [k, v] : row)
      if (position.emplace(k, columns.size()).second) columns.push_back(k);
  std::string out = csv_line(columns);
  std::vector<std::string> cells(columns.size());
  for (const auto& row : rows) {
    std::fill(cells.begin(), cells.end(), std::string());
    for (const auto& [k, v] : row) cells[position[k]] = v;
    out += csv_line(cells);
  }
  return out;
}

std::string key_value_csv(const std::vector<std::pair<std::string, std::string>>& row) {
  std::vector<std::string> header, values;
  for (const auto& [k, v] : row) {
    header.push_back(k);
    values.push_back(v);
  }
  return csv_line(header) + csv_line(values);
}

void write_key_value_csv(const std::string& path,
                         const std::vector<std::pair<std::string, std::string>>& row) {
  write_file_atomic(path, key_value_csv(row));
}

void write_file_atomic(const std::string& path, const std::string& content) {
  AtomicFile f(path);
  f.write(content);
  f.commit();
}

namespace {

// The cells of one line, split at every comma.
std::vector<std::string> split_commas(const std::string& line) {
  std::vector<std::string> cells(1);
  for (char c : line) {
    if (c == ',')
      cells.emplace_back();
    else
      cells.back() += c;
  }
  return cells;
}

}  // namespace

std::string csv_select_columns(const std::string& csv, const std::set<std::string>& names) {
  if (names.empty()) return csv;
  std::vector<size_t> keep;
  std::string out;
  size_t begin = 0;
  while (begin < csv.size()) {
    size_t end = csv.find('\n', begin);
    if (end == std::string::npos) end = csv.size();
    const std::vector<std::string> cells = split_commas(csv.substr(begin, end - begin));
    if (begin == 0)
      for (size_t i = 0; i < cells.size(); ++i)
        if (i == 0 || names.count(cells[i])) keep.push_back(i);
    for (size_t k = 0; k < keep.size() && keep[k] < cells.size(); ++k) {
      if (k) out += ',';
      out += cells[keep[k]];
    }
    if (end < csv.size()) out += '\n';
    begin = end + 1;
  }
  return out;
}

}  // namespace cstab
