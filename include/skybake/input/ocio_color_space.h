// output.color_space resolved: a built-in space (spectrum.h), or a colour
// space of an OpenColorIO config (output.ocio_config, else $OCIO), entered
// through the config's `aces_interchange` role (ACES2065-1): skybake's
// linear Rec.709 goes to ACES2065-1 by its own matrix and on to the named
// space by the config's processor, sampled once into a 3x3 matrix (a space
// that is not linear is refused). The space's primaries and white, for the
// EXR chromaticities, are the XYZ that OpenColorIO's
// "UTILITY - ACES-AP0_to_CIE-XYZ-D65_BFD" gives its primaries and white:
// exact for the D65 spaces configs hold; a space with another white is
// described as seen from D65 after Bradford adaptation, as OpenColorIO's
// ACES configs treat it.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "skybake/model/spectrum.h"

namespace skybake {

struct ColorSpaceLookup {
  std::optional<OutputColorSpace> space;
  std::string error;  // why not, with the names there are
};
// `config_path` empty: $OCIO, when set.
ColorSpaceLookup ResolveOutputColorSpace(const std::string& name, const std::string& config_path);

// The built-in names, comma-separated (for messages and docs).
std::string BuiltinColorSpaceNames();

}  // namespace skybake
