// Sequence bakes end to end on lavapipe under the validation layer: a
// 24-frame schedule, its manifest checked file by file against sha256sum,
// and the glTF scenes checked by the Khronos glTF-Validator and rendered by
// three.js in headless Chromium (node scripts in tests/viewer/).
#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <set>

#include <unistd.h>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>
#include <OpenImageIO/imageio.h>

#include "skybake/pipeline/pipeline.h"
#include "skybake/input/schedule.h"
#include "skybake/model/spectrum.h"
#include "schedule_fixtures.h"
#include "test_support.h"

namespace skybake {
namespace {

using testing::RunCommand;

namespace fs = std::filesystem;
using nlohmann::json;

using testing::kDay24;

// Small and quick: 16^3 cube faces, a 32 x 16 latlong.
const std::vector<std::string> kSmall = {"render.cube_size=16", "render.latlong_height=16", "gltf.segments=32"};

std::string ViewerDir() { return testing::SourceDir() + "/tests/viewer"; }

class Sequence : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // Per process: ctest runs each test case in its own process, maybe in parallel.
    out_dir_ = (fs::temp_directory_path() / fmt::format("skybake-sequence-test-{}", ::getpid())).string();
    fs::remove_all(out_dir_);
    ScheduleResult schedule = ParseSchedule(kDay24, "day24.toml");
    ASSERT_TRUE(schedule.ok());
    schedule_ = std::make_unique<Schedule>(schedule.schedule);
    FrameStyles styles = ResolveFrameStyles(testing::SourceDir() + "/configs/default.toml", kSmall, *schedule_);
    ASSERT_TRUE(styles.ok()) << styles.errors[0].Format();
    BakeOptions options;
    options.out_dir = out_dir_ + "/sequence";
    options.vulkan.validation = true;
    try {
      result_ = std::make_unique<BakeResult>(BakeSequence(styles.styles, *schedule_, options));
      ConfigResult single = LoadSkyStyle(testing::SourceDir() + "/configs/default.toml", kSmall);
      ASSERT_TRUE(single.ok());
      options.out_dir = out_dir_ + "/single";
      single_ = std::make_unique<BakeResult>(BakeStyle(single.style, options));
    } catch (const std::exception& e) {
      FAIL() << "bake failed: " << e.what()
             << "\nVulkan is required: apt-get install libvulkan1 mesa-vulkan-drivers vulkan-validationlayers";
    }
  }
  static void TearDownTestSuite() { fs::remove_all(out_dir_); }
  void SetUp() override {
    ASSERT_TRUE(result_) << "the sequence bake failed";
    ASSERT_TRUE(single_) << "the single bake failed";
  }

  static std::string out_dir_;
  static std::unique_ptr<Schedule> schedule_;
  static std::unique_ptr<BakeResult> result_, single_;
};
std::string Sequence::out_dir_;
std::unique_ptr<Schedule> Sequence::schedule_;
std::unique_ptr<BakeResult> Sequence::result_, Sequence::single_;

TEST_F(Sequence, TwentyFourFramesOneRendererNoValidationMessages) {
  EXPECT_EQ(result_->validation_messages, 0);
  EXPECT_EQ(single_->validation_messages, 0);
  ASSERT_EQ(result_->frames.size(), 24u);
  // One renderer for the whole sequence (the disc-less SH views use a variant
  // pipeline of the same renderer): the atmosphere never changes, so the
  // transmittance and multiple-scattering LUTs are built once, the per-sun
  // sky-view LUT once per frame.
  EXPECT_EQ(result_->renderer_builds, 1);
  EXPECT_EQ(result_->counters.transmittance_lut_builds, 1);
  EXPECT_EQ(result_->counters.multiscattering_lut_builds, 1);
  // The sky-view LUT depends on the sun: built once per frame, plus once for
  // the exposure of the highest sun (the half-float scale comes from the
  // disc's bound, without rendering).
  if (QualitySettings{}.sky_view_lut) {
    EXPECT_EQ(result_->counters.skyview_lut_builds, 24 + 1);
  }
  EXPECT_EQ(result_->atmosphere_updates, 0);
  EXPECT_EQ(result_->counters.frames >= 24, true);
  for (int frame = 1; frame <= 24; ++frame)
    for (const char* name : {"sky_px", "sky_nz", "sky_cube", "sky_latlong"})
      EXPECT_TRUE(fs::exists(fmt::format("{}/sequence/{}.{:04d}.exr", out_dir_, name, frame))) << name << " " << frame;
  EXPECT_TRUE(fs::exists(out_dir_ + "/sequence/sky_latlong.0024.png"));
  EXPECT_FALSE(fs::exists(out_dir_ + "/sequence/sky_latlong.0025.png"));
}

TEST_F(Sequence, ManifestListsEveryFileWithMatchingChecksum) {
  std::ifstream in(result_->manifest_path);
  ASSERT_TRUE(in) << result_->manifest_path;
  json manifest = json::parse(in);
  ASSERT_EQ(manifest["frames"].size(), 24u);
  // Run-dependent facts are in timings.json, so the manifest is the same for every run of the bake.
  for (const char* key : {"timings", "out_dir", "renderer_builds"}) EXPECT_FALSE(manifest.contains(key)) << key;
  json timings = json::parse(std::ifstream(out_dir_ + "/sequence/timings.json"));
  ASSERT_EQ(timings["frames"].size(), 24u);
  EXPECT_EQ(timings["renderer_builds"].get<int>(), result_->renderer_builds);
  std::set<std::string> listed;
  int checked = 0;
  auto check = [&](const json& file) {
    std::string path = out_dir_ + "/sequence/" + file["file"].get<std::string>();
    ASSERT_TRUE(fs::exists(path)) << path;
    EXPECT_EQ(fs::file_size(path), file["bytes"].get<uint64_t>()) << path;
    auto [status, output] = RunCommand("sha256sum '" + path + "'");
    ASSERT_EQ(status, 0) << output;
    EXPECT_EQ(output.substr(0, 64), file["sha256"].get<std::string>()) << path;
    listed.insert(file["file"].get<std::string>());
    ++checked;
  };
  for (size_t i = 0; i < 24; ++i) {
    const json& frame = manifest["frames"][i];
    const ScheduleFrame& expected = schedule_->frames[i];
    EXPECT_EQ(frame["frame"].get<int>(), expected.number);
    EXPECT_EQ(frame["time"].get<std::string>(), expected.time->Iso8601());
    for (int c = 0; c < 3; ++c) EXPECT_DOUBLE_EQ(frame["sun"]["direction"][c].get<double>(), expected.sun_direction[c]);
    EXPECT_EQ(frame["sh_irradiance_with_sun"].size(), 9u);
    EXPECT_EQ(frame["sh_irradiance_without_sun"][0].size(), 3u);
    EXPECT_EQ(timings["frames"][i]["frame"].get<int>(), expected.number);
    EXPECT_GT(timings["frames"][i]["render_s"].get<double>(), 0.0);
    for (const json& file : frame["files"]) check(file);
  }
  for (const json& file : manifest["scene"]) check(file);
  // 6 faces + strip + latlong + PNG per frame, then .gltf, .bin, .glb.
  EXPECT_EQ(checked, 24 * 9 + 3);
  // Every file of the folder is listed, apart from the manifest itself and the timings.
  for (const auto& entry : fs::directory_iterator(out_dir_ + "/sequence")) {
    std::string name = entry.path().filename().string();
    if (name == "manifest.json" || name == "timings.json" || name.find("screenshot") != std::string::npos) continue;
    EXPECT_TRUE(listed.count(name)) << name << " is not in the manifest";
  }
  // One exposure for the sequence.
  EXPECT_TRUE(manifest["exposure_ev100"].is_number());
  EXPECT_NE(manifest["exposure_source"].get<std::string>().find("every frame"), std::string::npos);
}

TEST_F(Sequence, ShOfTheSkyIsBrighterWithTheSun) {
  for (const FrameResult& f : result_->frames) {
    // Irradiance on an upward surface; the sun adds only when it is up.
    double with = EvaluateSh(f.sh_irradiance_with_sun, {0, 1, 0})[1];
    double without = EvaluateSh(f.sh_irradiance_without_sun, {0, 1, 0})[1];
    EXPECT_GT(without, 0.0) << f.number;
    if (f.sun_elevation_deg > 1.0) {
      EXPECT_GT(with, without) << f.number;
    }
  }
}

TEST_F(Sequence, GltfValidatorReportsNoErrorsOrWarnings) {
  std::string files;
  for (const char* dir : {"sequence", "single"})
    for (const char* name : {"sky.gltf", "sky.glb"}) files += " '" + out_dir_ + "/" + dir + "/" + name + "'";
  auto [status, output] = RunCommand("cd '" + ViewerDir() + "' && node validate.mjs" + files);
  std::printf("%s", output.c_str());
  EXPECT_EQ(status, 0) << output << "\n(install with: bash .ci/setup)";
  EXPECT_EQ(output.find("0 errors, 0 warnings"), output.find("0 errors, 0 warnings"));
  size_t count = 0;
  for (size_t p = output.find("0 errors, 0 warnings"); p != std::string::npos;
       p = output.find("0 errors, 0 warnings", p + 1))
    ++count;
  EXPECT_EQ(count, 4u);
}

// Rotates v by the glTF quaternion [x, y, z, w].
glm::dvec3 Rotate(const json& q, const glm::dvec3& v) {
  glm::dquat quat(q[3].get<double>(), q[0].get<double>(), q[1].get<double>(), q[2].get<double>());
  return quat * v;
}

TEST_F(Sequence, GltfSunShinesAwayFromTheBakedSun) {
  std::ifstream in(out_dir_ + "/sequence/sky.gltf");
  json gltf = json::parse(in);
  // A sequence animates its light's intensity and colour (KHR_animation_pointer).
  ASSERT_EQ(gltf["extensionsUsed"].size(), 3u);
  EXPECT_EQ(gltf["extensionsUsed"][2], "KHR_animation_pointer");
  EXPECT_FALSE(gltf.contains("extensionsRequired")) << "clients without the extension still load the scene";
  for (const json& name : gltf["extensionsUsed"]) EXPECT_NE(name.get<std::string>(), "KHR_materials_emissive_strength");
  const json& sun_node = gltf["nodes"][1];
  ASSERT_EQ(sun_node["extensions"]["KHR_lights_punctual"]["light"].get<int>(), 0);
  EXPECT_EQ(gltf["extensions"]["KHR_lights_punctual"]["lights"][0]["type"].get<std::string>(), "directional");
  // The light (the highest-sun frame, the last) shines along the node's -Z.
  const FrameResult& last = result_->frames.back();
  EXPECT_LT(glm::length(Rotate(sun_node["rotation"], {0, 0, -1}) + last.sun_direction), 1e-6);
  // Clients light with colour x intensity: intensity x Y(colour) is the
  // illuminance, the colour's brightest channel 1.
  const json& light = gltf["extensions"]["KHR_lights_punctual"]["lights"][0];
  const std::array<double, 3> colour = {light["color"][0].get<double>(), light["color"][1].get<double>(),
                                        light["color"][2].get<double>()};
  EXPECT_NEAR(std::max({colour[0], colour[1], colour[2]}), 1.0, 1e-12);
  EXPECT_NEAR(light["intensity"].get<double>() * Rec709Luminance(colour), last.sun_illuminance_lux,
              1e-6 * last.sun_illuminance_lux);
  // Every animation key points the light away from its frame's sun.
  const json& sampler = gltf["animations"][0]["samplers"][0];
  const json& output = gltf["accessors"][sampler["output"].get<int>()];
  const json& view = gltf["bufferViews"][output["bufferView"].get<int>()];
  ASSERT_EQ(output["count"].get<int>(), 24);
  std::ifstream bin(out_dir_ + "/sequence/sky.bin", std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(bin)), std::istreambuf_iterator<char>());
  const float* keys = reinterpret_cast<const float*>(bytes.data() + view["byteOffset"].get<size_t>());
  for (int k = 0; k < 24; ++k) {
    json q = {keys[4 * k], keys[4 * k + 1], keys[4 * k + 2], keys[4 * k + 3]};
    EXPECT_LT(glm::length(Rotate(q, {0, 0, -1}) + result_->frames[k].sun_direction), 1e-5) << "key " << k;
  }
}

// The light follows every frame: Babylon.js (which plays KHR_animation_pointer
// channels) moved to each frame's animation time lights with that frame's
// Sun: intensity x Y(colour) is the frame's illuminance (float32 keys), and
// the colour is the frame's (its brightest channel 1). The channels name no
// node, so clients without the extension skip them (three.js's test above,
// Blender's importer).
TEST_F(Sequence, BabylonLightsEachFrameWithItsOwnSun) {
  const json gltf = json::parse(std::ifstream(out_dir_ + "/sequence/sky.gltf"));
  int pointers = 0;
  for (const json& channel : gltf["animations"][0]["channels"]) {
    if (channel["target"]["path"] != "pointer") continue;
    ++pointers;
    EXPECT_FALSE(channel["target"].contains("node")) << channel.dump();
    const std::string pointer = channel["target"]["extensions"]["KHR_animation_pointer"]["pointer"];
    EXPECT_TRUE(pointer == "/extensions/KHR_lights_punctual/lights/0/intensity" ||
                pointer == "/extensions/KHR_lights_punctual/lights/0/color")
        << pointer;
  }
  EXPECT_EQ(pointers, 2);
  const json manifest = json::parse(std::ifstream(out_dir_ + "/sequence/manifest.json"));
  std::string times;
  for (const json& frame : manifest["frames"])
    times += (times.empty() ? "" : ",") + fmt::format("{}", frame["animation_time_s"].get<double>());
  const json line = testing::RunViewerPage("engine_babylon_sun_path.html", out_dir_ + "/sequence",
                                           out_dir_ + "/sun_path.png", "scene=sky.glb&times=" + times);
  ASSERT_FALSE(line.is_null());
  const json& report = line["report"];
  ASSERT_EQ(report.value("ok", false), true) << report.dump();
  ASSERT_EQ(report["frames"].size(), result_->frames.size());
  for (size_t k = 0; k < result_->frames.size(); ++k) {
    const FrameResult& frame = result_->frames[k];
    const json& seen = report["frames"][k];
    const std::array<double, 3> colour = {seen["color"][0].get<double>(), seen["color"][1].get<double>(),
                                          seen["color"][2].get<double>()};
    const double lux = seen["intensity"].get<double>() * Rec709Luminance(colour);
    EXPECT_NEAR(lux, frame.sun_illuminance_lux, 1e-5 * frame.sun_illuminance_lux + 1e-3) << "frame " << k;
    const double peak = std::max({frame.sun_irradiance[0], frame.sun_irradiance[1], frame.sun_irradiance[2]});
    if (!(peak > 0.0)) continue;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(colour[c], frame.sun_irradiance[c] / peak, 1e-5) << "frame " << k;
  }
  std::printf("Babylon.js %s: %zu frames, each lit by its own sun (noon %.0f lx)\n",
              report["version"].get<std::string>().c_str(), result_->frames.size(),
              report["frames"][result_->frames.size() / 2]["intensity"].get<double>());
}

// Blender 3.4's glTF importer, which has no KHR_animation_pointer, loads the
// sequence's scene: the dome, the sun light and its path (rotation keys).
TEST_F(Sequence, BlenderImportsTheAnimatedScene) {
  auto [which, where] = RunCommand("command -v blender");
  ASSERT_EQ(which, 0) << "blender is missing: run .ci/setup (Debian package blender)";
  const std::string command = "blender -b --factory-startup --python '" + testing::SourceDir() +
                              "/tests/engines/blender_import_scene.py' -- '" + out_dir_ + "/sequence/sky.glb'";
  auto [code, output] = RunCommand(command);
  ASSERT_EQ(code, 0) << command << "\n" << output;
  const size_t at = output.find("RESULT ");
  ASSERT_NE(at, std::string::npos) << output;
  const json result = json::parse(output.substr(at + 7, output.find('\n', at) - at - 7));
  std::printf("Blender: %s\n", result.dump().c_str());
  EXPECT_EQ(result["lights"], json::parse(R"([["sun", "SUN"]])"));
  EXPECT_EQ(result["fcurves"], json::parse(R"(["rotation_quaternion"])"));
  EXPECT_NE(std::find(result["objects"].begin(), result["objects"].end(), "skydome"), result["objects"].end());
}

// Mean sRGB colour of the top tenth of a screenshot.
std::array<double, 3> TopMean(const std::string& png) {
  auto in = OIIO::ImageInput::open(png);
  if (!in) return {-1, -1, -1};
  const OIIO::ImageSpec& spec = in->spec();
  std::vector<uint8_t> pixels(size_t(spec.width) * spec.height * spec.nchannels);
  in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, pixels.data());
  std::array<double, 3> sum{0, 0, 0};
  const int rows = std::max(1, spec.height / 10);
  for (int y = 0; y < rows; ++y)
    for (int x = 0; x < spec.width; ++x)
      for (int c = 0; c < 3; ++c) sum[c] += pixels[(size_t(y) * spec.width + x) * spec.nchannels + c];
  for (double& s : sum) s /= double(rows) * spec.width;
  return sum;
}

TEST_F(Sequence, ThreeJsRendersTheDomeInHeadlessChromium) {
  for (std::string scene : {out_dir_ + "/sequence/sky.glb", out_dir_ + "/single/sky.gltf"}) {
    std::string shot = scene + ".screenshot.png";
    fs::remove(shot);
    auto [status, output] = RunCommand("cd '" + ViewerDir() + "' && node view.mjs '" + scene + "' '" + shot + "'");
    std::printf("%s", output.c_str());
    ASSERT_EQ(status, 0) << output << "\n(install with: bash .ci/setup)";
    EXPECT_NE(output.find("\"ok\":\"1\""), std::string::npos) << output;
    EXPECT_NE(output.find("\"lights\":\"1\""), std::string::npos) << "the sun light did not load: " << output;
    std::array<double, 3> top = TopMean(shot);
    std::printf("%s: top of frame mean sRGB %.1f %.1f %.1f\n", shot.c_str(), top[0], top[1], top[2]);
    // A daytime sky: bright enough not to be black, and blue.
    EXPECT_GT(top[0] + top[1] + top[2], 3 * 40.0) << "the top of the frame is black";
    EXPECT_GT(top[2], top[0] + 20.0) << "the top of the frame is not sky blue";
  }
  // The sequence's scene animates the sun.
  auto [status, output] = RunCommand("cd '" + ViewerDir() + "' && node view.mjs '" + out_dir_ +
                                     "/sequence/sky.gltf' '" + out_dir_ + "/sequence/sky.gltf.screenshot.png'");
  EXPECT_EQ(status, 0) << output;
  EXPECT_NE(output.find("\"animations\":\"1\""), std::string::npos) << output;
}

// Every 15 minutes from 09:00 to `end` on 2013-05-27 at Cornell, with the
// style keys of `per_hour` drifting at their rates.
ScheduleResult MorningDrift(const std::string& end, const std::string& per_hour, const std::string& name) {
  return ParseSchedule(fmt::format(R"(
[schedule]
date = 2013-05-27
latitude_deg = 42.44337
longitude_deg = -76.48163
utc_offset_hours = -4.0
times = {{ start = 09:00:00, end = {}, step_minutes = 15 }}
[schedule.per_hour]
{})",
                                   end, per_hour),
                       name);
}

// A bake into a fresh temporary folder under the validation layer.
BakeOptions ValidatedBakeOptions(const std::string& name) {
  BakeOptions options;
  options.out_dir = (fs::temp_directory_path() / fmt::format("skybake-{}-test-{}", name, ::getpid())).string();
  options.vulkan.validation = true;
  options.force = true;
  return options;
}

// MorningDrift of the default style with `overrides`, baked into a fresh
// folder NAME under the validation layer (which says nothing): the schedule,
// the frames' styles, the options and the bake.
struct DriftBake {
  ScheduleResult schedule;
  FrameStyles styles;
  BakeOptions options;
  BakeResult result;
};
void BakeDrift(const std::string& end, const std::string& per_hour, const std::vector<std::string>& overrides,
               const std::string& name, DriftBake& bake) {
  bake.schedule = MorningDrift(end, per_hour, name + ".toml");
  ASSERT_TRUE(bake.schedule.ok());
  bake.styles = ResolveFrameStyles(testing::SourceDir() + "/configs/default.toml", overrides, bake.schedule.schedule);
  ASSERT_TRUE(bake.styles.ok()) << bake.styles.errors[0].Format();
  bake.options = ValidatedBakeOptions(name);
  bake.result = BakeSequence(bake.styles.styles, bake.schedule.schedule, bake.options);
  EXPECT_EQ(bake.result.validation_messages, 0);
}

// A scheduled drift of the atmosphere's constants changes uniforms and LUTs
// only: one renderer, its pipelines compiled once, the transmittance and
// multiple-scattering LUTs rebuilt per frame; and the frames differ.
TEST(SequenceDrift, AtmosphereDriftKeepsThePipelines) {
  DriftBake drift;
  ASSERT_NO_FATAL_FAILURE(BakeDrift("09:30:00", R"(
"atmosphere.mie.scattering_per_km" = 0.004
"atmosphere.mie.extinction_per_km" = 0.0044
)",
                                    kSmall, "drift", drift));
  const BakeResult& result = drift.result;
  ASSERT_EQ(result.frames.size(), 3u);
  EXPECT_EQ(result.renderer_builds, 1);
  // Frames 1, then 3 (the highest sun, for the exposure), then 1, 2, 3.
  EXPECT_EQ(result.atmosphere_updates, 4);
  EXPECT_EQ(result.counters.pipelines, 5);  // transmittance, multiple scattering, sky-view, sky, sun disc
  EXPECT_EQ(result.counters.transmittance_lut_builds, 5);
  EXPECT_EQ(result.counters.multiscattering_lut_builds, 5);
  // The haze grows: frames differ in their files.
  EXPECT_NE(result.frames[0].files[0].sha256, result.frames[2].files[0].sha256);
  fs::remove_all(drift.options.out_dir);
}

// A drift that switches an effect on mid-sequence needs another shader
// variant, so a new renderer, while the writer thread still encodes the last
// frame of the old one straight from its memory (RenderInPlace): the old
// renderer must live until that frame is written. Every frame's files equal
// those of a bake of that frame alone.
TEST(SequenceDrift, NewShaderVariantMidSequenceLeavesTheFrameBeingWrittenIntact) {
  // The disc pruned in the first frame (strength 0), on from the second.
  DriftBake drift;
  ASSERT_NO_FATAL_FAILURE(BakeDrift(
      "09:45:00", R"(
"effects.sun_disc_strength" = 1.5
)",
      {"render.cube_size=128", "render.latlong_height=128", "effects.sun_disc_strength=0"}, "variants", drift));
  const BakeResult& whole = drift.result;
  const BakeOptions& options = drift.options;
  ASSERT_EQ(whole.frames.size(), 4u);
  EXPECT_GE(whole.renderer_builds, 2);
  for (int number = 1; number <= 4; ++number) {
    BakeOptions alone = options;
    alone.out_dir = options.out_dir + fmt::format("-frame{}", number);
    alone.frames = FrameRange{number, number};
    const BakeResult part = BakeSequence(drift.styles.styles, drift.schedule.schedule, alone);
    ASSERT_EQ(part.frames.size(), 1u);
    const std::vector<BakedFile>& a = whole.frames[size_t(number - 1)].files;
    const std::vector<BakedFile>& b = part.frames[0].files;
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].sha256, b[i].sha256) << "frame " << number << " " << a[i].path;
    fs::remove_all(alone.out_dir);
  }
  fs::remove_all(options.out_dir);
}

// A long sequence's progress manifests cost in proportion to its frames:
// rewritten after every frame, their bytes grew as frames squared (100
// frames wrote about 50 times the final manifest); now after frames 1 to 20
// and then whenever the frames done have grown by a tenth (or every 30 s).
TEST(SequenceCost, ProgressManifestsAddUpToAFewFinalManifests) {
  const std::string root = testing::FreshTempDir("manifestcost");
  const std::string schedule = root + "/hundred.toml";
  std::ofstream(schedule)
      << "[schedule]\nsun = { elevation_deg = { start = 0, end = 49.5, step = 0.5 }, azimuth_deg = 135 }\n";
  testing::CommandRun run =
      testing::RunSkybake("bake '" + testing::SourceDir() + "/configs/default.toml' --schedule '" + schedule +
                          "' --size 1 -q --out '" + root + "/out'");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  nlohmann::json timings = nlohmann::json::parse(std::ifstream(root + "/out/timings.json"));
  const double seconds = timings["total_s"].get<double>();
  const uint64_t final_bytes = std::filesystem::file_size(root + "/out/manifest.json");
  EXPECT_LE(timings["manifest_writes"].get<int>(), 40 + int(seconds / 30.0)) << "100 before";
  EXPECT_LE(timings["manifest_bytes_written"].get<uint64_t>(), (14 + uint64_t(seconds / 30.0)) * final_bytes)
      << "about 50 times before";
  std::filesystem::remove_all(root);
}

// The CLI keeps no frame records (BakeOptions::keep_frame_records = false):
// each frame's files go to the callback as they are recorded, the frames'
// manifest entries and timings stay on disk until the end, and the bake
// writes the same manifest, byte for byte, and the same timings entries as
// one that keeps every record.
TEST(SequenceCost, BakeWithoutFrameRecordsWritesTheSameManifest) {
  DriftBake drift;
  ASSERT_NO_FATAL_FAILURE(BakeDrift("09:45:00", R"(
"atmosphere.ground_albedo" = 0.05
)",
                                    kSmall, "records-kept", drift));
  const std::vector<SkyStyle>& styles = drift.styles.styles;
  const Schedule& schedule = drift.schedule.schedule;
  const BakeOptions& kept = drift.options;
  const BakeResult& with_records = drift.result;
  BakeOptions streamed = ValidatedBakeOptions("records-streamed");
  streamed.keep_frame_records = false;
  std::vector<BakedFile> reported;
  streamed.frame_files = [&](const std::vector<BakedFile>& files) {
    reported.insert(reported.end(), files.begin(), files.end());
  };
  const BakeResult without = BakeSequence(styles, schedule, streamed);
  EXPECT_EQ(without.validation_messages, 0);
  ASSERT_EQ(with_records.frames.size(), 4u);
  EXPECT_TRUE(without.frames.empty());
  EXPECT_TRUE(without.stages.empty());
  // The frames' files reported in order, then the rest kept.
  ASSERT_EQ(reported.size() + without.files.size(), with_records.files.size());
  for (size_t i = 0; i < with_records.files.size(); ++i) {
    const BakedFile& a = with_records.files[i];
    const BakedFile& b = i < reported.size() ? reported[i] : without.files[i - reported.size()];
    EXPECT_EQ(fs::path(a.path).filename(), fs::path(b.path).filename());
    EXPECT_EQ(a.kind, b.kind);
    EXPECT_EQ(a.sha256, b.sha256) << a.path;
  }
  EXPECT_EQ(testing::ReadFileBytes(kept.out_dir + "/manifest.json"),
            testing::ReadFileBytes(streamed.out_dir + "/manifest.json"));
  EXPECT_EQ(testing::ReadFileBytes(kept.out_dir + "/sky.gltf"), testing::ReadFileBytes(streamed.out_dir + "/sky.gltf"));
  // timings.json: the same entries (their times differ from run to run).
  const json a = json::parse(std::ifstream(kept.out_dir + "/timings.json"));
  const json b = json::parse(std::ifstream(streamed.out_dir + "/timings.json"));
  ASSERT_EQ(a["frames"].size(), 4u);
  ASSERT_EQ(b["frames"].size(), 4u);
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(a["frames"][i]["frame"], b["frames"][i]["frame"]);
    EXPECT_EQ(a["frames"][i]["gpu_passes"].size(), b["frames"][i]["gpu_passes"].size());
  }
  // The stages in the same order ("waiting for files" apart: it shows only
  // when a wait took over 5 ms).
  auto stage_names = [](const json& timings) {
    std::vector<std::string> names;
    for (const json& stage : timings["stages"])
      if (stage["stage"] != "waiting for files") names.push_back(stage["stage"].get<std::string>());
    return names;
  };
  EXPECT_EQ(stage_names(a), stage_names(b));
  EXPECT_GT(stage_names(a).size(), 8u);
  // Nothing left beside the outputs: the records on disk had no name.
  EXPECT_EQ(testing::FileNames(kept.out_dir), testing::FileNames(streamed.out_dir));
  fs::remove_all(kept.out_dir);
  fs::remove_all(streamed.out_dir);
}

}  // namespace
}  // namespace skybake
