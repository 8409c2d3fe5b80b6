// Sequence bakes split for a farm, through the binary under the validation
// layer: shards (--shard I/N) and frame ranges (--frames A:B) write the same
// bytes as an unsharded bake of the same frames, merge-manifest joins their
// manifests into the unsharded bake's manifest.json and glTF scene byte for
// byte, and bad values or missing parts are refused with the fix.
#include <filesystem>
#include <functional>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "skybake/input/frame_numbering.h"
#include "test_support.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;
using testing::CommandRun;
using testing::FileNames;
using testing::FreshTempDir;
using testing::ReadFileBytes;
using testing::RunSkybake;

// Six clock times numbered from 11, so frame numbers and indices differ;
// frame 13 changes the atmosphere, so the renderer is rebuilt mid-sequence
// and a shard may start on a rebuilt one.
constexpr const char* kSixFrames = R"([schedule]
first_frame = 11
date = 2013-05-27
latitude_deg = 42.44337
longitude_deg = -76.48163
utc_offset_hours = -4.0

[[schedule.frames]]
time = 07:00:00
[[schedule.frames]]
time = 08:00:00
[[schedule.frames]]
time = 09:00:00
set = { "atmosphere.mie.g" = 0.7 }
[[schedule.frames]]
time = 10:00:00
[[schedule.frames]]
time = 11:00:00
[[schedule.frames]]
time = 12:00:00
)";

std::string Style() { return testing::SourceDir() + "/configs/default.toml"; }

class Shard : public ::testing::Test {
 protected:
  // One folder per process (ctest runs each test in its own), with the
  // schedule and, on first use, the unsharded bake to compare against.
  static void SetUpTestSuite() {
    root_ = FreshTempDir("shard");
    schedule_ = root_ + "/six.toml";
    std::ofstream(schedule_) << kSixFrames;
  }
  static void TearDownTestSuite() { fs::remove_all(root_); }

  // `skybake bake` of the six frames at 16^3, validation on, plus `extra`.
  static CommandRun Bake(const std::string& out, const std::string& extra) {
    return RunSkybake("bake '" + Style() + "' --schedule '" + schedule_ + "' --size 16 -q --vulkan-validation --out '" +
                      out + "' " + extra);
  }
  static const std::string& Whole() {
    static const std::string whole = [] {
      const std::string out = root_ + "/whole";
      CommandRun run = Bake(out, "");
      EXPECT_EQ(run.exit_code, 0) << run.output;
      return out;
    }();
    return whole;
  }
  // Every file of the unsharded bake is in `dir` with the same bytes
  // (manifest.json and the glTF scene included), timings.json apart.
  static void ExpectSameAsWhole(const std::string& dir) {
    const std::set<std::string> whole = FileNames(Whole());
    ASSERT_EQ(whole.size(), 6u * 9 + 3 + 2) << "9 files per frame, the scene, manifest.json, timings.json";
    for (const std::string& name : whole) {
      if (name == "timings.json") continue;
      ASSERT_TRUE(fs::exists(dir + "/" + name)) << name;
      EXPECT_TRUE(ReadFileBytes(dir + "/" + name) == ReadFileBytes(Whole() + "/" + name)) << name << " differs";
    }
  }

  static std::string root_, schedule_;
};
std::string Shard::root_, Shard::schedule_;

TEST_F(Shard, ThreeShardsInOneFolderMergeToTheUnshardedBake) {
  const std::string out = root_ + "/farm";
  for (int i = 1; i <= 3; ++i) {
    CommandRun run = Bake(out, fmt::format("--shard {}/3", i));
    ASSERT_EQ(run.exit_code, 0) << run.output;
  }
  // Contiguous blocks of two, each with its own manifest and no scene yet.
  const std::set<std::string> names = FileNames(out);
  for (const char* name : {"manifest.shard-0011-0012.json", "manifest.shard-0013-0014.json",
                           "manifest.shard-0015-0016.json", "timings.shard-0013-0014.json"})
    EXPECT_TRUE(names.count(name)) << name;
  for (const char* name : {"manifest.json", "sky.gltf", "sky.glb", "timings.json"})
    EXPECT_FALSE(names.count(name)) << name;
  nlohmann::json part = nlohmann::json::parse(std::ifstream(out + "/manifest.shard-0013-0014.json"));
  EXPECT_EQ(part["part"], nlohmann::json({{"first_frame", 13}, {"last_frame", 14}, {"frames", 2}, {"of_frames", 6}}));
  ASSERT_EQ(part["frames"].size(), 2u);
  EXPECT_EQ(part["frames"][0]["frame"].get<int>(), 13);
  EXPECT_TRUE(part["complete"].get<bool>());
  EXPECT_TRUE(part["scene"].empty());

  CommandRun merge = RunSkybake("merge-manifest '" + out + "'");
  ASSERT_EQ(merge.exit_code, 0) << merge.output;
  EXPECT_NE(merge.output.find("6 frames from 3 parts"), std::string::npos) << merge.output;
  ExpectSameAsWhole(out);

  // --resume against the shard's own manifest: every frame verified, none
  // rendered again, no byte changed.
  CommandRun resume = RunSkybake("bake '" + Style() + "' --schedule '" + schedule_ +
                                 "' --size 16 --vulkan-validation --out '" + out + "' --shard 2/3 --resume");
  ASSERT_EQ(resume.exit_code, 0) << resume.output;
  EXPECT_NE(resume.output.find("resuming from 2 frame(s) in manifest.shard-0013-0014.json"), std::string::npos)
      << resume.output;
  EXPECT_EQ(resume.output.find(" 8 views"), std::string::npos) << "a frame was rendered again: " << resume.output;
  ExpectSameAsWhole(out);
  // A merge is not repeated over its result without --force.
  CommandRun again = RunSkybake("merge-manifest '" + out + "'");
  EXPECT_EQ(again.exit_code, 6) << again.output;
  EXPECT_EQ(RunSkybake("merge-manifest --force '" + out + "'").exit_code, 0);
  ExpectSameAsWhole(out);
}

TEST_F(Shard, FrameRangesInSeparateFoldersCopiedTogetherMergeToTheUnshardedBake) {
  // Three machines: frames 11-13, then 14-16 split in two shards (14, 15-16).
  const std::string a = root_ + "/a", b = root_ + "/b", c = root_ + "/c";
  CommandRun run = Bake(a, "--frames 11:13");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  run = Bake(b, "--frames 14:16 --shard 1/2");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  run = Bake(c, "--frames 14:16 --shard 2/2");
  ASSERT_EQ(run.exit_code, 0) << run.output;

  // --frames 11:13 bakes exactly frames 11, 12 and 13.
  std::set<std::string> expected = {"manifest.shard-0011-0013.json", "timings.shard-0011-0013.json"};
  for (int frame = 11; frame <= 13; ++frame)
    for (const char* kind : {"px", "nx", "py", "ny", "pz", "nz", "cube", "latlong"}) {
      expected.insert(fmt::format("sky_{}.{:04d}.exr", kind, frame));
      if (std::string(kind) == "latlong") expected.insert(fmt::format("sky_latlong.{:04d}.png", frame));
    }
  EXPECT_EQ(FileNames(a), expected);
  EXPECT_TRUE(FileNames(b).count("manifest.shard-0014-0014.json"));
  EXPECT_TRUE(FileNames(c).count("manifest.shard-0015-0016.json"));

  const std::string together = root_ + "/together";
  fs::create_directories(together);
  for (const std::string& dir : {a, b, c})
    for (const auto& e : fs::directory_iterator(dir))
      fs::copy_file(e.path(), together + "/" + e.path().filename().string());
  CommandRun merge = RunSkybake("merge-manifest '" + together + "'");
  ASSERT_EQ(merge.exit_code, 0) << merge.output;
  ExpectSameAsWhole(together);
}

TEST_F(Shard, MergeRefusesMissingFramesAndPartsOfAnotherBake) {
  const std::string out = root_ + "/gap";
  for (const char* shard : {"1/3", "3/3"}) {
    CommandRun run = Bake(out, std::string("--shard ") + shard);
    ASSERT_EQ(run.exit_code, 0) << run.output;
  }
  CommandRun missing = RunSkybake("merge-manifest '" + out + "'");
  EXPECT_EQ(missing.exit_code, 8) << missing.output;
  EXPECT_NE(missing.output.find("skybake: error: frames 13-14 of 11-16 are missing"), std::string::npos)
      << missing.output;
  EXPECT_NE(missing.output.find("--frames 13:14"), std::string::npos) << "names the fix: " << missing.output;
  EXPECT_FALSE(fs::exists(out + "/manifest.json"));
  EXPECT_FALSE(fs::exists(out + "/sky.gltf"));

  // The middle shard of another bake (another haze): its frames' files
  // would not belong to the same sequence.
  CommandRun other = Bake(out, "--shard 2/3 --set atmosphere.mie.g=0.75");
  ASSERT_EQ(other.exit_code, 0) << other.output;
  CommandRun mixed = RunSkybake("merge-manifest --sizes-only '" + out + "'");
  EXPECT_EQ(mixed.exit_code, 8) << mixed.output;
  EXPECT_NE(mixed.output.find("come from different bakes"), std::string::npos) << mixed.output;
  EXPECT_NE(mixed.output.find("manifest.shard-0013-0014.json"), std::string::npos)
      << "names the file: " << mixed.output;
  EXPECT_FALSE(fs::exists(out + "/manifest.json"));

  // A listed file that is gone is named, with the part it belongs to.
  CommandRun forced = Bake(out, "--shard 2/3 --force");
  ASSERT_EQ(forced.exit_code, 0) << forced.output;
  fs::remove(out + "/sky_nz.0015.exr");
  CommandRun gone = RunSkybake("merge-manifest '" + out + "'");
  EXPECT_EQ(gone.exit_code, 8) << gone.output;
  EXPECT_NE(gone.output.find("sky_nz.0015.exr, listed in " + out + "/manifest.shard-0015-0016.json, is missing"),
            std::string::npos)
      << gone.output;
}

// Hostile or edited shard manifests: every name read from a part must be a
// plain file name and the one the bake gives that frame and kind, the
// frames must give the parts' sequence_sha256, sizes must be integers in
// range; anything else is exit 8, before any file under such a name is
// opened (no size of a file outside the folder is ever shown) and with
// nothing written.
// An edit of a shard manifest that merge-manifest must refuse (exit 8).
struct ManifestEdit {
  const char* name;
  const char* part;  // the manifest edited
  std::function<void(nlohmann::json&)> edit;
  std::string message;  // expected in the output
};

// Names from the manifests that would leave the folder or name another
// file, and values skybake never writes.
std::vector<ManifestEdit> HostileManifestEdits() {
  auto file = [](int n) {
    return [n](nlohmann::json& m) -> nlohmann::json& { return m["frames"][0]["files"][n]["file"]; };
  };
  return {
      {"gltf name escapes", "0001-0001", [](nlohmann::json& m) { m["gltf"]["name"] = "../evil"; },
       "gltf.name: '../evil' is not a plain file name"},
      {"gltf name absolute", "0001-0001", [](nlohmann::json& m) { m["gltf"]["name"] = "/tmp/evil"; },
       "gltf.name: '/tmp/evil' is not a plain file name"},
      {"texture escapes", "0002-0002", [](nlohmann::json& m) { m["gltf"]["texture"]["file"] = "../secret.png"; },
       "gltf.texture.file: '../secret.png' is not a plain file name of a PNG in the folder"},
      {"frame file escapes", "0001-0001", [file](nlohmann::json& m) { file(0)(m) = "../../../etc/passwd"; },
       "frame 1: '../../../etc/passwd' is not the face file skybake names for frame 1 (....0001.exr)"},
      {"frame file absolute", "0001-0001", [file](nlohmann::json& m) { file(6)(m) = "/etc/passwd"; },
       "frame 1: '/etc/passwd' is not the cube strip file skybake names for frame 1"},
      {"frame file in a sub-folder", "0001-0001",
       [file](nlohmann::json& m) { file(7)(m) = "sub/sky_latlong.0001.exr"; },
       "frame 1: 'sub/sky_latlong.0001.exr' is not the latlong file skybake names for frame 1"},
      {"frame file with a newline", "0001-0001", [file](nlohmann::json& m) { file(1)(m) = "sky_nx.0001.exr\nX"; },
       "frame 1: 'sky_nx.0001.exr\\nX' is not the face file skybake names for frame 1"},
      {"another frame's file", "0001-0001", [file](nlohmann::json& m) { file(7)(m) = "sky_latlong.0002.exr"; },
       "frame 1: 'sky_latlong.0002.exr' is not the latlong file skybake names for frame 1 (....0001.exr)"},
      {"kind swapped", "0001-0001", [](nlohmann::json& m) { m["frames"][0]["files"][6]["kind"] = "latlong"; },
       "frame 1: 'sky_cube.0001.exr' is not the latlong file skybake names for frame 1 (BASE_latlong.0001)"},
      {"unknown kind", "0001-0001", [](nlohmann::json& m) { m["frames"][0]["files"][6]["kind"] = "secret"; },
       "frame 1: 'secret' is not a kind of file skybake writes"},
      {"negative size", "0001-0001", [](nlohmann::json& m) { m["frames"][0]["files"][0]["bytes"] = -1; },
       "'bytes' is -1, not an integer in [0, 9007199254740992]"},
      {"fractional size", "0001-0001", [](nlohmann::json& m) { m["frames"][0]["files"][0]["bytes"] = 1.5; },
       "'bytes' is 1.5, not an integer in [0, 9007199254740992]"},
      {"huge frame number", "0001-0001", [](nlohmann::json& m) { m["frames"][0]["frame"] = 4294967297.0; },
       "'frame' is 4294967297.0, not an integer"},
      {"edited style hash", "0001-0001",
       [](nlohmann::json& m) { m["frames"][0]["style_sha256"] = std::string(64, '0'); },
       "do not give their sequence_sha256: a manifest was edited"},
      {"edited sun", "0002-0002", [](nlohmann::json& m) { m["frames"][0]["sun"]["direction"][1] = 0.5; },
       "do not give their sequence_sha256"},
      {"face label edited", "0001-0001", [](nlohmann::json& m) { m["frames"][0]["files"][0]["face"] = "-X"; },
       "frame 1: '-X' is not the face of the frame's face file 1 (+X: +X, -X, +Y, -Y, +Z, -Z in that order)"},
      {"face label missing", "0001-0001", [](nlohmann::json& m) { m["frames"][0]["files"][2].erase("face"); },
       "no 'face'"},
      // Values skybake never writes (the style's ranges): exit 8 naming the
      // entry and the frame, never a scene of infinities or a 2^31-frame loop.
      {"gltf radius huge", "0001-0001", [](nlohmann::json& m) { m["gltf"]["radius_m"] = 1e308; },
       "'radius_m' is 1e+308, not a number in [0.001, 100000000]"},
      {"sun illuminance huge", "0002-0002", [](nlohmann::json& m) { m["frames"][0]["sun"]["illuminance_lux"] = 1e300; },
       "frame 2: 'illuminance_lux' is 1e+300, not a number in [0, 1000000000000]"},
      {"sun direction huge", "0002-0002", [](nlohmann::json& m) { m["frames"][0]["sun"]["direction"][0] = -1e308; },
       "frame 2: 'direction'[0] is -1e+308, not a number in [-1, 1]"},
      {"denormal sun radius", "0001-0001",
       [](nlohmann::json& m) { m["frames"][0]["sun"]["angular_radius_rad"] = 5e-324; },
       "frame 1: 'angular_radius_rad' is 5e-324, not a number in [1e-06, 0.5]"},
      {"sun elevation of the wrong type", "0001-0001",
       [](nlohmann::json& m) { m["frames"][0]["sun"]["elevation_deg"] = "high"; },
       "frame 1: 'elevation_deg' has the wrong type"},
      {"animation time negative", "0002-0002", [](nlohmann::json& m) { m["frames"][0]["animation_time_s"] = -1.0; },
       "frame 2: 'animation_time_s' is -1.0, not a number in [0, 10000000]"},
      {"part of 2^31 frames", "0001-0001", [](nlohmann::json& m) { m["part"]["last_frame"] = 2147483647; },
       "'last_frame' is 2147483647, not an integer in [1, 10099999]"},
      {"exposure huge", "0001-0001", [](nlohmann::json& m) { m["exposure_ev100"] = 1e308; },
       "'exposure_ev100' is 1e+308, not a number in [-100, 100]"},
      {"texture of another frame", "0001-0001",
       [](nlohmann::json& m) { m["gltf"]["texture"]["file"] = "sky_latlong.0001.png"; },
       "gltf.texture.file 'sky_latlong.0001.png' of the shard manifests in "},
  };
}

TEST(ShardManifest, MergeRefusesNamesAndValuesTheBakeWouldNotWrite) {
  const std::string root = FreshTempDir("hostile");
  const std::string schedule = root + "/two.toml";
  std::ofstream(schedule) << "[schedule]\nsun = { elevation_deg = [10, 20], azimuth_deg = 135 }\n";
  const std::string parts = root + "/parts";
  for (const char* shard : {"1/2", "2/2"}) {
    CommandRun run = RunSkybake("bake '" + Style() + "' --schedule '" + schedule + "' --size 8 -q --out '" + parts +
                                "' --shard " + shard);
    ASSERT_EQ(run.exit_code, 0) << run.output;
  }
  std::ofstream(root + "/secret.png") << "secret";
  const std::vector<ManifestEdit> cases = HostileManifestEdits();
  for (const ManifestEdit& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string dir = root + "/case";
    fs::remove_all(dir);
    fs::copy(parts, dir);
    // Both parts share the sequence-wide entries: edit those in both.
    for (const char* part : {"0001-0001", "0002-0002"}) {
      const std::string path = dir + "/manifest.shard-" + part + ".json";
      nlohmann::json m = nlohmann::json::parse(std::ifstream(path));
      const bool shared = std::string(c.name).rfind("gltf", 0) == 0 || std::string(c.name).rfind("texture", 0) == 0;
      if (shared || std::string(part) == c.part) c.edit(m);
      std::ofstream(path) << m.dump(2);
    }
    const std::set<std::string> before = FileNames(dir);
    CommandRun run = RunSkybake("merge-manifest --force '" + dir + "'");
    EXPECT_EQ(run.exit_code, 8) << run.output;
    EXPECT_NE(run.output.find(c.message), std::string::npos) << run.output;
    EXPECT_EQ(run.output.find("bytes, listed with"), std::string::npos) << "no size shown: " << run.output;
    EXPECT_EQ(FileNames(dir), before) << "nothing written";
    EXPECT_FALSE(fs::exists(root + "/evil.gltf"));
    EXPECT_FALSE(fs::exists("/tmp/evil.glb"));
  }
  // A listed file replaced by a link (to a copy of itself) is not followed.
  {
    const std::string dir = root + "/case";
    fs::remove_all(dir);
    fs::copy(parts, dir);
    fs::rename(dir + "/sky_latlong.0002.png", root + "/moved.png");
    fs::create_symlink(root + "/moved.png", dir + "/sky_latlong.0002.png");
    CommandRun run = RunSkybake("merge-manifest --sizes-only '" + dir + "'");
    EXPECT_EQ(run.exit_code, 8) << run.output;
    EXPECT_NE(run.output.find("sky_latlong.0002.png, listed in " + dir +
                              "/manifest.shard-0002-0002.json, is a symbolic link, which is not followed here"),
              std::string::npos)
        << run.output;
  }
  // A dangling link planted at the merged manifest's name is a file there:
  // refused without --force (exit 6), the link left as it was.
  {
    const std::string dir = root + "/case";
    fs::remove_all(dir);
    fs::copy(parts, dir);
    fs::create_symlink(root + "/nowhere/manifest.json", dir + "/manifest.json");
    CommandRun run = RunSkybake("merge-manifest '" + dir + "'");
    EXPECT_EQ(run.exit_code, 6) << run.output;
    EXPECT_NE(run.output.find(dir + "/manifest.json already exists: pass --force to replace it"), std::string::npos)
        << run.output;
    EXPECT_TRUE(fs::is_symlink(fs::symlink_status(dir + "/manifest.json")));
    EXPECT_FALSE(fs::exists(root + "/nowhere"));
  }
  // Two face files of part 1 swapped on disk and in its manifest, sizes and
  // checksums with them: every name is a face name and each part is
  // consistent on its own, but the two parts name the +X face differently.
  {
    const std::string dir = root + "/case";
    fs::remove_all(dir);
    fs::copy(parts, dir);
    fs::rename(dir + "/sky_px.0001.exr", dir + "/swap.exr");
    fs::rename(dir + "/sky_nx.0001.exr", dir + "/sky_px.0001.exr");
    fs::rename(dir + "/swap.exr", dir + "/sky_nx.0001.exr");
    const std::string path = dir + "/manifest.shard-0001-0001.json";
    nlohmann::json m = nlohmann::json::parse(std::ifstream(path));
    nlohmann::json& files = m["frames"][0]["files"];
    ASSERT_EQ(files[0]["face"], "+X");
    ASSERT_EQ(files[1]["face"], "-X");
    std::swap(files[0]["file"], files[1]["file"]);
    std::swap(files[0]["bytes"], files[1]["bytes"]);
    std::swap(files[0]["sha256"], files[1]["sha256"]);
    std::ofstream(path) << m.dump(2);
    const std::set<std::string> before = FileNames(dir);
    CommandRun run = RunSkybake("merge-manifest --force '" + dir + "'");
    EXPECT_EQ(run.exit_code, 8) << run.output;
    EXPECT_NE(run.output.find("frame 2: 'sky_px.0002.exr' is not the +X face file of frame 2: the other frames name "
                              "that face 'nx' (sky_nx.0002.exr)"),
              std::string::npos)
        << run.output;
    EXPECT_EQ(FileNames(dir), before) << "nothing written";
  }
  // The untouched parts merge.
  CommandRun merged = RunSkybake("merge-manifest '" + parts + "'");
  EXPECT_EQ(merged.exit_code, 0) << merged.output;
  fs::remove_all(root);
}

TEST_F(Shard, BadFramesAndShardsAreUsageErrorsBeforeAnyGpuWork) {
  const std::string out = root_ + "/bad";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--shard 0/3", "--shard 0/3: shards are counted from 1: use 1/3 to 3/3"},
      {"--shard 4/3", "--shard 4/3: shard 4 does not exist among 3: use 1/3 to 3/3"},
      {"--shard 1/0", "--shard 1/0: the number of shards must be at least 1"},
      {"--shard two/3", "--shard two/3: expected I/N"},
      {"--shard 3", "--shard 3: expected I/N"},
      {"--shard 7/7", "--shard 7/7: 6 frames (11 to 16) cannot make 7 shards: use at most 6 shards"},
      {"--frames 14:12", "--frames 14:12: the last frame comes before the first: use --frames 12:14"},
      {"--frames 1:3", "--frames 1:3: " + schedule_ + " has frames 11 to 16"},
      {"--frames 12:17", "--frames 12:17: " + schedule_ + " has frames 11 to 16"},
      {"--frames a:b", "--frames a:b: expected FIRST:LAST"},
      {"--frames 12", "--frames 12: expected FIRST:LAST"},
      {"--frames 11:12 --shard 3/3", "--shard 3/3: 2 frames (11 to 12) cannot make 3 shards"},
  };
  for (const auto& [args, message] : cases) {
    CommandRun run = Bake(out, args);
    EXPECT_EQ(run.exit_code, 2) << args << ": " << run.output;
    EXPECT_EQ(run.output.rfind("skybake: error: " + message, 0), 0u) << args << ": " << run.output;
    EXPECT_EQ(run.output.find("skybake: device"), std::string::npos) << "no GPU work";
  }
  CommandRun single = RunSkybake("bake '" + Style() + "' --size 16 --shard 1/2 --out '" + out + "'");
  EXPECT_EQ(single.exit_code, 2) << single.output;
  EXPECT_NE(single.output.find("--frames and --shard split a sequence bake: give --schedule"), std::string::npos)
      << single.output;
  EXPECT_FALSE(fs::exists(out)) << "nothing written";

  CommandRun help = RunSkybake("--help");
  EXPECT_NE(help.output.find("merge-manifest"), std::string::npos) << help.output;
  CommandRun bake_help = RunSkybake("bake --help");
  EXPECT_NE(bake_help.output.find("--shard I/N"), std::string::npos) << bake_help.output;
  EXPECT_NE(bake_help.output.find("--frames FIRST:LAST"), std::string::npos) << bake_help.output;
}

// Every frame of a sequence has the same number width, the one its last
// frame needs (at least four digits): frames 9,998 to 10,001 of a schedule
// numbered 9,996 to 10,001 are named .09998 to .10001 (not .9998 beside
// .10000), and a --resume of them finds them; a schedule ending at 9,999
// keeps today's four digits.
TEST(FrameNumbering, EveryFrameOfASequenceHasTheWidthOfItsLastFrame) {
  EXPECT_EQ(FrameNumberWidth(0), 4);
  EXPECT_EQ(FrameNumberWidth(9999), 4);
  EXPECT_EQ(FrameNumberWidth(10000), 5);
  EXPECT_EQ(FrameNumberWidth(100000), 6);
  EXPECT_EQ(FrameNumberSuffix(12), ".0012");
  EXPECT_EQ(FrameNumberSuffix(12, 5), ".00012");
  EXPECT_EQ(FrameNumberSuffix(0, 5), "");
  const std::string root = FreshTempDir("padding");
  for (int last : {10001, 9999}) {
    SCOPED_TRACE(last);
    const std::string schedule = fmt::format("{}/sun{}.toml", root, last);
    std::ofstream(schedule) << fmt::format(
        "[schedule]\nfirst_frame = {}\nsun = {{ elevation_deg = {{ start = 0, end = 5, step = 1 }}, "
        "azimuth_deg = 135 }}\n",
        last - 5);
    const std::string out = fmt::format("{}/out{}", root, last);
    // Names only: no validation layer, which makes lavapipe several times slower.
    const std::string bake = "bake '" + Style() + "' --schedule '" + schedule +
                             "' --size 1 --frames 9998:" + std::to_string(last) + " --out '" + out + "'";
    CommandRun run = RunSkybake(bake + " -q");
    ASSERT_EQ(run.exit_code, 0) << run.output;
    std::set<std::string> faces;
    for (const std::string& name : FileNames(out))
      if (name.rfind("sky_px.", 0) == 0) faces.insert(name);
    if (last == 10001) {
      EXPECT_EQ(faces, (std::set<std::string>{"sky_px.09998.exr", "sky_px.09999.exr", "sky_px.10000.exr",
                                              "sky_px.10001.exr"}));
      EXPECT_TRUE(fs::exists(out + "/sky_latlong.09998.png"));
      EXPECT_TRUE(fs::exists(out + "/manifest.shard-9998-10001.json"));
    } else {
      EXPECT_EQ(faces, (std::set<std::string>{"sky_px.9998.exr", "sky_px.9999.exr"}));
    }
    // The part's manifest names are the ones the bake gives: --resume
    // verifies every frame and renders none again.
    CommandRun resume = RunSkybake(bake + " --resume");
    EXPECT_EQ(resume.exit_code, 0) << resume.output;
    size_t verified = 0;
    for (size_t at = 0; (at = resume.output.find("files verified by checksum", at)) != std::string::npos; ++at)
      ++verified;
    EXPECT_EQ(verified, last == 10001 ? 4u : 2u) << resume.output;
  }
  fs::remove_all(root);
}

}  // namespace
}  // namespace skybake
