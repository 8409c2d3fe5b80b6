#include "skybake/model/clouds.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>

namespace skybake {

std::array<double, 4> CloudTypeProfile(CloudType type) {
  // [bottom_in, bottom_full, top_full, top_out], fractions of the layer's
  // own thickness: the shapes of the Nubis height gradients (a flat base and
  // a low top for stratus, a fast rise and a rounded top for cumulus, nearly
  // the whole column for cumulonimbus, a thin sheet for cirrus), each for a
  // layer that holds one type.
  switch (type) {
    case CloudType::kStratus:
      return {0.0, 0.1, 0.7, 1.0};
    case CloudType::kStratocumulus:
      return {0.0, 0.15, 0.55, 1.0};
    case CloudType::kCumulus:
      return {0.0, 0.08, 0.45, 1.0};
    case CloudType::kCumulonimbus:
      return {0.0, 0.05, 0.8, 1.0};
    case CloudType::kCirrus:
      return {0.0, 0.35, 0.65, 1.0};
    case CloudType::kCustom:
      break;
  }
  return {0.0, 0.1, 0.5, 1.0};
}

const char* CloudTypeName(CloudType type) {
  switch (type) {
    case CloudType::kStratus:
      return "stratus";
    case CloudType::kStratocumulus:
      return "stratocumulus";
    case CloudType::kCumulus:
      return "cumulus";
    case CloudType::kCumulonimbus:
      return "cumulonimbus";
    case CloudType::kCirrus:
      return "cirrus";
    case CloudType::kCustom:
      return "custom";
  }
  return "custom";
}

CloudQuality CloudQualityPreset(const std::string& name) {
  // From the cloud study's Pareto front (`skybake accuracy --study clouds`,
  // docs/accuracy.md "Clouds"): the cheapest case within each preset's bound
  // on the mean relative error over the sky, worst of a 45 and a 10 deg sun
  // (draft 10%, production 5%, reference 1%; ties within the CPU time's 10%
  // noise go to the lower error).
  // The light march's far samples read the nearest voxel (all but the first
  // light_trilinear_steps): production 3.42e-2 -> 3.50e-2 with 8 of 24
  // trilinear, draft 8.77e-2 -> 8.95e-2 with 3 of 12 (2026-12-02 run); the
  // reference keeps every light sample trilinear.
  // The light volume (CloudLightVolume in clouds.h): production 256 columns
  // x 32 slices, 2 exact near steps (3.50e-2 -> 4.26e-2; 512 columns 3.56e-2
  // for 4 times the volume's cost, 16 slices 5.7e-2); draft 256 x 16, 1
  // (8.95e-2 -> 9.29e-2); the reference marches every light sample.
  CloudQuality q;  // production: 48 / 24 steps, volumes 64 / 32 / 256, 4.3e-2
  q.light_trilinear_steps = 8;
  if (name == "draft") {
    q.view_steps = 24;  // 9.0e-2, 0.60 x production's CPU time
    q.light_steps = 12;
    q.light_trilinear_steps = 3;
    q.light_volume_columns = 256;
    q.light_volume_slices = 16;
    q.light_volume_near_steps = 1;
  } else if (name == "reference") {
    q.light_volume_columns = 0;
    q.light_trilinear_steps = 256;
    q.view_steps = 128;  // 8.4e-3, 3.2 x production's CPU time
    q.light_steps = 32;
    q.shape_resolution = 128;
    q.detail_resolution = 64;
    q.weather_resolution = 512;
  }
  return q;
}

std::vector<CloudLayer> ActiveCloudLayers(const CloudSettings& clouds) {
  std::vector<CloudLayer> active;
  for (const CloudLayer& l : clouds.layers)
    if (l.coverage > 0.0 && l.density_per_m > 0.0) active.push_back(l);
  std::stable_sort(active.begin(), active.end(),
                   [](const CloudLayer& a, const CloudLayer& b) { return a.altitude_m < b.altitude_m; });
  return active;
}

namespace {

std::string ResolvePath(const std::string& path, const std::string& style_dir) {
  std::filesystem::path p(path);
  if (p.is_relative() && !style_dir.empty()) p = std::filesystem::path(style_dir) / p;
  return p.string();
}

}  // namespace

std::vector<CloudProblem> ValidateClouds(const CloudSettings& clouds, const AtmosphereParams& atmosphere,
                                         const std::string& style_dir) {
  std::vector<CloudProblem> problems;
  if (int(clouds.layers.size()) > kMaxCloudLayers)
    problems.push_back({kMaxCloudLayers, "",
                        fmt::format("{} cloud layers; at most {} fit: merge or remove [[cloud_layer]] tables",
                                    clouds.layers.size(), kMaxCloudLayers)});
  const double loops = CloudLoopIterationsPerTexel(clouds);
  if (loops > kMaxCloudLoopIterations)
    problems.push_back(
        {-2, "",
         fmt::format("{} cloud layer(s) x {} view steps x {} light steps may run {:.0f} loop "
                     "iterations per texel; lavapipe ends a shader's loops after 65535 in all "
                     "(LP_MAX_TGSI_LOOP_ITERATIONS): lower quality.cloud_view_steps or "
                     "quality.cloud_light_steps (at most {:.0f} iterations)",
                     std::min<size_t>(ActiveCloudLayers(clouds).size(), kMaxCloudLayers), clouds.quality.view_steps,
                     clouds.quality.light_steps, loops, kMaxCloudLoopIterations)});
  // The light volume shares the noise buffer (one storage buffer: lavapipe
  // binds at most 128 MiB): at most 64 MiB of it.
  const CloudQuality& q = clouds.quality;
  const double volume_mib =
      double(q.light_volume_columns) * q.light_volume_columns * q.light_volume_slices * 4.0 / (1024.0 * 1024.0);
  if (!ActiveCloudLayers(clouds).empty() && q.light_volume_columns > 0 && volume_mib > 64.0)
    problems.push_back({-3, "",
                        fmt::format("{0} x {0} columns x {1} slices make a light volume of {2:.0f} MiB, above 64 MiB: "
                                    "lower quality.cloud_light_volume_columns or quality.cloud_light_volume_slices",
                                    q.light_volume_columns, q.light_volume_slices, volume_mib)});
  const double atmosphere_m = (atmosphere.top_radius_km - atmosphere.bottom_radius_km) * 1000.0;
  for (size_t i = 0; i < clouds.layers.size(); ++i) {
    const CloudLayer& l = clouds.layers[i];
    const int index = int(i);
    const double top = l.altitude_m + l.thickness_m;
    if (top > atmosphere_m)
      problems.push_back({index, "thickness_m",
                          fmt::format("the layer's top at {} m is above the top of the atmosphere ({} m): lower "
                                      "altitude_m or thickness_m",
                                      top, atmosphere_m)});
    const std::array<double, 4>& p = l.profile;
    if (!(p[0] <= p[1] && p[1] <= p[2] && p[2] <= p[3]) || p[0] < 0.0 || p[3] > 1.0 || p[3] <= p[0])
      problems.push_back({index, "profile",
                          fmt::format("[{}, {}, {}, {}]: expected [bottom_in, bottom_full, top_full, top_out], "
                                      "non-decreasing fractions in [0, 1] with top_out > bottom_in",
                                      p[0], p[1], p[2], p[3])});
    if (l.formation.enabled && !l.formation.mask_image.empty()) {
      const std::string path = ResolvePath(l.formation.mask_image, style_dir);
      std::string problem = CheckCloudMask(path, l.formation);
      if (!problem.empty()) problems.push_back({index, "formation.mask_image", fmt::format("{}: {}", path, problem)});
    }
    if (!l.weather_image.empty()) {
      const std::string path = ResolvePath(l.weather_image, style_dir);
      std::string problem = CheckWeatherImage(path);
      if (!problem.empty())
        problems.push_back(
            {index, "weather_image",
             fmt::format("{}: {}: give an EXR or PNG whose first channel is the coverage, 0..1", path, problem)});
    }
  }
  return problems;
}

double CloudEarthShadowElevationDeg(double bottom_radius_km, double observer_altitude_km, double highest_top_km,
                                    double max_distance_km, double sun_angular_radius_rad) {
  const double R = bottom_radius_km;
  const double r0 = R + std::max(observer_altitude_km, 0.0);
  const double r_top = R + std::max(highest_top_km, 0.0) + 0.01;
  // The disc's visibility is 0 where mu_s <= this, at every radius up to r_top.
  const double x = R / r_top;
  const double mu_shadow = -std::sqrt(1.0 - x * x) - x * sun_angular_radius_rad - 1e-4;
  // The farthest sample, and the largest angle between its zenith and the observer's.
  const double t_max = std::min(max_distance_km, std::sqrt(r0 * r0 - R * R) + std::sqrt(r_top * r_top - R * R));
  const double gamma = 2.0 * std::asin(std::min(t_max / (2.0 * R), 1.0));
  // theta_s - gamma >= acos(mu_shadow): the elevation pi / 2 - theta_s.
  return (M_PI / 2.0 - gamma - std::acos(mu_shadow)) * 180.0 / M_PI;
}

double CloudLoopIterationsPerTexel(const CloudSettings& clouds) {
  const double layers = double(std::min<size_t>(ActiveCloudLayers(clouds).size(), kMaxCloudLayers));
  if (layers == 0.0) return 0.0;
  const CloudQuality& q = clouds.quality;
  // Per view sample: the layer loop; per lit sample also the lighting loop's
  // own iteration, the light march (each step a layer loop), the octaves and
  // the albedo's layer loop, and with more than one layer the march through
  // the bands above (a band per layer at most, min(light_steps, 4) steps
  // each, each a layer loop).
  const double above = layers > 1.0 ? layers * (1.0 + std::min(q.light_steps, 4) * (1.0 + layers)) : 0.0;
  // The light march is two loops (trilinear, then nearest reads), one of
  // them possibly empty: a loop runs its body at least once.
  // The empty-space loop (clouds.glsl, CloudMargin) adds its own iteration
  // and its layer loop per view sample.
  const double per_sample = 3.0 + 2.0 * layers + (q.light_steps + 1) * (1.0 + layers) + q.octaves + layers + above;
  return layers * q.view_steps * per_sample;
}

size_t CloudNoiseFloats(const gpu::GpuClouds& c) {
  const size_t layers = size_t(std::max(c.counts.x, 0));
  return std::max<size_t>(CloudSkipFirst(c) + layers * CloudSkipFloatsPerLayer(c), 4);
}

size_t CloudSkipFirst(const gpu::GpuClouds& c) {
  const size_t per_layer = size_t(c.resolution.x) * c.resolution.x * c.resolution.x +
                           size_t(c.resolution.y) * c.resolution.y * c.resolution.y +
                           size_t(c.resolution.z) * c.resolution.z;
  return per_layer * size_t(std::max(c.counts.x, 0));
}

size_t CloudSkipFloatsPerLayer(const gpu::GpuClouds& c) {
  const size_t nw = size_t(c.resolution.z), ns = size_t(c.resolution.x);
  return nw * nw + ns * ns * ns;  // one cell per texel
}

namespace {

// The maximum along one axis of a grid (`size` [x, y, z] values, x fastest)
// over each cell's two texels: for cell a, the values at a and a + 1,
// wrapped. `axis` 0, 1, 2; the result has the same size.
std::vector<float> CellMaxAlong(const std::vector<float>& v, std::array<int, 3> size, int axis) {
  const int n = size[axis];
  const size_t stride = axis == 0 ? 1 : axis == 1 ? size_t(size[0]) : size_t(size[0]) * size[1];
  std::vector<float> r(v.size());
  for (int z = 0; z < size[2]; ++z)
    for (int y = 0; y < size[1]; ++y)
      for (int x = 0; x < size[0]; ++x) {
        const std::array<int, 3> p = {x, y, z};
        const size_t i = (size_t(z) * size[1] + y) * size[0] + x;
        const size_t next = p[axis] + 1 < n ? i + stride : i - size_t(n - 1) * stride;
        r[i] = std::max(v[i], v[next]);
      }
  return r;
}

}  // namespace

void FillCloudSkipMaps(const gpu::GpuClouds& c, float* noise) {
  const int ns = c.resolution.x, nw = c.resolution.z;
  float* out = noise + CloudSkipFirst(c);
  for (int l = 0; l < c.counts.x; ++l, out += CloudSkipFloatsPerLayer(c)) {
    const gpu::GpuCloudLayer& layer = c.layers[l];
    std::vector<float> weather(noise + layer.noise.z, noise + layer.noise.z + size_t(nw) * nw);
    weather = CellMaxAlong(CellMaxAlong(weather, {nw, nw, 1}, 0), {nw, nw, 1}, 1);
    std::copy(weather.begin(), weather.end(), out);
    float* shape_out = out + weather.size();
    if (layer.weather.w > 1.5f) {
      std::fill(shape_out, shape_out + size_t(ns) * ns * ns, 1.0f);
      continue;
    }
    std::vector<float> shape(noise + layer.noise.x, noise + layer.noise.x + size_t(ns) * ns * ns);
    for (int axis = 0; axis < 3; ++axis) shape = CellMaxAlong(shape, {ns, ns, ns}, axis);
    std::copy(shape.begin(), shape.end(), shape_out);
  }
}

gpu::GpuClouds CloudGeometryUniform(const CloudSettings& clouds) {
  gpu::GpuClouds g{};
  const std::vector<CloudLayer> layers = ActiveCloudLayers(clouds);
  if (layers.empty()) return g;
  const CloudQuality& q = clouds.quality;
  const int count = std::min<int>(int(layers.size()), kMaxCloudLayers);
  g.counts = {count, q.view_steps, q.light_steps, q.octaves};
  g.resolution = {q.shape_resolution, q.detail_resolution, q.weather_resolution, 0};
  // Aerial-perspective LUT 32 azimuths x 64 zenith angles x 32 distances;
  // ambient table of 16 altitudes.
  g.lut = {32, 64, 32, 16};
  // Hillaire 2016 / takram defaults: forward 0.7, backward -0.2, mixed 0.5;
  // Wrenninge 2013 octaves a = b = c = 0.5.
  // phase.w: the light samples read trilinearly (clouds.glsl,
  // CloudOpticalDepthToSun); all of them, those of the bands above too, when
  // light_trilinear_steps >= light_steps.
  const int trilinear = q.light_trilinear_steps >= q.light_steps ? 4096 : q.light_trilinear_steps;
  g.phase = {0.7f, -0.2f, 0.5f, float(trilinear)};
  g.octave = {0.5f, 0.5f, 0.5f, 0.0f};
  double top_km = 0.0;
  for (int i = 0; i < count; ++i) {
    const CloudLayer& l = layers[i];
    gpu::GpuCloudLayer& o = g.layers[i];
    const double bottom_km = l.altitude_m * 1e-3, thickness_km = l.thickness_m * 1e-3;
    top_km = std::max(top_km, bottom_km + thickness_km);
    o.shell = {float(bottom_km), float(bottom_km + thickness_km), float(l.density_per_m * 1e3), float(l.albedo)};
    o.profile = {float(l.profile[0]), float(l.profile[1]), float(l.profile[2]), float(l.profile[3])};
    o.shape = {float(l.shape_amount), float(1e3 / l.shape_size_m), float(l.detail_amount),
               float(1e3 / l.detail_size_m)};
    if (l.type == CloudType::kCirrus) {
      // World x = east, z = -north; the hook from the shear along the
      // streaks, (m/s per km) / (m/s) = km^-1.
      const std::array<double, 2> a = CirrusStreakDirection(l);
      const double shear_along = l.shear_m_s_per_km[0] * a[0] + l.shear_m_s_per_km[1] * a[1];
      o.streaks = {float(a[0]), float(-a[1]), float(l.streak_ratio), float(shear_along / (2.0 * kCirrusFallSpeedM_s))};
    }
  }
  // range.w: the view march skips empty space (FillCloudSkipMaps).
  g.range = {float(q.max_distance_km), float(std::max(top_km + 1.0, 1.0)), float(q.panorama_scale), 1.0f};
  // Bands: the layers' shells, overlapping ones merged (layers are sorted by bottom).
  int bands = 0;
  for (int i = 0; i < count; ++i) {
    const float lo = g.layers[i].shell.x, hi = g.layers[i].shell.y;
    if (bands > 0 && lo <= g.bands[bands - 1].y) {
      g.bands[bands - 1].y = std::max(g.bands[bands - 1].y, hi);
    } else {
      g.bands[bands++] = {lo, hi, 0.0f, 0.0f};
    }
  }
  g.resolution.w = bands;
  // The light volume after the noise and its bounds (CloudNoiseFloats).
  if (q.light_volume_columns > 0) {
    g.light_volume = {q.light_volume_columns, q.light_volume_slices, q.light_volume_near_steps,
                      int32_t(CloudNoiseFloats(g))};
    // The columns' feet reach past the farthest sample by the band's
    // thickness over the tangent of the Sun's lowest elevation there
    // (kCloudLightVolumeMinElevationDeg less the curvature's tilt at that
    // distance, taken as 4 deg at most): a generous 2 deg here.
    double thickness_km = 0.0;
    for (int b = 0; b < g.resolution.w; ++b) thickness_km = std::max(thickness_km, double(g.bands[b].y - g.bands[b].x));
    const double extent_km = 1.1 * q.max_distance_km + thickness_km / std::tan(2.0 * M_PI / 180.0);
    g.light_volume_grid = {float(kCloudLightVolumeWarpKm), float(std::asinh(extent_km / kCloudLightVolumeWarpKm)),
                           float(kCloudLightVolumeSubsteps), 0.0f};
  }
  return g;
}

double CloudEarthShadowElevationDeg(const gpu::GpuClouds& clouds, const gpu::GpuAtmosphere& atmosphere) {
  double top = 0.0;
  for (int b = 0; b < clouds.resolution.w; ++b) top = std::max(top, double(clouds.bands[b].y));
  return CloudEarthShadowElevationDeg(atmosphere.radii.x, atmosphere.radii.z, top, clouds.range.x,
                                      atmosphere.solar_irradiance.w);
}

CloudInputs ToCloudInputs(const CloudSettings& clouds, uint32_t aoas_seed, const std::string& style_dir,
                          double time_s) {
  CloudInputs in;
  gpu::GpuClouds& g = in.uniform;
  g = CloudGeometryUniform(clouds);
  const int count = g.counts.x;
  if (count == 0) return in;
  const std::vector<CloudLayer> layers = ActiveCloudLayers(clouds);
  const CloudQuality& q = clouds.quality;
  const size_t shape = size_t(q.shape_resolution) * q.shape_resolution * q.shape_resolution;
  const size_t detail = size_t(q.detail_resolution) * q.detail_resolution * q.detail_resolution;
  const size_t weather = size_t(q.weather_resolution) * q.weather_resolution;
  for (int i = 0; i < count; ++i) {
    const CloudLayer& l = layers[i];
    gpu::GpuCloudLayer& o = g.layers[i];
    // World x = east, z = -north. A formation's layer moves on the
    // formation's clock (cloud_formation.h), so that a clock time bakes the
    // same clouds whichever frame a schedule starts at.
    const double seconds =
        l.formation.enabled ? FormationTimeSeconds(l.formation, clouds.local_clock_s, time_s) : time_s;
    o.wind_offset = {float(l.wind_m_s[0] * seconds * 1e-3), float(-l.wind_m_s[1] * seconds * 1e-3),
                     float(l.shear_m_s_per_km[0] * seconds * 1e-3), float(-l.shear_m_s_per_km[1] * seconds * 1e-3)};
    if (l.formation.enabled) {
      ApplyCloudFormation(l, l.seed.value_or(aoas_seed), q.weather_resolution, seconds, style_dir, o, in.weather_images,
                          q.shape_resolution);
    } else if (l.weather_image.empty()) {
      o.weather = {float(l.coverage), float(1e3 / l.weather_size_m), float(1e3 / l.weather_size_m), 0.0f};
      // z: the warp's weather tile (km; 0 when the layer tiles), w: the
      // weather read three times through it (shaders/cloud_weather.glsl).
      o.weather_origin = {0.0f, 0.0f, l.tiling ? 0.0f : float(l.weather_size_m * 1e-3), l.tiling ? 0.0f : 1.0f};
    } else {
      // The image's north-west corner (row 0, column 0) at world x = west
      // edge, z = -(north edge).
      o.weather = {float(l.coverage), float(1e3 / l.weather_extent_m[0]), float(1e3 / l.weather_extent_m[1]), 1.0f};
      // The image as placed; only the shape is warped (z), by the warp of
      // the layer's weather_size_m.
      o.weather_origin = {float(l.weather_origin_m[0] * 1e-3),
                          float(-(l.weather_origin_m[1] + l.weather_extent_m[1]) * 1e-3),
                          l.tiling ? 0.0f : float(l.weather_size_m * 1e-3), 0.0f};
      const std::vector<float> map = ReadWeatherImage(ResolvePath(l.weather_image, style_dir), q.weather_resolution);
      in.weather_images.insert(in.weather_images.end(), map.begin(), map.end());
    }
    const size_t first = size_t(i) * (shape + detail + weather);
    o.noise = {int32_t(first), int32_t(first + shape), int32_t(first + shape + detail),
               int32_t(l.seed.value_or(aoas_seed))};
  }
  return in;
}

size_t CloudLightVolumeFloats(const gpu::GpuClouds& c) {
  if (c.light_volume.x <= 0) return 0;
  return size_t(c.light_volume.x) * size_t(c.light_volume.x) * size_t(c.light_volume.y);
}

bool CloudLightVolumeOn(const gpu::GpuClouds& c) {
  return c.counts.x > 0 && c.light_volume.x > 0 && c.resolution.w == 1;
}

std::array<double, 2> CirrusStreakDirection(const CloudLayer& l) {
  const double half_km = 0.5 * l.thickness_m * 1e-3;
  const double east = l.wind_m_s[0] + l.shear_m_s_per_km[0] * half_km;
  const double north = l.wind_m_s[1] + l.shear_m_s_per_km[1] * half_km;
  const double speed = std::hypot(east, north);
  if (speed < 1e-6) return {1.0, 0.0};
  return {east / speed, north / speed};
}

bool CloudCirrusOn(const gpu::GpuClouds& c) {
  for (int l = 0; l < std::min(c.counts.x, CLOUD_MAX_LAYERS); ++l)
    if (c.layers[l].streaks.z > 0.0f) return true;
  return false;
}

bool CloudFormationDensityOn(const gpu::GpuClouds& c) {
  for (int l = 0; l < std::min(c.counts.x, CLOUD_MAX_LAYERS); ++l)
    if (c.layers[l].weather.w > 1.5f) return true;
  return false;
}

bool CloudLightVolumeForSun(const gpu::GpuClouds& c, double sun_y) {
  return CloudLightVolumeOn(c) && sun_y >= std::sin(kCloudLightVolumeMinElevationDeg * M_PI / 180.0);
}

}  // namespace skybake
