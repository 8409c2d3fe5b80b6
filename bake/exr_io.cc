#include "skybake/exr_io.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>

#include <unistd.h>

#include <fmt/format.h>
#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenImageIO/imageio.h>

namespace skybake {
namespace {

Imf::Compression CompressionFromName(const std::string& name) {
  if (name == "none") return Imf::NO_COMPRESSION;
  if (name == "rle") return Imf::RLE_COMPRESSION;
  if (name == "zips") return Imf::ZIPS_COMPRESSION;
  if (name == "piz") return Imf::PIZ_COMPRESSION;
  return Imf::ZIP_COMPRESSION;
}

// Renames the finished temporary file over `path`; removes it on failure.
void CommitFile(const std::string& temporary, const std::string& path) {
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    int error = errno;
    std::remove(temporary.c_str());
    throw OutputError(fmt::format("cannot move {} into place: {}", path, std::strerror(error)));
  }
}

uint64_t FileSize(const std::string& path) {
  std::error_code ec;
  uintmax_t size = std::filesystem::file_size(path, ec);
  return ec ? 0 : uint64_t(size);
}

}  // namespace

std::string TemporaryPathFor(const std::string& path) {
  std::filesystem::path p(path);
  // One fmt::format call: GCC 12's -Wrestrict misfires on `"." + std::string`.
  std::string name = fmt::format(".{}.tmp{}", p.filename().string(), ::getpid());
  return (p.parent_path() / name).string();
}

double CheckedMaxValue(const std::vector<const RgbaImage*>& images) {
  double max_value = 0.0;
  for (const RgbaImage* image : images) {
    for (size_t i = 0; i < image->rgba.size(); ++i) {
      if (i % 4 == 3) continue;
      float v = image->rgba[i];
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
    throw OutputError(fmt::format(
        "the brightest value {:.6g} exceeds the half-float maximum {}: set output.pixel_type = "
        "\"float\", or output.overflow = \"scale\" to scale the image by a power of two",
        max_value, kHalfMax));
  return std::exp2(-std::ceil(std::log2(max_value / kHalfMax)));
}

uint64_t WriteExr(const std::string& path, const RgbaImage& image, const ExrWriteOptions& options) {
  const int w = image.width;
  const int h = image.height;
  Imf::PixelType type = options.pixel_type == PixelType::kHalf ? Imf::HALF : Imf::FLOAT;
  Imf::Header header(w, h);
  header.compression() = CompressionFromName(options.compression);
  header.channels().insert("R", Imf::Channel(type));
  header.channels().insert("G", Imf::Channel(type));
  header.channels().insert("B", Imf::Channel(type));
  Imf::addChromaticities(header, Imf::Chromaticities());  // Rec.709 primaries, D65
  if (options.envmap >= 0) Imf::addEnvmap(header, Imf::Envmap(options.envmap));
  if (options.white_luminance > 0.0) Imf::addWhiteLuminance(header, float(options.white_luminance));
  for (const auto& [key, value] : options.attributes)
    header.insert(key, Imf::StringAttribute(value));

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
      for (int c = 0; c < 3; ++c) rgb_half[3 * i + c] = half(image.rgba[4 * i + c] * scale);
    base = reinterpret_cast<char*>(rgb_half.data());
    element = sizeof(half);
  } else {
    rgb_float.resize(n * 3);
    for (size_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) rgb_float[3 * i + c] = image.rgba[4 * i + c] * scale;
    base = reinterpret_cast<char*>(rgb_float.data());
    element = sizeof(float);
  }
  Imf::FrameBuffer frame;
  const size_t xs = 3 * element;
  const size_t ys = size_t(w) * xs;
  frame.insert("R", Imf::Slice(type, base + 0 * element, xs, ys));
  frame.insert("G", Imf::Slice(type, base + 1 * element, xs, ys));
  frame.insert("B", Imf::Slice(type, base + 2 * element, xs, ys));

  std::string temporary = TemporaryPathFor(path);
  try {
    Imf::OutputFile file(temporary.c_str(), header);
    file.setFrameBuffer(frame);
    file.writePixels(h);
  } catch (const std::exception& e) {
    std::remove(temporary.c_str());
    throw OutputError(fmt::format("cannot write {}: {}", path, e.what()));
  }
  CommitFile(temporary, path);
  return FileSize(path);
}

uint64_t WritePng(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb) {
  std::string temporary = TemporaryPathFor(path);
  auto out = OIIO::ImageOutput::create("png");
  if (!out) throw OutputError("OpenImageIO has no PNG writer: " + OIIO::geterror());
  OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::UINT8);
  spec.attribute("oiio:ColorSpace", "sRGB");
  spec.attribute("Software", "skybake " SKYBAKE_VERSION);
  bool ok = out->open(temporary, spec) && out->write_image(OIIO::TypeDesc::UINT8, rgb.data());
  ok = out->close() && ok;
  if (!ok) {
    std::string message = out->geterror();
    std::remove(temporary.c_str());
    throw OutputError(fmt::format("cannot write {}: {}", path, message));
  }
  CommitFile(temporary, path);
  return FileSize(path);
}

}  // namespace skybake
