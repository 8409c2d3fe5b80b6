// The bake, stage by stage (pipeline.h). BakeFrames is the pipeline; each
// stage is a named function or class in a file of its own:
//   render_plan.cc      the plan, made once: frames, views, file names
//   bake_outputs.cc     the outputs before any GPU work, resume.cc its --resume
//   exposure.cc         the sequence's exposure and half-float scale
//   frame_lighting.cc   a frame's SH, Sun and IBL maps
//   frame_writer.cc     the writer thread one frame behind, and the frames' record
//   manifest_builder.cc the manifest as frames are done
#include "skybake/pipeline/pipeline.h"

#include "skybake/base/file_door.h"

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <malloc.h>
#include <memory>
#include <optional>
#include <thread>

#include <fmt/format.h>

#include "bake_outputs.h"
#include "exposure.h"
#include "frame_lighting.h"
#include "frame_writer.h"
#include "manifest_builder.h"
#include "renderer_cache.h"
#include "resume.h"
#include "skybake/pipeline/engine_files.h"
#include "skybake/pipeline/night_sky.h"
#include "skybake/pipeline/pass_plan.h"
#include "skybake/pipeline/render_plan.h"
#include "stage_timer.h"
#include "twilight_skip.h"

namespace skybake {
namespace {

// Each render's output is one storage buffer: refuse views the device cannot bind.
void CheckDeviceLimits(const RenderPlan& plan, VulkanContext& context) {
  const uint64_t max_range = context.properties().limits.maxStorageBufferRange;
  for (const FramePlan& frame : plan.frames) {
    for (const ViewRequest& v : frame.views) {
      uint64_t bytes = uint64_t(v.width) * uint64_t(v.height) * 16;
      if (bytes > max_range)
        throw VulkanError(fmt::format("a {}x{} view needs {} MiB in one storage buffer; {} allows {} MiB "
                                      "(maxStorageBufferRange): lower render.cube_size or render.latlong_height",
                                      v.width, v.height, bytes >> 20, context.device_info().name, max_range >> 20),
                          VK_ERROR_OUT_OF_DEVICE_MEMORY);
    }
  }
}

// Pipelines and LUTs: built for the first frame, rebuilt only on atmosphere changes.
// The persistent pipeline cache's part in the pipelines stage (gpu/pipeline_cache.h).
std::string PipelineCacheReport(const PipelineCacheStatus& s) {
  if (!s.enabled) return "pipeline cache off";
  std::string report = s.loaded                    ? fmt::format("pipeline cache hit ({} bytes)", s.loaded_bytes)
                       : s.ignored_because.empty() ? "pipeline cache empty"
                                                   : "pipeline cache ignored: " + s.ignored_because;
  if (s.saved) report += fmt::format(", saved ({} bytes)", s.saved_bytes);
  if (!s.save_error.empty()) report += ", not saved: " + s.save_error;
  return report;
}

void PreparePipelines(const SkyStyle& first, RendererCache& renderers, VulkanContext& context, StageTimer& timer,
                      BakeResult& result) {
  {
    const RenderCounters& c = renderers.Main(first).counters();
    // Saved now, so that a bake that fails later still leaves it; pipelines
    // made later (a twilight frame's, the IBL's) are saved at the end.
    context.SavePipelineCache();
    timer.Finish("pipelines", fmt::format("{} compute pipelines, {} from built-in shader variants; {}", c.pipelines,
                                          c.variant_pipelines, PipelineCacheReport(context.pipeline_cache_status())));
  }
  renderers.Main(first).PrecomputeLuts();
  for (const PassTiming& t : renderers.Main(first).last_timings()) result.gpu_passes.push_back(t);
  timer.Finish("LUTs", fmt::format("transmittance {}x{}, multiple scattering {}x{}", first.quality.transmittance_width,
                                   first.quality.transmittance_height, first.quality.multiscattering_size,
                                   first.quality.multiscattering_size));
}

// What every frame's stages share: the plan, the device and its renderers,
// the night sky, what --resume found, the exposure, the stage reports.
struct FrameStages {
  const RenderPlan& plan;
  const BakeOptions& options;
  VulkanContext& context;
  RendererCache& renderers;
  std::unique_ptr<IblBaker>& ibl_baker;  // made by the first frame that asks for IBL maps
  NightSkyBake* night;                   // null without a night sky
  NightSkyRenderer* night_renderer;
  const PreviousBake& previous;
  const BakeExposure& exposure;
  const TwilightSkip& twilight_skip;  // frames whose views render without the twilight march
  StageTimer& timer;
};

FrameResult FrameResultOf(const FramePlan& plan) {
  FrameResult frame;
  frame.number = plan.number;
  frame.time = plan.time;
  frame.sun_direction = plan.sun;
  frame.sun_elevation_deg = plan.elevation_deg;
  frame.sun_azimuth_deg = plan.azimuth_deg;
  return frame;
}

std::string RenderDetail(const FramePlan& plan, bool verified) {
  size_t texels = 0;
  for (const ViewRequest& v : plan.views) texels += size_t(v.width) * v.height;
  if (verified) texels = 0;
  return fmt::format("{} views, {:.2f} Mtexels, sun elevation {:.2f} azimuth {:.2f}{}{}",
                     verified ? 0 : plan.views.size(), texels * 1e-6, plan.elevation_deg, plan.azimuth_deg,
                     plan.time ? ", " + plan.time->Iso8601() : "",
                     verified ? ", files verified by checksum: not rendered again" : "");
}

// One frame: its views in one submission, its lighting, its IBL maps and
// engine images; then its files on the writer thread, or, resumed, its
// verified files as they are. Returns whether it rendered the frame.
bool BakeFrame(const FramePlan& plan, FrameStages& s, FrameWriter& writer) {
  const SkyStyle& style = *plan.style;
  FrameResult frame = FrameResultOf(plan);
  // A resumed sequence skips frames whose files are verified against the manifest.
  std::optional<std::vector<BakedFile>> verified;
  if (s.plan.sequence && s.options.resume)
    verified =
        VerifiedFrame(s.previous, plan, s.options.out_dir, s.exposure.half_scale, s.exposure.ev100.value_or(0.0));

  // Render: every view of the frame in one submission, then the SH views.
  // In place: the writer thread reads the texels where the device wrote
  // them while the next frame renders into other memory.
  Clock::time_point render_start = Clock::now();
  SkyRenderer& renderer = s.renderers.Main(style, plan.CloudTimeSeconds(), plan.sun);
  RenderedViews rendered;
  if (!verified) {
    // The views alone without the march when it cannot show (twilight_skip.h).
    renderer.set_twilight_march(!s.twilight_skip.frames.count(plan.number));
    rendered = renderer.RenderInPlace(plan.sun, plan.views, style.output.sun == SunOutput::kMap);
    renderer.set_twilight_march(true);
    for (const PassTiming& t : renderer.last_timings()) frame.gpu_passes.push_back(t);
  }
  std::optional<FrameNight> night;
  if (s.night)
    if (std::optional<NightFrame> n = s.night->Frame(style, plan.time, plan.sun))
      night = FrameNight{s.night, s.night_renderer, std::move(*n)};
  ComputeFrameLighting(renderer, plan, night, frame);
  frame.render_seconds = SecondsSince(render_start);
  s.timer.Finish(plan.Label(), RenderDetail(plan, verified.has_value()));

  // Passes beside the views: the IBL maps, the engine preset's images.
  std::optional<IblMaps> ibl;
  if (style.ibl.Requested() && !verified)
    ibl = RenderFrameIbl(renderer, s.ibl_baker, s.context, plan, night, frame, s.timer);
  std::vector<RgbaImage> engine;
  if (!plan.names.engine.empty() && !verified) {
    engine = RenderEngineImages(renderer, plan.sun, style);
    s.timer.Finish("engine", fmt::format("{}: {} images for {}", plan.Label(), engine.size(), style.output.engine));
  }
  // The cloud shadow map (cloud_shadow.h): its placement follows from the
  // style, the sun and the time alone (recorded for verified frames too).
  std::vector<float> cloud_shadow;
  if (style.cloud_shadow.enabled) {
    frame.cloud_shadow =
        CloudShadowInfoOf(PrunedStyle(style).clouds, style.cloud_shadow, plan.sun, plan.CloudTimeSeconds());
    if (!verified) {
      cloud_shadow = renderer.RenderCloudShadow(plan.sun, style.cloud_shadow);
      for (const PassTiming& t : renderer.last_timings()) frame.gpu_passes.push_back(t);
    }
  }
  if (verified) {
    writer.RecordVerified(std::move(frame), std::move(*verified));
    return false;
  }

  // Files: encoded, written and checksummed on the writer thread while the
  // device renders the next frame.
  FrameJob job{&plan,
               {},
               std::move(rendered.hold),
               std::move(ibl),
               std::move(engine),
               std::move(cloud_shadow),
               frame.cloud_shadow};
  for (size_t i = 0; i < plan.views.size(); ++i)
    job.images.push_back({plan.views[i].width, plan.views[i].height, {}, rendered.views[i]});
  if (night) {
    s.night->AddToViews(*s.night_renderer, style, night->frame, plan.views, job.images);
    s.timer.Report("night sky", s.night->TakeSeconds(), plan.Label() + ": " + NightSkyBake::Describe(night->frame));
  }
  writer.Write(std::move(frame), std::move(job));
  return true;
}

// A fault injected at a frame boundary (BakeOptions::stop_after_frame): the
// frame's files are written and the manifest lists them, then the process
// stops itself, as a frozen node would, for a farm test to kill or requeue
// it at a known frame instead of racing a poll.
void StopHere() {
  std::fflush(nullptr);
  std::raise(SIGSTOP);
}
void StopAtFrameBoundary(FrameWriter& writer, ManifestBuilder& manifest) {
  writer.Collect();
  manifest.Write(false);
  StopHere();
}

// Scene and manifest: a whole bake ends as merge-manifest does, through
// WriteSceneAndManifest, so both give the same bytes; a part writes only
// its own manifest (merge-manifest writes the scene once all parts are in).
// Then timings.json: what differs from run to run, beside the manifest.
void FinishBake(const RenderPlan& plan, const BakeOptions& options, ManifestBuilder& manifest, StageTimer& timer,
                Clock::time_point bake_start, BakeResult& result) {
  if (plan.part) {
    manifest.Write(true);
  } else {
    std::vector<BakedFile> scene_files = manifest.WriteSceneAndManifest();
    for (const BakedFile& f : scene_files) result.files.push_back(f);
    if (!scene_files.empty())
      timer.Finish("glTF", fmt::format("{} ({} sun key{}), .glb", scene_files.front().path, manifest.frames(),
                                       manifest.frames() == 1 ? "" : "s"));
  }
  result.files.push_back({result.manifest_path, "manifest", WrittenFileSize(result.manifest_path), ""});
  timer.Finish("manifest", result.manifest_path);
  const std::string timings_path = OutputPath(options, TimingsFileName(plan.part));
  WriteTimings(result, options.out_dir, SecondsSince(bake_start), timings_path, timer.spools());
  result.files.push_back({timings_path, "timings", WrittenFileSize(timings_path), ""});
}

BakeResult BakeFrames(const RenderPlan& plan, const BakeOptions& options) {
  BakeResult result;
  StageTimer timer(result, options.progress);
  if (!options.keep_frame_records) timer.SpoolRecords(options.out_dir);
  const Clock::time_point bake_start = Clock::now();
  // OpenEXR compresses line blocks on its own pool, one thread per core.
  SetExrThreads(int(std::max(1u, std::thread::hardware_concurrency())));

  // Outputs, before any GPU work (a part's too: every sequence-wide value
  // below still comes from every frame of the plan); the night sky's
  // catalogues read and its input checked (night_sky.h).
  const OutputLock lock = ClaimOutputs(plan, options);
  if (options.stop_after_frame == 0) StopHere();  // fault injection: the lock held, no frame yet
  std::unique_ptr<NightSkyBake> night = NightSkyBake::For(plan.styles(), plan.schedule, options.star_catalogue);
  const PreviousBake previous = PrepareOutputs(plan, options, timer, result);

  // Device: headless Vulkan, best device or the one asked for; one for the whole bake.
  VulkanContext context(options.vulkan);
  std::optional<NightSkyRenderer> night_renderer;  // the moonlit sky's renderer, destroyed before the device
  if (night) night_renderer.emplace(context);
  timer.Finish(
      "device",
      fmt::format("{} ({}){}{}", context.device_info().name, context.device_info().type,
                  options.vulkan.software_driver_selection.empty() ? "" : ", software driver only (no GPU device node)",
                  options.vulkan.lavapipe_threads.empty() || !IsLavapipe(context.device_info())
                      ? ""
                      : fmt::format(", lavapipe threads {}", options.vulkan.lavapipe_threads)));
  CheckDeviceLimits(plan, context);

  RendererCache renderers(context, result, options.shaders);
  std::unique_ptr<IblBaker> ibl_baker;
  PreparePipelines(plan.first(), renderers, context, timer, result);

  // Exposure and half-float scale: the sequence's, before any file is written.
  BakeExposure exposure = ChooseSequenceExposure(plan, renderers, timer);
  result.half_scale = exposure.half_scale;
  // Twilight frames that would round to 0 at that scale, marched or not: not marched (twilight_skip.h).
  const TwilightSkip twilight_skip = options.shaders.twilight_skip
                                         ? ChooseTwilightSkips(plan, renderers, exposure.half_scale, night != nullptr)
                                         : TwilightSkip();
  if (twilight_skip.probed > 0) timer.Finish("twilight probe", twilight_skip.report);
  std::filesystem::create_directories(options.out_dir);

  // Frames: rendered in order, each one's files written beside the next
  // one's render, the manifest rewritten as they are done.
  ManifestBuilder manifest(plan, options, exposure, result);
  FrameWriter writer(plan, options, timer, exposure, manifest, result);
  FrameStages stages{
      plan,     options,  context,       renderers, ibl_baker, night.get(), night_renderer ? &*night_renderer : nullptr,
      previous, exposure, twilight_skip, timer};
  const int frame_count =
      int(std::count_if(plan.frames.begin(), plan.frames.end(), [&](const FramePlan& f) { return plan.Bakes(f); }));
  int frame_index = 0;
  for (const FramePlan& frame : plan.frames) {
    if (!plan.Bakes(frame)) continue;  // another part's frame
    FrameProgress progress{FrameProgress::Event::kStart, ++frame_index, frame_count, frame.number, plan.sequence};
    if (options.frame_progress) options.frame_progress(progress);
    const bool rendered = BakeFrame(frame, stages, writer);
    if (frame_index == frame_count) writer.Collect();  // the last frame's files are waited for at once
    if (rendered && options.stop_after_frame == frame.number) StopAtFrameBoundary(writer, manifest);
    progress.event = FrameProgress::Event::kDone;
    if (options.frame_progress) options.frame_progress(progress);
  }
  writer.Collect();

  FinishBake(plan, options, manifest, timer, bake_start, result);
  result.counters = renderers.Current().counters();
  result.validation_messages = context.validation_message_count();
  return result;
}

}  // namespace

void KeepFrameMemoryInHeap() {
  mallopt(M_MMAP_THRESHOLD, 1 << 30);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
}

BakeResult BakeStyle(const SkyStyle& style, const BakeOptions& options) {
  if (options.frames) throw std::invalid_argument("BakeStyle: a frame selection needs a schedule (BakeSequence)");
  return BakeFrames(PlanSingleBake(style), options);
}

BakeResult BakeSequence(const std::vector<SkyStyle>& styles, const Schedule& schedule, const BakeOptions& options) {
  return BakeFrames(PlanSequenceBake(styles, schedule, options.frames), options);
}

}  // namespace skybake
