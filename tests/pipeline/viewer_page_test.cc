// `skybake view DIR` (viewer_page.h): the page opens in headless Chromium
// with nothing but itself (every request the page makes is listed: only the
// page, the test's report and Chromium's own favicon), the view moves with
// a drag through the page's own pointer handlers, and the screenshot's
// pixels show what lies there: on a `skybake testpattern` folder, the +X
// face's red 10 degrees below the horizon after turning to East, the white
// horizon facing North; the exposure slider darkens; on a two-frame
// sequence the frame slider shows the other frame (the night one, darker).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <glm/glm.hpp>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <nlohmann/json.hpp>

#include "skybake/pipeline/test_pattern.h"
#include "test_support.h"

namespace skybake {
namespace {

struct Shot {
  nlohmann::json report, requests;
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;
  glm::dvec3 At(int x, int y) const {
    const size_t i = 3 * (size_t(y) * width + x);
    return {double(rgb[i]), double(rgb[i + 1]), double(rgb[i + 2])};
  }
  // Mean over the upper half (the panel sits at the bottom left).
  double UpperMean() const {
    double sum = 0.0;
    for (int y = 0; y < height / 2; ++y)
      for (int x = 0; x < width; ++x) sum += At(x, y).x + At(x, y).y + At(x, y).z;
    return sum / (3.0 * width * (height / 2));
  }
};

Shot Open(const std::string& dir, const std::string& test) {
  Shot shot;
  const std::string png = dir + "/shot.png";
  std::remove(png.c_str());
  const nlohmann::json line = testing::RunViewerPage("bake/view.html", dir, png, "test=" + test);
  if (line.is_null()) return shot;
  shot.report = line["report"];
  shot.requests = line["requests"];
  testing::ReadRgb(png, shot.width, shot.height, shot.rgb);
  return shot;
}

double Srgb8(double linear) {
  const double v = linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
  return 255.0 * v;
}

TEST(ViewerPageTest, LooksAroundTheTestPattern) {
  const std::string dir = testing::FreshTempDir("view_pattern");
  ASSERT_EQ(testing::RunSkybake("testpattern --size 256 --out " + dir).exit_code, 0);
  testing::CommandRun view = testing::RunSkybake("view " + dir);
  ASSERT_EQ(view.exit_code, 0) << view.output;
  EXPECT_EQ(testing::RunSkybake("view " + dir).exit_code, 6) << "an existing page is kept without --force";
  EXPECT_EQ(testing::RunSkybake("view --force " + dir).exit_code, 0);

  // Drag 360 px left: a quarter turn to the East; 40 px up: 10 degrees down.
  Shot east = Open(dir, "drag:-360,-40;tonemap:linear");
  ASSERT_EQ(east.report.value("ok", false), true) << east.report.dump();
  EXPECT_EQ(east.report["yaw"], 90);
  EXPECT_EQ(east.report["pitch"], -10);
  EXPECT_EQ(east.requests, nlohmann::json({"/bake/view.html", "/report", "/favicon.ico"}))
      << "the page asks for nothing but itself";
  ASSERT_EQ(east.width, 320);
  const glm::dvec3 red = TestPatternFaceColor(0);
  const glm::dvec3 centre = east.At(160, 120);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(centre[c], Srgb8(red[c]), 4.0) << "the +X face's red at the centre";

  // No drag: facing North on the horizon, white; 10 degrees below, -Z's yellow.
  Shot north = Open(dir, "tonemap:linear");
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(north.At(160, 120)[c], 255.0, 4.0) << "the horizon ahead";
  Shot below = Open(dir, "drag:0,-40;tonemap:linear");
  const glm::dvec3 yellow = TestPatternFaceColor(5);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(below.At(160, 120)[c], Srgb8(yellow[c]), 4.0) << "North's -Z face";

  // Four stops down: a sixteenth of the linear value.
  Shot darker = Open(dir, "drag:-360,-40;tonemap:linear;ev:-4");
  EXPECT_NEAR(darker.At(160, 120).x, Srgb8(red.x / 16.0), 4.0);
}

// The default style baked at 32 into DIR/out over a schedule whose sun
// goes from 30 deg to -10 deg elevation in steps of `step_deg` (azimuth
// 135 deg), and its page (`skybake view DIR/out`).
void BakeAndViewSunSequence(const std::string& dir, int step_deg) {
  const std::string schedule = dir + "/schedule.toml";
  FILE* f = std::fopen(schedule.c_str(), "w");
  ASSERT_TRUE(f);
  std::fputs(
      fmt::format("[schedule]\nsun = {{ elevation_deg = {{ start = 30, end = -10, step = {} }}, azimuth_deg = 135 }}\n",
                  step_deg)
          .c_str(),
      f);
  std::fclose(f);
  testing::CommandRun bake = testing::RunSkybake("bake " + testing::SourceDir() + "/configs/default.toml --schedule " +
                                                 schedule + " --size 32 -q --out " + dir + "/out");
  ASSERT_EQ(bake.exit_code, 0) << bake.output;
  ASSERT_EQ(testing::RunSkybake("view " + dir + "/out").exit_code, 0);
}

TEST(ViewerPageTest, ScrubsTheFramesOfASequence) {
  const std::string dir = testing::FreshTempDir("view_sequence");
  ASSERT_NO_FATAL_FAILURE(BakeAndViewSunSequence(dir, -40));
  Shot day = Open(dir + "/out", "drag:0,40");
  Shot night = Open(dir + "/out", "drag:0,40;frame:1");
  ASSERT_EQ(day.report["frames"], 2);
  EXPECT_EQ(day.report["label"], "frame 1");
  EXPECT_EQ(night.report["label"], "frame 2");
  std::printf("upper-half mean sRGB: frame 1 %.1f, frame 2 %.1f\n", day.UpperMean(), night.UpperMean());
  EXPECT_GT(day.UpperMean(), 40.0) << "the day sky at the bake's exposure";
  EXPECT_LT(night.UpperMean(), 0.5 * day.UpperMean()) << "sun 10 degrees below the horizon, same exposure";
}

// A long sequence: with --embed-mib 0 only the first frame is inside the
// page; the others are referenced by file name and fetched when the slider
// reaches them (the harness serves the folder over HTTP).
TEST(ViewerPageTest, LaterFramesBeyondTheCapAreReferencedNotEmbedded) {
  const std::string dir = testing::FreshTempDir("view_capped");
  ASSERT_NO_FATAL_FAILURE(BakeAndViewSunSequence(dir, -20));
  const auto full = std::filesystem::file_size(dir + "/out/view.html");
  ASSERT_EQ(testing::RunSkybake("view --force --embed-mib 0 " + dir + "/out").exit_code, 0);
  const auto capped = std::filesystem::file_size(dir + "/out/view.html");
  // Each latlong EXR of the sequence, base64 (4/3 of its bytes).
  double latlongs = 0.0;
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir + "/out"))
    if (e.path().extension() == ".exr" && e.path().filename().string().find("_latlong") != std::string::npos) {
      latlongs += double(e.file_size());
      names.push_back(e.path().filename().string());
    }
  std::sort(names.begin(), names.end());
  ASSERT_EQ(names.size(), 3u);
  std::printf("view.html: %ju bytes with every frame inside, %ju with the first only\n", uintmax_t(full),
              uintmax_t(capped));
  const double second_and_third = double(std::filesystem::file_size(dir + "/out/" + names[1]) +
                                         std::filesystem::file_size(dir + "/out/" + names[2]));
  EXPECT_NEAR(double(full - capped), second_and_third * 4.0 / 3.0, 64.0) << "two frames' base64 left out";
  EXPECT_GT(latlongs, 0.0);

  Shot first = Open(dir + "/out", "drag:0,40");
  ASSERT_EQ(first.report.value("ok", false), true) << first.report.dump();
  EXPECT_EQ(first.report["embedded"], 1);
  EXPECT_EQ(first.report["frames"], 3);
  EXPECT_EQ(first.requests, nlohmann::json({"/bake/view.html", "/report", "/favicon.ico"}))
      << "the embedded first frame needs no request";
  Shot third = Open(dir + "/out", "drag:0,40;frame:2");
  ASSERT_EQ(third.report.value("ok", false), true) << third.report.dump();
  EXPECT_EQ(third.report["label"], "frame 3");
  EXPECT_EQ(third.report["shown"], "frame 3");
  bool fetched = false;
  for (const auto& r : third.requests) fetched = fetched || r == "/bake/" + names[2];
  EXPECT_TRUE(fetched) << third.requests.dump() << " should ask for " << names[2];
  std::printf("upper-half mean sRGB: frame 1 %.1f, frame 3 %.1f\n", first.UpperMean(), third.UpperMean());
  EXPECT_LT(third.UpperMean(), 0.5 * first.UpperMean()) << "frame 3 (sun 10 degrees down) is what is shown";
}

TEST(ViewerPageTest, NothingToShowIsRefused) {
  const std::string dir = testing::FreshTempDir("view_empty");
  testing::CommandRun r = testing::RunSkybake("view " + dir);
  EXPECT_EQ(r.exit_code, 5) << r.output;
  EXPECT_NE(r.output.find("holds no latlong to show"), std::string::npos) << r.output;
}

// --embed-mib takes a finite size: NaN, infinities and negatives are a bad
// command line (exit 2), and no page is written.
TEST(ViewerPageTest, EmbedSizeMustBeFinite) {
  const std::string dir = testing::FreshTempDir("view_embed");
  for (const char* value : {"nan", "inf", "-inf", "-1"}) {
    testing::CommandRun r = testing::RunSkybake(std::string("view --embed-mib ") + value + " " + dir);
    EXPECT_EQ(r.exit_code, 2) << value << ": " << r.output;
    EXPECT_NE(r.output.find("expected a finite number at or above 0"), std::string::npos) << r.output;
  }
  EXPECT_FALSE(std::filesystem::exists(dir + "/view.html"));
}

// Names a manifest lists are checked by the one check of listed names and
// opened through the door: a name leaving the folder is exit 8 before any
// file is opened; a link, a FIFO or a link to a device at a plain name is
// refused unread (exit 5); nothing outside the folder reaches the page.
TEST(ViewerPageTest, HostileManifestNamesAndFilesAreRefused) {
  namespace fs = std::filesystem;
  const std::string root = testing::FreshTempDir("view_hostile");
  const std::string secret = testing::WriteFile(root, "secret.exr", "SECRET-BYTES");
  const std::string dir = root + "/bake";
  fs::create_directories(dir);
  ASSERT_EQ(::mkfifo((dir + "/fifo.exr").c_str(), 0600), 0);
  fs::create_symlink(secret, dir + "/link.exr");
  fs::create_symlink("/dev/zero", dir + "/zero.exr");
  testing::WriteFile(dir, "text.exr", "not an EXR");
  struct Case {
    const char* name;
    int exit_code;
    const char* message;
  };
  for (const Case& c : {Case{"../secret.exr", 8, "'../secret.exr' is not a plain file name of the manifest's folder"},
                        Case{"/etc/passwd", 8, "'/etc/passwd' is not a plain file name of the manifest's folder"},
                        Case{"sub/x.exr", 8, "'sub/x.exr' is not a plain file name of the manifest's folder"},
                        Case{"x\\u001b[2J.exr", 8, "'x\\x1b[2J.exr' is not a plain file name"},
                        Case{"link.exr", 5, "link.exr': it is a symbolic link, which is not followed here"},
                        Case{"zero.exr", 5, "zero.exr': it is a symbolic link, which is not followed here"},
                        Case{"fifo.exr", 5, "fifo.exr': it is a FIFO (named pipe), not a regular file"},
                        Case{"text.exr", 5, "text.exr' is not an OpenEXR file"}}) {
    SCOPED_TRACE(c.name);
    testing::WriteFile(
        dir, "manifest.json",
        std::string(R"({"frames": [{"frame": 1, "files": [{"kind": "latlong", "file": ")") + c.name + "\"}]}]}");
    testing::CommandRun r = testing::RunSkybake("view " + dir);
    EXPECT_EQ(r.exit_code, c.exit_code) << r.output;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir + "/view.html"));
  }
  // The manifest itself as a link is not followed either.
  fs::remove(dir + "/manifest.json");
  testing::WriteFile(root, "elsewhere.json", R"({"frames": []})");
  fs::create_symlink(root + "/elsewhere.json", dir + "/manifest.json");
  testing::CommandRun r = testing::RunSkybake("view " + dir);
  EXPECT_EQ(r.exit_code, 5) << r.output;
  EXPECT_NE(r.output.find("manifest.json': it is a symbolic link"), std::string::npos) << r.output;
  fs::remove_all(root);
}

}  // namespace
}  // namespace skybake
