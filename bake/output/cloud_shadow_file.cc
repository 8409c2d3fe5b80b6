#include "skybake/output/cloud_shadow_file.h"

#include "skybake/input/frame_numbering.h"
#include "skybake/output/exr_io.h"
#include "skybake/output/sha256.h"

namespace skybake {

std::string CloudShadowFileName(const std::string& basename, int frame_number, int number_width) {
  return basename + "_cloudshadow" + FrameNumberSuffix(frame_number, number_width) + ".exr";
}

BakedFile WriteCloudShadowFile(const std::string& path, const std::vector<float>& transmittance,
                               const CloudShadowInfo& info, const std::map<std::string, std::string>& attributes) {
  RgbaImage image;
  image.width = image.height = info.resolution;
  image.rgba.resize(image.texels() * 4);
  for (size_t i = 0; i < image.texels(); ++i) {
    const float t = i < transmittance.size() ? transmittance[i] : 0.0f;
    image.rgba[4 * i + 0] = image.rgba[4 * i + 1] = image.rgba[4 * i + 2] = t;
    image.rgba[4 * i + 3] = 1.0f;
  }
  ExrWriteOptions exr;
  exr.pixel_type = PixelType::kFloat;
  exr.compression = "zip";
  exr.attributes = attributes;
  // Not radiance: the frame's radiance scale and units do not apply.
  exr.attributes.erase("skybake:scale");
  exr.attributes["skybake:units"] = "transmittance (dimensionless), 0..1";
  for (const auto& [key, value] : CloudShadowAttributes(info)) exr.attributes[key] = value;
  const std::string bytes = EncodeExr(path, image, exr);
  WriteFileAtomically(path, bytes);
  return {path, "cloud_shadow", bytes.size(), Sha256OfText(bytes)};
}

}  // namespace skybake
