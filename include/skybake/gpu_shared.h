// Uniform, push-constant and binding layout shared by the C++ host code and the
// GLSL compute shaders. This one file is compiled by both languages, so the two
// sides cannot drift apart. Every member is a vec4/ivec4 so that the std140 and
// C++ layouts are identical without padding rules.
//
// Frames and units: lengths in km, scattering coefficients in km^-1, angles in
// radians, +Y up; sun_direction points towards the Sun.
//
// Not laid out by clang-format: glslang reads it too, and its tables of
// constants keep their comments on their own lines.
// clang-format off
#ifndef SKYBAKE_GPU_SHARED_H
#define SKYBAKE_GPU_SHARED_H

#ifdef __cplusplus
#include <cstdint>
namespace skybake::gpu {
struct alignas(16) vec4 { float x, y, z, w; };
struct alignas(16) ivec4 { int32_t x, y, z, w; };
#define SKYBAKE_GPU_STRUCT(name) struct name
#else
#define SKYBAKE_GPU_STRUCT(name) struct name
#endif

// Specialization constants (constant_id) of the sky and cloud shaders
// (shaders/common.glsl, clouds.glsl). SkyRenderer::CreatePipeline gives every
// pipeline all of them; a shader that does not use one ignores it.
#define SPEC_MULTIPLE_SCATTERING 0  // bool, EffectSettings
#define SPEC_SUN_DISC 1             // bool
#define SPEC_GROUND 2               // bool
#define SPEC_OUTPUT_DIRECTION 3     // bool: write texel directions (mapping tests)
#define SPEC_SKYDOME 4              // bool, the AOAS principles that act per texel
#define SPEC_AMBIGUITY 5            // bool
#define SPEC_CLOUD_NOISE 6          // bool
#define SPEC_CLOUD_SHAPES 7         // bool
#define SPEC_INTEGRATOR 10          // int INTEGRATOR_*, the quality settings
#define SPEC_USE_SKY_VIEW 11        // bool
#define SPEC_MIE 12                 // bool, the constituents and night dimming
#define SPEC_OZONE 13               // bool
#define SPEC_NIGHT 14               // bool
#define SPEC_SUN_DISC_PASS 15       // bool: sky_render as the sun-disc pass
#define SPEC_TWILIGHT_MARCH 16      // bool: the twilight band is ray-marched (quality.twilight_march_band_deg)
#define SPEC_CLOUD_LAYERS 20        // int: the active volumetric cloud layers
#define SPEC_CLOUD_SUN_LIGHT 21     // bool: the Sun lights the clouds (off: every band in the Earth's shadow)
#define SPEC_CLOUD_LIGHT_VOLUME 22  // bool: the light march's far part read from the frame's light volume (clouds.h)
#define SPEC_GROUND_CLOUD_SHADOW 23  // bool: the clouds' shadow on the ground below the horizon (GpuClouds.ground_shadow.x > 0)
#define SPEC_TEXEL_VIEWS 24          // bool: the reads go through the texel views (off: a buffer has more texels than the device's texel buffers hold)
#define SPEC_CLOUD_FORMATION 25      // bool: some layer's density is a formation's volume (GpuCloudLayer.weather.w = 2; CloudFormationDensityOn)
#define SPEC_CLOUD_CIRRUS 31         // bool: some layer is cirrus (GpuCloudLayer.streaks.z > 0; CloudCirrusOn): streaks, ice phase

// Descriptor bindings, all in set 0.
#define BINDING_ATMOSPHERE 0       // uniform GpuAtmosphere
#define BINDING_TRANSMITTANCE 1    // storage vec4[], transmittance LUT
#define BINDING_MULTISCATTERING 2  // storage vec4[], multiple-scattering LUT
#define BINDING_OUTPUT 3           // storage vec4[], rendered texels
#define BINDING_SKYVIEW 4          // storage uint64[], sky-view LUT (PackSkyViewTexel)
#define BINDING_AOAS 5             // uniform GpuAoas, the style's aesthetic principles
#define BINDING_CLOUDS 6           // uniform GpuClouds, the volumetric cloud layers (clouds.h)
#define BINDING_CLOUD_NOISE 7      // storage float[], per layer: shape volume, detail volume, weather map
#define BINDING_CLOUD_LUT 8        // storage vec4[], aerial perspective LUT, then the ambient light table
#define BINDING_DISPATCH 9         // storage SkyPush[], each dispatch's constants (the push constant is its index)
// Texel views (uniform texel buffers) of the storage buffers above, the
// same bytes, for the shaders' reads (SPEC_TEXEL_VIEWS; SkyRenderer::TexelViewRange).
#define BINDING_CLOUD_NOISE_TEXELS 10     // samplerBuffer, R32_SFLOAT: BINDING_CLOUD_NOISE
#define BINDING_CLOUD_TABLE_TEXELS 11     // samplerBuffer, R32G32B32A32_SFLOAT: BINDING_CLOUD_LUT's tables (not the panorama after them)
#define BINDING_TRANSMITTANCE_TEXELS 12   // samplerBuffer, R32G32B32A32_SFLOAT: BINDING_TRANSMITTANCE
#define BINDING_MULTISCATTERING_TEXELS 13 // samplerBuffer, R32G32B32A32_SFLOAT: BINDING_MULTISCATTERING
#define BINDING_SKYVIEW_TEXELS 14         // usamplerBuffer, R32G32_UINT: BINDING_SKYVIEW's 64-bit words
#define TEXEL_VIEW_COUNT 5                // bindings BINDING_CLOUD_NOISE_TEXELS on

// Output mappings (SkyPush.view.x).
#define MAPPING_LATLONG 0      // OpenEXR latlong, 2N x N, Imf::LatLongMap
#define MAPPING_CUBE_STRIP 1   // OpenEXR cube strip, N x 6N, Imf::CubeMap
#define MAPPING_VULKAN_FACE 2  // one face of a Vulkan cube map, N x N
#define MAPPING_DIRECTIONS 3   // explicit directions read from the output buffer

// Integrators for the in-scattering integral (GpuAtmosphere.samples.w).
// Galaj & Wojciechowski 2019 study the midpoint, trapezoidal and Simpson
// rules; the analytic step of Hillaire 2020 is the default.
#define INTEGRATOR_ANALYTIC 0   // Hillaire 2020: source constant per step, exact transmittance
#define INTEGRATOR_MIDPOINT 1   // composite midpoint rule (Galaj 2019 eq. 4)
#define INTEGRATOR_TRAPEZOID 2  // composite trapezoidal rule (Galaj 2019 eq. 6)
#define INTEGRATOR_SIMPSON 3    // composite Simpson rule (Galaj 2019 eq. 8)

// Placement of the view-ray samples (GpuAtmosphere.render.w).
#define STEPS_UNIFORM 0    // t = t_max u (Galaj 2019)
#define STEPS_QUADRATIC 1  // t = t_max u^2, denser near the observer

// Workgroup size of every 2D compute shader.
#define SKYBAKE_LOCAL_SIZE_X 8
#define SKYBAKE_LOCAL_SIZE_Y 8

SKYBAKE_GPU_STRUCT(GpuAtmosphere) {
  vec4 rayleigh_scattering;    // xyz: km^-1 at sea level; w: scale height, km
  vec4 mie_scattering;         // xyz: km^-1 at sea level; w: scale height, km
  vec4 mie_extinction;         // xyz: km^-1 at sea level; w: phase anisotropy g
  vec4 absorption_extinction;  // xyz: ozone km^-1 at the tent peak; w: peak altitude, km
  vec4 ground_albedo;          // xyz: Lambertian albedo; w: ozone tent half width, km
  vec4 solar_irradiance;       // xyz: at the top of the atmosphere; w: sun angular radius, rad
  vec4 radii;                  // x: bottom radius km; y: top radius km; z: observer altitude km; w: limb darkening u
  vec4 output_scale;           // xyz: per channel, direct sunlight's radiance to output (the disc, sunlit clouds
                               // and ground; colour_conversion.h); w: unused
  ivec4 lut_sizes;             // x,y: transmittance LUT; z,w: multiple-scattering LUT
  ivec4 samples;               // x: view steps; y: transmittance LUT steps; z: multi-scattering steps; w: integrator
  ivec4 effects;               // x: multiple scattering on; y: sun disc on; z: ground on; w: ms sqrt(directions)
  ivec4 render;                // x: light steps (0: transmittance LUT); y,z: sky-view LUT size; w: step distribution
  vec4 strengths;              // x: multiple-scattering strength; y: sun-disc strength; zw: unused
  vec4 night;                  // xyz: night-sky radiance (output units before output_scale); w: strength
  vec4 twilight;               // x: twilight march band, rad (0: off); y: its view steps; z: sine of the Sun's
                               // elevation below which a frame is twilight; w: unused
  vec4 sky_to_output[3];       // rows (xyz): the air's scattered radiance to output (colour_conversion.h); w: unused
  vec4 ambient_to_direct[3];   // rows (xyz): inverse(diag(output_scale)) x sky_to_output, which gives the sky light
                               // that clouds scatter (their ambient table) the sky conversion; w: unused
};

// Most cloud-shape segments a style can have (GpuAoas.shape_segments). A
// point is one segment; a spline is sampled into kAoasSplineSubdivisions
// segments per span on the host.
#define AOAS_MAX_SHAPE_SEGMENTS 192

// Perlin 2002, "Improving Noise": the reference permutation of 0..255, the
// one table of Improved Perlin noise (shaders/aoas.glsl). The GPU reads it
// from GpuAoas.perlin_permutation rather than from a constant array: Mesa's
// lavapipe spends minutes compiling dynamic indexing into a 256-entry
// constant array.
#define SKYBAKE_PERLIN_PERMUTATION                                                       \
  151, 160, 137, 91, 90, 15, 131, 13, 201, 95, 96, 53, 194, 233, 7, 225, 140, 36, 103,  \
  30, 69, 142, 8, 99, 37, 240, 21, 10, 23, 190, 6, 148, 247, 120, 234, 75, 0, 26, 197,  \
  62, 94, 252, 219, 203, 117, 35, 11, 32, 57, 177, 33, 88, 237, 149, 56, 87, 174, 20,   \
  125, 136, 171, 168, 68, 175, 74, 165, 71, 134, 139, 48, 27, 166, 77, 146, 158, 231,   \
  83, 111, 229, 122, 60, 211, 133, 230, 220, 105, 92, 41, 55, 46, 245, 40, 244, 102,    \
  143, 54, 65, 25, 63, 161, 1, 216, 80, 73, 209, 76, 132, 187, 208, 89, 18, 169, 200,   \
  196, 135, 130, 116, 188, 159, 86, 164, 100, 109, 198, 173, 186, 3, 64, 52, 217, 226,  \
  250, 124, 123, 5, 202, 38, 147, 118, 126, 255, 82, 85, 212, 207, 206, 59, 227, 47,    \
  16, 58, 17, 182, 189, 28, 42, 223, 183, 170, 213, 119, 248, 152, 2, 44, 154, 163,     \
  70, 221, 153, 101, 155, 167, 43, 172, 9, 129, 22, 39, 253, 19, 98, 108, 110, 79, 113, \
  224, 232, 178, 185, 112, 104, 218, 246, 97, 228, 251, 34, 242, 193, 238, 210, 144,    \
  12, 191, 179, 162, 241, 81, 51, 145, 235, 249, 14, 239, 107, 49, 192, 214, 31, 181,   \
  199, 106, 157, 184, 84, 204, 176, 115, 121, 50, 45, 127, 4, 150, 254, 138, 236, 205,  \
  93, 222, 114, 67, 29, 24, 72, 243, 141, 128, 195, 78, 66, 215, 61, 156, 180

// The aesthetic principles of AOAS (Shen, Mallett, Shkurko 2019), see
// shaders/aoas.glsl. Lengths in skydome space are in the scene's units
// (dome.x is the dome radius); noise and perturbation sizes in dome radii.
SKYBAKE_GPU_STRUCT(GpuAoas) {
  vec4 dome;                // x: dome radius, scene units; y: l_pt, dome radii; z: perturbation grain, dome radii; w: unused
  vec4 viewer;              // xyz: viewer position P^s_v in skydome space, scene units; w: unused
  vec4 perturbation_offset; // xyz: seed offset of the perturbation field (noise space); w: unused
  vec4 noise;               // x: s_noise, dome radii; y: threshold; z: strength; w: shape strength
  vec4 noise_offset;        // xyz: drift + seed offset (noise space); w: unused
  vec4 color_scale;         // xyz: radiance -> Rec.709 RGB in which saturation is judged; w: unused
  ivec4 counts;             // x: shape segments; y: noise octaves; zw: unused
  // Segment i runs from shape_segments[2i] to shape_segments[2i+1] on the
  // unit sphere: xyz unit direction; w of the first: fade radius, rad;
  // w of the second: strength in [0, 1].
  vec4 shape_segments[2 * AOAS_MAX_SHAPE_SEGMENTS];
  // SKYBAKE_PERLIN_PERMUTATION, four entries per ivec4.
  ivec4 perlin_permutation[64];
};

SKYBAKE_GPU_STRUCT(SkyPush) {
  vec4 sun_direction;  // xyz: unit vector towards the Sun; w: unused
  ivec4 view;          // x: mapping; y: width; z: height; w: cube face (MAPPING_VULKAN_FACE), or the
                       // cloud panorama pass's block stride (CloudPanoramaBlockStride)
  ivec4 offsets;       // x: first output texel of this view in the output buffer; y: 1 = no sun disc;
                       // z: first direction of a MAPPING_DIRECTIONS view; w: cloud panorama and
                       // resample passes: the panorama's marched rows, begin + end x 65536
  ivec4 rect;          // sun-disc pass: texels [x, z) x [y, w) of the view
};

// Volumetric cloud layers (include/skybake/model/clouds.h, shaders/clouds.glsl).
// Lengths in km, extinction in km^-1; world x, z as in the sky's frame.
#define CLOUD_MAX_LAYERS 4
// What one dispatch of cloud_lut.comp computes (SkyPush.view.x).
#define CLOUD_PASS_AERIAL 0   // aerial-perspective LUT, once per sun position
#define CLOUD_PASS_AMBIENT 1  // sky/ground ambient light per altitude, once per sun position
#define CLOUD_PASS_SHAPE 2    // shape noise volume of layer SkyPush.view.w, once per renderer
#define CLOUD_PASS_DETAIL 3   // detail noise volume of layer SkyPush.view.w
#define CLOUD_PASS_WEATHER 4  // procedural weather map of layer SkyPush.view.w
#define CLOUD_PASS_LIGHT_VOLUME 5  // the light volume's columns (GpuClouds.light_volume), once per frame
// Modes of the cloud pass (SkyPush.rect.w; cloud_panorama.glsl, cloud_panorama.h).
#define CLOUD_MODE_MARCH 0     // march the view's own texels (no panorama)
#define CLOUD_MODE_PANORAMA 1  // march the panorama's texels into the cloud table buffer
#define CLOUD_MODE_RESAMPLE 2  // composite the view from the panorama
// The cloud panorama's narrowest row, texels (cloud_panorama.glsl, cloud_panorama.h).
#define CLOUD_PANORAMA_MIN_ROW_WIDTH 16
// The empty-space bounds (clouds.h, FillCloudSkipMaps; clouds.glsl, CloudMargin): one cell per
// texel interval of a weather map and a shape volume (the cell between texel centres i and i + 1,
// which a bilinear or trilinear read at any point of it touches alone). A point within this
// fraction of a cell of its edge is not bounded (rounding could put the read in the next cell).
#define CLOUD_SKIP_EDGE 1e-3
// The light volume's column march (clouds.glsl, ComputeCloudLightColumn): samples per slice interval.
// Compiled in: a per-lane integer division by a uniform is a scalar division per lane on lavapipe.
#define CLOUD_LIGHT_VOLUME_SUBSTEPS 1

SKYBAKE_GPU_STRUCT(GpuCloudLayer) {
  vec4 shell;           // x: bottom altitude km; y: top altitude km; z: extinction at full density km^-1; w: albedo
  vec4 profile;         // height-profile stops (bottom in, bottom full, top full, top out), fractions of the thickness
  vec4 shape;           // x: shape amount; y: 1 / shape tile, km^-1; z: detail amount; w: 1 / detail tile, km^-1
  vec4 weather;         // x: coverage; y: 1 / weather extent along x, km^-1; z: along z; w: 1 = user image
                        // (or a formation's coverage); 2 = also a formation's whole density, its volume in
                        // the shape volume's place (cloud_formation.h)
  vec4 wind_offset;     // xy: world x, z moved by the wind at the bottom, km; zw: more per km of height (shear), km/km
  vec4 weather_origin;  // xy: world x, z of the weather map's corner, km; z: the non-repeating warp's weather
                        // tile, km (0: the layer tiles); w: 1 = the weather read three times through the warp
                        // (shaders/cloud_weather.glsl)
  ivec4 noise;          // x, y, z: first float of the shape volume, detail volume, weather map; w: seed
  vec4 streaks;         // cirrus (shaders/cloud_cirrus.glsl): xy: unit world x, z along the streaks; z: their length
                        // over their width (0: not cirrus, the water phase); w: the fall streaks' hook, km^-1
};

SKYBAKE_GPU_STRUCT(GpuClouds) {
  ivec4 counts;      // x: layers; y: view steps per layer crossing; z: light steps; w: scattering octaves
  ivec4 resolution;  // x: shape volume edge; y: detail volume edge; z: weather map edge; w: bands
  ivec4 lut;         // aerial perspective LUT x: azimuth texels; y: zenith texels; z: distance slices; w: ambient altitudes
  vec4 phase;        // x: forward g; y: backward g; z: forward weight; w: unused
  vec4 octave;       // Wrenninge 2013 x: contribution a; y: attenuation b; z: eccentricity c; w: unused
  vec4 range;        // x: max cloud distance km; y: top altitude of the ambient table km; z: panorama scale;
                     // w: 1 = the view march skips empty space by the bounds after the noise (FillCloudSkipMaps)
  vec4 ground_shadow;  // the clouds' shadow on the ground the sky shows below the horizon (cloud_shadow.h):
                      // x: strength (0: off); y: samples per band crossing along the sun direction; zw: unused
  // The union of the layers' shells, overlapping layers merged: x, y: bottom
  // and top altitude km, by altitude; resolution.w of them. The view ray is
  // marched through each band it crosses, in order along the ray.
  vec4 bands[CLOUD_MAX_LAYERS];
  GpuCloudLayer layers[CLOUD_MAX_LAYERS];
  // The light volume (clouds.h, CloudLightVolume; clouds.glsl): the optical
  // depth toward the Sun of points of the band, per frame, on columns along
  // the Sun. x: columns along each of world x and z (0: off, the exact
  // march); y: altitude slices through the band; z: the exact light steps
  // nearest the view sample (kCloudLightVolumeNearStepKm each); w: the first
  // float of the volume in the noise buffer.
  ivec4 light_volume;
  // x: L, km, and y: U of the columns' warped grid, world x = L sinh(u) for u
  // over [-U, U]; z: the column march's samples per slice interval (CLOUD_LIGHT_VOLUME_SUBSTEPS, which the
  // shader uses); w: unused.
  vec4 light_volume_grid;
};


// --- Image-based lighting (shaders/ibl_prefilter.comp, bake/gpu/ibl.cc)
#define IBL_BINDING_SOURCE 0  // samplerCube: the sky without the Sun, RGBA float, its box-filtered mips
#define IBL_BINDING_OUTPUT 1  // storage vec4[]: the filtered texels, level after level
#define IBL_MODE_SPECULAR 0    // GGX-prefiltered radiance of one mip level (split sum, N = V = R)
#define IBL_MODE_IRRADIANCE 1  // cosine-filtered radiance E / pi (a white Lambertian surface's radiance)
#define IBL_MODE_DFG 2         // split-sum DFG table: x = N.V, y = perceptual roughness
#define IBL_MODE_GGX_SAMPLES 3 // a specular level's GGX sample table (GgxSampleEntry), shared by its texels
#define IBL_MODE_SPECULAR_GRID 4 // a specular level's wide-footprint samples on a grid 2^k coarser (IblGridOf)
#define IBL_MODE_GRID_RANGES 5 // the run of a level's sorted sample table each grid holds, and the table's weight
#define IBL_MAX_GRIDS 4        // coarse grids a specular level has at most (k = 1..4)

SKYBAKE_GPU_STRUCT(IblPush) {
  ivec4 target;         // x: IBL_MODE_*; y: face size of this level, texels; z: first output texel; w: samples
  ivec4 source;         // x: face size of the source's level 0, texels; y: source mip count;
                        // z: IBL_MODE_SPECULAR(_GRID): first entry of the level's sample table in the output;
                        // w: IBL_MODE_SPECULAR: first texel of the level's coarse grids; _GRID: the grid's k
  vec4 lobe;            // x: GGX alpha = roughness^2; y: mip bias of the filtered lookups (log2 texels);
                        // z: normalization W of the sun's kernel (IblSunKernelNormalization); w: 1 = add the sun
  vec4 sun_direction;   // xyz: unit vector towards the Sun; w: unused
  vec4 sun_irradiance;  // xyz: the Sun's irradiance at normal incidence (output units x sr); w: unused
  vec4 moon_direction;  // xyz: unit vector towards the Moon; w: unused
  vec4 moon_irradiance; // xyz: the Moon's irradiance, as sun_irradiance; w: 1 = add the Moon too (with lobe.w)
};

#ifdef __cplusplus
static_assert(sizeof(GpuCloudLayer) == 8 * 16, "GpuCloudLayer must be vec4-packed");
static_assert(sizeof(GpuClouds) == (9 + 9 * CLOUD_MAX_LAYERS) * 16, "GpuClouds must be vec4-packed");
static_assert(sizeof(IblPush) == 7 * 16, "IblPush must be vec4-packed");
static_assert(sizeof(GpuAtmosphere) == 21 * 16, "GpuAtmosphere must be vec4-packed");
static_assert(sizeof(SkyPush) == 4 * 16, "SkyPush must be vec4-packed");
static_assert(sizeof(GpuAoas) == (7 + 2 * AOAS_MAX_SHAPE_SEGMENTS + 64) * 16,
              "GpuAoas must be vec4-packed");
}  // namespace skybake::gpu
#endif

#endif  // SKYBAKE_GPU_SHARED_H
// clang-format on
