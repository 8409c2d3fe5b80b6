#include "skybake/gpu/cloud_panorama.h"

#include <algorithm>
#include <cmath>

namespace skybake {

int CloudPanoramaHeightFor(const ViewRequest& view) {
  constexpr double kHalfPi = 1.57079632679489662;
  switch (view.mapping) {
    case MAPPING_LATLONG: return view.height;
    case MAPPING_CUBE_STRIP:
    case MAPPING_VULKAN_FACE: return int(std::ceil(kHalfPi * double(view.width)));
    default: return 0;
  }
}

CloudPanorama ChooseCloudPanorama(const std::vector<ViewRequest>& views, double scale) {
  CloudPanorama none;
  if (!(scale > 0.0) || views.empty()) return none;
  int finest = 0;
  size_t view_texels = 0;
  for (const ViewRequest& v : views) {
    if (v.mapping == MAPPING_DIRECTIONS) return none;
    finest = std::max(finest, CloudPanoramaHeightFor(v));
    view_texels += size_t(v.width) * size_t(v.height);
  }
  const int height = std::max(2, int(std::ceil(scale * double(finest))));
  if (height > kMaxCloudPanoramaHeight) return none;
  CloudPanorama p{2 * height, height};
  // Cheaper only when the views hold clearly more texels than the panorama.
  if (3 * p.texels() > 2 * view_texels) return none;
  return p;
}

}  // namespace skybake
