#include "cloud_plan.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>

#include <fmt/format.h>

#include "skybake/gpu/cloud_panorama.h"
#include "skybake/model/cloud_formation.h"
#include "skybake/model/clouds.h"

namespace skybake {

void AddCloudMarchPlan(const SkyStyle& first, int layers, const std::vector<ViewRequest>& views, int frames,
                       int shadowed, double shadow_below_deg, PassPlan& plan) {
  const CloudQuality& cq = first.clouds.quality;
  const double per_texel = double(cq.view_steps) * layers * (1.0 + cq.light_steps);
  const double per_texel_shadowed = double(cq.view_steps) * layers;
  // A marching pass: its sunlit frames, then its frames in the Earth's shadow.
  auto march = [&](const std::string& name, const std::string& size, const std::string& frequency, double texels) {
    if (frames > shadowed) plan.passes.push_back({name, size, frequency, frames - shadowed, texels * per_texel});
    if (shadowed > 0)
      plan.passes.push_back({name + " in the Earth's shadow", size,
                             fmt::format("frames with the Sun below {:.2f} deg (no light march)", shadow_below_deg),
                             shadowed, texels * per_texel_shadowed});
  };
  auto view_name = [](const ViewRequest& v) {
    return v.mapping == MAPPING_LATLONG      ? std::string("clouds latlong")
           : v.mapping == MAPPING_CUBE_STRIP ? std::string("clouds cube strip")
                                             : fmt::format("clouds face {}", v.face);
  };
  // The light volume (clouds.h, CloudLightVolume), where the renderer uses it
  // (CloudLightVolumeOn); a frame with the Sun below
  // kCloudLightVolumeMinElevationDeg does without it.
  if (CloudLightVolumeOn(CloudGeometryUniform(first.clouds)) && frames > shadowed)
    plan.passes.push_back(
        {"cloud light volume",
         fmt::format("{0} x {0} columns x {1} slices, {2} exact near steps", cq.light_volume_columns,
                     cq.light_volume_slices, cq.light_volume_near_steps),
         fmt::format("once per frame with the Sun above {:.0f} deg (quality.cloud_light_volume_columns)",
                     kCloudLightVolumeMinElevationDeg),
         frames - shadowed,
         double(cq.light_volume_columns) * cq.light_volume_columns * (cq.light_volume_slices - 1) *
             kCloudLightVolumeSubsteps});
  const CloudPanorama panorama = ChooseCloudPanorama(views, cq.panorama_scale);
  if (panorama.width == 0) {
    for (const ViewRequest& v : views)
      march(view_name(v), fmt::format("{} x {}", v.width, v.height), "once per frame (at most)",
            double(v.width) * v.height);
    return;
  }
  std::vector<std::array<double, 2>> bands;
  for (const CloudLayer& l : ActiveCloudLayers(first.clouds))
    bands.push_back({l.altitude_m * 1e-3, (l.altitude_m + l.thickness_m) * 1e-3});
  const CloudPanoramaRows rows = CloudPanoramaRowsSeeingBands(panorama, first.atmosphere.bottom_radius_km,
                                                              first.atmosphere.observer_altitude_m * 1e-3, bands);
  march("clouds panorama",
        fmt::format("{} x {}, rows {} to {} marched, {} texels", panorama.width, panorama.height, rows.begin,
                    rows.end - 1, CloudPanoramaMarchedTexels(panorama, rows)),
        fmt::format("once per frame (quality.cloud_panorama_scale = {})", cq.panorama_scale),
        double(CloudPanoramaMarchedTexels(panorama, rows)));
  for (const ViewRequest& v : views)
    plan.passes.push_back(
        {view_name(v) + " (resampled)", fmt::format("{} x {}", v.width, v.height), "once per frame", frames, 0.0});
}

void AddCloudShadowPlan(const SkyStyle& first, int frames, PassPlan& plan) {
  const CloudShadowSettings& s = first.cloud_shadow;
  const std::vector<CloudLayer> layers = ActiveCloudLayers(first.clouds);
  const bool runs = s.enabled && !layers.empty() && s.strength > 0.0;
  const std::string why_off = !layers.empty() ? "cloud_shadow.strength = 0 (the map is all ones, no pass)"
                                              : "no cloud layer after pruning (the map is all ones, no pass)";
  plan.effects.push_back({"cloud shadow map", s.enabled, runs,
                          runs ? fmt::format("[cloud_shadow] enabled, {} x {} texels over {} m, strength {}",
                                             s.resolution, s.resolution, s.extent_m, s.strength)
                               : (s.enabled ? why_off : "switched off in the style")});
  const bool ground = s.enabled && s.ground;
  const bool ground_on = ground && runs && PrunedStyle(first).effects.ground;
  plan.effects.push_back(
      {"ground cloud shadow", ground, ground_on,
       ground_on ? fmt::format("cloud_shadow.ground = true: below-horizon texels march {} steps per band", s.steps)
       : ground  ? (runs ? "the sky shows no ground (effects.ground off or ground_albedo 0)" : why_off)
                 : "switched off in the style"});
  if (!runs) return;
  const int bands = CloudGeometryUniform(first.clouds).resolution.w;  // the shells merged where they overlap
  plan.passes.push_back({"cloud shadow map", fmt::format("{} x {}", s.resolution, s.resolution),
                         "once per frame with the Sun up", frames,
                         double(s.resolution) * s.resolution * s.steps * bands});
}

void AddCloudFormationPlan(const std::vector<SkyStyle>& frames, const std::vector<double>& hours_from_start,
                           PassPlan& plan) {
  const SkyStyle& first = frames.front();
  bool requested = false;
  for (const CloudLayer& l : first.clouds.layers) requested = requested || l.formation.enabled;
  std::string why_on;
  for (const CloudLayer& l : ActiveCloudLayers(first.clouds)) {
    const CloudFormation& f = l.formation;
    if (!f.enabled) continue;
    // The steps a process simulates: from 0 to the last frame's step, and
    // the one after it when the frame falls between two; on the formation's
    // clock (cloud_formation.h), from the first frame's local clock time.
    uint64_t steps = 0;
    for (size_t i = 0; i < std::max<size_t>(hours_from_start.size(), 1); ++i) {
      const double h = i < hours_from_start.size() ? std::max(hours_from_start[i], 0.0) : 0.0;
      const std::optional<double> clock = i < frames.size() ? frames[i].clouds.local_clock_s : std::nullopt;
      const double t_h = FormationTimeSeconds(f, clock, h * 3600.0) / 3600.0;
      const double step = f.warmup_steps + f.steps_per_hour * t_h;
      steps = std::max(steps, uint64_t(std::floor(step)) + (step > std::floor(step) ? 1 : 0));
    }
    const double cells = double(f.cells[0]) * f.cells[1] * f.cells[2];
    why_on += fmt::format("{}{} x {} x {} cells at {} m, {} steps per hour", why_on.empty() ? "" : "; ", f.cells[0],
                          f.cells[1], f.cells[2], l.altitude_m, f.steps_per_hour);
    plan.passes.push_back({fmt::format("cloud formation (CPU) at {} m", l.altitude_m),
                           fmt::format("{} x {} x {}", f.cells[0], f.cells[1], f.cells[2]),
                           fmt::format("{} warm-up + {} per hour", f.warmup_steps, f.steps_per_hour), int(steps),
                           cells});
  }
  plan.effects.push_back({"cloud formation", requested, !why_on.empty(),
                          !why_on.empty() ? "[cloud_layer.formation] enabled: " + why_on
                          : requested     ? "every layer with a formation is pruned (coverage 0 or density_per_m 0)"
                                          : "switched off in the style"});
}

}  // namespace skybake
