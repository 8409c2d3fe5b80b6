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
#include "skybake/output/manifest.h"
#include "skybake/pipeline/pipeline.h"
#include "skybake/pipeline/render_plan.h"
#include "stage_timer.h"

namespace skybake {

class ManifestBuilder {
 public:
  // Reads the frames done from `result` and the exposure as it stands when
  // a manifest is built (a single bake's is chosen by its frame).
  ManifestBuilder(const RenderPlan& plan, const BakeOptions& options, const BakeExposure& exposure,
                  BakeResult& result);

  // The manifest of the frames done.
  Manifest Build() const;
  // Writes it with the scene's files, into result.manifest_path.
  void Write(const std::vector<BakedFile>& scene, bool complete);
  // After a frame: writes it when enough has changed since the last write
  // (a killed bake leaves a valid record of the frames done).
  void WriteProgress();

 private:
  const RenderPlan& plan_;
  const BakeOptions& options_;
  const BakeExposure& exposure_;
  BakeResult& result_;
  std::vector<std::string> style_sha256_;  // per frame of the plan
  std::string sequence_identity_;          // every frame's number, time, sun and style
  std::map<int, size_t> frame_index_;      // frame number -> index in the plan
  Clock::time_point written_;
  double write_seconds_ = 0.0;
  size_t written_frames_ = 0;  // frames in the last manifest written
};

}  // namespace skybake
