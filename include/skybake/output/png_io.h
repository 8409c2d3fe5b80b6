// 8-bit sRGB PNG encoding for the latlong preview, the glTF textures, the
// ground texture and the gallery sheet, through libpng directly: a bake that
// writes PNGs loads no OpenImageIO (base/oiio_module.h; docs/performance.md,
// "PNG without OpenImageIO").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace skybake {

// The PNG of `width` x `height` 8-bit RGB pixels, rows from the top: an sRGB
// chunk (with its gAMA and cHRM, as the PNG specification recommends), a
// Software text "skybake VERSION", no time stamp, so the same pixels give
// the same bytes. Throws OutputError when libpng fails.
std::string EncodePngRgb8(int width, int height, const std::vector<uint8_t>& rgb);

}  // namespace skybake
