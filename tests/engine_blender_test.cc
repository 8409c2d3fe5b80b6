// The blender preset checked in Blender itself (Debian's Blender 3.4, as a
// user would): Blender's own glTF importer brings in sky.glb and its sun
// light, the preset's latlong becomes the World's Environment Texture with
// the default mapping, and Cycles (CPU, no denoiser: Debian's build has no
// OpenImageDenoise) renders a 3-degree camera along the imported sun light
// and turned 90, 180 and 270 degrees about the vertical
// (tests/engines/blender_sun_check.py). The sky's Sun must be along the
// light: that view far brighter than the three others. The bake's OpenEXR
// latlong, set the same way, puts it a quarter turn away (Blender's
// equirect centre faces +X, OpenEXR's +Z): the trap the preset removes.
#include <algorithm>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "test_support.h"

namespace skybake {
namespace {

struct Probe {
  std::vector<double> radiance;  // along the sun light, then turned 90, 180, 270 degrees
};

Probe RunBlender(const std::string& dir, const std::string& latlong) {
  const std::string command = "blender -b --factory-startup --python '" + testing::SourceDir() +
                              "/tests/engines/blender_sun_check.py' -- '" + dir + "/sky.glb' '" + dir + "/" +
                              latlong + "' '" + dir + "'";
  auto [code, output] = testing::RunCommand(command);
  Probe probe;
  EXPECT_EQ(code, 0) << command << "\n" << output;
  const size_t at = output.find("RESULT ");
  EXPECT_NE(at, std::string::npos) << "blender (Debian package, installed by .ci/setup) printed no result:\n"
                                   << output;
  if (at == std::string::npos) return probe;
  const std::string line = output.substr(at + 7, output.find('\n', at) - at - 7);
  nlohmann::json result = nlohmann::json::parse(line);
  for (const auto& r : result["radiance"]) probe.radiance.push_back(r.get<double>());
  return probe;
}

TEST(EngineBlenderTest, SkysSunIsAlongTheImportedSunLight) {
  auto [which, where] = testing::RunCommand("command -v blender");
  ASSERT_EQ(which, 0) << "blender is missing: run .ci/setup (Debian package blender)";
  const std::string dir = testing::FreshTempDir("engine_blender");
  testing::CommandRun bake = testing::RunSkybake("bake " + testing::SourceDir() +
                                                 "/configs/default.toml --size 128 -q --vulkan-validation "
                                                 "--engine blender --out " + dir);
  ASSERT_EQ(bake.exit_code, 0) << bake.output;

  const Probe preset = RunBlender(dir, "sky_blender_latlong.exr");
  ASSERT_EQ(preset.radiance.size(), 4u);
  const double others = std::max({preset.radiance[1], preset.radiance[2], preset.radiance[3]});
  std::printf("blender preset: along the sun light %.6g, turned 90/180/270 deg %.6g %.6g %.6g\n",
              preset.radiance[0], preset.radiance[1], preset.radiance[2], preset.radiance[3]);
  EXPECT_GT(preset.radiance[0], 2.0 * others) << "the sky's Sun is not along Blender's imported sun light";

  // The OpenEXR latlong: the Sun a quarter turn away, as users found.
  const Probe openexr = RunBlender(dir, "sky_latlong.exr");
  ASSERT_EQ(openexr.radiance.size(), 4u);
  std::printf("OpenEXR latlong: along the sun light %.6g, turned 90/180/270 deg %.6g %.6g %.6g\n",
              openexr.radiance[0], openexr.radiance[1], openexr.radiance[2], openexr.radiance[3]);
  EXPECT_GT(openexr.radiance[1], 2.0 * std::max({openexr.radiance[0], openexr.radiance[2], openexr.radiance[3]}));
}

}  // namespace
}  // namespace skybake
