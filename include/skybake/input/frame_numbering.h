// How a frame's number appears in the names of its files.
#pragma once

#include <algorithm>
#include <string>

#include <fmt/format.h>

namespace skybake {

// The fewest digits of a frame number in file names.
constexpr int kFrameNumberMinDigits = 4;

// The digits of every frame number in a sequence's file names: four, or as
// many as its last frame needs, so that all the names of one sequence have
// one width and sort in frame order (a sequence of 10,000 frames or more
// names its first frame .00001, not .0001 beside .10000). The sequence's
// whole schedule decides it, so every part of it names frames alike.
inline int FrameNumberWidth(int last_frame_number) {
  int digits = 1;
  for (int n = last_frame_number; n >= 10; n /= 10) ++digits;
  return std::max(kFrameNumberMinDigits, digits);
}

// ".0012" for frame 12 in file names (`width` digits, FrameNumberWidth),
// "" for 0 (a single bake).
inline std::string FrameNumberSuffix(int number, int width = kFrameNumberMinDigits) {
  return number > 0 ? fmt::format(".{:0{}d}", number, width) : "";
}

}  // namespace skybake
