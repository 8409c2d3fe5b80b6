// A bake, stage by stage: Vulkan device, pipelines, LUTs, render, EXR files,
// preview. The library reports each stage through a callback and never
// prints; the CLI decides how to show progress.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "skybake/config.h"
#include "skybake/exr_io.h"
#include "skybake/schedule.h"
#include "skybake/shard.h"
#include "skybake/sh.h"
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
  kExitOutput = 5,    // an output file could not be written (disk full, no permission)
  kExitExists = 6,    // the bake's files already exist: pass --force or --resume
  kExitBudget = 7,    // the bake would exceed the memory or time budget (README "Limits")
  kExitMerge = 8,     // merge-manifest: shard manifests missing frames, overlapping, of different bakes
};

// The bake's files are already in the output folder and neither --force nor
// --resume was given. Thrown before any GPU work.
class OutputExistsError : public OutputError {
 public:
  using OutputError::OutputError;
};

// The bake would need more memory or time than the budget. Thrown before any
// GPU work; the message gives the estimate.
class BudgetError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
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
  bool force = false;   // overwrite files of a previous bake in out_dir
  bool resume = false;  // sequence: keep frames verified against its manifest in out_dir, bake the rest
  // Sequence: bake only these frames (a part, for a farm): their files,
  // manifest.shard-FIRST-LAST.json and timings.shard-FIRST-LAST.json, no
  // scene. Exposure, half scale and the scene's texture frame still come
  // from every frame, so a part's files equal the same frames of a whole bake.
  std::optional<FrameRange> frames;
  double max_memory_mib = 4096.0;       // budget for one frame's host + device memory (README "Limits")
  double max_frame_seconds = 3600.0;    // budget for one frame's estimated lavapipe render time
};

// Estimated peak memory and lavapipe time of one frame of `style`.
struct ResourceEstimate {
  double memory_mib = 0.0;      // device output buffer, host copies, LUTs, encoded files
  double samples = 0.0;         // ray-march samples (texels x steps, LUTs included)
  double seconds = 0.0;         // samples / kLavapipeSamplesPerSecond
};
ResourceEstimate EstimateResources(const SkyStyle& style);

// Throws BudgetError when `style` is over the budget of `options`, naming the
// estimate, the budget and the keys to lower.
void CheckBudget(const SkyStyle& style, const BakeOptions& options);

struct BakedFile {
  std::string path;
  std::string kind;  // "face", "cube", "latlong", "preview", "gltf", "gltf_bin", "glb", "manifest"
  uint64_t bytes = 0;
  std::string sha256;  // hex; empty for the manifest itself
};

// What one frame of a bake produced.
struct FrameResult {
  int number = 1;                    // in file names; 0 for a single bake (no number)
  std::optional<CivilTime> time;
  glm::dvec3 sun_direction{0, 1, 0};
  double sun_elevation_deg = 0.0;
  double sun_azimuth_deg = 0.0;
  std::vector<BakedFile> files;
  ShRgb sh_irradiance_with_sun{};     // E_lm, sun disc included as its transmitted irradiance
  ShRgb sh_irradiance_without_sun{};  // E_lm of the sky alone
  Rgb sun_irradiance{0, 0, 0};        // transmitted sun at the observer, output units x sr
  double sun_illuminance_lux = 0.0;
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
  double half_scale = 1.0;   // power-of-two factor applied to fit half range
  double preview_ev100 = 0.0;
  int validation_messages = 0;
  std::string manifest_path;
  int renderer_builds = 0;  // SkyRenderer constructions (new shader variants or LUT sizes)
  int atmosphere_updates = 0;  // atmosphere changes served by the same pipelines (new uniforms and LUTs)
  int manifest_writes = 0;     // progress manifests written during the bake (the final one apart)
  uint64_t manifest_bytes_written = 0;  // their bytes: linear in the frames, not quadratic
  std::vector<std::string> removed_temporaries;  // left by a killed bake, removed before baking
};

// Bakes one style (one sun position) into options.out_dir, which is created
// if needed: EXR maps, preview, glTF scene, manifest.json, timings.json.
// Before any GPU work: BudgetError over the budget, OutputExistsError when a
// file it would write exists (unless options.force or options.resume); stale temporaries of
// its file names are removed. Later: VulkanUnavailable, VulkanError or
// OutputError. manifest.json is rewritten after every frame.
BakeResult BakeStyle(const SkyStyle& style, const BakeOptions& options);

// Bakes a sequence: frame k of `schedule` with `styles[k]` (see
// ResolveFrameStyles), files numbered name.####.ext. One Vulkan context
// throughout; the renderer and its LUTs are rebuilt only when a frame
// changes the atmosphere, quality, effects or units. One exposure and one
// half-float scale for the whole sequence. Writes one glTF scene with the
// sun animated across the frames, manifest.json and timings.json; with
// options.frames, only those frames and their part's manifest (manifest.h).
BakeResult BakeSequence(const std::vector<SkyStyle>& styles, const Schedule& schedule,
                        const BakeOptions& options);

// SHA-256 of a file, lowercase hex. Throws OutputError.
// A frame's images and encoded files (up to 34 MB each) are allocated and
// freed every frame. glibc serves blocks above its mmap threshold (at most
// 32 MB) from fresh mappings and trims freed heap back to the system, so
// every frame paid for page faults and zeroed pages again; keeping them in
// the heap made W2 7% faster for 5% more peak memory (docs/performance.md).
// The CLI calls this first; so do the benchmarks that time frames.
void KeepFrameMemoryInHeap();

std::string Sha256OfFile(const std::string& path);
std::string Sha256OfText(std::string_view text);

// The views one bake renders, in order: six Vulkan faces, the cube strip,
// the latlong (each only when enabled in `output`).
std::vector<ViewRequest> PlanViews(const SkyStyle& style);

}  // namespace skybake
