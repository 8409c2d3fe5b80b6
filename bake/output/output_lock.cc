#include "skybake/output/output_lock.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <set>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fmt/format.h>

#include "skybake/output/exr_io.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;

constexpr const char* kMutexName = ".skybake.lock";
constexpr const char* kClaimPrefix = ".skybake.lock.";
constexpr const char* kClaimHeader = "skybake output lock\n";
// A claim lists every file of its bake: 100,000 frames of 9 files with
// 40-byte names are 36 MB; anything larger is not a claim of ours.
constexpr off_t kMaxClaimBytes = off_t(256) << 20;

std::string ProcessCommandLine() {
  std::string command;
  if (FILE* f = std::fopen("/proc/self/cmdline", "rb")) {
    char buffer[4096];
    size_t n = std::fread(buffer, 1, sizeof buffer, f);
    std::fclose(f);
    for (size_t i = 0; i < n; ++i) {
      const unsigned char c = static_cast<unsigned char>(buffer[i]);
      command += c == 0 ? ' ' : (c < 0x20 || c == 0x7f) ? '?' : char(c);
    }
  }
  while (!command.empty() && command.back() == ' ') command.pop_back();
  return command;
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
  throw OutputError(fmt::format("cannot lock the output folder {} ({} {}/{}: {}): choose a writable --out folder "
                                "that holds no link named {}",
                                dir, what, dir, kMutexName, std::strerror(error), kMutexName));
}

bool LockingUnsupported(int error) { return error == ENOLCK || error == EOPNOTSUPP || error == ENOSYS; }

// The folder's short-lived mutex: `.skybake.lock`, flock'd; the file is
// removed by its holder before unlocking, so a waiter that then gets the
// lock on the removed file tries again on a new one. -1 when the file
// system has no flock (a warning says so).
int LockFolder(const std::string& dir) {
  const std::string path = (fs::path(dir) / kMutexName).string();
  for (;;) {
    int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK, 0644);
    if (fd < 0) FailLock(dir, "opening", errno);
    struct stat held {}, named {};
    if (::fstat(fd, &held) != 0 || !S_ISREG(held.st_mode)) {
      ::close(fd);
      FailLock(dir, "checking", EINVAL);
    }
    int rc;
    while ((rc = ::flock(fd, LOCK_EX)) != 0 && errno == EINTR) {
    }
    if (rc != 0) {
      const int error = errno;
      ::close(fd);
      if (LockingUnsupported(error)) {
        std::fprintf(stderr, "skybake: warning: %s cannot be locked (%s): concurrent bakes into it are not "
                             "detected\n", dir.c_str(), std::strerror(error));
        return -1;
      }
      FailLock(dir, "locking", error);
    }
    if (::lstat(path.c_str(), &named) == 0 && named.st_dev == held.st_dev && named.st_ino == held.st_ino) return fd;
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

OutputLock OutputLock::Claim(const std::string& dir, const std::vector<std::string>& names) {
  const int mutex = LockFolder(dir);
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
  int fd = ::open(claim_path.c_str(), O_RDWR | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (fd < 0) FailLock(dir, "creating a claim in", errno);
  lock.path_ = claim_path;
  lock.fd_ = fd;
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

OutputLock::OutputLock(OutputLock&& other) noexcept : fd_(other.fd_), path_(std::move(other.path_)) {
  other.fd_ = -1;
  other.path_.clear();
}

OutputLock& OutputLock::operator=(OutputLock&& other) noexcept {
  if (this != &other) {
    Release();
    fd_ = other.fd_;
    path_ = std::move(other.path_);
    other.fd_ = -1;
    other.path_.clear();
  }
  return *this;
}

OutputLock::~OutputLock() { Release(); }

void OutputLock::Release() {
  if (fd_ < 0) return;
  ::unlink(path_.c_str());
  ::close(fd_);
  fd_ = -1;
}

}  // namespace skybake
