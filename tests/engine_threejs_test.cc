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

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "test_support.h"

namespace skybake {
namespace {

std::string ViewerDir() { return testing::SourceDir() + "/tests/viewer"; }

nlohmann::json RunPage(const std::string& page, const std::string& dir, const std::string& query = "") {
  const std::string command = "cd '" + ViewerDir() + "' && node run_page.mjs " + page + " '" + dir + "' '" + dir +
                              "/screenshot.png' '" + query + "'";
  auto [code, output] = testing::RunCommand(command);
  EXPECT_EQ(code, 0) << command << "\n" << output;
  const size_t at = output.find("{\"chromium_exit\"");
  if (at == std::string::npos) {
    ADD_FAILURE() << "no report from " << page << ":\n" << output;
    return {};
  }
  nlohmann::json line = nlohmann::json::parse(output.substr(at, output.find('\n', at) - at), nullptr, false);
  EXPECT_FALSE(line.is_discarded()) << output;
  return line.is_discarded() ? nlohmann::json() : line["report"];
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

}  // namespace
}  // namespace skybake
