// The cloud shadow map of a frame (the Unigine seed's "Shadows from
// Clouds"): the transmittance of direct sunlight through every cloud layer
// onto a horizontal receiver plane, projected along the sun direction
// (shaders/cloud_shadow.comp). Written per frame as BASE_cloudshadow.exr
// (BASE_cloudshadow.NNNN.exr in a sequence), its placement in the EXR header
// and in manifest.json, for engines to use as a directional-light cookie
// (Unity), a light function (Unreal) or a world-space texture (Godot,
// three.js); docs/clouds.md "Cloud shadows".
//
// Frame and units: skybake's world frame (+Y up, North = -Z, East = +X),
// metres. Row 0 of the map is its north edge, column 0 its west edge: a
// texel's column runs along +X (east), its row along +Z (south).
#pragma once

#include <array>
#include <map>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace skybake {

struct CloudSettings;
struct CloudInputs;

// The [cloud_shadow] section of a style (off by default).
struct CloudShadowSettings {
  bool enabled = false;
  int resolution = 256;              // texels along each edge of the square map
  double extent_m = 30000.0;         // edge of the map on the ground, m
  double center_east_m = 0.0;        // centre of the map, east of the viewer, m
  double center_north_m = 0.0;       // centre of the map, north of the viewer, m
  double receiver_altitude_m = 0.0;  // altitude of the receiver plane above the ground, m
  double strength = 1.0;             // multiplies the clouds' optical depth (0: no shadow, 1: physical)
  int steps = 32;                    // samples per cloud band crossing along the sun direction
  bool ground = true;                // the ground the sky shows below the horizon is shadowed too
};

// Where a map lies and what it holds, as recorded in its EXR header and in
// manifest.json.
struct CloudShadowInfo {
  int resolution = 0;
  double extent_m = 0.0;
  std::array<double, 3> origin_m{};             // world x, y, z of the map's north-west corner (row 0, column 0)
  std::array<double, 3> axis_u{1.0, 0.0, 0.0};  // columns (world +X, east)
  std::array<double, 3> axis_v{0.0, 0.0, 1.0};  // rows (world +Z, south)
  double receiver_altitude_m = 0.0;
  glm::dvec3 sun_direction{0.0, 1.0, 0.0};
  bool sun_above_horizon = true;  // false: the map is all zeros (no direct sunlight)
  double strength = 1.0;
  bool tiles = false;                                // the map repeats seamlessly beyond its edges
  std::vector<std::array<double, 2>> wind_offset_m;  // per active layer: [east, north] moved by the wind, m
};

// A rendered map: transmittance in [0, 1], resolution^2 values, row 0 north.
struct CloudShadowMap {
  CloudShadowInfo info;
  std::vector<float> transmittance;
};

// Whether a map of `extent_m` repeats without a seam: its extent is a whole
// number of tiles of every active layer's shape, detail and weather (or
// formation lattice, or weather image), east and north.
bool CloudShadowTiles(const CloudSettings& clouds, double extent_m);

// The placement of a frame's map (no rendering): the sun, the clouds' wind
// offsets at clock time `time_s`.
CloudShadowInfo CloudShadowInfoOf(const CloudSettings& clouds, const CloudShadowSettings& shadow, const glm::dvec3& sun,
                                  double time_s);

// EXR header attributes (skybake:shadow:*, names within the 31 characters of OpenEXR) of a map.
std::map<std::string, std::string> CloudShadowAttributes(const CloudShadowInfo& info);

// Turns the cloud pass's ground shadow on (GpuClouds.ground_shadow.x =
// strength, .y = steps) when the section and its `ground` are on; else leaves the
// inputs as they are (the sky pass's ground unchanged, byte for byte).
void ApplyGroundCloudShadow(const CloudShadowSettings& shadow, CloudInputs& clouds);

}  // namespace skybake
