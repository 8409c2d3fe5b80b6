// The maps' colour spaces (output.color_space, ocio_color_space.h) with
// OpenColorIO (Debian's 2.1) as the authority:
// - each built-in space's matrix from linear Rec.709 is the one
//   OpenColorIO's built-in transforms give;
// - a bake in each space (and in a space of an OpenColorIO config), its EXR
//   converted back to linear Rec.709 by OpenColorIO, is the Rec.709 bake to
//   half-float precision, and OpenImageIO reads its chromaticities back;
// - a name that is neither built in nor in the config, or a space that is
//   not linear, is refused with the names there are, before any GPU work.
#include <cmath>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include <OpenColorIO/OpenColorIO.h>
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include "skybake/input/ocio_color_space.h"
#include "skybake/model/spectrum.h"
#include "test_support.h"

namespace skybake {
namespace {

namespace OCIO = OCIO_NAMESPACE;

std::string TestConfig() { return testing::SourceDir() + "/tests/colour/ocio/test_config.ocio"; }

OCIO::TransformRcPtr Builtin(const char* style, OCIO::TransformDirection direction = OCIO::TRANSFORM_DIR_FORWARD) {
  OCIO::BuiltinTransformRcPtr t = OCIO::BuiltinTransform::Create();
  t->setStyle(style);
  t->setDirection(direction);
  return t;
}

// OpenColorIO's own way from a built-in space (or a config space, through the
// config's aces_interchange role) to linear Rec.709: ACES AP1 to Rec.709
// (Bradford) at the end of each chain.
OCIO::ConstCPUProcessorRcPtr ToRec709(const std::string& space) {
  OCIO::GroupTransformRcPtr group = OCIO::GroupTransform::Create();
  const auto inverse = OCIO::TRANSFORM_DIR_INVERSE;
  if (space == "acescg") {
  } else if (space == "aces2065-1") {
    group->appendTransform(Builtin("ACEScg_to_ACES2065-1", inverse));
  } else if (space == "xyz") {
    group->appendTransform(Builtin("UTILITY - ACES-AP1_to_CIE-XYZ-D65_BFD", inverse));
  } else if (space == "rec2020") {
    // OpenColorIO 2.1 has no linear Rec.2020 built-in: its Rec.2020 display
    // (Rec.1886, a pure 2.4 power with a black of 0) undone.
    OCIO::ExponentTransformRcPtr gamma = OCIO::ExponentTransform::Create();
    const double power[4] = {2.4, 2.4, 2.4, 1.0};
    gamma->setValue(power);
    gamma->setDirection(inverse);  // linear -> encoded
    group->appendTransform(gamma);
    group->appendTransform(Builtin("DISPLAY - CIE-XYZ-D65_to_REC.1886-REC.2020", inverse));
    group->appendTransform(Builtin("UTILITY - ACES-AP1_to_CIE-XYZ-D65_BFD", inverse));
  } else {
    OCIO::ColorSpaceTransformRcPtr to_aces = OCIO::ColorSpaceTransform::Create();
    to_aces->setSrc(space.c_str());
    to_aces->setDst("aces_interchange");
    group->appendTransform(to_aces);
    group->appendTransform(Builtin("ACEScg_to_ACES2065-1", inverse));
  }
  group->appendTransform(Builtin("UTILITY - ACES-AP1_to_LINEAR-REC709_BFD"));
  OCIO::ConstConfigRcPtr config = space == "acescg" || space == "aces2065-1" || space == "xyz" || space == "rec2020"
                                      ? OCIO::Config::CreateRaw()
                                      : OCIO::Config::CreateFromFile(TestConfig().c_str());
  return config->getProcessor(group)->getDefaultCPUProcessor();
}

// Each built-in matrix against OpenColorIO on colours in Rec.709's gamut
// (the Rec.2020 display path clamps what is outside its own).
TEST(OcioColorSpace, BuiltinMatricesAreOpenColorIOs) {
  const std::vector<std::array<double, 3>> colours = {{1, 0, 0},          {0, 1, 0},       {0, 0, 1},      {1, 1, 1},
                                                      {0.18, 0.18, 0.18}, {0.9, 0.5, 0.1}, {0.2, 0.4, 0.8}};
  for (const NamedColorSpace& n : BuiltinColorSpaces()) {
    if (n.space == ColorSpace::kRec709) continue;
    const OCIO::ConstCPUProcessorRcPtr back = ToRec709(n.name);
    const Matrix3 m = Rec709To(n.space);
    double worst = 0.0;
    for (const auto& c : colours) {
      const std::array<double, 3> ours = Apply(m, c);
      float pixel[3] = {float(ours[0]), float(ours[1]), float(ours[2])};
      back->applyRGB(pixel);
      for (int i = 0; i < 3; ++i) worst = std::max(worst, std::abs(pixel[i] - c[i]));
    }
    std::printf("%-10s Rec.709 -> space (skybake) -> Rec.709 (OpenColorIO): worst %.2e\n", n.name, worst);
    EXPECT_LT(worst, 2e-4) << n.name;
  }
}

// A config space resolves through OpenColorIO: linear Display P3's primaries
// and white come back as its definition's.
TEST(OcioColorSpace, ConfigSpaceHasItsPrimaries) {
  const ColorSpaceLookup p3 = ResolveOutputColorSpace("Linear P3-D65", TestConfig());
  ASSERT_TRUE(p3.space) << p3.error;
  const double want[4][2] = {{0.680, 0.320}, {0.265, 0.690}, {0.150, 0.060}, {0.3127, 0.3290}};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 2; ++j) EXPECT_NEAR(p3.space->chromaticities[i][j], want[i][j], 2e-4) << i << j;
  // ACEScg of the config is the built-in ACEScg's matrix.
  const ColorSpaceLookup cg = ResolveOutputColorSpace("ACEScg", TestConfig());
  ASSERT_TRUE(cg.space) << cg.error;
  const Matrix3 builtin = Rec709To(ColorSpace::kAcesCg);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(cg.space->from_rec709[i][j], builtin[i][j], 2e-5) << i << j;
}

struct Map {
  int width = 0, height = 0;
  std::vector<float> rgb;
  std::vector<float> chromaticities;
  std::string color_space;
};

Map ReadMap(const std::string& path) {
  Map m;
  auto in = OIIO::ImageInput::open(path);
  if (!in) return m;
  const OIIO::ImageSpec& spec = in->spec();
  m.width = spec.width;
  m.height = spec.height;
  m.rgb.resize(size_t(spec.width) * spec.height * 3);
  in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, m.rgb.data());
  if (const OIIO::ParamValue* p = spec.find_attribute("chromaticities"); p && p->type().numelements() == 8) {
    const float* v = static_cast<const float*>(p->data());
    m.chromaticities.assign(v, v + 8);
  }
  m.color_space = spec.get_string_attribute("skybake:color_space");
  return m;
}

std::string Bake(const std::string& space, const std::string& dir, const std::string& extra = "") {
  const std::string out = dir + "/" + std::to_string(std::hash<std::string>()(space));
  const testing::CommandRun r = testing::RunSkybake(
      "bake " + testing::SourceDir() +
      "/configs/default.toml -q --size 16 --vulkan-validation --set output.faces=false "
      "--set output.cube_strip=false --set gltf.enabled=false --set output.preview=false --set 'output.color_space=\"" +
      space + "\"'" + extra + " --out " + out);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return out + "/sky_latlong.exr";
}

// Each space's half-float latlong, back to Rec.709 through OpenColorIO, is
// the Rec.709 bake's to half-float precision: within 2^-9 of the texel's
// brightest channel (two roundings of 2^-11 and the matrices' gain), and its
// chromaticities and name are the space's.
TEST(OcioColorSpace, EachSpaceBackToRec709IsTheRec709Bake) {
  const std::string dir = testing::FreshTempDir("ocio_spaces");
  const Map rec709 = ReadMap(Bake("rec709", dir));
  ASSERT_GT(rec709.width, 0);
  EXPECT_EQ(rec709.color_space, "rec709");
  std::vector<std::pair<std::string, ColorSpaceLookup>> spaces;
  for (const NamedColorSpace& n : BuiltinColorSpaces())
    if (n.space != ColorSpace::kRec709) spaces.push_back({n.name, ResolveOutputColorSpace(n.name, "")});
  spaces.push_back({"Linear P3-D65", ResolveOutputColorSpace("Linear P3-D65", TestConfig())});
  for (const auto& [name, lookup] : spaces) {
    SCOPED_TRACE(name);
    ASSERT_TRUE(lookup.space) << lookup.error;
    const std::string extra = name == "Linear P3-D65" ? " --set 'output.ocio_config=\"" + TestConfig() + "\"'" : "";
    const Map map = ReadMap(Bake(name, dir, extra));
    ASSERT_EQ(map.rgb.size(), rec709.rgb.size());
    EXPECT_EQ(map.color_space, name);
    ASSERT_EQ(map.chromaticities.size(), 8u) << "OpenImageIO reads no chromaticities";
    for (int i = 0; i < 8; ++i)
      EXPECT_NEAR(map.chromaticities[i], lookup.space->chromaticities[i / 2][i % 2], 1e-6) << i;
    const OCIO::ConstCPUProcessorRcPtr back = ToRec709(name);
    double worst = 0.0;
    for (size_t t = 0; t < map.rgb.size() / 3; ++t) {
      float pixel[3] = {map.rgb[3 * t], map.rgb[3 * t + 1], map.rgb[3 * t + 2]};
      back->applyRGB(pixel);
      const float* want = &rec709.rgb[3 * t];
      const double peak = std::max({std::abs(want[0]), std::abs(want[1]), std::abs(want[2])});
      for (int i = 0; i < 3; ++i) {
        const double e = std::abs(pixel[i] - want[i]) / std::max(peak, 1e-6);
        worst = std::max(worst, e);
        ASSERT_LE(e, 1.0 / 512.0) << "texel " << t << " channel " << i << ": " << pixel[i] << " vs " << want[i];
      }
    }
    std::printf("%-14s back to Rec.709 through OpenColorIO: worst %.2e of the texel's brightest channel\n",
                name.c_str(), worst);
  }
}

// The IBL maps follow the maps' space: their EXRs carry its chromaticities
// and name and hold the Rec.709 bake's radiance through its matrix; the
// KTX2 file's data format descriptor names its primaries (ACEScg: AP1,
// colorPrimaries 7) and its key/value data its name; the glTF's RGBD PNGs
// stay Rec.709 (byte-identical).
TEST(OcioColorSpace, IblFilesFollowTheMapsSpace) {
  const std::string dir = testing::FreshTempDir("ocio_ibl");
  const std::string ibl =
      " --set ibl.specular=true --set ibl.irradiance=true --set ibl.ktx2=true --set ibl.size=16 --set ibl.samples=16 "
      "--set gltf.image_based_light=true --set 'output.pixel_type=\"float\"'";
  std::map<std::string, std::string> out;
  for (const std::string space : {"rec709", "acescg"}) {
    out[space] = dir + "/" + space;
    const testing::CommandRun r =
        testing::RunSkybake("bake " + testing::SourceDir() +
                            "/configs/default.toml -q --size 16 --vulkan-validation --set "
                            "output.faces=false --set output.cube_strip=false --set 'output.color_space=\"" +
                            space + "\"'" + ibl + " --out " + out[space]);
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  const Map rec = ReadMap(out["rec709"] + "/sky_irradiance.exr");
  const Map cg = ReadMap(out["acescg"] + "/sky_irradiance.exr");
  ASSERT_GT(rec.width, 0);
  ASSERT_EQ(rec.rgb.size(), cg.rgb.size());
  EXPECT_EQ(rec.color_space, "rec709");
  EXPECT_EQ(cg.color_space, "acescg");
  ASSERT_EQ(cg.chromaticities.size(), 8u);
  EXPECT_FLOAT_EQ(cg.chromaticities[0], 0.713f);
  EXPECT_FLOAT_EQ(cg.chromaticities[7], 0.33767f);
  const Matrix3 m = Rec709To(ColorSpace::kAcesCg);
  for (size_t t = 0; t < rec.rgb.size() / 3; ++t)
    for (int i = 0; i < 3; ++i) {
      const double want = m[i][0] * rec.rgb[3 * t] + m[i][1] * rec.rgb[3 * t + 1] + m[i][2] * rec.rgb[3 * t + 2];
      ASSERT_NEAR(cg.rgb[3 * t + i], want, 1e-5 * std::abs(want) + 1e-9) << "texel " << t;
    }
  // KTX2: the DFD's colorPrimaries byte (header 48 bytes, then dfdByteOffset;
  // in the DFD: dfdTotalSize, two words, then colorModel, colorPrimaries).
  for (const auto& [space, primaries] : std::vector<std::pair<std::string, int>>{{"rec709", 1}, {"acescg", 7}}) {
    const std::string ktx = testing::ReadFileBytes(out[space] + "/sky_specular.ktx2");
    ASSERT_GT(ktx.size(), 80u);
    uint32_t dfd = 0;
    std::memcpy(&dfd, ktx.data() + 48, 4);
    EXPECT_EQ(int(uint8_t(ktx[dfd + 13])), primaries) << space;
    EXPECT_NE(ktx.find(std::string("skybake:color_space") + '\0' + space), std::string::npos) << space;
  }
  for (const char* face : {"px", "nz"}) {
    const std::string png = std::string("/sky_specular_m0_") + face + ".png";
    EXPECT_EQ(testing::ReadFileBytes(out["rec709"] + png), testing::ReadFileBytes(out["acescg"] + png)) << png;
  }
}

// Names that are not spaces, and a space that is not linear: exit 3 before
// any GPU work, with the names to choose from; $OCIO names the config when
// no key does.
TEST(OcioColorSpace, UnknownOrNonLinearSpacesAreRefusedWithTheNames) {
  const std::string style = testing::SourceDir() + "/configs/default.toml";
  testing::CommandRun r = testing::RunSkybake("check " + style + " --set 'output.color_space=\"p3\"'");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("output.color_space"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("'rec709', 'acescg', 'aces2065-1', 'rec2020', 'xyz'"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("output.ocio_config"), std::string::npos) << r.output;

  r = testing::RunSkybake("check " + style + " --set 'output.color_space=\"P3\"' --set 'output.ocio_config=\"" +
                          TestConfig() + "\"'");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("'Linear P3-D65'"), std::string::npos) << "the config's names: " << r.output;

  r = testing::RunSkybake("check " + style +
                          " --set 'output.color_space=\"Gamma 2.2 ACEScg\"' --set "
                          "'output.ocio_config=\"" +
                          TestConfig() + "\"'");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("not a linear space"), std::string::npos) << r.output;

  r = testing::RunSkybake("check " + style +
                          " --set 'output.color_space=\"Linear P3-D65\"' --set "
                          "'output.ocio_config=\"/nonexistent/config.ocio\"'");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("cannot be read"), std::string::npos) << r.output;
  // A device is not read (it would never end).
  r = testing::RunSkybake("check " + style +
                          " --set 'output.color_space=\"Linear P3-D65\"' --set "
                          "'output.ocio_config=\"/dev/zero\"'");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("not a regular file"), std::string::npos) << r.output;

  r = testing::RunSkybake("check " + style + " --set 'output.color_space=\"Linear P3-D65\"'",
                          "OCIO='" + TestConfig() + "' ");
  EXPECT_EQ(r.exit_code, 0) << "$OCIO names the config: " << r.output;
}

}  // namespace
}  // namespace skybake
