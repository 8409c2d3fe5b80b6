// Uniform, push-constant and binding layout shared by the C++ host code and the
// GLSL compute shaders. This one file is compiled by both languages, so the two
// sides cannot drift apart. Every member is a vec4/ivec4 so that the std140 and
// C++ layouts are identical without padding rules.
//
// Frames and units: lengths in km, scattering coefficients in km^-1, angles in
// radians, +Y up; sun_direction points towards the Sun.
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

// Descriptor bindings, all in set 0.
#define BINDING_ATMOSPHERE 0       // uniform GpuAtmosphere
#define BINDING_TRANSMITTANCE 1    // storage vec4[], transmittance LUT
#define BINDING_MULTISCATTERING 2  // storage vec4[], multiple-scattering LUT
#define BINDING_OUTPUT 3           // storage vec4[], rendered texels
#define BINDING_SKYVIEW 4          // storage vec4[], sky-view LUT

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
  vec4 output_scale;           // xyz: per-channel factor applied to radiance before output; w: unused
  ivec4 lut_sizes;             // x,y: transmittance LUT; z,w: multiple-scattering LUT
  ivec4 samples;               // x: view steps; y: transmittance LUT steps; z: multi-scattering steps; w: integrator
  ivec4 effects;               // x: multiple scattering on; y: sun disc on; z: ground on; w: ms sqrt(directions)
  ivec4 render;                // x: light steps (0: transmittance LUT); y,z: sky-view LUT size; w: step distribution
  vec4 strengths;              // x: multiple-scattering strength; y: sun-disc strength; zw: unused
};

SKYBAKE_GPU_STRUCT(SkyPush) {
  vec4 sun_direction;  // xyz: unit vector towards the Sun; w: unused
  ivec4 view;          // x: mapping; y: width; z: height; w: cube face (MAPPING_VULKAN_FACE)
  ivec4 offsets;       // x: first output texel of this view in the output buffer
};

#ifdef __cplusplus
static_assert(sizeof(GpuAtmosphere) == 13 * 16, "GpuAtmosphere must be vec4-packed");
static_assert(sizeof(SkyPush) == 3 * 16, "SkyPush must be vec4-packed");
}  // namespace skybake::gpu
#endif

#endif  // SKYBAKE_GPU_SHARED_H
