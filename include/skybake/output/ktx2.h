// KTX 2.0 files (Khronos KTX File Format Specification 2.0), written by
// skybake: cube maps with their mip chain and 2D images, uncompressed or with
// zstd supercompression (scheme 2), in three linear HDR formats:
//
//   rgba16f    VK_FORMAT_R16G16B16A16_SFLOAT (97), 8 bytes a texel, max 65504
//   b10g11r11  VK_FORMAT_B10G11R11_UFLOAT_PACK32 (122), 4 bytes, R and G with
//              6 mantissa bits, B with 5, max 65024 (R, G) and 64512 (B)
//   e5b9g9r9   VK_FORMAT_E5B9G9R9_UFLOAT_PACK32 (123), 4 bytes, 9-bit
//              mantissas sharing one exponent, max 65408
//
// Every file carries a Khronos basic data format descriptor (RGBSDA model,
// BT.709 primaries, linear transfer), KTXorientation "rd" and KTXwriter, and
// the caller's key/value pairs. A value beyond the format's range is refused
// (OutputError naming the fix), never clamped; NaN and negative values too.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "skybake/input/output_settings.h"
#include "skybake/gpu/ibl.h"

namespace skybake {

struct Ktx2Options {
  KtxFormat format = KtxFormat::kRgba16f;
  int zstd_level = 0;                           // 0: none; else the zstd level of each mip level's data
  double scale = 1.0;                           // multiplies every value before it is encoded
  std::map<std::string, std::string> metadata;  // key/value data (UTF-8 strings)
  uint32_t primaries = 1;  // the DFD's colorPrimaries (Khronos Data Format 1.3, khr_df_primaries_e): 1 BT.709
};

// The DFD colorPrimaries of a colour space: BT.709 1, BT.2020 4, CIE XYZ 5,
// ACES AP0 6, ACEScc/ACEScg AP1 7, Display P3 10, matched by chromaticities;
// 0 (unspecified) for any other (its name and chromaticities then travel in
// the key/value data).
uint32_t Ktx2Primaries(const OutputColorSpace& space);

// VkFormat number and texel size in bytes of a format.
uint32_t Ktx2VkFormat(KtxFormat format);
uint32_t Ktx2TexelBytes(KtxFormat format);
const char* Ktx2FormatName(KtxFormat format);

// A cube map (faceCount 6) whose level i is levels[i] (level 0 the largest,
// each the next halving). Faces in the KTX2 and Vulkan order +X -X +Y -Y +Z -Z.
std::string EncodeKtx2Cube(const std::vector<CubeLevel>& levels, const Ktx2Options& options);

// One 2D image, RGBA float texels, rows from the top.
std::string EncodeKtx2Image(int width, int height, const std::vector<float>& rgba, const Ktx2Options& options);

// The packed encodings, for tests: round to nearest, throw OutputError
// beyond range.
uint32_t PackB10G11R11(float r, float g, float b);
uint32_t PackE5B9G9R9(float r, float g, float b);

}  // namespace skybake
