#include "skybake/pipeline/engine_files.h"

#include <filesystem>

#include "skybake/output/sha256.h"

namespace skybake {

std::vector<RgbaImage> RenderEngineImages(SkyRenderer& renderer, const glm::dvec3& sun, const SkyStyle& style) {
  std::vector<RgbaImage> images;
  const EnginePreset* preset = FindEnginePreset(style.output.engine);
  if (!preset) return images;
  for (const EngineImage& e : EngineImages(*preset, style.render.cube_size, style.render.latlong_height))
    images.push_back({e.width, e.height, renderer.RenderDirections(sun, e.directions), nullptr});
  return images;
}

std::vector<BakedFile> WriteEngineFiles(const SkyStyle& style, const std::vector<RgbaImage>& images,
                                        const ExrWriteOptions& exr, const std::string& out_dir,
                                        const std::vector<std::string>& names) {
  const EnginePreset* preset = FindEnginePreset(style.output.engine);
  if (!preset) return {};
  // Only the layout is needed here: the directions of a 1 x 1 bake.
  const std::vector<EngineImage> layout = EngineImages(*preset, 1, 1);
  std::vector<ExrFile> files;
  for (size_t i = 0; i < images.size(); ++i) {
    ExrWriteOptions options = exr;
    options.envmap = layout[i].envmap;
    options.attributes["skybake:engine"] = preset->title;
    options.attributes["skybake:engine_mapping"] = layout[i].mapping;
    options.attributes["skybake:engine_frame"] = preset->frame + "; " + preset->import;
    files.push_back({(std::filesystem::path(out_dir) / names[i]).string(), &images[i], options});
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
