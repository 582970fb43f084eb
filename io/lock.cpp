#include "io/lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "core/params.hpp"

namespace cstab {

FolderLock::FolderLock(const std::string& dir, const std::string& command) {
  const std::string path = dir + "/" + file_name();
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0)
    throw UsageError(dir + ": cannot write the results folder (lock file " + file_name() +
                     "): " + std::strerror(errno));
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    char buf[256] = {};
    const ssize_t n = ::pread(fd_, buf, sizeof buf - 1, 0);
    ::close(fd_);
    fd_ = -1;
    if (err != EWOULDBLOCK)
      throw UsageError(dir + ": cannot lock the results folder: " + std::strerror(err));
    std::string holder = n > 0 ? std::string(buf, size_t(n)) : std::string();
    for (char& c : holder)
      if (c == '\n') c = ' ';
    while (!holder.empty() && holder.back() == ' ') holder.pop_back();
    throw UsageError(dir + ": in use by another cstab command (" +
                     (holder.empty() ? std::string("pid unknown") : "pid " + holder) +
                     "); wait for it to finish");
  }
  const std::string text = std::to_string(::getpid()) + "\n" + command + "\n";
  if (::ftruncate(fd_, 0) == 0) {
    const ssize_t w = ::pwrite(fd_, text.data(), text.size(), 0);
    (void)w;  // the pid is information; the flock is the lock
  }
}

FolderLock::~FolderLock() {
  if (fd_ >= 0) ::close(fd_);
}

}  // namespace cstab
