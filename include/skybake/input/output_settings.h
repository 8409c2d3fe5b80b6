// The output part of a sky style ([output], [preview], [gltf], [ibl]): what
// files a bake writes and how they are encoded. Apart from the rest of the
// style so that the file writers (output/) read these settings alone.
#pragma once

#include <string>
#include <vector>

#include "skybake/model/spectrum.h"

namespace skybake {

enum class PixelType { kHalf, kFloat };
// What a value beyond half-float range does: scale the whole image by a power
// of two (recorded in the EXR `whiteLuminance`), or refuse to write.
enum class OverflowPolicy { kScale, kRefuse };
// kLuminance: linear Rec.709 in cd/m^2 (radiance times Bruneton 2017's
// SKY_SPECTRAL_RADIANCE_TO_LUMINANCE); kSpectral: W m^-2 sr^-1 nm^-1 at
// 680/550/440 nm, the unit of the Kider 2014 measurements.
enum class OutputUnits { kLuminance, kSpectral };
// Where the Sun goes (docs/colour.md): kLight, the maps hold the sky (and
// Moon, stars, clouds) without the solar disc and the Sun is a light (its
// illuminance, colour, direction and angular radius in the manifest, the
// glTF and the engine files), so half-float files need no scale; kMap, the
// disc is drawn into the maps too (a half-float bake then scales every file
// by a power of two to fit it, skybake:scale) and the light is written as
// well: a client that uses both counts the Sun twice.
enum class SunOutput { kLight, kMap };

// Deflate level of ZIP-compressed EXRs, chosen from the codec table of
// docs/performance.md (`build/tests/exr_codec_benchmark`).
constexpr int kDefaultZipLevel = 2;

struct OutputSettings {
  std::string basename = "sky";
  PixelType pixel_type = PixelType::kHalf;
  std::string compression = "zip";   // none | rle | zips | zip | piz
  int zip_level = kDefaultZipLevel;  // deflate level of zip and zips, 1..9
  OverflowPolicy overflow = OverflowPolicy::kScale;
  OutputUnits units = OutputUnits::kLuminance;
  SunOutput sun = SunOutput::kLight;
  // The colour space of luminance output's EXR maps (their
  // `chromaticities` and `skybake:color_space`): a built-in space or one of
  // an OpenColorIO config (ocio_color_space.h); previews, glTF and SH stay
  // Rec.709.
  OutputColorSpace color_space;
  std::string ocio_config;  // the config that names color_space; empty: $OCIO
  bool faces = true;        // six face files
  bool cube_strip = true;   // one N x 6N cube strip
  bool latlong = true;      // one 2N x N latlong
  bool preview = true;      // tone-mapped sRGB PNG of the latlong
  std::vector<std::string> face_names = {"px", "nx", "py", "ny", "pz", "nz"};
  std::string engine = "none";  // an engine preset (engine_preset.h) writes its files too
};

struct PreviewSettings {
  bool auto_exposure = true;  // key the upper hemisphere's log-average to mid grey
  double ev100 = 14.0;        // used when auto_exposure is false
};

// The glTF 2.0 scene written beside the maps (see gltf_scene.h).
enum class DomeShape { kSphere, kHemisphere };
struct GltfSettings {
  bool enabled = true;  // write name.gltf (+ .bin) and name.glb
  DomeShape dome = DomeShape::kSphere;
  // Horizontal radius of the dome. Within every client's default camera
  // range from where that camera starts: Blender's startup camera clips at
  // 100 m and stands 11.3 m from the origin, three.js's PerspectiveCamera at
  // 2000 m, Babylon.js's cameras at 10000 m (docs/engines.md, "The dome and
  // the clients' default cameras").
  double radius_m = 50.0;
  double flattening = 0.0;         // 0: round; f: vertical radius = (1 - f) * radius_m
  int segments = 64;               // around the horizon; half as many rings pole to pole
  bool image_based_light = false;  // EXT_lights_image_based from ibl.specular (gltf_ibl.h)
};

// The USD sky layer written beside the maps (usd_layer.h): NAME.usda with
// a DomeLight textured with each frame's latlong EXR and a DistantLight for
// the Sun (and the Moon). Off by default, and then no key is recorded.
struct UsdSettings {
  bool enabled = false;  // write name.usda (needs output.latlong and luminance units)
};

// Image-based lighting outputs from the same bake (include/skybake/ibl.h):
// split-sum GGX-prefiltered radiance, an irradiance cube, the DFG table. All
// off by default, and then no pass runs and no key is recorded.
enum class KtxFormat { kRgba16f, kB10g11r11, kE5b9g9r9 };
struct IblSettings {
  bool specular = false;         // GGX-prefiltered radiance, one cube mip level per roughness
  bool irradiance = false;       // irradiance cube, stored as E / pi (a white Lambertian surface's radiance)
  bool dfg = false;              // split-sum DFG table (N.V x roughness -> scale, bias of F0)
  int size = 256;                // face edge of level 0, texels: a power of two in [8, 1024]
  int levels = 0;                // mip levels; 0: down to 8 x 8 (log2(size) - 2); at most log2(size) + 1
  int samples = 256;             // GGX samples per texel of a level (filtered importance sampling)
  int irradiance_size = 32;      // irradiance face edge, texels
  int irradiance_samples = 512;  // cosine samples per irradiance texel
  int dfg_size = 128;            // DFG table edge, texels
  int dfg_samples = 1024;        // GGX samples per DFG texel
  double full_samples_roughness =
      0.0;                   // 0: ibl.samples at every level; r > 0: fewer below roughness r (IblLevelSamples)
  double lod_bias = 0.0;     // mip bias of the filtered lookups, log2 texels (docs/ibl.md: 0 measured best)
  bool include_sun = false;  // the Sun's energy in the maps (else it is the glTF sun light alone)
  bool exr = true;           // one EXR per cube level / irradiance / DFG
  bool ktx2 = false;         // KTX2 cube files with their mips
  KtxFormat ktx2_format = KtxFormat::kRgba16f;
  int ktx2_zstd_level = 0;  // 0: no supercompression; 1..19: zstd level
  bool Requested() const { return specular || irradiance || dfg; }
};

}  // namespace skybake
