#include "frame_lighting.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "skybake/model/aoas.h"
#include "skybake/model/colour_conversion.h"
#include "skybake/model/sh.h"
#include "skybake/output/gltf_ibl.h"

namespace skybake {
namespace {

double Luminance(const Rgb& rgb) { return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]; }

// The views one frame renders for its SH: six small faces.
std::vector<ViewRequest> ShViews(const SkyStyle& style) {
  const int n = std::min(style.render.cube_size, 64);
  std::vector<ViewRequest> views;
  for (int face = 0; face < 6; ++face) views.push_back({MAPPING_VULKAN_FACE, n, n, face});
  return views;
}

// The Sun's irradiance from the disc's centre radiance, and its illuminance.
// A style whose disc is not drawn (effects.sun_disc = false, or strength 0)
// keeps the Sun's light, from the host's 48 bins (SunLightAtObserver); so do
// the spectral units' lux.
void RecordSun(const SkyStyle& style, const glm::dvec3& sun, const std::vector<float>& with_disc,
               const std::vector<float>& without_disc, FrameResult& frame) {
  const double alpha = style.atmosphere.sun_angular_radius_rad;
  const double disc_solid_angle = M_PI * alpha * alpha * (1.0 - style.atmosphere.limb_darkening_u / 3.0);
  for (int c = 0; c < 3; ++c)
    frame.sun_irradiance[c] = std::max(0.0, double(with_disc[c]) - double(without_disc[c])) * disc_solid_angle;
  const bool disc = style.effects.sun_disc && style.effects.sun_disc_strength > 0.0;
  if (disc && style.output.units == OutputUnits::kLuminance) {
    frame.sun_illuminance_lux = Luminance(frame.sun_irradiance);
    return;
  }
  const SunLight light = SunLightAtObserver(StyledAtmosphere(style.atmosphere, style.aoas), style.effects, sun);
  if (!disc) frame.sun_irradiance = style.output.units == OutputUnits::kLuminance ? light.luminance : light.radiance;
  frame.sun_illuminance_lux = Luminance(light.luminance);
}

}  // namespace

void ComputeFrameLighting(SkyRenderer& renderer, const FramePlan& plan, const std::optional<FrameNight>& night,
                          FrameResult& frame) {
  const SkyStyle& style = *plan.style;
  const std::vector<float> with_disc = renderer.RenderDirections(plan.sun, {plan.sun});
  const std::vector<float> without_disc = renderer.RenderDirections(plan.sun, {plan.sun}, false);
  std::vector<ViewRequest> sh_views = ShViews(style);
  std::vector<std::vector<float>> sh_faces = renderer.Render(plan.sun, sh_views, false);
  for (const PassTiming& t : renderer.last_timings()) frame.gpu_passes.push_back(t);
  if (night) night->AddToFaces(style, sh_views, sh_faces);
  RecordSun(style, plan.sun, with_disc, without_disc, frame);
  ShRgb sky = ProjectCubeFaces({sh_faces[0].data(), sh_faces[1].data(), sh_faces[2].data(), sh_faces[3].data(),
                                sh_faces[4].data(), sh_faces[5].data()},
                               sh_views[0].width);
  frame.sh_irradiance_without_sun = RadianceToIrradiance(sky);
  AddDirectionalSource(sky, plan.sun, frame.sun_irradiance);
  if (night) night->bake->RecordMoon(style, night->frame, sky, frame.moon);
  frame.sh_irradiance_with_sun = RadianceToIrradiance(sky);
}

IblMaps RenderFrameIbl(SkyRenderer& renderer, std::unique_ptr<IblBaker>& baker, VulkanContext& context,
                       const FramePlan& plan, const std::optional<FrameNight>& night, FrameResult& frame,
                       StageTimer& timer) {
  const SkyStyle& style = *plan.style;
  if (!baker) baker = std::make_unique<IblBaker>(context);
  const int n = style.ibl.size;
  std::vector<ViewRequest> source_views;
  for (int face = 0; face < 6; ++face) source_views.push_back({MAPPING_VULKAN_FACE, n, n, face});
  std::vector<std::vector<float>> source_faces = renderer.Render(plan.sun, source_views, false);
  if (night) night->AddToFaces(style, source_views, source_faces);
  for (const PassTiming& t : renderer.last_timings()) frame.gpu_passes.push_back({"IBL source " + t.name, t.gpu_ms});
  CubeLevel source;
  source.size = n;
  for (int face = 0; face < 6; ++face) source.faces[face] = std::move(source_faces[face]);
  IblRequest request{style.ibl, plan.sun, frame.sun_irradiance, style.ibl.dfg && plan.names.with_dfg};
  if (night) NightSkyBake::AddMoonToIbl(style, night->frame, request);
  IblMaps maps = baker->Bake(request, source);
  maps.gltf_scale = GltfIblScale(frame.sh_irradiance_without_sun);
  for (const PassTiming& t : baker->last_timings()) frame.gpu_passes.push_back(t);
  timer.Finish("IBL",
               fmt::format("{}: {} x {} source without the sun disc, {} specular levels x {} samples, "
                           "irradiance {} x {} samples{}{}",
                           plan.Label(), n, n, style.ibl.specular ? IblLevelCount(style.ibl) : 0, style.ibl.samples,
                           style.ibl.irradiance ? style.ibl.irradiance_size : 0, style.ibl.irradiance_samples,
                           request.dfg ? ", DFG table" : "", style.ibl.include_sun ? ", sun included" : ""));
  return maps;
}

}  // namespace skybake
