// The 24-frame clock-time schedule of the schedule and sequence tests:
// 2013-05-27 at Ithaca, NY (42.44337 N, 76.48163 W, UTC-4; the site and day
// of the Kider 2014 measurements), 06:00 to 11:45 local time every 15 minutes.
#pragma once

#include <string>

namespace skybake::testing {

inline constexpr const char* kDay24 = R"(
[schedule]
date = 2013-05-27
latitude_deg = 42.44337
longitude_deg = -76.48163
utc_offset_hours = -4.0
times = { start = 06:00:00, end = 11:45:00, step_minutes = 15 }
)";

// A schedule of that site and day from `start` to `end` (local time,
// "hh:mm:ss") every `step_minutes`.
inline std::string IthacaSchedule(const std::string& start, const std::string& end, int step_minutes) {
  return "[schedule]\ndate = 2013-05-27\nlatitude_deg = 42.44337\nlongitude_deg = -76.48163\nutc_offset_hours = -4.0\n"
         "times = { start = " +
         start + ", end = " + end + ", step_minutes = " + std::to_string(step_minutes) + " }\n";
}

}  // namespace skybake::testing
