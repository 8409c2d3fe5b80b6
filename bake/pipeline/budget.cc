// The resource estimate of one frame and the budget check (pipeline.h).
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "skybake/model/clouds.h"
#include "skybake/model/spectrum.h"
#include "skybake/pipeline/engine_files.h"
#include "skybake/pipeline/pass_plan.h"
#include "skybake/pipeline/pipeline.h"
#include "skybake/pipeline/render_plan.h"

namespace skybake {

// Ray-march samples per second of lavapipe on the 2-core CI machine, measured
// on the default style's production bake (3.67 Mtexels x 48 steps in 14.5 s;
// README "Limits"). A slower or faster machine scales every estimate alike.
constexpr double kLavapipeSamplesPerSecond = 1.2e7;

namespace {

// The spectral mode in the budget's messages (empty without it).
std::string SpectralNote(const SkyStyle& style) {
  const int n = style.quality.wavelengths;
  return n > kRgbWavelengths ? fmt::format(", {} wavelengths in {} groups of 3", n, (n + 2) / 3) : "";
}
std::string SpectralAdvice(const SkyStyle& style) {
  return style.quality.wavelengths > kRgbWavelengths ? ", lower quality.wavelengths" : "";
}

// The cloud formations' lattices a process keeps (cloud_formation.h): per
// layer with a formation, the smoothing_steps + 2 steps a frame reads (three
// bytes a cell, SimulateFormationSteps) and their densities smoothed over
// space (four bytes a cell), MiB.
double FormationMiB(const SkyStyle& style) {
  double bytes = 0.0;
  for (const CloudLayer& l : ActiveCloudLayers(style.clouds)) {
    const CloudFormation& f = l.formation;
    if (f.enabled) bytes += (f.smoothing_steps + 2.0) * 7.0 * double(f.cells[0]) * f.cells[1] * f.cells[2];
  }
  return bytes / (1024.0 * 1024.0);
}

}  // namespace

ResourceEstimate EstimateResources(const SkyStyle& style) {
  const std::vector<ViewRequest> views = PlanViews(style);
  const double latlong = 2.0 * style.render.latlong_height * double(style.render.latlong_height);
  double texels = 0.0, largest = 0.0;
  for (const ViewRequest& v : views) {
    texels += double(v.width) * v.height;
    largest = std::max(largest, double(v.width) * v.height);
  }
  // The engine preset's images (engine_files.h): their directions (3
  // doubles) while they render, then their RGBA float pixels until written.
  // The renderer's output buffer (32 bytes a texel) grows when one of them
  // needs more than the views.
  double engine_texels = 0.0, largest_engine = 0.0;
  for (const EngineImageSize& i : PlanEngineImages(style)) {
    engine_texels += double(i.width) * i.height;
    largest_engine = std::max(largest_engine, double(i.width) * i.height);
  }
  const double engine_growth = 32.0 * std::max(0.0, largest_engine - texels);
  largest = std::max(largest, largest_engine);
  const QualitySettings& q = style.quality;
  // The spectral mode (spectral_sky.h): one renderer per group of three
  // bins, each with its LUTs and an output buffer of its own (RGBA float, 16
  // bytes a texel), their sum on the host in place of the one renderer's.
  // The style pass (the AOAS saturation clouds and shapes, the night floor
  // on the combined colour) has one more such buffer; with cloud layers, the
  // style's change of the colour is one more on the host.
  const double groups = q.wavelengths > kRgbWavelengths ? std::ceil(q.wavelengths / 3.0) : 1.0;
  const bool style_pass = style.aoas.clouds.enabled || style.aoas.shapes.enabled || style.effects.night_dimming;
  const double style_buffers = style_pass ? (ActiveCloudLayers(style.clouds).empty() ? 1.0 : 2.0) : 0.0;
  const double spectral_buffers = q.wavelengths > kRgbWavelengths ? 16.0 * (groups + style_buffers) * texels : 0.0;
  const double luts = groups * 16.0 *
                      (double(q.transmittance_width) * q.transmittance_height +
                       double(q.multiscattering_size) * q.multiscattering_size +
                       (q.sky_view_lut ? double(q.sky_view_width) * q.sky_view_height : 0.0));
  const double channel = style.output.pixel_type == PixelType::kHalf ? 2.0 : 4.0;
  ResourceEstimate e;
  // Device output buffer and its host copy (RGBA float each), the largest
  // image's RGB copy and encoded file, the preview's luminance, sRGB and PNG,
  // the engine images.
  const bool preview = WritesLatlongPng(style);
  const double bytes = 32.0 * texels + 2.0 * 3.0 * channel * largest + (preview ? 22.0 * latlong : 0.0) + luts +
                       (24.0 + 16.0) * engine_texels + engine_growth + spectral_buffers;
  e.memory_mib = bytes / (1024.0 * 1024.0) + FormationMiB(style);
  // Samples: the pass plan's count for one frame (each ray-marched texel
  // marches view_steps, times light_steps when the Sun's transmittance is
  // marched too; a sky-view texel is one LUT read; plus the LUTs), each
  // sky pass once per group of three bins in the spectral mode.
  e.samples = PlanPasses({style}).total_samples;
  e.seconds = e.samples / kLavapipeSamplesPerSecond;
  return e;
}

void CheckBudget(const SkyStyle& style, const BakeOptions& options) {
  const ResourceEstimate e = EstimateResources(style);
  // Whole MiB, unless the two would then read the same ("1 MiB above 1 MiB").
  auto pair = [](double need, double budget) {
    const bool close = fmt::format("{:.0f}", need) == fmt::format("{:.0f}", budget);
    return close ? std::pair{fmt::format("{:.3f}", need), fmt::format("{:.3f}", budget)}
                 : std::pair{fmt::format("{:.0f}", need), fmt::format("{:.0f}", budget)};
  };
  if (e.memory_mib > options.max_memory_mib) {
    const auto [need, budget] = pair(e.memory_mib, options.max_memory_mib);
    if (const double formation = FormationMiB(style); formation > 0.5 * options.max_memory_mib)
      throw BudgetError(fmt::format(
          "the bake needs an estimated {} MiB of memory per frame, {:.0f} MiB of it the cloud formations' "
          "lattices (formation.cells x (smoothing_steps + 2) steps, 7 bytes a cell), above the budget of {} MiB: "
          "lower [cloud_layer.formation] cells or smoothing_steps, or raise --max-memory-mib (README \"Limits\")",
          need, formation, budget));
    throw BudgetError(fmt::format(
        "the bake needs an estimated {} MiB of memory per frame (cube {}, latlong {}x{}{}), above the budget "
        "of {} MiB: lower render.cube_size or render.latlong_height{}, turn off outputs, or raise "
        "--max-memory-mib (README \"Limits\")",
        need, style.render.cube_size, 2 * style.render.latlong_height, style.render.latlong_height, SpectralNote(style),
        budget, SpectralAdvice(style)));
  }
  if (e.seconds > options.max_frame_seconds)
    throw BudgetError(fmt::format(
        "the bake needs an estimated {:.3g} ray-march samples per frame, about {:.0f} s of lavapipe time, above "
        "the budget of {:.0f} s per frame: lower quality.view_steps, quality.light_steps or the sizes{}, or raise "
        "--max-frame-seconds (README \"Limits\")",
        e.samples, e.seconds, options.max_frame_seconds, SpectralAdvice(style)));
}

// What a sequence keeps of a frame until it ends. A bake that keeps its
// frame records (BakeOptions::keep_frame_records, the library's default):
// each frame's record (its files' names, sizes and checksums, its Sun, SH
// and timings), measured before the manifest streamed as 104 KiB per frame
// for the default style at --size 1 with 9 files a frame over 1,000 frames
// with the progress manifests built whole in memory, which 64 KiB + 6 KiB
// per file bounds (an upper bound now). The CLI keeps no records (its
// manifest entries and timings stay on disk, json_spool.h): what is left is
// what the glTF scene needs of a frame and the scene's texts at the end:
// 3.1 KiB a frame while 10,000 frames bake, 26.1 KiB a frame to the end of
// the bake (tests/benchmark/long_sequence.py, docs/performance_history.md "Long
// sequences"), which kStreamedFrameBytes bounds.
constexpr double kFrameRecordBytes = 64.0 * 1024.0;
constexpr double kFileRecordBytes = 6.0 * 1024.0;
constexpr double kStreamedFrameBytes = 32.0 * 1024.0;

double SequenceRecordMiB(const RenderPlan& plan, const BakeOptions& options) {
  double bytes = 0.0;
  for (const FramePlan& f : plan.frames) {
    bytes += double(f.style->resolved_toml.size());  // every frame's style, for the whole sequence's values
    if (!plan.Bakes(f)) continue;
    bytes += options.keep_frame_records ? kFrameRecordBytes + kFileRecordBytes * double(f.names.All().size())
                                        : kStreamedFrameBytes;
  }
  return bytes / (1024.0 * 1024.0);
}

void CheckSequenceBudget(const RenderPlan& plan, const BakeOptions& options) {
  if (!plan.sequence) return;
  double frame_mib = 0.0;
  int baked = 0;
  for (const FramePlan& f : plan.frames) {
    frame_mib = std::max(frame_mib, EstimateResources(*f.style).memory_mib);
    baked += plan.Bakes(f) ? 1 : 0;
  }
  const double records_mib = SequenceRecordMiB(plan, options);
  if (frame_mib + records_mib <= options.max_memory_mib) return;
  throw BudgetError(fmt::format(
      "the sequence needs an estimated {:.0f} MiB of memory: {:.0f} MiB for its largest frame and {:.0f} MiB for "
      "what it keeps of its {} frames ({}), above the budget of {:.0f} MiB: bake "
      "it in parts (--frames A:B or --shard I/N, then merge-manifest), or raise --max-memory-mib (README "
      "\"Limits\")",
      frame_mib + records_mib, frame_mib, records_mib, baked,
      options.keep_frame_records ? "their records and manifest entries" : "their styles and the scene's per-frame data",
      options.max_memory_mib));
}

}  // namespace skybake
