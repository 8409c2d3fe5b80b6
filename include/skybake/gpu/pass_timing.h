// What the GPU passes cost and how often they ran: the names and GPU times of
// the passes of a render, and the renderer's counters. Plain data, no
// Vulkan, so that the manifest and timings.json can carry them.
#pragma once

#include <string>

namespace skybake {

struct PassTiming {
  std::string name;
  double gpu_ms = 0.0;  // from timestamps; 0 when the device has none
};

// What the renderer has done, for tests and progress reports.
struct RenderCounters {
  int transmittance_lut_builds = 0;
  int multiscattering_lut_builds = 0;
  int skyview_lut_builds = 0;
  int frames = 0;
  int pipelines = 0;              // compute pipelines compiled
  int variant_pipelines = 0;      // of which from the fixed-quality variants (SKYBAKE_GENERIC_SHADERS=1: none)
  int sun_disc_dispatches = 0;    // dispatches of the sun-disc pass
  int cloud_noise_builds = 0;     // noise volumes generated (once per renderer unless seeds change)
  int cloud_table_builds = 0;     // aerial-perspective LUT and ambient table (once per sun position)
  int cloud_dispatches = 0;       // dispatches of the cloud pass
  int shadowed_cloud_frames = 0;  // frames whose cloud march ran without the Sun's light (every band in the shadow)
  long long sun_disc_texels = 0;  // texels they covered
  long long twilight_texels = 0;  // texels of the views' sky pass rendered by the twilight pipeline
  long long sky_texels = 0;       // texels of the views' sky pass, with either pipeline
};

}  // namespace skybake
