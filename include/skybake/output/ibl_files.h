// The files of a frame's image-based lighting maps (gpu/ibl.h): their names
// and their encoding as EXR and KTX2 (ktx2.h).
#pragma once

#include <string>
#include <vector>

#include "skybake/gpu/ibl.h"
#include "skybake/input/frame_numbering.h"
#include "skybake/input/style.h"
#include "skybake/output/exr_io.h"

namespace skybake {

// The files one frame's IBL maps go to (in out_dir), in the order written:
// per EXR level `<basename>_specular_m<l>[.####].exr`, `<basename>_irradiance[.####].exr`,
// `<basename>_dfg.exr`; KTX2 `<basename>_specular[.####].ktx2`,
// `<basename>_irradiance[.####].ktx2`, `<basename>_dfg.ktx2`. The DFG table
// does not depend on the sky: only `with_dfg` (the bake's first frame) has it.
struct IblFileName {
  std::string name;
  std::string kind;  // "ibl_specular", "ibl_irradiance", "ibl_dfg"
};
std::vector<IblFileName> IblFileNames(const SkyStyle& style, int number_in_name, bool with_dfg,
                                      int number_width = kFrameNumberMinDigits);

// Every image of the maps, for the half-range check of the frame's scale.
std::vector<RgbaImage> IblImagesForRangeCheck(const IblMaps& maps);

// Encodes the files of IblFileNames (same order) in memory: EXRs with the
// frame's `exr` options (scale, attributes; the DFG table unscaled), each
// cube level's six faces stacked top to bottom, and KTX2 files (ktx2.h).
std::vector<std::string> EncodeIblFiles(const IblMaps& maps, const SkyStyle& style, const ExrWriteOptions& exr,
                                        bool with_dfg);

}  // namespace skybake
