// The aesthetic principles of AOAS ("Aesthetically-Oriented Atmospheric
// Scattering", Shen, Mallett, Shkurko, Eurographics 2019) as a style sets
// them, and their packing for the shaders (shaders/aoas.glsl).
//
// Frame: skydome space is the world frame, +Y up, North = -Z, East = +X; the
// ground plane passes through the dome centre. Positions on the dome are
// given in degrees: elevation above the horizon, azimuth clockwise from North
// (compass bearing). Sizes of the principles (l_pt, s_noise, grain) are in
// dome radii, so they do not change when the dome is scaled.
//
// Each principle has an on/off switch (AoasSwitches); the ones that change
// shader code are specialization constants 4..7 of shaders/common.glsl.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "skybake/model/atmosphere.h"
#include "skybake/gpu_shared.h"

namespace skybake {

// Splines are sampled into this many arcs per span between control points.
constexpr int kAoasSplineSubdivisions = 8;

// Section 3.2: the single atmosphere skydome.
struct SkydomeSettings {
  bool enabled = false;
  double radius = 1.0;                           // dome radius R, scene units (> 0)
  glm::dvec3 viewer_position = {0.0, 0.0, 0.0};  // P^s_v, scene units, |P| < R, y >= 0
};

// Sky hue: the Rayleigh constants replaced by a free RGB vector (km^-1 at
// 680/550/440 nm), given directly or as a target colour "#rrggbb" (sRGB).
struct HueSettings {
  bool enabled = false;
  std::string color;  // "#rrggbb"; when set, it decides `rayleigh_per_km`
  Rgb rayleigh_per_km = {5.802e-3, 13.558e-3, 33.100e-3};
  double strength = 1.0;  // 0: physical constants, 1: the hue vector
};

// Ambiguity, eq. 5-6: the view direction towards P^s_f is replaced by the one
// towards P^s_f + <rand(l_pt), rand(l_pt), rand(l_pt)>.
struct AmbiguitySettings {
  bool enabled = false;
  double l_pt = 0.02;    // neighbourhood half size, dome radii
  double grain = 0.004;  // feature size of the random field, dome radii
};

// Cloud complexity, eq. 7-8: Improved Perlin noise scaling HSV saturation.
struct CloudNoiseSettings {
  bool enabled = false;
  double s_noise = 0.25;               // feature size S_noise, dome radii
  int octaves = 4;                     // fractal octaves
  double threshold = 0.0;              // noise below this gives no cloud, in [-1, 1)
  double strength = 0.8;               // saturation removed at the noise peaks, [0, 1]
  glm::dvec3 drift = {0.0, 0.0, 0.0};  // offset of the noise field, in S_noise units
};

// Cloud shapes: clouds along user points, polylines or splines, fading
// linearly with angular distance.
enum class ShapeKind { kPoint, kPolyline, kSpline };
struct CloudShape {
  ShapeKind kind = ShapeKind::kPoint;
  std::vector<std::array<double, 2>> points;  // [elevation_deg, azimuth_deg]
  bool closed = false;                        // polyline/spline: join the last point to the first
  double radius_deg = 3.0;                    // distance at which the cloud has faded to nothing
  double strength = 1.0;                      // saturation removed on the shape, [0, 1]
};
struct CloudShapeSettings {
  bool enabled = false;
  double strength = 1.0;  // scales every shape
  std::vector<CloudShape> shapes;
};

struct AoasSettings {
  uint32_t seed = 1;  // drives the perturbation field and the cloud noise
  SkydomeSettings skydome;
  HueSettings hue;
  AmbiguitySettings ambiguity;
  CloudNoiseSettings clouds;
  CloudShapeSettings shapes;
};

// The shader-code switches (specialization constants 4..7).
struct AoasSwitches {
  bool skydome = false;
  bool ambiguity = false;
  bool cloud_noise = false;
  bool cloud_shapes = false;
};

// What the renderer needs for the principles that act per texel.
struct AoasInputs {
  AoasSwitches switches;
  gpu::GpuAoas uniform{};
};

// Linear sRGB/Rec.709 of "#rrggbb"; false if the text is not of that form.
bool ParseHexColor(const std::string& text, Rgb& linear_rgb);

// A Rayleigh vector whose sky has the hue of `target_linear_rgb` (seen in the
// Rec.709 RGB `display_scale` maps radiance to) and the physical luminance
// gradient. In the optically thin limit single-scattered radiance in channel
// c is proportional to beta_c E_c, so beta_c = k t_c / (E_c K_c) (E: solar
// irradiance, K: display_scale) gives the target hue; k makes the
// luminance-weighted optical thickness sum_c Y_c beta_c E_c K_c equal to the
// physical one, which keeps the sky's brightness and its gradient.
Rgb RayleighForTargetColor(const Rgb& target_linear_rgb, const AtmosphereParams& physical, const Rgb& display_scale);

// The atmosphere with the hue principle applied (the Rayleigh constants
// mixed towards the hue vector by hue.strength).
AtmosphereParams StyledAtmosphere(const AtmosphereParams& physical, const AoasSettings& aoas);

// Unit direction of a dome position (elevation, azimuth clockwise from North).
glm::dvec3 DomeDirection(double elevation_deg, double azimuth_deg);

// The arcs of every shape: points become zero-length arcs, polylines one arc
// per edge, splines (Catmull-Rom through the points, on the unit sphere)
// kAoasSplineSubdivisions arcs per span. Each arc: start, end.
struct ShapeArc {
  glm::dvec3 start, end;
  double radius_rad;
  double strength;
};
std::vector<ShapeArc> ShapeArcs(const CloudShapeSettings& shapes);

// Packs the per-texel principles. `color_scale` maps radiance to the Rec.709
// RGB in which saturation is judged (OutputScale(kLuminance)). Throws
// std::invalid_argument when the shapes need more than
// AOAS_MAX_SHAPE_SEGMENTS arcs (the style check reports it first).
AoasInputs ToAoasInputs(const AoasSettings& aoas, const Rgb& color_scale);

// The seed's offset of a noise field (stream 0: perturbation, 1: clouds):
// multiples of 1/256 in [0, 64), exact in float and double alike.
glm::dvec3 SeedOffset(uint32_t seed, uint32_t stream);

}  // namespace skybake
