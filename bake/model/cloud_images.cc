// Weather images of cloud layers (clouds.h), read through the OpenImageIO
// module: EXR, PNG or anything else it reads.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include <fmt/format.h>

#include "skybake/base/file_door.h"
#include "skybake/model/clouds.h"

namespace skybake {
namespace {

struct LoadedImage {
  int width = 0, height = 0, channels = 0;
  std::vector<float> pixels;
};

// "" when the image loads and has 1, 3 or 4 channels; else what is wrong.
std::string LoadImage(const std::string& path, LoadedImage& image) {
  // Through the door (file_door.h): a regular file, read once per bake,
  // its size checked from its header.
  if (std::string problem = ReadImageFile(path, image.width, image.height, image.channels, image.pixels);
      !problem.empty())
    return problem;
  if (image.width < 1 || image.height < 1) return "the image is empty";
  if (image.channels != 1 && image.channels != 3 && image.channels != 4)
    return fmt::format("{} channels; expected 1 (coverage) or 3/4 (R = coverage)", image.channels);
  return "";
}

}  // namespace

std::string CheckWeatherImage(const std::string& path) {
  LoadedImage image;
  return LoadImage(path, image);
}

std::vector<float> ReadWeatherImage(const std::string& path, int resolution) {
  LoadedImage image;
  std::string problem = LoadImage(path, image);
  if (!problem.empty()) throw std::runtime_error(path + ": " + problem);
  // Bilinear, wrapping (the map tiles), at the centres of the map's texels.
  std::vector<float> map(size_t(resolution) * resolution);
  auto at = [&](int x, int y) {
    x = ((x % image.width) + image.width) % image.width;
    y = ((y % image.height) + image.height) % image.height;
    return std::clamp(image.pixels[(size_t(y) * image.width + x) * image.channels], 0.0f, 1.0f);
  };
  for (int j = 0; j < resolution; ++j) {
    for (int i = 0; i < resolution; ++i) {
      const double u = (i + 0.5) / resolution * image.width - 0.5;
      const double v = (j + 0.5) / resolution * image.height - 0.5;
      const int x0 = int(std::floor(u)), y0 = int(std::floor(v));
      const double fx = u - x0, fy = v - y0;
      const double a = at(x0, y0) * (1 - fx) + at(x0 + 1, y0) * fx;
      const double b = at(x0, y0 + 1) * (1 - fx) + at(x0 + 1, y0 + 1) * fx;
      map[size_t(j) * resolution + i] = float(a * (1 - fy) + b * fy);
    }
  }
  return map;
}

}  // namespace skybake
