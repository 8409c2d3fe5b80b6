// What a frame lights a scene with, and its image-based light (private to
// the pipeline layer): the SH of the sky with and without the Sun, the
// Sun's irradiance and illuminance, the Moon's record, and the IBL maps
// filtered on the device.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "skybake/gpu/ibl.h"
#include "skybake/gpu/sky_renderer.h"
#include "skybake/output/bake_record.h"
#include "skybake/pipeline/night_sky.h"
#include "skybake/pipeline/render_plan.h"
#include "stage_timer.h"

namespace skybake {

// A frame's night sky (night_sky.h) with the bake's parts that add it.
struct FrameNight {
  NightSkyBake* bake = nullptr;
  NightSkyRenderer* renderer = nullptr;
  NightFrame frame;
  void AddToFaces(const SkyStyle& style, const std::vector<ViewRequest>& views,
                  std::vector<std::vector<float>>& faces) const {
    bake->AddToFaces(*renderer, style, frame, views, faces);
  }
};

// The frame's SH and Sun (into `frame`): the sky without the disc from
// small faces; the disc added as the irradiance it delivers (centre
// radiance times its limb-darkened solid angle), which point-sampled texels
// would alias; the Moon's light with the night sky.
void ComputeFrameLighting(SkyRenderer& renderer, const FramePlan& plan, const std::optional<FrameNight>& night,
                          FrameResult& frame);

// The frame's IBL maps: the sky without the disc at ibl.size, filtered on
// the device into the specular chain, the irradiance cube and (first frame)
// the DFG table; reports the "IBL" stage. `baker` is made by the first frame
// that asks for the maps.
IblMaps RenderFrameIbl(SkyRenderer& renderer, std::unique_ptr<IblBaker>& baker, VulkanContext& context,
                       const FramePlan& plan, const std::optional<FrameNight>& night, FrameResult& frame,
                       StageTimer& timer);

}  // namespace skybake
