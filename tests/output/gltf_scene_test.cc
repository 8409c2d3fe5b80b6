// The skydome mesh and the sun node: geometry checked against OpenEXR's
// latlong mapping and glTF's light convention.
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <OpenEXR/ImfEnvmap.h>

#include "skybake/output/exr_io.h"
#include "skybake/output/gltf_scene.h"
#include "test_support.h"

namespace skybake {
namespace {

// Direction of the latlong texel position under glTF UV (u, v) by
// Imf::LatLongMap::direction (pixel centres at (i + 0.5) / size).
glm::dvec3 ImfDirectionAtUv(glm::dvec2 uv, int w, int h) {
  Imath::Box2i window(Imath::V2i(0, 0), Imath::V2i(w - 1, h - 1));
  Imath::V2f pixel(float(uv.x * w - 0.5), float(uv.y * h - 0.5));
  Imath::V3f d = Imf::LatLongMap::direction(window, pixel);
  return glm::normalize(glm::dvec3(d.x, d.y, d.z));
}

TEST(GltfScene, DomeUvsMatchTheLatlongLayout) {
  for (DomeShape shape : {DomeShape::kSphere, DomeShape::kHemisphere}) {
    GltfSettings settings;
    settings.dome = shape;
    settings.segments = 48;
    const int w = 128, h = 64;
    DomeMesh dome = BuildDome(settings, w, h);
    ASSERT_EQ(dome.uvs.size(), dome.directions.size());
    double worst = 0.0;
    for (size_t i = 0; i < dome.uvs.size(); ++i) {
      glm::dvec3 from_uv = ImfDirectionAtUv(glm::dvec2(dome.uvs[i]), w, h);
      worst = std::max(worst, glm::length(from_uv - dome.directions[i]));
      // Vertex position (without flattening) points the same way.
      EXPECT_LT(glm::length(glm::normalize(glm::dvec3(dome.positions[i])) - dome.directions[i]), 1e-6);
    }
    EXPECT_LT(worst, 1e-5) << "float UVs against Imf::LatLongMap";
    // Round trip through the inverse mapping.
    glm::dvec3 d = glm::normalize(glm::dvec3(0.3, 0.5, -0.8));
    EXPECT_LT(glm::length(ImfDirectionAtUv(LatLongUvFromDirection(d, w, h), w, h) - d), 1e-6);
  }
}

TEST(GltfScene, SeamHasTwoColumnsAtTheTextureEdges) {
  GltfSettings settings;
  settings.segments = 32;
  const int w = 64, h = 32;
  DomeMesh dome = BuildDome(settings, w, h);
  const int columns = settings.segments + 1;
  const int ring = 5;  // away from the poles
  glm::vec2 left = dome.uvs[ring * columns], right = dome.uvs[ring * columns + settings.segments];
  EXPECT_NEAR(left.x, 0.5 / w, 1e-6);         // longitude +pi, first texel centre
  EXPECT_NEAR(right.x, 1.0 - 0.5 / w, 1e-6);  // longitude -pi, last texel centre
  EXPECT_EQ(left.y, right.y);
  EXPECT_LT(glm::length(dome.directions[ring * columns] - dome.directions[ring * columns + settings.segments]), 1e-12);
  // No triangle spans more than one column of the texture.
  for (size_t t = 0; t < dome.indices.size(); t += 3) {
    float umin = 1, umax = 0;
    for (int k = 0; k < 3; ++k) {
      umin = std::min(umin, dome.uvs[dome.indices[t + k]].x);
      umax = std::max(umax, dome.uvs[dome.indices[t + k]].x);
    }
    EXPECT_LT(umax - umin, 1.5f / settings.segments) << "triangle " << t / 3;
  }
}

TEST(GltfScene, DomeFacesInwards) {
  GltfSettings settings;
  settings.segments = 24;
  DomeMesh dome = BuildDome(settings, 48, 24);
  ASSERT_FALSE(dome.indices.empty());
  for (size_t t = 0; t < dome.indices.size(); t += 3) {
    glm::dvec3 a(dome.positions[dome.indices[t]]), b(dome.positions[dome.indices[t + 1]]),
        c(dome.positions[dome.indices[t + 2]]);
    glm::dvec3 normal = glm::cross(b - a, c - a);  // counter-clockwise front face
    ASSERT_GT(glm::length(normal), 0.0) << "degenerate triangle " << t / 3;
    EXPECT_LT(glm::dot(normal, a + b + c), 0.0) << "triangle " << t / 3 << " faces outwards";
  }
}

TEST(GltfScene, FlatteningAndHemisphere) {
  GltfSettings settings;
  settings.radius_m = 500.0;
  settings.flattening = 0.75;
  settings.dome = DomeShape::kHemisphere;
  DomeMesh dome = BuildDome(settings, 64, 32);
  float top = -1e9f, bottom = 1e9f, widest = 0.0f;
  for (const glm::vec3& p : dome.positions) {
    top = std::max(top, p.y), bottom = std::min(bottom, p.y);
    widest = std::max(widest, std::hypot(p.x, p.z));
  }
  EXPECT_NEAR(top, 125.0, 1e-3);   // (1 - 0.75) * 500
  EXPECT_NEAR(bottom, 0.0, 1e-3);  // a hemisphere stops at the horizon
  EXPECT_NEAR(widest, 500.0, 1e-3);
}

TEST(GltfScene, SunNodeShinesAwayFromTheSun) {
  for (glm::dvec3 sun : {glm::dvec3(0, 1, 0), glm::normalize(glm::dvec3(0.5, 0.3, -0.8)), glm::dvec3(0, 0, -1),
                         glm::dvec3(0, 0, 1), glm::normalize(glm::dvec3(-1, -0.1, 0))}) {
    glm::dquat q = SunNodeRotation(sun);
    glm::dvec3 light_travel = q * glm::dvec3(0, 0, -1);  // glTF: the light shines along -Z
    EXPECT_LT(glm::length(light_travel + sun), 1e-9);
    EXPECT_NEAR(glm::length(q), 1.0, 1e-12);
  }
}

// Frames whose animation times differ in double but round to one float32
// (seconds apart, 10,000 hours in): the sampler's times are still strictly
// increasing, as glTF requires, each spaced to the next float32 after the
// key before it; distinct float32 times are kept as they are.
TEST(GltfScene, AnimationTimesAreStrictlyIncreasingInFloat32) {
  const std::string dir = testing::FreshTempDir("gltf_times");
  WritePng(dir + "/sky.png", 4, 2, std::vector<uint8_t>(4 * 2 * 3, 128));
  SceneDescription scene;
  scene.name = "sky";
  scene.out_dir = dir;
  scene.texture_file = "sky.png";
  scene.texture_width = 4;
  scene.texture_height = 2;
  for (double t : {10000.0, 10000.0001, 10000.0002, 10000.0003, 10001.0}) {
    SceneSun sun;
    sun.time_s = t;
    sun.illuminance_lux = 1000.0;
    scene.suns.push_back(sun);
  }
  ASSERT_EQ(float(10000.0), float(10000.0003)) << "the case needs times equal in float32";
  WriteGltfScene(scene);
  const nlohmann::json gltf = nlohmann::json::parse(std::ifstream(dir + "/sky.gltf"));
  const nlohmann::json& input = gltf["accessors"][gltf["animations"][0]["samplers"][0]["input"].get<int>()];
  const nlohmann::json& view = gltf["bufferViews"][input["bufferView"].get<int>()];
  ASSERT_EQ(input["count"].get<int>(), 5);
  const std::string bin = testing::ReadFileBytes(dir + "/sky.bin");
  std::vector<float> times(5);
  std::memcpy(times.data(), bin.data() + view.value("byteOffset", size_t(0)), 5 * sizeof(float));
  EXPECT_EQ(times[0], 10000.0f);
  for (int k = 1; k < 4; ++k) EXPECT_EQ(times[k], std::nextafter(times[k - 1], HUGE_VALF)) << "key " << k;
  EXPECT_EQ(times[4], 10001.0f) << "a distinct time is kept";
  EXPECT_EQ(input["max"][0].get<float>(), 10001.0f);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace skybake
