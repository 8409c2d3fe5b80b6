#include "skybake/pipeline.h"

#include <chrono>
#include <filesystem>

#include <fmt/format.h>

#include "skybake/envmap.h"
#include "skybake/exr_io.h"
#include "skybake/tonemap.h"

namespace skybake {
namespace {

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

 private:
  using Clock = std::chrono::steady_clock;
  BakeResult& result_;
  const ProgressCallback& progress_;
  Clock::time_point start_;
};

std::string FormatVector(const glm::dvec3& v) { return fmt::format("{:.9g} {:.9g} {:.9g}", v.x, v.y, v.z); }

}  // namespace

std::vector<ViewRequest> PlanViews(const SkyStyle& style) {
  std::vector<ViewRequest> views;
  const int n = style.render.cube_size;
  if (style.output.faces)
    for (int face = 0; face < 6; ++face) views.push_back({MAPPING_VULKAN_FACE, n, n, face});
  if (style.output.cube_strip) views.push_back({MAPPING_CUBE_STRIP, n, 6 * n, 0});
  if (style.output.latlong || style.output.preview) {
    const int h = style.render.latlong_height;
    views.push_back({MAPPING_LATLONG, 2 * h, h, 0});
  }
  return views;
}

BakeResult BakeStyle(const SkyStyle& style, const BakeOptions& options) {
  BakeResult result;
  StageTimer timer(result, options.progress);

  // Device: headless Vulkan, best device or the one asked for.
  VulkanContext context(options.vulkan);
  timer.Finish("device", fmt::format("{} ({})", context.device_info().name, context.device_info().type));

  // Pipelines: compiled once, with the effects as specialization constants.
  // The hue principle acts on the atmosphere (its Rayleigh constants), the
  // other AOAS principles per texel; saturation is judged in Rec.709 luminance RGB.
  const Rgb output_scale = OutputScale(style.output.units);
  const AtmosphereParams atmosphere = StyledAtmosphere(style.atmosphere, style.aoas);
  const AoasInputs aoas = ToAoasInputs(style.aoas, OutputScale(OutputUnits::kLuminance));
  SkyRenderer renderer(context, atmosphere, style.quality, style.effects, output_scale, false, aoas);
  timer.Finish("pipelines");

  // LUTs: transmittance, then multiple scattering.
  renderer.PrecomputeLuts();
  for (const PassTiming& t : renderer.last_timings()) result.gpu_passes.push_back(t);
  timer.Finish("LUTs", fmt::format("transmittance {}x{}, multiple scattering {}x{}",
                                   style.quality.transmittance_width, style.quality.transmittance_height,
                                   style.quality.multiscattering_size, style.quality.multiscattering_size));

  // Render: every view of the frame in one submission.
  const glm::dvec3 sun = SunDirectionFromElevationAzimuth(style.sun.elevation_deg, style.sun.azimuth_deg);
  std::vector<ViewRequest> views = PlanViews(style);
  std::vector<std::vector<float>> pixels = renderer.Render(sun, views);
  for (const PassTiming& t : renderer.last_timings()) result.gpu_passes.push_back(t);
  size_t texels = 0;
  for (const ViewRequest& v : views) texels += size_t(v.width) * v.height;
  timer.Finish("render", fmt::format("{} views, {:.2f} Mtexels, {} steps per texel", views.size(),
                                     texels * 1e-6, style.quality.view_steps));

  std::vector<RgbaImage> images;
  for (size_t i = 0; i < views.size(); ++i)
    images.push_back({views[i].width, views[i].height, std::move(pixels[i])});
  std::vector<const RgbaImage*> all;
  for (const RgbaImage& image : images) all.push_back(&image);

  // Files: one scale for the whole bake, so faces, strip and latlong agree.
  std::filesystem::create_directories(options.out_dir);
  const double max_value = CheckedMaxValue(all);
  if (style.output.pixel_type == PixelType::kHalf)
    result.half_scale = HalfRangeScale(max_value, style.output.overflow);
  ExrWriteOptions exr;
  exr.pixel_type = style.output.pixel_type;
  exr.compression = style.output.compression;
  exr.scale = result.half_scale;
  const bool luminance = style.output.units == OutputUnits::kLuminance;
  if (luminance) exr.white_luminance = 1.0 / result.half_scale;
  exr.attributes = {
      {"skybake:version", SKYBAKE_VERSION},
      {"skybake:config", style.resolved_toml},
      {"skybake:source", style.source_path},
      {"skybake:units", luminance ? "linear Rec.709 luminance, cd/m^2 per 1.0 divided by skybake:scale"
                                  : "spectral radiance W m^-2 sr^-1 nm^-1 at 680/550/440 nm (R/G/B), "
                                    "divided by skybake:scale"},
      {"skybake:scale", fmt::format("{:.9g}", result.half_scale)},
      {"skybake:frame", "+Y up, North -Z, East +X; right-handed"},
      {"skybake:sun_direction", FormatVector(sun)},
  };
  auto path_of = [&](const std::string& suffix) {
    return (std::filesystem::path(options.out_dir) / (style.output.basename + suffix)).string();
  };
  size_t index = 0;
  if (style.output.faces) {
    for (int face = 0; face < 6; ++face, ++index) {
      ExrWriteOptions face_exr = exr;
      face_exr.attributes["skybake:cube_face"] = CubeFaceLabel(face);
      face_exr.attributes["skybake:face_orientation"] = "Vulkan cube map face (sc, tc) table";
      std::string path = path_of("_" + style.output.face_names[face] + ".exr");
      result.files.push_back({path, "face", WriteExr(path, images[index], face_exr)});
    }
  }
  if (style.output.cube_strip) {
    ExrWriteOptions cube_exr = exr;
    cube_exr.envmap = 1;  // ENVMAP_CUBE
    std::string path = path_of("_cube.exr");
    result.files.push_back({path, "cube", WriteExr(path, images[index], cube_exr)});
    ++index;
  }
  const RgbaImage* latlong = (style.output.latlong || style.output.preview) ? &images[index] : nullptr;
  if (style.output.latlong) {
    ExrWriteOptions latlong_exr = exr;
    latlong_exr.envmap = 0;  // ENVMAP_LATLONG
    std::string path = path_of("_latlong.exr");
    result.files.push_back({path, "latlong", WriteExr(path, *latlong, latlong_exr)});
  }
  timer.Finish("write EXR", fmt::format("{} files, {} compression, {}", result.files.size(),
                                        style.output.compression,
                                        style.output.pixel_type == PixelType::kHalf ? "half" : "float"));

  // Preview: exposure, ACES, sRGB. Exposure works in cd/m^2, so spectral
  // output is converted to luminance for the preview only.
  if (style.output.preview) {
    std::vector<float> display = latlong->rgba;
    if (!luminance) {
      Rgb to_luminance = OutputScale(OutputUnits::kLuminance);
      for (size_t i = 0; i < display.size(); ++i)
        if (i % 4 != 3) display[i] *= float(to_luminance[i % 4]);
    }
    result.preview_ev100 = style.preview.auto_exposure
                               ? AutoEv100(display, latlong->width, latlong->height)
                               : style.preview.ev100;
    std::vector<uint8_t> srgb = TonemapToSrgb8(display, latlong->width, latlong->height,
                                               ExposureFromEv100(result.preview_ev100));
    std::string path = path_of("_latlong.png");
    result.files.push_back({path, "preview", WritePng(path, latlong->width, latlong->height, srgb)});
    timer.Finish("preview", fmt::format("EV100 {:.2f}, ACES filmic, sRGB", result.preview_ev100));
  }
  result.counters = renderer.counters();
  result.validation_messages = context.validation_message_count();
  return result;
}

}  // namespace skybake
