#include "skybake/gpu/cloud_panorama.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "skybake/gpu_shared.h"

namespace skybake {

int CloudPanoramaHeightFor(const ViewRequest& view) {
  constexpr double kHalfPi = 1.57079632679489662;
  switch (view.mapping) {
    case MAPPING_LATLONG:
      return view.height;
    case MAPPING_CUBE_STRIP:
    case MAPPING_VULKAN_FACE:
      return int(std::ceil(kHalfPi * double(view.width)));
    default:
      return 0;
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

CloudPanoramaRows CloudPanoramaRowsSeeingBands(const CloudPanorama& panorama, double bottom_radius_km,
                                               double observer_altitude_km,
                                               const std::vector<std::array<double, 2>>& bands) {
  CloudPanoramaRows rows{0, panorama.height};
  if (bands.empty() || panorama.height < 2) return rows;
  double lowest = bands.front()[0], highest = bands.front()[1];
  for (const auto& b : bands) {
    lowest = std::min(lowest, b[0]);
    highest = std::max(highest, b[1]);
  }
  constexpr double kPi = 3.14159265358979323846;
  // Row y's cosine of the zenith angle (DirectionFromLatLongPixel).
  auto mu = [&](int y) { return std::sin(-kPi * (double(y) / double(panorama.height - 1) - 0.5)); };
  if (observer_altitude_km < lowest) {
    const double ratio = bottom_radius_km / (bottom_radius_km + observer_altitude_km);
    const double mu_horizon = -std::sqrt(std::max(1.0 - ratio * ratio, 0.0));
    while (rows.end > 1 && mu(rows.end - 1) < mu_horizon - kCloudPanoramaRowMargin) --rows.end;
  } else if (observer_altitude_km > highest) {
    while (rows.begin < panorama.height - 1 && mu(rows.begin) > kCloudPanoramaRowMargin) ++rows.begin;
  }
  return rows;
}

int CloudPanoramaRowWidth(const CloudPanorama& panorama, int y) {
  constexpr double kPi = 3.14159265358979323846;
  const double cos_latitude = std::sin(kPi * double(y) / double(panorama.height - 1));
  const int w = int(std::ceil(double(panorama.width) * cos_latitude)) + 1;
  return std::clamp(w, std::min(CLOUD_PANORAMA_MIN_ROW_WIDTH, panorama.width), panorama.width);
}

int CloudPanoramaBlockStride(int blocks) {
  int stride = std::max(int(0.618 * double(blocks)), 1);
  while (std::gcd(stride, blocks) != 1) ++stride;
  return stride;
}

size_t CloudPanoramaMarchedTexels(const CloudPanorama& panorama, const CloudPanoramaRows& rows) {
  size_t texels = 0;
  for (int y = rows.begin; y < rows.end; ++y) texels += size_t(CloudPanoramaRowWidth(panorama, y));
  return texels;
}

}  // namespace skybake
