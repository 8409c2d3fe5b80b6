// A sky style: the physical atmosphere, the sun, the render and output
// settings, read from a TOML file. Every key is optional; a missing key keeps
// its default (see configs/default.toml, which lists them all with units).
//
// Errors are collected, not thrown one by one: a style with three mistakes
// reports all three, each with file:line:column and the key path.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "skybake/aoas.h"
#include "skybake/atmosphere.h"
#include "skybake/cloud_shadow.h"
#include "skybake/clouds.h"

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

// Image-based lighting outputs from the same bake (include/skybake/ibl.h):
// split-sum GGX-prefiltered radiance, an irradiance cube, the DFG table. All
// off by default, and then no pass runs and no key is recorded.
enum class KtxFormat { kRgba16f, kB10g11r11, kE5b9g9r9 };
struct IblSettings {
  bool specular = false;        // GGX-prefiltered radiance, one cube mip level per roughness
  bool irradiance = false;      // irradiance cube, stored as E / pi (a white Lambertian surface's radiance)
  bool dfg = false;             // split-sum DFG table (N.V x roughness -> scale, bias of F0)
  int size = 256;               // face edge of level 0, texels: a power of two in [8, 1024]
  int levels = 0;               // mip levels; 0: down to 8 x 8 (log2(size) - 2); at most log2(size) + 1
  int samples = 256;            // GGX samples per texel of a level (filtered importance sampling)
  int irradiance_size = 32;     // irradiance face edge, texels
  int irradiance_samples = 512; // cosine samples per irradiance texel
  int dfg_size = 128;           // DFG table edge, texels
  int dfg_samples = 1024;       // GGX samples per DFG texel
  double lod_bias = 0.0;        // mip bias of the filtered lookups, log2 texels (docs/ibl.md: 0 measured best)
  bool include_sun = false;     // the Sun's energy in the maps (else it is the glTF sun light alone)
  bool exr = true;              // one EXR per cube level / irradiance / DFG
  bool ktx2 = false;            // KTX2 cube files with their mips
  KtxFormat ktx2_format = KtxFormat::kRgba16f;
  int ktx2_zstd_level = 0;      // 0: no supercompression; 1..19: zstd level
  bool Requested() const { return specular || irradiance || dfg; }
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
  CloudSettings clouds;       // volumetric [[cloud_layer]] tables and their sampling (clouds.h)
  CloudShadowSettings cloud_shadow;  // [cloud_shadow]: the frame's cloud shadow map (cloud_shadow.h)
  GltfSettings gltf;
  IblSettings ibl;
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

// The rule for every file name skybake writes into, or reads from, an output
// folder (output.basename, output.face_names, names read from manifests):
// 1 to 128 letters, digits, '_', '-', '.', '+', no "..", not starting with '.'.
bool IsPlainFileName(const std::string& name);

// `text` in single quotes for a message, with control characters, quotes
// and backslashes escaped (\n, \t, \x1b, \'), so nothing read from a file
// reaches the terminal raw.
std::string EscapedText(std::string_view text);

// Limits of a style or schedule file, checked before it is parsed: 16 MiB
// (a schedule of the documented 100,000 frames listed one by one is under
// 8 MiB) and dotted keys of at most 64 parts (skybake's have at most 5; the
// TOML parser recurses once per part and 50,000 overflow its stack).
inline constexpr size_t kMaxInputBytes = size_t(16) << 20;
inline constexpr size_t kMaxKeyParts = 64;

// Reads a style or schedule file (`what`: "style", "schedule") into `text`:
// a regular file (not a directory, device or pipe) of at most
// kMaxInputBytes; otherwise the error, at `(file)`.
std::optional<ConfigError> ReadInputFile(const std::string& path, const char* what, std::string& text);

// The error for a key of more than kMaxKeyParts parts in `text`, located.
std::optional<ConfigError> DeepKeyError(std::string_view text, const std::string& name);

// Per-channel factor from spectral radiance to the chosen output units.
Rgb OutputScale(OutputUnits units);

}  // namespace skybake
