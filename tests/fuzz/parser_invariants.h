// What the style and schedule parsers must do with any input: not crash,
// and what they accept must hold together. Shared by the libFuzzer target
// (tests/fuzz/parsers_fuzz.cc) and the regression test that replays
// tests/fuzz/regressions/ in every build (tests/e2e/fuzz_regression_test.cc).
//  - every error names a key and a message;
//  - an accepted style's resolved TOML reads back to the same resolved TOML;
//  - an accepted schedule has frames, and its first and last frames'
//    assignments resolve against the default style without a crash.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

#include "skybake/input/config.h"
#include "skybake/input/schedule.h"

namespace skybake::fuzz {

inline void Require(bool condition, const char* what) {
  if (!condition) {
    std::fprintf(stderr, "skybake parsers: invariant broken: %s\n", what);
    std::abort();
  }
}

inline void CheckErrors(const std::vector<ConfigError>& errors) {
  for (const ConfigError& e : errors) {
    Require(!e.key.empty(), "an error names its key");
    Require(!e.message.empty(), "an error has a message");
    Require(e.line >= 0 && e.column >= 0, "an error's position is not negative");
    Require(!e.Format().empty(), "an error formats");
  }
}

// Reads `text` as a style and as a schedule and checks the invariants above.
inline void CheckParsers(std::string_view text) {
  ConfigResult style = ParseSkyStyle(text, "fuzz.toml", {});
  CheckErrors(style.errors);
  if (style.ok()) {
    ConfigResult again = ParseSkyStyle(style.style.resolved_toml, "resolved.toml", {});
    Require(again.ok(), "an accepted style's resolved TOML is accepted");
    Require(again.style.resolved_toml == style.style.resolved_toml, "resolved TOML is a fixed point");
  }

  ScheduleResult schedule = ParseSchedule(text, "fuzz.toml");
  CheckErrors(schedule.errors);
  if (schedule.ok()) {
    Require(!schedule.schedule.frames.empty(), "an accepted schedule has frames");
    const SkyStyle base = ParseSkyStyle("", "default.toml", {}).style;
    for (const ScheduleFrame* frame : {&schedule.schedule.frames.front(), &schedule.schedule.frames.back()}) {
      std::vector<ConfigError> errors;
      std::vector<FrameOverride> overrides = FrameStyleOverrides(schedule.schedule, *frame, base, errors);
      CheckErrors(errors);
      std::vector<std::string> assignments;
      for (const FrameOverride& o : overrides) assignments.push_back(o.Assignment());
      CheckErrors(ParseSkyStyle("", "default.toml", assignments).errors);
    }
  }
}

}  // namespace skybake::fuzz
