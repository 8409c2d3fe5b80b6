// The threejs preset checked in three.js itself (headless Chromium, three.js
// 0.170 from tests/viewer/node_modules, tests/viewer/engine_threejs.html):
// GLTFLoader brings in sky.glb and its sun light; the preset's latlong is
// the background through EXRLoader as an equirect, then its six faces as a
// CubeTexture. A 3-degree camera along the light must see the sky's Sun:
// far brighter than turned 90, 180 or 270 degrees about +Y. The bake's
// OpenEXR latlong loaded the same way puts it a quarter turn away (three.js's
// equirectUv centres +X, OpenEXR +Z): the trap the preset removes.
#include <algorithm>
#include <string>
#include <vector>

#include <cmath>

#include <glm/glm.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "skybake/pipeline/test_pattern.h"
#include "test_support.h"

namespace skybake {
namespace {

nlohmann::json RunPage(const std::string& page, const std::string& dir, const std::string& query = "") {
  const nlohmann::json line = testing::RunViewerPage(page, dir, dir + "/screenshot.png", query);
  return line.is_null() ? nlohmann::json() : line["report"];
}

TEST(EngineThreejsTest, SkysSunIsAlongTheSceneSunLight) {
  const std::string dir = testing::FreshTempDir("engine_threejs");
  testing::CommandRun bake = testing::RunSkybake("bake " + testing::SourceDir() +
                                                 "/configs/default.toml --size 128 -q --vulkan-validation "
                                                 "--engine threejs --out " + dir);
  ASSERT_EQ(bake.exit_code, 0) << bake.output;
  nlohmann::json report = RunPage("engine_threejs.html", dir);
  ASSERT_TRUE(report.is_object()) << report.dump();
  ASSERT_EQ(report.value("ok", false), true) << report.dump();
  std::printf("three.js: %s\n", report.dump().c_str());
  for (const char* name : {"equirect", "cube"}) {
    const std::vector<double> r = report[name].get<std::vector<double>>();
    ASSERT_EQ(r.size(), 4u);
    EXPECT_GT(r[0], 2.0 * std::max({r[1], r[2], r[3]})) << name << ": the sky's Sun is not along the sun light";
  }
  const std::vector<double> openexr = report["openexr"].get<std::vector<double>>();
  ASSERT_EQ(openexr.size(), 4u);
  EXPECT_GT(openexr[1], 2.0 * std::max({openexr[0], openexr[2], openexr[3]})) << "the trap is a quarter turn";
}

// `skybake testpattern --engine threejs` in three.js: the colour seen along
// each face axis is that face's tint (TestPatternFaceColor), the horizon is
// marked, and North's letter stands above the horizon at -Z: for the
// equirect and for the CubeTexture.
TEST(EngineThreejsTest, TestPatternIsWhereItSaysInThreejs) {
  const std::string dir = testing::FreshTempDir("engine_threejs_pattern");
  testing::CommandRun r = testing::RunSkybake("testpattern --engine threejs --size 128 --out " + dir);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // Face axes 10 degrees below the horizon (the horizon line and the letters are above or on it).
  const std::vector<glm::dvec3> dirs = {{1, -0.18, 0}, {-1, -0.18, 0}, {0, 1, 0}, {0, -1, 0}, {0, -0.18, 1},
                                        {0, -0.18, -1},
                                        {1, 0, 0.5},                                  // on the +X face's horizon
                                        {1, 0.2, 0.5},                                // beside it, above
                                        {0, std::sin(6.0 * M_PI / 180.0), -std::cos(6.0 * M_PI / 180.0)}};  // N
  std::string query = "pattern=1&dirs=";
  for (size_t i = 0; i < dirs.size(); ++i)
    query += (i ? ";" : "") + std::to_string(dirs[i].x) + "," + std::to_string(dirs[i].y) + "," +
             std::to_string(dirs[i].z);
  nlohmann::json report = RunPage("engine_threejs.html", dir, query);
  ASSERT_TRUE(report.is_object()) << report.dump();
  ASSERT_EQ(report.value("ok", false), true) << report.dump();
  std::printf("three.js pattern: %s\n", report.dump().c_str());
  for (const char* name : {"equirect", "cube"}) {
    const auto seen = report[name].get<std::vector<std::vector<double>>>();
    ASSERT_EQ(seen.size(), dirs.size()) << name;
    for (int face = 0; face < 6; ++face) {
      const glm::dvec3 expected = TestPatternFaceColor(face);
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(seen[size_t(face)][size_t(c)], expected[c], 0.02) << name << " along face " << face;
    }
    // The white horizon line lifts green on the red +X face; the view above it is plain.
    EXPECT_GT(seen[6][1], TestPatternFaceColor(0)[1] + 0.1) << name << ": horizon";
    EXPECT_NEAR(seen[7][1], TestPatternFaceColor(0)[1], 0.02) << name << ": above the horizon";
    // North's white letter lifts blue on the yellow -Z face.
    EXPECT_GT(seen[8][2], TestPatternFaceColor(5)[2] + 0.1) << name << ": N above the horizon at -Z";
  }
}

}  // namespace
}  // namespace skybake
