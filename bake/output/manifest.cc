#include "skybake/output/manifest.h"

#include "skybake/base/file_door.h"
#include "skybake/output/sha256.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <set>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "skybake/output/cloud_shadow_json.h"
#include "skybake/output/exr_io.h"
#include "skybake/output/gltf_scene.h"
#include "skybake/output/json_spool.h"
#include "skybake/output/output_lock.h"
#include "skybake/output/usd_layer.h"
#include "skybake/input/engine_preset.h"
#include "skybake/model/envmap.h"

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
  json file = {{"file", f.file}, {"kind", f.kind}, {"bytes", f.bytes}, {"sha256", f.sha256}};
  if (!f.face.empty()) file["face"] = f.face;
  return file;
}

json RangeJson(const FrameRange& r) {
  return {{"first_frame", r.first}, {"last_frame", r.last}, {"frames", r.count()}};
}

json MoonJson(const MoonRecord& m) {
  return {{"direction", VectorJson(m.direction)},
          {"elevation_deg", m.elevation_deg},
          {"azimuth_deg", m.azimuth_deg},
          {"phase_angle_deg", m.phase_angle_deg},
          {"illuminated_fraction", m.illuminated_fraction},
          {"bright_limb_deg", m.bright_limb_deg},
          {"angular_radius_rad", m.angular_radius_rad},
          {"top_illuminance_lux", m.top_illuminance_lux},
          {"illuminance_lux", m.illuminance_lux},
          {"irradiance", RgbJson(m.irradiance)},
          {"light", m.light}};
}

json FrameJsonWithoutMoon(const ManifestFrame& f);
json FrameJson(const ManifestFrame& f) {
  json frame = FrameJsonWithoutMoon(f);
  if (f.moon) frame["moon"] = MoonJson(*f.moon);
  return frame;
}

json FrameJsonWithoutMoon(const ManifestFrame& f) {
  json files = json::array();
  for (const ManifestFile& file : f.files) files.push_back(FileJson(file));
  json frame = {{"frame", f.number},
                {"style_sha256", f.style_sha256},
                {"time", f.time ? json(*f.time) : json(nullptr)},
                {"hours_from_start", f.hours_from_start},
                {"animation_time_s", f.animation_time_s},
                {"sun",
                 {{"elevation_deg", f.sun_elevation_deg},
                  {"azimuth_deg", f.sun_azimuth_deg},
                  {"direction", VectorJson(f.sun_direction)},
                  {"illuminance_lux", f.sun_illuminance_lux},
                  {"irradiance", RgbJson(f.sun_irradiance)}}},
                {"sh_irradiance_with_sun", ShJson(f.sh_irradiance_with_sun)},
                {"sh_irradiance_without_sun", ShJson(f.sh_irradiance_without_sun)},
                {"files", files}};
  if (f.cloud_shadow) frame["cloud_shadow"] = CloudShadowJson(*f.cloud_shadow);
  if (f.sun_angular_radius_rad) frame["sun"]["angular_radius_rad"] = *f.sun_angular_radius_rad;
  return frame;
}

json ManifestJson(const Manifest& m) {
  json j = {
      {"version", m.version},
      {"commit", m.commit},
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
      {"gltf",
       {{"enabled", m.gltf.enabled},
        {"name", m.gltf.name},
        {"dome", m.gltf.dome.dome == DomeShape::kHemisphere ? "hemisphere" : "sphere"},
        {"radius_m", m.gltf.dome.radius_m},
        {"flattening", m.gltf.dome.flattening},
        {"segments", m.gltf.dome.segments},
        {"texture",
         {{"file", m.gltf.texture_file}, {"width", m.gltf.texture_width}, {"height", m.gltf.texture_height}}}}},
  };
  if (m.usd.enabled) j["usd"] = {{"enabled", true}, {"name", m.usd.name}};
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
  // An integer in [lo, hi] (a real, a string or a value out of range fails).
  int64_t Integer(const json& object, const char* key, int64_t lo, int64_t hi) const {
    const json& v = Get<json>(object, key);
    if (v.is_number_unsigned()) {
      if (v.get<uint64_t>() <= uint64_t(hi) && int64_t(v.get<uint64_t>()) >= lo) return int64_t(v.get<uint64_t>());
    } else if (v.is_number_integer() && v.get<int64_t>() >= lo && v.get<int64_t>() <= hi) {
      return v.get<int64_t>();
    }
    Fail(fmt::format("'{}' is {}, not an integer in [{}, {}]", key, v.dump(), lo, hi));
  }
  int Int(const json& object, const char* key) const {
    return int(Integer(object, key, std::numeric_limits<int>::min(), std::numeric_limits<int>::max()));
  }
  glm::dvec3 Vector(const json& object, const char* key) const {
    std::vector<double> v = Get<std::vector<double>>(object, key);
    if (v.size() != 3) Fail(fmt::format("'{}' is not 3 numbers", key));
    return {v[0], v[1], v[2]};
  }
  ShRgb Sh(const json& object, const char* key) const {
    std::vector<std::vector<double>> rows = Get<std::vector<std::vector<double>>>(object, key);
    ShRgb sh{};
    if (rows.size() != sh.size()) Fail(fmt::format("'{}' is not {} rows", key, sh.size()));
    for (size_t i = 0; i < sh.size(); ++i) {
      if (rows[i].size() != 3) Fail(fmt::format("'{}' row {} is not 3 numbers", key, i));
      for (double v : rows[i])
        if (!(std::abs(v) <= 1e15)) Fail(fmt::format("'{}' row {} has {}, not a number in [-1e15, 1e15]", key, i, v));
      sh[i] = {rows[i][0], rows[i][1], rows[i][2]};
    }
    return sh;
  }
  // Frame numbers as a schedule gives them: from 1 to 9,999,999 +
  // 100,000 frames, a sequence of at most 100,000 (schedule.h).
  FrameRange Range(const json& object, const char* key) const {
    const json& r = Get<json>(object, key);
    FrameRange range{int(Integer(r, "first_frame", 1, kMaxFrameNumber)),
                     int(Integer(r, "last_frame", 1, kMaxFrameNumber))};
    if (range.last < range.first) Fail(fmt::format("'{}' ends before it starts", key));
    if (int64_t(range.last) - range.first >= kMaxSequenceFrames)
      Fail(fmt::format("'{}' spans more than the {} frames of a sequence", key, kMaxSequenceFrames));
    return range;
  }
  // A finite number in [lo, hi]: the values skybake writes for the key (the
  // style's ranges, configs/default.toml, and what follows from them).
  double Real(const json& object, const char* key, double lo, double hi) const {
    const json& v = Get<json>(object, key);
    if (!v.is_number()) Fail(fmt::format("'{}' has the wrong type", key));
    const double x = v.get<double>();
    if (!(x >= lo && x <= hi)) Fail(fmt::format("'{}' is {}, not a number in [{}, {}]", key, v.dump(), lo, hi));
    return x;
  }
  glm::dvec3 Bounded(const json& object, const char* key, double lo, double hi) const {
    const glm::dvec3 v = Vector(object, key);
    for (int i = 0; i < 3; ++i)
      if (!(v[i] >= lo && v[i] <= hi))
        Fail(fmt::format("'{}'[{}] is {}, not a number in [{}, {}]", key, i, v[i], lo, hi));
    return v;
  }
  [[noreturn]] void Fail(const std::string& what) const {
    throw ManifestError(
        fmt::format("{}: {}{}: not a skybake manifest, or one from another version", path_, where_, what));
  }
  // What an error names before the entry: "frame 12: " while a frame is read.
  void At(std::string where) const { where_ = std::move(where); }

  static constexpr int64_t kMaxFrameNumber = 9999999 + 100000;
  static constexpr int64_t kMaxSequenceFrames = 100000;

 private:
  std::string path_;
  mutable std::string where_;
};

// The ranges of the numbers a manifest records (Reader::Real): a sun or
// Moon up to 1e12 lux (10^4 W m^-2 nm^-1 of irradiance, the style's
// largest, is about 10^9 lux), SH coefficients up to 1e15, times up to 1e7
// (hours of a schedule or frame indices), EV100 within [-100, 100].
constexpr double kMaxLux = 1e12;
constexpr double kMaxSh = 1e15;
constexpr double kMaxTime = 1e7;

// The largest file a manifest may list: 2^53 bytes (8 PiB), the integers a
// JSON number holds exactly in every reader.
constexpr int64_t kMaxFileBytes = int64_t(1) << 53;

std::vector<ManifestFile> FilesOf(const Reader& r, const json& array) {
  if (!array.is_array()) r.Fail("a file list is not an array");
  std::vector<ManifestFile> files;
  for (const json& f : array) {
    files.push_back({r.Get<std::string>(f, "file"), r.Get<std::string>(f, "kind"),
                     uint64_t(r.Integer(f, "bytes", 0, kMaxFileBytes)), r.Get<std::string>(f, "sha256")});
    if (files.back().kind == "face") files.back().face = r.Get<std::string>(f, "face");
  }
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

// A name read from a manifest that is not the one skybake gives: the
// manifest was edited (or is hostile). Nothing is opened under it.
[[noreturn]] void FailName(const std::string& path, const std::string& where, const std::string& name,
                           const std::string& expected) {
  throw ManifestError(
      fmt::format("{}: {}: {} is not {}: the manifest was edited or is not skybake's; nothing was "
                  "read under that name. Bake the part again (with --force) to rewrite it",
                  path, where, EscapedText(name), expected));
}

}  // namespace

bool IsListedNameOk(const std::string& name) { return FolderNameProblem(name).empty() && IsPlainFileName(name); }

void CheckListedName(const std::string& manifest_path, const std::string& where, const std::string& name) {
  if (!IsListedNameOk(name)) FailName(manifest_path, where, name, "a plain file name of the manifest's folder");
}

namespace {

bool EndsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// An image-based-lighting file of a frame (IblFileNames, bake/output/ibl_files.cc), listed
// after the latlong and before the PNG: BASE_specular_mL.NNNN.exr per level
// or BASE_specular.NNNN.ktx2, BASE_irradiance.NNNN.exr/.ktx2, and the
// frame-independent BASE_dfg.exr/.ktx2. `stage` as in CheckNames (3: IBL).
void CheckIblName(const std::string& path, const std::string& where, int number_in_name, int number_width,
                  const ManifestFile& file, std::string& base, int& stage) {
  if (file.kind == "ibl_gltf") {
    // BASE_specular_mLEVEL_FACE.NNNN.png: the scene's EXT_lights_image_based faces (gltf_ibl.h).
    const std::string tail = FrameNumberSuffix(number_in_name, number_width) + ".png";
    std::string stem = EndsWith(file.file, tail) ? file.file.substr(0, file.file.size() - tail.size()) : "";
    const size_t face = stem.size() > 3 ? stem.size() - 3 : std::string::npos;
    const std::string face_name = face == std::string::npos ? "" : stem.substr(face);
    const bool face_ok = face_name == "_px" || face_name == "_nx" || face_name == "_py" || face_name == "_ny" ||
                         face_name == "_pz" || face_name == "_nz";
    if (face_ok) stem.resize(face);
    const size_t m = stem.rfind("_specular_m");
    const bool level_ok = m != std::string::npos && m > 0 && m + 11 < stem.size() &&
                          stem.find_first_not_of("0123456789", m + 11) == std::string::npos;
    if (stage > 3 || !IsListedNameOk(file.file) || !face_ok || !level_ok)
      FailName(path, where, file.file,
               fmt::format("the {} file skybake names for frame {} (BASE_specular_mLEVEL_FACE{})", file.kind,
                           number_in_name, tail));
    const std::string b = stem.substr(0, m);
    if (!base.empty() && b != base)
      FailName(path, where, file.file, fmt::format("a file of the frame's other files' basename '{}'", base));
    base = b;
    stage = 3;
    return;
  }
  const std::string number = file.kind == "ibl_dfg" ? std::string() : FrameNumberSuffix(number_in_name, number_width);
  const char* suffix = file.kind == "ibl_specular"     ? "_specular"
                       : file.kind == "ibl_irradiance" ? "_irradiance"
                                                       : "_dfg";
  const std::string shape = fmt::format("BASE{}{}.exr or .ktx2{}", suffix, number,
                                        file.kind == "ibl_specular" ? " (BASE_specular_mLEVEL... for EXR levels)" : "");
  std::string stem;
  for (const char* ext : {".exr", ".ktx2"})
    if (stem.empty() && EndsWith(file.file, number + ext))
      stem = file.file.substr(0, file.file.size() - number.size() - std::strlen(ext));
  if (stage > 3 || !IsListedNameOk(file.file) || stem.empty())
    FailName(path, where, file.file,
             fmt::format("the {} file skybake names for frame {} ({})", file.kind, number_in_name, shape));
  // An EXR specular level: strip its _mLEVEL.
  if (file.kind == "ibl_specular" && EndsWith(file.file, ".exr")) {
    const size_t m = stem.rfind("_m");
    const bool digits = m != std::string::npos && m + 2 < stem.size() &&
                        stem.find_first_not_of("0123456789", m + 2) == std::string::npos;
    if (!digits)
      FailName(path, where, file.file,
               fmt::format("the {} file skybake names for frame {} ({})", file.kind, number_in_name, shape));
    stem.resize(m);
  }
  if (!EndsWith(stem, suffix) || stem.size() == std::strlen(suffix))
    FailName(path, where, file.file,
             fmt::format("the {} file skybake names for frame {} ({})", file.kind, number_in_name, shape));
  const std::string b = stem.substr(0, stem.size() - std::strlen(suffix));
  if (!base.empty() && b != base)
    FailName(path, where, file.file, fmt::format("a file of the frame's other files' basename '{}'", base));
  base = b;
  stage = 3;
}

// Every name of a manifest is a plain file name and the one the bake gives
// its frame and kind: BASE_FACE.NNNN.exr (six faces), BASE_cube.NNNN.exr,
// BASE_latlong.NNNN.exr, the IBL files (CheckIblName), BASE_cloudshadow.NNNN.exr, BASE_latlong.NNNN.png,
// in that order, one BASE per frame; the scene is NAME.gltf, NAME.bin, NAME.glb; the texture a PNG.
void CheckNames(const std::string& path, const Manifest& m) {
  std::map<std::string, std::string> face_names;  // "+X" -> "px": the same in every frame
  if (!IsListedNameOk(m.gltf.name)) FailName(path, "gltf.name", m.gltf.name, "a plain file name");
  if (!IsListedNameOk(m.gltf.texture_file) || !EndsWith(m.gltf.texture_file, ".png"))
    FailName(path, "gltf.texture.file", m.gltf.texture_file, "a plain file name of a PNG in the folder");
  // Every frame number of a sequence has its width (FrameNumberWidth).
  const int number_width = FrameNumberWidth(m.sequence ? m.sequence->last : 0);
  for (const ManifestFrame& f : m.frames) {
    const std::string where = fmt::format("frame {}", f.number);
    const std::string number = FrameNumberSuffix(f.number, number_width);
    std::string base;
    std::vector<std::string> faces;
    int stage = 0;  // 0 faces, 1 cube, 2 latlong, 3 IBL, 4 png, 5 done: the order files are written in
    auto stem_of = [&](const ManifestFile& file, const char* ext, const char* what) {
      const std::string tail = number + ext;
      if (!IsListedNameOk(file.file) || !EndsWith(file.file, tail) || file.file.size() == tail.size())
        FailName(path, where, file.file,
                 fmt::format("the {} file skybake names for frame {} (...{})", what, f.number, tail));
      return file.file.substr(0, file.file.size() - tail.size());
    };
    auto with_suffix = [&](const ManifestFile& file, const std::string& stem, const char* suffix, const char* what,
                           int at) {
      if (stage > at || !EndsWith(stem, suffix) || stem.size() == std::strlen(suffix))
        FailName(path, where, file.file,
                 fmt::format("the {} file skybake names for frame {} (BASE{}{})", what, f.number, suffix, number));
      const std::string b = stem.substr(0, stem.size() - std::strlen(suffix));
      if (!base.empty() && b != base)
        FailName(path, where, file.file, fmt::format("a file of the frame's other files' basename '{}'", base));
      base = b;
      stage = at + 1;
    };
    for (const ManifestFile& file : f.files) {
      if (file.kind == "face") {
        if (stage > 0 || faces.size() == 6)
          FailName(path, where, file.file, "one of six face files listed before the frame's other files");
        if (file.face != CubeFaceLabel(int(faces.size())))
          FailName(path, where, file.face,
                   fmt::format("the face of the frame's face file {} ({}: +X, -X, +Y, -Y, +Z, -Z in that order)",
                               faces.size() + 1, CubeFaceLabel(int(faces.size()))));
        faces.push_back(stem_of(file, ".exr", "face"));
      } else if (file.kind == "cube") {
        with_suffix(file, stem_of(file, ".exr", "cube strip"), "_cube", "cube strip", 1);
      } else if (file.kind == "latlong") {
        with_suffix(file, stem_of(file, ".exr", "latlong"), "_latlong", "latlong", 2);
      } else if (file.kind == "ibl_specular" || file.kind == "ibl_irradiance" || file.kind == "ibl_dfg" ||
                 file.kind == "ibl_gltf") {
        CheckIblName(path, where, f.number, number_width, file, base, stage);
      } else if (file.kind == "engine") {
        // BASE_ENGINE_SUFFIX.NNNN.exr (engine_preset.h), after the IBL files.
        const std::optional<std::string> b = EngineFileBase(file.file, f.number, number_width);
        if (stage > 4 || !IsListedNameOk(file.file) || !b || b->empty())
          FailName(path, where, file.file,
                   fmt::format("an engine preset's file skybake names for frame {} "
                               "(BASE_ENGINE_SUFFIX{}.exr)",
                               f.number, number));
        if (!base.empty() && *b != base)
          FailName(path, where, file.file, fmt::format("a file of the frame's other files' basename '{}'", base));
        base = *b;
        stage = 4;
      } else if (file.kind == "preview" || file.kind == "gltf_texture") {
        with_suffix(file, stem_of(file, ".png", "preview"), "_latlong", "preview", 4);
      } else if (file.kind == "cloud_shadow") {
        with_suffix(file, stem_of(file, ".exr", "cloud shadow"), "_cloudshadow", "cloud shadow", 3);
      } else {
        FailName(path, where, file.kind,
                 "a kind of file skybake writes (face, cube, latlong, ibl_specular, ibl_irradiance, ibl_dfg, ibl_gltf, "
                 "engine, preview, gltf_texture, cloud_shadow)");
      }
    }
    if (!faces.empty() && faces.size() != 6)
      FailName(path, where, faces.back(),
               "one of six face files (the frame lists " + std::to_string(faces.size()) + ")");
    // The faces share the frame's basename (the other files', else the
    // scene's name, else their common prefix) and differ from each other.
    if (!faces.empty()) {
      if (base.empty()) {
        base = m.gltf.name;
        for (const std::string& face : faces)
          if (face.compare(0, base.size() + 1, base + "_") != 0) base.clear();
        if (base.empty()) {
          for (size_t cut = faces[0].rfind('_'); cut != std::string::npos && cut > 0 && base.empty();
               cut = faces[0].rfind('_', cut - 1)) {
            const std::string candidate = faces[0].substr(0, cut);
            bool all = true;
            for (const std::string& face : faces) all = all && face.compare(0, cut + 1, candidate + "_") == 0;
            if (all) base = candidate;
          }
        }
      }
      std::set<std::string> names;
      for (size_t i = 0; i < faces.size(); ++i) {
        const std::string face = faces[i];
        if (base.empty() || face.compare(0, base.size() + 1, base + "_") != 0 || face.size() == base.size() + 1 ||
            !names.insert(face).second || face == base + "_cube" || face == base + "_latlong")
          FailName(path, where, f.files[i].file,
                   fmt::format("a face file skybake names for frame {} (BASE_FACE{}.exr, six different faces)",
                               f.number, number));
        // A face keeps its name in every frame: a face file renamed to
        // another face's name (and listed so) differs from the other frames.
        const std::string label = CubeFaceLabel(int(i));
        const std::string face_name = face.substr(base.size() + 1);
        auto [known, inserted] = face_names.emplace(label, face_name);
        if (!inserted && known->second != face_name)
          FailName(path, where, f.files[i].file,
                   fmt::format("the {} face file of frame {}: the other frames name that face '{}' ({}_{}{}.exr)",
                               label, f.number, known->second, base, known->second, number));
      }
    }
  }
  static const std::map<std::string, std::string> kSceneExtension = {
      {"gltf", ".gltf"}, {"gltf_bin", ".bin"}, {"glb", ".glb"}, {"gltf_ground", "_ground.png"}};
  if (m.usd.enabled && !IsListedNameOk(m.usd.name)) FailName(path, "usd.name", m.usd.name, "a plain file name");
  for (const ManifestFile& file : m.scene) {
    if (file.kind == "usd" && m.usd.enabled && file.file == m.usd.name + ".usda") continue;
    auto it = kSceneExtension.find(file.kind);
    if (it == kSceneExtension.end() || file.file != m.gltf.name + it->second)
      FailName(path, "scene", file.file,
               fmt::format("a scene file skybake names ({}.gltf, .bin, .glb, _ground.png, .usda)", m.gltf.name));
  }
}

}  // namespace

std::string SequenceIdentityLine(int number, const std::string& time_iso8601, const glm::dvec3& sun,
                                 const std::string& style_sha256) {
  return fmt::format("{} {} {:.17g} {:.17g} {:.17g} {}\n", number, time_iso8601, sun.x, sun.y, sun.z, style_sha256);
}

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
  f.moon = frame.moon;
  f.sh_irradiance_without_sun = frame.sh_irradiance_without_sun;
  int faces = 0;  // a frame lists its faces first, +X to -Z (WriteViewExrs)
  for (const BakedFile& file : frame.files) {
    f.files.push_back({fs::path(file.path).filename().string(), file.kind, file.bytes, file.sha256});
    if (file.kind == "face") f.files.back().face = CubeFaceLabel(faces++);
  }
  f.cloud_shadow = frame.cloud_shadow;
  return f;
}

std::string ManifestText(const Manifest& manifest) { return ManifestJson(manifest).dump(2) + "\n"; }

std::string ManifestFrameText(const ManifestFrame& frame) { return FrameJson(frame).dump(2); }

void WriteManifest(const Manifest& manifest, const std::string& path) {
  WriteFileAtomically(path, ManifestText(manifest));
}

namespace {

MoonRecord MoonOf(const Reader& r, const json& moon) {
  MoonRecord mr;
  mr.direction = r.Bounded(moon, "direction", -1.0, 1.0);
  mr.elevation_deg = r.Real(moon, "elevation_deg", -90.0, 90.0);
  mr.azimuth_deg = r.Real(moon, "azimuth_deg", -360.0, 360.0);
  mr.phase_angle_deg = r.Real(moon, "phase_angle_deg", -360.0, 360.0);
  mr.illuminated_fraction = r.Real(moon, "illuminated_fraction", 0.0, 1.0);
  mr.bright_limb_deg = r.Real(moon, "bright_limb_deg", -360.0, 360.0);
  mr.angular_radius_rad = r.Real(moon, "angular_radius_rad", 0.0, 0.5);
  mr.top_illuminance_lux = r.Real(moon, "top_illuminance_lux", 0.0, kMaxLux);
  mr.illuminance_lux = r.Real(moon, "illuminance_lux", 0.0, kMaxLux);
  const glm::dvec3 moon_irradiance = r.Bounded(moon, "irradiance", 0.0, kMaxLux);
  mr.irradiance = {moon_irradiance.x, moon_irradiance.y, moon_irradiance.z};
  mr.light = r.Get<bool>(moon, "light");
  return mr;
}

ManifestFrame FrameOf(const Reader& r, const json& f) {
  ManifestFrame frame;
  frame.number = r.Int(f, "frame");
  r.At(fmt::format("frame {}: ", frame.number));
  frame.style_sha256 = r.Get<std::string>(f, "style_sha256");
  if (f.contains("time") && !f["time"].is_null()) frame.time = r.Get<std::string>(f, "time");
  frame.hours_from_start = r.Real(f, "hours_from_start", 0.0, kMaxTime);
  frame.animation_time_s = r.Real(f, "animation_time_s", 0.0, kMaxTime);
  const json& sun = r.Get<json>(f, "sun");
  frame.sun_elevation_deg = r.Real(sun, "elevation_deg", -90.0, 90.0);
  frame.sun_azimuth_deg = r.Real(sun, "azimuth_deg", -1e5, 1e5);
  frame.sun_direction = r.Bounded(sun, "direction", -1.0, 1.0);
  frame.sun_illuminance_lux = r.Real(sun, "illuminance_lux", 0.0, kMaxLux);
  const glm::dvec3 irradiance = r.Bounded(sun, "irradiance", 0.0, kMaxLux);  // output units x sr
  frame.sun_irradiance = {irradiance.x, irradiance.y, irradiance.z};
  if (sun.contains("angular_radius_rad")) frame.sun_angular_radius_rad = r.Real(sun, "angular_radius_rad", 1e-6, 0.5);
  frame.sh_irradiance_with_sun = r.Sh(f, "sh_irradiance_with_sun");
  frame.sh_irradiance_without_sun = r.Sh(f, "sh_irradiance_without_sun");
  if (f.contains("moon")) frame.moon = MoonOf(r, r.Get<json>(f, "moon"));
  frame.files = FilesOf(r, r.Get<json>(f, "files"));
  if (f.contains("cloud_shadow")) frame.cloud_shadow = CloudShadowFromJson(f["cloud_shadow"]);
  r.At("");
  return frame;
}

ManifestScene SceneOf(const Reader& r, const json& gltf) {
  ManifestScene scene;
  scene.enabled = r.Get<bool>(gltf, "enabled");
  scene.name = r.Get<std::string>(gltf, "name");
  scene.dome.dome = r.Get<std::string>(gltf, "dome") == "hemisphere" ? DomeShape::kHemisphere : DomeShape::kSphere;
  scene.dome.radius_m = r.Real(gltf, "radius_m", 1e-3, 1e8);  // the style's gltf.radius_m
  scene.dome.flattening = r.Real(gltf, "flattening", 0.0, std::nextafter(1.0, 0.0));
  scene.dome.segments = int(r.Integer(gltf, "segments", 3, 4096));
  scene.dome.enabled = scene.enabled;
  const json& texture = r.Get<json>(gltf, "texture");
  scene.texture_file = r.Get<std::string>(texture, "file");
  scene.texture_width = int(r.Integer(texture, "width", 1, 16384));
  scene.texture_height = int(r.Integer(texture, "height", 1, 8192));
  return scene;
}

}  // namespace

// A manifest's text through the door (file_door.h): a regular file, not a
// link, at most kMaxManifestBytes (100,000 frames of all outputs are about
// 300 MiB).
constexpr uint64_t kMaxManifestBytes = uint64_t(1) << 30;

std::string ManifestBytes(const std::string& path) {
  std::string bytes;
  if (const std::string problem = ReadRegularFile(path, kMaxManifestBytes, FileLinks::kRefuse, bytes); !problem.empty())
    throw ManifestSyntaxError(fmt::format("cannot read {}: it {}", EscapedText(path), problem));
  return bytes;
}

Manifest ReadManifest(const std::string& path, ManifestNames names) {
  json j = json::parse(ManifestBytes(path), nullptr, false);
  Reader r(path);
  if (j.is_discarded() || !j.is_object())
    throw ManifestSyntaxError(
        fmt::format("{}: invalid JSON: not a skybake manifest, or one from another version", path));
  Manifest m;
  m.version = r.Get<std::string>(j, "version");
  // Absent from the manifests of skybake before it recorded its commit.
  if (j.contains("commit")) m.commit = r.Get<std::string>(j, "commit");
  m.style = r.Get<std::string>(j, "style");
  m.schedule = r.Get<std::string>(j, "schedule");
  m.sequence_sha256 = r.Get<std::string>(j, "sequence_sha256");
  m.units = r.Get<std::string>(j, "units");
  m.exposure_ev100 = r.Real(j, "exposure_ev100", -100.0, 100.0);
  m.exposure_source = r.Get<std::string>(j, "exposure_source");
  m.texture_frame = r.Int(j, "texture_frame");
  m.half_scale = r.Real(j, "half_scale", 1e-30, 1e30);
  m.gltf = SceneOf(r, r.Get<json>(j, "gltf"));
  if (j.contains("usd")) {
    const json& usd = r.Get<json>(j, "usd");
    m.usd.enabled = r.Get<bool>(usd, "enabled");
    m.usd.name = r.Get<std::string>(usd, "name");
  }
  if (j.contains("place"))
    m.place = GeoLocation{r.Get<double>(j["place"], "latitude_deg"), r.Get<double>(j["place"], "longitude_deg")};
  if (j.contains("sequence")) m.sequence = r.Range(j, "sequence");
  if (j.contains("part")) m.part = r.Range(j, "part");
  for (const json& f : r.Get<json>(j, "frames")) m.frames.push_back(FrameOf(r, f));
  m.complete = r.Get<bool>(j, "complete");
  m.scene = FilesOf(r, r.Get<json>(j, "scene"));
  if (names == ManifestNames::kChecked) CheckNames(path, m);
  return m;
}

namespace {

double Degrees(double radians) { return radians * 180.0 / M_PI; }

// The USD layer of the manifest's frames: each frame's latlong EXR (and the
// scale in its header), sun, Moon and provenance.
UsdLayerDescription UsdLayerOf(const Manifest& manifest, const std::string& out_dir) {
  UsdLayerDescription layer;
  layer.name = manifest.usd.name;
  layer.out_dir = out_dir;
  layer.sequence = manifest.sequence.has_value();
  layer.version = manifest.version;
  layer.commit = manifest.commit;
  layer.style = manifest.style;
  layer.schedule = manifest.schedule;
  layer.sequence_sha256 = manifest.sequence_sha256;
  for (const ManifestFrame& f : manifest.frames) {
    UsdFrame frame;
    frame.number = f.number;
    for (const ManifestFile& file : f.files)
      if (file.kind == "latlong") frame.latlong_file = file.file;
    if (frame.latlong_file.empty())
      throw OutputError(fmt::format("frame {} has no latlong EXR for the USD layer's dome", f.number));
    frame.texture_scale = ExrSkybakeScale((fs::path(out_dir) / frame.latlong_file).string());
    frame.color_space = ExrSkybakeColorSpace((fs::path(out_dir) / frame.latlong_file).string());
    frame.time = f.time.value_or("");
    frame.sun_elevation_deg = f.sun_elevation_deg;
    frame.sun_azimuth_deg = f.sun_azimuth_deg;
    frame.style_sha256 = f.style_sha256;
    if (!f.sun_angular_radius_rad)
      throw OutputError(fmt::format("frame {} has no sun.angular_radius_rad for the USD layer's Sun", f.number));
    frame.sun = {f.sun_direction, f.sun_illuminance_lux, f.sun_irradiance, Degrees(2.0 * *f.sun_angular_radius_rad)};
    if (f.moon && f.moon->light)
      frame.moon = UsdDistantKey{f.moon->direction, f.moon->illuminance_lux, f.moon->irradiance,
                                 Degrees(2.0 * f.moon->angular_radius_rad)};
    layer.frames.push_back(std::move(frame));
  }
  return layer;
}

}  // namespace

std::vector<BakedFile> WriteScene(Manifest& manifest, const std::string& out_dir) {
  // Scene: the dome textured with the reference frame, the sun (animated
  // for a sequence), all from the manifest's frames.
  std::vector<BakedFile> scene_files;
  manifest.scene.clear();
  if (manifest.gltf.enabled && !manifest.frames.empty()) {
    // The provenance's frames as text, one frame's small JSON at a time:
    // the whole list as one JSON value (and again in the glTF writer's
    // forms) cost about 60 KiB a frame at the end of a long sequence.
    std::string frames_compact, frames_pretty;
    SceneDescription scene;
    scene.name = manifest.gltf.name;
    scene.out_dir = out_dir;
    scene.texture_file = manifest.gltf.texture_file;
    scene.texture_width = manifest.gltf.texture_width;
    scene.texture_height = manifest.gltf.texture_height;
    scene.dome = manifest.gltf.dome;
    for (size_t i = 0; i < manifest.frames.size(); ++i) {
      const ManifestFrame& f = manifest.frames[i];
      if (f.number == manifest.texture_frame) {
        scene.light_frame = int(i);
        // EXT_lights_image_based: the texture frame's RGBD faces (gltf_ibl.h).
        for (const ManifestFile& file : f.files)
          if (file.kind == "ibl_gltf") scene.ibl_images.push_back(file.file);
        scene.ibl_sh = f.sh_irradiance_without_sun;
        // The ground plane: the texture frame's cloud shadow map (gltf_scene.h "ground").
        for (const ManifestFile& file : f.files)
          if (file.kind == "cloud_shadow" && f.cloud_shadow) {
            scene.ground_texture_file = manifest.gltf.name + "_ground.png";
            WriteCloudShadowGroundPng((fs::path(out_dir) / file.file).string(),
                                      (fs::path(out_dir) / scene.ground_texture_file).string());
            scene.ground = f.cloud_shadow;
          }
      }
      SceneSun sun;
      sun.time_s = f.animation_time_s;
      sun.direction = f.sun_direction;
      sun.illuminance_lux = f.sun_illuminance_lux;
      double peak = std::max({f.sun_irradiance[0], f.sun_irradiance[1], f.sun_irradiance[2]});
      if (peak > 0.0) sun.color = {f.sun_irradiance[0] / peak, f.sun_irradiance[1] / peak, f.sun_irradiance[2] / peak};
      scene.suns.push_back(sun);
      if (f.moon && f.moon->light) scene.moons.push_back(SceneMoonOf(*f.moon, f.animation_time_s));
      json extras = {{"frame", f.number},
                     {"time", f.time.value_or("")},
                     {"animation_time_s", f.animation_time_s},
                     {"sun_direction", VectorJson(f.sun_direction)},
                     {"sun_illuminance_lux", f.sun_illuminance_lux},
                     {"sh_irradiance_with_sun", ShJson(f.sh_irradiance_with_sun)},
                     {"sh_irradiance_without_sun", ShJson(f.sh_irradiance_without_sun)}};
      if (f.moon && f.moon->light) extras["moon"] = MoonJson(*f.moon);
      frames_compact += (i == 0 ? "" : ",") + extras.dump();
      frames_pretty += (i == 0 ? "\n    " : ",\n    ") + IndentedJson(extras.dump(2), "    ");
    }
    const json provenance = {{"version", manifest.version},
                             {"style", manifest.style},
                             {"schedule", manifest.schedule},
                             {"units", manifest.units},
                             {"exposure_ev100", manifest.exposure_ev100},
                             {"texture_frame", manifest.texture_frame},
                             {"sh_basis", kShBasis},
                             {"frames", json::array()}};
    // The frames in place of the empty list: the bytes dump() and dump(2)
    // give the whole object (json_spool.h).
    scene.extras_json = SplicedJson(provenance.dump(), "\"frames\":[]", "\"frames\":[" + frames_compact + "]");
    frames_compact = {};
    scene.extras_json_pretty =
        SplicedJson(provenance.dump(2), "\n  \"frames\": []", "\n  \"frames\": [" + frames_pretty + "\n  ]");
    WrittenScene written = WriteGltfScene(scene);
    std::vector<std::pair<std::string, const char*>> files = {
        {written.gltf_path, "gltf"}, {written.bin_path, "gltf_bin"}, {written.glb_path, "glb"}};
    if (scene.ground) files.push_back({(fs::path(out_dir) / scene.ground_texture_file).string(), "gltf_ground"});
    for (auto [path, kind] : files) {
      scene_files.push_back({path, kind, WrittenFileSize(path), Sha256OfFile(path)});
      manifest.scene.push_back(
          {fs::path(path).filename().string(), kind, scene_files.back().bytes, scene_files.back().sha256});
    }
  }
  if (manifest.usd.enabled && !manifest.frames.empty()) {
    const std::string path = WriteUsdLayer(UsdLayerOf(manifest, out_dir));
    scene_files.push_back({path, "usd", WrittenFileSize(path), Sha256OfFile(path)});
    manifest.scene.push_back(
        {fs::path(path).filename().string(), "usd", scene_files.back().bytes, scene_files.back().sha256});
  }
  return scene_files;
}

std::vector<BakedFile> WriteSceneAndManifest(Manifest& manifest, const std::string& out_dir) {
  std::vector<BakedFile> scene_files = WriteScene(manifest, out_dir);
  // Manifest: written last, once every file it lists is in place.
  manifest.complete = true;
  WriteManifest(manifest, (fs::path(out_dir) / ManifestFileName(std::nullopt)).string());
  return scene_files;
}

namespace {

json TimingsStageJson(const StageReport& s) { return {{"stage", s.name}, {"seconds", s.seconds}}; }

json TimingsFrameJson(const FrameResult& f) {
  json passes = json::array();
  for (const PassTiming& t : f.gpu_passes) passes.push_back({{"name", t.name}, {"gpu_ms", t.gpu_ms}});
  return {{"frame", f.number}, {"render_s", f.render_seconds}, {"write_s", f.write_seconds}, {"gpu_passes", passes}};
}

}  // namespace

std::string TimingsStageText(const StageReport& stage) { return TimingsStageJson(stage).dump(2); }

std::string TimingsFrameText(const FrameResult& frame) { return TimingsFrameJson(frame).dump(2); }

void WriteTimings(const BakeResult& result, const std::string& out_dir, double total_seconds, const std::string& path,
                  const TimingsSpools* spools) {
  json stages = json::array();
  for (const StageReport& s : result.stages) stages.push_back(TimingsStageJson(s));
  json frames = json::array();
  for (const FrameResult& f : result.frames) frames.push_back(TimingsFrameJson(f));
  json timings = {{"out_dir", out_dir},
                  {"renderer_builds", result.renderer_builds},
                  {"manifest_writes", result.manifest_writes},
                  {"manifest_bytes_written", result.manifest_bytes_written},
                  {"total_s", total_seconds},
                  {"stages", stages},
                  {"frames", frames}};
  if (!spools) return WriteFileAtomically(path, timings.dump(2) + "\n");
  // The entries on disk (a bake that keeps no frame records: result's lists are empty).
  WriteJsonWithSpools(path, timings.dump(2) + "\n", {{"stages", &spools->stages}, {"frames", &spools->frames}});
}

namespace {

// The parts of a merge: every manifest.shard-FIRST-LAST.json of the folder,
// read and checked (ReadManifest), each with the JSON all parts share, in
// the order of their first frames.
struct MergeParts {
  std::vector<std::string> paths;
  std::vector<std::pair<Manifest, json>> parts;
  std::vector<size_t> order;  // indices into paths and parts, by first frame
  const Manifest& operator[](size_t i) const { return parts[i].first; }
};

MergeParts ReadMergeParts(const MergeOptions& options) {
  const fs::path dir(options.dir);
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw ManifestError(fmt::format("{} is not a folder: give the folder the shards baked into", options.dir));
  static const std::regex kPartName(R"(manifest\.shard-\d+-\d+\.json)");
  MergeParts p;
  for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (e.is_regular_file() && std::regex_match(name, kPartName)) p.paths.push_back(e.path().string());
  }
  if (p.paths.empty())
    throw ManifestError(
        fmt::format("no shard manifests (manifest.shard-FIRST-LAST.json) in {}: bake with --shard "
                    "I/N or --frames A:B into it first",
                    options.dir));
  for (const std::string& path : p.paths) {
    Manifest m = ReadManifest(path);
    p.parts.emplace_back(std::move(m), SharedPart(json::parse(ManifestBytes(path))));
  }
  p.order.resize(p.parts.size());
  for (size_t i = 0; i < p.order.size(); ++i) p.order[i] = i;
  for (size_t i = 0; i < p.parts.size(); ++i)
    if (!p[i].part || !p[i].sequence)
      throw ManifestError(fmt::format("{} is not the manifest of a part of a sequence", p.paths[i]));
  std::sort(p.order.begin(), p.order.end(), [&](size_t a, size_t b) { return p[a].part->first < p[b].part->first; });
  return p;
}

// One bake: the parts agree on everything but their frames.
void CheckOneBake(const MergeParts& p) {
  const size_t first = p.order.front();
  for (size_t i : p.order) {
    const json& a = p.parts[first].second;
    const json& b = p.parts[i].second;
    if (a == b) continue;
    std::string key;
    for (const json* side : {&a, &b})
      for (auto it = side->begin(); it != side->end() && key.empty(); ++it)
        if (!a.contains(it.key()) || !b.contains(it.key()) || a[it.key()] != b[it.key()]) key = it.key();
    throw ManifestError(fmt::format(
        "{} and {} come from different bakes: their '{}' differs ({} vs {}): bake every shard with the same "
        "skybake version, style, schedule, --set and --size into one folder",
        p.paths[first], p.paths[i], key, a.contains(key) ? a[key].dump() : "none",
        b.contains(key) ? b[key].dump() : "none"));
  }
}

// Every frame of the sequence once: complete parts, no overlap, no gap.
void CheckEveryFrameOnce(const MergeParts& p, const FrameRange& sequence, const std::string& dir) {
  std::map<int, size_t> owner;  // frame number -> part
  for (size_t i : p.order) {
    const Manifest& m = p[i];
    if (!m.complete || int(m.frames.size()) != m.part->count())
      throw ManifestError(
          fmt::format("{} is incomplete ({} of frames {} baked): finish it by running its bake "
                      "again with --resume",
                      p.paths[i], m.frames.size(), FrameRangeText(*m.part)));
    for (const ManifestFrame& f : m.frames) {
      if (!m.part->Contains(f.number) || !sequence.Contains(f.number))
        throw ManifestError(
            fmt::format("{} lists frame {}, outside its part {}", p.paths[i], f.number, FrameRangeText(*m.part)));
      auto [it, inserted] = owner.emplace(f.number, i);
      if (!inserted)
        throw ManifestError(
            fmt::format("frame {} is in both {} and {}: the shards overlap; remove one of the two "
                        "manifests (with its files if they differ) and merge again",
                        f.number, p.paths[it->second], p.paths[i]));
    }
  }
  std::vector<int> missing;
  for (int n = sequence.first; n <= sequence.last; ++n)
    if (!owner.count(n)) missing.push_back(n);
  if (missing.empty()) return;
  const bool one_range = missing.back() - missing.front() + 1 == int(missing.size());
  throw ManifestError(fmt::format(
      "frame{} {} of {} {} missing: no shard manifest in {} lists {}: bake {} into {} (the missing --shard, or {}), "
      "then merge again",
      missing.size() == 1 ? "" : "s", RangesText(missing), FrameRangeText(sequence), missing.size() == 1 ? "is" : "are",
      dir, missing.size() == 1 ? "it" : "them", missing.size() == 1 ? "it" : "them", dir,
      one_range ? fmt::format("--frames {}:{}", missing.front(), missing.back())
                : "--frames FIRST:LAST for each missing range"));
}

// A listed file in place, as part `part_path` recorded it for frame `f`.
void CheckListedFile(const fs::path& dir, const ManifestFile& file, const ManifestFrame& f, const Manifest& part,
                     const std::string& part_path, bool verify_checksums) {
  const fs::path path = dir / file.file;  // a plain name (ReadManifest): inside dir
  // Through the door (file_door.h): a link is not followed, and a FIFO or a
  // device is refused without being opened for long.
  uint64_t bytes = 0;
  const std::string problem = RegularFileSize(path.string(), bytes);
  if (problem == "no such file")
    throw ManifestError(
        fmt::format("{}, listed in {}, is missing: copy it from the machine that baked frames "
                    "{}, or bake them again with --frames {}:{} --resume",
                    path.string(), part_path, FrameRangeText(*part.part), part.part->first, part.part->last));
  if (!problem.empty())
    throw ManifestError(
        fmt::format("{}, listed in {}, {}: put the file itself in the "
                    "folder",
                    path.string(), part_path, problem));
  if (bytes != file.bytes || (verify_checksums && Sha256OfFile(path.string()) != file.sha256))
    throw ManifestError(fmt::format(
        "{} does not match {} ({}): it is truncated, changed or from another bake; "
        "bake frame {} again with --frames {}:{} --resume",
        path.string(), part_path,
        bytes != file.bytes ? fmt::format("{} bytes, listed with {}", bytes, file.bytes) : "SHA-256 differs", f.number,
        f.number, f.number));
}

// The frames are the ones the parts say they baked: their numbers, times,
// suns and styles give the parts' sequence_sha256, and the scene's texture
// is the texture frame's PNG.
void CheckMergedIdentity(const Manifest& merged, const std::string& dir) {
  std::string identity;
  std::string texture;
  for (const ManifestFrame& f : merged.frames) {
    identity += SequenceIdentityLine(f.number, f.time.value_or(""), f.sun_direction, f.style_sha256);
    if (f.number == merged.texture_frame)
      for (const ManifestFile& file : f.files)
        if (file.kind == "preview" || file.kind == "gltf_texture") texture = file.file;
  }
  if (Sha256OfText(identity) != merged.sequence_sha256)
    throw ManifestError(
        fmt::format("the frames of the shard manifests in {} (their numbers, times, suns and "
                    "style_sha256) do not give their sequence_sha256: a manifest was edited, or "
                    "the parts come from different bakes; bake the parts again with --force",
                    dir));
  if (merged.gltf.enabled && texture != merged.gltf.texture_file)
    throw ManifestError(
        fmt::format("gltf.texture.file {} of the shard manifests in {} is not the PNG of texture "
                    "frame {} ({}): a manifest was edited; bake the parts again with --force",
                    EscapedText(merged.gltf.texture_file), dir, merged.texture_frame,
                    texture.empty() ? "none" : EscapedText(texture)));
}

}  // namespace

MergeResult MergeShardManifests(const MergeOptions& options) {
  const fs::path dir(options.dir);
  std::error_code ec;
  // The parts, from one bake, with every frame once.
  const MergeParts parts = ReadMergeParts(options);
  CheckOneBake(parts);
  const Manifest& shared = parts[parts.order.front()];
  CheckEveryFrameOnce(parts, *shared.sequence, options.dir);

  // The names of all parts together (one name per face in every frame),
  // then every listed file in place, as the part recorded it.
  Manifest merged = shared;
  merged.part.reset();
  merged.frames.clear();
  merged.scene.clear();
  for (size_t i : parts.order)
    for (const ManifestFrame& f : parts[i].frames) merged.frames.push_back(f);
  CheckNames(fmt::format("the shard manifests in {}", options.dir), merged);
  for (size_t i : parts.order)
    for (const ManifestFrame& f : parts[i].frames)
      for (const ManifestFile& file : f.files)
        CheckListedFile(dir, file, f, parts[i], parts.paths[i], options.verify_checksums);
  CheckMergedIdentity(merged, options.dir);

  // What the merge writes, locked against any other live bake or merge
  // writing it (OutputLock), then new unless --force.
  std::vector<std::string> outputs = {ManifestFileName(std::nullopt)};
  if (merged.gltf.enabled)
    for (const char* ext : {".gltf", ".bin", ".glb"}) outputs.push_back(merged.gltf.name + ext);
  if (merged.usd.enabled) outputs.push_back(merged.usd.name + ".usda");
  const OutputLock lock = OutputLock::Claim(options.dir, outputs);
  if (!options.force) {
    for (const std::string& name : outputs)
      // A link counts as a file, a dangling one too (exists() follows it).
      if (fs::exists(fs::symlink_status(dir / name, ec)))
        throw OutputExistsError(fmt::format("{} already exists: pass --force to replace it", (dir / name).string()));
  }

  MergeResult result;
  for (size_t i : parts.order) result.parts.push_back(parts.paths[i]);
  result.frames = int(merged.frames.size());
  result.scene_files = WriteSceneAndManifest(merged, options.dir);
  result.manifest_path = (dir / ManifestFileName(std::nullopt)).string();
  return result;
}

}  // namespace skybake
