// A schedule: the frames of a time-lapse, read from TOML (a [schedule] table
// in its own file, so one schedule serves many styles, or inline in a style).
//
// Each frame has a sun position, given either directly (elevation and
// azimuth, degrees, azimuth clockwise from North) or as a clock time at a
// place (date, latitude, longitude, UTC offset; solar_position.h turns it
// into a direction). Frames come as ranges (start / end / step) or lists.
// Any style key can change per frame: `ramp` interpolates a key linearly
// from the first frame to the last, `per_hour` adds rate x hours since the
// first frame (a drift from a velocity), and `[[schedule.frames]]` entries
// carry their own `set` table. README "Schedules" lists every key.
//
// Errors are collected like a style's, each with file:line:column.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "skybake/input/config.h"
#include "skybake/model/solar_position.h"

namespace skybake {

// One style change for one frame, as a `--set` assignment, with the place in
// the schedule it came from (for error messages).
struct FrameOverride {
  std::string key;         // dotted style key, e.g. "atmosphere.mie.g"
  std::string toml_value;  // TOML text of the value
  ConfigError origin;      // file, line, column of the schedule entry
  std::string Assignment() const { return key + "=" + toml_value; }
};

struct ScheduleFrame {
  int number = 1;                 // in file names: name.0001.exr
  std::optional<CivilTime> time;  // when the frame is a clock time
  double hours_from_start = 0.0;  // since the first frame (0 without clock times)
  double fraction = 0.0;          // 0 at the first frame, 1 at the last (time, else index)
  double elevation_deg = 0.0;
  double azimuth_deg = 0.0;  // clockwise from North
  glm::dvec3 sun_direction{0.0, 1.0, 0.0};
  std::vector<FrameOverride> overrides;  // from the frame's own `set` table
};

// A linear change of one style key across the frames.
struct ScheduleRamp {
  std::string key;
  std::vector<double> from, to;  // 1 value, or 3 for an RGB triple
  ConfigError origin;
};

// value(frame) = style value + rate x hours_from_start.
struct ScheduleRate {
  std::string key;
  std::vector<double> rate_per_hour;  // 1 value, or 3 for an RGB triple
  ConfigError origin;
};

struct Schedule {
  std::string source_path;
  std::optional<GeoLocation> place;  // set when frames are clock times
  std::vector<ScheduleFrame> frames;
  std::vector<ScheduleRamp> ramps;
  std::vector<ScheduleRate> rates;
  bool clock_times = false;  // every frame has a time
};

struct ScheduleResult {
  Schedule schedule;
  std::vector<ConfigError> errors;
  bool ok() const { return errors.empty(); }
};

// Reads the [schedule] table of a file (a schedule file, or a style with an
// inline schedule). Never throws for user errors.
ScheduleResult LoadSchedule(const std::string& path);
ScheduleResult ParseSchedule(std::string_view toml_text, const std::string& name);

// Whether a TOML file (a style) has an inline [schedule] table; and the
// same of a style's TOML text (a style given as a dict or text in Python).
bool FileHasSchedule(const std::string& path);
bool TextHasSchedule(std::string_view toml_text, const std::string& name);

// The `--set` assignments that turn the base style into `frame`'s style:
// the sun, then ramps and rates (which read their base value from
// `base_style`), then the frame's own overrides. Errors (a ramp on a key the
// style does not have as a number) go to `errors`.
std::vector<FrameOverride> FrameStyleOverrides(const Schedule& schedule, const ScheduleFrame& frame,
                                               const SkyStyle& base_style, std::vector<ConfigError>& errors);

// Reads `style_path` once per frame with `overrides` then the frame's
// assignments on top. An error in a frame's assignment is reported at its
// place in the schedule, prefixed with the frame number.
struct FrameStyles {
  std::vector<SkyStyle> styles;  // one per frame
  std::vector<ConfigError> errors;
  // Keys set by --set that the schedule sets again per frame (a ramp, a
  // rate, a frame's set): the schedule's value wins, which is said, once
  // per key, at the schedule's place.
  std::vector<ConfigError> warnings;
  bool ok() const { return errors.empty(); }
};
FrameStyles ResolveFrameStyles(const std::string& style_path, const std::vector<std::string>& overrides,
                               const Schedule& schedule);
// The same for a style given as TOML text (`style_path` names it in errors
// and provenance): a style that was never a file, from the Python module.
FrameStyles ResolveFrameStylesOfText(std::string_view text, const std::string& style_path,
                                     const std::vector<std::string>& overrides, const Schedule& schedule);

}  // namespace skybake
