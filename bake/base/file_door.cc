#include "skybake/base/file_door.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <map>
#include <mutex>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fmt/format.h>

#include "skybake/base/errors.h"

namespace skybake {
namespace {

// What a file that is not regular is, for the message.
std::string NotRegular(mode_t mode) {
  if (S_ISDIR(mode)) return "is a directory, not a file";
  if (S_ISFIFO(mode)) return "is a FIFO (named pipe), not a regular file";
  if (S_ISSOCK(mode)) return "is a socket, not a regular file";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "is a device, not a regular file";
  return "is not a regular file";
}

std::string OpenProblem(int error, FileLinks links) {
  if (error == ENOENT) return "no such file";
  if (error == ELOOP && links == FileLinks::kRefuse) return "is a symbolic link, which is not followed here";
  if (error == EACCES) return "cannot be read (no permission)";
  return fmt::format("cannot be opened ({})", std::strerror(error));
}

// `fd` (open, non-blocking) checked to be a regular file and made blocking;
// closed on a problem.
std::string CheckOpened(int fd, int& out) {
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    const int error = errno;
    ::close(fd);
    return fmt::format("cannot be examined ({})", std::strerror(error));
  }
  if (!S_ISREG(st.st_mode)) {
    ::close(fd);
    return NotRegular(st.st_mode);
  }
  const int flags = ::fcntl(fd, F_GETFL);
  if (flags >= 0) ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);
  out = fd;
  return "";
}

// Reads `fd` to its end, at most `max_bytes`; closes it.
std::string ReadAll(int fd, uint64_t max_bytes, std::string& bytes) {
  bytes.clear();
  struct stat st {};
  if (::fstat(fd, &st) == 0 && uint64_t(st.st_size) > max_bytes) {
    ::close(fd);
    return fmt::format("is {} bytes, more than the {} MiB such a file may have", uint64_t(st.st_size), max_bytes >> 20);
  }
  if (st.st_size > 0) bytes.reserve(size_t(st.st_size));
  char buffer[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int error = errno;
      ::close(fd);
      bytes.clear();
      return fmt::format("cannot be read ({})", std::strerror(error));
    }
    if (n == 0) break;
    bytes.append(buffer, size_t(n));
    if (bytes.size() > max_bytes) {
      ::close(fd);
      bytes.clear();
      return fmt::format("is more than the {} MiB such a file may have", max_bytes >> 20);
    }
  }
  ::close(fd);
  return "";
}

}  // namespace

namespace {

std::string FolderKey(const std::string& dir) {
  std::string key = std::filesystem::path(dir.empty() ? "." : dir).lexically_normal().string();
  while (key.size() > 1 && key.back() == '/') key.pop_back();
  return key;
}

struct HeldFolders {
  std::mutex mutex;
  std::map<std::string, std::pair<int, int>> fd_and_count;
};
HeldFolders& Held() {
  static HeldFolders held;
  return held;
}

}  // namespace

void HoldFolder(const std::string& dir, int fd) {
  HeldFolders& h = Held();
  std::lock_guard<std::mutex> lock(h.mutex);
  auto [it, inserted] = h.fd_and_count.try_emplace(FolderKey(dir), fd, 0);
  if (!inserted) ::close(fd);
  ++it->second.second;
}

void ReleaseFolder(const std::string& dir) {
  HeldFolders& h = Held();
  std::lock_guard<std::mutex> lock(h.mutex);
  auto it = h.fd_and_count.find(FolderKey(dir));
  if (it == h.fd_and_count.end()) return;
  if (--it->second.second == 0) {
    ::close(it->second.first);
    h.fd_and_count.erase(it);
  }
}

int HeldFolder(const std::string& dir) {
  HeldFolders& h = Held();
  std::lock_guard<std::mutex> lock(h.mutex);
  auto it = h.fd_and_count.find(FolderKey(dir));
  return it == h.fd_and_count.end() ? -1 : it->second.first;
}

std::string OpenRegularFile(const std::string& path, FileLinks links, int& fd) {
  fd = -1;
  if (path.empty()) return "no such file (an empty path)";
  const int flags = O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY | (links == FileLinks::kRefuse ? O_NOFOLLOW : 0);
  // A file of a held folder is opened in the folder held, whatever its name
  // points to now.
  const std::filesystem::path p(path);
  const int dir_fd = HeldFolder(p.parent_path().string());
  const int opened = dir_fd >= 0 ? ::openat(dir_fd, p.filename().c_str(), flags) : ::open(path.c_str(), flags);
  if (opened < 0) return OpenProblem(errno, links);
  return CheckOpened(opened, fd);
}

std::string OpenStreamOutput(const std::string& path, int& fd) {
  fd = -1;
  if (path.empty()) return "is an empty path";
  const int opened = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_NONBLOCK | O_CLOEXEC | O_NOCTTY, 0644);
  if (opened < 0) {
    const int error = errno;
    if (error == ENXIO) return "is a FIFO (named pipe) or socket that no process reads";
    if (error == EISDIR) return "is a directory, not a file";
    if (error == EACCES) return "cannot be written (no permission)";
    return fmt::format("cannot be opened for writing ({})", std::strerror(error));
  }
  struct stat st {};
  if (::fstat(opened, &st) != 0 || !(S_ISREG(st.st_mode) || S_ISFIFO(st.st_mode) || S_ISCHR(st.st_mode))) {
    ::close(opened);
    return S_ISBLK(st.st_mode) ? "is a block device, not a file" : "is not a regular file, a pipe or a terminal";
  }
  const int flags = ::fcntl(opened, F_GETFL);
  if (flags >= 0) ::fcntl(opened, F_SETFL, flags & ~O_NONBLOCK);
  fd = opened;
  return "";
}

std::string ReadRegularFile(const std::string& path, uint64_t max_bytes, FileLinks links, std::string& bytes) {
  int fd = -1;
  const std::string problem = OpenRegularFile(path, links, fd);
  if (!problem.empty()) return problem;
  return ReadAll(fd, max_bytes, bytes);
}

namespace {

// The kept reads, and how many KeptReadScopes are open.
struct KeptReads {
  struct Kept {
    std::string problem;
    std::shared_ptr<const std::string> bytes;
  };
  std::mutex mutex;
  std::map<std::string, Kept> kept;
  int scopes = 0;
};

KeptReads& TheKeptReads() {
  static KeptReads* reads = new KeptReads;  // never destroyed: a read may come from a thread at exit
  return *reads;
}

}  // namespace

KeptReadScope::KeptReadScope() {
  KeptReads& k = TheKeptReads();
  std::lock_guard<std::mutex> lock(k.mutex);
  if (k.scopes++ == 0) k.kept.clear();
}

KeptReadScope::~KeptReadScope() {
  KeptReads& k = TheKeptReads();
  std::lock_guard<std::mutex> lock(k.mutex);
  --k.scopes;
}

std::string ReadKept(const std::string& path, uint64_t max_bytes, std::shared_ptr<const std::string>& bytes) {
  KeptReads& reads = TheKeptReads();
  std::lock_guard<std::mutex> lock(reads.mutex);
  std::map<std::string, KeptReads::Kept>& kept = reads.kept;
  auto it = kept.find(path);
  if (it == kept.end()) {
    auto read = std::make_shared<std::string>();
    KeptReads::Kept k;
    k.problem = ReadRegularFile(path, max_bytes, FileLinks::kFollow, *read);
    if (k.problem.empty()) k.bytes = std::move(read);
    it = kept.emplace(path, std::move(k)).first;
  }
  bytes = it->second.bytes;
  return it->second.problem;
}

std::string FolderNameProblem(const std::string& name) {
  if (name.empty()) return "is an empty name";
  if (name == "." || name == "..") return "names a folder, not a file in it";
  if (name.size() > 255) return "is longer than the 255 bytes of a file name";
  for (char ch : name) {
    const unsigned char c = static_cast<unsigned char>(ch);
    if (c == '/' || c == '\\') return "is a path, not a plain file name of the folder";
    if (c < 0x20 || c == 0x7f) return "has a control character";
  }
  return "";
}

std::string ReadFolderFile(const std::string& dir, const std::string& name, uint64_t max_bytes, std::string& bytes) {
  if (std::string problem = FolderNameProblem(name); !problem.empty()) return problem;
  const int dir_fd = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd < 0) return fmt::format("cannot open its folder ({})", std::strerror(errno));
  const int opened = ::openat(dir_fd, name.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY | O_NOFOLLOW);
  const int error = errno;
  ::close(dir_fd);
  if (opened < 0) return OpenProblem(error, FileLinks::kRefuse);
  int fd = -1;
  if (std::string problem = CheckOpened(opened, fd); !problem.empty()) return problem;
  return ReadAll(fd, max_bytes, bytes);
}

std::string RegularFileSize(const std::string& path, uint64_t& size) {
  int fd = -1;
  if (std::string problem = OpenRegularFile(path, FileLinks::kRefuse, fd); !problem.empty()) return problem;
  struct stat st {};
  const int rc = ::fstat(fd, &st);
  ::close(fd);
  if (rc != 0) return "cannot be examined";
  size = uint64_t(st.st_size);
  return "";
}

uint64_t WrittenFileSize(const std::string& path) {
  uint64_t size = 0;
  if (const std::string problem = RegularFileSize(path, size); !problem.empty())
    throw OutputError(fmt::format("{} was written but now {}: another process changed the output folder", path,
                                  problem == "no such file" ? "is gone" : problem));
  return size;
}

}  // namespace skybake
