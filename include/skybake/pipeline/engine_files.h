// The files of an engine preset (input/engine_preset.h): its images
// rendered at a frame's Sun and written beside the bake's own files.
#pragma once

#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "skybake/gpu/sky_renderer.h"
#include "skybake/input/engine_preset.h"
#include "skybake/output/bake_record.h"
#include "skybake/output/exr_io.h"

namespace skybake {

// Renders the images of the style's preset (EngineImages) at the frame's
// Sun: every texel along its direction, sun disc included as in the bake's
// other files.
std::vector<RgbaImage> RenderEngineImages(SkyRenderer& renderer, const glm::dvec3& sun, const SkyStyle& style);

// Encodes and writes them as EXRs named `names` (EngineFileNames) in
// `out_dir`, with the frame's options `exr` (scale, provenance) and the
// preset's attributes (skybake:engine, skybake:engine_mapping, envmap).
std::vector<BakedFile> WriteEngineFiles(const SkyStyle& style, const std::vector<RgbaImage>& images,
                                        const ExrWriteOptions& exr, const std::string& out_dir,
                                        const std::vector<std::string>& names);

}  // namespace skybake
