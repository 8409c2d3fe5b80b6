// A lock on the files a bake (or a part of one, or a merge) writes into a
// folder, so that two processes writing the same files into one folder
// cannot corrupt it, while the parts of one sequence (`--shard`, `--frames`),
// whose files differ, write into one folder at the same time.
//
// Semantics (README "Safe outputs"):
//  - A claim is a hidden file `.skybake.lock.PID.RANDOM` in the folder that
//    lists the file names the process will write, its pid, host and command
//    line, and is held with flock(LOCK_EX) for as long as the process runs:
//    the kernel drops the lock when the process ends in any way (kill -9
//    included), and the next claimer removes the file of a claim no one holds.
//  - Claims are checked and made under a short exclusive flock on
//    `.skybake.lock` (removed after each use), so of two processes starting
//    together exactly one sees the other.
//  - A claim that shares a file name with a live claim is refused with
//    OutputLockedError (exit code 6) naming the other process and the first
//    shared file; a claim of other names (another part's frames and part
//    manifest) proceeds.
//  - The mutex is waited for at most a bounded time (SKYBAKE_LOCK_WAIT_SECONDS,
//    default 60 s), then OutputLockedError (exit 6) names its holder's pid
//    and host, which the holder writes into `.skybake.lock`.
//  - Links are never followed: the lock files are opened with O_NOFOLLOW.
#pragma once

#include <string>
#include <vector>

#include "skybake/base/errors.h"

namespace skybake {

// Another live process writes some of the same files into the folder.
class OutputLockedError : public OutputExistsError {
 public:
  using OutputExistsError::OutputExistsError;
};

// How long a claimer waits for the folder's mutex, which its holder keeps
// for the milliseconds of reading the claims: 60 s is a stopped or hung
// holder (a claim of 100,000 frames, 36 MB, is read in well under 1 s).
inline constexpr double kDefaultMutexWaitSeconds = 60.0;

class OutputLock {
 public:
  OutputLock() = default;
  // Claims `names` (plain file names) in the existing folder `dir`. Throws
  // OutputLockedError on an overlap with a live claim, OutputError when the
  // folder cannot hold a lock file (not writable).
  // The folder's mutex is waited for at most SKYBAKE_LOCK_WAIT_SECONDS
  // (default kDefaultMutexWaitSeconds); then OutputLockedError names its
  // holder (pid and host).
  static OutputLock Claim(const std::string& dir, const std::vector<std::string>& names);
  static OutputLock Claim(const std::string& dir, const std::vector<std::string>& names, double wait_seconds);
  OutputLock(OutputLock&& other) noexcept;
  OutputLock& operator=(OutputLock&& other) noexcept;
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;
  // Releases the claim: its file is removed, then the lock dropped.
  ~OutputLock();
  const std::string& path() const { return path_; }

 private:
  void Release();
  int fd_ = -1;
  std::string path_;
  std::string dir_;  // the folder held (file_door.h) while the claim lives
};

// True for the names of the lock's own files (`.skybake.lock`,
// `.skybake.lock.PID.RANDOM`).
bool IsLockFileName(const std::string& file_name);

}  // namespace skybake
