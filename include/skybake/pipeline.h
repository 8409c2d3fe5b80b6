// A bake, stage by stage: Vulkan device, pipelines, LUTs, render, EXR files,
// preview. The library reports each stage through a callback and never
// prints; the CLI decides how to show progress.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "skybake/config.h"
#include "skybake/sky_renderer.h"
#include "skybake/vulkan_context.h"

namespace skybake {

// Process exit codes, one per failure kind (README "Exit codes").
enum ExitCode : int {
  kExitOk = 0,
  kExitInternal = 1,  // a bug: please report it
  kExitUsage = 2,     // bad command line
  kExitConfig = 3,    // the style or schedule is invalid
  kExitVulkan = 4,    // no usable Vulkan driver or device, or a Vulkan failure
  kExitOutput = 5,    // an output file could not be written
};

struct StageReport {
  std::string name;
  double seconds = 0.0;
  std::string detail;
};
using ProgressCallback = std::function<void(const StageReport&)>;

struct BakeOptions {
  std::string out_dir = "out";
  VulkanOptions vulkan;
  ProgressCallback progress;  // may be empty
};

struct BakedFile {
  std::string path;
  std::string kind;  // "face", "cube", "latlong", "preview"
  uint64_t bytes = 0;
};

struct BakeResult {
  std::vector<BakedFile> files;
  std::vector<StageReport> stages;
  std::vector<PassTiming> gpu_passes;  // LUT and render passes, GPU timestamps
  RenderCounters counters;
  double half_scale = 1.0;   // power-of-two factor applied to fit half range
  double preview_ev100 = 0.0;
  int validation_messages = 0;
};

// Bakes one style (one sun position) into options.out_dir, which is created
// if needed. Throws VulkanUnavailable, VulkanError or OutputError.
BakeResult BakeStyle(const SkyStyle& style, const BakeOptions& options);

// The views one bake renders, in order: six Vulkan faces, the cube strip,
// the latlong (each only when enabled in `output`).
std::vector<ViewRequest> PlanViews(const SkyStyle& style);

}  // namespace skybake
