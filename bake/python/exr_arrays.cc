#include "exr_arrays.h"

#include <exception>

#include <ImfArray.h>
#include <ImfRgbaFile.h>
#include <fmt/format.h>

#include "skybake/base/errors.h"

namespace skybake {

RgbImage ReadExrRgb(const std::string& path) {
  try {
    Imf::RgbaInputFile in(path.c_str());
    const Imath::Box2i window = in.dataWindow();
    RgbImage image;
    image.width = window.max.x - window.min.x + 1;
    image.height = window.max.y - window.min.y + 1;
    Imf::Array2D<Imf::Rgba> texels(image.height, image.width);
    in.setFrameBuffer(&texels[0][0] - window.min.x - window.min.y * image.width, 1, image.width);
    in.readPixels(window.min.y, window.max.y);
    image.rgb.resize(size_t(image.width) * image.height * 3);
    float* out = image.rgb.data();
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x) {
        const Imf::Rgba& t = texels[y][x];
        *out++ = t.r;
        *out++ = t.g;
        *out++ = t.b;
      }
    return image;
  } catch (const std::exception& e) {
    throw OutputError(fmt::format("{} cannot be read back: {}", path, e.what()));
  }
}

}  // namespace skybake
