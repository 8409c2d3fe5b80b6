#include "skybake/manifest.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "skybake/exr_io.h"
#include "skybake/gltf_scene.h"
#include "skybake/output_lock.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kShBasis =
    "real SH l<=2, order (0,0)(1,-1)(1,0)(1,1)(2,-2)(2,-1)(2,0)(2,1)(2,2), Ramamoorthi-Hanrahan 2001 constants on "
    "world x,y,z (+Y up); irradiance E(n) = sum E_lm Y_lm(n)";
constexpr const char* kFrameConvention =
    "+Y up, right-handed, North -Z, East +X; sun_direction points towards the Sun; azimuth clockwise from North";

// --- JSON form. nlohmann writes doubles in their shortest round-trip form,
// so a manifest read back holds the very doubles that were written: a merge
// builds the scene from the same values as the bake that wrote the parts.

json VectorJson(const glm::dvec3& v) { return {v.x, v.y, v.z}; }
json RgbJson(const Rgb& c) { return {c[0], c[1], c[2]}; }
json ShJson(const ShRgb& c) {
  json rows = json::array();
  for (const Rgb& rgb : c) rows.push_back(RgbJson(rgb));
  return rows;
}

json FileJson(const ManifestFile& f) {
  return {{"file", f.file}, {"kind", f.kind}, {"bytes", f.bytes}, {"sha256", f.sha256}};
}

json RangeJson(const FrameRange& r) { return {{"first_frame", r.first}, {"last_frame", r.last}, {"frames", r.count()}}; }

json FrameJson(const ManifestFrame& f) {
  json files = json::array();
  for (const ManifestFile& file : f.files) files.push_back(FileJson(file));
  return {{"frame", f.number},
          {"style_sha256", f.style_sha256},
          {"time", f.time ? json(*f.time) : json(nullptr)},
          {"hours_from_start", f.hours_from_start},
          {"animation_time_s", f.animation_time_s},
          {"sun", {{"elevation_deg", f.sun_elevation_deg},
                   {"azimuth_deg", f.sun_azimuth_deg},
                   {"direction", VectorJson(f.sun_direction)},
                   {"illuminance_lux", f.sun_illuminance_lux},
                   {"irradiance", RgbJson(f.sun_irradiance)}}},
          {"sh_irradiance_with_sun", ShJson(f.sh_irradiance_with_sun)},
          {"sh_irradiance_without_sun", ShJson(f.sh_irradiance_without_sun)},
          {"files", files}};
}

json ManifestJson(const Manifest& m) {
  json j = {
      {"version", m.version},
      {"style", m.style},
      {"schedule", m.schedule},
      {"sequence_sha256", m.sequence_sha256},
      {"units", m.units},
      {"exposure_ev100", m.exposure_ev100},
      {"exposure_source", m.exposure_source},
      {"texture_frame", m.texture_frame},
      {"half_scale", m.half_scale},
      {"sh_basis", kShBasis},
      {"frame_convention", kFrameConvention},
      {"gltf", {{"enabled", m.gltf.enabled},
                {"name", m.gltf.name},
                {"dome", m.gltf.dome.dome == DomeShape::kHemisphere ? "hemisphere" : "sphere"},
                {"radius_m", m.gltf.dome.radius_m},
                {"flattening", m.gltf.dome.flattening},
                {"segments", m.gltf.dome.segments},
                {"texture", {{"file", m.gltf.texture_file},
                             {"width", m.gltf.texture_width},
                             {"height", m.gltf.texture_height}}}}},
  };
  if (m.place) j["place"] = {{"latitude_deg", m.place->latitude_deg}, {"longitude_deg", m.place->longitude_deg}};
  if (m.sequence) j["sequence"] = RangeJson(*m.sequence);
  if (m.part) {
    j["part"] = RangeJson(*m.part);
    if (m.sequence) j["part"]["of_frames"] = m.sequence->count();
  }
  json frames = json::array();
  for (const ManifestFrame& f : m.frames) frames.push_back(FrameJson(f));
  j["frames"] = frames;
  j["complete"] = m.complete;
  json scene = json::array();
  for (const ManifestFile& f : m.scene) scene.push_back(FileJson(f));
  j["scene"] = scene;
  return j;
}

// Reading: every access names the file and the entry when it fails.
class Reader {
 public:
  explicit Reader(std::string path) : path_(std::move(path)) {}

  template <typename T>
  T Get(const json& object, const char* key) const {
    if (!object.is_object() || !object.contains(key)) Fail(fmt::format("no '{}'", key));
    try {
      return object.at(key).get<T>();
    } catch (const json::exception&) {
      Fail(fmt::format("'{}' has the wrong type", key));
    }
  }
  glm::dvec3 Vector(const json& object, const char* key) const {
    std::vector<double> v = Get<std::vector<double>>(object, key);
    if (v.size() != 3) Fail(fmt::format("'{}' is not 3 numbers", key));
    return {v[0], v[1], v[2]};
  }
  Rgb RgbOf(const json& object, const char* key) const {
    glm::dvec3 v = Vector(object, key);
    return {v.x, v.y, v.z};
  }
  ShRgb Sh(const json& object, const char* key) const {
    std::vector<std::vector<double>> rows = Get<std::vector<std::vector<double>>>(object, key);
    ShRgb sh{};
    if (rows.size() != sh.size()) Fail(fmt::format("'{}' is not {} rows", key, sh.size()));
    for (size_t i = 0; i < sh.size(); ++i) {
      if (rows[i].size() != 3) Fail(fmt::format("'{}' row {} is not 3 numbers", key, i));
      sh[i] = {rows[i][0], rows[i][1], rows[i][2]};
    }
    return sh;
  }
  FrameRange Range(const json& object, const char* key) const {
    const json& r = Get<json>(object, key);
    FrameRange range{Get<int>(r, "first_frame"), Get<int>(r, "last_frame")};
    if (range.last < range.first) Fail(fmt::format("'{}' ends before it starts", key));
    return range;
  }
  [[noreturn]] void Fail(const std::string& what) const {
    throw ManifestError(fmt::format("{}: {}: not a skybake manifest, or one from another version", path_, what));
  }

 private:
  std::string path_;
};

std::vector<ManifestFile> FilesOf(const Reader& r, const json& array) {
  if (!array.is_array()) r.Fail("a file list is not an array");
  std::vector<ManifestFile> files;
  for (const json& f : array)
    files.push_back({r.Get<std::string>(f, "file"), r.Get<std::string>(f, "kind"), r.Get<uint64_t>(f, "bytes"),
                     r.Get<std::string>(f, "sha256")});
  return files;
}

std::string FrameRangeText(const FrameRange& r) {
  return r.first == r.last ? fmt::format("{}", r.first) : fmt::format("{}-{}", r.first, r.last);
}

// The frames of `numbers` as ranges: "2-3, 7".
std::string RangesText(const std::vector<int>& numbers) {
  std::string text;
  for (size_t i = 0; i < numbers.size();) {
    size_t j = i;
    while (j + 1 < numbers.size() && numbers[j + 1] == numbers[j] + 1) ++j;
    if (!text.empty()) text += ", ";
    text += FrameRangeText({numbers[i], numbers[j]});
    i = j + 1;
  }
  return text;
}

// Everything of a manifest that all parts of one bake share.
json SharedPart(json manifest) {
  for (const char* key : {"frames", "part", "complete", "scene"}) manifest.erase(key);
  return manifest;
}

}  // namespace

std::string ManifestFileName(const std::optional<FrameRange>& part) {
  return part ? fmt::format("manifest.shard-{:04d}-{:04d}.json", part->first, part->last) : "manifest.json";
}

std::string TimingsFileName(const std::optional<FrameRange>& part) {
  return part ? fmt::format("timings.shard-{:04d}-{:04d}.json", part->first, part->last) : "timings.json";
}

ManifestFrame ManifestFrameOf(const FrameResult& frame) {
  ManifestFrame f;
  f.number = frame.number;
  if (frame.time) f.time = frame.time->Iso8601();
  f.sun_elevation_deg = frame.sun_elevation_deg;
  f.sun_azimuth_deg = frame.sun_azimuth_deg;
  f.sun_direction = frame.sun_direction;
  f.sun_illuminance_lux = frame.sun_illuminance_lux;
  f.sun_irradiance = frame.sun_irradiance;
  f.sh_irradiance_with_sun = frame.sh_irradiance_with_sun;
  f.sh_irradiance_without_sun = frame.sh_irradiance_without_sun;
  for (const BakedFile& file : frame.files)
    f.files.push_back({fs::path(file.path).filename().string(), file.kind, file.bytes, file.sha256});
  return f;
}

void WriteManifest(const Manifest& manifest, const std::string& path) {
  WriteFileAtomically(path, ManifestJson(manifest).dump(2) + "\n");
}

Manifest ReadManifest(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ManifestError(fmt::format("cannot read {}", path));
  json j = json::parse(in, nullptr, false);
  Reader r(path);
  if (j.is_discarded() || !j.is_object()) r.Fail("invalid JSON");
  Manifest m;
  m.version = r.Get<std::string>(j, "version");
  m.style = r.Get<std::string>(j, "style");
  m.schedule = r.Get<std::string>(j, "schedule");
  m.sequence_sha256 = r.Get<std::string>(j, "sequence_sha256");
  m.units = r.Get<std::string>(j, "units");
  m.exposure_ev100 = r.Get<double>(j, "exposure_ev100");
  m.exposure_source = r.Get<std::string>(j, "exposure_source");
  m.texture_frame = r.Get<int>(j, "texture_frame");
  m.half_scale = r.Get<double>(j, "half_scale");
  const json& gltf = r.Get<json>(j, "gltf");
  m.gltf.enabled = r.Get<bool>(gltf, "enabled");
  m.gltf.name = r.Get<std::string>(gltf, "name");
  m.gltf.dome.dome = r.Get<std::string>(gltf, "dome") == "hemisphere" ? DomeShape::kHemisphere : DomeShape::kSphere;
  m.gltf.dome.radius_m = r.Get<double>(gltf, "radius_m");
  m.gltf.dome.flattening = r.Get<double>(gltf, "flattening");
  m.gltf.dome.segments = r.Get<int>(gltf, "segments");
  m.gltf.dome.enabled = m.gltf.enabled;
  const json& texture = r.Get<json>(gltf, "texture");
  m.gltf.texture_file = r.Get<std::string>(texture, "file");
  m.gltf.texture_width = r.Get<int>(texture, "width");
  m.gltf.texture_height = r.Get<int>(texture, "height");
  if (j.contains("place"))
    m.place = GeoLocation{r.Get<double>(j["place"], "latitude_deg"), r.Get<double>(j["place"], "longitude_deg")};
  if (j.contains("sequence")) m.sequence = r.Range(j, "sequence");
  if (j.contains("part")) m.part = r.Range(j, "part");
  for (const json& f : r.Get<json>(j, "frames")) {
    ManifestFrame frame;
    frame.number = r.Get<int>(f, "frame");
    frame.style_sha256 = r.Get<std::string>(f, "style_sha256");
    if (f.contains("time") && !f["time"].is_null()) frame.time = r.Get<std::string>(f, "time");
    frame.hours_from_start = r.Get<double>(f, "hours_from_start");
    frame.animation_time_s = r.Get<double>(f, "animation_time_s");
    const json& sun = r.Get<json>(f, "sun");
    frame.sun_elevation_deg = r.Get<double>(sun, "elevation_deg");
    frame.sun_azimuth_deg = r.Get<double>(sun, "azimuth_deg");
    frame.sun_direction = r.Vector(sun, "direction");
    frame.sun_illuminance_lux = r.Get<double>(sun, "illuminance_lux");
    frame.sun_irradiance = r.RgbOf(sun, "irradiance");
    frame.sh_irradiance_with_sun = r.Sh(f, "sh_irradiance_with_sun");
    frame.sh_irradiance_without_sun = r.Sh(f, "sh_irradiance_without_sun");
    frame.files = FilesOf(r, r.Get<json>(f, "files"));
    m.frames.push_back(std::move(frame));
  }
  m.complete = r.Get<bool>(j, "complete");
  m.scene = FilesOf(r, r.Get<json>(j, "scene"));
  return m;
}

std::vector<BakedFile> WriteSceneAndManifest(Manifest& manifest, const std::string& out_dir) {
  // Scene: the dome textured with the reference frame, the sun (animated
  // for a sequence), all from the manifest's frames.
  std::vector<BakedFile> scene_files;
  manifest.scene.clear();
  if (manifest.gltf.enabled && !manifest.frames.empty()) {
    json frame_extras = json::array();
    SceneDescription scene;
    scene.name = manifest.gltf.name;
    scene.out_dir = out_dir;
    scene.texture_file = manifest.gltf.texture_file;
    scene.texture_width = manifest.gltf.texture_width;
    scene.texture_height = manifest.gltf.texture_height;
    scene.dome = manifest.gltf.dome;
    for (size_t i = 0; i < manifest.frames.size(); ++i) {
      const ManifestFrame& f = manifest.frames[i];
      if (f.number == manifest.texture_frame) scene.light_frame = int(i);
      SceneSun sun;
      sun.time_s = f.animation_time_s;
      sun.direction = f.sun_direction;
      sun.illuminance_lux = f.sun_illuminance_lux;
      double peak = std::max({f.sun_irradiance[0], f.sun_irradiance[1], f.sun_irradiance[2]});
      if (peak > 0.0) sun.color = {f.sun_irradiance[0] / peak, f.sun_irradiance[1] / peak, f.sun_irradiance[2] / peak};
      scene.suns.push_back(sun);
      frame_extras.push_back({{"frame", f.number},
                              {"time", f.time.value_or("")},
                              {"animation_time_s", f.animation_time_s},
                              {"sun_direction", VectorJson(f.sun_direction)},
                              {"sun_illuminance_lux", f.sun_illuminance_lux},
                              {"sh_irradiance_with_sun", ShJson(f.sh_irradiance_with_sun)},
                              {"sh_irradiance_without_sun", ShJson(f.sh_irradiance_without_sun)}});
    }
    json provenance = {{"version", manifest.version},       {"style", manifest.style},
                       {"schedule", manifest.schedule},     {"units", manifest.units},
                       {"exposure_ev100", manifest.exposure_ev100}, {"texture_frame", manifest.texture_frame},
                       {"sh_basis", kShBasis},              {"frames", frame_extras}};
    scene.extras_json = provenance.dump();
    WrittenScene written = WriteGltfScene(scene);
    for (auto [path, kind] : {std::pair{written.gltf_path, "gltf"}, {written.bin_path, "gltf_bin"},
                              {written.glb_path, "glb"}}) {
      scene_files.push_back({path, kind, fs::file_size(path), Sha256OfFile(path)});
      manifest.scene.push_back({fs::path(path).filename().string(), kind, scene_files.back().bytes,
                                scene_files.back().sha256});
    }
  }
  // Manifest: written last, once every file it lists is in place.
  manifest.complete = true;
  WriteManifest(manifest, (fs::path(out_dir) / ManifestFileName(std::nullopt)).string());
  return scene_files;
}

void WriteTimings(const BakeResult& result, const std::string& out_dir, double total_seconds,
                  const std::string& path) {
  json stages = json::array();
  for (const StageReport& s : result.stages) stages.push_back({{"stage", s.name}, {"seconds", s.seconds}});
  json frames = json::array();
  for (const FrameResult& f : result.frames) {
    json passes = json::array();
    for (const PassTiming& t : f.gpu_passes) passes.push_back({{"name", t.name}, {"gpu_ms", t.gpu_ms}});
    frames.push_back({{"frame", f.number}, {"render_s", f.render_seconds}, {"write_s", f.write_seconds},
                      {"gpu_passes", passes}});
  }
  json timings = {{"out_dir", out_dir},
                  {"renderer_builds", result.renderer_builds},
                  {"total_s", total_seconds},
                  {"stages", stages},
                  {"frames", frames}};
  WriteFileAtomically(path, timings.dump(2) + "\n");
}

MergeResult MergeShardManifests(const MergeOptions& options) {
  const fs::path dir(options.dir);
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw ManifestError(fmt::format("{} is not a folder: give the folder the shards baked into", options.dir));

  // The parts: every manifest.shard-FIRST-LAST.json, by first frame.
  static const std::regex kPartName(R"(manifest\.shard-\d+-\d+\.json)");
  std::vector<std::string> paths;
  for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (e.is_regular_file() && std::regex_match(name, kPartName)) paths.push_back(e.path().string());
  }
  if (paths.empty())
    throw ManifestError(fmt::format("no shard manifests (manifest.shard-FIRST-LAST.json) in {}: bake with --shard "
                                    "I/N or --frames A:B into it first",
                                    options.dir));
  std::vector<std::pair<Manifest, json>> parts;
  for (const std::string& path : paths) {
    Manifest m = ReadManifest(path);
    std::ifstream in(path, std::ios::binary);
    parts.emplace_back(std::move(m), SharedPart(json::parse(in)));
  }
  std::vector<size_t> order(parts.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  for (size_t i = 0; i < parts.size(); ++i)
    if (!parts[i].first.part || !parts[i].first.sequence)
      throw ManifestError(fmt::format("{} is not the manifest of a part of a sequence", paths[i]));
  std::sort(order.begin(), order.end(),
            [&](size_t a, size_t b) { return parts[a].first.part->first < parts[b].first.part->first; });

  // One bake: the parts agree on everything but their frames.
  const size_t first = order.front();
  for (size_t i : order) {
    const json& a = parts[first].second;
    const json& b = parts[i].second;
    if (a == b) continue;
    std::string key;
    for (const json* side : {&a, &b})
      for (auto it = side->begin(); it != side->end() && key.empty(); ++it)
        if (!a.contains(it.key()) || !b.contains(it.key()) || a[it.key()] != b[it.key()]) key = it.key();
    throw ManifestError(fmt::format(
        "{} and {} come from different bakes: their '{}' differs ({} vs {}): bake every shard with the same "
        "skybake version, style, schedule, --set and --size into one folder",
        paths[first], paths[i], key, a.contains(key) ? a[key].dump() : "none", b.contains(key) ? b[key].dump() : "none"));
  }

  // Every frame once: complete parts, no overlap, no gap.
  const Manifest& shared = parts[first].first;
  const FrameRange sequence = *shared.sequence;
  std::map<int, size_t> owner;  // frame number -> part
  for (size_t i : order) {
    const Manifest& m = parts[i].first;
    if (!m.complete || int(m.frames.size()) != m.part->count())
      throw ManifestError(fmt::format("{} is incomplete ({} of frames {} baked): finish it by running its bake "
                                      "again with --resume",
                                      paths[i], m.frames.size(), FrameRangeText(*m.part)));
    for (const ManifestFrame& f : m.frames) {
      if (!m.part->Contains(f.number) || !sequence.Contains(f.number))
        throw ManifestError(fmt::format("{} lists frame {}, outside its part {}", paths[i], f.number,
                                        FrameRangeText(*m.part)));
      auto [it, inserted] = owner.emplace(f.number, i);
      if (!inserted)
        throw ManifestError(fmt::format("frame {} is in both {} and {}: the shards overlap; remove one of the two "
                                        "manifests (with its files if they differ) and merge again",
                                        f.number, paths[it->second], paths[i]));
    }
  }
  std::vector<int> missing;
  for (int n = sequence.first; n <= sequence.last; ++n)
    if (!owner.count(n)) missing.push_back(n);
  if (!missing.empty()) {
    const bool one_range = missing.back() - missing.front() + 1 == int(missing.size());
    throw ManifestError(fmt::format(
        "frame{} {} of {} {} missing: no shard manifest in {} lists {}: bake {} into {} (the missing --shard, or {}), "
        "then merge again",
        missing.size() == 1 ? "" : "s", RangesText(missing), FrameRangeText(sequence),
        missing.size() == 1 ? "is" : "are", options.dir, missing.size() == 1 ? "it" : "them",
        missing.size() == 1 ? "it" : "them", options.dir,
        one_range ? fmt::format("--frames {}:{}", missing.front(), missing.back())
                  : "--frames FIRST:LAST for each missing range"));
  }

  // Every listed file in place, as the part recorded it.
  Manifest merged = shared;
  merged.part.reset();
  merged.frames.clear();
  merged.scene.clear();
  for (size_t i : order) {
    for (const ManifestFrame& f : parts[i].first.frames) {
      for (const ManifestFile& file : f.files) {
        const fs::path path = dir / file.file;
        if (!fs::is_regular_file(path, ec))
          throw ManifestError(fmt::format("{}, listed in {}, is missing: copy it from the machine that baked frames "
                                          "{}, or bake them again with --frames {}:{} --resume",
                                          path.string(), paths[i], FrameRangeText(*parts[i].first.part),
                                          parts[i].first.part->first, parts[i].first.part->last));
        const uint64_t bytes = fs::file_size(path);
        if (bytes != file.bytes || (options.verify_checksums && Sha256OfFile(path.string()) != file.sha256))
          throw ManifestError(fmt::format("{} does not match {} ({}): it is truncated, changed or from another bake; "
                                          "bake frame {} again with --frames {}:{} --resume",
                                          path.string(), paths[i],
                                          bytes != file.bytes ? fmt::format("{} bytes, listed with {}", bytes, file.bytes)
                                                              : "SHA-256 differs",
                                          f.number, f.number, f.number));
      }
      merged.frames.push_back(f);
    }
  }

  // What the merge writes, locked against any other live bake or merge
  // writing it (OutputLock), then new unless --force.
  std::vector<std::string> outputs = {ManifestFileName(std::nullopt)};
  if (merged.gltf.enabled)
    for (const char* ext : {".gltf", ".bin", ".glb"}) outputs.push_back(merged.gltf.name + ext);
  const OutputLock lock = OutputLock::Claim(options.dir, outputs);
  if (!options.force) {
    for (const std::string& name : outputs)
      if (fs::exists(dir / name, ec))
        throw OutputExistsError(fmt::format("{} already exists: pass --force to replace it", (dir / name).string()));
  }

  MergeResult result;
  for (size_t i : order) result.parts.push_back(paths[i]);
  result.frames = int(merged.frames.size());
  result.scene_files = WriteSceneAndManifest(merged, options.dir);
  result.manifest_path = (dir / ManifestFileName(std::nullopt)).string();
  return result;
}

}  // namespace skybake
