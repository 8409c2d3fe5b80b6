#include "skybake/output/exr_io.h"
#include "skybake/base/file_door.h"
#include "skybake/output/png_io.h"

#include "exr_deflate.h"

#include <atomic>
#include <functional>
#include <map>
#include <chrono>
#include <cerrno>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <mutex>
#include <set>

#include <fcntl.h>
#include <signal.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fmt/format.h>
#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfThreading.h>

namespace skybake {
namespace {

Imf::Compression CompressionFromName(const std::string& name) {
  if (name == "none") return Imf::NO_COMPRESSION;
  if (name == "rle") return Imf::RLE_COMPRESSION;
  if (name == "zips") return Imf::ZIPS_COMPRESSION;
  if (name == "piz") return Imf::PIZ_COMPRESSION;
  return Imf::ZIP_COMPRESSION;
}

// An OpenEXR output stream into memory: the file is encoded whole, then
// written by WriteFileAtomically, so every byte reaches the disk through one
// checked path.
class MemoryOStream : public Imf::OStream {
 public:
  explicit MemoryOStream(const std::string& name) : Imf::OStream(name.c_str()) {}
  void write(const char c[], int n) override {
    if (position_ + size_t(n) > bytes_.size()) bytes_.resize(position_ + size_t(n));
    std::memcpy(bytes_.data() + position_, c, size_t(n));
    position_ += size_t(n);
  }
  uint64_t tellp() override { return position_; }
  void seekp(uint64_t pos) override { position_ = size_t(pos); }
  std::string TakeBytes() { return std::move(bytes_); }

 private:
  std::string bytes_;
  size_t position_ = 0;
};

// What to do about a failed write, by errno.
std::string WriteFix(int error) {
  if (error == ENOSPC || error == EDQUOT) return ": the disk is full; free space or choose another --out";
  if (error == EFBIG) return ": the file is larger than the file-size limit (ulimit -f) or the file system allows";
  if (error == EACCES || error == EPERM || error == EROFS) return ": choose a writable --out folder";
  return "";
}

}  // namespace

std::string TemporaryPathFor(const std::string& path) {
  std::filesystem::path p(path);
  // Unguessable: the pid (for the stale-temporary cleaner) and 64 random
  // bits, so no one can plant a file or link at the name beforehand.
  uint64_t random = 0;
  if (::getrandom(&random, sizeof random, 0) != ssize_t(sizeof random)) {
    static std::atomic<uint64_t> counter{0};
    random = uint64_t(std::chrono::steady_clock::now().time_since_epoch().count()) * 0x9e3779b97f4a7c15ull ^
             (counter++ << 1);
  }
  // One fmt::format call: GCC 12's -Wrestrict misfires on `"." + std::string`.
  std::string name = fmt::format(".{}.tmp{}.{:016x}", p.filename().string(), ::getpid(), random);
  return (p.parent_path() / name).string();
}

int CreateExclusiveFile(std::string& temporary, const std::string& path) {
  // O_EXCL | O_NOFOLLOW: an existing file or link at the name is never
  // opened (EEXIST, ELOOP), so a planted link cannot redirect the write.
  for (int attempt = 0;; ++attempt) {
    temporary = TemporaryPathFor(path);
    int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (fd >= 0 || errno != EEXIST || attempt == 16) return fd;
  }
}

void WriteFileAtomically(const std::string& path, std::string_view bytes) {
  WriteFileAtomically(path, [bytes](const ByteSink& write) { write(bytes); });
}

void WriteFileAtomically(const std::string& path, const std::function<void(const ByteSink&)>& produce) {
  std::string temporary;
  bool created = false;
  std::function<void()> remove_temporary = [&] { ::unlink(temporary.c_str()); };
  auto fail = [&](const char* what, int error, int fd) {
    if (fd >= 0) ::close(fd);
    if (created) remove_temporary();
    throw OutputError(
        fmt::format("cannot write {} ({} {}: {}){}", path, what, temporary, std::strerror(error), WriteFix(error)));
  };
  // In a held folder (file_door.h) relative to its descriptor: the
  // folder the bake locked, whatever its name points to now.
  const std::filesystem::path target(path);
  const int dir_fd = HeldFolder(target.parent_path().string());
  const std::string name = target.filename().string();
  std::string temporary_name;
  auto unlink_temporary = [&] {
    if (dir_fd >= 0) ::unlinkat(dir_fd, temporary_name.c_str(), 0);
    else ::unlink(temporary.c_str());
  };
  int fd = -1;
  if (dir_fd >= 0) {
    for (int attempt = 0;; ++attempt) {
      temporary = TemporaryPathFor(path);
      temporary_name = std::filesystem::path(temporary).filename().string();
      fd = ::openat(dir_fd, temporary_name.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
      if (fd >= 0 || errno != EEXIST || attempt == 16) break;
    }
  } else {
    fd = CreateExclusiveFile(temporary, path);
  }
  if (fd < 0) fail("creating", errno, -1);
  created = true;
  remove_temporary = unlink_temporary;
  const ByteSink write = [&](std::string_view bytes) {
    for (size_t done = 0; done < bytes.size();) {
      ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) fail("writing", n < 0 ? errno : EIO, fd);
      done += size_t(n);
    }
  };
  try {
    produce(write);
  } catch (const OutputError&) {
    throw;  // from `write`: the descriptor is closed and the temporary removed
  } catch (...) {
    ::close(fd);
    unlink_temporary();
    throw;
  }
  // On disk before the rename, so that even a power cut leaves the old file
  // or the whole new one.
  if (::fsync(fd) != 0) fail("syncing", errno, fd);
  if (::close(fd) != 0) fail("closing", errno, -1);
  const int renamed = dir_fd >= 0 ? ::renameat(dir_fd, temporary_name.c_str(), dir_fd, name.c_str())
                                  : std::rename(temporary.c_str(), path.c_str());
  if (renamed != 0) {
    int error = errno;
    unlink_temporary();
    throw OutputError(fmt::format("cannot move {} into place: {}", path, std::strerror(error)));
  }
}

bool IsTemporaryOf(const std::string& file_name, const std::string& output_name, int* pid) {
  // .NAME.tmpPID.RANDOM (TemporaryPathFor), or .NAME.tmpPID of earlier versions.
  const std::string prefix = "." + output_name + ".tmp";
  if (file_name.size() <= prefix.size() || file_name.compare(0, prefix.size(), prefix) != 0) return false;
  int value = 0;
  size_t i = prefix.size();
  for (; i < file_name.size() && file_name[i] != '.'; ++i) {
    char c = file_name[i];
    if (c < '0' || c > '9' || value > 100000000) return false;
    value = value * 10 + (c - '0');
  }
  if (i == prefix.size()) return false;
  if (i < file_name.size()) {
    const std::string random = file_name.substr(i + 1);
    if (random.size() != 16 || random.find_first_not_of("0123456789abcdef") != std::string::npos) return false;
  }
  if (pid) *pid = value;
  return true;
}

std::vector<std::string> RemoveStaleTemporaries(const std::string& dir, const std::vector<std::string>& names) {
  std::vector<std::string> removed;
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) return removed;
  std::set<std::string> wanted(names.begin(), names.end());
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string file = entry.path().filename().string();
    if (file.size() < 2 || file[0] != '.') continue;
    const size_t tmp = file.rfind(".tmp");
    if (tmp == std::string::npos) continue;
    const std::string output = file.substr(1, tmp - 1);
    int pid = 0;
    if (!wanted.count(output) || !IsTemporaryOf(file, output, &pid)) continue;
    // A live writer keeps its file; a dead one (killed) left it behind. A
    // link is never a temporary of skybake's (planted): removed, not followed.
    const bool link = entry.is_symlink(ec);
    if (!link && (pid == ::getpid() || (pid > 0 && ::kill(pid, 0) == 0))) continue;
    if (std::filesystem::remove(entry.path(), ec)) removed.push_back(entry.path().string());
  }
  return removed;
}

double CheckedMaxValue(const std::vector<const RgbaImage*>& images) {
  // One pass without branches (the compiler vectorizes it): a value is bad
  // unless 0 <= v <= FLT_MAX, which NaN fails too.
  float max_rgb = 0.0f;
  bool bad = false;
  for (const RgbaImage* image : images) {
    const float* p = image->data();
    const size_t texels = image->texels();
    for (size_t t = 0; t < texels; ++t) {
      const float r = p[4 * t], g = p[4 * t + 1], b = p[4 * t + 2];
      bad |= !(r >= 0.0f && r <= FLT_MAX) | !(g >= 0.0f && g <= FLT_MAX) | !(b >= 0.0f && b <= FLT_MAX);
      max_rgb = std::max(max_rgb, std::max(r, std::max(g, b)));
    }
  }
  if (!bad) return double(max_rgb);
  // Which value, for the message.
  double max_value = 0.0;
  for (const RgbaImage* image : images) {
    for (size_t i = 0; i < image->texels() * 4; ++i) {
      if (i % 4 == 3) continue;
      float v = image->data()[i];
      if (!std::isfinite(v) || v < 0.0f)
        throw OutputError(fmt::format(
            "internal error: rendered value {} at texel {} is not a finite non-negative radiance", v, i / 4));
      max_value = std::max(max_value, double(v));
    }
  }
  return max_value;
}

double HalfRangeScale(double max_value, OverflowPolicy policy) {
  if (max_value <= kHalfMax) return 1.0;
  if (policy == OverflowPolicy::kRefuse)
    throw OutputError(
        fmt::format("the brightest value {:.6g} exceeds the half-float maximum {}: set output.pixel_type = "
                    "\"float\", or output.overflow = \"scale\" to scale the image by a power of two",
                    max_value, kHalfMax));
  return std::exp2(-std::ceil(std::log2(max_value / kHalfMax)));
}

namespace {
std::atomic<int> exr_threads{1};  // SetExrThreads
}  // namespace

void SetExrThreads(int threads) {
  exr_threads = std::max(threads, 1);
  if (Imf::globalThreadCount() != threads) Imf::setGlobalThreadCount(threads);
}

uint64_t WriteExr(const std::string& path, const RgbaImage& image, const ExrWriteOptions& options) {
  const std::string bytes = EncodeExr(path, image, options);
  WriteFileAtomically(path, bytes);
  return bytes.size();
}

namespace {

// OpenEXR's own encoder (every compression; the zlib ZIP for comparison).
std::string EncodeWithOpenExr(const std::string& path, const RgbaImage& image, const ExrWriteOptions& options) {
  const int w = image.width;
  const int h = image.height;
  Imf::PixelType type = options.pixel_type == PixelType::kHalf ? Imf::HALF : Imf::FLOAT;
  Imf::Header header(w, h);
  header.compression() = CompressionFromName(options.compression);
  header.zipCompressionLevel() = options.zip_level;
  header.channels().insert("R", Imf::Channel(type));
  header.channels().insert("G", Imf::Channel(type));
  header.channels().insert("B", Imf::Channel(type));
  const std::array<float, 8>& xy = options.chromaticities;
  Imf::addChromaticities(header, Imf::Chromaticities({xy[0], xy[1]}, {xy[2], xy[3]}, {xy[4], xy[5]}, {xy[6], xy[7]}));
  if (options.envmap >= 0) Imf::addEnvmap(header, Imf::Envmap(options.envmap));
  if (options.white_luminance > 0.0) Imf::addWhiteLuminance(header, float(options.white_luminance));
  for (const auto& [key, value] : options.attributes) header.insert(key, Imf::StringAttribute(value));

  // Scaled RGB copy in the file's pixel type (OpenEXR's OutputFile does not
  // convert float frame buffers to half channels).
  const size_t n = size_t(w) * h;
  const float scale = float(options.scale);
  std::vector<float> rgb_float;
  std::vector<half> rgb_half;
  char* base = nullptr;
  size_t element = 0;
  if (type == Imf::HALF) {
    rgb_half.resize(n * 3);
    for (size_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) rgb_half[3 * i + c] = half(image.data()[4 * i + c] * scale);
    base = reinterpret_cast<char*>(rgb_half.data());
    element = sizeof(half);
  } else {
    rgb_float.resize(n * 3);
    for (size_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) rgb_float[3 * i + c] = image.data()[4 * i + c] * scale;
    base = reinterpret_cast<char*>(rgb_float.data());
    element = sizeof(float);
  }
  Imf::FrameBuffer frame;
  const size_t xs = 3 * element;
  const size_t ys = size_t(w) * xs;
  frame.insert("R", Imf::Slice(type, base + 0 * element, xs, ys));
  frame.insert("G", Imf::Slice(type, base + 1 * element, xs, ys));
  frame.insert("B", Imf::Slice(type, base + 2 * element, xs, ys));

  MemoryOStream encoded(path);
  try {
    Imf::OutputFile file(encoded, header);
    file.setFrameBuffer(frame);
    file.writePixels(h);
  } catch (const std::exception& e) {
    throw OutputError(fmt::format("cannot encode {}: {}", path, e.what()));
  }  // the OutputFile destructor writes the line offsets: encoded is complete here
  return encoded.TakeBytes();
}

}  // namespace

std::vector<std::string> EncodeExrs(const std::vector<ExrFile>& files) {
  std::vector<std::string> encoded(files.size());
  std::vector<const ExrFile*> ours;
  std::vector<size_t> where;
  for (size_t i = 0; i < files.size(); ++i) {
    if (!files[i].options.openexr_encoder && DeflateEncoderHandles(files[i].options.compression)) {
      ours.push_back(&files[i]);
      where.push_back(i);
    } else {
      encoded[i] = EncodeWithOpenExr(files[i].name, *files[i].image, files[i].options);
    }
  }
  if (!ours.empty()) {
    std::vector<std::string> bytes = EncodeExrsDeflate(ours, exr_threads);
    for (size_t k = 0; k < ours.size(); ++k) encoded[where[k]] = std::move(bytes[k]);
  }
  return encoded;
}

std::string EncodeExr(const std::string& path, const RgbaImage& image, const ExrWriteOptions& options) {
  return std::move(EncodeExrs({ExrFile{path, &image, options}})[0]);
}

uint64_t WritePng(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb) {
  // Encoded in memory by libpng, then written like every other file.
  std::string encoded;
  try {
    encoded = EncodePngRgb8(width, height, rgb);
  } catch (const OutputError& e) {
    throw OutputError(fmt::format("cannot encode {}: {}", path, e.what()));
  }
  WriteFileAtomically(path, encoded);
  return encoded.size();
}

}  // namespace skybake
