// The manifest of a bake (manifest.json): every file with its size and
// SHA-256, per frame the time, sun and SH irradiance, and the sequence-wide
// values (exposure, half scale, the glTF scene's texture frame). It holds
// only what the bake determines, so the same bake gives the same bytes;
// wall-clock timings and the output folder go to timings.json.
//
// A part of a sequence (`--frames`, `--shard`) writes
// manifest.shard-FIRST-LAST.json instead, in the same format with a `part`
// entry and only its frames, and no glTF scene. `skybake merge-manifest`
// joins the parts into manifest.json and the scene through the same
// function a whole bake ends with (WriteSceneAndManifest), so a merged
// folder equals an unsharded bake byte for byte.
#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "skybake/model/atmosphere.h"
#include "skybake/model/cloud_shadow.h"
#include "skybake/input/config.h"
#include "skybake/input/frame_numbering.h"
#include "skybake/base/errors.h"
#include "skybake/output/bake_record.h"
#include "skybake/output/json_spool.h"
#include "skybake/model/sh.h"
#include "skybake/input/shard.h"
#include "skybake/model/solar_position.h"

namespace skybake {

struct ManifestFile {
  std::string file;  // name inside the output folder
  std::string kind;  // as BakedFile::kind
  uint64_t bytes = 0;
  std::string sha256;  // lowercase hex
  // Kind "face": which cube face the file is, "+X" ... "-Z" (CubeFaceLabel),
  // so that a face file renamed to another face's name is found; empty for
  // every other kind.
  std::string face;
};

struct ManifestFrame {
  int number = 0;                   // in file names; 0 for a single bake
  std::string style_sha256;         // of the frame's resolved style TOML
  std::optional<std::string> time;  // ISO 8601 with UTC offset, for clock-time schedules
  double hours_from_start = 0.0;
  double animation_time_s = 0.0;  // the glTF sun key: hours of clock time, else the frame's index
  double sun_elevation_deg = 0.0;
  double sun_azimuth_deg = 0.0;  // clockwise from North
  glm::dvec3 sun_direction{0, 1, 0};
  double sun_illuminance_lux = 0.0;
  Rgb sun_irradiance{0, 0, 0};  // transmitted sun at the observer, output units x sr
  ShRgb sh_irradiance_with_sun{};
  ShRgb sh_irradiance_without_sun{};
  // The style's sun.angular_radius_rad of the frame, recorded (as
  // sun.angular_radius_rad) only with the USD layer, whose Sun takes it.
  std::optional<double> sun_angular_radius_rad;
  std::optional<MoonRecord> moon;               // with the night sky's Moon; absent otherwise
  std::vector<ManifestFile> files;              // in the order they are written
  std::optional<CloudShadowInfo> cloud_shadow;  // where the frame's cloud shadow map lies (cloud_shadow.h)
};

// What the glTF scene takes from the style, decided from the whole sequence
// (the texture is the reference frame's PNG), so a merge needs no style.
struct ManifestScene {
  bool enabled = false;
  std::string name;  // output.basename: name.gltf, name.bin, name.glb
  GltfSettings dome;
  std::string texture_file;  // the reference frame's PNG
  int texture_width = 0, texture_height = 0;
};

// What the USD layer takes from the style (usd_layer.h): recorded only when
// it is on, so that a bake without it keeps its manifest's bytes.
struct ManifestUsd {
  bool enabled = false;
  std::string name;  // output.basename: name.usda
};

struct Manifest {
  std::string version;          // SKYBAKE_VERSION
  std::string commit;           // the git commit skybake was built from, "unknown" outside git
  std::string style, schedule;  // paths as given on the command line (recorded in every EXR too)
  std::string sequence_sha256;  // every frame's number, time, sun and resolved style: one bake, one value
  std::string units;
  double exposure_ev100 = 0.0;
  std::string exposure_source;
  int texture_frame = 0;  // the reference frame (highest sun)
  double half_scale = 1.0;
  std::optional<GeoLocation> place;
  std::optional<FrameRange> sequence;  // every frame of the schedule; unset for a single bake
  std::optional<FrameRange> part;      // the frames of a part (--frames, --shard); unset for a whole bake
  ManifestScene gltf;
  ManifestUsd usd;
  std::vector<ManifestFrame> frames;  // by frame number
  bool complete = false;              // every frame of the bake (or part) is done
  std::vector<ManifestFile> scene;    // the glTF scene's files and the USD layer, once written
};

// manifest.json for a whole bake, manifest.shard-0003-0004.json for the part
// of frames 3 to 4 (numbers padded as in frame file names); the same for
// timings.json and timings.shard-0003-0004.json.
std::string ManifestFileName(const std::optional<FrameRange>& part);
std::string TimingsFileName(const std::optional<FrameRange>& part);

// One frame's line of the text whose SHA-256 is a manifest's
// sequence_sha256: number, ISO 8601 time ("" without), sun direction,
// style_sha256.
std::string SequenceIdentityLine(int number, const std::string& time_iso8601, const glm::dvec3& sun,
                                 const std::string& style_sha256);

// The manifest's frame record of a baked frame (files by name, not path).
ManifestFrame ManifestFrameOf(const FrameResult& frame);

// Writes `manifest` as JSON to `path`, atomically. Throws OutputError.
void WriteManifest(const Manifest& manifest, const std::string& path);
// The bytes WriteManifest writes; a frame's entry in them (at indent 0):
// a bake keeps its frames' entries on disk (json_spool.h) and writes the
// manifest around them, with the same bytes.
std::string ManifestText(const Manifest& manifest);
std::string ManifestFrameText(const ManifestFrame& frame);

// ReadManifest's error for a file that cannot be read or is not a JSON
// object (a ManifestError, exit 8, as any other): apart, so that --resume
// can say what to do instead.
class ManifestSyntaxError : public ManifestError {
 public:
  using ManifestError::ManifestError;
};

// The one check of a name read from a manifest, by every command that opens
// one (view, gallery, merge-manifest, --resume): a plain file name directly
// inside the manifest's folder (FolderNameProblem of file_door.h, and
// IsPlainFileName: no '/', no '..', not absolute, no control character).
// Throws ManifestError (exit 8) naming `manifest_path`, `where` (the entry)
// and the name, escaped.
void CheckListedName(const std::string& manifest_path, const std::string& where, const std::string& name);
bool IsListedNameOk(const std::string& name);

// Whether ReadManifest checks the names it reads against the ones skybake
// gives (kUnchecked: the caller compares them with the exact names of its
// own bake, as --resume does, before opening anything under them).
enum class ManifestNames { kChecked, kUnchecked };

// Reads a manifest written by WriteManifest: the one reader, for
// merge-manifest and --resume. Throws ManifestSyntaxError when the file
// cannot be read or is not a JSON object, ManifestError naming the file and
// the entry that is missing, malformed (a `bytes` that is not an integer in
// [0, 2^53], a frame number that is not an int) or (kChecked) a name that
// is not the one skybake gives that frame and kind (a plain file name,
// BASE_FACE.NNNN.exr, BASE_cube.NNNN.exr, BASE_latlong.NNNN.exr,
// BASE_latlong.NNNN.png in that order; the scene NAME.gltf/.bin/.glb).
Manifest ReadManifest(const std::string& path, ManifestNames names = ManifestNames::kChecked);

// How a whole bake ends, and a merge: writes the glTF scene (when
// manifest.gltf.enabled) and the USD layer (manifest.usd.enabled) from the frames' suns and SH and the texture PNG in
// `out_dir`, lists its files in manifest.scene, marks the manifest complete
// and writes out_dir/manifest.json. Returns the scene's files. Throws
// OutputError.
std::vector<BakedFile> WriteSceneAndManifest(Manifest& manifest, const std::string& out_dir);
// Its first half: the scene alone, listed in manifest.scene. It reads of
// the frames their suns, SH, times and Moons, and the files of the texture
// frame only; the USD layer every frame's latlong EXR (its name, and the
// skybake:scale in its header) and style_sha256.
std::vector<BakedFile> WriteScene(Manifest& manifest, const std::string& out_dir);

// Run-dependent facts of a bake, kept out of the manifest: the output folder,
// wall-clock and GPU timings per stage and frame, renderer builds.
// With `spools`, its stages and frames are the entries there (a bake that
// keeps no frame records, BakeOptions::keep_frame_records), each made by
// TimingsStageText or TimingsFrameText.
struct TimingsSpools {
  explicit TimingsSpools(const std::string& dir) : stages(dir), frames(dir) {}
  JsonArraySpool stages, frames;
};
std::string TimingsStageText(const StageReport& stage);
std::string TimingsFrameText(const FrameResult& frame);
void WriteTimings(const BakeResult& result, const std::string& out_dir, double total_seconds, const std::string& path,
                  const TimingsSpools* spools = nullptr);

struct MergeOptions {
  std::string dir;               // holds the parts' manifests and files
  bool verify_checksums = true;  // SHA-256 of every listed file; sizes only when false
  bool force = false;            // replace an existing manifest.json and scene
};

struct MergeResult {
  std::vector<std::string> parts;  // the shard manifests merged, by first frame
  int frames = 0;
  std::string manifest_path;
  std::vector<BakedFile> scene_files;
};

// Joins every manifest.shard-*.json of options.dir into manifest.json and
// writes the glTF scene. The parts must come from one bake (same version,
// style, schedule, sequence, exposure and half scale), be complete, not
// overlap and together cover every frame of the schedule; every listed file
// must be in options.dir with its size (and SHA-256). Throws ManifestError
// otherwise, before writing anything; OutputExistsError when manifest.json
// or the scene exists and options.force is not set.
MergeResult MergeShardManifests(const MergeOptions& options);

}  // namespace skybake
