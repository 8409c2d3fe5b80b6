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

// The size of each image of the style's presets (EnginePresetsOf, each in
// EngineImages order) at the style's render.cube_size and
// render.latlong_height: faces N x N, a latlong 2H x H, a cube strip N x 6N;
// empty without a preset. For `skybake plan` and the resource estimate
// (budget.cc), without the directions.
struct EngineImageSize {
  std::string suffix;  // ENGINE_SUFFIX: "threejs_px", "blender_latlong", ...
  int width = 0, height = 0;
};
std::vector<EngineImageSize> PlanEngineImages(const SkyStyle& style);

// Renders the images of the style's presets (EnginePresetsOf, each in
// EngineImages order) at the frame's Sun with the frame's renderer (its
// LUTs, its sky): every texel along its direction, sun disc included as in
// the bake's other files. Several presets' images are the same render along
// their own directions.
std::vector<RgbaImage> RenderEngineImages(SkyRenderer& renderer, const glm::dvec3& sun, const SkyStyle& style);

// The half-float scale of a frame's engine files: the bake's own
// (`bake_scale`, found from the bake's other files alone, so that a preset
// never changes them) while their brightest value `max_value` fits in it,
// else that scale times the power of two that brings them within half range
// (HalfRangeScale with `overflow`: kRefuse throws). Their texels follow the
// engine's directions, not the bake's, so one of them can land nearer the
// centre of the sun disc than any texel of the bake's own files. Float
// files: `bake_scale`.
double EngineFileScale(double max_value, double bake_scale, PixelType pixel_type, OverflowPolicy overflow);

// Encodes and writes them as EXRs named `names` (EngineFileNames) in
// `out_dir`, with the frame's options `exr` (provenance; the scale of
// EngineFileScale over each preset's own images, in each file's
// skybake:scale) and each preset's attributes (skybake:engine,
// skybake:engine_mapping, envmap).
std::vector<BakedFile> WriteEngineFiles(const SkyStyle& style, const std::vector<RgbaImage>& images,
                                        const ExrWriteOptions& exr, const std::string& out_dir,
                                        const std::vector<std::string>& names);

}  // namespace skybake
