// Spherical-harmonic projection of cube maps against analytic coefficients.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "skybake/model/envmap.h"
#include "skybake/model/sh.h"

namespace skybake {
namespace {

// Six Vulkan faces filled with radiance(direction), RGBA.
template <class F>
std::vector<std::vector<float>> MakeFaces(int n, F radiance) {
  std::vector<std::vector<float>> faces(6, std::vector<float>(size_t(n) * n * 4));
  for (int face = 0; face < 6; ++face)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        Rgb l = radiance(VulkanCubeTexelDirection(face, x, y, n));
        float* t = &faces[face][(size_t(y) * n + x) * 4];
        t[0] = float(l[0]), t[1] = float(l[1]), t[2] = float(l[2]), t[3] = 1.0f;
      }
  return faces;
}

ShRgb Project(const std::vector<std::vector<float>>& faces, int n) {
  return ProjectCubeFaces(
      {faces[0].data(), faces[1].data(), faces[2].data(), faces[3].data(), faces[4].data(), faces[5].data()}, n);
}

TEST(Sh, TexelSolidAnglesCoverTheSphere) {
  for (int n : {1, 2, 7, 64}) {
    double total = 0.0;
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) total += 6.0 * CubeTexelSolidAngle(x, y, n);
    EXPECT_NEAR(total, 4.0 * M_PI, 1e-12) << n;
  }
  EXPECT_NEAR(CubeTexelSolidAngle(0, 0, 1), 4.0 * M_PI / 6.0, 1e-12);
}

TEST(Sh, ConstantEnvironment) {
  // L = c: L_00 = c * integral of Y00 = c * 4 pi * 0.282095, every other
  // coefficient 0, and the irradiance on any surface is pi c.
  const Rgb c = {1.0, 2.5, 0.25};
  const int n = 16;
  ShRgb radiance = Project(MakeFaces(n, [&](const glm::dvec3&) { return c; }), n);
  for (int ch = 0; ch < 3; ++ch) {
    EXPECT_NEAR(radiance[0][ch], c[ch] * 4.0 * M_PI * 0.282095, 1e-6 * c[ch]);
    for (int i = 1; i < kShCoefficients; ++i) EXPECT_NEAR(radiance[i][ch], 0.0, 1e-6) << i;
  }
  ShRgb irradiance = RadianceToIrradiance(radiance);
  for (glm::dvec3 normal : {glm::dvec3(0, 1, 0), glm::dvec3(1, 0, 0), glm::normalize(glm::dvec3(-1, -2, 3))}) {
    Rgb e = EvaluateSh(irradiance, normal);
    // 0.282095 is Y00 = 1 / (2 sqrt(pi)) to 6 digits: relative error 2e-6.
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(e[ch], M_PI * c[ch], 1e-5 * M_PI * c[ch]);
  }
}

TEST(Sh, SingleClampedCosineLobe) {
  // L(w) = max(0, w . a). By the Funk-Hecke theorem a zonal function has
  // L_lm = sqrt(4 pi / (2l + 1)) z_l Y_lm(a), with z_l its coefficient about
  // +Z: z_0 = sqrt(pi) / 2, z_1 = sqrt(pi / 3), z_2 = sqrt(5 pi) / 8.
  const glm::dvec3 axis = glm::normalize(glm::dvec3(0.3, 0.8, -0.5));
  const double z[3] = {std::sqrt(M_PI) / 2.0, std::sqrt(M_PI / 3.0), std::sqrt(5.0 * M_PI) / 8.0};
  const int band_of[kShCoefficients] = {0, 1, 1, 1, 2, 2, 2, 2, 2};
  const int n = 256;
  const Rgb scale = {1.0, 0.5, 2.0};
  ShRgb radiance = Project(MakeFaces(n,
                                     [&](const glm::dvec3& d) {
                                       double lobe = std::max(0.0, glm::dot(d, axis));
                                       return Rgb{scale[0] * lobe, scale[1] * lobe, scale[2] * lobe};
                                     }),
                           n);
  std::array<double, kShCoefficients> y = ShBasis(axis);
  for (int i = 0; i < kShCoefficients; ++i) {
    int l = band_of[i];
    double expected = std::sqrt(4.0 * M_PI / (2 * l + 1)) * z[l] * y[i];
    // Texel-centre quadrature of the kink at the lobe's edge: 1e-4 at N = 256.
    for (int ch = 0; ch < 3; ++ch)
      EXPECT_NEAR(radiance[i][ch], scale[ch] * expected, 1e-4 * scale[ch]) << "coefficient " << i;
  }
  // Irradiance facing the lobe: exactly the integral of cos^2 over the
  // hemisphere, 2 pi / 3. Its order-2 SH approximation is
  // sum_l A_l z_l sqrt((2l + 1) / (4 pi)) = pi/4 + pi/3 + 5 pi/64.
  ShRgb irradiance = RadianceToIrradiance(radiance);
  double expected_e = M_PI / 4.0 + M_PI / 3.0 + 5.0 * M_PI / 64.0;
  EXPECT_NEAR(EvaluateSh(irradiance, axis)[0], expected_e, 1e-3);
  EXPECT_NEAR(expected_e, 2.0 * M_PI / 3.0, 0.03);  // l <= 2 captures all but ~1%
}

TEST(Sh, DirectionalSource) {
  ShRgb c{};
  const glm::dvec3 sun = glm::normalize(glm::dvec3(1, 1, 0));
  AddDirectionalSource(c, sun, {10.0, 20.0, 30.0});
  EXPECT_NEAR(c[0][1], 20.0 * 0.282095, 1e-12);
  EXPECT_NEAR(c[3][2], 30.0 * 0.488603 * sun.x, 1e-12);
  // Irradiance facing the source is close to the source itself (order 2).
  Rgb e = EvaluateSh(RadianceToIrradiance(c), sun);
  EXPECT_NEAR(e[0] / 10.0, 1.0, 0.15);
}

}  // namespace
}  // namespace skybake
