// The bake's manifest as frames are done (private to the pipeline layer):
// every file with its size and SHA-256, per frame; rewritten atomically as
// frames are done, `complete` once the bake (or part) is. Its sequence-wide
// entries come from every frame of the plan, so the parts of a sequence
// agree on them and merge-manifest can check that they do.
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "exposure.h"
#include "skybake/output/bake_record.h"
#include "skybake/output/json_spool.h"
#include "skybake/output/manifest.h"
#include "skybake/pipeline/pipeline.h"
#include "skybake/pipeline/render_plan.h"
#include "stage_timer.h"

namespace skybake {

class ManifestBuilder {
 public:
  // Reads the exposure as it stands when a manifest is written (a single
  // bake's is chosen by its frame); sets result.manifest_path and counts
  // its writes there.
  ManifestBuilder(const RenderPlan& plan, const BakeOptions& options, const BakeExposure& exposure, BakeResult& result);

  // A frame done: its manifest entry goes to the record on disk (the
  // manifest is written around it, never built whole in memory), and what
  // the scene needs of it (its sun, SH, time and Moon; the texture frame's
  // files) is kept, only by a whole bake with a scene.
  void Add(const FrameResult& frame);
  size_t frames() const { return spool_.size(); }
  // The manifest without its frames: the sequence-wide values.
  Manifest Head() const;
  // Writes the manifest of the frames done, into result.manifest_path.
  void Write(bool complete);
  // After a frame: writes it when enough has changed since the last write
  // (a killed bake leaves a valid record of the frames done).
  void WriteProgress();
  // A whole bake's end, as merge-manifest ends (WriteSceneAndManifest):
  // the scene, then the manifest, complete. Returns the scene's files.
  std::vector<BakedFile> WriteSceneAndManifest();

 private:
  const RenderPlan& plan_;
  const BakeOptions& options_;
  const BakeExposure& exposure_;
  BakeResult& result_;
  std::vector<std::string> style_sha256_;  // per frame of the plan
  std::string sequence_sha256_;            // of every frame's number, time, sun and style
  std::map<int, size_t> frame_index_;      // frame number -> index in the plan
  JsonArraySpool spool_;                   // the entries of the frames done
  bool keeps_scene_frames_ = false;
  std::vector<ManifestFrame> scene_frames_;
  Clock::time_point written_;
  double write_seconds_ = 0.0;
  size_t written_frames_ = 0;  // frames in the last manifest written
};

}  // namespace skybake
