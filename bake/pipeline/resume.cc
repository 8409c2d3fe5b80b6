#include "resume.h"

#include <filesystem>

#include <fmt/format.h>

#include "skybake/base/errors.h"
#include "skybake/base/file_door.h"
#include "skybake/input/config.h"
#include "skybake/model/envmap.h"
#include "skybake/output/sha256.h"

namespace skybake {

PreviousBake ReadPreviousManifest(const std::string& path) {
  PreviousBake previous;
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::symlink_status(path, ec);
  if (!std::filesystem::exists(status)) return previous;
  // What --resume cannot read is the folder's problem, not a write failure:
  // exit 6, as for any file in the way, with the fix.
  if (std::filesystem::is_directory(status))
    throw OutputExistsError(
        fmt::format("{} is a directory, not a manifest, so --resume cannot tell which frames are "
                    "done: move it away, or pass --force instead to bake every frame again",
                    path));
  if (!std::filesystem::is_regular_file(status))
    throw OutputExistsError(
        fmt::format("{} is not a regular file (a link, a pipe or a device), so --resume does not "
                    "read it: move it away, or pass --force instead to bake every frame again",
                    path));
  Manifest manifest;
  try {
    manifest = ReadManifest(path, ManifestNames::kUnchecked);
  } catch (const ManifestSyntaxError&) {
    throw OutputExistsError(
        fmt::format("{} is not valid JSON, so --resume cannot tell which frames are done: pass "
                    "--force instead to bake every frame again",
                    path));
  } catch (const ManifestError&) {
    previous.loaded = true;  // proves no frame: every frame is baked again
    return previous;
  }
  previous.loaded = true;
  previous.half_scale = manifest.half_scale;
  previous.exposure_ev100 = manifest.exposure_ev100;
  for (ManifestFrame& f : manifest.frames) {
    const int number = f.number;
    previous.frames[number] = std::move(f);
  }
  return previous;
}

std::optional<std::vector<BakedFile>> VerifiedFrame(const PreviousBake& previous, const FramePlan& frame,
                                                    const std::string& out_dir, double half_scale, double ev100) {
  if (!previous.loaded || previous.half_scale != half_scale || previous.exposure_ev100 != ev100) return std::nullopt;
  auto it = previous.frames.find(frame.number);
  if (it == previous.frames.end()) return std::nullopt;
  const ManifestFrame& f = it->second;
  if (f.style_sha256 != Sha256OfText(frame.style->resolved_toml)) return std::nullopt;
  const std::vector<std::string> expected = frame.names.All();
  const std::vector<std::string> kinds = frame.names.Kinds(*frame.style);
  size_t index = 0;
  for (const ManifestFile& entry : f.files) {
    if (index >= expected.size() || entry.file != expected[index] || entry.kind != kinds[index])
      throw ManifestError(fmt::format(
          "the manifest in {} lists {} ({}) for frame {}, where this bake of the same style writes {}: the manifest "
          "was edited or is not skybake's; nothing was read under that name. Pass --force instead of --resume to "
          "bake every frame again",
          out_dir, EscapedText(entry.file), EscapedText(entry.kind), frame.number,
          index < expected.size() ? EscapedText(expected[index]) : "no more files"));
    // A face file is listed as the face the bake writes under its name
    // (the faces come first, +X to -Z).
    const std::string face = kinds[index] == "face" ? CubeFaceLabel(int(index)) : "";
    if (entry.face != face)
      throw ManifestError(fmt::format(
          "the manifest in {} lists {} as face {} for frame {}, where this bake of the same style writes face {} "
          "under that name: the manifest was edited or is not skybake's. Pass --force instead of --resume to bake "
          "every frame again",
          out_dir, EscapedText(entry.file), EscapedText(entry.face), frame.number, face.empty() ? "none" : face));
    ++index;
  }
  if (index != expected.size()) return std::nullopt;
  std::vector<BakedFile> files;
  index = 0;
  for (const ManifestFile& entry : f.files) {
    std::string path = (std::filesystem::path(out_dir) / expected[index]).string();
    // Through the door (file_door.h): only a regular file of the folder is
    // verified; a link, FIFO or device at the name is baked over, not read.
    uint64_t bytes = 0;
    if (!RegularFileSize(path, bytes).empty()) return std::nullopt;
    std::string sha = Sha256OfFile(path);
    if (sha != entry.sha256) return std::nullopt;
    files.push_back({path, kinds[index], bytes, sha});
    ++index;
  }
  return files;
}

}  // namespace skybake
