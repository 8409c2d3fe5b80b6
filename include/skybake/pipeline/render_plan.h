// The plan of one bake, made once before any file or GPU work and read by
// every stage: which frames it renders (a single bake is a sequence of one
// frame), with which views (PlanViews) and file names, which frame is the
// sequence's reference, and which part of the sequence this run bakes.
// `skybake plan` reads the same object for the frames it plans.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "skybake/input/frame_numbering.h"
#include "skybake/input/schedule.h"
#include "skybake/input/shard.h"
#include "skybake/input/style.h"
#include "skybake/model/view.h"
#include "skybake/output/ibl_files.h"

namespace skybake {

// The file names one frame writes (in out_dir), in the order they are written.
struct FrameNames {
  std::vector<std::string> faces;   // six, when output.faces
  std::string cube, latlong, png;   // empty when not written
  std::vector<IblFileName> ibl;     // the IBL maps' files (ibl_files.h), when asked for
  std::vector<std::string> engine;  // the engine preset's files (engine_preset.h), when one is set
  bool with_dfg = false;            // the bake's first frame carries the DFG table
  std::string cloud_shadow;         // the cloud shadow map (cloud_shadow.h), when asked for
  std::vector<std::string> All() const;
  // The manifest's kind of each file, in the order of All().
  std::vector<std::string> Kinds(const SkyStyle& style) const;
};
FrameNames FrameFileNames(const SkyStyle& style, int number_in_name, bool with_dfg = false,
                          int number_width = kFrameNumberMinDigits);

// One frame to bake: its style, sun, place in the sequence, views and files.
struct FramePlan {
  const SkyStyle* style = nullptr;
  int number = 0;  // 0: a single bake, no number in file names
  std::optional<CivilTime> time;
  double hours_from_start = 0.0;
  double elevation_deg = 0.0, azimuth_deg = 0.0;
  glm::dvec3 sun{0, 1, 0};
  std::vector<ViewRequest> views;  // PlanViews(*style), in the order the writer reads them
  FrameNames names;                // the first frame's carry the DFG table
  // Clock time since the sequence's first frame, in seconds: what the wind
  // moves the clouds by (0 for a single bake, and for a schedule without
  // clock times). A cloud formation's layer takes its own clock from the
  // frame's style instead (clouds.local_clock_s, cloud_formation.h).
  double CloudTimeSeconds() const { return hours_from_start * 3600.0; }
  // "frame N", or "render" for a single bake: the frame's stage name.
  std::string Label() const;
};

struct RenderPlan {
  std::vector<FramePlan> frames;       // every frame of the sequence, in order; one for a single bake
  const Schedule* schedule = nullptr;  // none for a single bake
  // A schedule's frames share one exposure and one half-float scale, chosen
  // before any file is written (ChooseSequenceExposure); a single bake's
  // frame finds its own from its images when its files are written.
  bool sequence = false;
  std::optional<FrameRange> part;  // the frames this run bakes (--frames, --shard); all when unset
  size_t reference = 0;            // the highest sun: the sequence's exposure and the glTF scene's texture
  bool exposed = false;            // some frame writes a preview or the glTF texture
  std::string manifest_name;       // ManifestFileName(part)
  std::vector<std::string> files;  // every file this run writes, the manifest and timings last

  bool Bakes(const FramePlan& frame) const { return !part || part->Contains(frame.number); }
  const SkyStyle& first() const { return *frames.front().style; }
  std::vector<const SkyStyle*> styles() const;  // every frame's
  std::vector<SkyStyle> BakedStyles() const;    // the frames this run bakes, for PlanPasses
};

// A single bake of `style` at its own sun.
RenderPlan PlanSingleBake(const SkyStyle& style);
// Frame k of `schedule` with `styles[k]` (ResolveFrameStyles); `part` within
// the schedule's frames (std::invalid_argument otherwise, as for a count of
// styles that does not match).
RenderPlan PlanSequenceBake(const std::vector<SkyStyle>& styles, const Schedule& schedule,
                            const std::optional<FrameRange>& part);

}  // namespace skybake
