#include "skybake/tools/reference_model.h"

#include "skybake/model/shared_glsl.h"

#include <algorithm>
#include <thread>

#include <type_traits>

#include <glm/glm.hpp>

namespace skybake {

struct ReferenceModel::Impl {
  glsl::AtmosphereParameters atm;
  glsl::AoasParameters aoas;
  gpu::GpuAoas gpu_aoas;
  glm::dvec3 output_scale;
  std::vector<glm::dvec3> transmittance;
  std::vector<glm::dvec3> multiscattering;
  std::vector<glm::dvec3> skyview;
  bool use_skyview = false;
  bool skyview_ready = false;
  glm::dvec3 skyview_sun{0.0};

  // The parameters for a frame with this Sun: a twilight frame's
  // (TwilightSunElevationDeg) reads the sun transmittance in the logarithm
  // and marches the band (without the sky-view LUT: every texel, with the
  // twilight steps), as the GPU's twilight pipeline; any other frame's
  // marches no band, as the GPU's day pipeline.
  glsl::AtmosphereParameters ForSun(const glm::dvec3& sun) const {
    glsl::AtmosphereParameters a = atm;
    a.transmittance_log = sun.y < atm.twilight_sun_sine;
    // No sunlit air in view: the day pipeline (SkyRenderer::MarchesTwilightBand).
    if (a.transmittance_log && use_skyview &&
        !SunlitAirInView(std::asin(std::clamp(sun.y, -1.0, 1.0)) * 180.0 / M_PI, atm.bottom_radius, atm.top_radius,
                         atm.observer_altitude, atm.sun_angular_radius))
      a.transmittance_log = false;
    if (!a.transmittance_log) a.twilight_march_band = 0.0;
    if (a.transmittance_log && !use_skyview) a.view_steps = a.twilight_march_steps;  // every texel marched
    return a;
  }

  // The LUTs and the AOAS block, for the shared code's hooks on this thread.
  void Bind() const {
    glsl::Tables tables;
    tables.transmittance = &transmittance;
    tables.multiscattering = &multiscattering;
    tables.skyview = &skyview;
    tables.skyview_width = atm.sky_view_width;
    tables.transmittance_width = atm.transmittance_width;
    tables.multiscattering_width = atm.multiscattering_width;
    tables.aoas = &gpu_aoas;
    glsl::BindTables(tables);
  }
};

namespace {

// Runs fn(i) for i in [0, n) on all hardware threads; each thread binds the LUTs.
template <class Fn>
void ParallelFor(size_t n, const ReferenceModel::Impl* impl, Fn fn) {
  unsigned threads = std::max(1u, std::thread::hardware_concurrency());
  std::vector<std::thread> pool;
  for (unsigned t = 0; t < threads; ++t) {
    pool.emplace_back([&, t] {
      impl->Bind();
      for (size_t i = t; i < n; i += threads) fn(i);
    });
  }
  for (auto& th : pool) th.join();
}

glm::dvec3 ToVec(const Rgb& rgb) { return {rgb[0], rgb[1], rgb[2]}; }
glm::dvec3 ToVec(const gpu::vec4& v) { return {v.x, v.y, v.z}; }

// The same unpacking as AoasFromUniform() in shaders/common.glsl.
glsl::AoasParameters AoasFromUniform(const gpu::GpuAoas& g, const AoasSwitches& switches) {
  glsl::AoasParameters aoas;
  aoas.dome_radius = g.dome.x;
  aoas.viewer_position = ToVec(g.viewer);
  aoas.l_pt = g.dome.y;
  aoas.perturbation_grain = g.dome.z;
  aoas.perturbation_offset = ToVec(g.perturbation_offset);
  aoas.s_noise = g.noise.x;
  aoas.noise_octaves = g.counts.y;
  aoas.noise_threshold = g.noise.y;
  aoas.noise_strength = g.noise.z;
  aoas.noise_offset = ToVec(g.noise_offset);
  aoas.shape_strength = g.noise.w;
  aoas.shape_segment_count = std::min(g.counts.x, AOAS_MAX_SHAPE_SEGMENTS);
  aoas.color_scale = ToVec(g.color_scale);
  aoas.skydome = switches.skydome;
  aoas.ambiguity = switches.ambiguity;
  aoas.cloud_noise = switches.cloud_noise;
  aoas.cloud_shapes = switches.cloud_shapes;
  return aoas;
}

}  // namespace

ReferenceModel::ReferenceModel(const AtmosphereParams& a, const QualitySettings& q, const EffectSettings& effects,
                               const Rgb& output_scale, const AoasInputs& aoas_inputs)
    : impl_(new Impl) {
  impl_->gpu_aoas = aoas_inputs.uniform;
  impl_->aoas = AoasFromUniform(aoas_inputs.uniform, aoas_inputs.switches);
  impl_->atm = glsl::SharedAtmosphere(a, q, effects);
  impl_->use_skyview = q.sky_view_lut;
  impl_->output_scale = ToVec(output_scale);
  impl_->transmittance.assign(size_t(q.transmittance_width) * q.transmittance_height, glm::dvec3(1.0));
  impl_->multiscattering.assign(size_t(q.multiscattering_size) * q.multiscattering_size, glm::dvec3(0.0));
}

ReferenceModel::~ReferenceModel() { delete impl_; }
ReferenceModel::ReferenceModel(ReferenceModel&& other) noexcept : impl_(other.impl_) { other.impl_ = nullptr; }

void ReferenceModel::PrecomputeLuts() {
  const glsl::AtmosphereParameters& atm = impl_->atm;
  int tw = atm.transmittance_width;
  ParallelFor(impl_->transmittance.size(), impl_, [&](size_t i) {
    impl_->transmittance[i] = glsl::ComputeTransmittanceLutTexel(atm, int(i % tw), int(i / tw));
  });
  if (atm.multiple_scattering) {
    int mw = atm.multiscattering_width;
    ParallelFor(impl_->multiscattering.size(), impl_, [&](size_t i) {
      impl_->multiscattering[i] = glsl::ComputeMultipleScatteringLutTexel(atm, int(i % mw), int(i / mw));
    });
  }
}

void ReferenceModel::PrepareSun(const glm::dvec3& sun) const {
  if (!impl_->use_skyview) return;
  if (impl_->skyview_ready && impl_->skyview_sun == sun) return;
  impl_->skyview_ready = true;
  impl_->skyview_sun = sun;
  const glsl::AtmosphereParameters& atm = impl_->atm;
  impl_->skyview.assign(size_t(atm.sky_view_width) * atm.sky_view_height, glm::dvec3(0.0));
  int w = atm.sky_view_width;
  ParallelFor(impl_->skyview.size(), impl_,
              [&](size_t i) { impl_->skyview[i] = glsl::ComputeSkyViewLutTexel(atm, int(i % w), int(i / w), sun.y); });
}

double ReferenceModel::TwilightMarchWeight(const glm::dvec3& view, const glm::dvec3& sun) const {
  if (!impl_->use_skyview) return 0.0;
  PrepareSun(sun);
  impl_->Bind();
  return glsl::TwilightMarchWeight(impl_->ForSun(sun), view, sun);
}

glm::dvec3 ReferenceModel::Radiance(const glm::dvec3& view, const glm::dvec3& sun) const {
  PrepareSun(sun);  // the sky-view LUT, as the GPU builds it
  impl_->Bind();
  glsl::AtmosphereParameters atm = impl_->ForSun(sun);
  const double twilight_weight = impl_->use_skyview ? glsl::TwilightMarchWeight(atm, view, sun) : 0.0;
  if (impl_->use_skyview && !(twilight_weight > 0.0))
    return glsl::ComputeSkyRadianceFromSkyView(atm, view, sun) * impl_->output_scale;
  if (!impl_->use_skyview) return glsl::ComputeSkyRadiance(atm, view, sun) * impl_->output_scale;
  // The band's march, with the disc added as the GPU's sun-disc pass adds it
  // to a sky-view renderer's texels: through the transmittance LUT.
  atm.view_steps = atm.twilight_march_steps;
  glsl::AtmosphereParameters sky = atm;
  sky.sun_disc = false;
  glm::dvec3 radiance = glsl::ComputeSkyRadiance(sky, view, sun);
  if (atm.sun_disc) radiance += glsl::SunDiscThroughAtmosphere(atm, view, sun) * atm.solar_irradiance;
  // At the edge of the marched texels above the band, mixed with the LUT's (TwilightMarchWeight).
  if (twilight_weight < 1.0)
    radiance = glm::mix(glsl::ComputeSkyRadianceFromSkyView(atm, view, sun), radiance, twilight_weight);
  return radiance * impl_->output_scale;
}

glm::dvec3 ReferenceModel::StyledRadiance(const glm::dvec3& w, const glm::dvec3& sun) const {
  PrepareSun(sun);
  impl_->Bind();
  return glsl::ComputeStyledSkyRadiance(impl_->ForSun(sun), impl_->aoas, w, sun, impl_->use_skyview) *
         impl_->output_scale;
}

std::vector<double> ReferenceModel::RenderView(const glm::dvec3& sun, const ViewRequest& view) const {
  PrepareSun(sun);
  std::vector<glm::dvec3> dirs = ViewDirections(view);
  std::vector<double> image(dirs.size() * 4);
  const glsl::AtmosphereParameters atm = impl_->ForSun(sun);
  ParallelFor(dirs.size(), impl_, [&](size_t i) {
    glm::dvec3 l =
        glsl::ComputeStyledSkyRadiance(atm, impl_->aoas, dirs[i], sun, impl_->use_skyview) * impl_->output_scale;
    image[4 * i + 0] = l.x;
    image[4 * i + 1] = l.y;
    image[4 * i + 2] = l.z;
    image[4 * i + 3] = 1.0;
  });
  return image;
}

glm::dvec3 ReferenceModel::TransmittanceFromLut(double altitude_km, double mu) const {
  impl_->Bind();
  double r = impl_->atm.bottom_radius + altitude_km;
  return glsl::GetTransmittanceToTopBoundary(impl_->atm, r, altitude_km, mu);
}

glm::dvec3 ReferenceModel::TransmittanceDirect(double altitude_km, double mu, int steps) const {
  double r = impl_->atm.bottom_radius + altitude_km;
  return glm::exp(-glsl::ComputeOpticalDepthToTopBoundary(impl_->atm, r, altitude_km, mu, steps));
}

const std::vector<glm::dvec3>& ReferenceModel::transmittance_lut() const { return impl_->transmittance; }
const std::vector<glm::dvec3>& ReferenceModel::multiscattering_lut() const { return impl_->multiscattering; }

}  // namespace skybake
