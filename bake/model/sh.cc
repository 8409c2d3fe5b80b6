#include "skybake/model/sh.h"

#include <cmath>

#include <glm/geometric.hpp>

#include "skybake/model/envmap.h"

namespace skybake {
namespace {

// Integral of the cube-face area element 1 / (1 + u^2 + v^2)^(3/2) from the
// face centre to (u, v): the solid angle of the rectangle [0, u] x [0, v].
double AreaElement(double u, double v) { return std::atan2(u * v, std::sqrt(u * u + v * v + 1.0)); }

}  // namespace

std::array<double, kShCoefficients> ShBasis(const glm::dvec3& d) {
  const double x = d.x, y = d.y, z = d.z;
  return {0.282095,
          0.488603 * y,
          0.488603 * z,
          0.488603 * x,
          1.092548 * x * y,
          1.092548 * y * z,
          0.315392 * (3.0 * z * z - 1.0),
          1.092548 * x * z,
          0.546274 * (x * x - y * y)};
}

double CubeTexelSolidAngle(int x, int y, int n) {
  const double u0 = 2.0 * x / n - 1.0, u1 = 2.0 * (x + 1) / n - 1.0;
  const double v0 = 2.0 * y / n - 1.0, v1 = 2.0 * (y + 1) / n - 1.0;
  return AreaElement(u1, v1) - AreaElement(u0, v1) - AreaElement(u1, v0) + AreaElement(u0, v0);
}

ShRgb ProjectCubeFaces(const std::array<const float*, 6>& faces, int n) {
  ShRgb result{};
  // The solid angle depends only on (x, y), the same for every face.
  std::vector<double> solid_angle(size_t(n) * n);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) solid_angle[size_t(y) * n + x] = CubeTexelSolidAngle(x, y, n);
  for (int face = 0; face < 6; ++face) {
    for (int y = 0; y < n; ++y) {
      for (int x = 0; x < n; ++x) {
        const float* texel = faces[face] + (size_t(y) * n + x) * 4;
        const double w = solid_angle[size_t(y) * n + x];
        std::array<double, kShCoefficients> basis = ShBasis(VulkanCubeTexelDirection(face, x, y, n));
        for (int i = 0; i < kShCoefficients; ++i)
          for (int c = 0; c < 3; ++c) result[i][c] += double(texel[c]) * basis[i] * w;
      }
    }
  }
  return result;
}

void AddDirectionalSource(ShRgb& coefficients, const glm::dvec3& d, const Rgb& irradiance) {
  std::array<double, kShCoefficients> basis = ShBasis(glm::normalize(d));
  for (int i = 0; i < kShCoefficients; ++i)
    for (int c = 0; c < 3; ++c) coefficients[i][c] += irradiance[c] * basis[i];
}

ShRgb RadianceToIrradiance(const ShRgb& radiance) {
  // Ramamoorthi & Hanrahan 2001, eq. 8: A_l of the clamped cosine.
  const double kBand[3] = {M_PI, 2.0 * M_PI / 3.0, M_PI / 4.0};
  const int kBandOf[kShCoefficients] = {0, 1, 1, 1, 2, 2, 2, 2, 2};
  ShRgb result = radiance;
  for (int i = 0; i < kShCoefficients; ++i)
    for (int c = 0; c < 3; ++c) result[i][c] *= kBand[kBandOf[i]];
  return result;
}

Rgb EvaluateSh(const ShRgb& coefficients, const glm::dvec3& d) {
  std::array<double, kShCoefficients> basis = ShBasis(d);
  Rgb result{0.0, 0.0, 0.0};
  for (int i = 0; i < kShCoefficients; ++i)
    for (int c = 0; c < 3; ++c) result[c] += coefficients[i][c] * basis[i];
  return result;
}

}  // namespace skybake
