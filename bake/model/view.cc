#include "skybake/model/view.h"

#include "skybake/model/shared_glsl.h"

#include <type_traits>

#include <glm/glm.hpp>

namespace skybake {

glm::dvec3 ViewTexelDirection(const ViewRequest& v, int x, int y) {
  if (v.mapping == MAPPING_LATLONG) return glsl::DirectionFromLatLongPixel(x, y, v.width, v.height);
  if (v.mapping == MAPPING_CUBE_STRIP) return glsl::DirectionFromCubeStripPixel(x, y, v.width);
  if (v.mapping == MAPPING_VULKAN_FACE) return glsl::DirectionFromVulkanCubeTexel(v.face, x, y, v.width);
  return glm::dvec3(0.0, 1.0, 0.0);
}

std::vector<glm::dvec3> ViewDirections(const ViewRequest& v) {
  std::vector<glm::dvec3> dirs(size_t(v.width) * v.height);
  for (int y = 0; y < v.height; ++y)
    for (int x = 0; x < v.width; ++x) dirs[size_t(y) * v.width + x] = ViewTexelDirection(v, x, y);
  return dirs;
}

}  // namespace skybake
