// Volumetric cloud layers of a sky style, and their packing for the cloud
// passes (shaders/clouds.glsl). Not to be confused with the AOAS `[clouds]`
// principle (saturation noise, eq. 7-8, aoas.h): these are `[[cloud_layer]]`
// tables, up to kMaxCloudLayers of them, each a spherical shell of cloud
// above the planet, ray-marched per output texel and lit by the atmosphere.
//
// Model (docs/clouds.md): the density of Schneider 2015 / Nubis (weather
// coverage x height profile x Perlin-Worley shape noise, eroded by Worley
// detail noise), Beer-Lambert extinction with the energy-conserving step
// integral (Hillaire 2016, section 5.6.3), the sun through the atmosphere's
// transmittance LUT and through the cloud (marched light steps), a dual-lobe
// Henyey-Greenstein phase with Wrenninge 2013's multiple-scattering octaves,
// ambient light of the sky above and the ground below at the sample's
// altitude, and the atmosphere between the viewer and every cloud sample
// (aerial-perspective LUT).
//
// Frame and units: the world frame of the sky (+Y up, North = -Z, East = +X);
// altitudes, thicknesses and sizes in metres, extinction in 1/m, wind in m/s
// ([east, north]), shear in m/s per km of height above the layer's bottom.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "skybake/model/atmosphere.h"
#include "skybake/model/cloud_formation.h"
#include "skybake/gpu_shared.h"

namespace skybake {

constexpr int kMaxCloudLayers = CLOUD_MAX_LAYERS;

// Height profiles: where in the layer (0 = bottom, 1 = top) the cloud grows
// from nothing to full density and fades out again.
enum class CloudType { kStratus, kStratocumulus, kCumulus, kCumulonimbus, kCirrus, kCustom };

// The profile of a type as [bottom_in, bottom_full, top_full, top_out]
// fractions of the layer's thickness (the remap stops of the Nubis height
// gradient, chosen for a layer of its own).
std::array<double, 4> CloudTypeProfile(CloudType type);
const char* CloudTypeName(CloudType type);

// Cirrus (type = "cirrus", docs/clouds.md "Cirrus"): the noise squeezed
// along the mean wind by the streak ratio, the fall streaks bent by the shear
// (hook = shear along the streaks / (2 v_f), v_f the crystals' fall speed),
// and the ice phase (shaders/cloud_ice_phase.glsl) in place of the water one.
// kCirrusFallSpeedM_s: a typical terminal velocity of cirrus ice crystals,
// 0.5-1.5 m/s for crystals of 100-500 um (Heymsfield and Iaquinta 2000,
// "Cirrus crystal terminal velocities", J. Atmos. Sci. 57, 916-938).
constexpr double kCirrusDefaultStreakRatio = 8.0;
constexpr double kCirrusFallSpeedM_s = 1.0;

struct CloudLayer {
  double altitude_m = 1500.0;   // bottom of the layer above the ground
  double thickness_m = 1500.0;  // top = altitude_m + thickness_m
  CloudType type = CloudType::kCumulus;
  std::array<double, 4> profile = CloudTypeProfile(CloudType::kCumulus);  // type = "custom" sets it
  double coverage = 0.5;                                // 0: no cloud, 0.5: the weather map as is, 1: overcast
  double density_per_m = 0.05;                          // extinction at full density, 1/m
  double albedo = 0.99;                                 // single-scattering albedo
  double shape_amount = 1.0;                            // 0: a flat slab, 1: the full Perlin-Worley shape
  double shape_size_m = 4000.0;                         // edge of one tile of the shape noise
  double detail_amount = 0.35;                          // erosion by the detail noise, 0..1
  double detail_size_m = 400.0;                         // edge of one tile of the detail noise
  std::array<double, 2> wind_m_s = {0.0, 0.0};          // [east, north] at the bottom
  std::array<double, 2> shear_m_s_per_km = {0.0, 0.0};  // extra wind per km above the bottom
  std::optional<uint32_t> seed;                         // aoas.seed when unset
  // Weather map: procedural tiling noise of this extent, or an image.
  double weather_size_m = 30000.0;  // edge of one tile of the procedural weather map
  // false (default): the shape, detail and procedural weather are read
  // through a non-periodic domain warp (shaders/cloud_weather.glsl), so the
  // layer never repeats; true: they repeat with their tile sizes (a cloud
  // shadow map of whole tiles then wraps without a seam, CloudShadowTiles).
  bool tiling = false;
  std::string weather_image;                                      // EXR or PNG; R = coverage (0..1); "" = procedural
  std::array<double, 2> weather_extent_m = {30000.0, 30000.0};    // [east, north] size of the image
  std::array<double, 2> weather_origin_m = {-15000.0, -15000.0};  // [east, north] of its south-west corner
  CloudFormation formation;  // [cloud_layer.formation]: coverage from the automaton (cloud_formation.h)
  // type = "cirrus" only: the streaks' length over their width (the noise
  // squeezed along the layer's mean wind, shaders/cloud_cirrus.glsl).
  double streak_ratio = kCirrusDefaultStreakRatio;
};

// The streaks' direction (unit [east, north]): the wind at the layer's middle
// (wind + shear x half the thickness), or east when that is calm.
std::array<double, 2> CirrusStreakDirection(const CloudLayer& layer);

// Cloud sampling settings; quality.preset sets them, [quality] cloud_* keys
// refine them.
struct CloudQuality {
  int view_steps = 48;   // view samples per layer crossing of a texel
  int light_steps = 24;  // samples toward the Sun per lit view sample
  // Light samples nearest the view sample that read the volumes trilinearly;
  // the farther ones (and the bands above) read the nearest voxel, 8 times
  // fewer loads. >= light_steps: every light sample trilinear.
  int light_trilinear_steps = 8;
  int octaves = 8;                 // Wrenninge multiple-scattering octaves
  int shape_resolution = 64;       // shape noise volume edge, voxels
  int detail_resolution = 32;      // detail noise volume edge, voxels
  int weather_resolution = 256;    // procedural weather map edge, texels
  double max_distance_km = 300.0;  // no cloud beyond this distance from the viewer
  // Cloud panorama height over the finest view's (cloud_panorama.h); 0: every
  // view marches its own texels.
  double panorama_scale = 1.0;
  // The light volume (CloudLightVolume below): columns along each horizontal
  // axis (0: off, every light sample marched), altitude slices, and the
  // light steps nearest the view sample that stay exact.
  int light_volume_columns = 256;
  int light_volume_slices = 32;
  int light_volume_near_steps = 2;
};
CloudQuality CloudQualityPreset(const std::string& name);

struct CloudSettings {
  std::vector<CloudLayer> layers;
  CloudQuality quality;
  // The frame's local clock time, seconds since midnight of its date (a
  // schedule's clock times, local = UTC + utc_offset_hours; set per frame by
  // ResolveFrameStyles, not a style key): the clock of the layers' formations
  // (FormationTimeSeconds, cloud_formation.h). None for a single bake and a
  // schedule without clock times.
  std::optional<double> local_clock_s;
};

// The layers a bake renders: those with coverage and density above 0 (the
// others are pruned and change nothing), sorted by altitude.
std::vector<CloudLayer> ActiveCloudLayers(const CloudSettings& clouds);

// A problem with one layer found before any GPU work: `layer` indexes the
// style's [[cloud_layer]] tables (-1: the whole list), `key` the layer's key.
struct CloudProblem {
  int layer = -1;
  std::string key;
  std::string message;
};
// Cross-field checks: top above the atmosphere, >4 layers, a weather image
// that cannot be read (relative paths from `style_dir`). Ranges of single
// keys are checked while reading.
std::vector<CloudProblem> ValidateClouds(const CloudSettings& clouds, const AtmosphereParams& atmosphere,
                                         const std::string& style_dir);

// Loop iterations one texel of the cloud pass may run, at most: every band
// crossed with view_steps samples, each lit sample marching light_steps
// samples over every layer and summing the octaves. Lavapipe ends all the
// loops of an invocation after 65535 iterations in all (Mesa's
// LP_MAX_TGSI_LOOP_ITERATIONS, shared by every loop of a shader), which
// would cut the march short silently; the style check refuses settings
// above kMaxCloudLoopIterations.
double CloudLoopIterationsPerTexel(const CloudSettings& clouds);
constexpr double kMaxCloudLoopIterations = 60000.0;

// The Sun's elevation, deg, below which every sample the cloud march can
// take lies in the Earth's shadow (the cloud pass then runs without the
// Sun's light march: SPEC_CLOUD_SUN_LIGHT, clouds.glsl). Frame: the
// planet's centre at the origin, the observer `observer_altitude_km` above
// `bottom_radius_km`; every band's top at most `highest_top_km`, no sample
// beyond `max_distance_km` (quality.cloud_max_distance_km). The shader's
// disc visibility (CloudSunLight, as GetTransmittanceToSun) is exactly 0
// where mu_s <= cos_theta_h - sin_theta_h alpha at the sample's radius r
// (sin_theta_h = R / r, cos_theta_h = -sqrt(1 - (R / r)^2), alpha the Sun's
// angular radius): the whole disc below the sample's horizon. That bound
// falls with r (for r < R sqrt(1 + alpha^2) / alpha), so it is taken at the
// highest top. A sample's zenith is at most gamma from the observer's,
// 2 asin(t / 2R) for a sample t from the observer (the chord between the two
// radii is at least 2 R sin(gamma / 2)), and t is at most the distance along
// a ray that grazes the ground to the highest top, sqrt(r0^2 - R^2) +
// sqrt(r_top^2 - R^2), or max_distance_km. So mu_s <= cos(theta_s - gamma),
// theta_s the Sun's zenith angle at the observer. Conservative: 10 m on the
// top and 1e-4 on the cosine (about 0.006 deg) for the shader's float
// rounding. W3 (a 3 km top, 300 km): -3.80 deg.
double CloudEarthShadowElevationDeg(double bottom_radius_km, double observer_altitude_km, double highest_top_km,
                                    double max_distance_km, double sun_angular_radius_rad);

// The part of the cloud uniform block that depends on the layers' geometry
// alone: the counts and resolutions, each active layer's shell (bottom, top,
// extinction, albedo), profile and noise sizes, the distance range and the
// bands (the shells merged where they overlap). ToCloudInputs starts from it
// and adds each layer's wind, weather and noise offsets; the pass plan reads
// it without building the weather maps.
gpu::GpuClouds CloudGeometryUniform(const CloudSettings& clouds);

// CloudEarthShadowElevationDeg for the values the GPU is given: the highest
// band top of `clouds`, its distance bound (range.x), and the radii and the
// Sun's angular radius of `atmosphere`. The renderer (which frames run
// without the light march) and the pass plan (which frames it lists) both
// ask this, so they agree to the frame.
double CloudEarthShadowElevationDeg(const gpu::GpuClouds& clouds, const gpu::GpuAtmosphere& atmosphere);

// The light volume (quality.cloud_light_volume_*, clouds.glsl): per frame,
// the clouds' optical depth toward the Sun from points of the band, over the
// light march's own distance (CloudOpticalDepthToSun), on columns that
// follow the Sun's rays up through the band: a column starts at world (x, z)
// on the band's bottom, x and z each on a warped grid x = L sinh(u)
// (kCloudLightVolumeWarpKm: fine near the viewer, coarse far away, where a
// texel covers more cloud), and holds the depth at `slices` altitudes
// through the band. A lit view sample marches its first `near_steps` light
// steps (kCloudLightVolumeNearStepKm each) exactly and reads the rest from
// the volume, trilinearly, at the point the near steps reach. One band only
// (a style whose layers make two or more keeps the exact march), and only a
// Sun at least kCloudLightVolumeMinElevationDeg above the horizon: every
// column then rises through the band within the march's distance bound.
constexpr double kCloudLightVolumeWarpKm = 1.0;
constexpr double kCloudLightVolumeNearStepKm = 0.1;
constexpr double kCloudLightVolumeMinElevationDeg = 6.0;
// Samples of the column's march per slice interval (compiled into the shader).
constexpr int kCloudLightVolumeSubsteps = CLOUD_LIGHT_VOLUME_SUBSTEPS;
// Floats of the light volume (0 when off).
size_t CloudLightVolumeFloats(const gpu::GpuClouds& clouds);
// Whether a frame with the Sun at `sun_y` (the sine of its elevation) reads
// the light volume: on, one band, the Sun high enough.
bool CloudLightVolumeOn(const gpu::GpuClouds& clouds);
// Whether some layer's density is a cloud formation's volume (weather.w = 2,
// cloud_formation.h); off, the shaders compile that read out
// (SPEC_CLOUD_FORMATION).
bool CloudFormationDensityOn(const gpu::GpuClouds& clouds);
// Whether some active layer is cirrus (GpuCloudLayer.streaks.z > 0); off, the
// shaders compile the streaks and the ice phase out (SPEC_CLOUD_CIRRUS).
bool CloudCirrusOn(const gpu::GpuClouds& clouds);
bool CloudLightVolumeForSun(const gpu::GpuClouds& clouds, double sun_y);

// What the renderer needs: the uniform block, the weather images (R channel,
// resampled to the procedural map's resolution), and the sizes of the noise
// volumes. Empty `uniform.counts.x` (0 layers) means no cloud pass at all.
struct CloudInputs {
  gpu::GpuClouds uniform{};
  std::vector<float> weather_images;  // per layer with an image: resolution^2 floats, in layer order
  int layers() const { return uniform.counts.x; }
};
// `time_s`: clock time since the sequence's first frame; the wind moves the
// clouds by wind x time_s (no re-randomising per frame). A layer with a
// formation runs on the formation's clock instead (FormationTimeSeconds of
// clouds.local_clock_s, cloud_formation.h): its wind, drift and lattice.
CloudInputs ToCloudInputs(const CloudSettings& clouds, uint32_t aoas_seed, const std::string& style_dir, double time_s);

// Floats of the noise buffer (shape, detail and weather of every active
// layer, then the empty-space bounds of every layer), and where each part of
// layer i starts.
size_t CloudNoiseFloats(const gpu::GpuClouds& clouds);

// The empty-space bounds of the view march (clouds.glsl, CloudMargin), after
// every layer's noise in the noise buffer: per layer its weather map's
// maximum over each cell between 2 x 2 texel centres, then its shape
// volume's over each cell between 2^3 voxel centres (cell i along an axis:
// texels i and i + 1, wrapping as the noise tiles: one cell per texel).
// Those are exactly the texels a bilinear (trilinear) read at a point of the
// cell reads, so the bound is the tightest a maximum can be; a point within
// CLOUD_SKIP_EDGE of a cell's edge is not bounded (rounding could put the
// read in the next cell) and is marched. Where the weather and shape maxima
// times the height profile stay below Schneider's coverage threshold,
// LayerExtinction is 0 and the march skips the density.
size_t CloudSkipFirst(const gpu::GpuClouds& clouds);  // the first float of layer 0's bounds
size_t CloudSkipFloatsPerLayer(const gpu::GpuClouds& clouds);
// Writes every layer's bounds from its noise (`noise`: CloudNoiseFloats
// floats, the noise already generated). A formation's density volume (in the
// shape volume's place) is not bounded: its cells hold 1, and CloudMargin
// marches such a layer's every sample.
void FillCloudSkipMaps(const gpu::GpuClouds& clouds, float* noise);

// Reads a weather image's first channel (coverage) resampled to
// `resolution` x `resolution` (rows from the north edge); throws
// std::runtime_error naming the path when it cannot.
std::vector<float> ReadWeatherImage(const std::string& path, int resolution);
// Checks a weather image without keeping its pixels: "" or what is wrong.
std::string CheckWeatherImage(const std::string& path);

}  // namespace skybake
