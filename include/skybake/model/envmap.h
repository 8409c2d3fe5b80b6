// Environment-map layouts on the CPU side, from OpenEXR's own mappings
// (Imf::LatLongMap, Imf::CubeMap). The shaders implement the same mappings in
// shaders/envmap.glsl; tests check that the two agree texel for texel.
//
//   latlong    2N x N, OpenEXR ENVMAP_LATLONG: +Y up, +Z at the centre,
//              +X at a quarter of the width, seam at -Z.
//   cube strip N x 6N, OpenEXR ENVMAP_CUBE: faces +X -X +Y -Y +Z -Z from the
//              top, each oriented as Imf::CubeMap defines.
//   faces      six N x N images in the Vulkan cube face orientation (texel
//              centres at (i + 0.5) / N), in the order +X -X +Y -Y +Z -Z.
#pragma once

#include <string>
#include <vector>

#include <glm/vec3.hpp>

namespace skybake {

// Unit direction of latlong pixel (x, y) by Imf::LatLongMap::direction.
glm::dvec3 LatLongDirection(int x, int y, int width, int height);

// Unit directions of every pixel of an N x 6N cube strip, row-major, by
// Imf::CubeMap::direction and Imf::CubeMap::pixelPosition.
std::vector<glm::dvec3> CubeStripDirections(int face_size);

// Unit direction through the centre of Vulkan cube texel (x, y) of `face`,
// from the Vulkan specification's face-selection table, written here
// independently of the shader code.
glm::dvec3 VulkanCubeTexelDirection(int face, int x, int y, int face_size);

// "+X", "-X", ... for face 0..5.
const char* CubeFaceLabel(int face);

}  // namespace skybake
