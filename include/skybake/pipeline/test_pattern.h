// An orientation test pattern (`skybake testpattern`), in the spirit of
// OpenEXR's OrientationCube.exr: an environment whose every direction says
// where it is, written through any engine preset (engine_preset.h) so a user
// can check the preset in their own engine in a minute.
//
// Each cube face of skybake's world (+Y up, right-handed, North = -Z, East =
// +X) is tinted its own colour (TestPatternFaceColor) and carries, in black,
// its name in the middle ("+X") and the axes that run to its right and top
// edges as seen from inside; a white line marks the horizon, white letters
// N E S W stand just above it at the compass points. Text reads the right
// way round from the centre: a face's right is cross(face axis, +Y) and its
// top +Y; looking up (+Y) right is +X and top +Z (facing North, tilting
// up), looking down (-Y) right is +X and top -Z.
#pragma once

#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "skybake/output/exr_io.h"

namespace skybake {

// The pattern's linear RGB along a unit direction of skybake's world.
glm::dvec3 TestPatternColor(const glm::dvec3& direction);

// Tint of the face whose major axis is face 0..5 (+X -X +Y -Y +Z -Z), away from its text.
glm::dvec3 TestPatternFaceColor(int face);

struct TestPatternOptions {
  std::string out_dir = "out";
  std::string engine = "none";  // a preset name, or none: skybake's own faces, strip and latlong
  std::string basename = "sky";
  int size = 256;  // cube face edge; the latlong is 2N x N
  bool force = false;
  double max_memory_mib = 4096.0;  // budget (README "Limits"); over it, BudgetError (exit 7) before any file
};

// The pattern's memory in MiB: every image's directions (3 doubles a
// texel) held at once, and the largest image's RGBA float pixels and its
// file being encoded (about 16 bytes a texel more).
double TestPatternMemoryMiB(const TestPatternOptions& options);

// Writes the pattern as the files a bake would (the bake's own six Vulkan
// faces, OpenEXR strip and latlong, and the preset's files) into out_dir.
// Throws BudgetError (exit 7) over options.max_memory_mib, before any file;
// OutputError (exit 5) or OutputExistsError-like std::runtime_error
// when a file exists without force. Returns the paths written.
std::vector<std::string> WriteTestPattern(const TestPatternOptions& options);

}  // namespace skybake
