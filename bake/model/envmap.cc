#include "skybake/model/envmap.h"

#include <cmath>

#include <glm/geometric.hpp>
#include <OpenEXR/ImfEnvmap.h>

namespace skybake {

glm::dvec3 LatLongDirection(int x, int y, int width, int height) {
  Imath::Box2i window(Imath::V2i(0, 0), Imath::V2i(width - 1, height - 1));
  Imath::V3f d = Imf::LatLongMap::direction(window, Imath::V2f(float(x), float(y)));
  return glm::normalize(glm::dvec3(d.x, d.y, d.z));
}

std::vector<glm::dvec3> CubeStripDirections(int n) {
  Imath::Box2i window(Imath::V2i(0, 0), Imath::V2i(n - 1, 6 * n - 1));
  std::vector<glm::dvec3> directions(size_t(n) * 6 * n);
  for (int face = 0; face < 6; ++face) {
    for (int py = 0; py < n; ++py) {
      for (int px = 0; px < n; ++px) {
        Imf::CubeMapFace f = Imf::CubeMapFace(face);
        Imath::V2f pif{float(px), float(py)};
        Imath::V2f pixel = Imf::CubeMap::pixelPosition(f, window, pif);
        Imath::V3f d = Imf::CubeMap::direction(f, window, pif);
        const int x = int(std::lround(pixel.x));
        const int y = int(std::lround(pixel.y));
        directions[size_t(y) * n + x] = glm::normalize(glm::dvec3(d.x, d.y, d.z));
      }
    }
  }
  return directions;
}

glm::dvec3 VulkanCubeTexelDirection(int face, int x, int y, int n) {
  // Vulkan spec "Cube Map Face Selection and Transformations": for major
  // axis ma, s = (sc / |ma| + 1) / 2 and t = (tc / |ma| + 1) / 2, so a texel
  // centre gives sc = 2 s - 1, tc = 2 t - 1, solved here for the direction.
  double s = (x + 0.5) / n;
  double t = (y + 0.5) / n;
  double sc = 2.0 * s - 1.0;
  double tc = 2.0 * t - 1.0;
  glm::dvec3 d;
  switch (face) {
    case 0:
      d = {1.0, -tc, -sc};
      break;  // +X: sc = -rz, tc = -ry
    case 1:
      d = {-1.0, -tc, sc};
      break;  // -X: sc = +rz, tc = -ry
    case 2:
      d = {sc, 1.0, tc};
      break;  // +Y: sc = +rx, tc = +rz
    case 3:
      d = {sc, -1.0, -tc};
      break;  // -Y: sc = +rx, tc = -rz
    case 4:
      d = {sc, -tc, 1.0};
      break;  // +Z: sc = +rx, tc = -ry
    default:
      d = {-sc, -tc, -1.0};
      break;  // -Z: sc = -rx, tc = -ry
  }
  return glm::normalize(d);
}

const char* CubeFaceLabel(int face) {
  static const char* kLabels[6] = {"+X", "-X", "+Y", "-Y", "+Z", "-Z"};
  return kLabels[face % 6];
}

}  // namespace skybake
