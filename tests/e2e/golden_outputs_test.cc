// Golden outputs: a fixed set of bakes through the binary (under the
// validation layer), and the SHA-256 of every file each one writes, compared
// with the list kept in tests/golden/outputs.sha256. A change that alters any
// byte of an existing output (a refactor, a new effect that should prune to
// nothing, a new dependency) fails here, naming the bake and the file.
//
// The list is for this machine kind's Vulkan driver (Debian 12's lavapipe):
// after an intended change of output, regenerate it with
//   SKYBAKE_UPDATE_GOLDEN=1 build/tests/golden_outputs_test
// and say in the commit why the bytes changed.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "skybake/pipeline/pipeline.h"
#include "test_support.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;
using testing::RunSkybake;

struct GoldenBake {
  const char* name;  // the folder under the test's temporary directory
  std::string args;  // after `skybake`; {out} is the folder, {src} the checkout
};

// Each style is given relative to the checkout (the manifest records the path
// as given), so the test runs from the checkout.
std::vector<GoldenBake> Bakes() {
  return {
      {"default_half", "bake configs/default.toml --size 32 -q --out {out}"},
      {"default_float", "bake configs/default.toml --size 24 --set output.pixel_type=float -q --out {out}"},
      {"default_twilight", "bake configs/default.toml --size 16 --set sun.elevation_deg=-4 -q --out {out}"},
      {"default_high_observer",
       "bake configs/default.toml --size 16 --set atmosphere.observer_altitude_m=8000 --set sun.elevation_deg=35 "
       "--out {out}"},
      {"aoas_heart_clouds", "bake configs/styles/heart_clouds.toml --size 24 -q --out {out}"},
      {"aoas_crystal_blue", "bake configs/styles/crystal_blue.toml --size 24 -q --out {out}"},
      {"aoas_ambiguous_yellow", "bake configs/styles/ambiguous_yellow.toml --size 24 -q --out {out}"},
      {"five_frames", "bake configs/default.toml --schedule tests/golden/five_frames.toml --size 16 -q --out {out}"},
      {"five_frames_float",
       "bake configs/default.toml --schedule tests/golden/five_frames.toml --size 12 "
       "--set output.pixel_type=float -q --out {out}"},
      // A part of the same sequence on its own, then both parts merged.
      {"five_frames_part",
       "bake configs/default.toml --schedule tests/golden/five_frames.toml --size 16 --shard 2/2 -q --out {out}"},
      {"five_frames_merged",
       "bake configs/default.toml --schedule tests/golden/five_frames.toml --size 16 --shard 1/2 -q --out {out} && "
       "{bin} bake configs/default.toml --schedule tests/golden/five_frames.toml --size 16 --shard 2/2 -q --out {out} "
       "&& "
       "{bin} merge-manifest {out}"},
  };
}

std::string GoldenListPath() { return testing::SourceDir() + "/tests/golden/outputs.sha256"; }

// The SHA-256 of a bake's file. A manifest records the git commit the
// binary was built from, which every commit changes: its sum is taken with
// the commit as a build outside git records it ("unknown").
std::string GoldenSha256(const fs::path& path) {
  const std::string name = path.filename().string();
  if (name.rfind("manifest", 0) != 0 || path.extension() != ".json") return Sha256OfFile(path.string());
  static const std::regex commit(R"("commit": "[0-9a-f]{40}")");
  return Sha256OfText(std::regex_replace(testing::ReadFileBytes(path.string()), commit, R"("commit": "unknown")",
                                         std::regex_constants::format_first_only));
}

// "bake/file sha256" for every file of every bake but timings.json (seconds
// differ from run to run), sorted.
std::map<std::string, std::string> BakeAll(const std::string& root) {
  std::map<std::string, std::string> sums;
  for (const GoldenBake& bake : Bakes()) {
    const std::string out = root + "/" + bake.name;
    std::string args = bake.args;
    for (auto [key, value] : {std::pair<std::string, std::string>{"{out}", out}, {"{bin}", SKYBAKE_BINARY}}) {
      for (size_t at; (at = args.find(key)) != std::string::npos;) args.replace(at, key.size(), value);
    }
    const testing::CommandRun run =
        RunSkybake(args, "cd '" + testing::SourceDir() + "' && export SKYBAKE_VULKAN_VALIDATION=1 &&");
    EXPECT_EQ(run.exit_code, 0) << bake.name << ": " << run.output;
    if (run.exit_code != 0) continue;
    for (const auto& entry : fs::directory_iterator(out)) {
      const std::string file = entry.path().filename().string();
      if (file == "timings.json" || file.rfind("timings.", 0) == 0) continue;
      sums[std::string(bake.name) + "/" + file] = GoldenSha256(entry.path());
    }
  }
  return sums;
}

TEST(GoldenOutputsTest, EveryOutputOfTheFixedBakesKeepsItsBytes) {
  const auto sums = BakeAll(testing::FreshTempDir("golden"));
  if (std::getenv("SKYBAKE_UPDATE_GOLDEN") != nullptr) {
    std::ofstream list(GoldenListPath());
    for (const auto& [file, sum] : sums) list << sum << "  " << file << "\n";
    GTEST_SKIP() << "wrote " << sums.size() << " sums to " << GoldenListPath();
  }
  std::map<std::string, std::string> expected;
  std::ifstream list(GoldenListPath());
  ASSERT_TRUE(list) << "missing " << GoldenListPath();
  for (std::string sum, file; list >> sum >> file;) expected[file] = sum;
  ASSERT_GT(expected.size(), 100u);
  for (const auto& [file, sum] : expected) {
    auto found = sums.find(file);
    if (found == sums.end()) {
      ADD_FAILURE() << file << ": no longer written";
    } else {
      EXPECT_EQ(found->second, sum) << file << ": bytes changed";
    }
  }
  for (const auto& [file, sum] : sums) EXPECT_TRUE(expected.count(file)) << file << ": new file, not in the list";
}

}  // namespace
}  // namespace skybake
