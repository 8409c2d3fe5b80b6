#include "ktx2_arrays.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include <Imath/half.h>
#include <fmt/format.h>
#include <zstd.h>

#include "skybake/base/errors.h"
#include "skybake/base/file_door.h"

namespace skybake {
namespace {

// 1 GiB: over 15 times the largest KTX2 skybake writes (ibl.size at most
// 1024: an rgba16f cube with every level, 6 x 1024^2 x 8 x 4/3 = 67 MB).
constexpr uint64_t kMaxKtx2Bytes = uint64_t(1) << 30;

uint32_t Get32(const std::string& b, size_t at) {
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= uint32_t(uint8_t(b[at + i])) << (8 * i);
  return v;
}
uint64_t Get64(const std::string& b, size_t at) { return uint64_t(Get32(b, at)) | (uint64_t(Get32(b, at + 4)) << 32); }

// An unsigned small float (KTX2 B10G11R11: 5-bit exponent, bias 15, no sign).
float UnsignedFloat(uint32_t bits, int mantissa_bits) {
  const uint32_t exponent = bits >> mantissa_bits, mantissa = bits & ((1u << mantissa_bits) - 1);
  const double fraction = double(mantissa) / double(1u << mantissa_bits);
  if (exponent == 0) return float(std::ldexp(fraction, -14));
  if (exponent == 31)
    return mantissa ? std::numeric_limits<float>::quiet_NaN() : std::numeric_limits<float>::infinity();
  return float(std::ldexp(1.0 + fraction, int(exponent) - 15));
}

// One texel of `format` (its Vulkan enum) into rgb.
void DecodeTexel(uint32_t format, const uint8_t* t, float* rgb) {
  if (format == 97) {  // VK_FORMAT_R16G16B16A16_SFLOAT
    for (int c = 0; c < 3; ++c) {
      Imath::half h;
      h.setBits(uint16_t(t[2 * c] | (t[2 * c + 1] << 8)));
      rgb[c] = float(h);
    }
    return;
  }
  const uint32_t v = uint32_t(t[0]) | (uint32_t(t[1]) << 8) | (uint32_t(t[2]) << 16) | (uint32_t(t[3]) << 24);
  if (format == 122) {  // VK_FORMAT_B10G11R11_UFLOAT_PACK32
    rgb[0] = UnsignedFloat(v & 0x7FF, 6);
    rgb[1] = UnsignedFloat((v >> 11) & 0x7FF, 6);
    rgb[2] = UnsignedFloat(v >> 22, 5);
    return;
  }
  // VK_FORMAT_E5B9G9R9_UFLOAT_PACK32: value = mantissa 2^(exponent - 15 - 9)
  const int exponent = int(v >> 27);
  for (int c = 0; c < 3; ++c) rgb[c] = float(std::ldexp(double((v >> (9 * c)) & 0x1FF), exponent - 15 - 9));
}

}  // namespace

std::vector<Ktx2Level> ReadKtx2Rgb(const std::string& path) {
  auto fail = [&](const std::string& why) {
    return OutputError(fmt::format("{} cannot be read back as KTX2: {}", path, why));
  };
  // Through the door (file_door.h), as the EXRs are: a FIFO, a device or a
  // link planted at the name is refused, not waited on or followed.
  std::string b;
  if (const std::string problem = ReadRegularFile(path, kMaxKtx2Bytes, FileLinks::kRefuse, b); !problem.empty())
    throw fail("it " + problem);
  constexpr uint8_t kIdentifier[12] = {0xAB, 'K', 'T', 'X', ' ', '2', '0', 0xBB, '\r', '\n', 0x1A, '\n'};
  if (b.size() < 80 || std::memcmp(b.data(), kIdentifier, 12) != 0) throw fail("no KTX2 identifier");
  const uint32_t format = Get32(b, 12), width = Get32(b, 20), height = Get32(b, 24), faces = Get32(b, 36);
  const uint32_t level_count = std::max(1u, Get32(b, 40)), scheme = Get32(b, 44);
  if (format != 97 && format != 122 && format != 123)
    throw fail(fmt::format("vkFormat {} is not one skybake writes", format));
  if (width != height || (faces != 1 && faces != 6) || Get32(b, 32) > 0 || Get32(b, 28) > 0)
    throw fail("not a square 2D image or cube");
  if (scheme != 0 && scheme != 2) throw fail(fmt::format("supercompression scheme {} is not zstd", scheme));
  const size_t texel_bytes = format == 97 ? 8 : 4;
  if (b.size() < 80 + size_t(level_count) * 24) throw fail("truncated level index");
  std::vector<Ktx2Level> levels;
  for (uint32_t i = 0; i < level_count; ++i) {
    const uint64_t offset = Get64(b, 80 + 24 * i), length = Get64(b, 88 + 24 * i);
    const uint64_t raw_length = Get64(b, 96 + 24 * i);
    if (offset > b.size() || length > b.size() - offset) throw fail(fmt::format("level {} lies past the end", i));
    Ktx2Level level;
    level.size = int(std::max(1u, width >> i));
    level.faces = int(faces);
    const size_t texels = size_t(level.size) * level.size * faces;
    if (raw_length != texels * texel_bytes)
      throw fail(fmt::format("level {} holds {} bytes, not {}", i, raw_length, texels * texel_bytes));
    std::string raw = b.substr(offset, length);
    if (scheme == 2) {
      std::string unpacked(raw_length, '\0');
      const size_t n = ZSTD_decompress(unpacked.data(), unpacked.size(), raw.data(), raw.size());
      if (ZSTD_isError(n) || n != raw_length) throw fail(fmt::format("level {}'s zstd data does not decompress", i));
      raw = std::move(unpacked);
    } else if (raw.size() != raw_length) {
      throw fail(fmt::format("level {} holds {} bytes, not {}", i, raw.size(), raw_length));
    }
    level.rgb.resize(texels * 3);
    for (size_t t = 0; t < texels; ++t)
      DecodeTexel(format, reinterpret_cast<const uint8_t*>(raw.data()) + t * texel_bytes, &level.rgb[3 * t]);
    levels.push_back(std::move(level));
  }
  return levels;
}

}  // namespace skybake
