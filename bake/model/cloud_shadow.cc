// The cloud shadow map's placement, tiling and provenance (cloud_shadow.h);
// the map itself is rendered by SkyRenderer::RenderCloudShadow
// (bake/gpu/cloud_shadow_render.cc, shaders/cloud_shadow.comp), written by
// bake/output/cloud_shadow_file.cc, recorded by bake/output/cloud_shadow_json.cc.
#include "skybake/model/cloud_shadow.h"

#include <cmath>

#include <fmt/format.h>

#include "skybake/model/clouds.h"

namespace skybake {
namespace {

// `extent` is a whole number (at least one) of `period`s, to 1e-9 of it.
bool WholeTiles(double extent, double period) {
  if (!(period > 0.0)) return false;
  const double n = extent / period;
  return n >= 1.0 - 1e-9 && std::abs(n - std::round(n)) <= 1e-9 * std::max(1.0, n);
}

std::string Vec3(const std::array<double, 3>& v) { return fmt::format("{:.9g} {:.9g} {:.9g}", v[0], v[1], v[2]); }

}  // namespace

bool CloudShadowTiles(const CloudSettings& clouds, double extent_m) {
  for (const CloudLayer& l : ActiveCloudLayers(clouds)) {
    // A layer read through the non-periodic warp never repeats
    // (shaders/cloud_weather.glsl); a formation's coverage or density is
    // not warped, its noise is (FormationShapeWarped).
    if (l.formation.enabled ? FormationShapeWarped(l) : !l.tiling) return false;
    std::array<double, 2> weather = {l.weather_size_m, l.weather_size_m};
    if (l.formation.enabled) weather = l.formation.size_m;
    else if (!l.weather_image.empty()) weather = l.weather_extent_m;
    for (double period : {l.shape_size_m, l.detail_size_m, weather[0], weather[1]})
      if (!WholeTiles(extent_m, period)) return false;
  }
  return true;
}

CloudShadowInfo CloudShadowInfoOf(const CloudSettings& clouds, const CloudShadowSettings& s, const glm::dvec3& sun,
                                  double time_s) {
  CloudShadowInfo info;
  info.resolution = s.resolution;
  info.extent_m = s.extent_m;
  // North-west corner: west of the centre by half the extent, north by half
  // (world z = -north).
  info.origin_m = {s.center_east_m - 0.5 * s.extent_m, s.receiver_altitude_m, -(s.center_north_m + 0.5 * s.extent_m)};
  info.receiver_altitude_m = s.receiver_altitude_m;
  info.sun_direction = sun;
  info.sun_above_horizon = sun.y > 0.0;
  info.strength = s.strength;
  info.tiles = CloudShadowTiles(clouds, s.extent_m);
  for (const CloudLayer& l : ActiveCloudLayers(clouds)) {
    // A formation's layer moves on the formation's clock (ToCloudInputs).
    const double t_s = l.formation.enabled ? FormationTimeSeconds(l.formation, clouds.local_clock_s, time_s) : time_s;
    std::array<double, 2> offset = {l.wind_m_s[0] * t_s, l.wind_m_s[1] * t_s};
    // A formation's drift (cloud_formation.h) moves its coverage as well.
    if (l.formation.enabled)
      for (int a = 0; a < 2; ++a)
        offset[a] +=
            l.formation.velocity_cells_per_hour[a] * t_s / 3600.0 * l.formation.size_m[a] / l.formation.cells[a];
    info.wind_offset_m.push_back(offset);
  }
  return info;
}

std::map<std::string, std::string> CloudShadowAttributes(const CloudShadowInfo& i) {
  std::string wind;
  for (const std::array<double, 2>& w : i.wind_offset_m)
    wind += fmt::format("{}{:.9g} {:.9g}", wind.empty() ? "" : "; ", w[0], w[1]);
  return {
      {"skybake:shadow:content",
       "transmittance of direct sunlight through the cloud layers onto the receiver plane (R = G = B), 0..1"},
      {"skybake:shadow:extent_m", fmt::format("{:.9g}", i.extent_m)},
      {"skybake:shadow:origin_m", Vec3(i.origin_m) + " (world x y z of the north-west corner, row 0 column 0)"},
      {"skybake:shadow:axis_u", Vec3(i.axis_u) + " (columns, east)"},
      {"skybake:shadow:axis_v", Vec3(i.axis_v) + " (rows, south)"},
      {"skybake:shadow:receiver_alt_m", fmt::format("{:.9g}", i.receiver_altitude_m)},
      {"skybake:shadow:sun_direction",
       fmt::format("{:.9g} {:.9g} {:.9g}", i.sun_direction.x, i.sun_direction.y, i.sun_direction.z)},
      {"skybake:shadow:sun_up", i.sun_above_horizon ? "true" : "false (all zeros: no direct sunlight)"},
      {"skybake:shadow:strength", fmt::format("{:.9g}", i.strength)},
      {"skybake:shadow:tiles", i.tiles ? "true" : "false"},
      {"skybake:shadow:wind_offset_m", wind.empty() ? "none" : wind + " (per layer, east north)"},
  };
}

void ApplyGroundCloudShadow(const CloudShadowSettings& s, CloudInputs& clouds) {
  if (!s.enabled || !s.ground || s.strength == 0.0 || clouds.layers() == 0) return;
  clouds.uniform.ground_shadow.x = float(s.strength);
  clouds.uniform.ground_shadow.y = float(s.steps);
}

}  // namespace skybake
