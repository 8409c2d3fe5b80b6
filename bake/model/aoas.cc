#include "skybake/model/aoas.h"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>
#include <glm/glm.hpp>

namespace skybake {
namespace {

// Rec.709 luminance weights of linear RGB.
constexpr double kLuminanceWeights[3] = {0.2126, 0.7152, 0.0722};

double SrgbDecode(double v) { return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); }

// SplitMix64 (Steele, Lea, Flood 2014): a well-mixed 64-bit hash of a counter.
uint64_t SplitMix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// Uniform Catmull-Rom interpolation between p1 and p2 at t in [0, 1].
glm::dvec3 CatmullRom(const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2, const glm::dvec3& p3,
                      double t) {
  double t2 = t * t, t3 = t2 * t;
  return 0.5 * ((2.0 * p1) + (-p0 + p2) * t + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t2 +
                (-p0 + 3.0 * p1 - 3.0 * p2 + p3) * t3);
}

}  // namespace

bool ParseHexColor(const std::string& text, Rgb& linear_rgb) {
  if (text.size() != 7 || text[0] != '#') return false;
  Rgb rgb;
  for (int c = 0; c < 3; ++c) {
    int value = 0;
    for (int k = 0; k < 2; ++k) {
      char ch = text[1 + 2 * c + k];
      int digit = (ch >= '0' && ch <= '9')   ? ch - '0'
                  : (ch >= 'a' && ch <= 'f') ? ch - 'a' + 10
                  : (ch >= 'A' && ch <= 'F') ? ch - 'A' + 10
                                             : -1;
      if (digit < 0) return false;
      value = value * 16 + digit;
    }
    rgb[c] = SrgbDecode(value / 255.0);
  }
  linear_rgb = rgb;
  return true;
}

Rgb RayleighForTargetColor(const Rgb& target, const AtmosphereParams& physical, const Rgb& display_scale) {
  double physical_weight = 0.0, target_weight = 0.0;
  for (int c = 0; c < 3; ++c) {
    physical_weight +=
        kLuminanceWeights[c] * physical.rayleigh_scattering_per_km[c] * physical.solar_irradiance[c] * display_scale[c];
    target_weight += kLuminanceWeights[c] * target[c];
  }
  Rgb beta = {0.0, 0.0, 0.0};
  if (!(target_weight > 0.0)) return beta;  // black target: no Rayleigh scattering
  double k = physical_weight / target_weight;
  for (int c = 0; c < 3; ++c) {
    double per_beta = physical.solar_irradiance[c] * display_scale[c];
    beta[c] = per_beta > 0.0 ? k * target[c] / per_beta : 0.0;
  }
  return beta;
}

AtmosphereParams StyledAtmosphere(const AtmosphereParams& physical, const AoasSettings& aoas) {
  AtmosphereParams styled = physical;
  if (!aoas.hue.enabled) return styled;
  for (int c = 0; c < 3; ++c)
    styled.rayleigh_scattering_per_km[c] =
        physical.rayleigh_scattering_per_km[c] +
        aoas.hue.strength * (aoas.hue.rayleigh_per_km[c] - physical.rayleigh_scattering_per_km[c]);
  return styled;
}

glm::dvec3 DomeDirection(double elevation_deg, double azimuth_deg) {
  return SunDirectionFromElevationAzimuth(elevation_deg, azimuth_deg);
}

std::vector<ShapeArc> ShapeArcs(const CloudShapeSettings& settings) {
  std::vector<ShapeArc> arcs;
  const double kDegToRad = M_PI / 180.0;
  for (const CloudShape& shape : settings.shapes) {
    std::vector<glm::dvec3> p;
    for (const auto& point : shape.points) p.push_back(DomeDirection(point[0], point[1]));
    if (p.empty()) continue;
    const double radius = shape.radius_deg * kDegToRad;
    auto add = [&](const glm::dvec3& a, const glm::dvec3& b) { arcs.push_back({a, b, radius, shape.strength}); };
    const size_t n = p.size();
    if (shape.kind == ShapeKind::kPoint || n == 1) {
      for (const glm::dvec3& q : p) add(q, q);
      continue;
    }
    const size_t spans = shape.closed ? n : n - 1;
    for (size_t i = 0; i < spans; ++i) {
      const glm::dvec3& a = p[i];
      const glm::dvec3& b = p[(i + 1) % n];
      if (shape.kind == ShapeKind::kPolyline) {
        add(a, b);
        continue;
      }
      // Neighbours for the tangents; open ends repeat the end point.
      glm::dvec3 before = shape.closed ? p[(i + n - 1) % n] : (i == 0 ? a : p[i - 1]);
      glm::dvec3 after = shape.closed ? p[(i + 2) % n] : (i + 2 < n ? p[i + 2] : b);
      glm::dvec3 previous = a;
      for (int s = 1; s <= kAoasSplineSubdivisions; ++s) {
        double t = double(s) / kAoasSplineSubdivisions;
        glm::dvec3 next = s == kAoasSplineSubdivisions ? b : glm::normalize(CatmullRom(before, a, b, after, t));
        add(previous, next);
        previous = next;
      }
    }
  }
  return arcs;
}

glm::dvec3 SeedOffset(uint32_t seed, uint32_t stream) {
  glm::dvec3 offset;
  for (int i = 0; i < 3; ++i) {
    uint64_t h = SplitMix64((uint64_t(seed) << 32) ^ (uint64_t(stream) << 8) ^ uint64_t(i));
    offset[i] = double(h % 16384) / 256.0;
  }
  return offset;
}

AoasInputs ToAoasInputs(const AoasSettings& aoas, const Rgb& color_scale) {
  AoasInputs in;
  std::vector<ShapeArc> arcs = aoas.shapes.enabled ? ShapeArcs(aoas.shapes) : std::vector<ShapeArc>{};
  if (arcs.size() > AOAS_MAX_SHAPE_SEGMENTS)
    throw std::invalid_argument(
        fmt::format("the cloud shapes need {} arcs; at most {} fit", arcs.size(), AOAS_MAX_SHAPE_SEGMENTS));
  in.switches.skydome = aoas.skydome.enabled;
  in.switches.ambiguity = aoas.ambiguity.enabled;
  in.switches.cloud_noise = aoas.clouds.enabled;
  in.switches.cloud_shapes = aoas.shapes.enabled && !arcs.empty();

  auto v4 = [](const glm::dvec3& v, double w) { return gpu::vec4{float(v.x), float(v.y), float(v.z), float(w)}; };
  gpu::GpuAoas& g = in.uniform;
  const SkydomeSettings& dome = aoas.skydome;
  g.dome = {float(dome.enabled ? dome.radius : 1.0), float(aoas.ambiguity.l_pt), float(aoas.ambiguity.grain), 0.0f};
  g.viewer = v4(dome.enabled ? dome.viewer_position : glm::dvec3(0.0), 0.0);
  g.perturbation_offset = v4(SeedOffset(aoas.seed, 0), 0.0);
  g.noise = {float(aoas.clouds.s_noise), float(aoas.clouds.threshold), float(aoas.clouds.strength),
             float(aoas.shapes.strength)};
  g.noise_offset = v4(SeedOffset(aoas.seed, 1) + aoas.clouds.drift, 0.0);
  g.color_scale = v4(glm::dvec3(color_scale[0], color_scale[1], color_scale[2]), 0.0);
  g.counts = {int32_t(arcs.size()), aoas.clouds.octaves, 0, 0};
  static constexpr int kPermutation[256] = {SKYBAKE_PERLIN_PERMUTATION};
  for (int i = 0; i < 64; ++i)
    g.perlin_permutation[i] = {kPermutation[4 * i], kPermutation[4 * i + 1], kPermutation[4 * i + 2],
                               kPermutation[4 * i + 3]};
  for (size_t i = 0; i < arcs.size(); ++i) {
    g.shape_segments[2 * i] = v4(arcs[i].start, arcs[i].radius_rad);
    g.shape_segments[2 * i + 1] = v4(arcs[i].end, arcs[i].strength);
  }
  return in;
}

}  // namespace skybake
