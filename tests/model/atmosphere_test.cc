// The physics of shaders/atmosphere.glsl on the CPU: known answers for the
// geometry (in double and in float32, the shader's precision), closed forms
// for transmittance, Bruneton 2017's published transmittance table, and the
// qualitative facts of a clear sky.
#include <cmath>
#include <fstream>
#include <sstream>
#include <utility>

#include <gtest/gtest.h>
#include <type_traits>

#include <glm/glm.hpp>

#include "skybake/input/config.h"
#include "skybake/tools/reference_model.h"
#include "test_support.h"

namespace skybake {

// The shared source instantiated here in double and in float. The LUT hooks
// (glsl_test_hooks.h) are never reached by the geometry functions tested
// with these copies.
namespace f64 {
#define SKYBAKE_REAL double
#include "glsl_test_hooks.h"
#undef SKYBAKE_REAL
#include "atmosphere.glsl"
}  // namespace f64
#undef SKYBAKE_ATMOSPHERE_GLSL
#undef SKYBAKE_ATMOSPHERE_PARAMETERS_GLSL
namespace f32 {
#define SKYBAKE_REAL float
#include "glsl_test_hooks.h"
#undef SKYBAKE_REAL
#include "atmosphere.glsl"
}  // namespace f32

namespace {

template <class Atm>
Atm EarthParameters() {
  Atm atm{};
  atm.bottom_radius = 6360.0;
  atm.top_radius = 6460.0;
  atm.rayleigh_scale_height = 8.0;
  atm.mie_scale_height = 1.2;
  atm.ozone_peak_altitude = 25.0;
  atm.ozone_half_width = 15.0;
  atm.transmittance_width = 256;
  atm.transmittance_height = 64;
  return atm;
}

TEST(AtmosphereGeometryTest, VerticalRayReachesTheTopAtTheThickness) {
  auto atm = EarthParameters<f64::AtmosphereParameters>();
  for (double h : {0.0, 1e-6, 1.0, 50.0, 99.9}) {
    EXPECT_NEAR(f64::DistanceToTopBoundary(atm, 6360.0 + h, h, 1.0), 100.0 - h, 1e-9) << h;
    EXPECT_NEAR(f64::DistanceToTopBoundary(atm, 6360.0 + h, h, -1.0), 100.0 + h + 2 * 6360.0, 1e-6);
  }
}

TEST(AtmosphereGeometryTest, GroundDistanceIsStableInFloat32AtEarthScale) {
  // Observer 1 m up looking 1 degree down: the near root must not cancel.
  auto a64 = EarthParameters<f64::AtmosphereParameters>();
  auto a32 = EarthParameters<f32::AtmosphereParameters>();
  for (double h : {1e-3, 1e-6, 0.5, 10.0}) {
    for (double mu : {-1.0, -0.5, -0.0174524, -1e-3}) {
      double r = 6360.0 + h;
      if (!f64::RayIntersectsGround(a64, r, h, mu)) continue;
      ASSERT_TRUE(f32::RayIntersectsGround(a32, float(r), float(h), float(mu))) << h << " " << mu;
      double d64 = f64::DistanceToBottomBoundary(a64, r, h, mu);
      float d32 = f32::DistanceToBottomBoundary(a32, float(r), float(h), float(mu));
      EXPECT_NEAR(d32 / d64, 1.0, 1e-5) << "altitude " << h << " mu " << mu;
    }
  }
  // Straight down from altitude h the ground is h away.
  EXPECT_NEAR(f64::DistanceToBottomBoundary(a64, 6360.001, 0.001, -1.0), 0.001, 1e-12);
}

TEST(AtmosphereGeometryTest, AltitudeAlongRayIsStableInFloat32) {
  auto a64 = EarthParameters<f64::AtmosphereParameters>();
  auto a32 = EarthParameters<f32::AtmosphereParameters>();
  for (double mu : {0.0, 0.01, 0.5, -0.01}) {
    for (double t : {0.01, 1.0, 10.0, 100.0}) {
      double h64 = f64::AltitudeAlongRay(a64, 6360.001, 0.001, mu, t);
      float h32 = f32::AltitudeAlongRay(a32, 6360.001f, 0.001f, float(mu), float(t));
      if (h64 < 0) continue;
      EXPECT_NEAR(h32, h64, 1e-6 * std::max(1.0, h64) + 1e-7) << mu << " " << t;
    }
  }
}

TEST(AtmosphereGeometryTest, TransmittanceLutParametrisationRoundTrips) {
  auto atm = EarthParameters<f64::AtmosphereParameters>();
  for (int y = 0; y < atm.transmittance_height; y += 7) {
    for (int x = 0; x < atm.transmittance_width; x += 13) {
      f64::RadiusAndCosine rm = f64::RMuFromTransmittanceTexel(atm, x, y);
      f64::vec2 uv = f64::TransmittanceUvFromRMu(atm, rm.r, rm.altitude, rm.mu);
      EXPECT_NEAR(uv.x * atm.transmittance_width - 0.5, x, 1e-6);
      EXPECT_NEAR(uv.y * atm.transmittance_height - 0.5, y, 1e-6);
    }
  }
}

TEST(AtmosphereGeometryTest, MiePhaseIsNormalisedAndFiniteAtExtremeAnisotropy) {
  // The Cornette-Shanks phase is Henyey-Greenstein times 3(1+nu^2)/(2(2+g^2)):
  // exactly normalised at g = 0, within 2% at |g| = 0.8 (checked on a fine
  // nu grid). At g = +/-0.999 the peak is too narrow for the grid, so there
  // the check is that float32 stays finite and matches double evaluated at
  // the same (float-rounded) g.
  for (double g : {0.0, 0.8, -0.8, 0.999, -0.999}) {
    if (std::abs(g) < 0.9) {
      const int n = 2000000;
      double sum = 0.0;
      for (int i = 0; i < n; ++i) {
        double mu = -1.0 + 2.0 * (i + 0.5) / n;
        f64::vec3 view(std::sqrt(1 - mu * mu), mu, 0.0);
        sum += f64::MiePhase(g, view, f64::vec3(0, 1, 0)) * 2.0 * M_PI * (2.0 / n);
      }
      EXPECT_NEAR(sum, 1.0, g == 0.0 ? 1e-9 : 0.02) << "g " << g;
    }
    const float gf = float(g);
    for (double mu : {1.0, 0.9999999, 0.5, -0.9999999, -1.0}) {
      f32::vec3 view32(float(std::sqrt(1 - mu * mu)), float(mu), 0.0f);
      f64::vec3 view64(view32);
      float p32 = f32::MiePhase(gf, view32, f32::vec3(0, 1, 0));
      double p64 = f64::MiePhase(double(gf), view64, f64::vec3(0, 1, 0));
      EXPECT_TRUE(std::isfinite(p32) && p32 > 0) << g << " " << mu;
      EXPECT_NEAR(p32 / p64, 1.0, 1e-5) << "g " << g << " mu " << mu;
    }
  }
}

TEST(AtmosphereGeometryTest, OneMinusExpOverXIsAccurateNearZero) {
  for (double x : {0.0, 1e-8, 1e-4, 0.0099, 0.01, 0.5, 10.0, 1e4}) {
    double exact = x == 0.0 ? 1.0 : -std::expm1(-x) / x;
    EXPECT_NEAR(f32::OneMinusExpOverX(float(x)) / exact, 1.0, 2e-6) << x;
  }
}

// Closed form of the vertical optical depth through exponential layers and
// the ozone tent: tau = sum beta H (1 - exp(-thickness / H)) + beta_O3 * half width.
TEST(AtmosphereTransmittanceTest, VerticalTransmittanceEqualsClosedForm) {
  AtmosphereParams a;
  QualitySettings q;
  ReferenceModel model(a, q, EffectSettings{}, {1, 1, 1});
  model.PrecomputeLuts();
  const double thickness = a.top_radius_km - a.bottom_radius_km;
  for (int c = 0; c < 3; ++c) {
    double tau =
        a.rayleigh_scattering_per_km[c] * a.rayleigh_scale_height_km *
            (1 - std::exp(-thickness / a.rayleigh_scale_height_km)) +
        a.mie_extinction_per_km[c] * a.mie_scale_height_km * (1 - std::exp(-thickness / a.mie_scale_height_km)) +
        a.ozone_absorption_per_km[c] * a.ozone_half_width_km;
    double exact = std::exp(-tau);
    EXPECT_NEAR(model.TransmittanceDirect(0.0, 1.0, 4096)[c] / exact, 1.0, 1e-6) << c;
    // The LUT's first texel sits exactly at (ground, zenith), so reading it
    // returns that texel's own quadrature ...
    EXPECT_NEAR(model.TransmittanceFromLut(0.0, 1.0)[c], model.TransmittanceDirect(0.0, 1.0, q.transmittance_steps)[c],
                1e-12);
    // ... whose midpoint-rule error with h = 100/256 km is about
    // tau_Mie h^2 / (24 H_Mie^2) ~ 2.4e-5 here: bound it by 1e-4.
    EXPECT_NEAR(model.TransmittanceFromLut(0.0, 1.0)[c] / exact, 1.0, 1e-4) << c;
  }
}

TEST(AtmosphereTransmittanceTest, MoreOpticalDepthNeverBrightens) {
  AtmosphereParams a;
  ReferenceModel model(a, QualitySettings{}, EffectSettings{}, {1, 1, 1});
  model.PrecomputeLuts();
  // Lower sun (smaller mu) or lower observer: never more transmittance.
  for (double h : {0.0, 1.0, 10.0}) {
    glm::dvec3 previous(1.0);
    for (double mu = 1.0; mu >= -0.2; mu -= 0.01) {
      glm::dvec3 t = model.TransmittanceFromLut(h, mu);
      for (int c = 0; c < 3; ++c) EXPECT_LE(t[c], previous[c] + 1e-12) << h << " " << mu;
      previous = t;
    }
  }
}

TEST(AtmosphereTransmittanceTest, MatchesBruneton2017Table) {
  // shared/groundtruth/bruneton2017/transmittance_ground.csv: Bruneton's demo
  // atmosphere (top 6420 km), float32 GPU texture, 500-point trapezoidal
  // integration there; our direct integral here.
  std::ifstream in(testing::SharedDir() + "/groundtruth/bruneton2017/transmittance_ground.csv");
  ASSERT_TRUE(in) << "missing shared/groundtruth (expected beside the checkout)";
  AtmosphereParams a;
  a.top_radius_km = 6420.0;
  ReferenceModel model(a, QualitySettings{}, EffectSettings{}, {1, 1, 1});
  std::string line;
  int rows = 0;
  double worst = 0.0;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line.rfind("texel", 0) == 0) continue;
    std::stringstream s(line);
    std::string field;
    std::vector<double> v;
    while (std::getline(s, field, ',')) v.push_back(std::stod(field));
    double mu = v[1];
    glm::dvec3 t = model.TransmittanceDirect(0.0, mu, 4096);
    for (int c = 0; c < 3; ++c) {
      double expected = v[4 + c];
      if (expected < 1e-3) continue;
      worst = std::max(worst, std::abs(t[c] / expected - 1.0));
    }
    ++rows;
  }
  EXPECT_EQ(rows, 256);
  EXPECT_LT(worst, 2e-3) << "max relative difference to Bruneton 2017";
  RecordProperty("max_relative_difference", std::to_string(worst));
}

// Qualitative facts of a clear sky, on the double reference.
class SkyFactsTest : public ::testing::Test {
 protected:
  struct Direction {
    double elevation_deg, azimuth_deg;
  };
  // The default sky's radiance (reference model) toward `a` and toward `b`
  // with the Sun toward `sun`.
  static std::pair<glm::dvec3, glm::dvec3> TwoSkies(Direction sun, Direction a, Direction b) {
    ReferenceModel m(AtmosphereParams{}, QualitySettings{}, EffectSettings{}, {1, 1, 1});
    m.PrecomputeLuts();
    const glm::dvec3 s = SunDirectionFromElevationAzimuth(sun.elevation_deg, sun.azimuth_deg);
    return {m.Radiance(SunDirectionFromElevationAzimuth(a.elevation_deg, a.azimuth_deg), s),
            m.Radiance(SunDirectionFromElevationAzimuth(b.elevation_deg, b.azimuth_deg), s)};
  }
};

TEST_F(SkyFactsTest, NoonZenithIsBluerThanHorizon) {
  const auto [zenith, horizon] = TwoSkies({80.0, 180.0}, {90.0, 0.0}, {1.0, 0.0});
  EXPECT_GT(zenith.b / zenith.r, horizon.b / horizon.r);
  EXPECT_GT(zenith.b, zenith.r);
}

TEST_F(SkyFactsTest, SunsetSkyNearTheSunIsRedderThanOpposite) {
  const auto [near_sun, opposite] = TwoSkies({1.0, 270.0}, {3.0, 260.0}, {3.0, 90.0});
  EXPECT_GT(near_sun.r / near_sun.b, opposite.r / opposite.b);
}

TEST_F(SkyFactsTest, SunDirectionConvention) {
  // North = -Z, East = +X, +Y up.
  glm::dvec3 east = SunDirectionFromElevationAzimuth(0.0, 90.0);
  glm::dvec3 north = SunDirectionFromElevationAzimuth(0.0, 0.0);
  glm::dvec3 zenith = SunDirectionFromElevationAzimuth(90.0, 123.0);
  EXPECT_NEAR(east.x, 1.0, 1e-12);
  EXPECT_NEAR(north.z, -1.0, 1e-12);
  EXPECT_NEAR(zenith.y, 1.0, 1e-12);
}

}  // namespace
}  // namespace skybake
