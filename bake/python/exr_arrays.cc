#include "exr_arrays.h"

#include <fmt/format.h>

#include "skybake/base/errors.h"
#include "skybake/output/exr_read.h"

namespace skybake {

// Through the door (exr_read.h): a FIFO, device or link at the name is
// refused, not waited on or followed.
RgbImage ReadExrRgb(const std::string& path) {
  RgbImage image;
  std::vector<float> rgba;
  if (const std::string problem = ReadExrRgba(path, image.width, image.height, rgba); !problem.empty())
    throw OutputError(fmt::format("{} cannot be read back: it {}", path, problem));
  image.rgb.resize(size_t(image.width) * image.height * 3);
  for (size_t i = 0; i < size_t(image.width) * image.height; ++i)
    for (size_t c = 0; c < 3; ++c) image.rgb[3 * i + c] = rgba[4 * i + c];
  return image;
}

}  // namespace skybake
