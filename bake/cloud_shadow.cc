// The cloud shadow map's placement, tiling and provenance (cloud_shadow.h);
// the map itself is rendered by SkyRenderer::RenderCloudShadow
// (bake/cloud_shadow_render.cc, shaders/cloud_shadow.comp).
#include "skybake/cloud_shadow.h"

#include <cmath>

#include <fmt/format.h>

#include "skybake/clouds.h"
#include "skybake/manifest.h"

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
  info.origin_m = {s.center_east_m - 0.5 * s.extent_m, s.receiver_altitude_m,
                   -(s.center_north_m + 0.5 * s.extent_m)};
  info.receiver_altitude_m = s.receiver_altitude_m;
  info.sun_direction = sun;
  info.sun_above_horizon = sun.y > 0.0;
  info.strength = s.strength;
  info.tiles = CloudShadowTiles(clouds, s.extent_m);
  for (const CloudLayer& l : ActiveCloudLayers(clouds))
  {
    std::array<double, 2> offset = {l.wind_m_s[0] * time_s, l.wind_m_s[1] * time_s};
    // A formation's drift (cloud_formation.h) moves its coverage as well.
    if (l.formation.enabled)
      for (int a = 0; a < 2; ++a)
        offset[a] += l.formation.velocity_cells_per_hour[a] * time_s / 3600.0 * l.formation.size_m[a] /
                     l.formation.cells[a];
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
  clouds.uniform.range.z = float(s.strength);
  clouds.uniform.range.w = float(s.steps);
}

std::string CloudShadowFileName(const std::string& basename, int frame_number) {
  return basename + "_cloudshadow" + FrameNumberSuffix(frame_number) + ".exr";
}

}  // namespace skybake

// ---------------------------------------------------------------- manifest.json

#include "cloud_shadow_json.h"

namespace skybake {

nlohmann::json CloudShadowJson(const CloudShadowInfo& i) {
  nlohmann::json wind = nlohmann::json::array();
  for (const std::array<double, 2>& w : i.wind_offset_m) wind.push_back({w[0], w[1]});
  return {{"resolution", i.resolution},
          {"extent_m", i.extent_m},
          {"origin_m", {i.origin_m[0], i.origin_m[1], i.origin_m[2]}},
          {"axis_u", {i.axis_u[0], i.axis_u[1], i.axis_u[2]}},
          {"axis_v", {i.axis_v[0], i.axis_v[1], i.axis_v[2]}},
          {"receiver_altitude_m", i.receiver_altitude_m},
          {"sun_direction", {i.sun_direction.x, i.sun_direction.y, i.sun_direction.z}},
          {"sun_above_horizon", i.sun_above_horizon},
          {"strength", i.strength},
          {"tiles", i.tiles},
          {"wind_offset_m", wind}};
}

CloudShadowInfo CloudShadowFromJson(const nlohmann::json& j) {
  auto member = [&](const char* key) -> const nlohmann::json& {
    if (!j.is_object() || !j.contains(key)) throw std::runtime_error(std::string("cloud_shadow.") + key + " is missing");
    return j.at(key);
  };
  auto triple = [&](const char* key) {
    const nlohmann::json& a = member(key);
    if (!a.is_array() || a.size() != 3) throw std::runtime_error(std::string("cloud_shadow.") + key + ": expected 3 numbers");
    return std::array<double, 3>{a[0].get<double>(), a[1].get<double>(), a[2].get<double>()};
  };
  CloudShadowInfo i;
  try {
    i.resolution = member("resolution").get<int>();
    i.extent_m = member("extent_m").get<double>();
    i.origin_m = triple("origin_m");
    i.axis_u = triple("axis_u");
    i.axis_v = triple("axis_v");
    i.receiver_altitude_m = member("receiver_altitude_m").get<double>();
    const std::array<double, 3> sun = triple("sun_direction");
    i.sun_direction = {sun[0], sun[1], sun[2]};
    i.sun_above_horizon = member("sun_above_horizon").get<bool>();
    i.strength = member("strength").get<double>();
    i.tiles = member("tiles").get<bool>();
    for (const nlohmann::json& w : member("wind_offset_m")) i.wind_offset_m.push_back({w.at(0).get<double>(), w.at(1).get<double>()});
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(std::string("cloud_shadow: ") + e.what());
  }
  return i;
}

}  // namespace skybake
