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

}  // namespace skybake
