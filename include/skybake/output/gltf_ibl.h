// The glTF scene's image-based light (EXT_lights_image_based, the Babylon.js
// and Adobe extension; KhronosGroup/glTF extensions/2.0/Vendor/
// EXT_lights_image_based): the prefiltered specular levels of ibl.h as
// RGBD PNGs, one per level and face, and the SH irradiance of the sky
// without the Sun (the Sun is the scene's KHR_lights_punctual light).
//
//   faces    +X -X +Y -Y +Z -Z, the standard (OpenGL) cube orientation on
//            glTF's axes (skybake's Vulkan faces), each image flipped about
//            its vertical axis as the extension asks
//   levels   every level of ibl.specular, roughness level / (levels - 1)
//            ("mips evenly map to roughness values from 0 to 1")
//   RGBD     as Babylon.js's toRGBD: D = floor(max(255 / max(rgb), 1)) / 255,
//            rgb' = (rgb D)^(1 / 2.2), alpha = D; decoded rgb = rgb'^2.2 / alpha
//   scale    the PNGs and the coefficients hold the sky times k, a power of
//            two that brings the sky's average radiance to 2..4, and the
//            light's intensity is 1 / k: decoded times intensity is the
//            bake's output unit (cd/m^2, lux for the coefficients)
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "skybake/model/sh.h"

namespace skybake {

// k for a frame, from its SH irradiance without the Sun (E_lm).
double GltfIblScale(const ShRgb& sh_irradiance_without_sun);

// An RGBD PNG of one face (size x size RGBA float texels, rows from the
// top), values times `scale`, mirrored left to right.
std::string EncodeRgbdFacePng(const float* rgba, int size, double scale);

// Decodes one RGBD texel (for tests and viewers): the value times the scale.
void DecodeRgbd(const uint8_t rgbd[4], double rgb[3]);

// The size of a PNG's image from its header; 0 when the bytes are not a PNG.
int PngWidth(const std::string& bytes);

}  // namespace skybake
