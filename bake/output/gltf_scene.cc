#include "skybake/output/gltf_scene.h"

#include "skybake/base/file_door.h"
#include "skybake/output/gltf_ibl.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <sstream>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <glm/gtx/quaternion.hpp>
#include <nlohmann/json.hpp>

#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#define TINYGLTF_NO_INCLUDE_JSON
#include <tiny_gltf.h>

#include "skybake/model/spectrum.h"
#include "skybake/model/tonemap.h"
#include "skybake/output/exr_io.h"
#include "skybake/output/exr_read.h"
#include "skybake/output/json_spool.h"

namespace skybake {
namespace {

using nlohmann::json;

// Appends `bytes` to the buffer, 4-byte aligned, and returns the new bufferView.
int AddBufferView(tinygltf::Model& model, const void* bytes, size_t size, int target) {
  std::vector<unsigned char>& data = model.buffers[0].data;
  while (data.size() % 4) data.push_back(0);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = data.size();
  view.byteLength = size;
  view.target = target;
  const unsigned char* p = static_cast<const unsigned char*>(bytes);
  data.insert(data.end(), p, p + size);
  model.bufferViews.push_back(view);
  return int(model.bufferViews.size() - 1);
}

int AddAccessor(tinygltf::Model& model, int view, int component, size_t count, int type, std::vector<double> min = {},
                std::vector<double> max = {}) {
  tinygltf::Accessor a;
  a.bufferView = view;
  a.componentType = component;
  a.count = count;
  a.type = type;
  a.minValues = std::move(min);
  a.maxValues = std::move(max);
  model.accessors.push_back(a);
  return int(model.accessors.size() - 1);
}

// The scene's extras hold this string until the texts are written.
constexpr const char* kExtrasPlaceholder = "\x01skybake provenance\x01";

tinygltf::Value ToValue(const json& j) {
  if (j.is_object()) {
    tinygltf::Value::Object o;
    for (auto it = j.begin(); it != j.end(); ++it) o[it.key()] = ToValue(it.value());
    return tinygltf::Value(std::move(o));
  }
  if (j.is_array()) {
    tinygltf::Value::Array a;
    for (const json& item : j) a.push_back(ToValue(item));
    return tinygltf::Value(std::move(a));
  }
  if (j.is_boolean()) return tinygltf::Value(j.get<bool>());
  if (j.is_number_integer()) return tinygltf::Value(int(j.get<int64_t>()));
  if (j.is_number()) return tinygltf::Value(j.get<double>());
  if (j.is_string()) return tinygltf::Value(j.get<std::string>());
  return tinygltf::Value();
}

// Vertex positions (with the bounds glTF requires of them), normals, texture
// coordinates and triangle indices, each in a bufferView of its own.
int AddPositions(tinygltf::Model& model, const std::vector<glm::vec3>& positions) {
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const glm::vec3& p : positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  return AddAccessor(model, AddBufferView(model, positions.data(), positions.size() * 12, TINYGLTF_TARGET_ARRAY_BUFFER),
                     TINYGLTF_COMPONENT_TYPE_FLOAT, positions.size(), TINYGLTF_TYPE_VEC3, {lo.x, lo.y, lo.z},
                     {hi.x, hi.y, hi.z});
}

int AddNormals(tinygltf::Model& model, const std::vector<glm::vec3>& normals) {
  return AddAccessor(model, AddBufferView(model, normals.data(), normals.size() * 12, TINYGLTF_TARGET_ARRAY_BUFFER),
                     TINYGLTF_COMPONENT_TYPE_FLOAT, normals.size(), TINYGLTF_TYPE_VEC3);
}

int AddTexcoords(tinygltf::Model& model, const std::vector<glm::vec2>& uvs) {
  return AddAccessor(model, AddBufferView(model, uvs.data(), uvs.size() * 8, TINYGLTF_TARGET_ARRAY_BUFFER),
                     TINYGLTF_COMPONENT_TYPE_FLOAT, uvs.size(), TINYGLTF_TYPE_VEC2);
}

int AddIndices(tinygltf::Model& model, const std::vector<uint32_t>& indices) {
  return AddAccessor(model,
                     AddBufferView(model, indices.data(), indices.size() * 4, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER),
                     TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, indices.size(), TINYGLTF_TYPE_SCALAR);
}

// A PNG by file name, its sampler (linear, `wrap` on both axes) and the
// texture joining them; returns the texture.
int AddTexture(tinygltf::Model& model, const std::string& name, const std::string& uri, int wrap) {
  tinygltf::Image image;
  image.name = name;
  image.uri = uri;
  image.mimeType = "image/png";
  model.images.push_back(image);
  tinygltf::Sampler sampler;
  sampler.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
  sampler.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
  sampler.wrapS = sampler.wrapT = wrap;
  model.samplers.push_back(sampler);
  tinygltf::Texture texture;
  texture.source = int(model.images.size()) - 1;
  texture.sampler = int(model.samplers.size()) - 1;
  model.textures.push_back(texture);
  return int(model.textures.size()) - 1;
}

// A rough, non-metallic material whose base colour is `texture`; `unlit`:
// KHR_materials_unlit (the sky dome shows its texture as it is). Returns it.
int AddMaterial(tinygltf::Model& model, const std::string& name, int texture, bool unlit) {
  tinygltf::Material material;
  material.name = name;
  material.pbrMetallicRoughness.baseColorTexture.index = texture;
  material.pbrMetallicRoughness.metallicFactor = 0.0;
  material.pbrMetallicRoughness.roughnessFactor = 1.0;
  if (unlit) material.extensions["KHR_materials_unlit"] = tinygltf::Value(tinygltf::Value::Object());
  model.materials.push_back(material);
  return int(model.materials.size()) - 1;
}

// A mesh of one triangle primitive and the node that places it, both named
// `name`; returns the node.
int AddMeshNode(tinygltf::Model& model, const std::string& name, tinygltf::Primitive primitive) {
  primitive.mode = TINYGLTF_MODE_TRIANGLES;
  tinygltf::Mesh mesh;
  mesh.name = name;
  mesh.primitives.push_back(primitive);
  model.meshes.push_back(mesh);
  tinygltf::Node node;
  node.name = name;
  node.mesh = int(model.meshes.size()) - 1;
  model.nodes.push_back(node);
  return int(model.nodes.size()) - 1;
}

// The texture PNG through the door (file_door.h): a regular file of the
// folder, never read through a link; at most 1 GiB (a 16384 x 8192 RGB PNG
// stored raw is 384 MiB).
std::string ReadFile(const std::string& path) {
  std::string bytes;
  if (const std::string problem = ReadRegularFile(path, uint64_t(1) << 30, FileLinks::kRefuse, bytes); !problem.empty())
    throw OutputError(fmt::format("cannot read {} for the glTF scene: it {}", path, problem));
  return bytes;
}

// The ground plane under the dome (gltf_scene.h "ground"): a square at the
// receiver altitude over the cloud shadow map's extent, UV (0, 0) at the
// map's north-west corner (row 0, column 0), u along its axis_u (east),
// v along axis_v (south); normal +Y, counter-clockwise seen from above.
void AddCloudShadowGround(const SceneDescription& scene, tinygltf::Model& model, tinygltf::Scene& gltf_scene) {
  const CloudShadowInfo& g = *scene.ground;
  const glm::dvec3 o(g.origin_m[0], g.origin_m[1], g.origin_m[2]);
  const glm::dvec3 u = glm::dvec3(g.axis_u[0], g.axis_u[1], g.axis_u[2]) * g.extent_m;
  const glm::dvec3 v = glm::dvec3(g.axis_v[0], g.axis_v[1], g.axis_v[2]) * g.extent_m;
  const glm::vec3 corners[4] = {glm::vec3(o), glm::vec3(o + u), glm::vec3(o + v), glm::vec3(o + u + v)};
  const std::vector<glm::vec3> positions(corners, corners + 4);
  const std::vector<glm::vec3> normals(4, glm::vec3(0.0f, 1.0f, 0.0f));
  const std::vector<glm::vec2> uvs = {{0.0f, 0.0f}, {1.0f, 0.0f}, {0.0f, 1.0f}, {1.0f, 1.0f}};
  const std::vector<uint32_t> indices = {0, 2, 3, 0, 3, 1};
  tinygltf::Primitive primitive;
  primitive.attributes["POSITION"] = AddPositions(model, positions);
  primitive.attributes["NORMAL"] = AddNormals(model, normals);
  primitive.attributes["TEXCOORD_0"] = AddTexcoords(model, uvs);
  primitive.indices = AddIndices(model, indices);
  // A map that tiles repeats beyond its edges; one that does not is clamped.
  const int texture = AddTexture(model, "cloud_shadow", scene.ground_texture_file,
                                 g.tiles ? TINYGLTF_TEXTURE_WRAP_REPEAT : TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE);
  primitive.material = AddMaterial(model, "cloud_shadow_ground", texture, false);
  gltf_scene.nodes.push_back(AddMeshNode(model, "cloud_shadow_ground", primitive));
}

// EXT_lights_image_based: the RGBD faces as images (by file name; the .glb
// embeds them), the SH times the PNGs' scale k, intensity 1 / k, and the
// scene's reference to the light (gltf_ibl.h).
void AddImageBasedLight(const SceneDescription& scene, tinygltf::Model& model, tinygltf::Scene& gltf_scene) {
  const double k = GltfIblScale(scene.ibl_sh);
  const int size = PngWidth(ReadFile((std::filesystem::path(scene.out_dir) / scene.ibl_images[0]).string()));
  if (size <= 0) throw OutputError(fmt::format("{} is not a PNG", scene.ibl_images[0]));
  json levels = json::array();
  for (size_t level = 0; level * 6 < scene.ibl_images.size(); ++level) {
    json faces = json::array();
    for (size_t face = 0; face < 6; ++face) {
      tinygltf::Image image;
      image.name = scene.ibl_images[level * 6 + face];
      image.uri = scene.ibl_images[level * 6 + face];
      image.mimeType = "image/png";
      faces.push_back(int(model.images.size()));
      model.images.push_back(image);
    }
    levels.push_back(faces);
  }
  json coefficients = json::array();
  for (const Rgb& c : scene.ibl_sh) coefficients.push_back({c[0] * k, c[1] * k, c[2] * k});
  json light = {{"name", scene.name + " sky"},      {"intensity", 1.0 / k},
                {"rotation", {0.0, 0.0, 0.0, 1.0}}, {"irradianceCoefficients", coefficients},
                {"specularImageSize", size},        {"specularImages", levels}};
  model.extensions["EXT_lights_image_based"] = ToValue(json{{"lights", json::array({light})}});
  model.extensionsUsed.push_back("EXT_lights_image_based");
  gltf_scene.extensions["EXT_lights_image_based"] = ToValue(json{{"light", 0}});
}

}  // namespace

glm::dvec2 LatLongUvFromDirection(const glm::dvec3& d, int w, int h) {
  // Inverse of Imf::LatLongMap::direction: pixel x = (0.5 - lon / 2pi)(w - 1),
  // y = (0.5 - lat / pi)(h - 1); texel x's centre is at u = (x + 0.5) / w.
  glm::dvec3 n = glm::normalize(d);
  double lat = std::asin(std::clamp(n.y, -1.0, 1.0));
  double lon = std::atan2(n.x, n.z);
  double x = (0.5 - lon / (2.0 * M_PI)) * (w - 1);
  double y = (0.5 - lat / M_PI) * (h - 1);
  return {(x + 0.5) / w, (y + 0.5) / h};
}

DomeMesh BuildDome(const GltfSettings& settings, int w, int h) {
  DomeMesh mesh;
  const int segments = settings.segments;
  const int rings_full = segments / 2;  // pole to pole
  const int rings = settings.dome == DomeShape::kHemisphere ? rings_full / 2 : rings_full;
  const double vertical = settings.radius_m * (1.0 - settings.flattening);
  // Vertex (i, j): latitude pi/2 - i pi / rings_full, longitude pi - 2 pi j / segments.
  // Column j = segments repeats j = 0 at the other edge of the texture.
  for (int i = 0; i <= rings; ++i) {
    double lat = M_PI / 2.0 - M_PI * i / rings_full;
    for (int j = 0; j <= segments; ++j) {
      double lon = M_PI - 2.0 * M_PI * j / segments;
      if (i == 0 || i == rings_full) lon = M_PI - 2.0 * M_PI * (j + 0.5) / segments;  // pole: mid-column
      glm::dvec3 d(std::sin(lon) * std::cos(lat), std::sin(lat), std::cos(lon) * std::cos(lat));
      if (i == 0) d = {0.0, 1.0, 0.0};
      if (i == rings_full) d = {0.0, -1.0, 0.0};
      // Texture coordinates from latitude and longitude directly, so the seam
      // columns get u at the left (lon +pi) and right (lon -pi) edges.
      double x = (0.5 - lon / (2.0 * M_PI)) * (w - 1);
      double y = (0.5 - lat / M_PI) * (h - 1);
      mesh.uvs.push_back(glm::vec2(float((x + 0.5) / w), float((y + 0.5) / h)));
      mesh.directions.push_back(d);
      mesh.positions.push_back(
          glm::vec3(float(settings.radius_m * d.x), float(vertical * d.y), float(settings.radius_m * d.z)));
    }
  }
  const int columns = segments + 1;
  auto add = [&](uint32_t a, uint32_t b, uint32_t c) {
    // Counter-clockwise seen from the centre: the face normal points inwards.
    glm::dvec3 pa = mesh.directions[a], pb = mesh.directions[b], pc = mesh.directions[c];
    glm::dvec3 normal = glm::cross(pb - pa, pc - pa);
    if (glm::dot(normal, pa + pb + pc) > 0.0) std::swap(b, c);
    mesh.indices.insert(mesh.indices.end(), {a, b, c});
  };
  for (int i = 0; i < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      uint32_t a = uint32_t(i * columns + j), b = a + 1;
      uint32_t c = uint32_t((i + 1) * columns + j), d = c + 1;
      if (i != 0) add(a, c, b);               // no degenerate triangle at the top pole
      if (i + 1 != rings_full) add(b, c, d);  // nor at the bottom pole
    }
  }
  return mesh;
}

glm::dquat SunNodeRotation(const glm::dvec3& sun_direction) {
  return glm::rotation(glm::dvec3(0.0, 0.0, 1.0), glm::normalize(sun_direction));
}

namespace {

// A KHR_lights_punctual directional light of `sun`'s illuminance (lux) and
// colour, and the node that turns it (its -Z along the sun's direction);
// returns the node. Clients light with colour x intensity (three.js,
// Babylon.js, Blender's importer, Filament), so the illuminance they apply
// is intensity x Y(colour); the colour's brightest channel is 1 (glTF keeps
// colours in [0, 1]), so the intensity is the illuminance / Y(colour): the
// Sun's lux at Y(colour) = 0.85 would otherwise light a scene 15% short
// (EngineThreejsTest.SkyAndSunShowOneExposure and its Babylon.js and Blender
// twins).
int AddDirectionalLight(tinygltf::Model& model, const std::string& name, const SceneSun& sun) {
  tinygltf::Light light;
  light.name = name;
  light.type = "directional";
  const double y = Rec709Luminance({sun.color[0], sun.color[1], sun.color[2]});
  light.intensity = y > 0.0 ? sun.illuminance_lux / y : 0.0;
  light.color = {sun.color[0], sun.color[1], sun.color[2]};
  model.lights.push_back(light);
  tinygltf::Node node;
  node.name = name;
  const glm::dquat q = SunNodeRotation(sun.direction);
  node.rotation = {q.x, q.y, q.z, q.w};
  tinygltf::Value::Object light_ref;
  light_ref["light"] = tinygltf::Value(int(model.lights.size()) - 1);
  node.extensions["KHR_lights_punctual"] = tinygltf::Value(light_ref);
  model.nodes.push_back(node);
  return int(model.nodes.size()) - 1;
}

// The accessors of a rotation track: one key per light direction, at its
// time (s); the input holds the times, the output the quaternions.
struct RotationKeys {
  int input = -1, output = -1;
};

RotationKeys AddRotationKeys(tinygltf::Model& model, const std::vector<SceneSun>& keys) {
  std::vector<float> times, rotations;
  for (const SceneSun& k : keys) {
    // glTF wants a sampler's times strictly increasing; distinct times in
    // double can round to one float32 (frames seconds apart a year in,
    // hours_from_start near 1e4): such a key is spaced to the next float
    // after its predecessor (a shift of at most a few float32 ulps, about
    // 1e-3 h a year in), never dropped or refused.
    float t = float(k.time_s);
    if (!times.empty() && !(t > times.back())) t = std::nextafter(times.back(), HUGE_VALF);
    times.push_back(t);
    const glm::dquat q = SunNodeRotation(k.direction);
    rotations.insert(rotations.end(), {float(q.x), float(q.y), float(q.z), float(q.w)});
  }
  // Keep consecutive quaternions in one hemisphere so interpolation takes the short way.
  for (size_t k = 4; k < rotations.size(); k += 4) {
    float dot = 0;
    for (int c = 0; c < 4; ++c) dot += rotations[k + c] * rotations[k - 4 + c];
    if (dot < 0)
      for (int c = 0; c < 4; ++c) rotations[k + c] = -rotations[k + c];
  }
  RotationKeys track;
  track.input =
      AddAccessor(model, AddBufferView(model, times.data(), times.size() * 4, 0), TINYGLTF_COMPONENT_TYPE_FLOAT,
                  times.size(), TINYGLTF_TYPE_SCALAR, {times.front()}, {times.back()});
  track.output = AddAccessor(model, AddBufferView(model, rotations.data(), rotations.size() * 4, 0),
                             TINYGLTF_COMPONENT_TYPE_FLOAT, times.size(), TINYGLTF_TYPE_VEC4);
  // Animation data is not vertex data: no target.
  model.bufferViews[model.accessors[track.input].bufferView].target = 0;
  model.bufferViews[model.accessors[track.output].bufferView].target = 0;
  return track;
}

// Animates `node`'s rotation by `track`: a sampler and a channel in the
// scene's one animation, made (and named `name`) if there is none yet.
// A linear sampler of the scene's one animation from accessors `input`
// (times) and `output` (values), and a channel of it with no target yet.
tinygltf::AnimationChannel& AddLinearChannel(tinygltf::Model& model, int input, int output) {
  tinygltf::Animation& animation = model.animations.front();
  tinygltf::AnimationSampler sampler;
  sampler.input = input;
  sampler.output = output;
  sampler.interpolation = "LINEAR";
  animation.samplers.push_back(sampler);
  tinygltf::AnimationChannel channel;
  channel.sampler = int(animation.samplers.size()) - 1;
  animation.channels.push_back(channel);
  return animation.channels.back();
}

void AnimateRotation(tinygltf::Model& model, const std::string& name, const RotationKeys& track, int node) {
  if (model.animations.empty()) {
    tinygltf::Animation animation;
    animation.name = name;
    model.animations.push_back(animation);
  }
  tinygltf::AnimationChannel& channel = AddLinearChannel(model, track.input, track.output);
  channel.target_node = node;
  channel.target_path = "rotation";
}

// The light that `node` carries (KHR_lights_punctual), by index.
int LightOfNode(const tinygltf::Model& model, int node) {
  return model.nodes.at(size_t(node)).extensions.at("KHR_lights_punctual").Get("light").GetNumberAsInt();
}

// Animates `property` of light `light` (KHR_animation_pointer) by the keys in
// `values` (`components` floats a key) at the times of accessor `times`.
// Core glTF animates nodes only; a channel whose target is a pointer names
// no node (WithoutPlaceholderNodes removes the placeholder tinygltf writes).
void AnimateLightProperty(tinygltf::Model& model, int light, const std::string& property, int times,
                          const std::vector<float>& values, int components) {
  const size_t count = values.size() / size_t(components);
  const int output =
      AddAccessor(model, AddBufferView(model, values.data(), values.size() * 4, 0), TINYGLTF_COMPONENT_TYPE_FLOAT,
                  count, components == 1 ? TINYGLTF_TYPE_SCALAR : TINYGLTF_TYPE_VEC3);
  model.bufferViews[model.accessors[output].bufferView].target = 0;
  tinygltf::AnimationChannel& channel = AddLinearChannel(model, times, output);
  channel.target_path = "pointer";
  tinygltf::Value::Object pointer;
  pointer["pointer"] = tinygltf::Value(fmt::format("/extensions/KHR_lights_punctual/lights/{}/{}", light, property));
  channel.target_extensions["KHR_animation_pointer"] = tinygltf::Value(pointer);
}

// A light's path over a sequence: its node's rotation, and its intensity
// and colour per frame (intensity x Y(colour) is the frame's illuminance,
// as AddDirectionalLight writes it), one key a frame.
void AnimateLight(tinygltf::Model& model, const std::string& name, const std::vector<SceneSun>& keys, int node) {
  const RotationKeys track = AddRotationKeys(model, keys);
  AnimateRotation(model, name, track, node);
  std::vector<float> intensities, colours;
  for (const SceneSun& k : keys) {
    const double y = Rec709Luminance({k.color[0], k.color[1], k.color[2]});
    intensities.push_back(float(y > 0.0 ? k.illuminance_lux / y : 0.0));
    colours.insert(colours.end(), {float(k.color[0]), float(k.color[1]), float(k.color[2])});
  }
  const int light = LightOfNode(model, node);
  AnimateLightProperty(model, light, "intensity", track.input, intensities, 1);
  AnimateLightProperty(model, light, "color", track.input, colours, 3);
  if (std::find(model.extensionsUsed.begin(), model.extensionsUsed.end(), "KHR_animation_pointer") ==
      model.extensionsUsed.end())
    model.extensionsUsed.push_back("KHR_animation_pointer");
}

// The Moon: light 1, node 2, its path in the animation (a second one when
// the Sun has none).
void AddMoonLight(tinygltf::Model& model, const std::vector<SceneSun>& moons, tinygltf::Scene& gltf_scene) {
  size_t brightest = 0;
  for (size_t i = 1; i < moons.size(); ++i)
    if (moons[i].illuminance_lux > moons[brightest].illuminance_lux) brightest = i;
  const int node = AddDirectionalLight(model, "moon", moons[brightest]);
  gltf_scene.nodes.push_back(node);
  if (moons.size() < 2) return;
  AnimateLight(model, "moon_path", moons, node);
}

// The sky dome, mesh 0 and node 0: its geometry and the tone-mapped sRGB
// latlong as its unlit texture (texture 0), clamped, so the seam columns at
// u = 0.5 / width and 1 - 0.5 / width never blend with each other.
void AddSkyDome(const SceneDescription& scene, tinygltf::Model& model) {
  const DomeMesh dome = BuildDome(scene.dome, scene.texture_width, scene.texture_height);
  tinygltf::Primitive primitive;
  primitive.attributes["POSITION"] = AddPositions(model, dome.positions);
  primitive.attributes["TEXCOORD_0"] = AddTexcoords(model, dome.uvs);
  primitive.indices = AddIndices(model, dome.indices);
  const int texture = AddTexture(model, "sky", scene.texture_file, TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE);
  primitive.material = AddMaterial(model, "sky_unlit", texture, true);
  AddMeshNode(model, "skydome", primitive);
}

// The sun, light 0 and node 1, at the scene's light frame; with more than
// one frame its path as the animation "sun_path", one key a frame.
void AddSun(const SceneDescription& scene, tinygltf::Model& model) {
  const int node = AddDirectionalLight(model, "sun", scene.suns.at(size_t(scene.light_frame)));
  if (scene.suns.size() > 1) AnimateLight(model, "sun_path", scene.suns, node);
}

// The whole scene: dome, sun, and what the bake adds (image-based light,
// Moon, cloud shadow ground), with the units and frame in the asset's extras.
tinygltf::Model BuildSceneModel(const SceneDescription& scene) {
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "skybake " SKYBAKE_VERSION;
  model.extensionsUsed = {"KHR_materials_unlit", "KHR_lights_punctual"};
  model.extensionsRequired = {};
  model.buffers.resize(1);
  AddSkyDome(scene, model);
  AddSun(scene, model);

  tinygltf::Scene gltf_scene;
  gltf_scene.name = scene.name;
  gltf_scene.nodes = {0, 1};
  if (!scene.ibl_images.empty()) AddImageBasedLight(scene, model, gltf_scene);
  if (!scene.moons.empty()) AddMoonLight(model, scene.moons, gltf_scene);
  if (scene.ground) AddCloudShadowGround(scene, model, gltf_scene);
  // The provenance (one entry a frame) goes into the written texts in
  // place of this string (WriteGltfAndBin, WriteGlb), never into the model.
  gltf_scene.extras = ToValue(json{{"skybake", scene.extras_json.empty() ? json::object() : json(kExtrasPlaceholder)}});
  model.scenes.push_back(gltf_scene);
  model.defaultScene = 0;
  json asset_extras = {
      {"skybake",
       {{"units",
         {{"length", "metre"},
          {"sun_intensity", "lux (KHR_lights_punctual directional): intensity x Y(colour) is the illuminance"},
          {"texture", "tone-mapped sRGB preview of the latlong (exposure, ACES filmic, sRGB OETF)"}}},
        {"frame", "+Y up, right-handed, North -Z, East +X; sun light shines along its node's -Z"},
        {"texture_layout", "OpenEXR latlong (Imf::LatLongMap): u = 0 at longitude +pi, v = 0 at latitude +pi/2"}}}};
  model.asset.extras = ToValue(asset_extras);
  return model;
}

// `text` with the placeholder string (as JSON) replaced by `provenance`, its
// lines after the first indented as the placeholder's line (dump(2)), or
// not at all (`pretty` false: compact JSON).
std::string WithProvenance(const std::string& text, const std::string& provenance, bool pretty) {
  const std::string marker = json(kExtrasPlaceholder).dump();
  const size_t at = text.find(marker);
  if (at == std::string::npos) return text;  // no provenance (an empty extras_json)
  std::string indent;
  if (pretty) {
    const size_t line = text.rfind('\n', at) + 1;
    indent = text.substr(line, text.find_first_not_of(' ', line) - line);
  }
  return SplicedJson(text, marker, pretty ? IndentedJson(provenance, indent) : provenance);
}

// The channels whose target is a pointer (AnimateLightProperty) name no
// node: tinygltf writes every channel's node, -1 where it has none.
// Returns whether it changed `document`.
bool WithoutPlaceholderNodes(json& document) {
  bool changed = false;
  if (!document.contains("animations")) return false;
  for (json& animation : document["animations"])
    for (json& channel : animation["channels"]) {
      json& target = channel["target"];
      if (target.value("path", "") == "pointer" && target.contains("node")) {
        target.erase("node");
        changed = true;
      }
    }
  return changed;
}

// name.gltf + name.bin: the JSON references the .bin and the PNG by name.
void WriteGltfAndBin(tinygltf::TinyGLTF& writer, const tinygltf::Model& model, const SceneDescription& scene,
                     const WrittenScene& written) {
  std::string bin(model.buffers[0].data.begin(), model.buffers[0].data.end());
  std::ostringstream out;
  if (!writer.WriteGltfSceneToStream(&model, out, true, false))
    throw OutputError(fmt::format("cannot serialise {}", written.gltf_path));
  json document = json::parse(out.str());
  WithoutPlaceholderNodes(document);
  document["buffers"][0]["uri"] = scene.name + ".bin";
  WriteFileAtomically(written.bin_path, bin);
  const std::string pretty = scene.extras_json_pretty.empty() && !scene.extras_json.empty()
                                 ? json::parse(scene.extras_json).dump(2)
                                 : scene.extras_json_pretty;
  WriteFileAtomically(written.gltf_path, WithProvenance(document.dump(2) + "\n", pretty, true));
}

uint32_t ReadU32(const std::string& bytes, size_t at) {
  uint32_t v = 0;
  std::memcpy(&v, bytes.data() + at, 4);  // little-endian, as the hosts skybake runs on
  return v;
}

void PutU32(std::string& bytes, size_t at, uint32_t v) { std::memcpy(bytes.data() + at, &v, 4); }

// A GLB (header, JSON chunk padded with spaces to 4 bytes, BIN chunk) with
// the provenance in its JSON chunk, the lengths as tinygltf writes them.
std::string GlbWithProvenance(const std::string& glb, const std::string& provenance) {
  const uint32_t json_length = ReadU32(glb, 12);
  std::string content = glb.substr(20, json_length);
  content.erase(content.find_last_not_of(' ') + 1);  // the padding
  if (json document = json::parse(content); WithoutPlaceholderNodes(document)) content = document.dump();
  content = WithProvenance(content, provenance, false);
  content.append((4 - content.size() % 4) % 4, ' ');
  std::string out = glb.substr(0, 20) + content + glb.substr(20 + json_length);
  PutU32(out, 8, uint32_t(out.size()));
  PutU32(out, 12, uint32_t(content.size()));
  return out;
}

// name.glb: the PNGs move into the binary chunk.
void WriteGlb(tinygltf::TinyGLTF& writer, const tinygltf::Model& model, const std::filesystem::path& dir,
              const std::string& texture_file, const std::string& provenance, const std::string& glb_path) {
  std::string png = ReadFile((dir / texture_file).string());
  tinygltf::Model glb = model;
  glb.images[0].uri.clear();
  glb.images[0].bufferView = AddBufferView(glb, png.data(), png.size(), 0);
  for (size_t i = 1; i < glb.images.size(); ++i) {
    const std::string face = ReadFile((dir / glb.images[i].uri).string());
    glb.images[i].uri.clear();
    glb.images[i].bufferView = AddBufferView(glb, face.data(), face.size(), 0);
  }
  std::ostringstream out;
  if (!writer.WriteGltfSceneToStream(&glb, out, false, true))
    throw OutputError(fmt::format("cannot serialise {}", glb_path));
  WriteFileAtomically(glb_path, GlbWithProvenance(out.str(), provenance));
}

}  // namespace

SceneSun SceneMoonOf(const MoonRecord& moon, double time_s) {
  SceneSun s;
  s.time_s = time_s;
  s.direction = moon.direction;
  s.illuminance_lux = moon.illuminance_lux;
  const double peak = std::max({moon.irradiance[0], moon.irradiance[1], moon.irradiance[2]});
  if (peak > 0.0) s.color = {moon.irradiance[0] / peak, moon.irradiance[1] / peak, moon.irradiance[2] / peak};
  return s;
}

WrittenScene WriteGltfScene(const SceneDescription& scene) {
  const std::filesystem::path dir(scene.out_dir);
  WrittenScene written;
  written.gltf_path = (dir / (scene.name + ".gltf")).string();
  written.bin_path = (dir / (scene.name + ".bin")).string();
  written.glb_path = (dir / (scene.name + ".glb")).string();
  const tinygltf::Model model = BuildSceneModel(scene);
  tinygltf::TinyGLTF writer;
  writer.SetImageWriter(nullptr, nullptr);
  WriteGltfAndBin(writer, model, scene, written);
  WriteGlb(writer, model, dir, scene.texture_file, scene.extras_json, written.glb_path);
  return written;
}

void WriteCloudShadowGroundPng(const std::string& exr_path, const std::string& png_path) {
  // Through the door (exr_read.h): a FIFO, device or link planted at the
  // map's name is refused, not waited on or followed.
  int width = 0, height = 0;
  std::vector<float> rgba;
  if (const std::string problem = ReadExrRgba(exr_path, width, height, rgba); !problem.empty())
    throw OutputError(
        fmt::format("{}: cannot read the cloud shadow map for the glTF ground: it {}; bake its frame "
                    "again",
                    exr_path, problem));
  std::vector<uint8_t> rgb(size_t(width) * size_t(height) * 3);
  for (size_t i = 0; i < size_t(width) * size_t(height); ++i) {
    const double t = std::clamp(double(rgba[4 * i]), 0.0, 1.0);
    rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = uint8_t(std::lround(SrgbEncode(t) * 255.0));
  }
  WritePng(png_path, width, height, rgb);
}

}  // namespace skybake
