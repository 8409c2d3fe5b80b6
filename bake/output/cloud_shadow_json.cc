// The cloud shadow map's record in manifest.json (cloud_shadow_json.h).
#include "skybake/output/cloud_shadow_json.h"

#include <stdexcept>
#include <string>

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
    if (!j.is_object() || !j.contains(key))
      throw std::runtime_error(std::string("cloud_shadow.") + key + " is missing");
    return j.at(key);
  };
  auto triple = [&](const char* key) {
    const nlohmann::json& a = member(key);
    if (!a.is_array() || a.size() != 3)
      throw std::runtime_error(std::string("cloud_shadow.") + key + ": expected 3 numbers");
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
    for (const nlohmann::json& w : member("wind_offset_m"))
      i.wind_offset_m.push_back({w.at(0).get<double>(), w.at(1).get<double>()});
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(std::string("cloud_shadow: ") + e.what());
  }
  return i;
}

}  // namespace skybake
