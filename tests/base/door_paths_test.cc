// The paths that were still opened by name, now through the door
// (file_door.h, exr_read.h): the cloud shadow EXR under the glTF ground and
// the Python module's EXR read-back (ReadExrRgba), --progress-json
// (OpenStreamOutput), --resume's check of a frame's files and merge-manifest's
// check of a listed file (RegularFileSize), and the LUT files an OpenColorIO
// config names. A FIFO planted where a file is expected is refused with its
// name, not waited on: every command here runs under `timeout`, so a hang is
// exit 124, a failure, not a stuck test.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include "skybake/base/errors.h"
#include "skybake/input/ocio_color_space.h"
#include "skybake/output/exr_read.h"
#include "skybake/output/gltf_scene.h"
#include "test_support.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;
using testing::CommandRun;
using testing::RunSkybake;

constexpr const char* kTimeout = "timeout 300";

std::string Style() { return testing::SourceDir() + "/configs/default.toml"; }

constexpr const char* kTwoFrames = R"([schedule]
first_frame = 1
date = 2013-05-27
latitude_deg = 42.44337
longitude_deg = -76.48163
utc_offset_hours = -4.0

[[schedule.frames]]
time = 09:00:00
[[schedule.frames]]
time = 12:00:00
)";

// The EXR read-back: a file OpenEXR decodes from the bytes the door read;
// a FIFO, a link, a device, a folder and a file that is not an EXR refused
// with what they are.
TEST(DoorPaths, ExrReadBackRefusesWhatIsNotARegularExr) {
  const std::string dir = testing::FreshTempDir("door_exr");
  testing::WriteTestImage(dir + "/good.exr", 5, 3, 4, [](int x, int y, int c) { return float(x + 10 * y + 100 * c); });
  int w = 0, h = 0;
  std::vector<float> rgba;
  ASSERT_EQ(ReadExrRgba(dir + "/good.exr", w, h, rgba), "");
  EXPECT_EQ(w, 5);
  EXPECT_EQ(h, 3);
  ASSERT_EQ(rgba.size(), 60u);
  EXPECT_EQ(rgba[4 * (2 * 5 + 4) + 1], float(4 + 20 + 100));  // x 4, y 2, green
  ASSERT_EQ(::mkfifo((dir + "/fifo.exr").c_str(), 0600), 0);
  fs::create_symlink(dir + "/good.exr", dir + "/link.exr");
  fs::create_directory(dir + "/folder.exr");
  testing::WriteFile(dir, "text.exr", "not an image at all");
  EXPECT_EQ(ReadExrRgba(dir + "/fifo.exr", w, h, rgba), "is a FIFO (named pipe), not a regular file");
  EXPECT_EQ(ReadExrRgba(dir + "/link.exr", w, h, rgba), "is a symbolic link, which is not followed here");
  EXPECT_EQ(ReadExrRgba("/dev/zero", w, h, rgba), "is a device, not a regular file");
  EXPECT_EQ(ReadExrRgba(dir + "/folder.exr", w, h, rgba), "is a directory, not a file");
  EXPECT_NE(ReadExrRgba(dir + "/text.exr", w, h, rgba).find("is not an OpenEXR file"), std::string::npos);
  EXPECT_TRUE(rgba.empty());
  // The glTF ground's map: refused with its name, and no PNG written.
  try {
    WriteCloudShadowGroundPng(dir + "/fifo.exr", dir + "/ground.png");
    ADD_FAILURE() << "a FIFO was read as the cloud shadow map";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find(dir + "/fifo.exr: cannot read the cloud shadow map for the glTF ground: it "
                                               "is a FIFO"),
              std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(fs::exists(dir + "/ground.png"));
  WriteCloudShadowGroundPng(dir + "/good.exr", dir + "/ground.png");
  EXPECT_TRUE(fs::is_regular_file(dir + "/ground.png"));
  fs::remove_all(dir);
}

// --progress-json: a FIFO no process reads is refused at once (exit 5, before
// anything is baked), as is a folder; /dev/null and a FIFO with a reader are
// written.
TEST(DoorPaths, ProgressJsonRefusesAFifoNoOneReads) {
  const std::string dir = testing::FreshTempDir("door_progress");
  ASSERT_EQ(::mkfifo((dir + "/fifo").c_str(), 0600), 0);
  const std::string bake = "bake '" + Style() + "' --size 16 --dry-run --out '" + dir + "/out' --progress-json ";
  CommandRun fifo = RunSkybake(bake + "'" + dir + "/fifo'", kTimeout);
  EXPECT_EQ(fifo.exit_code, 5) << fifo.output;
  EXPECT_NE(fifo.output.find("--progress-json " + dir +
                             "/fifo cannot be written: it is a FIFO (named pipe) or socket "
                             "that no process reads; nothing was baked"),
            std::string::npos)
      << fifo.output;
  CommandRun folder = RunSkybake(bake + "'" + dir + "'", kTimeout);
  EXPECT_EQ(folder.exit_code, 5) << folder.output;
  EXPECT_NE(folder.output.find("it is a directory, not a file"), std::string::npos) << folder.output;
  EXPECT_FALSE(fs::exists(dir + "/out"));
  CommandRun null = RunSkybake(bake + "/dev/null", kTimeout);
  EXPECT_EQ(null.exit_code, 0) << null.output;
  // A FIFO that a process holds open for reading (the shell opens it
  // read-write, so no wait): written.
  CommandRun read = RunSkybake(bake + "'" + dir + "/fifo'",
                               std::string(kTimeout) + " bash -c 'exec 3<>\"" + dir + "/fifo\"; exec \"$0\" \"$@\"'");
  EXPECT_EQ(read.exit_code, 0) << read.output;
  fs::remove_all(dir);
}

// A bake in two parts, then hostile files planted at its names.
class DoorPathsBaked : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = testing::FreshTempDir("door_paths");
    schedule_ = testing::WriteFile(root_, "two.toml", kTwoFrames);
    for (const char* frames : {"1:1", "2:2"}) {
      CommandRun run = RunSkybake("bake '" + Style() + "' --schedule '" + schedule_ + "' --size 16 -q --out '" + root_ +
                                      "/parts' --frames " + frames,
                                  kTimeout);
      ASSERT_EQ(run.exit_code, 0) << run.output;
    }
  }
  static void TearDownTestSuite() { fs::remove_all(root_); }
  static std::string Copy(const std::string& name) {
    const std::string dir = root_ + "/" + name;
    fs::remove_all(dir);
    fs::copy(root_ + "/parts", dir);
    return dir;
  }
  static std::string root_, schedule_;
};
std::string DoorPathsBaked::root_, DoorPathsBaked::schedule_;

// merge-manifest: a FIFO, a device link or a folder at a listed name is
// refused with the name and the part (exit 8), not opened for long.
TEST_F(DoorPathsBaked, MergeRefusesAFifoAtAListedName) {
  for (const char* kind : {"fifo", "device", "folder"}) {
    const std::string dir = Copy(std::string("merge_") + kind);
    const std::string listed = dir + "/sky_latlong.0002.exr";
    ASSERT_TRUE(fs::remove(listed));
    if (std::string(kind) == "fifo") {
      ASSERT_EQ(::mkfifo(listed.c_str(), 0600), 0);
    }
    if (std::string(kind) == "device") fs::create_symlink("/dev/zero", listed);
    if (std::string(kind) == "folder") fs::create_directory(listed);
    CommandRun run = RunSkybake("merge-manifest '" + dir + "'", kTimeout);
    EXPECT_EQ(run.exit_code, 8) << kind << ": " << run.output;
    const std::string said = std::string(kind) == "fifo"     ? "is a FIFO (named pipe), not a regular file"
                             : std::string(kind) == "device" ? "is a symbolic link, which is not followed here"
                                                             : "is a directory, not a file";
    EXPECT_NE(run.output.find(listed + ", listed in " + dir + "/manifest.shard-0002-0002.json, " + said +
                              ": put the file itself in the folder"),
              std::string::npos)
        << kind << ": " << run.output;
    EXPECT_FALSE(fs::exists(dir + "/manifest.json")) << kind;
  }
}

// --resume: a FIFO planted at a frame's file is refused with its name
// (exit 5) before anything is baked, and left there; a link planted at it
// (to a copy of the file) proves nothing, so the frame is baked again over
// the link, not read through it.
TEST_F(DoorPathsBaked, ResumeRefusesAFifoAndBakesOverALink) {
  const std::string dir = Copy("resume");
  const std::string planted = dir + "/sky_latlong.0002.exr";
  const std::string original = testing::ReadFileBytes(planted);
  const std::string resume =
      "bake '" + Style() + "' --schedule '" + schedule_ + "' --size 16 --out '" + dir + "' --frames 2:2 --resume";
  ASSERT_TRUE(fs::remove(planted));
  ASSERT_EQ(::mkfifo(planted.c_str(), 0600), 0);
  CommandRun fifo = RunSkybake(resume, kTimeout);
  EXPECT_EQ(fifo.exit_code, 5) << fifo.output;
  EXPECT_NE(fifo.output.find(planted + " is not a regular file: an output file cannot replace it"), std::string::npos)
      << fifo.output;
  EXPECT_TRUE(fs::is_fifo(fs::symlink_status(planted)));
  ASSERT_TRUE(fs::remove(planted));
  testing::WriteFile(root_, "copy.exr", original);
  fs::create_symlink(root_ + "/copy.exr", planted);
  CommandRun link = RunSkybake(resume, kTimeout);
  EXPECT_EQ(link.exit_code, 0) << link.output;
  ASSERT_TRUE(fs::is_regular_file(fs::symlink_status(planted))) << link.output;
  EXPECT_EQ(testing::ReadFileBytes(planted), original);
  EXPECT_NE(link.output.find("frame 2"), std::string::npos) << link.output;
}

// An OpenColorIO config whose LUT file is a FIFO, a device or larger than
// 64 MiB is refused with the LUT's name before OpenColorIO opens it; one
// whose LUT is a regular file resolves.
TEST(DoorPaths, OcioConfigWithAHostileLutIsRefused) {
  const std::string dir = testing::FreshTempDir("door_ocio");
  std::string config = testing::ReadFileBytes(testing::SourceDir() + "/tests/colour/ocio/test_config.ocio");
  config += R"(
  - !<ColorSpace>
    name: Lut space
    family: test
    isdata: false
    from_scene_reference: !<FileTransform> {src: lut.spi1d, interpolation: linear}
)";
  testing::WriteFile(dir, "config.ocio", config);
  testing::WriteFile(dir, "good.spi1d", "Version 1\nFrom 0.0 1.0\nLength 2\nComponents 1\n{\n0.0\n1.0\n}\n");
  struct Case {
    const char* name;
    std::function<void(const std::string&)> plant;
    const char* said;
  };
  const std::vector<Case> cases = {
      {"fifo", [](const std::string& p) { ASSERT_EQ(::mkfifo(p.c_str(), 0600), 0); },
       "is a FIFO (named pipe), not a regular file"},
      {"device", [](const std::string& p) { fs::create_symlink("/dev/zero", p); }, "is a device, not a regular file"},
      {"folder", [](const std::string& p) { fs::create_directory(p); }, "is a directory, not a file"},
      {"huge",
       [](const std::string& p) {
         ASSERT_EQ(::truncate(testing::WriteFile(fs::path(p).parent_path().string(), "lut.spi1d", "").c_str(),
                              off_t(65) << 20),
                   0);
       },
       "is 68157440 bytes, more than the 64 MiB a LUT may have"},
  };
  for (const Case& c : cases) {
    const std::string lut = dir + "/lut.spi1d";
    fs::remove_all(lut);
    c.plant(lut);
    const ColorSpaceLookup r = ResolveOutputColorSpace("ACEScg", dir + "/config.ocio");
    EXPECT_FALSE(r.space) << c.name;
    EXPECT_NE(r.error.find("the OpenColorIO config " + dir + "/config.ocio cannot be used: its LUT file 'lut.spi1d' (" +
                           lut + ") " + c.said),
              std::string::npos)
        << c.name << ": " << r.error;
  }
  fs::remove_all(dir + "/lut.spi1d");
  fs::copy_file(dir + "/good.spi1d", dir + "/lut.spi1d");
  const ColorSpaceLookup ok = ResolveOutputColorSpace("ACEScg", dir + "/config.ocio");
  EXPECT_TRUE(ok.space) << ok.error;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace skybake
