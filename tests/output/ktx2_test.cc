// KTX2 files (ktx2.h): the packed encodings against hand-worked values, the
// range refused, each format's data format descriptor word for word against
// the one KTX-Software's dfdutils makes for its VkFormat (in a small cube
// and in every file of the bakes below), and every file of an IBL bake
// through two readers: a conformance reader written here from
// the KTX 2.0 specification's rules (Ktx2Problems), and an independent
// parser, the npm package ktx-parse (tests/viewer/ktx2_dump.mjs): header,
// orientation and colour metadata, data format descriptor, the container
// written back by ktx-parse byte-identical, and every texel of every level
// against the EXR of the same level.
//
// KTX-Software's own validator (`ktx validate`) and libktx are in neither
// Debian 12 nor npm (docs/ibl.md, "KTX2"), so the test cannot run them.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <numeric>
#include <string>
#include <vector>

#include <sys/wait.h>

#include <Imath/half.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <zstd.h>

#include "skybake/output/exr_io.h"
#include "skybake/output/ktx2.h"
#include "test_support.h"

namespace skybake {
namespace {

using testing::RunCommand;

using nlohmann::json;

// Decoders written from the Vulkan specification, independently of the encoder.
float DecodeUnsignedFloat(uint32_t bits, int mantissa_bits) {
  const uint32_t e = bits >> mantissa_bits, m = bits & ((1u << mantissa_bits) - 1);
  if (e == 0) return float(std::ldexp(double(m) / (1 << mantissa_bits), -14));
  return float(std::ldexp(1.0 + double(m) / (1 << mantissa_bits), int(e) - 15));
}
std::array<float, 3> DecodeB10G11R11(uint32_t v) {
  return {DecodeUnsignedFloat(v & 0x7FF, 6), DecodeUnsignedFloat((v >> 11) & 0x7FF, 6),
          DecodeUnsignedFloat((v >> 22) & 0x3FF, 5)};
}
std::array<float, 3> DecodeE5B9G9R9(uint32_t v) {
  const double scale = std::ldexp(1.0, int(v >> 27) - 15 - 9);
  return {float((v & 0x1FF) * scale), float(((v >> 9) & 0x1FF) * scale), float(((v >> 18) & 0x1FF) * scale)};
}

TEST(Ktx2Test, PackedEncodingsOfKnownValues) {
  // 1.0 = 2^0: exponent 15, mantissa 0, in R (11 bits), G (11), B (10).
  EXPECT_EQ(PackB10G11R11(1.0f, 1.0f, 1.0f), (15u << 6) | ((15u << 6) << 11) | ((15u << 5) << 22));
  EXPECT_EQ(PackB10G11R11(0.0f, 0.0f, 0.0f), 0u);
  // 1.5 in R: exponent 15, mantissa 32 of 64.
  EXPECT_EQ(PackB10G11R11(1.5f, 0.0f, 0.0f), (15u << 6) | 32u);
  // Shared exponent: max 1 -> exponent 16, mantissas 256 (= 1.0 at 2^(16 - 24)).
  EXPECT_EQ(PackE5B9G9R9(1.0f, 0.5f, 0.0f), 256u | (128u << 9) | (16u << 27));
  for (float v : {0.001f, 0.37f, 3.0f, 1234.5f, 60000.0f}) {
    auto b = DecodeB10G11R11(PackB10G11R11(v, v, v));
    EXPECT_NEAR(b[0], v, v * 0.5 / 64);
    EXPECT_NEAR(b[2], v, v * 0.5 / 32);
    auto e = DecodeE5B9G9R9(PackE5B9G9R9(v, v * 0.25f, v));
    EXPECT_NEAR(e[0], v, v * 0.5 / 256);
    EXPECT_NEAR(e[1], v * 0.25f, v * 0.5 / 256);
  }
  EXPECT_THROW(PackB10G11R11(70000.0f, 0.0f, 0.0f), OutputError);
  EXPECT_THROW(PackB10G11R11(0.0f, 0.0f, 65400.0f), OutputError);  // B tops out at 64512 (65000 rounds to it)
  EXPECT_THROW(PackE5B9G9R9(65500.0f, 0.0f, 0.0f), OutputError);
  EXPECT_THROW(PackE5B9G9R9(-1.0f, 0.0f, 0.0f), OutputError);
  EXPECT_THROW(PackB10G11R11(NAN, 0.0f, 0.0f), OutputError);
}

// Little-endian words of a file.
uint32_t Word32(const std::string& bytes, size_t at) {
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= uint32_t(uint8_t(bytes[at + i])) << (8 * i);
  return v;
}
uint64_t Word64(const std::string& bytes, size_t at) {
  return uint64_t(Word32(bytes, at)) | (uint64_t(Word32(bytes, at + 4)) << 32);
}

// The header fields of a KTX 2.0 file (KTX File Format Specification 2.0,
// section 3.2: the 12-byte identifier, then these words in this order).
struct Ktx2Header {
  uint32_t vk_format, type_size, width, height, depth, layers, faces, levels, supercompression;
  uint32_t dfd_offset, dfd_length, kvd_offset, kvd_length;
  uint64_t sgd_offset, sgd_length;
};
Ktx2Header ReadKtx2Header(const std::string& bytes) {
  Ktx2Header h;
  uint32_t* words[] = {&h.vk_format,  &h.type_size,  &h.width,     &h.height,           &h.depth,
                       &h.layers,     &h.faces,      &h.levels,    &h.supercompression, &h.dfd_offset,
                       &h.dfd_length, &h.kvd_offset, &h.kvd_length};
  for (size_t i = 0; i < std::size(words); ++i) *words[i] = Word32(bytes, 12 + 4 * i);
  h.sgd_offset = Word64(bytes, 64);
  h.sgd_length = Word64(bytes, 72);
  return h;
}

// The descriptor of a file, as 32-bit words (dfdTotalSize first).
std::vector<uint32_t> DfdWords(const std::string& bytes) {
  const Ktx2Header h = ReadKtx2Header(bytes);
  std::vector<uint32_t> words;
  for (uint32_t at = 0; at < h.dfd_length; at += 4) words.push_back(Word32(bytes, h.dfd_offset + at));
  return words;
}

// A 1 x 1 cube of one level in `format`.
std::string TinyCube(KtxFormat format, int zstd_level = 0) {
  CubeLevel level;
  level.size = 1;
  for (auto& face : level.faces) face = {0.25f, 0.5f, 1.0f, 1.0f};
  Ktx2Options o;
  o.format = format;
  o.zstd_level = zstd_level;
  return EncodeKtx2Cube({level}, o);
}

// The descriptors KTX-Software makes for these formats (external/dfdutils
// at v5.0.0-rc2: vk2dfd.inl maps R16G16B16A16_SFLOAT to createDFDUnpacked(0,
// 4, 2, 0, s_SFLOAT), B10G11R11_UFLOAT_PACK32 to createDFDPacked(0, 3,
// {11, 11, 10}, {0, 1, 2}, s_UFLOAT) and E5B9G9R9_UFLOAT_PACK32 to the
// six-sample special case of createDFDPackedShifted; createdfd.c writes
// them), worked out by hand from that source and the Khronos Data Format
// Specification 1.3's layout: dfdTotalSize; vendorId 0 | descriptorType 0;
// versionNumber 2 (1.3) | descriptorBlockSize << 16; colorModel RGBSDA (1)
// | primaries BT709 (1) << 8 | transfer LINEAR (1) << 16 | flags
// ALPHA_STRAIGHT (0) << 24; texelBlockDimension 0 (1 x 1 x 1 x 1);
// bytesPlane0..3; bytesPlane4..7; then per sample: bitOffset | (bitLength -
// 1) << 16 | (channelId | qualifiers) << 24 with FLOAT 0x80, SIGNED 0x40,
// EXPONENT 0x20, alpha channel 15; samplePosition 0; sampleLower;
// sampleUpper.
std::vector<uint32_t> KtxSoftwareDfdWords(uint32_t vk_format) {
  const uint32_t kOne = 0x3F800000, kMinusOne = 0xBF800000;  // 1.0f, -1.0f
  const std::vector<uint32_t> rgba16f = {92,         0, 2 | (88 << 16), 0x00010101, 0, 8, 0,
                                         0xC00F0000, 0, kMinusOne,      kOne,   // R: 16 bits at 0, FLOAT | SIGNED
                                         0xC10F0010, 0, kMinusOne,      kOne,   // G: at 16
                                         0xC20F0020, 0, kMinusOne,      kOne,   // B: at 32
                                         0xCF0F0030, 0, kMinusOne,      kOne};  // A (15): at 48
  const std::vector<uint32_t> b10g11r11 = {76,         0,          2 | (72 << 16),
                                           0x00010101, 0,          4,
                                           0,          0x800A0000, 0,
                                           0,          kOne,  // R: 11 bits at 0, FLOAT, 0.0f to 1.0f
                                           0x810A000B, 0,          0,
                                           kOne,  // G: 11 bits at 11
                                           0x82090016, 0,          0,
                                           kOne};  // B: 10 bits at 22
  const std::vector<uint32_t> e5b9g9r9 = {124,        0,          2 | (120 << 16),
                                          0x00010101, 0,          4,
                                          0,          0x00080000, 0,
                                          0,          8448,  // R mantissa: 9 bits at 0, no qualifier, 0 to 8448
                                          0x2004001B, 0,          15,
                                          31,  // R exponent: 5 bits at 27, EXPONENT, 15 to 31
                                          0x01080009, 0,          0,
                                          8448,  // G mantissa at 9
                                          0x2104001B, 0,          15,
                                          31,  // G exponent
                                          0x02080012, 0,          0,
                                          8448,  // B mantissa at 18
                                          0x2204001B, 0,          15,
                                          31};  // B exponent
  return vk_format == 97 ? rgba16f : vk_format == 122 ? b10g11r11 : e5b9g9r9;
}

TEST(Ktx2Test, DataFormatDescriptorsAreKtxSoftwaresWordForWord) {
  for (int zstd : {0, 3}) {
    for (KtxFormat format : {KtxFormat::kRgba16f, KtxFormat::kB10g11r11, KtxFormat::kE5b9g9r9})
      EXPECT_EQ(DfdWords(TinyCube(format, zstd)), KtxSoftwareDfdWords(Ktx2VkFormat(format))) << Ktx2FormatName(format);
  }
}

// What the KTX 2.0 specification requires of a file of the kind skybake
// writes (2D or cube, one layer, an uncompressed VkFormat of 97, 122 or 123,
// no supercompression or zstd), written from its sections 3 (file
// structure), 3.10 (data format descriptor), 3.11 (key/value data) and 3.12
// (mip level data), independently of the writer; one line per rule broken.
std::vector<std::string> Ktx2Problems(const std::string& bytes) {
  std::vector<std::string> problems;
  auto check = [&](bool ok, const std::string& what) {
    if (!ok) problems.push_back(what);
    return ok;
  };
  static const char kIdentifier[12] = {'\xAB', 'K', 'T', 'X', ' ', '2', '0', '\xBB', '\r', '\n', '\x1A', '\n'};
  if (!check(bytes.size() >= 80 && std::memcmp(bytes.data(), kIdentifier, 12) == 0, "identifier")) return problems;
  const Ktx2Header h = ReadKtx2Header(bytes);
  // The format: texel block size, typeSize (the size of the unit of
  // endianness: 2 for 16-bit channels, 4 for packed 32-bit texels).
  const std::map<uint32_t, std::pair<uint32_t, uint32_t>> formats = {{97, {8, 2}}, {122, {4, 4}}, {123, {4, 4}}};
  if (!check(formats.count(h.vk_format) == 1, "vkFormat " + std::to_string(h.vk_format))) return problems;
  const auto [texel_bytes, type_size] = formats.at(h.vk_format);
  check(h.type_size == type_size, "typeSize");
  check(h.width > 0 && h.height > 0 && h.depth == 0 && h.layers == 0, "dimensions of a 2D texture");
  check(h.faces == 1 || (h.faces == 6 && h.width == h.height), "faceCount 1, or 6 with square faces");
  const uint32_t max_levels = 32 - uint32_t(__builtin_clz(std::max(h.width, h.height)));
  check(h.levels >= 1 && h.levels <= max_levels, "levelCount");
  check(h.supercompression == 0 || h.supercompression == 2, "supercompressionScheme");
  check(h.sgd_offset == 0 && h.sgd_length == 0, "no supercompression global data for scheme 0 or 2");
  if (!problems.empty()) return problems;

  // Index order: level index, DFD, key/value data, then the levels, each
  // region starting where the one before ends (plus the levels' padding).
  const size_t index_end = 80 + size_t(h.levels) * 24;
  check(h.dfd_offset == index_end, "dfdByteOffset right after the level index");
  check(h.dfd_offset % 4 == 0 && h.dfd_length % 4 == 0, "DFD 4-byte aligned");
  check(h.kvd_length == 0 ? h.kvd_offset == 0 : h.kvd_offset == h.dfd_offset + h.dfd_length,
        "kvdByteOffset right after the DFD");
  if (!check(h.dfd_offset + size_t(h.dfd_length) + h.kvd_length <= bytes.size(), "DFD and KVD inside the file"))
    return problems;

  // DFD: one basic block, whose size and samples agree with the VkFormat.
  const std::vector<uint32_t> dfd = DfdWords(bytes);
  check(dfd.size() >= 7 && dfd[0] == h.dfd_length, "dfdTotalSize = dfdByteLength");
  if (dfd.size() >= 7) {
    const uint32_t block_size = dfd[2] >> 16;
    check(dfd[1] == 0, "vendorId Khronos, descriptorType basic");
    check((dfd[2] & 0xFFFF) == 2, "versionNumber 2 (Data Format 1.3)");
    check(block_size == h.dfd_length - 4 && (block_size - 24) % 16 == 0, "descriptorBlockSize");
    check((dfd[3] & 0xFF) == 1, "colorModel RGBSDA for an RGB VkFormat");
    check(dfd[4] == 0, "texel block 1 x 1 x 1 x 1");
    check(dfd[5] == texel_bytes && dfd[6] == 0, "bytesPlane0 the texel size, the others 0");
    // Samples: inside the texel, not overlapping, each channel's bits
    // covered once, no sample position (single-sample formats).
    std::vector<int> bit_owner(texel_bytes * 8, -1);
    for (size_t i = 7; i + 4 <= dfd.size(); i += 4) {
      const uint32_t offset = dfd[i] & 0xFFFF, length = ((dfd[i] >> 16) & 0xFF) + 1;
      const uint32_t channel = (dfd[i] >> 24) & 0x0F, qualifiers = dfd[i] >> 24 & 0xF0;
      check(dfd[i + 1] == 0, "sample position 0");
      if (!check(offset + length <= texel_bytes * 8, "sample inside the texel")) continue;
      for (uint32_t b = offset; b < offset + length; ++b) {
        // The shared exponent is one field that several channels' samples name.
        if (bit_owner[b] >= 0 && !(qualifiers & 0x20)) check(false, "samples overlap at bit " + std::to_string(b));
        bit_owner[b] = int(channel);
      }
      check(channel <= 2 || channel == 15, "channel R, G, B or A");
    }
    check(std::count(bit_owner.begin(), bit_owner.end(), -1) == 0, "every bit of the texel described");
  }

  // Key/value data: entries sorted by key, unique, each key and value
  // NUL-terminated and valid, padding zero; KTXorientation of a 2D texture
  // is two letters [rl][du]; KTXwriter present.
  std::map<std::string, std::string> kvd;
  std::string previous_key;
  for (size_t at = h.kvd_offset, end = size_t(h.kvd_offset) + h.kvd_length; at < end;) {
    if (!check(at + 4 <= end, "KVD entry length")) break;
    const uint32_t length = Word32(bytes, at);
    if (!check(length >= 2 && at + 4 + length <= end, "keyAndValueByteLength")) break;
    const std::string entry = bytes.substr(at + 4, length);
    const size_t nul = entry.find('\0');
    if (!check(nul != std::string::npos && nul > 0, "key NUL-terminated, not empty")) break;
    const std::string key = entry.substr(0, nul);
    std::string value = entry.substr(nul + 1);
    check(key > previous_key, "keys sorted and unique (" + key + ")");
    previous_key = key;
    check(!value.empty() && value.back() == '\0', key + ": value NUL-terminated");
    if (!value.empty() && value.back() == '\0') value.pop_back();
    kvd[key] = value;
    at += 4 + length;
    const size_t padded = (at + 3) / 4 * 4;
    for (; at < padded; ++at) check(at < end && bytes[at] == '\0', "KVD padding zero and inside kvdByteLength");
  }
  check(kvd.count("KTXwriter") == 1, "KTXwriter");
  check(kvd.count("KTXorientation") == 1 && kvd["KTXorientation"].size() == 2 &&
            std::strchr("rl", kvd["KTXorientation"][0]) && std::strchr("du", kvd["KTXorientation"][1]),
        "KTXorientation of a 2D texture");

  // Levels: the index lists level 0 (largest) first; the data stores the
  // smallest first, back to back, each level aligned to lcm(texel size, 4)
  // without supercompression (1 with), the first right after the KVD; an
  // uncompressed level holds width x height x faces texels, and a zstd
  // level decompresses to exactly uncompressedByteLength.
  const size_t alignment = h.supercompression == 0 ? std::lcm(size_t(texel_bytes), size_t(4)) : 1;
  size_t expected_offset = size_t(h.kvd_offset ? h.kvd_offset + h.kvd_length : h.dfd_offset + h.dfd_length);
  for (uint32_t level = h.levels; level-- > 0;) {
    const size_t at = 80 + size_t(level) * 24;
    const uint64_t offset = Word64(bytes, at), length = Word64(bytes, at + 8), raw = Word64(bytes, at + 16);
    const std::string name = "level " + std::to_string(level);
    expected_offset = (expected_offset + alignment - 1) / alignment * alignment;
    check(offset == expected_offset, name + ": byteOffset");
    const uint64_t texels = uint64_t(std::max(1u, h.width >> level)) * std::max(1u, h.height >> level) * h.faces;
    check(raw == texels * texel_bytes, name + ": uncompressedByteLength");
    if (!check(offset + length <= bytes.size(), name + ": inside the file")) break;
    if (h.supercompression == 0) {
      check(length == raw, name + ": byteLength = uncompressedByteLength");
    } else {
      std::string decoded(raw, '\0');
      const size_t n = ZSTD_decompress(decoded.data(), decoded.size(), bytes.data() + offset, length);
      check(!ZSTD_isError(n) && n == raw, name + ": zstd data decompresses to uncompressedByteLength");
    }
    expected_offset = offset + length;
  }
  check(expected_offset == bytes.size(), "the file ends with level 0's data");
  return problems;
}

TEST(Ktx2Test, ConformanceReaderCatchesBrokenFiles) {
  const std::string good = TinyCube(KtxFormat::kE5b9g9r9);
  EXPECT_EQ(Ktx2Problems(good), std::vector<std::string>{});
  EXPECT_EQ(Ktx2Problems(TinyCube(KtxFormat::kRgba16f, 3)), std::vector<std::string>{});
  // One byte changed in each place the reader checks: it says so.
  auto broken = [&](size_t at, char value) {
    std::string b = good;
    b[at] = value;
    return Ktx2Problems(b);
  };
  EXPECT_FALSE(broken(16, 2).empty());                                          // typeSize
  EXPECT_FALSE(broken(ReadKtx2Header(good).dfd_offset + 20, 8).empty());        // bytesPlane0
  EXPECT_FALSE(broken(ReadKtx2Header(good).dfd_offset + 28 + 4, 1).empty());    // sample position
  EXPECT_FALSE(broken(ReadKtx2Header(good).kvd_offset + 4, 'a').empty());       // key order
  EXPECT_FALSE(broken(80, char(ReadKtx2Header(good).dfd_offset + 1)).empty());  // level offset
  EXPECT_FALSE(Ktx2Problems(good + "x").empty());                               // trailing bytes
}

struct Level {
  int width = 0, height = 0;
  std::vector<float> rgb;  // rows from the top, faces stacked
};
Level ReadExr(const std::string& path) {
  Level level;
  testing::ReadRgb(path, level.width, level.height, level.rgb);
  return level;
}

// One bake per format; zstd on the second. Every KTX2 file against the EXRs.
class Ktx2BakeTest : public ::testing::TestWithParam<std::tuple<std::string, int>> {};

TEST_P(Ktx2BakeTest, EveryTexelMatchesTheExr) {
  const auto [format, zstd] = GetParam();
  const std::string dir = testing::FreshTempDir("ktx2_" + format + std::to_string(zstd));
  testing::CommandRun r = testing::RunSkybake(
      "bake " + testing::SourceDir() +
      "/configs/default.toml --size 16 --set render.latlong_height=16 -q --set gltf.enabled=false "
      "--set ibl.size=32 --set ibl.specular=true --set ibl.irradiance=true --set ibl.irradiance_size=8 "
      "--set ibl.dfg_lut=true --set ibl.dfg_size=16 --set ibl.ktx2=true --set ibl.ktx2_format=" +
      format + " --set ibl.ktx2_zstd_level=" + std::to_string(zstd) + " --out " + dir);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const uint32_t vk_format = format == "rgba16f" ? 97 : format == "b10g11r11" ? 122 : 123;
  struct File {
    std::string ktx2;
    std::vector<std::string> exrs;
    int faces;
    uint32_t vk_format;
    int size;  // level 0's width
  };
  for (const File& f : std::vector<File>{{"sky_specular.ktx2",
                                          {"sky_specular_m0.exr", "sky_specular_m1.exr", "sky_specular_m2.exr"},
                                          6,
                                          vk_format,
                                          32},
                                         {"sky_irradiance.ktx2", {"sky_irradiance.exr"}, 6, vk_format, 8},
                                         {"sky_dfg.ktx2", {"sky_dfg.exr"}, 1, 97, 16}}) {
    SCOPED_TRACE(f.ktx2);
    const std::string bytes = testing::ReadFileBytes(dir + "/" + f.ktx2);
    EXPECT_EQ(Ktx2Problems(bytes), std::vector<std::string>{});
    EXPECT_EQ(DfdWords(bytes), KtxSoftwareDfdWords(f.vk_format));
    const std::string prefix = dir + "/dump_" + f.ktx2;
    auto [status, output] = RunCommand("cd '" + testing::SourceDir() + "/tests/viewer' && node ktx2_dump.mjs '" + dir +
                                       "/" + f.ktx2 + "' '" + prefix + "'");
    ASSERT_EQ(status, 0) << output;
    json k = json::parse(output);
    EXPECT_EQ(k["vkFormat"], f.vk_format);
    EXPECT_EQ(k["typeSize"], f.vk_format == 97 ? 2 : 4);
    EXPECT_EQ(k["faceCount"], f.faces);
    EXPECT_EQ(k["levelCount"], f.exrs.size());
    EXPECT_EQ(k["supercompressionScheme"], zstd > 0 ? 2 : 0);
    EXPECT_EQ(k["keyValue"]["KTXorientation"], "rd");
    EXPECT_EQ(k["keyValue"]["KTXwriter"], std::string("skybake ") + SKYBAKE_VERSION);
    EXPECT_TRUE(k["rewrittenIdentical"]) << "ktx-parse writes the container back with other bytes";
    const json& dfd = k["dfd"][0];
    EXPECT_EQ(dfd["colorModel"], 1);        // KHR_DF_MODEL_RGBSDA
    EXPECT_EQ(dfd["colorPrimaries"], 1);    // KHR_DF_PRIMARIES_BT709
    EXPECT_EQ(dfd["transferFunction"], 1);  // KHR_DF_TRANSFER_LINEAR
    EXPECT_EQ(dfd["bytesPlane"][0], f.vk_format == 97 ? 8 : 4);
    if (f.ktx2 == "sky_specular.ktx2") {
      EXPECT_NE(k["keyValue"]["skybake:ibl"].get<std::string>().find("roughness"), std::string::npos);
    }
    // The cube files carry the bake's scale, as the EXRs do.
    if (f.faces == 6) {
      EXPECT_FALSE(k["keyValue"]["skybake:scale"].get<std::string>().empty());
    }
    for (size_t level = 0; level < f.exrs.size(); ++level) {
      Level exr = ReadExr(dir + "/" + f.exrs[level]);
      const std::string data = testing::ReadFileBytes(prefix + ".level" + std::to_string(level));
      const size_t texels = size_t(exr.width) * exr.height;
      ASSERT_EQ(data.size(), texels * (f.vk_format == 97 ? 8 : 4)) << "level " << level;
      EXPECT_EQ(k["levels"][level]["uncompressedByteLength"], data.size());
      EXPECT_EQ(exr.width, f.size >> level);
      EXPECT_EQ(exr.height, f.faces * (f.size >> level));
      for (size_t i = 0; i < texels; ++i) {
        std::array<float, 3> got;
        if (f.vk_format == 97) {
          for (int c = 0; c < 3; ++c) {
            Imath::half h;
            h.setBits(uint16_t(uint8_t(data[8 * i + 2 * c]) | (uint8_t(data[8 * i + 2 * c + 1]) << 8)));
            got[c] = float(h);
          }
        } else {
          uint32_t v = 0;
          for (int b = 0; b < 4; ++b) v |= uint32_t(uint8_t(data[4 * i + b])) << (8 * b);
          got = f.vk_format == 122 ? DecodeB10G11R11(v) : DecodeE5B9G9R9(v);
        }
        const float* want = &exr.rgb[3 * i];
        const float max_want = std::max({want[0], want[1], want[2]});
        for (int c = 0; c < 3; ++c) {
          // The EXR holds half values of the same scaled texels: equal for
          // rgba16f; within half an ulp of the packed format plus the
          // EXR's own half rounding (2^-11) otherwise.
          double tolerance = f.vk_format == 97    ? 0.0
                             : f.vk_format == 122 ? (c == 2 ? 1.0 / 64 : 1.0 / 128) * want[c] + 1e-3 * want[c]
                                                  : max_want / 512.0 + 1e-3 * want[c];
          double error = std::abs(double(got[c]) - double(want[c]));
          EXPECT_LE(error, tolerance) << "level " << level << " texel " << i << " channel " << c;
        }
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Formats, Ktx2BakeTest,
                         ::testing::Values(std::make_tuple("rgba16f", 0), std::make_tuple("rgba16f", 3),
                                           std::make_tuple("b10g11r11", 0), std::make_tuple("e5b9g9r9", 5)));

}  // namespace
}  // namespace skybake
