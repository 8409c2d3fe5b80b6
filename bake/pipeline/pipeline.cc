#include "skybake/pipeline/pipeline.h"

#include "skybake/pipeline/pass_plan.h"

#include "renderer_cache.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <filesystem>
#include <fstream>
#include <future>
#include <malloc.h>
#include <thread>
#include <map>
#include <memory>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "skybake/model/envmap.h"
#include "skybake/output/ibl_files.h"
#include "skybake/output/sha256.h"
#include "skybake/output/exr_io.h"
#include "skybake/output/cloud_shadow_file.h"
#include "skybake/output/gltf_scene.h"
#include "skybake/gpu/ibl.h"
#include "skybake/model/sh.h"
#include "skybake/output/manifest.h"
#include "skybake/output/output_lock.h"
#include "skybake/model/tonemap.h"
#include "skybake/input/engine_preset.h"
#include "skybake/pipeline/engine_files.h"
#include "skybake/output/gltf_ibl.h"
#include "skybake/pipeline/night_sky.h"

namespace skybake {
namespace {

using Clock = std::chrono::steady_clock;
using nlohmann::json;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

class StageTimer {
 public:
  StageTimer(BakeResult& result, const ProgressCallback& progress)
      : result_(result), progress_(progress), start_(Clock::now()) {}
  void Finish(const std::string& name, const std::string& detail = "") {
    Clock::time_point now = Clock::now();
    StageReport report{name, std::chrono::duration<double>(now - start_).count(), detail};
    result_.stages.push_back(report);
    if (progress_) progress_(report);
    start_ = now;
  }
  // The first `seconds` of the time since the last Finish, timed elsewhere
  // (on the writer thread), as a stage of its own; the next Finish times the
  // rest.
  void Split(const std::string& name, double seconds, const std::string& detail = "") {
    Clock::time_point end = std::min(Clock::now(), start_ + std::chrono::duration_cast<Clock::duration>(
                                                                 std::chrono::duration<double>(seconds)));
    StageReport report{name, std::chrono::duration<double>(end - start_).count(), detail};
    result_.stages.push_back(report);
    if (progress_) progress_(report);
    start_ = end;
  }
  // A stage timed elsewhere (on the writer thread): reported, not counted
  // against the time since the last Finish.
  void Report(const std::string& name, double seconds, const std::string& detail = "") {
    StageReport report{name, seconds, detail};
    result_.stages.push_back(report);
    if (progress_) progress_(report);
  }

 private:
  BakeResult& result_;
  const ProgressCallback& progress_;
  Clock::time_point start_;
};

std::string FormatVector(const glm::dvec3& v) { return fmt::format("{:.9g} {:.9g} {:.9g}", v.x, v.y, v.z); }

double Luminance(const Rgb& rgb) { return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]; }

// One frame to bake: its style, sun and place in the sequence.
struct FramePlan {
  const SkyStyle* style = nullptr;
  int number = 0;  // 0: a single bake, no number in file names
  std::optional<CivilTime> time;
  double hours_from_start = 0.0;
  double elevation_deg = 0.0, azimuth_deg = 0.0;
  glm::dvec3 sun{0, 1, 0};
};

// Clock time of a frame since the sequence's first frame, in seconds: what
// the wind moves the clouds by (0 for a single bake, and for a schedule
// without clock times).
double CloudTimeOf(const FramePlan& plan) { return plan.hours_from_start * 3600.0; }


// Converts spectral output to luminance for exposure; a copy.
std::vector<float> DisplayLuminance(const float* rgba, size_t texels, OutputUnits units) {
  std::vector<float> display(rgba, rgba + 4 * texels);
  if (units == OutputUnits::kLuminance) return display;
  Rgb to_luminance = OutputScale(OutputUnits::kLuminance);
  for (size_t i = 0; i < display.size(); ++i)
    if (i % 4 != 3) display[i] *= float(to_luminance[i % 4]);
  return display;
}

// The views one frame renders for its SH: six small faces.
std::vector<ViewRequest> ShViews(const SkyStyle& style) {
  const int n = std::min(style.render.cube_size, 64);
  std::vector<ViewRequest> views;
  for (int face = 0; face < 6; ++face) views.push_back({MAPPING_VULKAN_FACE, n, n, face});
  return views;
}

// The file names one frame writes (in out_dir), in the order they are written.
struct FrameNames {
  std::vector<std::string> faces;  // six, when output.faces
  std::string cube, latlong, png;  // empty when not written
  std::vector<IblFileName> ibl;    // the IBL maps' files (ibl.h), when asked for
  std::vector<std::string> engine;  // the engine preset's files (engine_preset.h), when one is set
  bool with_dfg = false;           // the bake's first frame carries the DFG table
  std::string cloud_shadow;        // the cloud shadow map (cloud_shadow.h), when asked for
  std::vector<std::string> All() const {
    std::vector<std::string> all = faces;
    for (const std::string* n : {&cube, &latlong})
      if (!n->empty()) all.push_back(*n);
    for (const IblFileName& n : ibl) all.push_back(n.name);
    if (!cloud_shadow.empty()) all.push_back(cloud_shadow);
    for (const std::string& n : engine) all.push_back(n);
    if (!png.empty()) all.push_back(png);
    return all;
  }
};

FrameNames FrameFileNames(const SkyStyle& style, int number_in_name, bool with_dfg = false) {
  const OutputSettings& o = style.output;
  const std::string number = FrameNumberSuffix(number_in_name);
  FrameNames names;
  if (o.faces)
    for (int face = 0; face < 6; ++face) names.faces.push_back(o.basename + "_" + o.face_names[face] + number + ".exr");
  if (o.cube_strip) names.cube = o.basename + "_cube" + number + ".exr";
  if (o.latlong) names.latlong = o.basename + "_latlong" + number + ".exr";
  if (WritesLatlongPng(style)) names.png = o.basename + "_latlong" + number + ".png";
  names.ibl = IblFileNames(style, number_in_name, with_dfg);
  names.with_dfg = with_dfg;
  names.engine = EngineFileNames(style, number_in_name);
  if (style.cloud_shadow.enabled) names.cloud_shadow = CloudShadowFileName(o.basename, number_in_name);
  return names;
}

// The files of the frames in `part` (every frame when unset); a part writes
// its own manifest and no scene (merge-manifest writes it).
std::vector<std::string> PlannedFileNames(const std::vector<FramePlan>& plans, const std::optional<FrameRange>& part) {
  std::vector<std::string> names;
  for (const FramePlan& plan : plans)
    if (!part || part->Contains(plan.number))
      for (const std::string& n : FrameFileNames(*plan.style, plan.number, &plan == &plans.front()).All())
        names.push_back(n);
  const SkyStyle& first = *plans.front().style;
  if (first.gltf.enabled && !part)
    for (const char* ext : {".gltf", ".bin", ".glb"}) names.push_back(first.output.basename + ext);
  names.push_back(ManifestFileName(part));
  names.push_back(TimingsFileName(part));
  return names;
}

// What a resumed bake may skip: the frames of the previous manifest.
struct PreviousBake {
  bool loaded = false;
  double half_scale = 0.0;
  double exposure_ev100 = 0.0;
  std::map<int, json> frames;  // by frame number
};

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

// A string member, or "" when absent or not a string.
std::string StringOf(const json& object, const char* key) {
  return object.contains(key) && object[key].is_string() ? object[key].get<std::string>() : std::string();
}

// The files of `frame` from the previous manifest when every one of them is
// on disk with its recorded SHA-256 and the frame was baked with the same
// style, exposure and half scale; otherwise nothing. A frame of the same
// style lists exactly the names and kinds this bake gives it: any other
// name stops the bake (ManifestError, exit 8) before it is opened.
std::optional<std::vector<BakedFile>> VerifiedFrame(const PreviousBake& previous, const FramePlan& plan,
                                                    const std::string& out_dir, double half_scale,
                                                    double ev100, bool with_dfg) {
  if (!previous.loaded || previous.half_scale != half_scale || previous.exposure_ev100 != ev100)
    return std::nullopt;
  auto it = previous.frames.find(plan.number);
  if (it == previous.frames.end()) return std::nullopt;
  const json& f = it->second;
  if (StringOf(f, "style_sha256") != Sha256OfText(plan.style->resolved_toml)) return std::nullopt;
  if (!f.contains("files") || !f["files"].is_array()) return std::nullopt;
  const FrameNames names = FrameFileNames(*plan.style, plan.number, with_dfg);
  const std::vector<std::string> expected = names.All();
  // In the order of FrameNames::All().
  std::vector<std::string> kinds(names.faces.size(), "face");
  if (!names.cube.empty()) kinds.push_back("cube");
  if (!names.latlong.empty()) kinds.push_back("latlong");
  for (const IblFileName& n : names.ibl) kinds.push_back(n.kind);
  if (!names.cloud_shadow.empty()) kinds.push_back("cloud_shadow");
  kinds.insert(kinds.end(), names.engine.size(), "engine");
  if (!names.png.empty()) kinds.push_back(plan.style->output.preview ? "preview" : "gltf_texture");
  size_t index = 0;
  for (const json& entry : f["files"]) {
    const std::string name = entry.is_object() ? StringOf(entry, "file") : std::string();
    const std::string kind = entry.is_object() ? StringOf(entry, "kind") : std::string();
    if (index >= expected.size() || name != expected[index] || kind != kinds[index])
      throw ManifestError(fmt::format(
          "the manifest in {} lists {} ({}) for frame {}, where this bake of the same style writes {}: the manifest "
          "was edited or is not skybake's; nothing was read under that name. Pass --force instead of --resume to "
          "bake every frame again",
          out_dir, EscapedText(name), EscapedText(kind), plan.number,
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

// What the writer thread needs of a rendered frame.
struct FrameJob {
  FramePlan plan;
  FrameNames names;
  std::vector<RgbaImage> images;  // the frame's views, in PlanViews order
  std::shared_ptr<const void> hold;  // the renderer's memory the images view (RenderInPlace)
  double half_scale = 1.0;        // a sequence's; a single bake's is found from the images
  std::optional<double> ev100;    // a sequence's; a single bake's is found from the latlong
  std::optional<IblMaps> ibl;     // the frame's IBL maps, when asked for
  std::vector<RgbaImage> engine;  // the engine preset's images (engine_preset.h)
  std::vector<float> cloud_shadow;  // the frame's cloud shadow map (cloud_shadow.h), when asked for
  std::optional<CloudShadowInfo> cloud_shadow_info;
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

// The largest value the sun disc can give a frame, in output units: its
// centre radiance unattenuated (transmittance <= 1), when the disc is on and
// its top is above the observer's horizon; nothing otherwise, nor under the
// AOAS skydome (which moves the observer and turns the Sun).
std::optional<double> VisibleDiscBound(const SkyStyle& unpruned, double elevation_deg) {
  const SkyStyle style = PrunedStyle(unpruned);
  if (!style.effects.sun_disc || style.aoas.skydome.enabled) return std::nullopt;
  const AtmosphereParams a = StyledAtmosphere(style.atmosphere, style.aoas);
  const double r = a.bottom_radius_km + a.observer_altitude_m * 1e-3;
  const double dip_deg = std::acos(std::min(a.bottom_radius_km / r, 1.0)) * 180.0 / M_PI;
  const double alpha = a.sun_angular_radius_rad;
  if (elevation_deg < -dip_deg - alpha * 180.0 / M_PI) return std::nullopt;
  // SunDiscRadiance at the centre (atmosphere.glsl): 1 / (pi alpha^2 (1 - u/3)).
  const double centre = 1.0 / (M_PI * alpha * alpha * (1.0 - a.limb_darkening_u / 3.0));
  const Rgb scale = OutputScale(style.output.units);
  double bound = 0.0;
  for (int c = 0; c < 3; ++c)
    bound = std::max(bound, a.solar_irradiance[c] * scale[c] * centre * style.effects.sun_disc_strength);
  return bound;
}

BakeResult BakeFrames(const std::vector<FramePlan>& plans, const Schedule* schedule, const BakeOptions& options) {
  BakeResult result;
  StageTimer timer(result, options.progress);
  const Clock::time_point bake_start = Clock::now();
  const bool sequence = schedule != nullptr;
  const SkyStyle& first = *plans.front().style;
  // OpenEXR compresses line blocks on its own pool, one thread per core.
  SetExrThreads(int(std::max(1u, std::thread::hardware_concurrency())));
  // A part of the sequence (--frames, --shard) bakes only its frames; every
  // sequence-wide value below still comes from every frame in `plans`.
  const std::optional<FrameRange>& part = options.frames;
  const std::string manifest_name = ManifestFileName(part);

  // Outputs, before any GPU work: within budget, not overwriting a previous
  // bake unless asked to, stale temporaries of a killed bake removed.
  for (const FramePlan& plan : plans) CheckBudget(*plan.style, options);
  const std::vector<std::string> planned = PlannedFileNames(plans, part);
  auto path_of = [&](const std::string& name) { return (std::filesystem::path(options.out_dir) / name).string(); };
  // The lock on the planned files, held to the end of the bake (any exit,
  // kill -9 included, releases it): another live bake writing any of them
  // into this folder stops this one here (exit 6); parts of one sequence,
  // whose files differ, go ahead side by side.
  {
    std::error_code ec;
    const std::filesystem::file_status out = std::filesystem::status(options.out_dir, ec);
    if (std::filesystem::exists(out) && !std::filesystem::is_directory(out))
      throw OutputError(fmt::format("--out {} is not a folder: give a folder (it is created when missing)",
                                    options.out_dir));
    std::filesystem::create_directories(options.out_dir, ec);
    if (ec)
      throw OutputError(fmt::format("cannot create the output folder {}: {}: choose a writable --out folder",
                                    options.out_dir, ec.message()));
  }
  const OutputLock lock = OutputLock::Claim(options.out_dir, planned);
  // The night sky (night_sky.h): its catalogues read, its input checked, before any GPU work.
  std::vector<const SkyStyle*> plan_styles;
  for (const FramePlan& plan : plans) plan_styles.push_back(plan.style);
  std::unique_ptr<NightSkyBake> night = NightSkyBake::For(plan_styles, schedule);
  // What the renames at the end could not replace is found now, before any
  // GPU work: a directory (or a pipe, a socket) under an output's name.
  for (const std::string& name : planned) {
    if (options.resume && name == manifest_name) continue;  // read first: ReadPreviousManifest says what is wrong
    std::error_code ec;
    const std::filesystem::file_status st = std::filesystem::symlink_status(path_of(name), ec);
    if (std::filesystem::exists(st) && !std::filesystem::is_regular_file(st) && !std::filesystem::is_symlink(st))
      throw OutputError(fmt::format("{} is {}: an output file cannot replace it; move it away, or choose another --out",
                                    path_of(name), std::filesystem::is_directory(st) ? "a directory" : "not a regular file"));
  }
  if (!options.force && !options.resume) {
    for (const std::string& name : planned) {
      std::error_code ec;
      // A link (dangling or not) at the name is a file in the way too.
      if (std::filesystem::exists(std::filesystem::symlink_status(path_of(name), ec)))
        throw OutputExistsError(fmt::format(
            "{} already exists: pass --force to overwrite the bake's files{}, or choose another --out",
            path_of(name), sequence ? ", --resume to finish an interrupted sequence" : ""));
    }
  }
  PreviousBake previous;
  if (options.resume) previous = ReadPreviousManifest(path_of(manifest_name));
  result.removed_temporaries = RemoveStaleTemporaries(options.out_dir, planned);
  timer.Finish("outputs", fmt::format("{} files planned{}{}", planned.size(),
                                      result.removed_temporaries.empty()
                                          ? ""
                                          : fmt::format(", {} stale temporary file(s) removed",
                                                        result.removed_temporaries.size()),
                                      previous.loaded ? fmt::format(", resuming from {} frame(s) in {}",
                                                                    previous.frames.size(), manifest_name)
                                                      : ""));

  // Device: headless Vulkan, best device or the one asked for; one for the whole bake.
  VulkanContext context(options.vulkan);
  std::optional<NightSkyRenderer> night_renderer;  // the moonlit sky's renderer, destroyed before the device
  if (night) night_renderer.emplace(context);
  timer.Finish("device", fmt::format("{} ({}){}", context.device_info().name, context.device_info().type,
                                     DriverSelection().empty() ? "" : ", software driver only (no GPU device node)"));
  // Each render's output is one storage buffer: refuse views the device cannot bind.
  const uint64_t max_range = context.properties().limits.maxStorageBufferRange;
  for (const FramePlan& plan : plans) {
    for (const ViewRequest& v : PlanViews(*plan.style)) {
      uint64_t bytes = uint64_t(v.width) * uint64_t(v.height) * 16;
      if (bytes > max_range)
        throw VulkanError(fmt::format("a {}x{} view needs {} MiB in one storage buffer; {} allows {} MiB "
                                      "(maxStorageBufferRange): lower render.cube_size or render.latlong_height",
                                      v.width, v.height, bytes >> 20, context.device_info().name, max_range >> 20),
                          VK_ERROR_OUT_OF_DEVICE_MEMORY);
    }
  }

  // Pipelines and LUTs: built for the first frame, rebuilt only on atmosphere changes.
  RendererCache renderers(context, result, options.shaders);
  std::unique_ptr<IblBaker> ibl_baker;  // created by the first frame that asks for IBL maps
  {
    const RenderCounters& c = renderers.Main(first).counters();
    timer.Finish("pipelines", fmt::format("{} compute pipelines, {} from built-in shader variants", c.pipelines,
                                          c.variant_pipelines));
  }
  renderers.Main(first).PrecomputeLuts();
  for (const PassTiming& t : renderers.Main(first).last_timings()) result.gpu_passes.push_back(t);
  timer.Finish("LUTs", fmt::format("transmittance {}x{}, multiple scattering {}x{}",
                                   first.quality.transmittance_width, first.quality.transmittance_height,
                                   first.quality.multiscattering_size, first.quality.multiscattering_size));

  // The reference frame (highest sun) sets the sequence's exposure and lights the glTF scene.
  size_t reference = 0;
  for (size_t i = 1; i < plans.size(); ++i)
    if (plans[i].elevation_deg > plans[reference].elevation_deg) reference = i;

  // Sequence-wide exposure and half-float scale, decided before any file is
  // written, never per frame.
  std::optional<double> ev100;
  std::string exposure_source;
  double half_scale = 1.0;
  // Only previews and the glTF texture are exposed.
  const bool exposed = std::any_of(plans.begin(), plans.end(), [](const FramePlan& p) {
    return WritesLatlongPng(*p.style);
  });
  if (sequence) {
    const FramePlan& ref = plans[reference];
    if (!exposed) {
      exposure_source = "none (no preview or glTF texture)";
    } else if (ref.style->preview.auto_exposure) {
      const int h = ref.style->render.latlong_height;
      std::vector<float> latlong =
          renderers.Main(*ref.style, CloudTimeOf(ref)).Render(ref.sun, {{MAPPING_LATLONG, 2 * h, h, 0}})[0];
      ev100 = AutoEv100(DisplayLuminance(latlong.data(), latlong.size() / 4, ref.style->output.units), 2 * h, h);
      exposure_source = fmt::format("auto exposure of frame {} (highest sun), applied to every frame", ref.number);
    } else {
      ev100 = ref.style->preview.ev100;
      exposure_source = "preview.ev100";
    }
    if (first.output.pixel_type == PixelType::kHalf) {
      // The brightest texel of a frame is the sun disc's centre, or else the
      // sky near it. While the disc is above the horizon of some frame, its
      // unattenuated centre radiance bounds the sequence without rendering;
      // otherwise a coarse latlong plus the disc centre of every frame does.
      // A factor 2 of margin; writing checks the bound.
      double max_value = 0.0;
      for (const FramePlan& plan : plans)
        if (auto bound = VisibleDiscBound(*plan.style, plan.elevation_deg)) {
          // ibl.include_sun puts the Sun's energy into one texel of the
          // specular level 0: brighter than the disc by the ratio of their
          // solid angles when the texel is the smaller (ibl.h).
          const IblSettings& ibl = plan.style->ibl;
          double scale = 1.0;
          if (ibl.specular && ibl.include_sun) {
            const double a = plan.style->atmosphere.sun_angular_radius_rad;
            scale = std::max(1.0, M_PI * a * a / CubeTexelSolidAngle(0, 0, ibl.size));
          }
          max_value = std::max(max_value, *bound * scale);
        }
      for (const FramePlan& plan : max_value > 0.0 ? std::vector<FramePlan>{} : plans) {
        SkyRenderer& r = renderers.Main(*plan.style, CloudTimeOf(plan));
        std::vector<float> coarse = r.Render(plan.sun, {{MAPPING_LATLONG, 128, 64, 0}})[0];
        std::vector<float> centre = r.RenderDirections(plan.sun, {plan.sun});
        RgbaImage a{128, 64, coarse}, b{1, 1, centre};
        max_value = std::max(max_value, CheckedMaxValue({&a, &b}));
      }
      half_scale = HalfRangeScale(2.0 * max_value, first.output.overflow);
    }
    timer.Finish("exposure", fmt::format("EV100 {} ({}), half scale {:.9g}",
                                         ev100 ? fmt::format("{:.2f}", *ev100) : "-", exposure_source, half_scale));
  }
  result.half_scale = half_scale;

  std::filesystem::create_directories(options.out_dir);

  // Manifest: every file with its size and SHA-256, per frame; rewritten
  // atomically after every frame, `complete` once the bake (or part) is. Its
  // sequence-wide entries come from every frame of `plans`, so the parts of
  // a sequence agree on them and merge-manifest can check that they do.
  std::vector<std::string> style_sha256;  // per plan
  std::string sequence_identity;          // every frame's number, time, sun and style
  std::map<int, size_t> plan_of_frame;    // frame number -> index in plans
  for (size_t i = 0; i < plans.size(); ++i) {
    const FramePlan& plan = plans[i];
    style_sha256.push_back(Sha256OfText(plan.style->resolved_toml));
    sequence_identity +=
        SequenceIdentityLine(plan.number, plan.time ? plan.time->Iso8601() : "", plan.sun, style_sha256.back());
    plan_of_frame[plan.number] = i;
  }
  auto manifest_of = [&]() {
    Manifest m;
    m.version = SKYBAKE_VERSION;
    m.style = first.source_path;
    m.schedule = schedule ? schedule->source_path : "";
    m.sequence_sha256 = Sha256OfText(sequence_identity);
    m.units = first.output.units == OutputUnits::kLuminance ? "luminance cd/m^2 (sky), lux (irradiance)"
                                                            : "spectral W m^-2 sr^-1 nm^-1 at 680/550/440 nm";
    m.exposure_ev100 = ev100.value_or(0.0);
    m.exposure_source = exposure_source;
    m.texture_frame = plans[reference].number;
    m.half_scale = half_scale;
    if (schedule) {
      m.place = schedule->place;
      m.sequence = FrameRange{plans.front().number, plans.back().number};
    }
    m.part = part;
    // The scene's texture: the reference frame's PNG, a 2h x h latlong.
    const SkyStyle& ref = *plans[reference].style;
    m.gltf = {first.gltf.enabled, first.output.basename, first.gltf, FrameFileNames(ref, plans[reference].number).png,
              2 * ref.render.latlong_height, ref.render.latlong_height};
    for (const FrameResult& f : result.frames) {
      const size_t i = plan_of_frame.at(f.number);
      ManifestFrame frame = ManifestFrameOf(f);
      frame.style_sha256 = style_sha256[i];
      frame.hours_from_start = plans[i].hours_from_start;
      frame.animation_time_s = schedule && schedule->clock_times ? plans[i].hours_from_start : double(i);
      m.frames.push_back(std::move(frame));
    }
    return m;
  };
  // A write costs time in proportion to the frames done, so rewriting the
  // manifest after every frame grew as frames squared. It is rewritten after
  // a frame when the frames done have grown by a tenth since its last write
  // (so after each of the first twenty; the bytes written add up to about 11
  // times the final manifest), or when kManifestSeconds have passed since
  // the last write and at least kManifestSpacing times what it took (writes
  // stay under a tenth of the bake). Both keep the cost linear; a killed
  // bake loses at most the frames since the last write (--resume bakes them
  // again).
  constexpr double kManifestSpacing = 9.0;
  constexpr double kManifestSeconds = 30.0;
  Clock::time_point manifest_written = Clock::now();
  double manifest_write_seconds = 0.0;
  size_t manifest_frames = 0;  // frames in the last manifest written
  auto write_manifest = [&](const std::vector<BakedFile>& scene, bool complete) {
    Manifest m = manifest_of();
    for (const BakedFile& f : scene)
      m.scene.push_back({std::filesystem::path(f.path).filename().string(), f.kind, f.bytes, f.sha256});
    m.complete = complete;
    result.manifest_path = path_of(manifest_name);
    WriteManifest(m, result.manifest_path);
    ++result.manifest_writes;
    std::error_code ec;
    result.manifest_bytes_written += std::filesystem::file_size(result.manifest_path, ec);
  };
  auto write_progress_manifest = [&]() {
    const size_t done = result.frames.size();
    if (done - manifest_frames < std::max<size_t>(1, manifest_frames / 10) &&
        SecondsSince(manifest_written) < std::max(kManifestSeconds, kManifestSpacing * manifest_write_seconds))
      return;
    const Clock::time_point start = Clock::now();
    write_manifest({}, false);
    manifest_frames = done;
    manifest_written = Clock::now();
    manifest_write_seconds = std::chrono::duration<double>(manifest_written - start).count();
  };

  // One frame's files, from its rendered views: one scale for every file
  // (of the frame, or of the sequence). Runs on the writer thread; reads
  // only the job and constants of the bake.
  auto write_frame = [&](FrameJob& job) {
    WrittenFrame w;
    const FramePlan& plan = job.plan;
    const SkyStyle& style = *plan.style;
    const FrameNames& names = job.names;
    std::vector<RgbaImage>& images = job.images;
    Clock::time_point write_start = Clock::now();
    std::vector<const RgbaImage*> all;
    for (const RgbaImage& image : images) all.push_back(&image);
    const std::vector<RgbaImage> ibl_images = job.ibl ? IblImagesForRangeCheck(*job.ibl) : std::vector<RgbaImage>();
    for (const RgbaImage& image : ibl_images) all.push_back(&image);
    for (const RgbaImage& image : job.engine) all.push_back(&image);
    const double max_value = CheckedMaxValue(all);
    w.half_scale = job.half_scale;
    if (style.output.pixel_type == PixelType::kHalf) {
      if (!sequence) {
        w.half_scale = HalfRangeScale(max_value, style.output.overflow);
      } else if (max_value * job.half_scale > kHalfMax) {
        throw OutputError(fmt::format(
            "frame {}: the brightest value {:.6g} exceeds the sequence's half-float scale {:.9g}: set "
            "output.pixel_type = \"float\"", plan.number, max_value, job.half_scale));
      }
    }
    ExrWriteOptions exr;
    exr.pixel_type = style.output.pixel_type;
    exr.compression = style.output.compression;
    exr.zip_level = style.output.zip_level;
    exr.scale = w.half_scale;
    const bool luminance = style.output.units == OutputUnits::kLuminance;
    if (luminance) exr.white_luminance = 1.0 / w.half_scale;
    exr.attributes = {
        {"skybake:version", SKYBAKE_VERSION},
        {"skybake:config", style.resolved_toml},
        {"skybake:source", style.source_path},
        {"skybake:units", luminance ? "linear Rec.709 luminance, cd/m^2 per 1.0 divided by skybake:scale"
                                    : "spectral radiance W m^-2 sr^-1 nm^-1 at 680/550/440 nm (R/G/B), "
                                      "divided by skybake:scale"},
        {"skybake:scale", fmt::format("{:.9g}", w.half_scale)},
        {"skybake:frame", "+Y up, North -Z, East +X; right-handed"},
        {"skybake:sun_direction", FormatVector(plan.sun)},
    };
    if (plan.number > 0) exr.attributes["skybake:frame_number"] = std::to_string(plan.number);
    if (plan.time) exr.attributes["skybake:time"] = plan.time->Iso8601();
    // The frame's files encoded together in memory (their chunks shared
    // among the threads), then each written atomically and checksummed from
    // the same bytes.
    std::vector<ExrFile> exrs;
    std::vector<std::string> kinds;
    size_t view_index = 0;
    if (style.output.faces) {
      for (int face = 0; face < 6; ++face, ++view_index) {
        ExrWriteOptions face_exr = exr;
        face_exr.attributes["skybake:cube_face"] = CubeFaceLabel(face);
        face_exr.attributes["skybake:face_orientation"] = "Vulkan cube map face (sc, tc) table";
        exrs.push_back({path_of(names.faces[face]), &images[view_index], face_exr});
        kinds.push_back("face");
      }
    }
    if (style.output.cube_strip) {
      ExrWriteOptions cube_exr = exr;
      cube_exr.envmap = 1;  // ENVMAP_CUBE
      exrs.push_back({path_of(names.cube), &images[view_index], cube_exr});
      kinds.push_back("cube");
      ++view_index;
    }
    const RgbaImage* latlong = view_index < images.size() ? &images[view_index] : nullptr;
    if (style.output.latlong) {
      ExrWriteOptions latlong_exr = exr;
      latlong_exr.envmap = 0;  // ENVMAP_LATLONG
      exrs.push_back({path_of(names.latlong), latlong, latlong_exr});
      kinds.push_back("latlong");
    }
    const std::vector<std::string> encoded = EncodeExrs(exrs);
    // Each file on a thread of its own: most of a write is waiting for the
    // disk to confirm the fsync (about 1 ms a file here), which the files
    // can do together.
    std::vector<std::future<std::string>> checksums;
    for (size_t i = 0; i < exrs.size(); ++i)
      checksums.push_back(std::async(std::launch::async, [&, i] {
        WriteFileAtomically(exrs[i].name, encoded[i]);
        return Sha256OfText(encoded[i]);
      }));
    std::exception_ptr failure;
    for (size_t i = 0; i < exrs.size(); ++i) {
      try {
        w.files.push_back({exrs[i].name, kinds[i], encoded[i].size(), checksums[i].get()});
      } catch (...) {
        if (!failure) failure = std::current_exception();
      }
    }
    if (failure) std::rethrow_exception(failure);
    // The IBL maps, with the frame's scale and provenance (ibl.h).
    if (job.ibl) {
      const std::vector<std::string> ibl_files = EncodeIblFiles(*job.ibl, style, exr, names.with_dfg);
      for (size_t i = 0; i < ibl_files.size(); ++i) {
        const std::string path = path_of(names.ibl[i].name);
        WriteFileAtomically(path, ibl_files[i]);
        w.files.push_back({path, names.ibl[i].kind, ibl_files[i].size(), Sha256OfText(ibl_files[i])});
      }
    }
    if (job.cloud_shadow_info) w.files.push_back(WriteCloudShadowFile(path_of(names.cloud_shadow), job.cloud_shadow,
                                                                      *job.cloud_shadow_info, exr.attributes));
    if (!job.engine.empty()) {
      const std::vector<BakedFile> engine = WriteEngineFiles(style, job.engine, exr, options.out_dir, names.engine);
      w.files.insert(w.files.end(), engine.begin(), engine.end());
    }
    w.exr_seconds = SecondsSince(write_start);
    w.exr_detail = fmt::format("{} files, {} compression{}, {}", w.files.size(), style.output.compression,
                               style.output.compression == "zip" || style.output.compression == "zips"
                                   ? fmt::format(" level {}", style.output.zip_level)
                                   : "",
                               style.output.pixel_type == PixelType::kHalf ? "half" : "float");

    // Preview (and glTF texture): exposure, ACES, sRGB; one exposure for a sequence.
    w.ev100 = job.ev100;
    if (latlong && WritesLatlongPng(style)) {
      Clock::time_point preview_start = Clock::now();
      std::vector<float> display = DisplayLuminance(latlong->data(), latlong->texels(), style.output.units);
      if (!w.ev100) {
        w.ev100 = style.preview.auto_exposure ? AutoEv100(display, latlong->width, latlong->height)
                                              : style.preview.ev100;
        w.exposure_source = style.preview.auto_exposure ? "auto exposure" : "preview.ev100";
      }
      std::vector<uint8_t> srgb = TonemapToSrgb8(display, latlong->width, latlong->height, ExposureFromEv100(*w.ev100));
      std::string path = path_of(names.png);
      uint64_t bytes = WritePng(path, latlong->width, latlong->height, srgb);
      w.files.push_back({path, style.output.preview ? "preview" : "gltf_texture", bytes, Sha256OfFile(path)});
      w.preview_seconds = SecondsSince(preview_start);
    }
    w.write_seconds = SecondsSince(write_start);
    return w;
  };
  // The frame whose files are being written, and what the main thread does
  // once they are: the frame's record, progress and the manifest.
  std::optional<std::pair<FrameResult, std::future<WrittenFrame>>> pending;
  auto collect_pending = [&]() {
    if (!pending) return;
    Clock::time_point wait_start = Clock::now();
    WrittenFrame w = pending->second.get();
    FrameResult frame = std::move(pending->first);
    pending.reset();
    const std::string preview_detail =
        w.ev100 ? fmt::format("EV100 {:.2f}, ACES filmic, sRGB", *w.ev100) : std::string();
    if (!sequence) {
      // A single bake waits for its files: the wait is the EXRs, then the preview.
      if (w.preview_seconds > 0.0) {
        timer.Split("write EXR", w.exr_seconds, w.exr_detail);
        timer.Finish("preview", preview_detail);
      } else {
        timer.Finish("write EXR", w.exr_detail);
      }
    } else {
      if (SecondsSince(wait_start) > 0.005) timer.Finish("waiting for files");
      timer.Report("write EXR", w.exr_seconds,
                   w.exr_detail + fmt::format(", frame {}, beside the next frame's render", frame.number));
    }
    if (w.ev100) {
      if (!ev100) exposure_source = w.exposure_source;
      ev100 = w.ev100;
      result.preview_ev100 = *w.ev100;
      if (sequence && w.preview_seconds > 0.0) timer.Report("preview", w.preview_seconds, preview_detail);
    }
    if (!sequence) {
      half_scale = w.half_scale;
      result.half_scale = half_scale;
    }
    frame.files = std::move(w.files);
    frame.write_seconds = w.write_seconds;
    for (const BakedFile& f : frame.files) result.files.push_back(f);
    result.frames.push_back(std::move(frame));
    // The manifest as frames are done: a killed bake leaves a valid record of them.
    write_progress_manifest();
  };

  for (size_t index = 0; index < plans.size(); ++index) {
    const FramePlan& plan = plans[index];
    if (part && !part->Contains(plan.number)) continue;  // another part's frame
    const SkyStyle& style = *plan.style;
    FrameResult frame;
    frame.number = plan.number;
    frame.time = plan.time;
    frame.sun_direction = plan.sun;
    frame.sun_elevation_deg = plan.elevation_deg;
    frame.sun_azimuth_deg = plan.azimuth_deg;
    const std::string label = plan.number > 0 ? fmt::format("frame {}", plan.number) : "render";
    const FrameNames names = FrameFileNames(style, plan.number, index == 0);
    // A resumed sequence skips frames whose files are verified against the manifest.
    std::optional<std::vector<BakedFile>> verified;
    if (sequence && options.resume) verified = VerifiedFrame(previous, plan, options.out_dir, half_scale, ev100.value_or(0.0), index == 0);

    // Render: every view of the frame in one submission, then the SH views.
    Clock::time_point render_start = Clock::now();
    SkyRenderer& renderer = renderers.Main(style, CloudTimeOf(plan));
    const std::vector<ViewRequest> views = PlanViews(style);
    RenderedViews rendered;
    if (!verified) {
      // In place: the writer thread reads the texels where the device wrote
      // them while the next frame renders into other memory.
      rendered = renderer.RenderInPlace(plan.sun, views);
      for (const PassTiming& t : renderer.last_timings()) frame.gpu_passes.push_back(t);
    }
    // SH: the sky without the disc from small faces; the disc added as the
    // irradiance it delivers (centre radiance times its limb-darkened solid
    // angle), which point-sampled texels would alias.
    std::optional<NightFrame> night_frame;
    if (night) night_frame = night->Frame(style, plan.time, plan.sun);
    const std::vector<float> with_disc = renderer.RenderDirections(plan.sun, {plan.sun});
    const std::vector<float> without_disc = renderer.RenderDirections(plan.sun, {plan.sun}, false);
    std::vector<ViewRequest> sh_views = ShViews(style);
    std::vector<std::vector<float>> sh_faces = renderer.Render(plan.sun, sh_views, false);
    for (const PassTiming& t : renderer.last_timings()) frame.gpu_passes.push_back(t);
    if (night_frame) night->AddToFaces(*night_renderer, style, *night_frame, sh_views, sh_faces);
    const double alpha = style.atmosphere.sun_angular_radius_rad;
    const double disc_solid_angle = M_PI * alpha * alpha * (1.0 - style.atmosphere.limb_darkening_u / 3.0);
    for (int c = 0; c < 3; ++c)
      frame.sun_irradiance[c] = std::max(0.0, double(with_disc[c]) - double(without_disc[c])) * disc_solid_angle;
    if (!style.effects.sun_disc) frame.sun_irradiance = {0.0, 0.0, 0.0};
    Rgb sun_luminance = frame.sun_irradiance;
    if (style.output.units == OutputUnits::kSpectral) {
      Rgb k = OutputScale(OutputUnits::kLuminance);
      for (int c = 0; c < 3; ++c) sun_luminance[c] *= k[c];
    }
    frame.sun_illuminance_lux = Luminance(sun_luminance);
    ShRgb sky = ProjectCubeFaces({sh_faces[0].data(), sh_faces[1].data(), sh_faces[2].data(), sh_faces[3].data(),
                                  sh_faces[4].data(), sh_faces[5].data()},
                                 sh_views[0].width);
    frame.sh_irradiance_without_sun = RadianceToIrradiance(sky);
    AddDirectionalSource(sky, plan.sun, frame.sun_irradiance);
    if (night_frame) night->RecordMoon(style, *night_frame, sky, frame.moon);
    frame.sh_irradiance_with_sun = RadianceToIrradiance(sky);
    frame.render_seconds = SecondsSince(render_start);
    size_t texels = 0;
    for (const ViewRequest& v : views) texels += size_t(v.width) * v.height;
    if (verified) texels = 0;
    timer.Finish(label, fmt::format("{} views, {:.2f} Mtexels, sun elevation {:.2f} azimuth {:.2f}{}{}",
                                    verified ? 0 : views.size(), texels * 1e-6, plan.elevation_deg, plan.azimuth_deg,
                                    plan.time ? ", " + plan.time->Iso8601() : "",
                                    verified ? ", files verified by checksum: not rendered again" : ""));
    // IBL: the sky without the disc at ibl.size, filtered on the device into
    // the specular chain, the irradiance cube and (first frame) the DFG table.
    std::optional<IblMaps> ibl_maps;
    if (style.ibl.Requested() && !verified) {
      if (!ibl_baker) ibl_baker = std::make_unique<IblBaker>(context);
      const int n = style.ibl.size;
      std::vector<ViewRequest> source_views;
      for (int face = 0; face < 6; ++face) source_views.push_back({MAPPING_VULKAN_FACE, n, n, face});
      std::vector<std::vector<float>> source_faces = renderer.Render(plan.sun, source_views, false);
      if (night_frame) night->AddToFaces(*night_renderer, style, *night_frame, source_views, source_faces);
      for (const PassTiming& t : renderer.last_timings()) frame.gpu_passes.push_back({"IBL source " + t.name, t.gpu_ms});
      CubeLevel source;
      source.size = n;
      for (int face = 0; face < 6; ++face) source.faces[face] = std::move(source_faces[face]);
      IblRequest request{style.ibl, plan.sun, frame.sun_irradiance, style.ibl.dfg && names.with_dfg};
      ibl_maps = ibl_baker->Bake(request, source);
      ibl_maps->gltf_scale = GltfIblScale(frame.sh_irradiance_without_sun);
      for (const PassTiming& t : ibl_baker->last_timings()) frame.gpu_passes.push_back(t);
      timer.Finish("IBL", fmt::format("{}: {} x {} source without the sun disc, {} specular levels x {} samples, "
                                      "irradiance {} x {} samples{}{}",
                                      label, n, n, style.ibl.specular ? IblLevelCount(style.ibl) : 0,
                                      style.ibl.samples, style.ibl.irradiance ? style.ibl.irradiance_size : 0,
                                      style.ibl.irradiance_samples, request.dfg ? ", DFG table" : "",
                                      style.ibl.include_sun ? ", sun included" : ""));
    }
    std::vector<RgbaImage> engine_images;
    if (!names.engine.empty() && !verified) {
      engine_images = RenderEngineImages(renderer, plan.sun, style);
      timer.Finish("engine", fmt::format("{}: {} images for {}", label, engine_images.size(), style.output.engine));
    }
    // The cloud shadow map (cloud_shadow.h): its placement follows from the
    // style, the sun and the time alone (recorded for verified frames too).
    std::vector<float> cloud_shadow;
    if (style.cloud_shadow.enabled) {
      frame.cloud_shadow = CloudShadowInfoOf(PrunedStyle(style).clouds, style.cloud_shadow, plan.sun, CloudTimeOf(plan));
      if (!verified) {
        cloud_shadow = renderer.RenderCloudShadow(plan.sun, style.cloud_shadow);
        for (const PassTiming& t : renderer.last_timings()) frame.gpu_passes.push_back(t);
      }
    }
    if (verified) {
      collect_pending();
      frame.files = *verified;
      result.preview_ev100 = ev100.value_or(0.0);
      for (const BakedFile& f : frame.files) result.files.push_back(f);
      result.frames.push_back(std::move(frame));
      write_progress_manifest();
      continue;
    }

    // Files: encoded, written and checksummed on the writer thread while
    // the device renders the next frame (the last frame's, or a single
    // bake's, are waited for at once).
    std::vector<RgbaImage> images;
    for (size_t i = 0; i < views.size(); ++i) images.push_back({views[i].width, views[i].height, {}, rendered.views[i]});
    if (night_frame) night->AddToViews(*night_renderer, style, *night_frame, views, images);
    if (night_frame) timer.Report("night sky", night->TakeSeconds(), label + ": " + NightSkyBake::Describe(*night_frame));
    collect_pending();
    FrameJob job{plan, names, std::move(images), std::move(rendered.hold), half_scale, ev100, std::move(ibl_maps),
                 std::move(engine_images), std::move(cloud_shadow), frame.cloud_shadow};
    pending.emplace(std::move(frame),
                    std::async(std::launch::async, [&write_frame, job = std::move(job)]() mutable {
                      return write_frame(job);
                    }));
    if (!sequence || index + 1 == plans.size()) collect_pending();
  }
  collect_pending();

  // Scene and manifest: a whole bake ends as merge-manifest does, through
  // WriteSceneAndManifest, so both give the same bytes; a part writes only
  // its own manifest (merge-manifest writes the scene once all parts are in).
  if (part) {
    write_manifest({}, true);
  } else {
    Manifest manifest = manifest_of();
    std::vector<BakedFile> scene_files = WriteSceneAndManifest(manifest, options.out_dir);
    for (const BakedFile& f : scene_files) result.files.push_back(f);
    if (!scene_files.empty())
      timer.Finish("glTF", fmt::format("{} ({} sun key{}), .glb", scene_files.front().path, manifest.frames.size(),
                                       manifest.frames.size() == 1 ? "" : "s"));
    result.manifest_path = path_of(manifest_name);
  }
  result.files.push_back({result.manifest_path, "manifest", std::filesystem::file_size(result.manifest_path), ""});
  timer.Finish("manifest", result.manifest_path);
  // Timings: what differs from run to run, beside the manifest.
  const std::string timings_path = path_of(TimingsFileName(part));
  WriteTimings(result, options.out_dir, SecondsSince(bake_start), timings_path);
  result.files.push_back({timings_path, "timings", std::filesystem::file_size(timings_path), ""});

  result.counters = renderers.Current().counters();
  result.validation_messages = context.validation_message_count();
  return result;
}

}  // namespace

void KeepFrameMemoryInHeap() {
  mallopt(M_MMAP_THRESHOLD, 1 << 30);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
}

BakeResult BakeStyle(const SkyStyle& style, const BakeOptions& options) {
  FramePlan plan;
  plan.style = &style;
  plan.elevation_deg = style.sun.elevation_deg;
  plan.azimuth_deg = style.sun.azimuth_deg;
  plan.sun = SunDirectionFromElevationAzimuth(style.sun.elevation_deg, style.sun.azimuth_deg);
  if (options.frames) throw std::invalid_argument("BakeStyle: a frame selection needs a schedule (BakeSequence)");
  return BakeFrames({plan}, nullptr, options);
}

BakeResult BakeSequence(const std::vector<SkyStyle>& styles, const Schedule& schedule, const BakeOptions& options) {
  if (styles.size() != schedule.frames.size() || styles.empty())
    throw std::invalid_argument(fmt::format("BakeSequence: {} styles for {} frames", styles.size(),
                                            schedule.frames.size()));
  if (options.frames) {
    const FrameRange all = ScheduleFrameRange(schedule);
    if (!all.Contains(options.frames->first) || !all.Contains(options.frames->last) || options.frames->count() < 1)
      throw std::invalid_argument(fmt::format("BakeSequence: frames {} to {} are not within the schedule's {} to {}",
                                              options.frames->first, options.frames->last, all.first, all.last));
  }
  std::vector<FramePlan> plans;
  for (size_t i = 0; i < styles.size(); ++i) {
    const ScheduleFrame& f = schedule.frames[i];
    FramePlan plan;
    plan.style = &styles[i];
    plan.number = f.number;
    plan.time = f.time;
    plan.hours_from_start = f.hours_from_start;
    plan.elevation_deg = f.elevation_deg;
    plan.azimuth_deg = f.azimuth_deg;
    plan.sun = f.sun_direction;
    plans.push_back(plan);
  }
  return BakeFrames(plans, &schedule, options);
}

}  // namespace skybake
