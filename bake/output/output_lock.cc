#include "skybake/output/output_lock.h"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <set>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fmt/format.h>

#include "skybake/input/config.h"
#include "skybake/output/exr_io.h"
#include "skybake/base/file_door.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;

constexpr const char* kMutexName = ".skybake.lock";
constexpr const char* kClaimPrefix = ".skybake.lock.";
constexpr const char* kClaimHeader = "skybake output lock\n";
// A claim lists every file of its bake: 100,000 frames of 9 files with
// 40-byte names are 36 MB; anything larger is not a claim of ours.
constexpr off_t kMaxClaimBytes = off_t(256) << 20;

// `text` with control characters escaped, for a message (EscapedText
// without its quotes).
std::string EscapedName(std::string_view text) {
  const std::string quoted = EscapedText(text);
  return quoted.substr(1, quoted.size() - 2);
}

// The program, its subcommand and the part it bakes ("skybake bake --shard
// 2/4"), not the whole command line: a claim is read by whoever shares the
// folder, and the other arguments may name private paths.
std::string ProcessCommandLine() {
  std::vector<std::string> args(1);
  if (FILE* f = std::fopen("/proc/self/cmdline", "rb")) {
    char buffer[4096];
    const size_t n = std::fread(buffer, 1, sizeof buffer, f);
    std::fclose(f);
    for (size_t i = 0; i < n; ++i) {
      if (buffer[i] == 0) args.emplace_back();
      else args.back() += buffer[i];
    }
  }
  std::string command = fs::path(args[0]).filename().string();
  if (args.size() > 1 && !args[1].empty() && args[1][0] != '-') command += " " + args[1];
  for (size_t i = 2; i < args.size(); ++i) {
    if ((args[i] == "--shard" || args[i] == "--frames") && i + 1 < args.size())
      command += " " + args[i] + " " + args[i + 1];
    else if (args[i].rfind("--shard=", 0) == 0 || args[i].rfind("--frames=", 0) == 0) command += " " + args[i];
  }
  return EscapedName(command);
}

std::string HostName() {
  char host[256] = {};
  if (::gethostname(host, sizeof host - 1) != 0) return "unknown host";
  return host;
}

// What a live claim says of its holder, and its names.
struct Claim {
  std::string pid, host, command;
  std::vector<std::string> names;
};

bool ParseClaim(const std::string& text, Claim& claim) {
  if (text.compare(0, std::strlen(kClaimHeader), kClaimHeader) != 0) return false;
  size_t at = std::strlen(kClaimHeader);
  auto line = [&](std::string& out) {
    const size_t end = text.find('\n', at);
    if (end == std::string::npos) return false;
    out = text.substr(at, end - at);
    at = end + 1;
    return true;
  };
  auto field = [&](const char* key, std::string& out) {
    std::string l;
    if (!line(l) || l.compare(0, std::strlen(key), key) != 0) return false;
    out = l.substr(std::strlen(key));
    return true;
  };
  std::string count;
  if (!field("pid ", claim.pid) || !field("host ", claim.host) || !field("command ", claim.command) ||
      !field("names ", count))
    return false;
  std::string name;
  while (line(name)) claim.names.push_back(name);
  return true;
}

// Reads a claim file opened with `fd` (at most kMaxClaimBytes).
std::string ReadAll(int fd) {
  std::string text;
  char buffer[1 << 16];
  for (;;) {
    ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    text.append(buffer, size_t(n));
    if (off_t(text.size()) > kMaxClaimBytes) break;
  }
  return text;
}

[[noreturn]] void FailLock(const std::string& dir, const char* what, int error) {
  throw OutputError(
      fmt::format("cannot lock the output folder {} ({} {}/{}: {}): choose a writable --out folder "
                  "that holds no link named {}",
                  dir, what, dir, kMutexName, std::strerror(error), kMutexName));
}

bool LockingUnsupported(int error) { return error == ENOLCK || error == EOPNOTSUPP || error == ENOSYS; }

// What the mutex file says of its holder ("pid N\nhost H\n", written by
// the holder once it has the lock), as "pid N on H"; "an unknown process"
// when it says nothing (a holder from before the file said so, or one
// between taking the lock and writing).
std::string MutexHolder(int fd) {
  char buffer[512] = {};
  const ssize_t n = ::pread(fd, buffer, sizeof buffer - 1, 0);
  Claim holder;
  const std::string text =
      std::string(kClaimHeader) + std::string(buffer, n > 0 ? size_t(n) : 0) + "command \nnames 0\n";
  if (!ParseClaim(text, holder) || holder.pid.empty()) return "an unknown process";
  return fmt::format("pid {} on {}", EscapedName(holder.pid), EscapedName(holder.host));
}

// The folder's short-lived mutex: `.skybake.lock`, flock'd; the file is
// removed by its holder before unlocking, so a waiter that then gets the
// lock on the removed file tries again on a new one. -1 when the file
// system has no flock (a warning says so). Held for as long as one process
// reads the claims (milliseconds): a wait beyond `wait_seconds` means its
// holder is stopped or hung, and is refused with OutputLockedError naming
// the holder.
int LockFolder(const std::string& dir, double wait_seconds) {
  const std::string path = (fs::path(dir) / kMutexName).string();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(wait_seconds);
  for (;;) {
    int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK, 0644);
    if (fd < 0) FailLock(dir, "opening", errno);
    struct stat held {
    }, named{};
    if (::fstat(fd, &held) != 0 || !S_ISREG(held.st_mode)) {
      ::close(fd);
      FailLock(dir, "checking", EINVAL);
    }
    int rc;
    // Polled, not blocked on: a blocking flock has no timeout. From 1 ms,
    // doubling to 50 ms between tries.
    auto pause = std::chrono::milliseconds(1);
    while ((rc = ::flock(fd, LOCK_EX | LOCK_NB)) != 0 && (errno == EINTR || errno == EWOULDBLOCK)) {
      if (errno == EINTR) continue;
      if (std::chrono::steady_clock::now() >= deadline) {
        const std::string holder = MutexHolder(fd);
        ::close(fd);
        throw OutputLockedError(fmt::format(
            "{}/{} has been held for more than {} s by {}: that skybake is stopped or hung; end it, or choose "
            "another --out (SKYBAKE_LOCK_WAIT_SECONDS sets the wait)",
            dir, kMutexName, wait_seconds, holder));
      }
      std::this_thread::sleep_for(pause);
      pause = std::min(pause * 2, std::chrono::milliseconds(50));
    }
    if (rc != 0) {
      const int error = errno;
      ::close(fd);
      if (LockingUnsupported(error)) {
        std::fprintf(stderr,
                     "skybake: warning: %s cannot be locked (%s): concurrent bakes into it are not "
                     "detected\n",
                     dir.c_str(), std::strerror(error));
        return -1;
      }
      FailLock(dir, "locking", error);
    }
    if (::lstat(path.c_str(), &named) == 0 && named.st_dev == held.st_dev && named.st_ino == held.st_ino) {
      // Who holds it, for a waiter's message (best effort: a waiter copes
      // with an empty file).
      const std::string holder = fmt::format("pid {}\nhost {}\n", ::getpid(), HostName());
      if (::ftruncate(fd, 0) == 0 && ::pwrite(fd, holder.data(), holder.size(), 0) < 0) {
      }
      return fd;
    }
    ::close(fd);  // removed or replaced while we waited: take the new one
  }
}

void UnlockFolder(const std::string& dir, int fd) {
  if (fd < 0) return;
  ::unlink((fs::path(dir) / kMutexName).c_str());
  ::close(fd);
}

}  // namespace

bool IsLockFileName(const std::string& file_name) {
  return file_name == kMutexName || file_name.compare(0, std::strlen(kClaimPrefix), kClaimPrefix) == 0;
}

double MutexWaitSeconds() {
  const char* text = std::getenv("SKYBAKE_LOCK_WAIT_SECONDS");
  if (!text || !*text) return kDefaultMutexWaitSeconds;
  char* end = nullptr;
  const double seconds = std::strtod(text, &end);
  if (*end != '\0' || !std::isfinite(seconds) || seconds < 0.0 || seconds > 86400.0)
    throw UsageError(
        fmt::format("SKYBAKE_LOCK_WAIT_SECONDS='{}' is not a number of seconds in [0, 86400]: "
                    "give e.g. 30, or unset it (default {} s)",
                    EscapedName(text), kDefaultMutexWaitSeconds));
  return seconds;
}

OutputLock OutputLock::Claim(const std::string& dir, const std::vector<std::string>& names) {
  return Claim(dir, names, MutexWaitSeconds());
}

OutputLock OutputLock::Claim(const std::string& dir, const std::vector<std::string>& names, double wait_seconds) {
  const int mutex = LockFolder(dir, wait_seconds);
  if (mutex < 0) return OutputLock();
  struct Unlock {
    const std::string& dir;
    int fd;
    ~Unlock() { UnlockFolder(dir, fd); }
  } unlock{dir, mutex};

  // Live claims that share a name with ours refuse; claims no one holds
  // (their process ended, kill -9 included) are removed.
  const std::set<std::string> ours(names.begin(), names.end());
  std::error_code ec;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir, ec)) {
    const std::string file = entry.path().filename().string();
    if (file.compare(0, std::strlen(kClaimPrefix), kClaimPrefix) != 0) continue;
    int fd = ::open(entry.path().c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) continue;  // a link or gone: not a claim
    struct stat st {};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || st.st_size > kMaxClaimBytes) {
      ::close(fd);
      continue;
    }
    if (::flock(fd, LOCK_SH | LOCK_NB) == 0) {
      ::unlink(entry.path().c_str());  // stale: its holder is gone
      ::close(fd);
      continue;
    }
    const std::string text = ReadAll(fd);
    ::close(fd);
    skybake::Claim other;
    if (!ParseClaim(text, other)) continue;
    for (const std::string& name : other.names) {
      if (!ours.count(name)) continue;
      throw OutputLockedError(fmt::format(
          "{} is being written by another skybake (pid {} on {}: {}), which writes {} too: wait for it to end, or "
          "choose another --out (parts of one sequence, --shard or --frames, share a folder when their frames "
          "differ)",
          dir, other.pid, other.host, other.command, (fs::path(dir) / name).string()));
    }
  }

  // Ours: created new (never an existing file or link), locked, then filled.
  OutputLock lock;
  // TemporaryPathFor gives `..skybake.lock.tmpPID.RANDOM`: the claim is `.skybake.lock.PID.RANDOM`.
  const std::string temporary = fs::path(TemporaryPathFor((fs::path(dir) / kMutexName).string())).filename().string();
  const std::string claim_path =
      (fs::path(dir) / (kClaimPrefix + temporary.substr(std::strlen("..skybake.lock.tmp")))).string();
  // Readable by the owner and group only (farm users who share a folder
  // share a group); the umask may narrow it further.
  int fd = ::open(claim_path.c_str(), O_RDWR | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0640);
  if (fd < 0) FailLock(dir, "creating a claim in", errno);
  lock.path_ = claim_path;
  lock.fd_ = fd;
  // The folder itself, held with the lock to the end (file_door.h): the
  // bake's outputs are written relative to it.
  const int dir_fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd < 0) FailLock(dir, "opening the folder of", errno);
  HoldFolder(dir, dir_fd);
  lock.dir_ = dir;
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) FailLock(dir, "locking a claim in", errno);
  std::string text = kClaimHeader;
  text += fmt::format("pid {}\nhost {}\ncommand {}\nnames {}\n", ::getpid(), HostName(), ProcessCommandLine(),
                      names.size());
  for (const std::string& name : names) text += name + "\n";
  for (size_t done = 0; done < text.size();) {
    ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) FailLock(dir, "writing a claim in", n < 0 ? errno : EIO);
    done += size_t(n);
  }
  return lock;
}

OutputLock::OutputLock(OutputLock&& other) noexcept
    : fd_(other.fd_), path_(std::move(other.path_)), dir_(std::move(other.dir_)) {
  other.fd_ = -1;
  other.path_.clear();
  other.dir_.clear();
}

OutputLock& OutputLock::operator=(OutputLock&& other) noexcept {
  if (this != &other) {
    Release();
    fd_ = other.fd_;
    path_ = std::move(other.path_);
    dir_ = std::move(other.dir_);
    other.fd_ = -1;
    other.path_.clear();
    other.dir_.clear();
  }
  return *this;
}

OutputLock::~OutputLock() { Release(); }

void OutputLock::Release() {
  if (fd_ < 0) return;
  ::unlink(path_.c_str());
  ::close(fd_);
  fd_ = -1;
  if (!dir_.empty()) ReleaseFolder(dir_);
  dir_.clear();
}

}  // namespace skybake
