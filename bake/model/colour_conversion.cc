#include "skybake/model/colour_conversion.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "skybake/model/shared_glsl.h"

namespace skybake {
namespace {

constexpr int kProbeBins = kMaxWavelengthBins;  // the spectral mode's reference: 48 bins of 10 nm

// The constituents' coefficients at one wavelength, km^-1, and the solar
// irradiance there (W m^-2 nm^-1); `rgb`: linear Rec.709 cd/m^2 per unit
// radiance (W m^-2 sr^-1 nm^-1) at that wavelength (zero for the renderer's
// own three wavelengths, which are converted, not integrated).
struct Wavelength {
  double rayleigh = 0.0, mie_scattering = 0.0, mie_extinction = 0.0, ozone = 0.0, solar = 0.0;
  Rgb rgb{};
};

struct Probe {
  std::vector<Wavelength> bins;   // the 48 bins
  std::array<Wavelength, 3> rgb;  // the renderer's 680, 550, 440 nm
};

Probe MakeProbe(const AtmosphereParams& style, const EffectSettings& effects) {
  auto at = [&](const AtmosphereParams& a, int c) {
    Wavelength w;
    w.rayleigh = a.rayleigh_scattering_per_km[c];
    w.mie_scattering = effects.mie ? a.mie_scattering_per_km[c] : 0.0;
    w.mie_extinction = effects.mie ? a.mie_extinction_per_km[c] : 0.0;
    w.ozone = effects.ozone ? a.ozone_absorption_per_km[c] : 0.0;
    w.solar = a.solar_irradiance[c];
    return w;
  };
  Probe p;
  for (const SpectralGroup& g : SpectralGroups(style, WavelengthBins(kProbeBins)))
    for (int c = 0; c < 3; ++c) {
      if (g.bin[c] < 0) continue;
      Wavelength w = at(g.atmosphere, c);
      for (int row = 0; row < 3; ++row) w.rgb[row] = g.to_rgb[row][c];
      p.bins.push_back(w);
    }
  for (int c = 0; c < 3; ++c) p.rgb[c] = at(style, c);
  return p;
}

// The shared GLSL's atmosphere with unit coefficients, one constituent per
// channel, so that its medium samples and optical depths are the
// constituents' densities and columns (Rayleigh, Mie, ozone): one march
// serves every wavelength.
glsl::AtmosphereParameters ColumnAtmosphere(const AtmosphereParams& style, const EffectSettings& effects) {
  AtmosphereParams unit = style;
  unit.rayleigh_scattering_per_km = {1.0, 0.0, 0.0};
  unit.mie_scattering_per_km = {0.0, 1.0, 0.0};
  unit.mie_extinction_per_km = {0.0, 1.0, 0.0};
  unit.ozone_absorption_per_km = {0.0, 0.0, 1.0};
  QualitySettings q;
  EffectSettings e = effects;
  e.multiple_scattering = false;
  return glsl::SharedAtmosphere(unit, q, e);
}

double Extinction(const Wavelength& w, const glm::dvec3& column) {
  return w.rayleigh * column.x + w.mie_extinction * column.y + w.ozone * column.z;
}

// The columns (km) from altitude `altitude` along `mu` to the top, or a
// negative x where the ray meets the ground.
constexpr int kColumnSteps = 64;
glm::dvec3 ColumnsToTop(const glsl::AtmosphereParameters& atm, double altitude, double mu) {
  const double r = atm.bottom_radius + altitude;
  if (glsl::RayIntersectsGround(atm, r, altitude, mu)) return glm::dvec3(-1.0);
  return glsl::ComputeOpticalDepthToTopBoundary(atm, r, altitude, mu, kColumnSteps);
}

}  // namespace

// The sky is symmetric about the Sun's vertical: half a turn of azimuths.
std::vector<glm::dvec3> SkyProbeDirections(const glm::dvec3& sun) {
  const double sun_azimuth = std::atan2(sun.x, -sun.z);
  std::vector<glm::dvec3> views;
  for (double elevation_deg : {1.0, 3.0, 6.0, 10.0, 15.0, 25.0, 40.0, 60.0, 85.0})
    for (int k = 0; k < 8; ++k) {
      const double e = elevation_deg * M_PI / 180.0, a = sun_azimuth + M_PI * (k + 0.5) / 8.0;
      views.push_back({std::cos(e) * std::sin(a), std::sin(e), -std::cos(e) * std::cos(a)});
    }
  return views;
}

namespace {

// Single-scattered radiance along `view` at every probe wavelength (the 48
// bins, then the three), per unit of each wavelength's solar irradiance
// times that irradiance: W m^-2 sr^-1 nm^-1.
constexpr int kViewSteps = 48;
std::vector<double> SingleScattering(const glsl::AtmosphereParameters& atm, const Probe& probe, const glm::dvec3& view,
                                     const glm::dvec3& sun, double mie_g) {
  const size_t n = probe.bins.size() + 3;
  auto wavelength = [&](size_t k) -> const Wavelength& {
    return k < probe.bins.size() ? probe.bins[k] : probe.rgb[k - probe.bins.size()];
  };
  std::vector<double> radiance(n, 0.0);
  const double altitude = atm.observer_altitude, r = atm.bottom_radius + altitude, mu = view.y;
  const double t_max = glsl::RayIntersectsGround(atm, r, altitude, mu)
                           ? glsl::DistanceToBottomBoundary(atm, r, altitude, mu)
                           : glsl::DistanceToTopBoundary(atm, r, altitude, mu);
  if (!(t_max > 0.0)) return radiance;
  const double nu = glm::dot(view, sun);
  const double rayleigh_phase = glsl::RayleighPhase(nu);
  const double mie_phase = glsl::MiePhase(mie_g, view, sun);
  const double dt = t_max / kViewSteps;
  glm::dvec3 view_column(0.0);
  for (int i = 0; i < kViewSteps; ++i) {
    const double t = (i + 0.5) * dt;
    const double h = glsl::AltitudeAlongRay(atm, r, altitude, mu, t);
    const glsl::MediumSample m = glsl::SampleMedium(atm, h);
    const glm::dvec3 density(m.rayleigh_scattering.x, m.mie_scattering.y, m.extinction.z);
    const glm::dvec3 to_sample = view_column + 0.5 * dt * density;
    view_column += dt * density;
    // The Sun's direction at the sample: its local zenith is the sample's radial direction.
    const glm::dvec3 position = glm::dvec3(0.0, r, 0.0) + t * view;
    const double mu_s = glm::dot(position, sun) / glm::length(position);
    const glm::dvec3 sun_column = ColumnsToTop(atm, h, mu_s);
    if (sun_column.x < 0.0) continue;  // in the Earth's shadow
    const glm::dvec3 column = to_sample + sun_column;
    for (size_t k = 0; k < n; ++k) {
      const Wavelength& w = wavelength(k);
      const double scattering = w.rayleigh * density.x * rayleigh_phase + w.mie_scattering * density.y * mie_phase;
      radiance[k] += w.solar * std::exp(-Extinction(w, column)) * scattering * dt;
    }
  }
  return radiance;
}

Rgb Integrate(const Probe& probe, const std::vector<double>& radiance) {
  Rgb rgb{};
  for (size_t k = 0; k < probe.bins.size(); ++k)
    for (int c = 0; c < 3; ++c) rgb[c] += probe.bins[k].rgb[c] * radiance[k];
  return rgb;
}

}  // namespace

// Each direction weighted by the inverse of its luminance, so that every
// direction's colour counts, not the brightest's.
bool FitSkyMatrix(const std::vector<Rgb>& samples, const std::vector<Rgb>& targets, Matrix3& sky) {
  double brightest = 0.0;
  for (const Rgb& t : targets) brightest = std::max(brightest, Rec709Luminance(t));
  if (!(brightest > 0.0)) return false;
  Matrix3 gram{};
  int used = 0;
  for (size_t i = 0; i < samples.size(); ++i) {
    const double y = Rec709Luminance(targets[i]);
    if (!(y > 1e-9 * brightest)) continue;
    const double w = 1.0 / (y * y);
    ++used;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) gram[a][b] += w * samples[i][a] * samples[i][b];
  }
  if (used < 12) return false;
  const Matrix3 inverse = Inverse(gram);
  Matrix3 fitted{};
  for (int row = 0; row < 3; ++row) {
    Rgb rhs{};
    for (size_t i = 0; i < samples.size(); ++i) {
      const double y = Rec709Luminance(targets[i]);
      if (!(y > 1e-9 * brightest)) continue;
      for (int a = 0; a < 3; ++a) rhs[a] += samples[i][a] * targets[i][row] / (y * y);
    }
    fitted[row] = Apply(inverse, rhs);
  }
  for (const Rgb& r : fitted)
    for (double v : r)
      if (!std::isfinite(v)) return false;
  sky = fitted;
  return true;
}

namespace {

// Direct sunlight where it lights the frame: at the observer, or, with the
// Sun below the observer's horizon, at the lowest altitude above it that the
// Sun still reaches (the air and clouds it lights at twilight).
bool DirectFactors(const glsl::AtmosphereParameters& atm, const Probe& probe, const glm::dvec3& sun, Rgb& direct) {
  double altitude = atm.observer_altitude;
  const double mu_s = std::clamp(sun.y, -1.0, 1.0);
  if (mu_s < 0.0) {
    const double grazing = atm.bottom_radius / std::sqrt(std::max(1.0 - mu_s * mu_s, 1e-12)) - atm.bottom_radius;
    altitude = std::max(altitude, grazing + 1.0);
  }
  if (altitude >= atm.top_radius - atm.bottom_radius) return false;
  const glm::dvec3 column = ColumnsToTop(atm, altitude, mu_s);
  if (column.x < 0.0) return false;
  Rgb three{}, true_rgb{};
  for (int c = 0; c < 3; ++c) three[c] = probe.rgb[c].solar * std::exp(-Extinction(probe.rgb[c], column));
  for (const Wavelength& w : probe.bins)
    for (int c = 0; c < 3; ++c) true_rgb[c] += w.rgb[c] * w.solar * std::exp(-Extinction(w, column));
  for (int c = 0; c < 3; ++c) {
    if (!(three[c] > 1e-30) || !(true_rgb[c] > 0.0)) return false;
    direct[c] = true_rgb[c] / three[c];
  }
  return true;
}

}  // namespace

OutputConversion UniformOutputConversion(const Rgb& scale) {
  OutputConversion c;
  for (int i = 0; i < 3; ++i) c.sky[i][i] = scale[i];
  c.direct = scale;
  return c;
}

Rgb BrunetonSkyFactors() { return {114974.916437, 71305.954816, 65310.548555}; }
Rgb BrunetonSunFactors() { return {98242.79, 69954.40, 66475.01}; }

SunLight SunLightAtObserver(const AtmosphereParams& atmosphere, const EffectSettings& effects, const glm::dvec3& sun) {
  SunLight light;
  const Probe probe = MakeProbe(atmosphere, effects);
  const glsl::AtmosphereParameters atm = ColumnAtmosphere(atmosphere, effects);
  const glm::dvec3 column = ColumnsToTop(atm, atm.observer_altitude, std::clamp(sun.y, -1.0, 1.0));
  if (column.x < 0.0) return light;  // the disc's centre is below the horizon
  for (int c = 0; c < 3; ++c) light.radiance[c] = probe.rgb[c].solar * std::exp(-Extinction(probe.rgb[c], column));
  for (const Wavelength& w : probe.bins)
    for (int c = 0; c < 3; ++c) light.luminance[c] += w.rgb[c] * w.solar * std::exp(-Extinction(w, column));
  return light;
}

OutputConversion FrameOutputConversion(const AtmosphereParams& atmosphere, const EffectSettings& effects,
                                       const glm::dvec3& sun) {
  OutputConversion c = UniformOutputConversion(BrunetonSkyFactors());
  const Probe probe = MakeProbe(atmosphere, effects);
  const glsl::AtmosphereParameters atm = ColumnAtmosphere(atmosphere, effects);
  if (!DirectFactors(atm, probe, sun, c.direct)) c.direct = BrunetonSunFactors();
  std::vector<Rgb> samples, targets;
  for (const glm::dvec3& view : SkyProbeDirections(sun)) {
    const std::vector<double> radiance = SingleScattering(atm, probe, view, sun, atmosphere.mie_g);
    const size_t three = probe.bins.size();
    samples.push_back({radiance[three], radiance[three + 1], radiance[three + 2]});
    targets.push_back(Integrate(probe, radiance));
  }
  Matrix3 sky{};
  if (FitSkyMatrix(samples, targets, sky)) c.sky = sky;
  return c;
}

}  // namespace skybake
