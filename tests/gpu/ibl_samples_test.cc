// Per-level GGX sample counts (ibl.full_samples_roughness, IblLevelSamples):
// the count grows with roughness up to ibl.samples, at least 16; off (0, the
// default) every level has ibl.samples and the key is not recorded (the
// files are the bytes of a bake without it); on, `skybake plan` and each
// level's EXR name the level's count. docs/performance.md measures time and
// error at 512.
#include <string>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include "skybake/input/config.h"
#include "skybake/gpu/ibl.h"
#include "test_support.h"

namespace skybake {
namespace {

TEST(IblSamplesTest, CountGrowsWithRoughnessUpToTheSetting) {
  IblSettings s;
  s.samples = 256;
  EXPECT_EQ(IblLevelSamples(s, 1.0 / 6.0), 256) << "off by default";
  s.full_samples_roughness = 0.5;
  EXPECT_EQ(IblLevelSamples(s, 1.0 / 6.0), 86);   // ceil(256 / 3)
  EXPECT_EQ(IblLevelSamples(s, 2.0 / 6.0), 171);  // ceil(512 / 3)
  EXPECT_EQ(IblLevelSamples(s, 0.5), 256);
  EXPECT_EQ(IblLevelSamples(s, 1.0), 256);
  EXPECT_EQ(IblLevelSamples(s, 0.001), 16) << "at least 16";
  s.samples = 8;
  EXPECT_EQ(IblLevelSamples(s, 0.001), 8) << "never above ibl.samples";
}

std::string Style() { return testing::SourceDir() + "/configs/default.toml"; }

TEST(IblSamplesTest, PlanAndFilesNameEachLevelsCount) {
  testing::CommandRun plan = testing::RunSkybake("plan " + Style() +
                                                 " --set ibl.specular=true --set ibl.size=512 "
                                                 "--set ibl.full_samples_roughness=0.5");
  ASSERT_EQ(plan.exit_code, 0) << plan.output;
  EXPECT_NE(plan.output.find("86 171 256 256 256 256 samples (levels 1..)"), std::string::npos) << plan.output;
  const std::string dir = testing::FreshTempDir("ibl_samples");
  testing::CommandRun bake = testing::RunSkybake("bake " + Style() +
                                                 " --size 16 -q --vulkan-validation --set ibl.specular=true "
                                                 "--set ibl.size=64 --set ibl.full_samples_roughness=0.5 --out " +
                                                 dir);
  ASSERT_EQ(bake.exit_code, 0) << bake.output;
  auto in = OIIO::ImageInput::open(dir + "/sky_specular_m1.exr");
  ASSERT_TRUE(in);
  const std::string what = in->spec().get_string_attribute("skybake:ibl");
  EXPECT_NE(what.find("; 171 samples,"), std::string::npos) << what;  // level 1 of 4: roughness 1/3, ceil(256 x 2 / 3)
  EXPECT_NE(in->spec().get_string_attribute("skybake:config").find("full_samples_roughness = 0.5"), std::string::npos);
}

}  // namespace
}  // namespace skybake
