// Declarations shared by every compute shader: the uniform block, the LUT and
// output buffers, the push constants, the LUT fetch hooks of atmosphere.glsl,
// and the specialization constants that compile optional effects out.
#ifndef SKYBAKE_COMMON_GLSL
#define SKYBAKE_COMMON_GLSL

#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
// The sky-view variant with the twilight band's march compiled in
// (SkyRenderer::TwilightSkyPipeline).
#ifdef SKYBAKE_VARIANT_SKY_VIEW_TWILIGHT
#define SKYBAKE_VARIANT_SKY_VIEW
#endif
#include "glsl_prelude.glsl"
#include "skybake/gpu_shared.h"

layout(local_size_x = SKYBAKE_LOCAL_SIZE_X, local_size_y = SKYBAKE_LOCAL_SIZE_Y) in;

// A uniform block: lavapipe reads a uniform block's member at an offset the
// same for every lane once, a storage buffer's lane by lane (the LUT reads
// take the LUT sizes from it).
layout(std140, set = 0, binding = BINDING_ATMOSPHERE) uniform AtmosphereBlock {
  GpuAtmosphere gpu_atmosphere;
};
layout(std430, set = 0, binding = BINDING_TRANSMITTANCE) buffer TransmittanceBuffer {
  vec4 transmittance_texels[];
};
layout(std430, set = 0, binding = BINDING_MULTISCATTERING) buffer MultiScatteringBuffer {
  vec4 multiscattering_texels[];
};
layout(std430, set = 0, binding = BINDING_OUTPUT) buffer OutputBuffer {
  vec4 output_texels[];
};
// One 64-bit word per texel (PackSkyViewTexel): lavapipe fetches each
// component of a storage-buffer read with a loop over the SIMD lanes, so one
// word per texel instead of three floats makes the bilinear read that every
// output texel does a third as costly (docs/performance.md).
layout(std430, set = 0, binding = BINDING_SKYVIEW) buffer SkyViewBuffer {
  uint64_t skyview_texels[];
};
layout(std140, set = 0, binding = BINDING_AOAS) uniform AoasBlock {
  GpuAoas gpu_aoas;
};
// The dispatch's constants (SkyPush) come from a storage buffer, at the
// index the push constant gives, and not from push constants: lavapipe
// compiles a new variant of a shader for each new set of push-constant or
// uniform values that decide a branch ("inlined uniforms") and keeps every
// variant while the pipeline lives, so a sequence's new Sun every frame cost
// an LLVM compile and about 1 MiB that was never given back. Storage-buffer
// values are never inlined. (docs/performance_history.md, "Long sequences".)
layout(std430, set = 0, binding = BINDING_DISPATCH) readonly buffer DispatchBuffer {
  SkyPush dispatch_constants[];
};
layout(push_constant) uniform PushBlock {
  uint dispatch_index;
};
#define push dispatch_constants[dispatch_index]

// The LUTs' texel views (gpu_shared.h): lavapipe loads a storage buffer lane
// by lane, with a branch on the lane's mask and one on the buffer's bound per
// component, and a texel buffer with a vector gather. The values are the
// same, so are the bytes; the LUT passes write the storage buffers. Off
// (kTexelViews false) where a buffer has more texels than the device's texel
// buffers hold: the reads then use the storage buffers.
layout(constant_id = SPEC_TEXEL_VIEWS) const bool kTexelViews = true;
layout(set = 0, binding = BINDING_TRANSMITTANCE_TEXELS) uniform samplerBuffer transmittance_view;
layout(set = 0, binding = BINDING_MULTISCATTERING_TEXELS) uniform samplerBuffer multiscattering_view;
layout(set = 0, binding = BINDING_SKYVIEW_TEXELS) uniform usamplerBuffer skyview_view;

// Optional effects (EffectSettings); off effects are compiled out.
layout(constant_id = SPEC_MULTIPLE_SCATTERING) const bool kMultipleScattering = true;
layout(constant_id = SPEC_SUN_DISC) const bool kSunDisc = true;
layout(constant_id = SPEC_GROUND) const bool kGround = true;
layout(constant_id = SPEC_MIE) const bool kMie = true;
layout(constant_id = SPEC_OZONE) const bool kOzone = true;
layout(constant_id = SPEC_NIGHT) const bool kNight = false;
// Writes the texel direction instead of radiance (mapping tests).
layout(constant_id = SPEC_OUTPUT_DIRECTION) const bool kOutputDirection = false;
// sky_render as the sun-disc pass (SkyRenderer::Render): adds the disc to the
// texels of push.rect that the sky pass wrote without it. Its variant
// (CMakeLists.txt) has the pass fixed, so that glslang drops the sky pass's
// code and lavapipe has a fifth of the SPIR-V to translate.
#ifdef SKYBAKE_VARIANT_SUN_DISC_PASS
const bool kSunDiscPass = true;
#else
layout(constant_id = SPEC_SUN_DISC_PASS) const bool kSunDiscPass = false;
#endif
// The AOAS principles (AoasSwitches); a style that does not use one compiles
// it out. The sky hue needs no switch: it is the Rayleigh vector itself.
#ifdef SKYBAKE_VARIANT_SKY_VIEW
// The sky-view variant of sky_render (CMakeLists.txt): texels read the
// sky-view LUT and the skydome is off, fixed when compiling, so that the
// per-texel ray march is not in the SPIR-V at all.
const bool kSkydome = false;
#else
layout(constant_id = SPEC_SKYDOME) const bool kSkydome = false;
#endif
layout(constant_id = SPEC_AMBIGUITY) const bool kAmbiguity = false;
layout(constant_id = SPEC_CLOUD_NOISE) const bool kCloudNoise = false;
layout(constant_id = SPEC_CLOUD_SHAPES) const bool kCloudShapes = false;
// Quadrature rule (INTEGRATOR_*) and whether output texels read the sky-view
// LUT instead of ray-marching; ids from 10 on are the quality settings.
#ifdef SKYBAKE_VARIANT_ANALYTIC
// The analytic variant of a LUT shader (CMakeLists.txt): the other rules
// compiled out.
const int kIntegrator = INTEGRATOR_ANALYTIC;
#else
layout(constant_id = SPEC_INTEGRATOR) const int kIntegrator = INTEGRATOR_ANALYTIC;
#endif
#ifdef SKYBAKE_VARIANT_SKY_VIEW
const bool kUseSkyView = true;
#else
layout(constant_id = SPEC_USE_SKY_VIEW) const bool kUseSkyView = false;
#endif
// The per-texel march of the twilight band (InTwilightMarchBand): off in the
// sky-view variant, so that its SPIR-V keeps no ray march, on in its
// twilight form; the pipeline of a frame whose Sun is below the band has it.
#ifdef SKYBAKE_VARIANT_SKY_VIEW_TWILIGHT
const bool kTwilightMarch = true;
#elif defined(SKYBAKE_VARIANT_SKY_VIEW)
const bool kTwilightMarch = false;
#define SKYBAKE_NO_TWILIGHT_MARCH
#else
layout(constant_id = SPEC_TWILIGHT_MARCH) const bool kTwilightMarch = false;
#endif

vec3 TransmittanceLutTexel(int x, int y) {
  int i = y * gpu_atmosphere.lut_sizes.x + x;
  return kTexelViews ? texelFetch(transmittance_view, i).xyz : transmittance_texels[i].xyz;
}

vec3 MultipleScatteringLutTexel(int x, int y) {
  int i = y * gpu_atmosphere.lut_sizes.z + x;
  return kTexelViews ? texelFetch(multiscattering_view, i).xyz : multiscattering_texels[i].xyz;
}

// Three non-negative floats in one 64-bit word, 21 bits each: the float32
// bits without the sign bit, rounded to 12 mantissa bits, so the relative
// error of a texel is at most 2^-13 = 1.2e-4 (the sky-view LUT's own error
// in the production preset is 8.6e-3, docs/accuracy_skyview_results.md).
uint64_t PackSkyViewTexel(vec3 radiance) {
  uvec3 bits = min((floatBitsToUint(max(radiance, vec3(0.0))) + 0x400u) >> 11, uvec3(0x1FFFFFu));
  return packUint2x32(uvec2(bits.x | (bits.y << 21), (bits.y >> 11) | (bits.z << 10)));
}

vec3 UnpackSkyViewTexel(uint64_t word) {
  uvec2 halves = unpackUint2x32(word);
  uvec3 bits = uvec3(halves.x & 0x1FFFFFu, (halves.x >> 21) | ((halves.y & 0x3FFu) << 11),
                     (halves.y >> 10) & 0x1FFFFFu);
  return uintBitsToFloat(bits << 11);
}

vec3 SkyViewLutTexel(int x, int y) {
  int i = y * gpu_atmosphere.render.y + x;
  return UnpackSkyViewTexel(kTexelViews ? packUint2x32(texelFetch(skyview_view, i).xy) : skyview_texels[i]);
}

vec4 ShapeSegmentStart(int i) { return gpu_aoas.shape_segments[2 * i]; }
vec4 ShapeSegmentEnd(int i) { return gpu_aoas.shape_segments[2 * i + 1]; }
int PerlinPermutation(int i) { return gpu_aoas.perlin_permutation[i >> 2][i & 3]; }

#include "atmosphere.glsl"
#include "aoas.glsl"
#include "envmap.glsl"

// The air's scattered radiance to the output's colour: the frame's sky
// conversion (colour_conversion.h).
vec3 SkyToOutput(vec3 radiance) {
  return vec3(dot(gpu_atmosphere.sky_to_output[0].xyz, radiance), dot(gpu_atmosphere.sky_to_output[1].xyz, radiance),
              dot(gpu_atmosphere.sky_to_output[2].xyz, radiance));
}

// Whether `view` meets the ground: the test of SetUpSkyRay, which for an
// observer inside the atmosphere needs none of the ray's distances.
bool SeesGround(IN(AtmosphereParameters) atm, vec3 view) {
  if (atm.observer_altitude > atm.top_radius - atm.bottom_radius) {
    SkyRay ray = SetUpSkyRay(atm, view, vec3(0.0, 1.0, 0.0));
    return ray.in_atmosphere && ray.hits_ground;
  }
  return RayIntersectsGround(atm, atm.bottom_radius + atm.observer_altitude, atm.observer_altitude, ClampCosine(view.y));
}

AtmosphereParameters AtmosphereFromUniform() {
  AtmosphereParameters atm;
  atm.bottom_radius = gpu_atmosphere.radii.x;
  atm.top_radius = gpu_atmosphere.radii.y;
  atm.observer_altitude = gpu_atmosphere.radii.z;
  atm.rayleigh_scattering = gpu_atmosphere.rayleigh_scattering.xyz;
  atm.rayleigh_scale_height = gpu_atmosphere.rayleigh_scattering.w;
  atm.mie_scattering = gpu_atmosphere.mie_scattering.xyz;
  atm.mie_extinction = gpu_atmosphere.mie_extinction.xyz;
  atm.mie_scale_height = gpu_atmosphere.mie_scattering.w;
  atm.mie_g = gpu_atmosphere.mie_extinction.w;
  atm.absorption_extinction = gpu_atmosphere.absorption_extinction.xyz;
  atm.ozone_peak_altitude = gpu_atmosphere.absorption_extinction.w;
  atm.ozone_half_width = gpu_atmosphere.ground_albedo.w;
  atm.ground_albedo = gpu_atmosphere.ground_albedo.xyz;
  atm.solar_irradiance = gpu_atmosphere.solar_irradiance.xyz;
  atm.sun_angular_radius = gpu_atmosphere.solar_irradiance.w;
  atm.limb_darkening = gpu_atmosphere.radii.w;
  atm.transmittance_width = gpu_atmosphere.lut_sizes.x;
  atm.transmittance_height = gpu_atmosphere.lut_sizes.y;
  atm.multiscattering_width = gpu_atmosphere.lut_sizes.z;
  atm.multiscattering_height = gpu_atmosphere.lut_sizes.w;
  // A twilight frame's pipeline without the sky-view LUT marches every
  // texel with the twilight steps (quality.twilight_march_steps).
  atm.view_steps = kTwilightMarch && !kUseSkyView ? int(gpu_atmosphere.twilight.y) : gpu_atmosphere.samples.x;
  atm.transmittance_steps = gpu_atmosphere.samples.y;
  atm.multiscattering_steps = gpu_atmosphere.samples.z;
  atm.multiscattering_sqrt_dirs = gpu_atmosphere.effects.w;
  atm.integrator = kIntegrator;
  atm.light_steps = gpu_atmosphere.render.x;
  atm.step_distribution = gpu_atmosphere.render.w;
  atm.sky_view_width = gpu_atmosphere.render.y;
  atm.sky_view_height = gpu_atmosphere.render.z;
  atm.twilight_march_band = kTwilightMarch ? gpu_atmosphere.twilight.x : 0.0;
  atm.twilight_march_steps = int(gpu_atmosphere.twilight.y);
  atm.twilight_sun_sine = gpu_atmosphere.twilight.z;
  // Only a twilight frame's pipeline has kTwilightMarch (SkyRenderer::TwilightSkyPipeline).
  atm.transmittance_log = kTwilightMarch;
  atm.multiple_scattering = kMultipleScattering;
  atm.sun_disc = kSunDisc;
  atm.ground = kGround;
  atm.mie = kMie;
  atm.ozone = kOzone;
  atm.multiple_scattering_strength = gpu_atmosphere.strengths.x;
  atm.sun_disc_strength = gpu_atmosphere.strengths.y;
  atm.night = kNight;
  atm.night_radiance = gpu_atmosphere.night.xyz;
  atm.night_strength = gpu_atmosphere.night.w;
  return atm;
}

AoasParameters AoasFromUniform() {
  AoasParameters aoas;
  aoas.dome_radius = gpu_aoas.dome.x;
  aoas.viewer_position = gpu_aoas.viewer.xyz;
  aoas.l_pt = gpu_aoas.dome.y;
  aoas.perturbation_grain = gpu_aoas.dome.z;
  aoas.perturbation_offset = gpu_aoas.perturbation_offset.xyz;
  aoas.s_noise = gpu_aoas.noise.x;
  aoas.noise_octaves = gpu_aoas.counts.y;
  aoas.noise_threshold = gpu_aoas.noise.y;
  aoas.noise_strength = gpu_aoas.noise.z;
  aoas.noise_offset = gpu_aoas.noise_offset.xyz;
  aoas.shape_strength = gpu_aoas.noise.w;
  aoas.shape_segment_count = min(gpu_aoas.counts.x, AOAS_MAX_SHAPE_SEGMENTS);
  aoas.color_scale = gpu_aoas.color_scale.xyz;
  aoas.skydome = kSkydome;
  aoas.ambiguity = kAmbiguity;
  aoas.cloud_noise = kCloudNoise;
  aoas.cloud_shapes = kCloudShapes;
  return aoas;
}

#endif  // SKYBAKE_COMMON_GLSL
