// EXR writing: half-range policy, never Inf/NaN, attributes an independent
// reader (OpenImageIO) sees, and atomic replacement.
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>
#include <OpenImageIO/imageio.h>

#include "skybake/exr_io.h"
#include "skybake/tonemap.h"

namespace skybake {
namespace {

std::string TempDir() {
  auto dir = std::filesystem::temp_directory_path() / ("skybake_exr_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir.string();
}

RgbaImage Ramp(int w, int h, float top) {
  RgbaImage image{w, h, std::vector<float>(size_t(w) * h * 4, 1.0f)};
  for (size_t i = 0; i < size_t(w) * h; ++i)
    for (int c = 0; c < 3; ++c) image.rgba[4 * i + c] = top * float(i + 1) / float(w * h) / float(c + 1);
  return image;
}

TEST(ExrIoTest, HalfRangeScaleIsAPowerOfTwoThatFits) {
  EXPECT_EQ(HalfRangeScale(1.0, OverflowPolicy::kScale), 1.0);
  EXPECT_EQ(HalfRangeScale(kHalfMax, OverflowPolicy::kScale), 1.0);
  for (double v : {65505.0, 1e6, 1.6e9, 3e38}) {
    double s = HalfRangeScale(v, OverflowPolicy::kScale);
    EXPECT_LE(v * s, kHalfMax) << v;
    EXPECT_GT(v * s * 2.0, kHalfMax) << v;  // the largest power of two that fits
    EXPECT_EQ(std::exp2(std::round(std::log2(s))), s);
  }
  EXPECT_THROW(HalfRangeScale(1e5, OverflowPolicy::kRefuse), OutputError);
}

TEST(ExrIoTest, CheckedMaxRefusesNonFiniteAndNegative) {
  RgbaImage image = Ramp(4, 2, 10.0f);
  EXPECT_FLOAT_EQ(float(CheckedMaxValue({&image})), 10.0f);
  image.rgba[5] = std::nanf("");
  EXPECT_THROW(CheckedMaxValue({&image}), OutputError);
  image.rgba[5] = INFINITY;
  EXPECT_THROW(CheckedMaxValue({&image}), OutputError);
  image.rgba[5] = -1.0f;
  EXPECT_THROW(CheckedMaxValue({&image}), OutputError);
}

TEST(ExrIoTest, WritesHalfWithScaleAndAttributesReadableByOpenImageIO) {
  std::string dir = TempDir();
  RgbaImage image = Ramp(16, 8, 2.0e9f);  // a sun-disc-like maximum
  double scale = HalfRangeScale(CheckedMaxValue({&image}), OverflowPolicy::kScale);
  ExrWriteOptions options;
  options.envmap = 0;
  options.scale = scale;
  options.white_luminance = 1.0 / scale;
  options.attributes["skybake:version"] = "test";
  std::string path = dir + "/ramp.exr";
  EXPECT_GT(WriteExr(path, image, options), 0u);

  auto in = OIIO::ImageInput::open(path);
  ASSERT_TRUE(in) << OIIO::geterror();
  const OIIO::ImageSpec& spec = in->spec();
  EXPECT_EQ(spec.width, 16);
  EXPECT_EQ(spec.height, 8);
  ASSERT_EQ(spec.nchannels, 3);
  EXPECT_EQ(spec.format, OIIO::TypeDesc::HALF);
  // OpenImageIO reports the OpenEXR envmap attribute as its textureformat.
  EXPECT_EQ(spec.get_string_attribute("textureformat"), "LatLong Environment");
  std::vector<float> pixels(16 * 8 * 3);
  ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, pixels.data()));
  for (size_t i = 0; i < 16 * 8; ++i) {
    for (int c = 0; c < 3; ++c) {
      float v = pixels[3 * i + c];
      ASSERT_TRUE(std::isfinite(v));
      float expected = float(image.rgba[4 * i + c] * scale);
      EXPECT_NEAR(v, expected, std::max(1e-3f * expected, 6e-8f));  // half: 11-bit mantissa
    }
  }
  EXPECT_EQ(spec.get_string_attribute("skybake:version"), "test");
  EXPECT_NEAR(spec.get_float_attribute("whiteLuminance"), 1.0 / scale, 1e-3 / scale);
  in->close();
  // No temporary file is left behind.
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos) << entry.path();
  std::filesystem::remove_all(dir);
}

TEST(ExrIoTest, RefuseLeavesNoFile) {
  RgbaImage image = Ramp(4, 4, 1e6f);
  EXPECT_THROW(HalfRangeScale(CheckedMaxValue({&image}), OverflowPolicy::kRefuse), OutputError);
}

TEST(ExrIoTest, WriteIntoMissingFolderFailsCleanly) {
  RgbaImage image = Ramp(4, 4, 1.0f);
  EXPECT_THROW(WriteExr("/nonexistent-skybake-dir/x.exr", image, ExrWriteOptions{}), OutputError);
}

TEST(TonemapTest, AcesAndSrgbKnownValues) {
  EXPECT_NEAR(AcesFilmic(0.0), 0.0, 1e-12);
  EXPECT_NEAR(AcesFilmic(1e6), 1.0, 1e-3);
  EXPECT_NEAR(SrgbEncode(0.0031308), 0.04045, 1e-5);
  EXPECT_NEAR(SrgbEncode(1.0), 1.0, 1e-12);
  // Auto exposure maps a uniform sky to mid grey.
  std::vector<float> uniform(64 * 32 * 4, 5000.0f);
  double ev = AutoEv100(uniform, 64, 32);
  EXPECT_NEAR(5000.0 * ExposureFromEv100(ev), 0.18, 1e-9);
}

}  // namespace
}  // namespace skybake
