#include "resume.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include <fmt/format.h>

#include "skybake/base/errors.h"
#include "skybake/input/config.h"
#include "skybake/output/sha256.h"

namespace skybake {

using nlohmann::json;

PreviousBake ReadPreviousManifest(const std::string& path) {
  PreviousBake previous;
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::symlink_status(path, ec);
  if (!std::filesystem::exists(status)) return previous;
  // What --resume cannot read is the folder's problem, not a write failure:
  // exit 6, as for any file in the way, with the fix.
  if (std::filesystem::is_directory(status))
    throw OutputExistsError(fmt::format("{} is a directory, not a manifest, so --resume cannot tell which frames are "
                                        "done: move it away, or pass --force instead to bake every frame again",
                                        path));
  if (!std::filesystem::is_regular_file(status))
    throw OutputExistsError(fmt::format("{} is not a regular file (a link, a pipe or a device), so --resume does not "
                                        "read it: move it away, or pass --force instead to bake every frame again",
                                        path));
  std::ifstream in(path, std::ios::binary);
  json manifest = json::parse(in, nullptr, false);
  if (manifest.is_discarded() || !manifest.is_object())
    throw OutputExistsError(fmt::format("{} is not valid JSON, so --resume cannot tell which frames are done: pass "
                                        "--force instead to bake every frame again", path));
  previous.loaded = true;
  // A value of the wrong type matches no frame: those frames are baked again.
  auto number = [&](const char* key) {
    return manifest.contains(key) && manifest[key].is_number() ? manifest[key].get<double>() : std::nan("");
  };
  previous.half_scale = number("half_scale");
  previous.exposure_ev100 = number("exposure_ev100");
  if (manifest.contains("frames") && manifest["frames"].is_array())
    for (const json& f : manifest["frames"])
      if (f.is_object() && f.contains("frame") && f["frame"].is_number_integer() &&
          f["frame"].get<int64_t>() >= 0 && f["frame"].get<int64_t>() <= std::numeric_limits<int>::max())
        previous.frames[f["frame"].get<int>()] = f;
  return previous;
}

namespace {

// A string member, or "" when absent or not a string.
std::string StringOf(const json& object, const char* key) {
  return object.contains(key) && object[key].is_string() ? object[key].get<std::string>() : std::string();
}

}  // namespace

std::optional<std::vector<BakedFile>> VerifiedFrame(const PreviousBake& previous, const FramePlan& frame,
                                                    const std::string& out_dir, double half_scale, double ev100) {
  if (!previous.loaded || previous.half_scale != half_scale || previous.exposure_ev100 != ev100)
    return std::nullopt;
  auto it = previous.frames.find(frame.number);
  if (it == previous.frames.end()) return std::nullopt;
  const json& f = it->second;
  if (StringOf(f, "style_sha256") != Sha256OfText(frame.style->resolved_toml)) return std::nullopt;
  if (!f.contains("files") || !f["files"].is_array()) return std::nullopt;
  const std::vector<std::string> expected = frame.names.All();
  const std::vector<std::string> kinds = frame.names.Kinds(*frame.style);
  size_t index = 0;
  for (const json& entry : f["files"]) {
    const std::string name = entry.is_object() ? StringOf(entry, "file") : std::string();
    const std::string kind = entry.is_object() ? StringOf(entry, "kind") : std::string();
    if (index >= expected.size() || name != expected[index] || kind != kinds[index])
      throw ManifestError(fmt::format(
          "the manifest in {} lists {} ({}) for frame {}, where this bake of the same style writes {}: the manifest "
          "was edited or is not skybake's; nothing was read under that name. Pass --force instead of --resume to "
          "bake every frame again",
          out_dir, EscapedText(name), EscapedText(kind), frame.number,
          index < expected.size() ? EscapedText(expected[index]) : "no more files"));
    ++index;
  }
  if (index != expected.size()) return std::nullopt;
  std::vector<BakedFile> files;
  index = 0;
  for (const json& entry : f["files"]) {
    std::string path = (std::filesystem::path(out_dir) / expected[index]).string();
    std::error_code ec;
    // A link is not followed: only a regular file of the folder is verified.
    if (!std::filesystem::is_regular_file(std::filesystem::symlink_status(path, ec))) return std::nullopt;
    std::string sha = Sha256OfFile(path);
    if (sha != StringOf(entry, "sha256")) return std::nullopt;
    files.push_back({path, kinds[index], uint64_t(std::filesystem::file_size(path)), sha});
    ++index;
  }
  return files;
}

}  // namespace skybake
