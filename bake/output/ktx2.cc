// KTX 2.0 writer. The container (KTX File Format Specification 2.0, section
// 3): a 12-byte identifier, the header, the level index, the data format
// descriptor (DFD), the key/value data, then the mip levels from the
// smallest to the largest, each aligned to lcm(texel size, 4) bytes when not
// supercompressed.
#include "skybake/output/ktx2.h"

#include <cmath>
#include <cstring>

#include <Imath/half.h>
#include <fmt/format.h>
#include <zstd.h>

#include "skybake/output/exr_io.h"

namespace skybake {
namespace {

constexpr uint8_t kIdentifier[12] = {0xAB, 'K', 'T', 'X', ' ', '2', '0', 0xBB, '\r', '\n', 0x1A, '\n'};

void Put32(std::string& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(char((v >> (8 * i)) & 0xFF));
}
void Set32(std::string& out, size_t at, uint32_t v) {
  for (int i = 0; i < 4; ++i) out[at + i] = char((v >> (8 * i)) & 0xFF);
}
void Set64(std::string& out, size_t at, uint64_t v) {
  for (int i = 0; i < 8; ++i) out[at + i] = char((v >> (8 * i)) & 0xFF);
}
void PadTo(std::string& out, size_t alignment) {
  while (out.size() % alignment) out.push_back('\0');
}

// A non-negative float as an unsigned float of 5 exponent bits (bias 15) and
// `mantissa_bits`, rounded to nearest (Vulkan spec, "Unsigned 11-bit and
// 10-bit floating-point numbers"; the shared-exponent format is separate).
uint32_t PackUnsignedFloat(float v, int mantissa_bits, const char* channel) {
  if (!(v >= 0.0f) || std::isinf(v))
    throw OutputError(fmt::format("KTX2: {} value {} cannot be stored (negative, infinite or NaN)", channel, v));
  if (v == 0.0f) return 0;
  int k;
  const double f = std::frexp(double(v), &k);  // v = f 2^k, f in [0.5, 1)
  int exponent = k - 1 + 15;
  uint32_t mantissa;
  const double one = double(1u << mantissa_bits);
  if (exponent <= 0) {  // denormal: m / 2^mb * 2^-14
    exponent = 0;
    mantissa = uint32_t(std::lround(double(v) * std::ldexp(1.0, 14) * one));
  } else {
    mantissa = uint32_t(std::lround((2.0 * f - 1.0) * one));
  }
  // A mantissa rounded up to 2^mb carries into the exponent through the bit layout.
  const uint32_t bits = (uint32_t(exponent) << mantissa_bits) + mantissa;
  if ((bits >> mantissa_bits) >= 31)
    throw OutputError(
        fmt::format("KTX2: {} value {} is beyond the B10G11R11 range (max {}): use "
                    "ibl.ktx2_format = \"rgba16f\" or output.overflow = \"scale\"",
                    channel, v, mantissa_bits == 6 ? 65024 : 64512));
  return bits;
}

uint16_t HalfBits(float v) {
  if (!std::isfinite(v) || std::abs(v) > 65504.0f)
    throw OutputError(
        fmt::format("KTX2: value {} is beyond half-float range (max 65504): set output.overflow = "
                    "\"scale\" (every file scaled by the same power of two)",
                    v));
  return Imath::half(v).bits();
}

// The texels of one image in the format, little-endian.
void EncodeTexels(const float* rgba, size_t texels, const Ktx2Options& o, std::string& out) {
  const float scale = float(o.scale);
  for (size_t i = 0; i < texels; ++i) {
    const float r = rgba[4 * i] * scale, g = rgba[4 * i + 1] * scale, b = rgba[4 * i + 2] * scale;
    switch (o.format) {
      case KtxFormat::kRgba16f: {
        for (float v : {r, g, b, 1.0f}) {
          uint16_t h = HalfBits(v);
          out.push_back(char(h & 0xFF));
          out.push_back(char(h >> 8));
        }
        break;
      }
      case KtxFormat::kB10g11r11:
        Put32(out, PackB10G11R11(r, g, b));
        break;
      case KtxFormat::kE5b9g9r9:
        Put32(out, PackE5B9G9R9(r, g, b));
        break;
    }
  }
}

// Khronos basic data format descriptor (Khronos Data Format Specification
// 1.3, section 5): one block, RGBSDA model, the options' primaries, linear, alpha
// straight. KTX-Software's validator (`ktx validate`, error 6028) compares
// each sample field by field with the descriptor its dfdutils library makes
// for the VkFormat (external/dfdutils: vk2dfd.inl, createdfd.c), and libktx
// refuses a file whose samples differ; each format's samples here are the
// ones that mapping gives:
//   rgba16f    R, G, B, A (channel 15): 16 bits each at 0, 16, 32, 48;
//              FLOAT | SIGNED; lower -1.0f, upper 1.0f
//   b10g11r11  R 11 bits at 0, G 11 at 11, B 10 at 22; FLOAT; 0.0f to 1.0f
//   e5b9g9r9   per channel its 9-bit mantissa (no qualifier, lower 0, upper
//              8448) then the shared 5-bit exponent at 27 (EXPONENT, lower
//              15 = the bias, upper 31)
std::string DataFormatDescriptor(KtxFormat format, uint32_t primaries) {
  struct Sample {
    uint32_t bit_offset, bit_length, channel, qualifiers, lower, upper;
  };
  constexpr uint32_t kFloat = 0x80, kSigned = 0x40, kExponent = 0x20;
  constexpr uint32_t kOneF = 0x3F800000u, kMinusOneF = 0xBF800000u;
  std::vector<Sample> samples;
  switch (format) {
    case KtxFormat::kRgba16f:
      for (uint32_t c = 0; c < 4; ++c)
        samples.push_back({16 * c, 16, c == 3 ? 15u : c, kFloat | kSigned, kMinusOneF, kOneF});
      break;
    case KtxFormat::kB10g11r11:
      samples = {{0, 11, 0, kFloat, 0, kOneF}, {11, 11, 1, kFloat, 0, kOneF}, {22, 10, 2, kFloat, 0, kOneF}};
      break;
    case KtxFormat::kE5b9g9r9:
      // Each channel: its 9-bit mantissa, then the shared 5-bit exponent
      // (bias 15, max 31). The mantissa's upper bound is 8448, the value
      // dfdutils' createDFDPackedShifted gives for this format (256 was
      // refused with error 6028).
      for (uint32_t c = 0; c < 3; ++c) {
        samples.push_back({9 * c, 9, c, 0, 0, 8448});
        samples.push_back({27, 5, c, kExponent, 15, 31});
      }
      break;
  }
  const uint32_t block_size = 24 + 16 * uint32_t(samples.size());
  std::string d;
  Put32(d, 4 + block_size);                      // dfdTotalSize
  Put32(d, 0);                                   // vendorId 0 (Khronos), descriptorType 0 (basic)
  Put32(d, 2u | (block_size << 16));             // versionNumber 2 (KDF 1.3), descriptorBlockSize
  Put32(d, 1u | (primaries << 8) | (1u << 16));  // colorModel RGBSDA, colorPrimaries, transfer LINEAR, flags 0
  Put32(d, 0);                                   // texelBlockDimension 1 x 1 x 1 x 1
  Put32(d, Ktx2TexelBytes(format));              // bytesPlane0
  Put32(d, 0);                                   // bytesPlane4..7
  for (const Sample& s : samples) {
    Put32(d, s.bit_offset | ((s.bit_length - 1) << 16) | ((s.channel | s.qualifiers) << 24));
    Put32(d, 0);  // sample position 0
    Put32(d, s.lower);
    Put32(d, s.upper);
  }
  return d;
}

std::string KeyValueData(const std::map<std::string, std::string>& metadata) {
  std::map<std::string, std::string> all = metadata;  // sorted by key, as the specification requires
  all["KTXorientation"] = "rd";
  all["KTXwriter"] = std::string("skybake ") + SKYBAKE_VERSION;
  std::string kvd;
  for (const auto& [key, value] : all) {
    std::string entry = key + '\0' + value + '\0';
    Put32(kvd, uint32_t(entry.size()));
    kvd += entry;
    PadTo(kvd, 4);
  }
  return kvd;
}

// The whole file from each level's raw bytes (level 0 first).
std::string Assemble(uint32_t width, uint32_t height, uint32_t faces, const std::vector<std::string>& raw_levels,
                     const Ktx2Options& o) {
  const uint32_t level_count = uint32_t(raw_levels.size());
  std::vector<std::string> stored = raw_levels;
  if (o.zstd_level > 0) {
    for (std::string& level : stored) {
      std::string packed(ZSTD_compressBound(level.size()), '\0');
      size_t n = ZSTD_compress(packed.data(), packed.size(), level.data(), level.size(), o.zstd_level);
      if (ZSTD_isError(n)) throw OutputError(std::string("KTX2: zstd failed: ") + ZSTD_getErrorName(n));
      packed.resize(n);
      level = std::move(packed);
    }
  }
  std::string out(reinterpret_cast<const char*>(kIdentifier), 12);
  Put32(out, Ktx2VkFormat(o.format));
  Put32(out, o.format == KtxFormat::kRgba16f ? 2 : 4);  // typeSize: the unit of endianness
  Put32(out, width);
  Put32(out, height);
  Put32(out, 0);  // pixelDepth: not a 3D texture
  Put32(out, 0);  // layerCount: not an array
  Put32(out, faces);
  Put32(out, level_count);
  Put32(out, o.zstd_level > 0 ? 2 : 0);  // supercompressionScheme: 2 = Zstandard
  const size_t index_at = out.size();
  out.resize(out.size() + 4 * 4 + 2 * 8);  // dfd and kvd offsets/lengths, sgd offset/length
  const size_t level_index_at = out.size();
  out.resize(out.size() + size_t(level_count) * 24);
  const std::string dfd = DataFormatDescriptor(o.format, o.primaries);
  const size_t dfd_at = out.size();
  out += dfd;
  const std::string kvd = KeyValueData(o.metadata);
  const size_t kvd_at = out.size();
  out += kvd;
  Set32(out, index_at, uint32_t(dfd_at));
  Set32(out, index_at + 4, uint32_t(dfd.size()));
  Set32(out, index_at + 8, uint32_t(kvd_at));
  Set32(out, index_at + 12, uint32_t(kvd.size()));
  Set64(out, index_at + 16, 0);  // no supercompression global data (zstd has none)
  Set64(out, index_at + 24, 0);
  // Mip levels, smallest first.
  const size_t alignment = o.zstd_level > 0 ? 1 : (Ktx2TexelBytes(o.format) == 8 ? 8 : 4);
  for (uint32_t i = level_count; i-- > 0;) {
    PadTo(out, alignment);
    Set64(out, level_index_at + 24 * i, out.size());
    Set64(out, level_index_at + 24 * i + 8, stored[i].size());
    Set64(out, level_index_at + 24 * i + 16, raw_levels[i].size());
    out += stored[i];
  }
  return out;
}

}  // namespace

uint32_t Ktx2VkFormat(KtxFormat format) {
  switch (format) {
    case KtxFormat::kRgba16f:
      return 97;  // VK_FORMAT_R16G16B16A16_SFLOAT
    case KtxFormat::kB10g11r11:
      return 122;  // VK_FORMAT_B10G11R11_UFLOAT_PACK32
    case KtxFormat::kE5b9g9r9:
      return 123;  // VK_FORMAT_E5B9G9R9_UFLOAT_PACK32
  }
  return 0;
}

uint32_t Ktx2TexelBytes(KtxFormat format) { return format == KtxFormat::kRgba16f ? 8 : 4; }

const char* Ktx2FormatName(KtxFormat format) {
  switch (format) {
    case KtxFormat::kRgba16f:
      return "rgba16f";
    case KtxFormat::kB10g11r11:
      return "b10g11r11";
    case KtxFormat::kE5b9g9r9:
      return "e5b9g9r9";
  }
  return "";
}

uint32_t PackB10G11R11(float r, float g, float b) {
  return PackUnsignedFloat(r, 6, "red") | (PackUnsignedFloat(g, 6, "green") << 11) |
         (PackUnsignedFloat(b, 5, "blue") << 22);
}

// Vulkan spec, "Shared Exponent Format" (after EXT_texture_shared_exponent):
// N = 9 mantissa bits, B = 15, Emax = 31.
uint32_t PackE5B9G9R9(float r, float g, float b) {
  constexpr int kN = 9, kB = 15, kEmax = 31;
  const double max_value = double((1 << kN) - 1) / double(1 << kN) * std::ldexp(1.0, kEmax - kB);  // 65408
  for (float v : {r, g, b}) {
    if (!(v >= 0.0f) || std::isinf(v))
      throw OutputError(fmt::format("KTX2: value {} cannot be stored (negative, infinite or NaN)", v));
    if (v > max_value)
      throw OutputError(
          fmt::format("KTX2: value {} is beyond the E5B9G9R9 range (max {}): use "
                      "output.overflow = \"scale\"",
                      v, max_value));
  }
  const double max_rgb = std::max({double(r), double(g), double(b)});
  int exp_shared = std::max(-kB - 1, int(std::floor(std::log2(std::max(max_rgb, 1e-300))))) + 1 + kB;
  double denom = std::ldexp(1.0, exp_shared - kB - kN);
  if (std::lround(max_rgb / denom) == (1 << kN)) {
    denom *= 2.0;
    ++exp_shared;
  }
  auto mantissa = [&](float v) { return uint32_t(std::lround(double(v) / denom)); };
  return mantissa(r) | (mantissa(g) << 9) | (mantissa(b) << 18) | (uint32_t(exp_shared) << 27);
}

std::string EncodeKtx2Cube(const std::vector<CubeLevel>& levels, const Ktx2Options& options) {
  std::vector<std::string> raw;
  for (const CubeLevel& level : levels) {
    std::string bytes;
    bytes.reserve(size_t(level.size) * level.size * 6 * Ktx2TexelBytes(options.format));
    for (const std::vector<float>& face : level.faces) EncodeTexels(face.data(), face.size() / 4, options, bytes);
    raw.push_back(std::move(bytes));
  }
  return Assemble(uint32_t(levels.front().size), uint32_t(levels.front().size), 6, raw, options);
}

std::string EncodeKtx2Image(int width, int height, const std::vector<float>& rgba, const Ktx2Options& options) {
  std::string bytes;
  EncodeTexels(rgba.data(), size_t(width) * height, options, bytes);
  return Assemble(uint32_t(width), uint32_t(height), 1, {bytes}, options);
}

uint32_t Ktx2Primaries(const OutputColorSpace& space) {
  struct Known {
    uint32_t primaries;
    std::array<std::array<double, 2>, 4> xy;
  };
  static const Known known[] = {
      {1, Chromaticities(ColorSpace::kRec709)},
      {4, Chromaticities(ColorSpace::kRec2020)},
      {5, Chromaticities(ColorSpace::kXyz)},
      {6, Chromaticities(ColorSpace::kAces2065)},
      {7, Chromaticities(ColorSpace::kAcesCg)},
      {10, {{{0.680, 0.320}, {0.265, 0.690}, {0.150, 0.060}, {0.3127, 0.3290}}}},  // Display P3 (SMPTE EG 432-1)
  };
  for (const Known& k : known) {
    bool same = true;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 2; ++j) same = same && std::abs(k.xy[i][j] - space.chromaticities[i][j]) < 5e-4;
    if (same) return k.primaries;
  }
  return 0;
}

}  // namespace skybake
