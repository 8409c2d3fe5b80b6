#include "skybake/model/view.h"

#include "skybake/model/shared_glsl.h"

#include <algorithm>
#include <cmath>
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

std::vector<RowRange> RowsReachingElevations(const ViewRequest& v, double low, double high) {
  if (v.mapping == MAPPING_DIRECTIONS) return {{0, v.height}};
  auto elevation = [&](int x, int y) {
    const glm::dvec3 d = ViewTexelDirection(v, x, y);
    return std::atan2(d.y, std::hypot(d.x, d.z));
  };
  const int stride = v.mapping == MAPPING_LATLONG ? v.width : std::max(1, v.width / 128);
  const double widen = v.mapping == MAPPING_LATLONG ? 0.0 : double(stride) / v.width;
  std::vector<RowRange> runs;
  for (int y = 0; y < v.height; ++y) {
    double lo = elevation(0, y), hi = lo;
    for (int x = stride; x < v.width + stride - 1; x += stride) {
      const double e = elevation(std::min(x, v.width - 1), y);
      lo = std::min(lo, e);
      hi = std::max(hi, e);
    }
    if (!(hi + widen >= low && lo - widen <= high)) continue;
    if (!runs.empty() && runs.back().end == y) runs.back().end = y + 1;
    else runs.push_back({y, y + 1});
  }
  return runs;
}

}  // namespace skybake
