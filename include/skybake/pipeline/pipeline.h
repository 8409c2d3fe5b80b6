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

#include "skybake/base/errors.h"
#include "skybake/gpu/sky_renderer.h"
#include "skybake/gpu/vulkan_context.h"
#include "skybake/input/astronomy.h"
#include "skybake/input/config.h"
#include "skybake/input/schedule.h"
#include "skybake/input/shard.h"
#include "skybake/model/sh.h"
#include "skybake/output/bake_record.h"
#include "skybake/output/exr_io.h"
#include "skybake/output/sha256.h"

namespace skybake {

using ProgressCallback = std::function<void(const StageReport&)>;

// A frame of a bake starting, or done: rendered, and its files written (the
// last frame's) or handed to the writer thread, which writes them while the
// next frame renders. Frames are reported in order, index 1 to count.
struct FrameProgress {
  enum class Event { kStart, kDone };
  Event event = Event::kStart;
  int index = 0;          // 1-based among the frames this run bakes (a part's, with --frames or --shard)
  int count = 0;          // the frames this run bakes
  int number = 0;         // the frame's number in file names (sequences)
  bool sequence = false;  // false: a single bake, one frame
};
using FrameProgressCallback = std::function<void(const FrameProgress&)>;

struct BakeOptions {
  std::string out_dir = "out";
  VulkanOptions vulkan;
  ShaderSwitches shaders;  // the CLI's diagnostic switches (from the environment, read in main)
  // The star catalogue of a style whose night.star_catalogue is "" (main:
  // $SKYBAKE_STAR_CATALOGUE when set).
  std::string star_catalogue = DefaultStarCataloguePath();
  ProgressCallback progress;             // may be empty
  FrameProgressCallback frame_progress;  // may be empty
  // The git commit of the running binary ("unknown" outside git; main:
  // `skybake --version`'s), recorded in the manifest beside the version.
  std::string build_commit = "unknown";
  bool force = false;   // overwrite files of a previous bake in out_dir
  bool resume = false;  // sequence: keep frames verified against its manifest in out_dir, bake the rest
  // Sequence: bake only these frames (a part, for a farm): their files,
  // manifest.shard-FIRST-LAST.json and timings.shard-FIRST-LAST.json, no
  // scene. Exposure, half scale and the scene's texture frame still come
  // from every frame, so a part's files equal the same frames of a whole bake.
  std::optional<FrameRange> frames;
  double max_memory_mib = 4096.0;     // budget for one frame's host + device memory (README "Limits")
  double max_frame_seconds = 3600.0;  // budget for one frame's estimated lavapipe render time
  // What BakeResult keeps of each frame. On (the library's default): frames,
  // each frame's files in files, every stage in stages. Off (the CLI): a
  // sequence's memory stays flat however long it is: each frame's files go
  // to frame_files as they are recorded, its timings and the stages to
  // timings.json's record on disk; BakeResult keeps the scene's, manifest's
  // and timings' files alone.
  bool keep_frame_records = true;
  // Fault injection for farm tests (main: $SKYBAKE_STOP_AFTER_FRAME): once
  // this frame number is rendered, its files written and the manifest
  // rewritten to list it, the process stops itself (SIGSTOP); 0: once the
  // bake holds its outputs' lock, before its device and first frame.
  std::optional<int> stop_after_frame;
  std::function<void(const std::vector<BakedFile>&)> frame_files;  // may be empty
};

// Estimated peak memory and lavapipe time of one frame of `style`.
struct ResourceEstimate {
  double memory_mib = 0.0;  // device output buffer, host copies, LUTs, encoded files
  double samples = 0.0;     // ray-march samples (texels x steps, LUTs included)
  double seconds = 0.0;     // samples / kLavapipeSamplesPerSecond
};
ResourceEstimate EstimateResources(const SkyStyle& style);

// Throws BudgetError when `style` is over the budget of `options`, naming the
// estimate, the budget and the keys to lower.
void CheckBudget(const SkyStyle& style, const BakeOptions& options);

// What a bake keeps of each of its frames until the end (budget.cc), in MiB:
// the styles of every frame of `plan`, and what it keeps of each frame it
// bakes (its record, with options.keep_frame_records; else what the glTF
// scene needs). Throws BudgetError when the largest frame's estimate plus
// this is over options.max_memory_mib.
struct RenderPlan;
double SequenceRecordMiB(const RenderPlan& plan, const BakeOptions& options);
void CheckSequenceBudget(const RenderPlan& plan, const BakeOptions& options);

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
BakeResult BakeSequence(const std::vector<SkyStyle>& styles, const Schedule& schedule, const BakeOptions& options);

// A frame's images and encoded files (up to 34 MB each) are allocated and
// freed every frame. glibc serves blocks above its mmap threshold (at most
// 32 MB) from fresh mappings and trims freed heap back to the system, so
// every frame paid for page faults and zeroed pages again; keeping them in
// the heap made W2 7% faster for 5% more peak memory (docs/performance.md).
// The CLI calls this first; so do the benchmarks that time frames.
void KeepFrameMemoryInHeap();

}  // namespace skybake
