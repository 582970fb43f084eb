#include "io/lock.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <memory>
#include <string>

#include "core/params.hpp"

namespace cstab {

namespace {

// Whether `fd` is (still) the file at `path`: not removed or replaced
// between its open and its flock.
bool still_at_path(int fd, const std::string& path) {
  struct stat held {}, named {};
  return ::fstat(fd, &held) == 0 && ::stat(path.c_str(), &named) == 0 && held.st_dev == named.st_dev &&
         held.st_ino == named.st_ino;
}

[[noreturn]] void refuse_in_use(int fd, const std::string& dir) {
  char buf[256] = {};
  const ssize_t n = ::pread(fd, buf, sizeof buf - 1, 0);
  ::close(fd);
  std::string holder = n > 0 ? std::string(buf, size_t(n)) : std::string();
  for (char& c : holder)
    if (c == '\n') c = ' ';
  while (!holder.empty() && holder.back() == ' ') holder.pop_back();
  // The file names its last writer; a reader (merge on a shard) writes
  // nothing, so a recorded pid that is gone says nothing about the holder.
  const long pid = std::atol(holder.c_str());
  if (pid <= 0 || (::kill(pid_t(pid), 0) != 0 && errno == ESRCH)) holder.clear();
  throw UsageError(dir + ": in use by another cstab command (" +
                   (holder.empty() ? std::string("pid unknown") : "pid " + holder) + "); wait for it to finish");
}

}  // namespace

FolderLock::FolderLock(const std::string& dir, const std::string& command, Mode mode)
    : path_(dir + "/" + file_name()), uncaught_on_entry_(std::uncaught_exceptions()) {
  // Until the flock is on the file at the path (a holder may remove it
  // between our open and our flock): a few rounds at most.
  for (int attempt = 0; attempt < 100; ++attempt) {
    bool created = false;
    int fd = ::open(path_.c_str(), (mode == Mode::kRead ? O_RDONLY : O_RDWR) | O_CLOEXEC);
    if (fd < 0 && mode == Mode::kRead && (errno == ENOENT || errno == ENOTDIR)) return;  // no lock file: no writer
    if (fd < 0 && errno == ENOENT) {
      fd = ::open(path_.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
      if (fd < 0 && errno == EEXIST) continue;  // created meanwhile: lock that one
      created = fd >= 0;
    }
    if (fd < 0)
      throw UsageError(dir + ": cannot " + (mode == Mode::kRead ? "read" : "write") +
                       " the results folder (lock file " + file_name() + "): " + std::strerror(errno));
    if (::flock(fd, (mode == Mode::kRead ? LOCK_SH : LOCK_EX) | LOCK_NB) != 0) {
      const int err = errno;
      if (err == EWOULDBLOCK) refuse_in_use(fd, dir);  // (never one we created: nobody else had it)
      ::close(fd);
      if (created) ::unlink(path_.c_str());
      throw UsageError(dir + ": cannot lock the results folder: " + std::strerror(err));
    }
    if (!still_at_path(fd, path_)) {  // removed by a holder that failed: start over
      ::close(fd);
      continue;
    }
    fd_ = fd;
    created_ = created;
    if (mode == Mode::kWrite) {
      const std::string text = std::to_string(::getpid()) + "\n" + command + "\n";
      if (::ftruncate(fd_, 0) == 0) {
        const ssize_t w = ::pwrite(fd_, text.data(), text.size(), 0);
        (void)w;  // the pid is information; the flock is the lock
      }
    }
    return;
  }
  throw UsageError(dir + ": cannot lock the results folder: its lock file keeps being replaced");
}

FolderLock::~FolderLock() {
  if (fd_ < 0) return;
  // A command that fails leaves no lock file it created (removed while
  // still held, so a process that opened it meanwhile starts over).
  if (created_ && std::uncaught_exceptions() > uncaught_on_entry_) ::unlink(path_.c_str());
  ::close(fd_);
}

std::unique_ptr<FolderLock> create_locked_folder(const std::string& dir, const std::string& command,
                                                 const std::string& what) {
  std::error_code ec;
  const bool existed = std::filesystem::exists(dir);
  std::filesystem::create_directories(dir, ec);
  if (ec) throw UsageError(what + ": " + ec.message());
  try {
    return std::make_unique<FolderLock>(dir, command);
  } catch (const UsageError&) {
    if (!existed) std::filesystem::remove(dir, ec);  // nothing left behind
    throw;
  }
}

}  // namespace cstab
