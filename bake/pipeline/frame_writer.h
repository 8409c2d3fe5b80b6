// The bake's writer (private to the pipeline layer): a thread one frame
// behind the renders, which encodes, writes (atomically) and checksums a
// frame's files while the device renders the next; and the record of the
// frames done, which updates the manifest as they are.
#pragma once

#include <future>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "exposure.h"
#include "manifest_builder.h"
#include "skybake/gpu/ibl.h"
#include "skybake/output/bake_record.h"
#include "skybake/output/exr_io.h"
#include "skybake/pipeline/pipeline.h"
#include "skybake/pipeline/render_plan.h"
#include "stage_timer.h"

namespace skybake {

// What the writer thread needs of a rendered frame.
struct FrameJob {
  const FramePlan* plan = nullptr;
  std::vector<RgbaImage> images;     // the frame's views, in plan->views order
  std::shared_ptr<const void> hold;  // the renderer's memory the images view (RenderInPlace)
  std::optional<IblMaps> ibl;        // the frame's IBL maps, when asked for
  std::vector<RgbaImage> engine;     // the engine preset's images (engine_preset.h)
  std::vector<float> cloud_shadow;   // the frame's cloud shadow map (cloud_shadow.h), when asked for
  std::optional<CloudShadowInfo> cloud_shadow_info;
  // Filled in by FrameWriter::Write: a sequence's exposure and half scale
  // (a single bake's frame finds its own from its images and latlong).
  double half_scale = 1.0;
  std::optional<double> ev100;
};

// What it gives back.
struct WrittenFrame {
  std::vector<BakedFile> files;
  double half_scale = 1.0;
  std::optional<double> ev100;
  std::string exposure_source;
  double exr_seconds = 0.0, preview_seconds = 0.0, write_seconds = 0.0;
  std::string exr_detail;
};

// One frame's files, from its rendered views: one scale for every file (of
// the frame, or of the sequence). Runs on the writer thread; reads only the
// job and constants of the bake.
WrittenFrame WriteFrameFiles(FrameJob& job, const RenderPlan& plan, const BakeOptions& options);

class FrameWriter {
 public:
  FrameWriter(const RenderPlan& plan, const BakeOptions& options, StageTimer& timer, BakeExposure& exposure,
              ManifestBuilder& manifest, BakeResult& result)
      : plan_(plan), options_(options), timer_(timer), exposure_(exposure), manifest_(manifest), result_(result) {}

  // Waits for the frame in flight, then writes `job` beside the next
  // frame's render (the last frame's files are waited for with Collect).
  void Write(FrameResult frame, FrameJob job);
  // A frame whose files are verified against the previous manifest: recorded
  // as it is, after the frame in flight.
  void RecordVerified(FrameResult frame, std::vector<BakedFile> files);
  // Waits for the frame in flight and records it: progress, exposure, the
  // manifest.
  void Collect();

 private:
  void Record(FrameResult frame);

  const RenderPlan& plan_;
  const BakeOptions& options_;
  StageTimer& timer_;
  BakeExposure& exposure_;
  ManifestBuilder& manifest_;
  BakeResult& result_;
  // The frame whose files are being written, and its record.
  std::optional<std::pair<FrameResult, std::future<WrittenFrame>>> pending_;
};

}  // namespace skybake
