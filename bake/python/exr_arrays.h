// A written EXR's texels read back for the Python module's arrays: RGB
// float, rows from the top, as the file stores them (a luminance EXR in
// cd/m^2 times its skybake:scale; README "Output").
#pragma once

#include <string>
#include <vector>

namespace skybake {

struct RgbImage {
  int width = 0;
  int height = 0;
  std::vector<float> rgb;  // width x height x 3
};

// Throws OutputError naming the file when it cannot be read.
RgbImage ReadExrRgb(const std::string& path);

}  // namespace skybake
