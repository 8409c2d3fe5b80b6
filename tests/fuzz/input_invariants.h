// What must hold of the star catalogue reader for any bytes (ParseStarCatalogue,
// astronomy.h): no crash, no exception; a refused file has a message naming
// it; an accepted one has at least one star, every star finite with |dec| <=
// 90 deg and RA in [0, 360), and its faintest magnitude the largest of its
// stars'. Used by the fuzz target (inputs_fuzz.cc) and replayed on
// tests/fuzz/catalogues/ by tests/e2e/fuzz_regression_test.cc in every build.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>

#include "skybake/input/astronomy.h"

namespace skybake::fuzz {

[[noreturn]] inline void FailInput(const char* what) {
  std::fprintf(stderr, "inputs_fuzz: %s\n", what);
  std::abort();
}

inline void CheckCatalogue(const std::string& text) {
  std::string error;
  const std::optional<skybake::StarCatalogue> catalogue = skybake::ParseStarCatalogue(text, "fuzz.json", error);
  if (!catalogue) {
    if (error.find("fuzz.json") == std::string::npos) FailInput("a refused catalogue's message does not name the file");
    return;
  }
  if (catalogue->stars.empty()) FailInput("an accepted catalogue has no stars");
  double faintest = -HUGE_VAL;
  for (const skybake::CatalogueStar& s : catalogue->stars) {
    if (!std::isfinite(s.ra_j2000_deg) || !std::isfinite(s.dec_j2000_deg) || !std::isfinite(s.v_magnitude) ||
        !std::isfinite(s.b_minus_v))
      FailInput("a star with a value that is not finite");
    if (!(s.ra_j2000_deg >= 0.0 && s.ra_j2000_deg < 360.0)) FailInput("a star's RA outside [0, 360)");
    if (!(std::abs(s.dec_j2000_deg) <= 90.0)) FailInput("a star's declination outside [-90, 90]");
    faintest = std::max(faintest, s.v_magnitude);
  }
  if (faintest != catalogue->faintest_magnitude) FailInput("the faintest magnitude is not the largest star's");
}

}  // namespace skybake::fuzz
