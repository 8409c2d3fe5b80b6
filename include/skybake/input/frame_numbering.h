// How a frame's number appears in the names of its files.
#pragma once

#include <string>

#include <fmt/format.h>

namespace skybake {

// ".0012" for frame 12 in file names (at least four digits), "" for 0 (a
// single bake).
inline std::string FrameNumberSuffix(int number) { return number > 0 ? fmt::format(".{:04d}", number) : ""; }

}  // namespace skybake
