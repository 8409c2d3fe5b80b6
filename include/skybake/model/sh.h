// Spherical-harmonic irradiance of a baked sky, for diffuse lighting.
//
// Real spherical harmonics up to l = 2 (9 coefficients per channel), in the
// order (l, m) = (0,0) (1,-1) (1,0) (1,1) (2,-2) (2,-1) (2,0) (2,1) (2,2), with
// the normalisation and polynomials of Ramamoorthi & Hanrahan 2001, "An
// Efficient Representation for Irradiance Environment Maps", eq. 3,
// evaluated on the world-frame unit direction (x, y, z) (+Y up, North -Z,
// East +X), as three.js's SphericalHarmonics3 does:
//   Y00 = 0.282095
//   Y1-1 = 0.488603 y    Y10 = 0.488603 z    Y11 = 0.488603 x
//   Y2-2 = 1.092548 xy   Y2-1 = 1.092548 yz  Y20 = 0.315392 (3z^2 - 1)
//   Y21 = 1.092548 xz    Y22 = 0.546274 (x^2 - y^2)
//
// Radiance coefficients L_lm = integral of L(w) Y_lm(w) dw. Irradiance
// coefficients E_lm = A_l L_lm with A_0 = pi, A_1 = 2 pi / 3, A_2 = pi / 4
// (the clamped-cosine convolution, R&H 2001 eq. 8), so the irradiance on a
// surface with normal n is E(n) = sum_lm E_lm Y_lm(n): in lux when the sky is
// in cd/m^2, in W m^-2 nm^-1 when it is spectral radiance.
#pragma once

#include <array>
#include <vector>

#include <glm/vec3.hpp>

#include "skybake/model/atmosphere.h"

namespace skybake {

constexpr int kShCoefficients = 9;
using ShRgb = std::array<Rgb, kShCoefficients>;  // [coefficient][R, G, B]

// The nine basis functions at unit direction `d`.
std::array<double, kShCoefficients> ShBasis(const glm::dvec3& d);

// Solid angle, sr, of texel (x, y) of an N x N cube face (exact: the
// integral of the area element over the texel).
double CubeTexelSolidAngle(int x, int y, int face_size);

// Projects radiance given as the six Vulkan cube faces (+X -X +Y -Y +Z -Z,
// each N x N RGBA float, rows from the top, texel directions as
// VulkanCubeTexelDirection) onto the basis: radiance coefficients L_lm.
ShRgb ProjectCubeFaces(const std::array<const float*, 6>& faces, int face_size);

// Adds a source of irradiance `irradiance` (per channel) concentrated in unit
// direction `d`, such as the solar disc: L_lm += E Y_lm(d).
void AddDirectionalSource(ShRgb& radiance_coefficients, const glm::dvec3& d, const Rgb& irradiance);

// E_lm = A_l L_lm.
ShRgb RadianceToIrradiance(const ShRgb& radiance_coefficients);

// sum_lm c_lm Y_lm(d), per channel.
Rgb EvaluateSh(const ShRgb& coefficients, const glm::dvec3& d);

}  // namespace skybake
