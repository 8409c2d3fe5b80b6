// Per-engine output presets (`--engine NAME`, `[output] engine`): the sky
// written as the files one engine loads the right way up, with no manual
// step. Each preset is a list of images whose every texel is the sky along
// a direction of skybake's world (+Y up, right-handed, North = -Z, East =
// +X) chosen by the engine's own lookup formula, so the files are rendered
// for the engine directly, never resampled. docs/engines.md gives every
// convention with its source.
//
// The files come beside the bake's own (which keep OpenEXR's conventions):
// BASE_ENGINE_SUFFIX.NNNN.exr, one per image, in the order the engine loads
// them (three.js px nx py ny pz nz, Babylon px py pz nx ny nz, ...).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "skybake/input/frame_numbering.h"
#include "skybake/input/style.h"

namespace skybake {

// One image of a preset: its file suffix and the direction of every texel.
struct EngineImage {
  std::string suffix;  // "px", "Left", "latlong", ...
  std::string kind;    // "face" or "latlong" or "cube strip"
  int width = 0, height = 0;
  int envmap = -1;                     // EXR envmap attribute: -1 none, 0 latlong, 1 cube
  std::string mapping;                 // the lookup the texels follow, for the file's skybake:engine_mapping
  std::vector<glm::dvec3> directions;  // row-major from the top row, unit, skybake's world
};

struct EnginePreset {
  std::string name;                // as given to --engine
  std::string title;               // "three.js", "Blender (Cycles, EEVEE)"
  std::string frame;               // the engine's world frame: handedness, up, forward
  std::string import;              // how a glTF scene's axes land in the engine (the Sun light with them)
  std::vector<std::string> faces;  // file suffixes of its six faces in load order (empty: none)
  bool latlong = false;            // writes an equirect panorama
  bool cube_strip = false;         // writes an OpenEXR cube strip (exrenvmap)
  std::string formats;             // what the engine reads of what skybake writes
};

// Every preset, in --help order.
const std::vector<EnginePreset>& EnginePresets();
std::vector<std::string> EngineNames();  // "unity", "unreal", ...
const EnginePreset* FindEnginePreset(const std::string& name);

// The names of an `output.engine` value: "none" (no preset), or one or more
// preset names separated by commas ("threejs,babylon"; `--engine` repeated
// or given a list), spaces around a name ignored, in the order given.
std::vector<std::string> SplitEngineList(const std::string& engine);
// The presets `engine` (an `output.engine` value the style check accepted)
// names, in its order, each once; empty for "none". Every preset's files come
// from the same frame's renderer (engine_files.h).
std::vector<const EnginePreset*> EnginePresetsOf(const std::string& engine);

// The images of `preset` for a bake of face size `cube_size` and latlong
// height `latlong_height` (the latlong is 2h x h).
std::vector<EngineImage> EngineImages(const EnginePreset& preset, int cube_size, int latlong_height);

// The file names of a frame's engine images (FrameNumberSuffix numbering),
// preset by preset in EnginePresetsOf order, each in EngineImages order;
// empty when no preset is set.
std::vector<std::string> EngineFileNames(const SkyStyle& style, int number_in_name,
                                         int number_width = kFrameNumberMinDigits);

// What is wrong with the style's presets and the rest of its outputs (a face
// name that is one of a preset's files), or nothing.
std::optional<std::string> EngineStyleError(const SkyStyle& style);

// A manifest's engine file of a frame: BASE_ENGINE_SUFFIX.NNNN.exr for a
// known preset and suffix. Returns the BASE, or nothing when the name is not
// one skybake gives.
std::optional<std::string> EngineFileBase(const std::string& file, int number_in_name,
                                          int number_width = kFrameNumberMinDigits);

// The engines' own lookups, written from their sources (docs/engines.md),
// used to build the images above.
namespace engine_lookup {
// Vulkan / OpenGL / D3D cube face texel centre (x, y) of face 0..5 (+X -X +Y
// -Y +Z -Z) as a direction of the space the cube is sampled in.
glm::dvec3 CubeTexel(int face, int x, int y, int size);
// Equirect texel centre (x, y) of a w x h image whose u = offset +
// atan2(dot(d, a), dot(d, b)) / 2 pi (wrapped) and top row along `up`.
glm::dvec3 EquirectTexel(int x, int y, int w, int h, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& up,
                         double offset);
}  // namespace engine_lookup

}  // namespace skybake
