// The skybake binary end to end: a full bake under the validation layer, the
// files read back by an independent reader (OpenImageIO), exit codes.
#include <array>
#include <cstdio>
#include <filesystem>
#include <set>
#include <string>

#include <sys/wait.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <OpenImageIO/imageio.h>

#include "test_support.h"

namespace skybake {
namespace {

using testing::CommandRun;

// The binary with `env` assignments before it (run through bash).
CommandRun Skybake(const std::string& args, const std::string& env = "") { return testing::RunSkybake(args, env); }

std::string FreshDir(const std::string& name) {
  auto dir = std::filesystem::temp_directory_path() / ("skybake_cli_" + name + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  return dir.string();
}

std::string Style() { return testing::SourceDir() + "/configs/default.toml"; }

struct ExrInfo {
  int width = 0, height = 0, channels = 0;
  std::string textureformat;
  OIIO::TypeDesc format;
  bool has_config = false, has_chromaticities = false;
};

ExrInfo Inspect(const std::string& path) {
  ExrInfo info;
  auto in = OIIO::ImageInput::open(path);
  if (!in) return info;
  const OIIO::ImageSpec& spec = in->spec();
  info.width = spec.width;
  info.height = spec.height;
  info.channels = spec.nchannels;
  info.format = spec.format;
  info.textureformat = spec.get_string_attribute("textureformat");
  info.has_config = !spec.get_string_attribute("skybake:config").empty();
  info.has_chromaticities = spec.find_attribute("chromaticities") != nullptr;
  return info;
}

TEST(CliTest, FullBakeUnderValidationWritesReadableFiles) {
  std::string out = FreshDir("bake");
  CommandRun run = Skybake("bake " + Style() + " --size 16 --out " + out + " --vulkan-validation");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(run.output.find("validation"), std::string::npos) << run.output;
  // One progress line per stage, with its time.
  for (const char* stage : {"device", "pipelines", "LUTs", "render", "write EXR", "preview"})
    EXPECT_NE(run.output.find(std::string("skybake: ") + stage), std::string::npos) << stage;
  // Each stage once, and the stages of timings.json add up to the bake's
  // time: the EXRs' time does not also count the preview's.
  const nlohmann::json timings = nlohmann::json::parse(testing::ReadFileBytes(out + "/timings.json"));
  double sum = 0.0;
  std::set<std::string> stages;
  for (const nlohmann::json& stage : timings["stages"]) {
    sum += stage["seconds"].get<double>();
    EXPECT_TRUE(stages.insert(stage["stage"].get<std::string>()).second) << stage["stage"];
  }
  EXPECT_NEAR(sum, timings["total_s"].get<double>(), 0.002);

  for (const char* face : {"px", "nx", "py", "ny", "pz", "nz"}) {
    ExrInfo f = Inspect(out + "/sky_" + face + ".exr");
    EXPECT_EQ(f.width, 16) << face;
    EXPECT_EQ(f.height, 16) << face;
    EXPECT_EQ(f.channels, 3) << face;
    EXPECT_EQ(f.format, OIIO::TypeDesc::HALF) << face;
    EXPECT_TRUE(f.has_config && f.has_chromaticities) << face;
  }
  ExrInfo cube = Inspect(out + "/sky_cube.exr");
  EXPECT_EQ(cube.width, 16);
  EXPECT_EQ(cube.height, 96);
  EXPECT_EQ(cube.textureformat, "CubeFace Environment");
  ExrInfo latlong = Inspect(out + "/sky_latlong.exr");
  EXPECT_EQ(latlong.width, 32);
  EXPECT_EQ(latlong.height, 16);
  EXPECT_EQ(latlong.textureformat, "LatLong Environment");
  EXPECT_TRUE(latlong.has_config && latlong.has_chromaticities);
  ExrInfo preview = Inspect(out + "/sky_latlong.png");
  EXPECT_EQ(preview.width, 32);
  EXPECT_EQ(preview.format, OIIO::TypeDesc::UINT8);
  std::filesystem::remove_all(out);
}

TEST(CliTest, FloatOutputNeedsNoScale) {
  std::string out = FreshDir("float");
  CommandRun run = Skybake("bake " + Style() + " --size 8 -q --set output.pixel_type=float --out " + out);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(run.output.find("scaled"), std::string::npos) << run.output;
  EXPECT_EQ(Inspect(out + "/sky_latlong.exr").format, OIIO::TypeDesc::FLOAT);
  std::filesystem::remove_all(out);
}

TEST(CliTest, RefusedOverflowWritesNothing) {
  std::string out = FreshDir("refuse");
  // A sky beyond half range (a style made a thousand times brighter) is refused when written.
  CommandRun run =
      Skybake("bake " + Style() +
              " --size 8 -q --set sun.irradiance=[1474.0,1850.4,1911.98] --set output.overflow=refuse --out " + out);
  EXPECT_EQ(run.exit_code, 5) << run.output;
  EXPECT_NE(run.output.find("exceeds the half-float maximum"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("output.pixel_type"), std::string::npos) << "names the fix";
  size_t files = 0;
  if (std::filesystem::exists(out))
    for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(out)) ++files;
  EXPECT_EQ(files, 0u);
  std::filesystem::remove_all(out);
}

TEST(CliTest, InvalidStyleExitsWithConfigCodeBeforeAnyGpuWork) {
  std::string out = FreshDir("invalid");
  CommandRun run = Skybake("bake " + Style() + " --set atmosphere.mie.g=1.5 --set sun.elevatoin_deg=3 --out " + out);
  EXPECT_EQ(run.exit_code, 3) << run.output;
  EXPECT_NE(run.output.find("atmosphere.mie.g: 1.5 is out of range (-1, 1)"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("did you mean 'sun.elevation_deg'?"), std::string::npos) << run.output;
  EXPECT_EQ(run.output.find("skybake: device"), std::string::npos) << "no GPU work";
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(CliTest, CheckValidatesOnly) {
  CommandRun ok = Skybake("check " + Style());
  EXPECT_EQ(ok.exit_code, 0) << ok.output;
  CommandRun bad = Skybake("check " + Style() + " --set render.cube_size=0");
  EXPECT_EQ(bad.exit_code, 3) << bad.output;
}

// A preset that the explicit keys override entirely is baked as written, with
// a warning from check and from bake (the default template gives none).
TEST(CliTest, PresetOverriddenByEveryKeyWarns) {
  CommandRun plain = Skybake("check " + Style() + " --set quality.preset=reference");
  EXPECT_EQ(plain.exit_code, 0) << plain.output;
  EXPECT_EQ(plain.output.find("warning"), std::string::npos) << plain.output;
  std::string keys;
  for (const char* k : {"integrator=analytic", "sky_view_lut=true", "sky_view_lut_width=256", "sky_view_lut_height=144",
                        "view_steps=32", "transmittance_steps=256", "transmittance_lut_width=256",
                        "transmittance_lut_height=64", "twilight_march_band_deg=10", "twilight_march_steps=64"})
    keys += std::string(" --set quality.") + k;
  for (const char* command : {"check", "bake --dry-run"}) {
    CommandRun run = Skybake(std::string(command) + " " + Style() + " --set quality.preset=reference" + keys);
    EXPECT_EQ(run.exit_code, 0) << run.output;
    EXPECT_NE(run.output.find("skybake: warning: --set quality.preset=reference:1:5: quality.preset: preset "
                              "'reference' changes nothing"),
              std::string::npos)
        << command << ": " << run.output;
  }
}

TEST(CliTest, MissingVulkanDriverNamesThePackage) {
  CommandRun run = Skybake("bake " + Style() + " --size 4 --out " + FreshDir("nodriver"),
                           "VK_ICD_FILENAMES=/nonexistent/icd.json VK_DRIVER_FILES=/nonexistent/icd.json");
  EXPECT_EQ(run.exit_code, 4) << run.output;
  EXPECT_NE(run.output.find("mesa-vulkan-drivers"), std::string::npos) << run.output;
}

TEST(CliTest, DevicesListsLavapipe) {
  CommandRun run = Skybake("devices");
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("usable"), std::string::npos) << run.output;
}

TEST(CliTest, HelpShowsDefaultsAndUsageErrorsExitTwo) {
  CommandRun help = Skybake("bake --help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.output.find("--out TEXT=out"), std::string::npos) << help.output;
  CommandRun usage = Skybake("bake");
  EXPECT_EQ(usage.exit_code, 2) << usage.output;
}

// `skybake --version`: the project's version and the git commit of the
// checkout it was built from (this one: the build looks it up), exit 0; with
// anything else beside it a usage error saying so, exit 2, nothing run. A
// bake's manifest records both.
TEST(CliTest, VersionPrintsTheVersionAndCommitAndTheManifestRecordsThem) {
  const auto [git_status, git_head] = testing::RunCommand("git -C '" + testing::SourceDir() + "' rev-parse HEAD");
  const std::string commit = git_status == 0 ? git_head.substr(0, git_head.find('\n')) : "unknown";
  CommandRun version = Skybake("--version");
  EXPECT_EQ(version.exit_code, 0) << version.output;
  EXPECT_EQ(version.output, std::string("skybake ") + SKYBAKE_VERSION + " (commit " + commit + ")\n");

  for (const char* args : {"--version bake " SKYBAKE_SOURCE_DIR "/configs/default.toml", "bake --version",
                           "--version --help", "devices --version", "--version --version"}) {
    CommandRun mixed = Skybake(args);
    EXPECT_EQ(mixed.exit_code, 2) << args << ": " << mixed.output;
    EXPECT_EQ(mixed.output.rfind("skybake: error: --version takes no subcommand or other option (given: ", 0), 0u)
        << args << ": " << mixed.output;
    EXPECT_NE(mixed.output.find("run 'skybake --version' alone"), std::string::npos) << mixed.output;
  }

  const std::string out = FreshDir("version");
  CommandRun bake = Skybake("bake " + Style() + " --size 8 -q --set gltf.enabled=false --out " + out);
  ASSERT_EQ(bake.exit_code, 0) << bake.output;
  const nlohmann::json manifest = nlohmann::json::parse(testing::ReadFileBytes(out + "/manifest.json"));
  EXPECT_EQ(manifest["version"], SKYBAKE_VERSION);
  EXPECT_EQ(manifest["commit"], commit);
  std::filesystem::remove_all(out);
}

// The disc in half-float maps with no scale allowed can never be written:
// refused before any GPU work, at the key, with the fixes.
TEST(CliTest, SunInHalfMapsWithoutAScaleIsRefusedUpFront) {
  std::string out = FreshDir("sun_map_refuse");
  CommandRun run =
      Skybake("bake " + Style() + " --size 8 -q --set output.sun=map --set output.overflow=refuse --out " + out);
  EXPECT_EQ(run.exit_code, 3) << run.output;
  EXPECT_NE(run.output.find("output.sun: the solar disc in half-float maps exceeds half range"), std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("output.sun = \"light\""), std::string::npos) << "names the fix";
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace skybake
