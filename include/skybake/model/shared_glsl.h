// The shared GLSL (shaders/atmosphere.glsl, aoas.glsl, envmap.glsl) compiled
// as C++ in double, once (bake/model/shared_glsl.cc): its parameter structs
// (the same files the shaders include) and the functions the CPU side calls,
// with the names and arguments they have in GLSL. The double-precision
// reference (tools/reference_model.h), the accuracy study's converged
// reference, the views' texel directions (view.h) and the night sky's star
// transmittance all call this one instantiation.
//
// The LUT and AOAS hooks the shared code reads are bound per thread
// (BindTables); code that never reads a LUT (the geometry, the medium, a
// direct optical depth) needs none.
#pragma once

#include <type_traits>
#include <vector>

#include <glm/glm.hpp>

#include "skybake/gpu_shared.h"
#include "skybake/model/atmosphere.h"

namespace skybake::glsl {

#define SKYBAKE_REAL double
#include "skybake/model/glsl_compat.h"
#undef SKYBAKE_REAL
#include "atmosphere_parameters.glsl"
#include "aoas_parameters.glsl"

// What the hooks read on this thread: the LUTs (row-major texels) and the
// AOAS uniform block's shape arcs. Pointers, owned by the caller.
struct Tables {
  const std::vector<glm::dvec3>* transmittance = nullptr;
  const std::vector<glm::dvec3>* multiscattering = nullptr;
  const std::vector<glm::dvec3>* skyview = nullptr;
  int transmittance_width = 0;
  int multiscattering_width = 0;
  int skyview_width = 0;
  const gpu::GpuAoas* aoas = nullptr;
};
void BindTables(const Tables& tables);

// The parameters of the shared code for a style's atmosphere, quality and
// effects, as the GPU gets them from its uniform block.
AtmosphereParameters SharedAtmosphere(const AtmosphereParams& atmosphere, const QualitySettings& quality,
                                      const EffectSettings& effects);

// atmosphere.glsl: the medium and the geometry of rays.
MediumSample SampleMedium(IN(AtmosphereParameters) atm, Real altitude);
Real AltitudeAlongRay(IN(AtmosphereParameters) atm, Real r, Real altitude, Real mu, Real t);
Real DistanceToTopBoundary(IN(AtmosphereParameters) atm, Real r, Real altitude, Real mu);
bool RayIntersectsGround(IN(AtmosphereParameters) atm, Real r, Real altitude, Real mu);
Real DistanceToBottomBoundary(IN(AtmosphereParameters) atm, Real r, Real altitude, Real mu);
Real DistanceToAtmosphereEntry(IN(AtmosphereParameters) atm, Real r, Real altitude, Real mu);
Real RayleighPhase(Real nu);
Real MiePhase(Real g, vec3 view, vec3 sun);
// atmosphere.glsl: transmittance, the LUTs' texels and the sky's radiance.
vec3 ComputeOpticalDepthToTopBoundary(IN(AtmosphereParameters) atm, Real r, Real altitude, Real mu, int steps);
vec3 ComputeTransmittanceLutTexel(IN(AtmosphereParameters) atm, int x, int y);
vec3 GetTransmittanceToTopBoundary(IN(AtmosphereParameters) atm, Real r, Real altitude, Real mu);
vec3 ComputeMultipleScatteringLutTexel(IN(AtmosphereParameters) atm, int x, int y);
vec3 ComputeSkyViewLutTexel(IN(AtmosphereParameters) atm, int x, int y, Real mu_s);
vec3 ComputeSkyRadiance(IN(AtmosphereParameters) atm, vec3 view, vec3 sun);
vec3 ComputeSkyRadianceFromSkyView(IN(AtmosphereParameters) atm, vec3 view, vec3 sun);
Real TwilightMarchWeight(IN(AtmosphereParameters) atm, vec3 view, vec3 sun);
vec2 TwilightMarchElevations(IN(AtmosphereParameters) atm);
vec3 SunDiscThroughAtmosphere(IN(AtmosphereParameters) atm, vec3 view, vec3 sun);
// aoas.glsl: the styled sky.
vec3 ComputeStyledSkyRadiance(IN(AtmosphereParameters) atm, IN(AoasParameters) aoas, vec3 w, vec3 sun,
                              bool use_sky_view);
// envmap.glsl: texel directions.
vec3 DirectionFromLatLongPixel(Real x, Real y, int width, int height);
vec3 DirectionFromCubeStripPixel(int x, int y, int face_size);
vec3 DirectionFromVulkanCubeTexel(int face, int x, int y, int face_size);
// cloud_ice_phase.glsl: the phase of a cirrus layer's ice crystals, sr^-1.
Real IceCrystalPhase(Real cos_theta, Real eccentricity);

}  // namespace skybake::glsl

// glsl_compat.h's parameter macros stay inside this header.
#undef IN
#undef OUT
#undef CONST_REAL
