// The ranges of the cloud layer and formation keys (configs/default.toml
// states each): a value outside is a located error naming the range, exit 3,
// before any work; the ends of each range are accepted.
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "test_support.h"

namespace skybake {
namespace {

struct RangeCase {
  std::string key;    // in [[cloud_layer]] or, with "formation.", in [cloud_layer.formation]
  std::string value;  // out of range
  std::string said;   // the message after "s.toml:LINE:COLUMN: "
};

std::string LayerStyle(const std::string& key, const std::string& value) {
  if (key.rfind("formation.", 0) == 0)
    return "[[cloud_layer]]\ntype = \"cumulus\"\ncoverage = 0.5\n[cloud_layer.formation]\nenabled = true\n" +
           key.substr(10) + " = " + value + "\n";
  return "[[cloud_layer]]\ntype = \"cumulus\"\ncoverage = 0.5\n" + key + " = " + value + "\n";
}

TEST(KeyRanges, CloudLayerAndFormationValuesOutOfRangeAreLocatedErrors) {
  const std::string dir = testing::FreshTempDir("key_ranges");
  const std::vector<RangeCase> cases = {
      {"altitude_m", "1e300", "cloud_layer[0].altitude_m: expected a number in [0, 100000]"},
      {"weather_extent_m", "[1e300, 100.0]", "cloud_layer[0].weather_extent_m[0]: expected a number in [10, 10000000]"},
      {"weather_extent_m", "[100.0, 0.0]", "cloud_layer[0].weather_extent_m[1]: expected a number in [10, 10000000]"},
      {"weather_origin_m", "[0.0, -1e300]",
       "cloud_layer[0].weather_origin_m[1]: expected a number in [-10000000, 10000000]"},
      {"formation.origin_m", "[1e300, 0.0]",
       "cloud_layer[0].formation.origin_m[0]: expected a number in [-10000000, 10000000]"},
      {"formation.size_m", "[1e300, 10.0]", "cloud_layer[0].formation.size_m[0]: expected a number in [10, 10000000]"},
      {"formation.velocity_cells_per_hour", "[0.0, 0.0, 1e30]",
       "cloud_layer[0].formation.velocity_cells_per_hour[2]: expected a number in [-10000, 10000]"},
      {"formation.velocity_cells_per_hour", "[-10001.0, 0.0, 0.0]",
       "cloud_layer[0].formation.velocity_cells_per_hour[0]: expected a number in [-10000, 10000]"},
  };
  for (const RangeCase& c : cases) {
    testing::WriteFile(dir, "s.toml", LayerStyle(c.key, c.value));
    const testing::CommandRun run = testing::RunSkybake("check '" + dir + "/s.toml'");
    EXPECT_EQ(run.exit_code, 3) << c.key << " = " << c.value << ": " << run.output;
    EXPECT_NE(run.output.find(c.said), std::string::npos) << c.key << " = " << c.value << ": " << run.output;
  }
  // The ends of the ranges bake (check: ok).
  for (const auto& [key, value] : std::vector<std::pair<std::string, std::string>>{
           {"weather_extent_m", "[10.0, 10000000.0]"},
           {"weather_origin_m", "[-10000000.0, 10000000.0]"},
           {"formation.velocity_cells_per_hour", "[-10000.0, 10000.0, 0.0]"}}) {
    testing::WriteFile(dir, "s.toml", LayerStyle(key, value));
    const testing::CommandRun run = testing::RunSkybake("check '" + dir + "/s.toml'");
    EXPECT_EQ(run.exit_code, 0) << key << " = " << value << ": " << run.output;
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace skybake
