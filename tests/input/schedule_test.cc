// Schedules: frames from clock times, ranges and lists, per-frame style
// changes, and errors located in the schedule file.
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "skybake/input/schedule.h"
#include "skybake/model/solar_position.h"
#include "schedule_fixtures.h"
#include "test_support.h"

namespace skybake {
namespace {

std::string WriteTemp(const std::string& name, const std::string& text) {
  std::filesystem::path dir = std::filesystem::temp_directory_path() / "skybake-schedule-test";
  std::filesystem::create_directories(dir);
  std::string path = (dir / name).string();
  std::ofstream(path) << text;
  return path;
}

using testing::kDay24;

TEST(Schedule, ClockTimeRange) {
  ScheduleResult r = ParseSchedule(kDay24, "day24.toml");
  ASSERT_TRUE(r.ok()) << r.errors[0].Format();
  const Schedule& s = r.schedule;
  ASSERT_EQ(s.frames.size(), 24u);
  EXPECT_TRUE(s.clock_times);
  EXPECT_EQ(s.frames.front().number, 1);
  EXPECT_EQ(s.frames.back().number, 24);
  EXPECT_EQ(s.frames[14].time->Iso8601(), "2013-05-27T09:30:00-04:00");
  EXPECT_NEAR(s.frames[14].hours_from_start, 3.5, 1e-9);
  EXPECT_NEAR(s.frames.back().fraction, 1.0, 1e-12);
  // Frame 15 is the Kider capture 2013-05-27 09:30 EDT: sun zenith 48.94.
  EXPECT_NEAR(90.0 - s.frames[14].elevation_deg, 48.94, 0.05);
  SolarPosition p = ComputeSolarPosition(*s.frames[14].time, *s.place);
  // libnova caches nutation between nearby Julian days, so repeated calls
  // agree to about 1e-5 deg rather than bit for bit.
  EXPECT_NEAR(s.frames[14].azimuth_deg, p.azimuth_deg, 1e-4);
}

TEST(Schedule, TimeListAndFirstFrame) {
  ScheduleResult r = ParseSchedule(R"(
[schedule]
first_frame = 101
date = 2013-05-27
latitude_deg = 42.44337
longitude_deg = -76.48163
utc_offset_hours = -4
times = [09:30:00, 12:00:00, 13:30:00]
)",
                                   "list.toml");
  ASSERT_TRUE(r.ok()) << r.errors[0].Format();
  ASSERT_EQ(r.schedule.frames.size(), 3u);
  EXPECT_EQ(r.schedule.frames[2].number, 103);
  EXPECT_NEAR(r.schedule.frames[2].hours_from_start, 4.0, 1e-9);
}

TEST(Schedule, SunRangesAndLists) {
  ScheduleResult r = ParseSchedule(R"(
[schedule]
sun = { elevation_deg = { start = 0, end = 60, step = 5 }, azimuth_deg = 135 }
)",
                                   "sun.toml");
  ASSERT_TRUE(r.ok()) << r.errors[0].Format();
  ASSERT_EQ(r.schedule.frames.size(), 13u);
  EXPECT_DOUBLE_EQ(r.schedule.frames[12].elevation_deg, 60.0);
  EXPECT_DOUBLE_EQ(r.schedule.frames[12].azimuth_deg, 135.0);
  EXPECT_FALSE(r.schedule.clock_times);
  EXPECT_NEAR(r.schedule.frames[6].fraction, 0.5, 1e-12);

  ScheduleResult lists = ParseSchedule(R"(
[schedule]
sun = { elevation_deg = [5, 10, 20], azimuth_deg = [90, 120, 150] }
)",
                                       "lists.toml");
  ASSERT_TRUE(lists.ok());
  EXPECT_DOUBLE_EQ(lists.schedule.frames[1].azimuth_deg, 120.0);
  glm::dvec3 d = SunDirectionFromElevationAzimuth(10.0, 120.0);
  EXPECT_NEAR(lists.schedule.frames[1].sun_direction.x, d.x, 1e-15);
}

TEST(Schedule, ErrorsNameFileLineColumn) {
  ScheduleResult r = ParseSchedule(R"([schedule]
date = "2013-05-27"
latitude_deg = 42.4
longitude_deg = -76.5
utc_offset_hours = -4
times = { start = 06:00:00, end = 05:00:00, step_minutes = 15 }
colour = "red"
)",
                                   "bad.toml");
  ASSERT_FALSE(r.ok());
  std::string all;
  for (const ConfigError& e : r.errors) all += e.Format() + "\n";
  EXPECT_NE(all.find("bad.toml:2:8: schedule.date: expected a date such as 2013-05-27"), std::string::npos) << all;
  EXPECT_NE(all.find("bad.toml:7:10: schedule.colour: unknown key 'colour'"), std::string::npos) << all;
  EXPECT_NE(all.find("end is before start"), std::string::npos) << all;

  ScheduleResult missing = ParseSchedule("[schedule]\ntimes = [09:30:00]\n", "nowhere.toml");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.errors[0].Format().find("clock times need schedule.date"), std::string::npos);

  ScheduleResult steps = ParseSchedule(
      "[schedule]\nsun = { elevation_deg = { start = 0, end = 10, step = -1 }, azimuth_deg = 0 }\n", "s.toml");
  ASSERT_FALSE(steps.ok());
  EXPECT_NE(steps.errors[0].Format().find("s.toml:2:25"), std::string::npos) << steps.errors[0].Format();
}

// A number or an RGB triple is refused as in a style (the shared readers of
// bake/input/toml_reader.h): what the value is instead, a value that is not
// finite, a triple of the wrong length.
TEST(Schedule, NumbersAndTriplesAreRefusedAsInAStyle) {
  ScheduleResult r = ParseSchedule(R"([schedule]
sun = { elevation_deg = ["low", 20], azimuth_deg = nan }
ramp = { "atmosphere.ground_albedo" = [[0.1, 0.2], 0.3] }
)",
                                   "n.toml");
  ASSERT_FALSE(r.ok());
  std::string all;
  for (const ConfigError& e : r.errors) all += e.Format() + "\n";
  EXPECT_NE(all.find("n.toml:2:26: schedule.sun.elevation_deg[0]: expected a number, got a string\n"),
            std::string::npos)
      << all;
  EXPECT_NE(all.find("schedule.sun.azimuth_deg: must be a finite number (got nan)\n"), std::string::npos) << all;
  EXPECT_NE(all.find("n.toml:3:40: schedule.ramp.atmosphere.ground_albedo[0]: expected a number or an array of 3 "
                     "numbers [680 nm, 550 nm, 440 nm]\n"),
            std::string::npos)
      << all;
}

// A schedule typo gets the same answer as a style typo: located, with the
// nearest known key (the shared TOML reader, bake/input/toml_reader.h), in
// [schedule], its sun table and its ramps; no suggestion for a key near none.
TEST(Schedule, UnknownKeysSuggestTheNearestKnownOne) {
  ScheduleResult r = ParseSchedule(R"([schedule]
date = "2013-05-27"
latitude_deg = 42.4
longitude_deg = -76.5
utc_offset_hours = -4
tiems = [09:30:00]
frist_frame = 3
sun_colour = "red"
)",
                                   "typo.toml");
  ASSERT_FALSE(r.ok());
  std::string all;
  for (const ConfigError& e : r.errors) all += e.Format() + "\n";
  EXPECT_NE(all.find("typo.toml:6:9: schedule.tiems: unknown key 'tiems' (did you mean 'times'?) (expected "),
            std::string::npos)
      << all;
  EXPECT_NE(all.find("typo.toml:7:15: schedule.frist_frame: unknown key 'frist_frame' (did you mean 'first_frame'?)"),
            std::string::npos)
      << all;
  EXPECT_NE(all.find("schedule.sun_colour: unknown key 'sun_colour' (expected "), std::string::npos) << all;

  ScheduleResult sun = ParseSchedule("[schedule]\nsun = { elevation_deg = 10, azimuht_deg = 135 }\n", "sun.toml");
  ASSERT_FALSE(sun.ok());
  std::string sun_all;
  for (const ConfigError& e : sun.errors) sun_all += e.Format() + "\n";
  EXPECT_NE(sun_all.find("unknown key 'azimuht_deg' (did you mean 'azimuth_deg'?)"), std::string::npos) << sun_all;
}

TEST(Schedule, PerFrameStyleChanges) {
  std::string style = WriteTemp("style.toml", "[atmosphere.mie]\ng = 0.8\n[render]\ncube_size = 8\n");
  std::string text = std::string(kDay24) + R"(
[schedule.ramp]
"atmosphere.mie.g" = [0.7, 0.8]
"atmosphere.ground_albedo" = [[0.1, 0.1, 0.1], [0.3, 0.2, 0.1]]
[schedule.per_hour]
"atmosphere.observer_altitude_m" = 100.0
)";
  ScheduleResult r = ParseSchedule(text, "ramp.toml");
  ASSERT_TRUE(r.ok()) << r.errors[0].Format();
  FrameStyles styles = ResolveFrameStyles(style, {"render.latlong_height=8"}, r.schedule);
  ASSERT_TRUE(styles.ok()) << styles.errors[0].Format();
  ASSERT_EQ(styles.styles.size(), 24u);
  const double f = r.schedule.frames[12].fraction;  // 09:00, 3 of 5.75 hours
  EXPECT_NEAR(styles.styles[12].atmosphere.mie_g, 0.7 + 0.1 * f, 1e-12);
  EXPECT_NEAR(styles.styles[23].atmosphere.ground_albedo[0], 0.3, 1e-12);
  EXPECT_NEAR(styles.styles[12].atmosphere.observer_altitude_m, 300.0, 1e-9);
  EXPECT_NEAR(styles.styles[12].sun.elevation_deg, r.schedule.frames[12].elevation_deg, 1e-12);
  EXPECT_EQ(styles.styles[12].render.latlong_height, 8);  // the command line's --set still applies
}

TEST(Schedule, FrameSetErrorsPointIntoTheSchedule) {
  std::string style = WriteTemp("plain.toml", "[render]\ncube_size = 8\n");
  ScheduleResult r = ParseSchedule(R"([schedule]
[[schedule.frames]]
elevation_deg = 10
azimuth_deg = 90
[[schedule.frames]]
elevation_deg = 20
azimuth_deg = 90
set = { "atmosphere.mie.g" = 1.5, "effects.sun_disk" = false }
)",
                                   "frames.toml");
  ASSERT_TRUE(r.ok()) << r.errors[0].Format();
  ASSERT_EQ(r.schedule.frames.size(), 2u);
  FrameStyles styles = ResolveFrameStyles(style, {}, r.schedule);
  ASSERT_EQ(styles.errors.size(), 2u);
  EXPECT_EQ(styles.errors[0].Format(), "frames.toml:8:30: atmosphere.mie.g: frame 2: 1.5 is out of range (-1, 1)");
  EXPECT_NE(styles.errors[1].Format().find("frames.toml:8:56: effects.sun_disk: frame 2: unknown key 'sun_disk' "
                                           "(did you mean 'effects.sun_disc'?)"),
            std::string::npos)
      << styles.errors[1].Format();
}

TEST(Schedule, InlineInAStyle) {
  std::string style = WriteTemp("inline.toml", std::string("[render]\ncube_size = 8\n") + kDay24);
  EXPECT_TRUE(FileHasSchedule(style));
  ConfigResult config = LoadSkyStyle(style);
  EXPECT_TRUE(config.ok()) << (config.ok() ? "" : config.errors[0].Format());
  ScheduleResult r = LoadSchedule(style);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.schedule.frames.size(), 24u);
  EXPECT_FALSE(FileHasSchedule(testing::SourceDir() + "/configs/default.toml"));
}

TEST(Schedule, ExampleDayLoads) {
  std::string path = testing::SourceDir() + "/configs/schedules/day.toml";
  ScheduleResult r = LoadSchedule(path);
  ASSERT_TRUE(r.ok()) << r.errors[0].Format();
  FrameStyles styles = ResolveFrameStyles(testing::SourceDir() + "/configs/default.toml", {}, r.schedule);
  ASSERT_TRUE(styles.ok()) << styles.errors[0].Format();
  EXPECT_EQ(styles.styles.size(), r.schedule.frames.size());
}

}  // namespace
}  // namespace skybake
