#include "skybake/output/exr_read.h"

#include <cstring>
#include <exception>
#include <stdexcept>

#include <ImfArray.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfRgbaFile.h>
#include <fmt/format.h>

#include "skybake/base/file_door.h"

namespace skybake {
namespace {

// The bytes read through the door as OpenEXR's input stream.
class ByteStream : public Imf::IStream {
 public:
  explicit ByteStream(const std::string& bytes) : Imf::IStream("memory"), bytes_(bytes) {}
  bool read(char c[], int n) override {
    if (n < 0 || at_ > bytes_.size() || uint64_t(n) > bytes_.size() - at_)
      throw std::runtime_error("the file ends early");
    std::memcpy(c, bytes_.data() + at_, size_t(n));
    at_ += uint64_t(n);
    return at_ < bytes_.size();
  }
  uint64_t tellg() override { return at_; }
  void seekg(uint64_t pos) override { at_ = pos; }

 private:
  const std::string& bytes_;
  uint64_t at_ = 0;
};

}  // namespace

std::string ReadExrRgba(const std::string& path, int& width, int& height, std::vector<float>& rgba) {
  width = height = 0;
  rgba.clear();
  std::string bytes;
  if (std::string problem = ReadRegularFile(path, kMaxExrFileBytes, FileLinks::kRefuse, bytes); !problem.empty())
    return problem;
  try {
    ByteStream stream(bytes);
    Imf::RgbaInputFile in(stream);
    const Imath::Box2i window = in.dataWindow();
    const int64_t w = int64_t(window.max.x) - window.min.x + 1, h = int64_t(window.max.y) - window.min.y + 1;
    if (w <= 0 || h <= 0 || uint64_t(w) * uint64_t(h) > kMaxExrPixels)
      return fmt::format("has a data window of {} x {} pixels, not 1 to {} pixels", w, h, kMaxExrPixels);
    Imf::Array2D<Imf::Rgba> texels(h, w);
    in.setFrameBuffer(&texels[0][0] - window.min.x - int64_t(window.min.y) * w, 1, size_t(w));
    in.readPixels(window.min.y, window.max.y);
    rgba.resize(size_t(w) * size_t(h) * 4);
    float* out = rgba.data();
    for (int64_t y = 0; y < h; ++y)
      for (int64_t x = 0; x < w; ++x) {
        const Imf::Rgba& t = texels[y][x];
        *out++ = t.r;
        *out++ = t.g;
        *out++ = t.b;
        *out++ = t.a;
      }
    width = int(w);
    height = int(h);
  } catch (const std::exception& e) {
    rgba.clear();
    return fmt::format("is not an OpenEXR file ({})", e.what());
  }
  return "";
}

std::string ExrSizeOfBytes(const std::string& bytes, int& width, int& height) {
  width = height = 0;
  try {
    ByteStream stream(bytes);
    Imf::InputFile in(stream);
    const Imath::Box2i window = in.header().dataWindow();
    width = window.max.x - window.min.x + 1;
    height = window.max.y - window.min.y + 1;
  } catch (const std::exception& e) {
    return fmt::format("is not an OpenEXR file ({})", e.what());
  }
  return "";
}

}  // namespace skybake
