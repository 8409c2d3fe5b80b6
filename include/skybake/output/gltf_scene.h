// A glTF 2.0 scene of a bake: an inward-facing skydome textured with the
// tone-mapped latlong, and the sun as a directional light.
//
// Frame: glTF's and skybake's are the same: +Y up, right-handed, metres;
// North = -Z, East = +X. The dome's UVs follow the OpenEXR latlong layout
// of the texture (Imf::LatLongMap): pixel centre (0, 0) is latitude +pi/2,
// longitude +pi; direction = (sin(lon) cos(lat), sin(lat), cos(lon) cos(lat)).
// The seam (longitude +-pi, towards -Z) has two columns of vertices, one at
// each edge of the texture, so no triangle interpolates across it.
//
//   material  KHR_materials_unlit, baseColorTexture = the sRGB PNG (never
//             combined with KHR_materials_emissive_strength)
//   sun       KHR_lights_punctual directional light, lux, shining along the
//             node's -Z: the node is rotated so that +Z points at the Sun
//   sequence  a core node-rotation animation of the sun node, one key per
//             frame (1 s of animation per hour of clock time, else per frame)
//   moon      with the night sky's moonlight: a second directional light and
//             node "moon", animated the same way
//   ground    with [cloud_shadow]: node "cloud_shadow_ground", a horizontal
//             square at the map's receiver altitude over the map's extent,
//             its base colour the texture frame's cloud shadow map (NAME_ground.png,
//             sRGB-encoded transmittance; a lit, rough, non-metallic material)
//
// Files: name.gltf + name.bin beside the PNG, and name.glb with everything
// embedded. Provenance and units go in asset.extras and scene extras.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "skybake/input/output_settings.h"
#include "skybake/model/sh.h"
#include "skybake/input/astronomy.h"
#include "skybake/input/config.h"

namespace skybake {

struct DomeMesh {
  std::vector<glm::vec3> positions;    // metres
  std::vector<glm::vec2> uvs;          // glTF texture coordinates (origin top-left)
  std::vector<uint32_t> indices;       // triangles, counter-clockwise seen from inside
  std::vector<glm::dvec3> directions;  // unit direction of each vertex from the centre, before flattening
};

// The dome for a latlong texture of texture_width x texture_height.
DomeMesh BuildDome(const GltfSettings& settings, int texture_width, int texture_height);

// The UV (glTF, origin top-left, texel centres at (i + 0.5) / size) of the
// latlong texel that holds direction `d`.
glm::dvec2 LatLongUvFromDirection(const glm::dvec3& d, int texture_width, int texture_height);

// Rotation of a node whose -Z must shine along -sun_direction (towards the
// ground), i.e. whose +Z points at the Sun.
glm::dquat SunNodeRotation(const glm::dvec3& sun_direction);

struct SceneSun {
  double time_s = 0.0;            // animation time of this key
  glm::dvec3 direction{0, 1, 0};  // unit, towards the Sun
  double illuminance_lux = 0.0;   // transmitted sun at the observer
  Rgb color{1.0, 1.0, 1.0};       // linear Rec.709, max channel 1
};

struct SceneDescription {
  std::string name;  // base name: name.gltf, name.bin, name.glb
  std::string out_dir;
  std::string texture_file;  // the PNG, a file name inside out_dir
  int texture_width = 0;
  int texture_height = 0;
  GltfSettings dome;
  std::vector<SceneSun> suns;  // 1 for a bake, one per frame for a sequence
  int light_frame = 0;         // which sun sets the light's colour and intensity
  // The Moon as a second directional light (night.moonlight), one key per
  // frame that has it; its intensity and colour are the brightest key's
  // (a light's intensity is not animated in core glTF). Empty: no Moon.
  std::vector<SceneSun> moons;
  std::string extras_json;  // JSON object merged into the scene's extras (skybake provenance)
  // The same object as nlohmann's dump(2) writes it, or empty (then made
  // from extras_json): the writer puts the texts in place, never holding the
  // object in its JSON forms.
  std::string extras_json_pretty;
  // EXT_lights_image_based (gltf_ibl.h): levels x 6 RGBD PNGs in out_dir, level-major,
  // +X -X +Y -Y +Z -Z; none: no image-based light.
  std::vector<std::string> ibl_images;
  ShRgb ibl_sh{};  // E_lm of the sky without the Sun, the bake's units
  // The ground plane textured with a frame's cloud shadow map (cloud_shadow.h):
  // the PNG in out_dir and where the map lies. None: no ground plane.
  std::string ground_texture_file;
  std::optional<CloudShadowInfo> ground;
};

// The ground plane's texture: the transmittance of the cloud shadow map EXR
// at `exr_path` (its R channel), sRGB-encoded to 8-bit grey RGB so that a
// viewer's decoded base colour is the transmittance; written atomically to
// `png_path`. Throws OutputError.
void WriteCloudShadowGroundPng(const std::string& exr_path, const std::string& png_path);

// A frame's Moon as a light key: its direction, illuminance at the observer
// and colour (irradiance with the largest channel 1).
SceneSun SceneMoonOf(const MoonRecord& moon, double time_s);

struct WrittenScene {
  std::string gltf_path, bin_path, glb_path;
};

// Writes name.gltf (+ name.bin, referencing the PNG) and name.glb, each
// atomically. Throws OutputError.
WrittenScene WriteGltfScene(const SceneDescription& scene);

}  // namespace skybake
