// KTX2 files (ktx2.h): the packed encodings against hand-worked values, the
// range refused, and every file of an IBL bake read back by an independent
// reader, the npm package ktx-parse (tests/viewer/ktx2_dump.mjs): header,
// orientation and colour metadata, data format descriptor, the container
// written back by ktx-parse byte-identical, and every texel of every level
// against the EXR of the same level.
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <sys/wait.h>

#include <Imath/half.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

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
      "--set ibl.dfg_lut=true --set ibl.dfg_size=16 --set ibl.ktx2=true --set ibl.ktx2_format=" + format +
      " --set ibl.ktx2_zstd_level=" + std::to_string(zstd) + " --out " + dir);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const uint32_t vk_format = format == "rgba16f" ? 97 : format == "b10g11r11" ? 122 : 123;
  struct File {
    std::string ktx2;
    std::vector<std::string> exrs;
    int faces;
    uint32_t vk_format;
    int size;  // level 0's width
  };
  for (const File& f : std::vector<File>{
           {"sky_specular.ktx2", {"sky_specular_m0.exr", "sky_specular_m1.exr", "sky_specular_m2.exr"}, 6, vk_format, 32},
           {"sky_irradiance.ktx2", {"sky_irradiance.exr"}, 6, vk_format, 8},
           {"sky_dfg.ktx2", {"sky_dfg.exr"}, 1, 97, 16}}) {
    SCOPED_TRACE(f.ktx2);
    const std::string prefix = dir + "/dump_" + f.ktx2;
    auto [status, output] = RunCommand("cd '" + testing::SourceDir() + "/tests/viewer' && node ktx2_dump.mjs '" +
                                       dir + "/" + f.ktx2 + "' '" + prefix + "'");
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
