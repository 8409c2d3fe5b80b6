// The spectral mode's renderer (spectrum.h): one three-channel SkyRenderer
// per group of three wavelength bins, each with its group's atmosphere and
// LUTs, and their views combined into linear Rec.709 (cd/m^2) with the
// groups' CIE weights. Cost grows with the number of groups, ceil(N / 3).
// The principles that act on a texel's colour (the AOAS saturation clouds
// and shapes, the night floor) are applied once, to the combined colour, by
// a style pass; with cloud layers, to the sky behind them, as with three
// wavelengths (Render).
// A SkyRenderer whose quality asks for more than three wavelengths holds one
// and forwards to it, so every user of the renderer gets the spectral sky.
#pragma once

#include <memory>
#include <vector>

#include "skybake/gpu/sky_renderer.h"
#include "skybake/model/spectrum.h"

namespace skybake {

class SpectralSky {
 public:
  SpectralSky(VulkanContext& context, const AtmosphereParams& atmosphere, const QualitySettings& quality,
              const EffectSettings& effects, const AoasInputs& aoas, const CloudInputs& clouds,
              const ShaderSwitches& shaders);
  // Groups of one's own (SpectralGroups of other bins, a flat sun, ...).
  SpectralSky(VulkanContext& context, SpectralBins bins, std::vector<SpectralGroup> groups,
              const QualitySettings& quality, const EffectSettings& effects, const AoasInputs& aoas = AoasInputs(),
              const CloudInputs& clouds = CloudInputs(), const ShaderSwitches& shaders = ShaderSwitches());
  ~SpectralSky();

  const SpectralBins& bins() const { return bins_; }
  const std::vector<SpectralGroup>& groups() const { return groups_; }
  // The group's renderer: radiance (W m^-2 sr^-1 nm^-1) at its three wavelengths.
  SkyRenderer& group(size_t g) { return *renderers_[g]; }

  void PrecomputeLuts();
  // Every group's views, combined: linear Rec.709 in cd/m^2, alpha of the first group.
  // With the style pass and cloud layers, each group's frame is split around
  // the style pass (SkyRenderer::RenderClearSky, CompositeClouds): the
  // groups' clear skies are combined, styled, and the style's change R of
  // the combined colour is handed back to the groups (ColourChangeShares)
  // before each composites its layers, so the result is the clouds' light
  // plus their transmittance times the styled sky, the three-wavelength
  // path's order.
  std::vector<std::vector<float>> Render(const glm::dvec3& sun_direction, const std::vector<ViewRequest>& views,
                                         bool sun_disc);
  std::vector<float> RenderDirections(const glm::dvec3& sun_direction, const std::vector<glm::dvec3>& directions,
                                      bool sun_disc);
  bool UpdateAtmosphere(const AtmosphereParams& atmosphere, const QualitySettings& quality,
                        const EffectSettings& effects);
  bool UpdateAoas(const AoasInputs& aoas);
  bool UpdateClouds(const CloudInputs& clouds);

  // Every group's passes of the last call, in order, and their counters summed.
  const std::vector<PassTiming>& last_timings() const { return timings_; }
  RenderCounters counters() const;

 private:
  SpectralBins bins_;
  std::vector<SpectralGroup> groups_;
  std::vector<std::unique_ptr<SkyRenderer>> renderers_;
  // The style pass (SkyRenderer::StylePass) when the style has principles
  // that act on a texel's colour (the AOAS saturation clouds and shapes, the
  // night floor): the groups render without them, and it applies them to the
  // combined colour, as the three-wavelength sky pass does to its radiance.
  std::unique_ptr<SkyRenderer> style_;
  AoasInputs style_aoas_;
  EffectSettings style_effects_;
  std::vector<PassTiming> timings_;
  VulkanContext& context_;
  int cloud_layers_ = 0;
  std::vector<Matrix3> shares_;  // ColourChangeShares of groups_, with the style pass and cloud layers
  // The frame split around the style pass (Render, RenderDirections with
  // the style pass and cloud layers); `directions` for one MAPPING_DIRECTIONS view.
  std::vector<std::vector<float>> RenderStyledUnderClouds(const glm::dvec3& sun, const std::vector<ViewRequest>& views,
                                                          bool sun_disc, const std::vector<glm::dvec3>& directions);
};

}  // namespace skybake
