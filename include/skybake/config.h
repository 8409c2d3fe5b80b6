// A sky style: the physical atmosphere, the sun, the render and output
// settings, read from a TOML file. Every key is optional; a missing key keeps
// its default (see configs/default.toml, which lists them all with units).
//
// Errors are collected, not thrown one by one: a style with three mistakes
// reports all three, each with file:line:column and the key path.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "skybake/aoas.h"
#include "skybake/atmosphere.h"

namespace skybake {

enum class PixelType { kHalf, kFloat };
// What a value beyond half-float range does: scale the whole image by a power
// of two (recorded in the EXR `whiteLuminance`), or refuse to write.
enum class OverflowPolicy { kScale, kRefuse };
// kLuminance: linear Rec.709 in cd/m^2 (radiance times Bruneton 2017's
// SKY_SPECTRAL_RADIANCE_TO_LUMINANCE); kSpectral: W m^-2 sr^-1 nm^-1 at
// 680/550/440 nm, the unit of the Kider 2014 measurements.
enum class OutputUnits { kLuminance, kSpectral };

struct SunSettings {
  double elevation_deg = 45.0;  // above the horizon
  double azimuth_deg = 135.0;   // clockwise from North
};

struct RenderSettings {
  int cube_size = 512;       // cube face edge, texels
  int latlong_height = 512;  // latlong is 2 x height by height
  int device = -1;           // Vulkan device index; -1 = best available
};

// Deflate level of ZIP-compressed EXRs, chosen from the codec table of
// docs/performance.md (`build/tests/exr_codec_benchmark`).
constexpr int kDefaultZipLevel = 2;

struct OutputSettings {
  std::string basename = "sky";
  PixelType pixel_type = PixelType::kHalf;
  std::string compression = "zip";  // none | rle | zips | zip | piz
  int zip_level = kDefaultZipLevel;  // deflate level of zip and zips, 1..9
  OverflowPolicy overflow = OverflowPolicy::kScale;
  OutputUnits units = OutputUnits::kLuminance;
  bool faces = true;       // six face files
  bool cube_strip = true;  // one N x 6N cube strip
  bool latlong = true;     // one 2N x N latlong
  bool preview = true;     // tone-mapped sRGB PNG of the latlong
  std::vector<std::string> face_names = {"px", "nx", "py", "ny", "pz", "nz"};
};

struct PreviewSettings {
  bool auto_exposure = true;  // key the upper hemisphere's log-average to mid grey
  double ev100 = 14.0;        // used when auto_exposure is false
};

// The glTF 2.0 scene written beside the maps (see gltf_scene.h).
enum class DomeShape { kSphere, kHemisphere };
struct GltfSettings {
  bool enabled = true;              // write name.gltf (+ .bin) and name.glb
  DomeShape dome = DomeShape::kSphere;
  double radius_m = 1000.0;         // horizontal radius of the dome
  double flattening = 0.0;          // 0: round; f: vertical radius = (1 - f) * radius_m
  int segments = 64;                // around the horizon; half as many rings pole to pole
};

struct SkyStyle {
  AtmosphereParams atmosphere;
  std::string quality_preset = "production";  // see QualityPreset()
  QualitySettings quality;
  EffectSettings effects;
  SunSettings sun;
  RenderSettings render;
  OutputSettings output;
  PreviewSettings preview;
  AoasSettings aoas;          // the aesthetic principles (skydome, hue, ambiguity, clouds, shapes)
  GltfSettings gltf;
  std::string source_path;    // where it was read from
  std::string resolved_toml;  // every key with its final value, for provenance
};

// A user error located in an input file.
struct ConfigError {
  std::string file;
  int line = 0;    // 1-based; 0 when unknown
  int column = 0;  // 1-based; 0 when unknown
  std::string key; // dotted key path, e.g. "atmosphere.mie.g"
  std::string message;
  std::string Format() const;  // "file:line:col: key: message"
};

struct ConfigResult {
  SkyStyle style;
  std::vector<ConfigError> errors;
  // Not errors: the style bakes, but likely not as meant (a quality preset
  // whose every key is given explicitly, so it changes nothing).
  std::vector<ConfigError> warnings;
  bool ok() const { return errors.empty(); }
};

// Reads a style from `path`, applies `overrides` ("key.path=toml_value", as
// given to --set) on top, validates, and resolves. Never throws for user errors.
ConfigResult LoadSkyStyle(const std::string& path, const std::vector<std::string>& overrides = {});

// The same from TOML text, with `name` used in error locations.
ConfigResult ParseSkyStyle(std::string_view toml_text, const std::string& name,
                           const std::vector<std::string>& overrides = {});

// Per-channel factor from spectral radiance to the chosen output units.
Rgb OutputScale(OutputUnits units);

}  // namespace skybake
