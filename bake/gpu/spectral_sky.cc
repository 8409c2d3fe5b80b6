#include "skybake/gpu/spectral_sky.h"

#include <algorithm>
#include <stdexcept>
#include <utility>

namespace skybake {
namespace {

QualitySettings GroupQuality(QualitySettings q) {
  q.wavelengths = kRgbWavelengths;
  return q;
}

// The principles that act on a texel's colour (the AOAS saturation clouds
// and shapes, the night floor) are the style pass's, on the combined
// colour: the groups render the physical sky without them.
bool StylesColour(const AoasInputs& aoas, const EffectSettings& effects) {
  return aoas.switches.cloud_noise || aoas.switches.cloud_shapes || effects.night_dimming;
}
AoasInputs GroupAoas(AoasInputs aoas) {
  aoas.switches.cloud_noise = false;
  aoas.switches.cloud_shapes = false;
  return aoas;
}
EffectSettings GroupEffects(EffectSettings effects) {
  effects.night_dimming = false;
  return effects;
}
// The colour the style pass sees: linear Rec.709 in cd/m^2, which the
// AOAS colour scale (OutputScale(kLuminance)) maps the three-wavelength
// radiance to; radiance = colour / scale, as the sky pass sees it.
Rgb StyleScale(const AoasInputs& aoas) {
  const gpu::vec4& c = aoas.uniform.color_scale;
  return {c.x, c.y, c.z};
}

// Adds m * (the RGB of `in`) to the three channels of each texel of `out`
// (RGBA texels); with copy_alpha, out's alpha becomes in's. Sums the groups
// into RGB (to_rgb; the first group sets alpha) and adds a change's share to
// a group (shares_, alpha kept).
void AddTransformed(const float* in, size_t texels, const Matrix3& m, bool copy_alpha, float* out) {
  float f[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) f[i][j] = float(m[i][j]);
  for (size_t t = 0; t < texels; ++t) {
    const float* a = in + 4 * t;
    float* b = out + 4 * t;
    for (int i = 0; i < 3; ++i) b[i] += f[i][0] * a[0] + f[i][1] * a[1] + f[i][2] * a[2];
    if (copy_alpha) b[3] = a[3];
  }
}

}  // namespace

SpectralSky::SpectralSky(VulkanContext& context, const AtmosphereParams& atmosphere, const QualitySettings& quality,
                         const EffectSettings& effects, const AoasInputs& aoas, const CloudInputs& clouds,
                         const ShaderSwitches& shaders)
    : SpectralSky(context, WavelengthBins(quality.wavelengths),
                  SpectralGroups(atmosphere, WavelengthBins(quality.wavelengths)), quality, effects, aoas, clouds,
                  shaders) {}

SpectralSky::SpectralSky(VulkanContext& context, SpectralBins bins, std::vector<SpectralGroup> groups,
                         const QualitySettings& quality, const EffectSettings& effects, const AoasInputs& aoas,
                         const CloudInputs& clouds, const ShaderSwitches& shaders)
    : bins_(std::move(bins)),
      groups_(std::move(groups)),
      style_aoas_(aoas),
      style_effects_(effects),
      context_(context),
      cloud_layers_(clouds.layers()) {
  // Each group renders radiance (unit output scale); the CIE weights make it cd/m^2.
  for (const SpectralGroup& g : groups_)
    renderers_.push_back(std::make_unique<SkyRenderer>(context, g.atmosphere, GroupQuality(quality),
                                                       GroupEffects(effects), Rgb{1.0, 1.0, 1.0}, false,
                                                       GroupAoas(aoas), clouds, shaders));
  if (StylesColour(aoas, effects)) {
    if (StyleScale(aoas)[0] <= 0.0 || StyleScale(aoas)[1] <= 0.0 || StyleScale(aoas)[2] <= 0.0)
      throw std::invalid_argument("SpectralSky: the AOAS colour scale must be positive (ToAoasInputs)");
    style_ = SkyRenderer::StylePass(context, groups_.front().atmosphere, quality, effects, StyleScale(aoas), aoas);
    if (cloud_layers_ > 0) shares_ = ColourChangeShares(groups_);
  }
}

SpectralSky::~SpectralSky() = default;

void SpectralSky::PrecomputeLuts() {
  timings_.clear();
  for (auto& r : renderers_) {
    r->PrecomputeLuts();
    timings_.insert(timings_.end(), r->last_timings().begin(), r->last_timings().end());
  }
}

std::vector<std::vector<float>> SpectralSky::Render(const glm::dvec3& sun, const std::vector<ViewRequest>& views,
                                                    bool sun_disc) {
  if (style_ && cloud_layers_ > 0) return RenderStyledUnderClouds(sun, views, sun_disc, {});
  std::vector<std::vector<float>> sum;
  for (const ViewRequest& v : views) sum.emplace_back(size_t(v.width) * v.height * 4, 0.0f);
  timings_.clear();
  for (size_t g = 0; g < renderers_.size(); ++g) {
    // Read where the device wrote it; the hold is released before the next group.
    const RenderedViews rendered = renderers_[g]->RenderInPlace(sun, views, sun_disc);
    timings_.insert(timings_.end(), renderers_[g]->last_timings().begin(), renderers_[g]->last_timings().end());
    for (size_t i = 0; i < views.size(); ++i)
      AddTransformed(rendered.views[i], size_t(views[i].width) * views[i].height, groups_[g].to_rgb, g == 0,
                     sum[i].data());
  }
  if (style_) {
    style_->ApplyStyle(sun, views, sum);
    timings_.insert(timings_.end(), style_->last_timings().begin(), style_->last_timings().end());
  }
  return sum;
}

std::vector<float> SpectralSky::RenderDirections(const glm::dvec3& sun, const std::vector<glm::dvec3>& directions,
                                                 bool sun_disc) {
  if (style_ && cloud_layers_ > 0) {
    ViewRequest view;
    view.mapping = MAPPING_DIRECTIONS;
    view.width = int(directions.size());
    view.height = 1;
    return std::move(RenderStyledUnderClouds(sun, {view}, sun_disc, directions)[0]);
  }
  std::vector<float> sum(directions.size() * 4, 0.0f);
  timings_.clear();
  for (size_t g = 0; g < renderers_.size(); ++g) {
    const std::vector<float> group = renderers_[g]->RenderDirections(sun, directions, sun_disc);
    timings_.insert(timings_.end(), renderers_[g]->last_timings().begin(), renderers_[g]->last_timings().end());
    AddTransformed(group.data(), directions.size(), groups_[g].to_rgb, g == 0, sum.data());
  }
  if (style_) {
    ViewRequest view;
    view.mapping = MAPPING_DIRECTIONS;
    view.width = int(directions.size());
    view.height = 1;
    std::vector<std::vector<float>> images(1);
    images[0] = std::move(sum);
    style_->ApplyStyle(sun, {view}, images, directions);
    timings_.insert(timings_.end(), style_->last_timings().begin(), style_->last_timings().end());
    return std::move(images[0]);
  }
  return sum;
}

std::vector<std::vector<float>> SpectralSky::RenderStyledUnderClouds(const glm::dvec3& sun,
                                                                     const std::vector<ViewRequest>& views,
                                                                     bool sun_disc,
                                                                     const std::vector<glm::dvec3>& directions) {
  size_t total = directions.size();
  for (const ViewRequest& v : views) total += size_t(v.width) * v.height;
  if (VkDeviceSize(total) * 16 > context_.properties().limits.maxStorageBufferRange && views.size() > 1) {
    // In two halves, as SkyRenderer::Render splits a frame too large for one buffer.
    const size_t half = views.size() / 2;
    std::vector<std::vector<float>> images =
        RenderStyledUnderClouds(sun, std::vector<ViewRequest>(views.begin(), views.begin() + half), sun_disc, {});
    std::vector<PassTiming> timings = timings_;
    for (std::vector<float>& image :
         RenderStyledUnderClouds(sun, std::vector<ViewRequest>(views.begin() + half, views.end()), sun_disc, {}))
      images.push_back(std::move(image));
    timings.insert(timings.end(), timings_.begin(), timings_.end());
    timings_ = timings;
    return images;
  }
  timings_.clear();
  auto record = [this](const SkyRenderer& r) {
    timings_.insert(timings_.end(), r.last_timings().begin(), r.last_timings().end());
  };
  // Every group's clear sky (and Sun), combined; each stays in its
  // renderer's memory until its layers are composited over it.
  std::vector<std::vector<float>> sum;
  for (const ViewRequest& v : views) sum.emplace_back(size_t(v.width) * v.height * 4, 0.0f);
  std::vector<std::vector<float*>> skies;
  for (size_t g = 0; g < renderers_.size(); ++g) {
    skies.push_back(renderers_[g]->RenderClearSky(sun, views, sun_disc, directions));
    record(*renderers_[g]);
    for (size_t i = 0; i < views.size(); ++i)
      AddTransformed(skies[g][i], size_t(views[i].width) * views[i].height, groups_[g].to_rgb, g == 0, sum[i].data());
  }
  // The style's change of the combined sky, R = Style(sky) - sky.
  std::vector<std::vector<float>> change = sum;
  style_->ApplyStyle(sun, views, change, directions);
  record(*style_);
  for (size_t i = 0; i < views.size(); ++i) {
    for (size_t k = 0; k < change[i].size(); ++k) change[i][k] = k % 4 == 3 ? 0.0f : change[i][k] - sum[i][k];
    std::fill(sum[i].begin(), sum[i].end(), 0.0f);
  }
  // Each group's share of R added to its sky, its layers composited over
  // that (their light plus their transmittance times the texel), combined again.
  for (size_t g = 0; g < renderers_.size(); ++g) {
    for (size_t i = 0; i < views.size(); ++i)
      AddTransformed(change[i].data(), size_t(views[i].width) * views[i].height, shares_[g], false, skies[g][i]);
    renderers_[g]->CompositeClouds();
    record(*renderers_[g]);
    for (size_t i = 0; i < views.size(); ++i)
      AddTransformed(skies[g][i], size_t(views[i].width) * views[i].height, groups_[g].to_rgb, g == 0, sum[i].data());
  }
  return sum;
}

bool SpectralSky::UpdateAtmosphere(const AtmosphereParams& atmosphere, const QualitySettings& quality,
                                   const EffectSettings& effects) {
  if (quality.wavelengths != bins_.count()) return false;  // also refuses groups of one's own
  std::vector<SpectralGroup> groups = SpectralGroups(atmosphere, bins_);
  if (effects.night_dimming != (style_ && style_effects_.night_dimming)) return false;  // a style pass comes or goes
  for (size_t g = 0; g < renderers_.size(); ++g)
    if (!renderers_[g]->UpdateAtmosphere(groups[g].atmosphere, GroupQuality(quality), GroupEffects(effects),
                                         Rgb{1.0, 1.0, 1.0}))
      return false;
  if (style_ &&
      !style_->UpdateAtmosphere(groups.front().atmosphere, GroupQuality(quality), effects, StyleScale(style_aoas_)))
    return false;
  style_effects_ = effects;
  groups_ = groups;
  if (!shares_.empty()) shares_ = ColourChangeShares(groups_);
  return true;
}

bool SpectralSky::UpdateAoas(const AoasInputs& aoas) {
  // The style pass's switches are its pipeline's: another set needs a new renderer.
  const bool clouds_on = aoas.switches.cloud_noise || aoas.switches.cloud_shapes;
  const bool clouds_were = style_ && (style_aoas_.switches.cloud_noise || style_aoas_.switches.cloud_shapes);
  if (clouds_on != clouds_were) return false;
  bool ok = true;
  for (auto& r : renderers_) ok = r->UpdateAoas(GroupAoas(aoas)) && ok;
  if (style_) ok = style_->UpdateAoas(aoas) && ok;
  if (ok) style_aoas_ = aoas;
  return ok;
}

bool SpectralSky::UpdateClouds(const CloudInputs& clouds) {
  bool ok = true;
  for (auto& r : renderers_) ok = r->UpdateClouds(clouds) && ok;
  return ok;
}

RenderCounters SpectralSky::counters() const {
  RenderCounters sum;
  for (const auto& r : renderers_) {
    const RenderCounters& c = r->counters();
    sum.transmittance_lut_builds += c.transmittance_lut_builds;
    sum.multiscattering_lut_builds += c.multiscattering_lut_builds;
    sum.skyview_lut_builds += c.skyview_lut_builds;
    sum.pipelines += c.pipelines;
    sum.variant_pipelines += c.variant_pipelines;
    sum.sun_disc_dispatches += c.sun_disc_dispatches;
    sum.cloud_noise_builds += c.cloud_noise_builds;
    sum.cloud_table_builds += c.cloud_table_builds;
    sum.cloud_dispatches += c.cloud_dispatches;
    sum.sun_disc_texels += c.sun_disc_texels;
    sum.twilight_texels += c.twilight_texels;
    sum.sky_texels += c.sky_texels;
  }
  if (style_) sum.pipelines += style_->counters().pipelines;
  // A frame is every group's render of it.
  sum.frames = renderers_.empty() ? 0 : renderers_.front()->counters().frames;
  sum.shadowed_cloud_frames = renderers_.empty() ? 0 : renderers_.front()->counters().shadowed_cloud_frames;
  return sum;
}

}  // namespace skybake
