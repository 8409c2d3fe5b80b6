#include "skybake/output/json_spool.h"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include <fcntl.h>
#include <unistd.h>

#include <fmt/format.h>

namespace skybake {

JsonArraySpool::JsonArraySpool(std::string dir) : dir_(std::move(dir)) {}

JsonArraySpool::~JsonArraySpool() {
  if (fd_ >= 0) ::close(fd_);
}

void JsonArraySpool::Open() {
  // Unnamed, so nothing in the folder can be opened in its place, and
  // nothing is left behind by a killed bake.
  fd_ = ::open(dir_.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
  if (fd_ >= 0) return;
  if (std::FILE* f = std::tmpfile()) {
    fd_ = ::fcntl(fileno(f), F_DUPFD_CLOEXEC, 0);
    std::fclose(f);
  }
  if (fd_ < 0)
    throw OutputError(fmt::format("cannot make a temporary file in {} or the system's temporary folder: {}", dir_,
                                  std::strerror(errno)));
}

std::string IndentedJson(const std::string& text, const std::string& indent) {
  std::string out;
  out.reserve(text.size() + text.size() / 8);
  for (char c : text) {
    out += c;
    if (c == '\n') out += indent;  // a JSON string holds no raw newline: every one is between values
  }
  return out;
}

std::string SplicedJson(const std::string& text, const std::string& marker, const std::string& replacement) {
  const size_t at = text.find(marker);
  if (at == std::string::npos) throw std::logic_error("SplicedJson: no " + marker);
  return text.substr(0, at) + replacement + text.substr(at + marker.size());
}

void JsonArraySpool::Add(const std::string& element_text) {
  if (fd_ < 0) Open();
  // The element at indent 4, after the separator dump(2) puts before it.
  const std::string text = (count_ == 0 ? "\n    " : ",\n    ") + IndentedJson(element_text, "    ");
  for (size_t done = 0; done < text.size();) {
    ssize_t n = ::pwrite(fd_, text.data() + done, text.size() - done, off_t(bytes_ + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0)
      throw OutputError(fmt::format("cannot write the bake's record of its frames to a temporary file in {}: {}", dir_,
                                    std::strerror(n < 0 ? errno : EIO)));
    done += size_t(n);
  }
  bytes_ += text.size();
  ++count_;
}

void JsonArraySpool::WriteArray(const ByteSink& write) const {
  write("[");
  std::vector<char> buffer(size_t(1) << 20);
  for (uint64_t done = 0; done < bytes_;) {
    const size_t want = size_t(std::min<uint64_t>(buffer.size(), bytes_ - done));
    ssize_t n = ::pread(fd_, buffer.data(), want, off_t(done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0)
      throw OutputError(fmt::format("cannot read the bake's record of its frames back from a temporary file in {}: {}",
                                    dir_, std::strerror(n < 0 ? errno : EIO)));
    write(std::string_view(buffer.data(), size_t(n)));
    done += uint64_t(n);
  }
  write(count_ == 0 ? "]" : "\n  ]");
}

void WriteJsonWithSpools(const std::string& path, const std::string& document,
                         const std::vector<std::pair<std::string, const JsonArraySpool*>>& arrays) {
  // Where each array goes: after `"key": ` at indent 2. Inside a JSON string
  // every quote is escaped, so `"key": []` after a newline and two spaces is
  // the key itself.
  std::vector<std::pair<size_t, const JsonArraySpool*>> places;
  for (const auto& [key, spool] : arrays) {
    const std::string marker = "\n  \"" + key + "\": []";
    const size_t at = document.find(marker);
    if (at == std::string::npos) throw std::logic_error("WriteJsonWithSpools: no empty top-level array " + key);
    places.push_back({at + marker.size() - 2, spool});
  }
  std::sort(places.begin(), places.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  WriteFileAtomically(path, [&](const ByteSink& write) {
    size_t from = 0;
    for (const auto& [at, spool] : places) {
      write(std::string_view(document).substr(from, at - from));
      spool->WriteArray(write);
      from = at + 2;  // past "[]"
    }
    write(std::string_view(document).substr(from));
  });
}

}  // namespace skybake
