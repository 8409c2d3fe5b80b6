// A written KTX2 file's texels read back for the Python module's arrays:
// every mip level of a cube (faces +X -X +Y -Y +Z -Z, the KTX2 and Vulkan
// order) or of a 2D image, RGB float, rows from the top, as the file stores
// them (times its skybake:scale); zstd supercompression undone. Only the
// formats skybake writes (ktx2.h): R16G16B16A16_SFLOAT, B10G11R11_UFLOAT,
// E5B9G9R9_UFLOAT.
#pragma once

#include <string>
#include <vector>

namespace skybake {

struct Ktx2Level {
  int size = 0;            // width = height, texels
  int faces = 0;           // 6 for a cube, 1 for an image
  std::vector<float> rgb;  // faces x size x size x 3
};

// Level 0 (the largest) first. Throws OutputError naming the file when it
// cannot be read or is not one skybake writes.
std::vector<Ktx2Level> ReadKtx2Rgb(const std::string& path);

}  // namespace skybake
