// The views a bake renders (latlong, cube strip, Vulkan cube faces) and the
// direction each texel of a view looks along: the double-precision
// instantiation of shaders/envmap.glsl, the same mappings the GPU uses.
// World frame: +Y up, North -Z, East +X; right-handed.
#pragma once

#include <vector>

#include <glm/vec3.hpp>

#include "skybake/gpu_shared.h"

namespace skybake {

// One output view. `mapping` is a MAPPING_* of gpu_shared.h.
struct ViewRequest {
  int mapping = MAPPING_LATLONG;
  int width = 0;
  int height = 0;
  int face = 0;  // MAPPING_VULKAN_FACE: 0..5 = +X -X +Y -Y +Z -Z
};

// Unit direction of texel (x, y) of `view`, rows from the top (+Y for
// MAPPING_DIRECTIONS).
glm::dvec3 ViewTexelDirection(const ViewRequest& view, int x, int y);

// Direction of each texel of a view (rows from the top).
std::vector<glm::dvec3> ViewDirections(const ViewRequest& view);

// Rows [begin, end) of a view.
struct RowRange {
  int begin = 0;
  int end = 0;
};

// The runs of rows of `view` that may hold a texel whose elevation (rad above
// the horizontal, +Y up) lies in [low, high], in order. A latlong row has one
// elevation, so its test is exact. A cube face's or strip's row is sampled at
// every `stride`-th texel and its last (stride = face size / 128, at least 1)
// and the range widened by stride / face size rad, the most a direction
// turns within half a stride (a texel spans at most 2 / face size rad of the
// face's plane, which lies at distance >= 1 from the centre), so a row that
// holds such a texel is never missed. MAPPING_DIRECTIONS: every row.
std::vector<RowRange> RowsReachingElevations(const ViewRequest& view, double low, double high);

}  // namespace skybake
