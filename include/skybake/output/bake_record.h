// What a bake produced, as the manifest, timings.json and the CLI report it:
// its files with their checksums, each frame's sun and lighting, the stages'
// times and the GPU passes'. Plain data: no Vulkan, no style schema.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "skybake/input/astronomy.h"
#include "skybake/gpu/pass_timing.h"
#include "skybake/model/atmosphere.h"
#include "skybake/model/cloud_shadow.h"
#include "skybake/model/sh.h"
#include "skybake/model/solar_position.h"

namespace skybake {

struct StageReport {
  std::string name;
  double seconds = 0.0;
  std::string detail;
};

struct BakedFile {
  std::string path;
  std::string kind;  // "face", "cube", "latlong", "preview", "gltf", "gltf_bin", "glb", "usd", "manifest"
  uint64_t bytes = 0;
  std::string sha256;  // hex; empty for the manifest itself
};

// What one frame of a bake produced.
struct FrameResult {
  int number = 1;  // in file names; 0 for a single bake (no number)
  std::optional<CivilTime> time;
  glm::dvec3 sun_direction{0, 1, 0};
  double sun_elevation_deg = 0.0;
  double sun_azimuth_deg = 0.0;
  std::vector<BakedFile> files;
  ShRgb sh_irradiance_with_sun{};     // E_lm, sun disc included as its transmitted irradiance
  ShRgb sh_irradiance_without_sun{};  // E_lm of the sky alone
  Rgb sun_irradiance{0, 0, 0};        // transmitted sun at the observer, output units x sr
  double sun_illuminance_lux = 0.0;
  std::optional<MoonRecord> moon;  // with night.moon or night.moonlight (pipeline/night_sky.h)
  double render_seconds = 0.0;
  double write_seconds = 0.0;
  std::vector<PassTiming> gpu_passes;
  std::optional<CloudShadowInfo> cloud_shadow;  // placement of the frame's cloud shadow map, when written
};

struct BakeResult {
  std::vector<BakedFile> files;  // every file, frames then scene then manifest
  std::vector<FrameResult> frames;
  std::vector<StageReport> stages;
  std::vector<PassTiming> gpu_passes;  // LUT and render passes, GPU timestamps
  RenderCounters counters;
  double half_scale = 1.0;  // power-of-two factor applied to fit half range
  double preview_ev100 = 0.0;
  int validation_messages = 0;
  std::string manifest_path;
  int renderer_builds = 0;              // SkyRenderer constructions (new shader variants or LUT sizes)
  int atmosphere_updates = 0;           // atmosphere changes served by the same pipelines (new uniforms and LUTs)
  int manifest_writes = 0;              // progress manifests written during the bake (the final one apart)
  uint64_t manifest_bytes_written = 0;  // their bytes: linear in the frames, not quadratic
  std::vector<std::string> removed_temporaries;  // left by a killed bake, removed before baking
};

}  // namespace skybake
