// The accuracy study's foundations: the Gauss-Legendre rule, the converged
// reference (closed form, its own convergence), and the renderer converging
// to it as the work grows.
#include <cmath>

#include <gtest/gtest.h>
#include <glm/glm.hpp>

#include "skybake/accuracy.h"
#include "skybake/reference_model.h"
#include "test_support.h"

namespace skybake {
namespace {

TEST(GaussLegendreTest, EightPointsIntegrateDegree15Exactly) {
  std::vector<double> x, w;
  GaussLegendre(8, x, w);
  for (int degree = 0; degree <= 15; ++degree) {
    double sum = 0.0;
    for (int i = 0; i < 8; ++i) sum += w[i] * std::pow(x[i], degree);
    double exact = degree % 2 ? 0.0 : 2.0 / (degree + 1);
    EXPECT_NEAR(sum, exact, 1e-14) << degree;
  }
}

TEST(ConvergedReferenceTest, VerticalTransmittanceEqualsClosedForm) {
  AtmosphereParams a;
  ConvergedReference ref(a, 4.0);
  const double thickness = a.top_radius_km - a.bottom_radius_km;
  for (int c = 0; c < 3; ++c) {
    double tau = a.rayleigh_scattering_per_km[c] * a.rayleigh_scale_height_km *
                     (1 - std::exp(-thickness / a.rayleigh_scale_height_km)) +
                 a.mie_extinction_per_km[c] * a.mie_scale_height_km * (1 - std::exp(-thickness / a.mie_scale_height_km)) +
                 a.ozone_absorption_per_km[c] * a.ozone_half_width_km;
    EXPECT_NEAR(ref.Transmittance(0.0, 1.0)[c] / std::exp(-tau), 1.0, 1e-12) << c;
  }
}

TEST(ConvergedReferenceTest, DoublingTheWorkChangesLessThan1e6) {
  AtmosphereParams a;
  ConvergedReference coarse(a, 8.0), fine(a, 4.0);
  for (double sun_elevation : {90.0, 10.0, 0.0, -6.0}) {
    glm::dvec3 sun = SunDirectionFromElevationAzimuth(sun_elevation, 180.0);
    for (double elevation : {90.0, 20.0, 2.0, 0.0})
      for (double azimuth : {0.0, 170.0}) {
        glm::dvec3 view = SunDirectionFromElevationAzimuth(elevation, azimuth);
        glm::dvec3 x = coarse.Radiance(view, sun), y = fine.Radiance(view, sun);
        for (int c = 0; c < 3; ++c) {
          if (y[c] <= 0.0) continue;
          EXPECT_LT(std::abs(x[c] - y[c]) / y[c], 1e-6) << sun_elevation << " " << elevation << " " << azimuth;
        }
      }
  }
}

TEST(ConvergedReferenceTest, RendererConvergesToIt) {
  // Single scattering, Simpson with 512 quadratic steps and a marched sun
  // transmittance of 512 steps: within 1e-3 of the reference by day.
  AtmosphereParams a;
  QualitySettings q;
  q.sky_view_lut = false;
  q.integrator = INTEGRATOR_SIMPSON;
  q.view_steps = 512;
  q.light_steps = 512;
  EffectSettings single;
  single.multiple_scattering = false;
  single.sun_disc = false;
  single.ground = false;
  ReferenceModel model(a, q, single, {1, 1, 1});
  model.PrecomputeLuts();
  ConvergedReference ref(a, 4.0);
  for (double sun_elevation : {45.0, 10.0}) {
    glm::dvec3 sun = SunDirectionFromElevationAzimuth(sun_elevation, 180.0);
    for (double elevation : {90.0, 30.0, 5.0, 0.5})
      for (double azimuth : {0.0, 90.0, 180.0}) {
        glm::dvec3 view = SunDirectionFromElevationAzimuth(elevation, azimuth);
        glm::dvec3 x = model.Radiance(view, sun), y = ref.Radiance(view, sun);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(x[c] / y[c], 1.0, 1e-3) << sun_elevation << " " << elevation;
      }
  }
}

}  // namespace
}  // namespace skybake
