// The one C++ instantiation of the shared GLSL (shared_glsl.h): the hooks,
// then shaders/atmosphere.glsl, aoas.glsl and envmap.glsl compiled in double.
#include "skybake/model/shared_glsl.h"

#include <cmath>

#include "skybake/model/shared_params.h"

namespace skybake::glsl {

namespace {
// What the hooks read on this thread (BindTables); thread_local so that
// worker threads can evaluate in parallel.
thread_local Tables g_tables;

vec3 ToVec(const Rgb& rgb) { return {rgb[0], rgb[1], rgb[2]}; }
}  // namespace

void BindTables(const Tables& tables) { g_tables = tables; }

AtmosphereParameters SharedAtmosphere(const AtmosphereParams& a, const QualitySettings& q,
                                      const EffectSettings& effects) {
  AtmosphereParameters atm{};
  FillPhysicalParameters(a, atm);
  atm.transmittance_width = q.transmittance_width;
  atm.transmittance_height = q.transmittance_height;
  atm.multiscattering_width = q.multiscattering_size;
  atm.multiscattering_height = q.multiscattering_size;
  atm.view_steps = q.view_steps;
  atm.transmittance_steps = q.transmittance_steps;
  atm.multiscattering_steps = q.multiscattering_steps;
  atm.multiscattering_sqrt_dirs = q.multiscattering_sqrt_dirs;
  atm.integrator = q.integrator;
  atm.light_steps = q.light_steps;
  atm.step_distribution = q.step_distribution;
  atm.sky_view_width = q.sky_view_width;
  atm.sky_view_height = q.sky_view_height;
  atm.twilight_march_band = q.twilight_march_band_deg * M_PI / 180.0;
  atm.twilight_march_steps = q.twilight_march_steps > 0 ? q.twilight_march_steps : q.view_steps;
  atm.twilight_sun_sine = TwilightSunElevationDeg(q) > 0.0 ? std::sin(TwilightSunElevationDeg(q) * M_PI / 180.0) : -2.0;
  atm.transmittance_log = false;  // set per frame (ReferenceModel, as the GPU's twilight pipeline)
  atm.multiple_scattering = effects.multiple_scattering;
  atm.sun_disc = effects.sun_disc;
  atm.ground = effects.ground;
  atm.mie = effects.mie;
  atm.ozone = effects.ozone;
  atm.multiple_scattering_strength = effects.multiple_scattering_strength;
  atm.sun_disc_strength = effects.sun_disc_strength;
  atm.night = effects.night_dimming;
  atm.night_radiance = ToVec(NightSkyRadiance(effects));
  atm.night_strength = effects.night_dimming_strength;
  return atm;
}

// The hooks of atmosphere.glsl and aoas.glsl.
vec3 TransmittanceLutTexel(int x, int y) {
  return (*g_tables.transmittance)[size_t(y) * g_tables.transmittance_width + x];
}
vec3 MultipleScatteringLutTexel(int x, int y) {
  return (*g_tables.multiscattering)[size_t(y) * g_tables.multiscattering_width + x];
}
vec3 SkyViewLutTexel(int x, int y) { return (*g_tables.skyview)[size_t(y) * g_tables.skyview_width + x]; }
vec4 ShapeSegmentStart(int i) {
  const gpu::vec4& v = g_tables.aoas->shape_segments[2 * i];
  return vec4(v.x, v.y, v.z, v.w);
}
vec4 ShapeSegmentEnd(int i) {
  const gpu::vec4& v = g_tables.aoas->shape_segments[2 * i + 1];
  return vec4(v.x, v.y, v.z, v.w);
}
constexpr int kPerlinPermutation[256] = {SKYBAKE_PERLIN_PERMUTATION};
int PerlinPermutation(int i) { return kPerlinPermutation[i]; }

// The parameter macros of glsl_compat.h, which shared_glsl.h keeps to itself.
#define IN(T) const T&
#define OUT(T) T&
#define CONST_REAL constexpr Real
#include "atmosphere.glsl"
#include "aoas.glsl"
#include "envmap.glsl"
#include "cloud_ice_phase.glsl"

}  // namespace skybake::glsl
