// --resume (private to the pipeline layer): which frames of an interrupted
// sequence the previous manifest proves done, file by file.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "skybake/output/bake_record.h"
#include "skybake/output/manifest.h"
#include "skybake/pipeline/render_plan.h"

namespace skybake {

// What a resumed bake may skip: the frames of the previous manifest.
struct PreviousBake {
  bool loaded = false;
  double half_scale = 0.0;
  double exposure_ev100 = 0.0;
  std::map<int, ManifestFrame> frames;  // by frame number
};

// The manifest at `path` read by ReadManifest (manifest.h), when there is
// one (nothing loaded otherwise). OutputExistsError (exit 6) when it is a
// directory, not a regular file, or not JSON. A manifest ReadManifest finds
// malformed (a value of the wrong type, an entry missing) proves no frame:
// loaded, with no frames, every frame is baked again. Its names are checked
// by VerifiedFrame, against this bake's.
PreviousBake ReadPreviousManifest(const std::string& path);

// The files of `frame` from the previous manifest when every one of them is
// on disk with its recorded SHA-256 and the frame was baked with the same
// style, exposure and half scale; otherwise nothing. A frame of the same
// style lists exactly the names and kinds this bake gives it: any other
// name stops the bake (ManifestError, exit 8) before it is opened.
std::optional<std::vector<BakedFile>> VerifiedFrame(const PreviousBake& previous, const FramePlan& frame,
                                                    const std::string& out_dir, double half_scale, double ev100);

}  // namespace skybake
