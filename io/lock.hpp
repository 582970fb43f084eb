// The lock a results folder owns while a command writes it (`cstab matrix`,
// `merge`, `report`, `gate --update`): an exclusive flock on DIR/.cstab.lock,
// which holds the holder's pid and command. A second command on the same
// folder fails at once (UsageError, exit 2) naming the holder. The kernel
// releases the lock when its holder exits, however it dies (kill -9
// included), so a stale lock file is simply taken over. The file itself is
// never removed (removing it would let two processes lock two different
// files of the same name).
#pragma once

#include <string>

namespace cstab {

class FolderLock {
 public:
  // Locks `dir` (which must exist) for `command` ("cstab matrix", ...).
  // Throws UsageError if another process holds it or the lock file cannot
  // be created (a read-only folder).
  FolderLock(const std::string& dir, const std::string& command);
  ~FolderLock();
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

  static const char* file_name() { return ".cstab.lock"; }

 private:
  int fd_ = -1;
};

}  // namespace cstab
