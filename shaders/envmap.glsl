// Environment-map texel <-> direction mappings, written once in the common
// GLSL/C++ subset (see glsl_prelude.glsl). World frame: +Y up, right-handed.
//
// OpenEXR latlong (Imf::LatLongMap), data window W x H with W = 2H:
//   pixel (0, 0)         -> latitude +pi/2, longitude +pi
//   pixel (W-1, H-1)     -> latitude -pi/2, longitude -pi
//   direction = (sin(lon) cos(lat), sin(lat), cos(lon) cos(lat))
//   +Z at the image centre, +X at a quarter of the width, seam at -Z.
//   Integer pixel positions map to the ends of the ranges, so the first and
//   last rows sit exactly on the poles and the first and last columns on the
//   seam; this is OpenEXR's definition and readers expect it.
//
// OpenEXR cube strip (Imf::CubeMap), data window N x 6N, faces from the top:
//
//        +----+
//        | +X |  rows 0 .. N-1
//        | -X |  rows N .. 2N-1
//        | +Y |
//        | -Y |
//        | +Z |
//        | -Z |  rows 5N .. 6N-1
//        +----+
//
//   Within a face, Imf::CubeMap places texel centres on the face edges:
//   position-in-face p in [0, N-1] maps to [-1, 1] as p / (N-1) * 2 - 1.
//
// Vulkan cube faces (Vulkan spec, "Cube Map Face Selection"), N x N each,
// texel centres at (i + 0.5) / N, row 0 at the top of the image:
//   face  major  sc    tc
//   +X    +x     -z    -y
//   -X    -x     +z    -y
//   +Y    +y     +x    +z
//   -Y    -y     +x    -z
//   +Z    +z     +x    -y
//   -Z    -z     -x    -y
#ifndef SKYBAKE_ENVMAP_GLSL
#define SKYBAKE_ENVMAP_GLSL

CONST_REAL kEnvmapPi = 3.14159265358979323846;

// Direction (unit) of OpenEXR latlong pixel (x, y) in a width x height image.
vec3 DirectionFromLatLongPixel(Real x, Real y, int width, int height) {
  Real latitude = 0.0;
  Real longitude = 0.0;
  if (height > 1) latitude = -kEnvmapPi * (y / Real(height - 1) - 0.5);
  if (width > 1) longitude = -2.0 * kEnvmapPi * (x / Real(width - 1) - 0.5);
  vec3 direction;
  direction.x = sin(longitude) * cos(latitude);
  direction.y = sin(latitude);
  direction.z = cos(longitude) * cos(latitude);
  return direction;
}

// Direction of OpenEXR position-in-face (px, py) of face `face` (0..5 =
// +X -X +Y -Y +Z -Z), as Imf::CubeMap::direction, then normalized.
vec3 DirectionFromCubePositionInFace(int face, Real px, Real py, int face_size) {
  Real a = 0.0;
  Real b = 0.0;
  if (face_size > 1) {
    a = px / Real(face_size - 1) * 2.0 - 1.0;
    b = py / Real(face_size - 1) * 2.0 - 1.0;
  }
  vec3 direction;
  if (face == 0) { direction.x = 1.0;  direction.y = a;    direction.z = b; }
  else if (face == 1) { direction.x = -1.0; direction.y = a;    direction.z = b; }
  else if (face == 2) { direction.x = a;    direction.y = 1.0;  direction.z = b; }
  else if (face == 3) { direction.x = a;    direction.y = -1.0; direction.z = b; }
  else if (face == 4) { direction.x = a;    direction.y = b;    direction.z = 1.0; }
  else { direction.x = a;    direction.y = b;    direction.z = -1.0; }
  return normalize(direction);
}

// Direction of pixel (x, y) of an OpenEXR cube strip whose faces are
// face_size x face_size (the image is face_size x 6 face_size). Inverts
// Imf::CubeMap::pixelPosition face by face.
vec3 DirectionFromCubeStripPixel(int x, int y, int face_size) {
  int face = y / face_size;
  int local_y = y - face * face_size;
  int last = face_size - 1;
  int px = 0;
  int py = 0;
  if (face == 0) { px = last - local_y; py = x; }
  else if (face == 1) { px = last - local_y; py = last - x; }
  else if (face == 2) { px = x; py = last - local_y; }
  else if (face == 3) { px = x; py = local_y; }
  else if (face == 4) { px = last - x; py = last - local_y; }
  else { px = x; py = last - local_y; }
  return DirectionFromCubePositionInFace(face, Real(px), Real(py), face_size);
}

// Direction through the centre of texel (x, y) of Vulkan cube face `face`.
vec3 DirectionFromVulkanCubeTexel(int face, int x, int y, int face_size) {
  Real sc = 2.0 * (Real(x) + 0.5) / Real(face_size) - 1.0;
  Real tc = 2.0 * (Real(y) + 0.5) / Real(face_size) - 1.0;
  vec3 direction;
  if (face == 0) { direction.x = 1.0;  direction.y = -tc;  direction.z = -sc; }
  else if (face == 1) { direction.x = -1.0; direction.y = -tc;  direction.z = sc; }
  else if (face == 2) { direction.x = sc;   direction.y = 1.0;  direction.z = tc; }
  else if (face == 3) { direction.x = sc;   direction.y = -1.0; direction.z = -tc; }
  else if (face == 4) { direction.x = sc;   direction.y = -tc;  direction.z = 1.0; }
  else { direction.x = -sc;  direction.y = -tc;  direction.z = -1.0; }
  return normalize(direction);
}

#endif  // SKYBAKE_ENVMAP_GLSL
