// The double-precision CPU reference of the sky renderer. It compiles the
// same shared source as the shaders (shaders/atmosphere.glsl and
// shaders/aoas.glsl, shaders/envmap.glsl) with Real = double, so every function has the same
// name and structure on both sides and tests can put them side by side.
// Tests use it; bakes do not.
#pragma once

#include <vector>

#include <glm/vec3.hpp>

#include "skybake/model/aoas.h"
#include "skybake/model/atmosphere.h"
#include "skybake/model/view.h"

namespace skybake {

class ReferenceModel {
 public:
  // `aoas`: the per-texel aesthetic principles, read from the same packed
  // uniform the GPU gets (so both sides use the same float parameters).
  ReferenceModel(const AtmosphereParams& atmosphere, const QualitySettings& quality, const EffectSettings& effects,
                 const Rgb& output_scale, const AoasInputs& aoas = AoasInputs());
  ~ReferenceModel();
  ReferenceModel(ReferenceModel&&) noexcept;

  // Builds the LUTs (multi-threaded over texels).
  void PrecomputeLuts();

  // With quality.sky_view_lut: builds the sky-view LUT for this Sun (the
  // other calls then read it, as the GPU does). No-op otherwise.
  void PrepareSun(const glm::dvec3& sun) const;

  // Radiance times output_scale along unit `view` with the Sun along unit `sun`.
  glm::dvec3 Radiance(const glm::dvec3& view, const glm::dvec3& sun) const;

  // How much of `view` is ray-marched rather than read from the sky-view LUT
  // at twilight (TwilightMarchWeight, on the LUT built for this Sun): 0 to 1,
  // 0 without the LUT.
  double TwilightMarchWeight(const glm::dvec3& view, const glm::dvec3& sun) const;

  // The styled sky (ComputeStyledSkyRadiance) times output_scale for texel
  // direction `w`.
  glm::dvec3 StyledRadiance(const glm::dvec3& w, const glm::dvec3& sun) const;

  // RGBA image of one view, as SkyRenderer::Render returns it (styled).
  std::vector<double> RenderView(const glm::dvec3& sun, const ViewRequest& view) const;

  // Transmittance from altitude (km) to the top along mu, read from the LUT,
  // and computed directly with `steps` quadrature points.
  glm::dvec3 TransmittanceFromLut(double altitude_km, double mu) const;
  glm::dvec3 TransmittanceDirect(double altitude_km, double mu, int steps) const;

  const std::vector<glm::dvec3>& transmittance_lut() const;
  const std::vector<glm::dvec3>& multiscattering_lut() const;

  // Implementation (the shared code instantiated in double); public so that
  // helpers in reference_model.cc can name it.
  struct Impl;

 private:
  Impl* impl_;
};

}  // namespace skybake
