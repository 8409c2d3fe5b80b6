// Twilight frames whose march cannot show (pipeline/twilight_skip.h; the
// CLI's SKYBAKE_TWILIGHT_SKIP=1): a sequence's deep twilight frames render
// without the twilight band march when their probe says the march would
// not change their half floats, the
// bake says which, and their files match those of the marched bake to
// within one half-float step (the frames above are byte for byte the same).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "test_support.h"

namespace skybake {
namespace {

std::string Bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// The largest difference of two images of half floats, in half-float steps of the larger value.
double HalfStepsApart(const std::vector<float>& a, const std::vector<float>& b) {
  double worst = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    const double larger = std::max(std::fabs(double(a[i])), std::fabs(double(b[i])));
    const double step = larger < 0x1p-14 ? 0x1p-24 : std::ldexp(1.0, std::ilogb(larger) - 10);
    worst = std::max(worst, std::fabs(double(a[i]) - double(b[i])) / step);
  }
  return worst;
}

TEST(TwilightSkipTest, DeepTwilightFramesGoUnmarchedWithinAHalfFloatStep) {
  const std::string dir = testing::FreshTempDir("twilight_skip");
  // W2's place and day (the Sun a light: half scale 1): the Sun at -20.75
  // deg (W2's frame 13, which its probe finds unchanged by the march),
  // -19.33 deg (frame 14, which the march changes) and noon.
  const std::string schedule = testing::WriteFile(dir, "dusk.toml", R"([schedule]
first_frame = 1
date = 2013-05-27
latitude_deg = 42.44337
longitude_deg = -76.48163
utc_offset_hours = -4.0
times = [03:00:00, 03:15:00, 12:00:00]
)");
  const std::string common = testing::SourceDir() + "/configs/benchmark/w1.toml --schedule " + schedule +
                             " --size 96 --set output.cube_strip=false";
  const testing::CommandRun skipped =
      testing::RunSkybake("bake " + common + " --force --out " + dir + "/skipped", "SKYBAKE_TWILIGHT_SKIP=1");
  ASSERT_EQ(skipped.exit_code, 0) << skipped.output;
  const testing::CommandRun marched = testing::RunSkybake("bake " + common + " --force --out " + dir + "/marched");
  ASSERT_EQ(marched.exit_code, 0) << marched.output;
  EXPECT_EQ(marched.output.find("twilight probe"), std::string::npos) << marched.output;
  // The probe runs from the lowest Sun up and stops at the first frame the march changes.
  const size_t at = skipped.output.find("no twilight march in frames ");
  ASSERT_NE(at, std::string::npos) << skipped.output;
  const std::string line = skipped.output.substr(at, skipped.output.find('\n', at) - at);
  // "no twilight march in frames 4-5 (...": the frame numbers as runs.
  std::set<int> unmarched_frames;
  std::stringstream runs(line.substr(28, line.find(" (") - 28));
  for (std::string run; std::getline(runs, run, ',');) {
    const int first = std::stoi(run),
              last = run.find('-') == std::string::npos ? first : std::stoi(run.substr(run.find('-') + 1));
    for (int f = first; f <= last; ++f) unmarched_frames.insert(f);
  }
  EXPECT_EQ(unmarched_frames, std::set<int>{1}) << line;
  EXPECT_NE(line.find("2 probed"), std::string::npos) << line;  // the search ends at frame 2
  for (int frame = 1; frame <= 3; ++frame) {
    const bool unmarched = unmarched_frames.count(frame) > 0;
    for (const char* name : {"sky_latlong", "sky_px", "sky_nz"}) {
      const std::string file = std::string(name) + ".000" + std::to_string(frame) + ".exr";
      if (!unmarched) {
        EXPECT_EQ(Bytes(dir + "/skipped/" + file), Bytes(dir + "/marched/" + file)) << file;
        continue;
      }
      int w = 0, h = 0, w2 = 0, h2 = 0;
      std::vector<float> a, b;
      ASSERT_TRUE(testing::ReadRgb(dir + "/skipped/" + file, w, h, a));
      ASSERT_TRUE(testing::ReadRgb(dir + "/marched/" + file, w2, h2, b));
      ASSERT_EQ(a.size(), b.size()) << file;
      EXPECT_LE(HalfStepsApart(a, b), 1.0) << file << " (" << line << ")";
    }
  }
  // The plan says the march is probed; without SKYBAKE_TWILIGHT_SKIP=1 (the CLI's default) it does not.
  EXPECT_EQ(testing::RunSkybake("plan " + testing::SourceDir() + "/configs/benchmark/w1.toml --schedule " + schedule)
                .output.find("probed at the exposure stage"),
            std::string::npos);
  const testing::CommandRun plan = testing::RunSkybake(
      "plan " + testing::SourceDir() + "/configs/benchmark/w1.toml --schedule " + schedule, "SKYBAKE_TWILIGHT_SKIP=1");
  EXPECT_NE(plan.output.find("probed at the exposure stage"), std::string::npos) << plan.output;
}

}  // namespace
}  // namespace skybake
