// The bake's exposure and half-float scale (private to the pipeline layer):
// one for the whole sequence, decided before any file is written, never per
// frame; a single bake's frame decides its own from its images.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "renderer_cache.h"
#include "skybake/input/output_settings.h"
#include "skybake/pipeline/render_plan.h"
#include "stage_timer.h"

namespace skybake {

struct BakeExposure {
  std::optional<double> ev100;  // unset until chosen (a single bake: by its frame's writer)
  std::string source;           // what chose it, for the manifest
  double half_scale = 1.0;      // what every EXR value is multiplied by
};

// A sequence's exposure (the reference frame's auto exposure, or
// preview.ev100; none when nothing is exposed) and its half-float scale
// (bounded without rendering while the sun disc is up, else from coarse
// renders of every frame); reports the "exposure" stage. A single bake's is
// left to its frame: nothing chosen, no stage.
BakeExposure ChooseSequenceExposure(const RenderPlan& plan, RendererCache& renderers, StageTimer& timer);

// Converts spectral output to luminance for exposure; a copy.
std::vector<float> DisplayLuminance(const float* rgba, size_t texels, OutputUnits units);

}  // namespace skybake
