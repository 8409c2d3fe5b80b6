// Texel <-> direction mappings: the shared shader code (in double on the CPU
// and in float on lavapipe) against OpenEXR's Imf::LatLongMap / Imf::CubeMap
// and the Vulkan specification's cube face selection.
#include <cmath>

#include <gtest/gtest.h>
#include <glm/glm.hpp>

#include "skybake/model/envmap.h"
#include "skybake/tools/reference_model.h"
#include "skybake/gpu/sky_renderer.h"
#include "test_support.h"

namespace skybake {
namespace {

double MaxAngleError(const std::vector<glm::dvec3>& a, const std::vector<glm::dvec3>& b) {
  double worst = 0.0;
  for (size_t i = 0; i < a.size(); ++i) worst = std::max(worst, glm::length(a[i] - b[i]));
  return worst;
}

std::vector<glm::dvec3> ImfLatLong(int w, int h) {
  std::vector<glm::dvec3> dirs;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) dirs.push_back(LatLongDirection(x, y, w, h));
  return dirs;
}

std::vector<glm::dvec3> ToDirections(const std::vector<float>& rgba) {
  std::vector<glm::dvec3> dirs;
  for (size_t i = 0; i < rgba.size(); i += 4) dirs.push_back({rgba[i], rgba[i + 1], rgba[i + 2]});
  return dirs;
}

TEST(EnvmapTest, SharedLatLongMatchesOpenExr) {
  for (int h : {1, 2, 7, 32, 256}) {
    ViewRequest view{MAPPING_LATLONG, 2 * h, h, 0};
    EXPECT_LT(MaxAngleError(ViewDirections(view), ImfLatLong(2 * h, h)), 1e-6) << "height " << h;
  }
}

TEST(EnvmapTest, SharedCubeStripMatchesOpenExr) {
  for (int n : {2, 3, 16, 64}) {
    ViewRequest view{MAPPING_CUBE_STRIP, n, 6 * n, 0};
    EXPECT_LT(MaxAngleError(ViewDirections(view), CubeStripDirections(n)), 1e-6) << "size " << n;
  }
}

TEST(EnvmapTest, LatLongLandmarks) {
  // shared/CONVENTIONS.md: +Z at the centre, +X at a quarter of the width, +Y up.
  const int w = 513, h = 257;  // odd sizes put pixels exactly on the landmarks
  auto near = [](glm::dvec3 a, glm::dvec3 b) { return glm::length(a - b) < 1e-6; };
  EXPECT_TRUE(near(LatLongDirection(256, 128, w, h), {0, 0, 1}));
  EXPECT_TRUE(near(LatLongDirection(128, 128, w, h), {1, 0, 0}));
  EXPECT_TRUE(near(LatLongDirection(256, 0, w, h), {0, 1, 0}));
  EXPECT_TRUE(near(LatLongDirection(0, 128, w, h), {0, 0, -1}));
}

TEST(EnvmapTest, VulkanFacesRoundTripThroughTheSpecTable) {
  const int n = 16;
  for (int face = 0; face < 6; ++face) {
    ViewRequest view{MAPPING_VULKAN_FACE, n, n, face};
    std::vector<glm::dvec3> dirs = ViewDirections(view);
    for (int y = 0; y < n; ++y) {
      for (int x = 0; x < n; ++x) {
        const glm::dvec3& d = dirs[size_t(y) * n + x];
        EXPECT_NEAR(glm::length(d), 1.0, 1e-12);
        testing::CubeFaceHit ft = testing::SpecCubeFace(d);
        ASSERT_EQ(ft.face, face) << x << "," << y;
        EXPECT_NEAR(ft.s, (x + 0.5) / n, 1e-9);
        EXPECT_NEAR(ft.t, (y + 0.5) / n, 1e-9);
        EXPECT_LT(glm::length(d - VulkanCubeTexelDirection(face, x, y, n)), 1e-12);
      }
    }
  }
}

TEST(EnvmapTest, GpuMappingsMatchOpenExrAndVulkan) {
  VulkanContext& vulkan = testing::Vulkan();
  SkyRenderer renderer(vulkan, AtmosphereParams{}, QualitySettings{}, EffectSettings{}, {1.0, 1.0, 1.0},
                       /*output_directions=*/true);
  const int h = 64, n = 32;
  std::vector<ViewRequest> views = {{MAPPING_LATLONG, 2 * h, h, 0}, {MAPPING_CUBE_STRIP, n, 6 * n, 0}};
  for (int face = 0; face < 6; ++face) views.push_back({MAPPING_VULKAN_FACE, n, n, face});
  std::vector<std::vector<float>> out = renderer.Render({0, 1, 0}, views);
  EXPECT_LT(MaxAngleError(ToDirections(out[0]), ImfLatLong(2 * h, h)), 1e-6);
  EXPECT_LT(MaxAngleError(ToDirections(out[1]), CubeStripDirections(n)), 1e-6);
  for (int face = 0; face < 6; ++face) {
    std::vector<glm::dvec3> expected;
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) expected.push_back(VulkanCubeTexelDirection(face, x, y, n));
    EXPECT_LT(MaxAngleError(ToDirections(out[2 + face]), expected), 1e-6) << "face " << face;
  }
  testing::ExpectNoValidationMessages();
}

}  // namespace
}  // namespace skybake
