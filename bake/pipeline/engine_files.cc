#include "skybake/pipeline/engine_files.h"

#include <filesystem>

#include <fmt/format.h>

#include "skybake/output/sha256.h"

namespace skybake {

std::vector<EngineImageSize> PlanEngineImages(const SkyStyle& style) {
  std::vector<EngineImageSize> sizes;
  const int n = style.render.cube_size, h = style.render.latlong_height;
  for (const EnginePreset* preset : EnginePresetsOf(style.output.engine))
    // The layout of a 1 x 1 bake (no directions worth computing): its kinds.
    for (const EngineImage& e : EngineImages(*preset, 1, 1))
      sizes.push_back({preset->name + "_" + e.suffix, e.kind == "latlong" ? 2 * h : n,
                       e.kind == "latlong"      ? h
                       : e.kind == "cube strip" ? 6 * n
                                                : n});
  return sizes;
}

std::vector<RgbaImage> RenderEngineImages(SkyRenderer& renderer, const glm::dvec3& sun, const SkyStyle& style) {
  std::vector<RgbaImage> images;
  for (const EnginePreset* preset : EnginePresetsOf(style.output.engine))
    for (const EngineImage& e : EngineImages(*preset, style.render.cube_size, style.render.latlong_height))
      images.push_back({e.width, e.height,
                        renderer.RenderDirections(sun, e.directions, style.output.sun == SunOutput::kMap), nullptr});
  return images;
}

double EngineFileScale(double max_value, double bake_scale, PixelType pixel_type, OverflowPolicy overflow) {
  if (pixel_type != PixelType::kHalf || max_value * bake_scale <= kHalfMax) return bake_scale;
  return bake_scale * HalfRangeScale(max_value * bake_scale, overflow);
}

std::vector<BakedFile> WriteEngineFiles(const SkyStyle& style, const std::vector<RgbaImage>& images,
                                        const ExrWriteOptions& exr, const std::string& out_dir,
                                        const std::vector<std::string>& names) {
  std::vector<ExrFile> files;
  size_t next = 0;  // the first image of the preset
  for (const EnginePreset* preset : EnginePresetsOf(style.output.engine)) {
    // Only the layout is needed here: the directions of a 1 x 1 bake.
    const std::vector<EngineImage> layout = EngineImages(*preset, 1, 1);
    if (next + layout.size() > images.size()) break;
    // Each preset's scale from its own images: its files are the same bytes
    // whichever other presets the bake writes beside it.
    std::vector<const RgbaImage*> own;
    for (size_t i = 0; i < layout.size(); ++i) own.push_back(&images[next + i]);
    const double scale = EngineFileScale(CheckedMaxValue(own), exr.scale, exr.pixel_type, style.output.overflow);
    for (size_t i = 0; i < layout.size(); ++i) {
      ExrWriteOptions options = exr;
      if (scale != exr.scale) {
        options.scale = scale;
        options.attributes["skybake:scale"] = fmt::format("{:.9g}", scale);
        if (exr.white_luminance > 0.0) options.white_luminance = 1.0 / scale;
      }
      options.envmap = layout[i].envmap;
      options.attributes["skybake:engine"] = preset->title;
      options.attributes["skybake:engine_mapping"] = layout[i].mapping;
      options.attributes["skybake:engine_frame"] = preset->frame + "; " + preset->import;
      files.push_back({(std::filesystem::path(out_dir) / names[next + i]).string(), &images[next + i], options});
    }
    next += layout.size();
  }
  const std::vector<std::string> encoded = EncodeExrs(files);
  std::vector<BakedFile> baked;
  for (size_t i = 0; i < files.size(); ++i) {
    WriteFileAtomically(files[i].name, encoded[i]);
    baked.push_back({files[i].name, "engine", encoded[i].size(), Sha256OfText(encoded[i])});
  }
  return baked;
}

}  // namespace skybake
