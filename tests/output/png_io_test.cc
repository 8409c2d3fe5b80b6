// PNG encoding (png_io.h): libpng directly, no OpenImageIO. The pixels
// OpenImageIO decodes from the file are the ones given, the chunks are the
// ones documented (sRGB with gAMA and cHRM, Software, no time stamp), the
// same pixels give the same bytes; and a bake writes its preview PNG and
// its glTF scene without loading OpenImageIO.
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include "skybake/base/errors.h"
#include "skybake/output/png_io.h"
#include "test_support.h"

namespace skybake {
namespace {

// The chunk types of a PNG, in file order.
std::vector<std::string> ChunkTypes(const std::string& png) {
  std::vector<std::string> types;
  size_t at = 8;
  while (at + 12 <= png.size()) {
    const uint32_t length = uint32_t(uint8_t(png[at])) << 24 | uint32_t(uint8_t(png[at + 1])) << 16 |
                            uint32_t(uint8_t(png[at + 2])) << 8 | uint32_t(uint8_t(png[at + 3]));
    types.push_back(png.substr(at + 4, 4));
    at += 12 + length;
  }
  return types;
}

TEST(PngIoTest, OpenImageIODecodesThePixelsGiven) {
  const int width = 67, height = 13;  // odd sizes: no row padding hides an error
  std::vector<uint8_t> rgb(size_t(width) * height * 3);
  for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = uint8_t((i * 131 + i / 7) & 0xff);
  const std::string png = EncodePngRgb8(width, height, rgb);
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_EQ(EncodePngRgb8(width, height, rgb), png) << "the same pixels, the same bytes";

  const std::string path = testing::FreshTempDir("png_io") + "/pixels.png";
  testing::WriteFile(std::filesystem::path(path).parent_path().string(), "pixels.png", png);
  auto in = OIIO::ImageInput::open(path);
  ASSERT_TRUE(in) << OIIO::geterror();
  EXPECT_EQ(in->spec().width, width);
  EXPECT_EQ(in->spec().height, height);
  EXPECT_EQ(in->spec().nchannels, 3);
  std::vector<uint8_t> decoded(rgb.size());
  ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, decoded.data()));
  EXPECT_EQ(decoded, rgb);

  const std::vector<std::string> chunks = ChunkTypes(png);
  auto has = [&](const char* type) { return std::find(chunks.begin(), chunks.end(), type) != chunks.end(); };
  std::string listed;
  for (const std::string& type : chunks) listed += type + " ";
  EXPECT_TRUE(has("sRGB") && has("gAMA") && has("cHRM") && has("tEXt") && has("IDAT")) << listed;
  EXPECT_FALSE(has("tIME")) << "no time stamp";
  EXPECT_NE(png.find(std::string("Software\0skybake ", 17)), std::string::npos);
}

TEST(PngIoTest, PixelsThatDoNotFitTheSizeAreRefused) {
  EXPECT_THROW(EncodePngRgb8(4, 4, std::vector<uint8_t>(47)), OutputError);
  EXPECT_THROW(EncodePngRgb8(0, 4, {}), OutputError);
}

// A bake writes its PNG preview and its glTF scene (whose texture is that
// PNG) without loading OpenImageIO: the dynamic loader's log of the files
// it opens (LD_DEBUG=files) names the Vulkan loader and no OpenImageIO
// module or library. (A bake that wrote its PNGs through the module named
// libskybake_oiio.so and libOpenImageIO there.)
TEST(PngIoTest, ABakeWritesItsPngsWithoutOpenImageIO) {
  const std::string dir = testing::FreshTempDir("png_io_bake");
  testing::CommandRun r = testing::RunSkybake(
      "bake '" + testing::SourceDir() + "/configs/default.toml' --size 16 -q --vulkan-validation --out '" + dir + "'",
      "LD_DEBUG=files");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("libvulkan.so"), std::string::npos) << "no loader log:\n" << r.output;
  EXPECT_EQ(r.output.find("libskybake_oiio"), std::string::npos) << "the OpenImageIO module was loaded";
  EXPECT_EQ(r.output.find("libOpenImageIO"), std::string::npos) << "OpenImageIO was loaded";
  for (const char* file : {"sky_latlong.png", "sky.glb", "sky.gltf"})
    EXPECT_TRUE(std::filesystem::is_regular_file(dir + "/" + file)) << file;
  int width = 0, height = 0;
  std::vector<unsigned char> pixels;
  ASSERT_TRUE(testing::ReadRgb(dir + "/sky_latlong.png", width, height, pixels));
  EXPECT_EQ(width, 32);
  EXPECT_EQ(height, 16);
}

}  // namespace
}  // namespace skybake
