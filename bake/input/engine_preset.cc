#include "skybake/input/engine_preset.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include "skybake/model/envmap.h"
#include "skybake/input/frame_numbering.h"

namespace skybake {
namespace {

// How a preset's cube faces and panorama are looked up. A cube face texel
// is the Vulkan/OpenGL/D3D face table applied to the engine's lookup vector
// g; g = lookup(d) for skybake world direction d, a signed permutation
// (docs/engines.md gives each engine's source).
struct Layout {
  glm::dmat3 lookup{1.0};    // g = lookup * d
  std::vector<int> face_of;  // per file of EnginePreset::faces: the lookup-space face 0..5 it holds
  // Panorama: u = offset + atan2(d.a, d.b) / 2 pi (wrapped), top row along +Y.
  glm::dvec3 a{0.0}, b{0.0};
  double offset = 0.0;
  std::string latlong_mapping;
  std::string face_mapping;
};

constexpr double kPi = 3.14159265358979323846;

// Columns of a signed permutation, as images of skybake's +X, +Y, +Z.
glm::dmat3 Columns(glm::dvec3 x, glm::dvec3 y, glm::dvec3 z) { return glm::dmat3(x, y, z); }

const glm::dmat3 kMirrorX = Columns({-1, 0, 0}, {0, 1, 0}, {0, 0, 1});
// Unreal: glTF (x, y, z) is UE (x, z, y) (UE's glTF exporter, FGLTFConverterUtility::ConvertVector, inverted).
const glm::dmat3 kSwapYZ = Columns({1, 0, 0}, {0, 0, 1}, {0, 1, 0});

const std::vector<int> kFacesInOrder = {0, 1, 2, 3, 4, 5};

// Layout of each preset, by name.
Layout LayoutOf(const std::string& name) {
  Layout l;
  const std::string gl_faces = "OpenGL/Vulkan/D3D cube face table";
  if (name == "threejs") {
    // three.js samples a CubeTexture at (-x, y, z) (flipEnvMap = -1); equirectUv.
    l.lookup = kMirrorX;
    l.face_of = kFacesInOrder;
    l.face_mapping = "three.js CubeTexture: " + gl_faces + " at (flipEnvMap * x, y, z), flipEnvMap = -1";
    l.a = {0, 0, 1}, l.b = {1, 0, 0}, l.offset = 0.5;
    l.latlong_mapping = "three.js equirectUv: u = atan(z, x) / 2 pi + 0.5, v = asin(y) / pi + 0.5 (top row v = 1)";
  } else if (name == "babylon") {
    // Babylon's default left-handed scene: the glTF loader's root node turns
    // the scene half a turn about +Y and scales z by -1 (x negated overall).
    l.lookup = kMirrorX;
    l.face_of = {0, 2, 4, 1, 3, 5};  // px py pz nx ny nz
    l.face_mapping = "Babylon.js CubeTexture (left-handed scene, glTF root x mirrored): " + gl_faces;
  } else if (name == "unity") {
    // Unity (left-handed): glTF importers negate x.
    l.lookup = kMirrorX;
    l.face_of = {4, 5, 0, 1, 2, 3};  // Front [+Z], Back [-Z], Left [+X], Right [-X], Up [+Y], Down [-Y]
    l.face_mapping = "Unity cubemap faces (left-handed, glTF x negated): " + gl_faces;
  } else if (name == "unreal") {
    l.lookup = kSwapYZ;
    l.face_of = kFacesInOrder;
    l.face_mapping = "Unreal TextureCube (Z up, glTF (x, y, z) -> UE (x, z, y)): " + gl_faces;
    // TextureCompressorModule LookupLongLat: u = (1 + atan2(UE.x, -UE.y) / pi) / 2, v = acos(UE.z) / pi.
    l.a = {1, 0, 0}, l.b = {0, 0, -1}, l.offset = 0.5;
    l.latlong_mapping = "Unreal long-lat: u = (1 + atan2(x, -y) / pi) / 2, v = acos(z) / pi (UE axes, top row v = 0)";
  } else if (name == "godot") {
    // Godot sky shader: SKY_COORDS = (atan(x, -z) wrapped to [0, 2 pi), acos(y)) / (2 pi, pi).
    l.a = {1, 0, 0}, l.b = {0, 0, -1}, l.offset = 0.0;
    l.latlong_mapping = "Godot PanoramaSkyMaterial SKY_COORDS: u = atan(x, -z) / 2 pi (wrapped), v = acos(y) / pi";
  } else if (name == "blender") {
    // Cycles direction_to_equirectangular in Blender's Z-up frame (glTF
    // import: (x, y, z) -> (x, -z, y)): u = 0.5 - atan2(y_b, x_b) / 2 pi.
    l.a = {0, 0, 1}, l.b = {1, 0, 0}, l.offset = 0.5;
    l.latlong_mapping =
        "Blender equirectangular: u = 0.5 - atan2(y, x) / 2 pi, v = 1 - acos(z) / pi (Blender Z-up axes)";
  } else if (name == "filament") {
    // Filament samples cmgen's cube, which is skybake's Vulkan cube as is (docs/ibl.md, cmgen cross-check).
    l.face_of = kFacesInOrder;
    l.face_mapping = "Filament/cmgen cube (right-handed, +Y up): " + gl_faces;
  }
  return l;
}

glm::dvec3 UnitOf(glm::dvec3 v) { return glm::normalize(v); }

}  // namespace

namespace engine_lookup {

glm::dvec3 CubeTexel(int face, int x, int y, int size) { return VulkanCubeTexelDirection(face, x, y, size); }

glm::dvec3 EquirectTexel(int x, int y, int w, int h, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& up,
                         double offset) {
  const double u = (x + 0.5) / w;
  const double theta = kPi * (y + 0.5) / h;  // from the top row's pole
  const double longitude = 2.0 * kPi * (u - offset);
  return UnitOf(std::sin(theta) * (std::sin(longitude) * a + std::cos(longitude) * b) + std::cos(theta) * up);
}

}  // namespace engine_lookup

const std::vector<EnginePreset>& EnginePresets() {
  static const std::vector<EnginePreset> presets = {
      {"unity",
       "Unity",
       "left-handed, +Y up, +Z forward",
       "glTF importers (glTFast, UnityGLTF) negate x",
       {"Front", "Back", "Left", "Right", "Up", "Down"},
       false,
       false,
       "six EXR faces for the 6 Sided skybox or a cubemap's faces"},
      {"unreal",
       "Unreal Engine",
       "left-handed, +Z up, +X forward",
       "glTF (x, y, z) is UE (x, z, y)",
       {"px", "nx", "py", "ny", "pz", "nz"},
       true,
       false,
       "a long-lat EXR for the HDRI Backdrop or Sky Light; faces for a TextureCube"},
      {"godot",
       "Godot 4",
       "right-handed, +Y up, -Z forward",
       "glTF axes kept",
       {},
       true,
       false,
       "an EXR panorama for PanoramaSkyMaterial (Godot skies take panoramas, not cubemaps)"},
      {"blender",
       "Blender (Cycles, EEVEE)",
       "right-handed, +Z up, -Y forward",
       "glTF (x, y, z) is Blender (x, -z, y)",
       {},
       true,
       false,
       "an EXR equirect for the World's Environment Texture, default mapping"},
      {"threejs",
       "three.js",
       "right-handed, +Y up",
       "glTF axes kept",
       {"px", "nx", "py", "ny", "pz", "nz"},
       true,
       false,
       "an EXR equirect for EXRLoader (EquirectangularReflectionMapping); six EXR faces for a CubeTexture"},
      {"babylon",
       "Babylon.js",
       "left-handed, +Y up (default scene)",
       "the glTF loader's root node mirrors x",
       {"px", "py", "pz", "nx", "ny", "nz"},
       false,
       false,
       "six EXR faces in CubeTexture's file order px py pz nx ny nz"},
      {"filament",
       "Filament",
       "right-handed, +Y up",
       "glTF axes kept",
       {"px", "nx", "py", "ny", "pz", "nz"},
       false,
       false,
       "six EXR faces as cmgen writes them (and the IBL files of docs/ibl.md)"},
      {"exrenvmap",
       "OpenEXR envmap (exrenvmap, Imf::LatLongMap, Imf::CubeMap)",
       "right-handed, +Y up",
       "glTF axes kept",
       {},
       true,
       true,
       "ENVMAP_LATLONG and ENVMAP_CUBE EXRs (pixel centres on the edges, as OpenEXR defines)"},
  };
  return presets;
}

std::vector<std::string> EngineNames() {
  std::vector<std::string> names;
  for (const EnginePreset& p : EnginePresets()) names.push_back(p.name);
  return names;
}

const EnginePreset* FindEnginePreset(const std::string& name) {
  for (const EnginePreset& p : EnginePresets())
    if (p.name == name) return &p;
  return nullptr;
}

std::vector<std::string> SplitEngineList(const std::string& engine) {
  std::vector<std::string> names;
  size_t start = 0;
  while (true) {
    const size_t comma = engine.find(',', start);
    std::string name = engine.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    const size_t first = name.find_first_not_of(" \t"), last = name.find_last_not_of(" \t");
    names.push_back(first == std::string::npos ? std::string() : name.substr(first, last - first + 1));
    if (comma == std::string::npos) return names;
    start = comma + 1;
  }
}

std::vector<const EnginePreset*> EnginePresetsOf(const std::string& engine) {
  std::vector<const EnginePreset*> presets;
  for (const std::string& name : SplitEngineList(engine)) {
    const EnginePreset* preset = FindEnginePreset(name);
    if (preset && std::find(presets.begin(), presets.end(), preset) == presets.end()) presets.push_back(preset);
  }
  return presets;
}

std::vector<EngineImage> EngineImages(const EnginePreset& preset, int n, int h) {
  const Layout l = LayoutOf(preset.name);
  const glm::dmat3 to_skybake = glm::transpose(l.lookup);  // a signed permutation's inverse
  std::vector<EngineImage> images;
  for (size_t i = 0; i < preset.faces.size(); ++i) {
    EngineImage image{preset.faces[i], "face", n, n, -1, l.face_mapping + ", face " + CubeFaceLabel(l.face_of[i]), {}};
    image.directions.resize(size_t(n) * n);
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
        image.directions[size_t(y) * n + x] = to_skybake * engine_lookup::CubeTexel(l.face_of[i], x, y, n);
    images.push_back(std::move(image));
  }
  if (preset.latlong) {
    EngineImage image{"latlong", "latlong", 2 * h, h, -1, l.latlong_mapping, {}};
    image.directions.resize(size_t(2 * h) * h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < 2 * h; ++x)
        image.directions[size_t(y) * 2 * h + x] =
            preset.name == "exrenvmap" ? LatLongDirection(x, y, 2 * h, h)
                                       : engine_lookup::EquirectTexel(x, y, 2 * h, h, l.a, l.b, {0, 1, 0}, l.offset);
    if (preset.name == "exrenvmap") {
      image.envmap = 0;
      image.mapping = "OpenEXR Imf::LatLongMap";
    }
    images.push_back(std::move(image));
  }
  if (preset.cube_strip) {
    EngineImage image{"cube", "cube strip", n, 6 * n, 1, "OpenEXR Imf::CubeMap", CubeStripDirections(n)};
    images.push_back(std::move(image));
  }
  return images;
}

namespace {

// BASE_ENGINE_SUFFIX`number`.exr of each of `preset`'s images, in EngineImages order.
void AppendPresetFileNames(const EnginePreset& preset, const std::string& basename, const std::string& number,
                           std::vector<std::string>& names) {
  const std::string stem = basename + "_" + preset.name + "_";
  for (const std::string& face : preset.faces) names.push_back(stem + face + number + ".exr");
  if (preset.latlong) names.push_back(stem + "latlong" + number + ".exr");
  if (preset.cube_strip) names.push_back(stem + "cube" + number + ".exr");
}

}  // namespace

std::vector<std::string> EngineFileNames(const SkyStyle& style, int number_in_name, int number_width) {
  std::vector<std::string> names;
  const std::string number = FrameNumberSuffix(number_in_name, number_width);
  for (const EnginePreset* preset : EnginePresetsOf(style.output.engine))
    AppendPresetFileNames(*preset, style.output.basename, number, names);
  return names;
}

std::optional<std::string> EngineStyleError(const SkyStyle& style) {
  // BASE_FACE.exr of the bake's own faces must not be one of a preset's files.
  auto folded = [](std::string s) {
    for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
    return s;
  };
  for (const EnginePreset* preset : EnginePresetsOf(style.output.engine)) {
    std::vector<std::string> files;
    AppendPresetFileNames(*preset, style.output.basename, FrameNumberSuffix(0), files);
    for (const std::string& engine_file : files)
      for (const std::string& face : style.output.face_names)
        if (style.output.faces && folded(style.output.basename + "_" + face + ".exr") == folded(engine_file))
          return fmt::format("face name '{}' makes {}, a file of the {} preset: choose another face name", face,
                             engine_file, preset->name);
  }
  return std::nullopt;
}

std::optional<std::string> EngineFileBase(const std::string& file, int number_in_name, int number_width) {
  const std::string tail = FrameNumberSuffix(number_in_name, number_width) + ".exr";
  if (file.size() <= tail.size() || file.compare(file.size() - tail.size(), tail.size(), tail) != 0)
    return std::nullopt;
  const std::string stem = file.substr(0, file.size() - tail.size());
  for (const EnginePreset& p : EnginePresets()) {
    std::vector<std::string> suffixes = p.faces;
    if (p.latlong) suffixes.push_back("latlong");
    if (p.cube_strip) suffixes.push_back("cube");
    for (const std::string& s : suffixes) {
      const std::string end = "_" + p.name + "_" + s;
      if (stem.size() > end.size() && stem.compare(stem.size() - end.size(), end.size(), end) == 0)
        return stem.substr(0, stem.size() - end.size());
    }
  }
  return std::nullopt;
}

}  // namespace skybake
