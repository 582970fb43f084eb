// The lock a results folder owns while a command writes it (`cstab matrix`,
// `merge`, `report`, `gate --update`): an exclusive flock on DIR/.cstab.lock,
// which holds the holder's pid and command. A second command on the same
// folder fails at once (UsageError, exit 2) naming the holder. The kernel
// releases the lock when its holder exits, however it dies (kill -9
// included), so a stale lock file is simply taken over.
//
// A command that created the lock file and then fails (an exception leaves
// the scope of its FolderLock: a refused input, an I/O error) removes it
// again, so a refused command leaves nothing new behind; after success it
// stays, naming the last holder. Removing it is safe: whoever locks checks,
// once it holds the flock, that the file it locked is still the one at the
// path, and starts over if not (so two processes never hold two different
// files of the same name).
//
// A reading lock (`cstab merge` on its shard folders) is a shared flock on
// the folder's existing lock file: refused while a writer holds it (a
// matrix still running there), and a writer is refused while it is held.
// It never creates or writes the file (a shard may be read-only); a folder
// without a lock file has no writer.
#pragma once

#include <memory>
#include <string>

namespace cstab {

class FolderLock {
 public:
  enum class Mode { kWrite, kRead };

  // Locks `dir` (which must exist) for `command` ("cstab matrix", ...).
  // Throws UsageError if another process holds it (a writer, or with kWrite
  // a reader) or the lock file cannot be created (a read-only folder, kWrite).
  FolderLock(const std::string& dir, const std::string& command, Mode mode = Mode::kWrite);
  ~FolderLock();
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

  static const char* file_name() { return ".cstab.lock"; }

 private:
  std::string path_;
  int fd_ = -1;
  bool created_ = false;        // this process created the lock file
  int uncaught_on_entry_ = 0;   // std::uncaught_exceptions() when locked
};

// Creates `dir` (and its parents) and locks it for writing by `command`. A
// folder this call created is removed again if the lock is refused, so a
// refused command leaves nothing behind. If the folder cannot be created,
// throws UsageError("<what>: <reason>").
std::unique_ptr<FolderLock> create_locked_folder(const std::string& dir, const std::string& command,
                                                 const std::string& what);

}  // namespace cstab
