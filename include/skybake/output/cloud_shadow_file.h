// Writing a frame's cloud shadow map (cloud_shadow.h) as an EXR.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "skybake/input/frame_numbering.h"
#include "skybake/model/cloud_shadow.h"
#include "skybake/output/bake_record.h"

namespace skybake {

// The file name of a frame's map: BASE_cloudshadow.exr, BASE_cloudshadow.NNNN.exr in a sequence.
std::string CloudShadowFileName(const std::string& basename, int frame_number,
                                int number_width = kFrameNumberMinDigits);

// A float EXR, R = G = B = the transmittance, zip compressed, with the
// frame's provenance `attributes` and the map's placement
// (CloudShadowAttributes); written atomically, kind "cloud_shadow".
BakedFile WriteCloudShadowFile(const std::string& path, const std::vector<float>& transmittance,
                               const CloudShadowInfo& info, const std::map<std::string, std::string>& attributes);

}  // namespace skybake
