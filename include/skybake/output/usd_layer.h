// The USD sky layer of a bake (NAME.usda, USD's text format written
// directly: Debian has no OpenUSD): a DomeLight textured with each frame's
// latlong EXR and a DistantLight for the Sun (and one for the Moon).
//
// Stage: upAxis "Y", metersPerUnit 1, skybake's own frame (+Y up,
// right-handed, North = -Z, East = +X). A sequence's values are time
// samples at its frame numbers (startTimeCode = first frame, endTimeCode =
// last frame, 24 time codes per second); a single bake's are plain values.
//
//   /Sky        Xform, customData "skybake": the bake's provenance and one
//               dictionary per frame (time, sun, style_sha256, latlong)
//   /Sky/Dome   DomeLight: inputs:texture:file = the frame's latlong EXR
//               ("./NAME_latlong.NNNN.exr"), inputs:texture:format
//               "latlong". UsdLux orients a latlong dome as OpenEXR's
//               latlong with the pole along +Y, which is skybake's layout
//               (Imf::LatLongMap): no transform. Emitted radiance in nits
//               = texel x inputs:intensity (1) x 2^inputs:exposure, and
//               exposure = -log2(skybake:scale of the file), so the dome
//               emits the sky's cd/m^2.
//               inputs:texture:file carries colorSpace metadata naming
//               the EXR's colour space (UsdColorSpaceToken).
//   /Sky/Sun    DistantLight, normalize = true: inputs:intensity x
//   /Sky/Moon   2^exposure x inputs:color is the illuminance (lux, per
//               channel) on a surface facing the light; intensity is the
//               manifest's illuminance_lux, colour = irradiance /
//               illuminance (Rec.709 luminance 1), exposure 0; the
//               colour stays linear Rec.709 whatever output.color_space
//               (colorSpace "lin_rec709_scene", USD's default space);
//               inputs:angle is the disc's angular diameter in degrees;
//               xformOp:rotateXYZ turns the light's +Z towards the source
//               (a DistantLight shines along its -Z).
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "skybake/model/atmosphere.h"

namespace skybake {

// One key of a distant light.
struct UsdDistantKey {
  glm::dvec3 direction{0, 1, 0};  // unit, towards the Sun or Moon
  double illuminance_lux = 0.0;   // at normal incidence
  Rgb irradiance{0, 0, 0};        // per channel, linear Rec.709, lux
  double angular_diameter_deg = 0.0;
};

struct UsdFrame {
  int number = 0;                      // frame number, the time code of a sequence's samples
  std::string latlong_file;            // the latlong EXR, a plain file name beside the layer
  double texture_scale = 1.0;          // its skybake:scale (stored value = cd/m^2 x scale)
  std::string color_space = "rec709";  // its skybake:color_space (output.color_space)
  std::string time;                    // ISO 8601, or "" without clock times
  double sun_elevation_deg = 0.0;
  double sun_azimuth_deg = 0.0;
  std::string style_sha256;
  UsdDistantKey sun;
  std::optional<UsdDistantKey> moon;  // the frame's moonlight, when it has one
};

struct UsdLayerDescription {
  std::string name;  // NAME.usda
  std::string out_dir;
  bool sequence = false;  // time samples at the frame numbers
  std::vector<UsdFrame> frames;
  // Provenance (the manifest's).
  std::string version, commit, style, schedule, sequence_sha256;
};

// "text" as a USD string literal: double quotes, with \\ \" \n \r \t and
// \xHH for the other control bytes escaped.
std::string UsdStringLiteral(std::string_view text);
// `path` as a USD asset path: @path@, or @@@path@@@ when it holds an '@'
// (an "@@@" inside it escaped as \@@@).
std::string UsdAssetPathLiteral(std::string_view path);

// The xformOp:rotateXYZ angles, degrees, (x, y, 0), that turn a light's +Z
// towards `direction`: x = -elevation, y = atan2(d.x, d.z). USD applies X
// first, then Y.
glm::dvec3 UsdRotateXyzTowards(const glm::dvec3& direction);

// The layer's text.
std::string UsdLayerText(const UsdLayerDescription& layer);

// Writes out_dir/NAME.usda atomically and returns its path. Throws
// OutputError.
std::string WriteUsdLayer(const UsdLayerDescription& layer);

// The skybake:scale recorded in an EXR written by skybake (1 when absent).
// Throws OutputError when the file cannot be read.
double ExrSkybakeScale(const std::string& path);
// Its skybake:color_space ("rec709" when absent). Throws OutputError.
std::string ExrSkybakeColorSpace(const std::string& path);

// The colorSpace token USD's colour guide gives an output.color_space: the
// canonical interoperable names (OpenUSD, MaterialX and OpenColorIO's
// shared set) for the built-in spaces, rec709 -> "lin_rec709_scene",
// acescg -> "lin_ap1_scene", aces2065-1 -> "lin_ap0_scene", rec2020 ->
// "lin_rec2020_scene", xyz -> "lin_ciexyzd65_scene"; a space of an
// OpenColorIO config keeps its config name.
std::string UsdColorSpaceToken(const std::string& skybake_name);

}  // namespace skybake
