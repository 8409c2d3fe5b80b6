#include "skybake/tools/accuracy.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>
#include <type_traits>

#include <fmt/format.h>
#include <glm/glm.hpp>

#include "skybake/input/config.h"
#include "skybake/model/envmap.h"
#include "skybake/output/exr_io.h"
#include "skybake/tools/reference_model.h"
#include "skybake/gpu/sky_renderer.h"
#include "skybake/model/tonemap.h"
#include "skybake/gpu/vulkan_context.h"
#include "skybake/model/shared_params.h"

namespace skybake {
namespace converged {

// The shared geometry and medium functions, in double. The LUT hooks are
// never reached: this reference integrates every ray directly.
#define SKYBAKE_REAL double
#include "skybake/model/glsl_compat.h"
vec3 TransmittanceLutTexel(int, int) { return vec3(0.0); }
vec3 MultipleScatteringLutTexel(int, int) { return vec3(0.0); }
vec3 SkyViewLutTexel(int, int) { return vec3(0.0); }
#include "atmosphere.glsl"

AtmosphereParameters FromParams(const AtmosphereParams& a) {
  AtmosphereParameters atm{};
  FillPhysicalParameters(a, atm);
  atm.mie = true;
  atm.ozone = true;
  atm.night = false;
  return atm;
}

}  // namespace converged

void GaussLegendre(int n, std::vector<double>& nodes, std::vector<double>& weights) {
  nodes.assign(n, 0.0);
  weights.assign(n, 0.0);
  for (int i = 0; i < n; ++i) {
    double x = std::cos(M_PI * (i + 0.75) / (n + 0.5));  // Tricomi's initial guess
    for (int iteration = 0; iteration < 100; ++iteration) {
      double p0 = 1.0, p1 = x;
      for (int k = 2; k <= n; ++k) {
        double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      double derivative = n * (x * p1 - p0) / (x * x - 1.0);
      double dx = p1 / derivative;
      x -= dx;
      if (std::abs(dx) < 1e-16) {
        nodes[i] = x;
        weights[i] = 2.0 / ((1.0 - x * x) * derivative * derivative);
        break;
      }
    }
  }
}

namespace {

using converged::AtmosphereParameters;

constexpr int kGaussOrder = 8;

struct Quadrature {
  std::vector<double> nodes, weights;
  Quadrature() { GaussLegendre(kGaussOrder, nodes, weights); }
};
const Quadrature& GL() {
  static const Quadrature q;
  return q;
}

// Distances along the ray (r, altitude, mu) in (0, t_max) where the altitude
// crosses `a` km.
void AddAltitudeCrossings(const AtmosphereParameters& atm, double r, double altitude, double mu,
                          double a, double t_max, std::vector<double>& out) {
  double ra = atm.bottom_radius + a;
  double c = (altitude - a) * (r + ra);  // r^2 - ra^2
  double disc = (r * mu) * (r * mu) - c;
  if (disc < 0.0) return;
  double root = std::sqrt(disc);
  for (double t : {-r * mu - root, -r * mu + root})
    if (t > 0.0 && t < t_max) out.push_back(t);
}

// Breakpoints of the piecewise-smooth integrand along a ray: ozone corners
// and the closest approach to the planet centre.
std::vector<double> RayBreakpoints(const AtmosphereParameters& atm, double r, double altitude,
                                   double mu, double t_max) {
  std::vector<double> points = {0.0, t_max};
  for (double a : {atm.ozone_peak_altitude - atm.ozone_half_width, atm.ozone_peak_altitude,
                   atm.ozone_peak_altitude + atm.ozone_half_width})
    if (a > 0.0) AddAltitudeCrossings(atm, r, altitude, mu, a, t_max, points);
  if (mu < 0.0 && -r * mu < t_max) points.push_back(-r * mu);
  std::sort(points.begin(), points.end());
  return points;
}

// Integrates f over [a, b] with composite Gauss-Legendre, sub-segments of at
// most `segment` km.
template <class F>
glm::dvec3 Integrate(double a, double b, double segment, F f) {
  const Quadrature& q = GL();
  glm::dvec3 sum(0.0);
  if (b <= a) return sum;
  int pieces = std::max(1, int(std::ceil((b - a) / segment)));
  double h = (b - a) / pieces;
  for (int p = 0; p < pieces; ++p) {
    double c = a + p * h;
    for (int k = 0; k < kGaussOrder; ++k)
      sum += q.weights[k] * 0.5 * h * f(c + 0.5 * h * (q.nodes[k] + 1.0));
  }
  return sum;
}

glm::dvec3 OpticalDepth(const AtmosphereParameters& atm, double r, double altitude, double mu,
                        double segment) {
  double t_max = converged::DistanceToTopBoundary(atm, r, altitude, mu);
  std::vector<double> points = RayBreakpoints(atm, r, altitude, mu, t_max);
  glm::dvec3 depth(0.0);
  for (size_t i = 0; i + 1 < points.size(); ++i) {
    depth += Integrate(points[i], points[i + 1], segment, [&](double t) {
      return converged::SampleMedium(atm, converged::AltitudeAlongRay(atm, r, altitude, mu, t)).extinction;
    });
  }
  return depth;
}

// Sun transmittance with the same physics as the model: the transmittance to
// the top (along the horizon when the Sun is below it) times the visible
// fraction of the solar disc.
glm::dvec3 SunTransmittance(const AtmosphereParameters& atm, double r_t, double h, double mu_s,
                            double segment) {
  double sin_theta_h = atm.bottom_radius / r_t;
  double cos_theta_h = -std::sqrt(std::max(h * (r_t + atm.bottom_radius), 0.0)) / r_t;
  double visible = glm::smoothstep(-sin_theta_h * atm.sun_angular_radius,
                                   sin_theta_h * atm.sun_angular_radius, mu_s - cos_theta_h);
  if (visible <= 0.0) return glm::dvec3(0.0);
  double mu_eff = std::max(mu_s, cos_theta_h);
  return glm::exp(-OpticalDepth(atm, r_t, h, mu_eff, segment)) * visible;
}

}  // namespace

ConvergedReference::ConvergedReference(const AtmosphereParams& atmosphere, double segment_km)
    : atmosphere_(atmosphere), segment_km_(segment_km) {}

glm::dvec3 ConvergedReference::Transmittance(double altitude_km, double mu) const {
  AtmosphereParameters atm = converged::FromParams(atmosphere_);
  return glm::exp(-OpticalDepth(atm, atm.bottom_radius + altitude_km, altitude_km, mu, segment_km_));
}

glm::dvec3 ConvergedReference::Radiance(const glm::dvec3& view, const glm::dvec3& sun) const {
  AtmosphereParameters atm = converged::FromParams(atmosphere_);
  const double seg = segment_km_;
  double altitude = atm.observer_altitude;
  double r = atm.bottom_radius + altitude;
  double mu = glm::clamp(view.y, -1.0, 1.0);
  double mu_s = glm::clamp(sun.y, -1.0, 1.0);
  double nu = glm::clamp(glm::dot(view, sun), -1.0, 1.0);
  if (altitude > atm.top_radius - atm.bottom_radius) {
    double t_entry = converged::DistanceToAtmosphereEntry(atm, r, altitude, mu);
    if (t_entry < 0.0) return glm::dvec3(0.0);
    mu = glm::clamp((r * mu + t_entry) / atm.top_radius, -1.0, 1.0);
    mu_s = glm::clamp((r * mu_s + t_entry * nu) / atm.top_radius, -1.0, 1.0);
    r = atm.top_radius;
    altitude = atm.top_radius - atm.bottom_radius;
  }
  bool ground = converged::RayIntersectsGround(atm, r, altitude, mu);
  double t_max = ground ? converged::DistanceToBottomBoundary(atm, r, altitude, mu)
                        : converged::DistanceToTopBoundary(atm, r, altitude, mu);
  std::vector<double> points = RayBreakpoints(atm, r, altitude, mu, t_max);

  // The planet's shadow: where the sun visibility ramps, g(t) = +/-eps.
  auto shadow_offset = [&](double t, double sign) {
    double h = converged::AltitudeAlongRay(atm, r, altitude, mu, t);
    double r_t = atm.bottom_radius + h;
    double mu_s_t = (r * mu_s + t * nu) / r_t;
    double cos_theta_h = -std::sqrt(std::max(h * (r_t + atm.bottom_radius), 0.0)) / r_t;
    return mu_s_t - cos_theta_h - sign * (atm.bottom_radius / r_t) * atm.sun_angular_radius;
  };
  for (double sign : {-1.0, 1.0}) {
    const int samples = 512;
    double previous = shadow_offset(0.0, sign);
    for (int i = 1; i <= samples; ++i) {
      double t1 = t_max * i / samples;
      double value = shadow_offset(t1, sign);
      if ((previous < 0.0) != (value < 0.0)) {
        double lo = t_max * (i - 1) / samples, hi = t1;
        for (int k = 0; k < 80; ++k) {
          double mid = 0.5 * (lo + hi);
          if ((shadow_offset(lo, sign) < 0.0) == (shadow_offset(mid, sign) < 0.0)) lo = mid;
          else hi = mid;
        }
        points.push_back(0.5 * (lo + hi));
      }
      previous = value;
    }
  }
  std::sort(points.begin(), points.end());

  const double rayleigh_phase = converged::RayleighPhase(nu);
  const double mie_phase = converged::MiePhase(atm.mie_g, view, sun);
  auto extinction = [&](double t) {
    return converged::SampleMedium(atm, converged::AltitudeAlongRay(atm, r, altitude, mu, t)).extinction;
  };
  auto source = [&](double t) {
    double alt = converged::AltitudeAlongRay(atm, r, altitude, mu, t);
    double r_t = atm.bottom_radius + alt;
    double mu_s_t = glm::clamp((r * mu_s + t * nu) / r_t, -1.0, 1.0);
    converged::MediumSample m = converged::SampleMedium(atm, alt);
    return glm::dvec3((m.rayleigh_scattering * rayleigh_phase + m.mie_scattering * mie_phase) *
                      SunTransmittance(atm, r_t, alt, mu_s_t, seg));
  };
  const Quadrature& q = GL();
  // int_c^{c+h} T(0, t) S(t) dt by one 8-point rule, T from the optical depth
  // at c plus the (smooth) extinction integral from c to each node.
  auto rule = [&](double c, double h, const glm::dvec3& depth_c) {
    glm::dvec3 sum(0.0);
    for (int k = 0; k < kGaussOrder; ++k) {
      double t = c + 0.5 * h * (q.nodes[k] + 1.0);
      sum += q.weights[k] * 0.5 * h * glm::exp(-(depth_c + Integrate(c, t, seg, extinction))) * source(t);
    }
    return sum;
  };
  // Adaptive bisection where the integrand is steep (near the planet's
  // shadow the sun transmittance changes by orders of magnitude per km):
  // a segment is accepted when its two halves agree with it to 1e-10.
  std::function<glm::dvec3(double, double, const glm::dvec3&, const glm::dvec3&, int)> adaptive =
      [&](double c, double h, const glm::dvec3& depth_c, const glm::dvec3& whole, int level) {
        glm::dvec3 depth_mid = depth_c + Integrate(c, c + 0.5 * h, seg, extinction);
        glm::dvec3 left = rule(c, 0.5 * h, depth_c);
        glm::dvec3 right = rule(c + 0.5 * h, 0.5 * h, depth_mid);
        glm::dvec3 halves = left + right;
        double scale = std::max({halves.x, halves.y, halves.z, 1e-300});
        glm::dvec3 diff = glm::abs(halves - whole);
        if (level >= 24 || std::max({diff.x, diff.y, diff.z}) <= 1e-10 * scale) return halves;
        return adaptive(c, 0.5 * h, depth_c, left, level + 1) +
               adaptive(c + 0.5 * h, 0.5 * h, depth_mid, right, level + 1);
      };
  glm::dvec3 radiance(0.0);
  glm::dvec3 depth(0.0);  // optical depth from the observer to the current sub-segment
  for (size_t i = 0; i + 1 < points.size(); ++i) {
    double a = points[i], b = points[i + 1];
    if (b <= a) continue;
    int pieces = std::max(1, int(std::ceil((b - a) / seg)));
    double h = (b - a) / pieces;
    for (int p = 0; p < pieces; ++p) {
      double c = a + p * h;
      radiance += adaptive(c, h, depth, rule(c, h, depth), 0);
      depth += Integrate(c, c + h, seg, extinction);
    }
  }
  return radiance * atm.solar_irradiance;
}

}  // namespace skybake

namespace skybake {
namespace {

struct StudyCase {
  std::string name;
  QualitySettings quality;
};

std::string IntegratorName(int integrator) {
  switch (integrator) {
    case INTEGRATOR_MIDPOINT: return "midpoint";
    case INTEGRATOR_TRAPEZOID: return "trapezoid";
    case INTEGRATOR_SIMPSON: return "simpson";
    default: return "analytic";
  }
}

StudyCase MakeCase(int integrator, int view, int light, bool sky_view = false, int sw = 0, int sh = 0,
                   int steps = STEPS_UNIFORM) {
  StudyCase c;
  c.quality.step_distribution = steps;
  c.quality.integrator = integrator;
  c.quality.view_steps = view;
  c.quality.light_steps = light;
  c.quality.sky_view_lut = sky_view;
  if (sky_view) {
    c.quality.sky_view_width = sw;
    c.quality.sky_view_height = sh;
  }
  c.name = IntegratorName(integrator) + " " + std::to_string(view) + "/" +
           (light > 0 ? std::to_string(light) : std::string("LUT"));
  if (steps == STEPS_QUADRATIC) c.name += " quadratic";
  if (sky_view) c.name += fmt::format(" sky-view {}x{}", sw, sh);
  return c;
}

std::vector<StudyCase> StudyCases(bool quick) {
  std::vector<StudyCase> cases;
  const std::vector<std::pair<int, int>> paper = quick ? std::vector<std::pair<int, int>>{{16, 8}, {128, 64}}
                                                       : std::vector<std::pair<int, int>>{
                                                             {16, 8}, {32, 16}, {64, 32}, {128, 64}, {512, 256}};
  for (int integrator : {INTEGRATOR_MIDPOINT, INTEGRATOR_TRAPEZOID, INTEGRATOR_SIMPSON, INTEGRATOR_ANALYTIC})
    for (auto [v, l] : paper) cases.push_back(MakeCase(integrator, v, l));
  const std::vector<int> lut_steps = quick ? std::vector<int>{16, 64} : std::vector<int>{8, 16, 24, 32, 48, 64, 128, 256};
  for (int v : lut_steps) {
    cases.push_back(MakeCase(INTEGRATOR_ANALYTIC, v, 0));
    cases.push_back(MakeCase(INTEGRATOR_ANALYTIC, v, 0, false, 0, 0, STEPS_QUADRATIC));
  }
  if (!quick)
    for (int v : {16, 32, 64, 128}) {
      cases.push_back(MakeCase(INTEGRATOR_SIMPSON, v, 0));
      cases.push_back(MakeCase(INTEGRATOR_SIMPSON, v, 0, false, 0, 0, STEPS_QUADRATIC));
    }
  // A finer transmittance LUT (1024 x 256, 1024 quadrature points) removes
  // the interpolation floor of the 256 x 64 one.
  auto fine_lut = [](StudyCase c) {
    c.quality.transmittance_width = 1024;
    c.quality.transmittance_height = 256;
    c.quality.transmittance_steps = 1024;
    c.name += " T1024";
    return c;
  };
  if (!quick) {
    for (int v : {64, 128, 256}) {
      cases.push_back(fine_lut(MakeCase(INTEGRATOR_ANALYTIC, v, 0, false, 0, 0, STEPS_QUADRATIC)));
      cases.push_back(fine_lut(MakeCase(INTEGRATOR_SIMPSON, v, 0, false, 0, 0, STEPS_QUADRATIC)));
    }
    cases.push_back(fine_lut(MakeCase(INTEGRATOR_SIMPSON, 128, 0, true, 768, 432, STEPS_QUADRATIC)));
    cases.push_back(fine_lut(MakeCase(INTEGRATOR_SIMPSON, 128, 0, true, 1536, 864, STEPS_QUADRATIC)));
  }
  // The sky-view LUT: its resolution against its steps per texel (a frame
  // of a time-lapse pays for one LUT, whatever its output size).
  for (auto [w, h] : quick ? std::vector<std::pair<int, int>>{{192, 108}}
                           : std::vector<std::pair<int, int>>{{192, 108}, {192, 216}, {256, 144}, {320, 180}, {384, 216}})
    for (int v : quick ? std::vector<int>{48} : std::vector<int>{24, 32, 48})
      cases.push_back(MakeCase(INTEGRATOR_ANALYTIC, v, 0, true, w, h, STEPS_QUADRATIC));
  if (!quick) cases.push_back(MakeCase(INTEGRATOR_ANALYTIC, 48, 0, true, 768, 432, STEPS_QUADRATIC));
  return cases;
}

// Directions of the study: the upper hemisphere, denser towards the horizon
// (where the integrals are hardest): elevations 0 .. 90 deg, azimuths every
// 15 deg, the zenith once.
std::vector<glm::dvec3> StudyDirections(bool quick) {
  std::vector<glm::dvec3> dirs;
  const std::vector<double> elevations = quick ? std::vector<double>{0.0, 5.0, 30.0}
                                               : std::vector<double>{0.0, 0.5, 2.0, 5.0, 10.0, 20.0, 35.0, 55.0, 75.0};
  double step = quick ? 45.0 : 15.0;
  for (double e : elevations)
    for (double a = 0.0; a < 360.0; a += step) dirs.push_back(SunDirectionFromElevationAzimuth(e, a));
  dirs.push_back({0.0, 1.0, 0.0});
  return dirs;
}

template <class Fn>
void ParallelIndices(size_t n, Fn fn) {
  unsigned threads = std::max(1u, std::thread::hardware_concurrency());
  std::vector<std::thread> pool;
  for (unsigned t = 0; t < threads; ++t)
    pool.emplace_back([&, t] {
      for (size_t i = t; i < n; i += threads) fn(i);
    });
  for (auto& th : pool) th.join();
}

// CIE L*a*b* (D65) of a display sRGB colour after exposure and ACES.
glm::dvec3 DisplayLab(const glm::dvec3& radiance, const Rgb& to_luminance, double exposure) {
  glm::dvec3 lin;
  for (int c = 0; c < 3; ++c) lin[c] = AcesFilmic(radiance[c] * to_luminance[c] * exposure);
  // Linear sRGB -> XYZ (IEC 61966-2-1), white D65.
  double X = 0.4124 * lin.x + 0.3576 * lin.y + 0.1805 * lin.z;
  double Y = 0.2126 * lin.x + 0.7152 * lin.y + 0.0722 * lin.z;
  double Z = 0.0193 * lin.x + 0.1192 * lin.y + 0.9505 * lin.z;
  auto f = [](double t) { return t > 216.0 / 24389.0 ? std::cbrt(t) : (24389.0 / 27.0 * t + 16.0) / 116.0; };
  double fx = f(X / 0.95047), fy = f(Y / 1.0), fz = f(Z / 1.08883);
  return {116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)};
}

struct CaseResult {
  std::string name;
  QualitySettings quality;
  double elevation = 0.0;
  double rmse_mw = 0.0;       // mW m^-2 sr^-1 nm^-1
  double max_relative = 0.0;  // over values above 1e-4 of the maximum
  double max_delta_e = 0.0;   // CIE76 after exposure + ACES
  double ms_per_mp = 0.0;     // lavapipe, GPU timestamps, median of 3
};

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

// GPU time of one render per megapixel, with a latlong sized to the cost.
double TimePerMegapixel(VulkanContext& vulkan, const AtmosphereParams& atmosphere,
                        const QualitySettings& quality, const EffectSettings& effects) {
  SkyRenderer renderer(vulkan, atmosphere, quality, effects, {1, 1, 1});
  renderer.PrecomputeLuts();
  double cost = double(quality.view_steps + 1) * double(std::max(quality.light_steps, 1));
  if (quality.sky_view_lut) cost = 4.0;
  int height = int(std::clamp(std::sqrt(4e8 / cost / 2.0), 32.0, 512.0));
  ViewRequest view{MAPPING_LATLONG, 2 * height, height, 0};
  std::vector<double> samples;
  for (int run = 0; run < 3; ++run) {
    // A new sun per run, as per frame of a time-lapse: a sky-view LUT is
    // rebuilt and counted in the frame's time.
    renderer.Render(SunDirectionFromElevationAzimuth(45.0 + 0.5 * run, 180.0), {view});
    double ms = 0.0;
    for (const PassTiming& t : renderer.last_timings()) ms += t.gpu_ms;
    samples.push_back(ms / (2.0 * height * height * 1e-6));
  }
  return Median(samples);
}

struct KiderCapture {
  std::string id;
  double sun_zenith = 0.0, sun_azimuth = 0.0;
};

std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream s(line);
  std::string field;
  while (std::getline(s, field, ',')) out.push_back(field);
  return out;
}

}  // namespace

std::string RunAccuracyStudy(const AccuracyStudyOptions& options) {
  auto say = [&](const std::string& text) {
    if (options.progress) options.progress(text);
  };
  std::filesystem::create_directories(options.out_dir);
  AtmosphereParams atmosphere;  // Earth defaults, spectral units
  atmosphere.observer_altitude_m = options.observer_altitude_m;
  EffectSettings single;              // the integral under study: single scattering
  single.multiple_scattering = false;
  single.sun_disc = false;
  single.ground = false;
  // By day (3..90 deg, the presets' front) and at twilight (1 .. -10 deg),
  // where the Earth's shadow crosses the low sky.
  const std::vector<double> elevations = options.quick ? std::vector<double>{90.0, 45.0, 10.0, 3.0, 0.0, -3.0}
                                                       : std::vector<double>{90.0, 45.0, 10.0, 3.0, 1.0, 0.0,
                                                                             -1.0, -3.0, -6.0, -10.0};
  const std::vector<glm::dvec3> dirs = StudyDirections(options.quick);
  std::vector<StudyCase> cases = StudyCases(options.quick);
  if (!options.only.empty())
    std::erase_if(cases, [&](const StudyCase& c) { return c.name.find(options.only) == std::string::npos; });
  const Rgb to_luminance = OutputScale(OutputUnits::kLuminance);

  VulkanOptions vulkan_options;
  VulkanContext vulkan(vulkan_options);

  // 1. The converged reference, with its own convergence.
  say(fmt::format("reference: {} directions x {} sun elevations", dirs.size(), elevations.size()));
  std::map<double, std::vector<glm::dvec3>> reference;
  std::vector<std::string> convergence_rows;
  ConvergedReference fine(atmosphere, 4.0), coarse(atmosphere, 8.0);
  for (double elevation : elevations) {
    glm::dvec3 sun = SunDirectionFromElevationAzimuth(elevation, 180.0);
    std::vector<glm::dvec3> ref(dirs.size()), half(dirs.size());
    ParallelIndices(dirs.size(), [&](size_t i) {
      ref[i] = fine.Radiance(dirs[i], sun);
      half[i] = coarse.Radiance(dirs[i], sun);
    });
    // Over the values the study's errors are measured on: above 1e-4 of the maximum.
    double worst = 0.0, max_value = 0.0;
    for (const glm::dvec3& l : ref) max_value = std::max({max_value, l.x, l.y, l.z});
    for (size_t i = 0; i < dirs.size(); ++i)
      for (int c = 0; c < 3; ++c)
        if (ref[i][c] > 1e-4 * max_value) worst = std::max(worst, std::abs(half[i][c] - ref[i][c]) / ref[i][c]);
    convergence_rows.push_back(fmt::format("| {} | {:.2e} |", elevation, worst));
    reference[elevation] = ref;
    say(fmt::format("reference at {} deg: segment 8 km vs 4 km differ by {:.2e} at most", elevation, worst));
  }

  // 2. Every case on the GPU, against the reference.
  std::vector<CaseResult> results;
  for (const StudyCase& c : cases) {
    SkyRenderer renderer(vulkan, atmosphere, c.quality, single, {1, 1, 1});
    double ms_per_mp = TimePerMegapixel(vulkan, atmosphere, c.quality, single);
    for (double elevation : elevations) {
      glm::dvec3 sun = SunDirectionFromElevationAzimuth(elevation, 180.0);
      std::vector<float> gpu = renderer.RenderDirections(sun, dirs);
      const std::vector<glm::dvec3>& ref = reference[elevation];
      double max_value = 0.0, log_sum = 0.0;
      for (const glm::dvec3& l : ref) {
        max_value = std::max({max_value, l.x, l.y, l.z});
        double y = 0.2126 * l.x * to_luminance[0] + 0.7152 * l.y * to_luminance[1] + 0.0722 * l.z * to_luminance[2];
        log_sum += std::log(std::max(y, 1e-9));
      }
      double exposure = 0.18 / std::exp(log_sum / double(ref.size()));
      CaseResult r;
      r.name = c.name;
      r.quality = c.quality;
      r.elevation = elevation;
      r.ms_per_mp = ms_per_mp;
      double sum_sq = 0.0;
      for (size_t i = 0; i < dirs.size(); ++i) {
        glm::dvec3 g(gpu[4 * i], gpu[4 * i + 1], gpu[4 * i + 2]);
        for (int ch = 0; ch < 3; ++ch) {
          double diff = g[ch] - ref[i][ch];
          sum_sq += diff * diff;
          if (ref[i][ch] > 1e-4 * max_value)
            r.max_relative = std::max(r.max_relative, std::abs(diff) / ref[i][ch]);
        }
        glm::dvec3 lab_g = DisplayLab(g, to_luminance, exposure), lab_r = DisplayLab(ref[i], to_luminance, exposure);
        r.max_delta_e = std::max(r.max_delta_e, glm::length(lab_g - lab_r));
      }
      r.rmse_mw = 1000.0 * std::sqrt(sum_sq / (3.0 * dirs.size()));
      results.push_back(r);
    }
    say(fmt::format("{:<32} {:9.1f} ms/MP", c.name, ms_per_mp));
  }

  // 3. Summary per case: worst over the daylight elevations (sun >= 3 deg)
  // and over all, the Pareto front of (time, daylight error), the presets.
  struct Summary {
    std::string name;
    QualitySettings quality;
    double ms_per_mp = 0.0, day_error = 0.0, all_error = 0.0, day_delta_e = 0.0;
    bool pareto = false;
  };
  std::vector<Summary> summaries;
  for (const StudyCase& c : cases) {
    Summary s;
    s.name = c.name;
    s.quality = c.quality;
    for (const CaseResult& r : results) {
      if (r.name != c.name) continue;
      s.ms_per_mp = r.ms_per_mp;
      s.all_error = std::max(s.all_error, r.max_relative);
      if (r.elevation >= 3.0) {
        s.day_error = std::max(s.day_error, r.max_relative);
        s.day_delta_e = std::max(s.day_delta_e, r.max_delta_e);
      }
    }
    summaries.push_back(s);
  }
  for (Summary& s : summaries) {
    s.pareto = true;
    for (const Summary& o : summaries)
      if (&o != &s && o.ms_per_mp <= s.ms_per_mp && o.day_error <= s.day_error &&
          (o.ms_per_mp < s.ms_per_mp || o.day_error < s.day_error))
        s.pareto = false;
  }
  struct PresetChoice {
    std::string preset;
    double bound;
    const Summary* choice = nullptr;
  };
  std::vector<PresetChoice> presets = {{"draft", 0.05}, {"production", 0.01}, {"reference", 0.001}};
  for (PresetChoice& p : presets)
    for (const Summary& s : summaries)
      if (s.pareto && s.day_error <= p.bound && (!p.choice || s.ms_per_mp < p.choice->ms_per_mp)) p.choice = &s;

  // 4. Against the measured skies (Kider 2014), Bruneton's RMSE protocol at
  // 440/550/680 nm, observer at 0 m, Bruneton 2017's demo atmosphere.
  say("kider2014: 15 captures");
  AtmosphereParams bruneton;
  bruneton.top_radius_km = 6420.0;
  bruneton.ground_albedo = {0.1, 0.1, 0.1};
  std::vector<std::string> kider_rows;
  std::vector<std::pair<std::string, QualitySettings>> kider_models;
  {
    QualitySettings galaj16 = MakeCase(INTEGRATOR_MIDPOINT, 16, 8).quality;
    QualitySettings galaj512 = MakeCase(INTEGRATOR_MIDPOINT, 512, 256).quality;
    kider_models = {{"single scattering, midpoint 16/8", galaj16},
                    {"single scattering, midpoint 512/256", galaj512},
                    {"full model: multiple scattering + ground + production preset", QualityPreset("production")}};
  }
  std::map<std::string, KiderCapture> captures;
  {
    std::ifstream in(options.shared_dir + "/groundtruth/kider2014/captures.csv");
    std::string line;
    std::getline(in, line);
    while (std::getline(in, line)) {
      auto f = SplitCsv(line);
      if (f.size() < 7) continue;
      captures[f[0]] = {f[0], std::stod(f[4]), std::stod(f[6])};  // zenith, symmetry azimuth
    }
  }
  struct Measurement {
    glm::dvec3 dir;
    glm::dvec3 rgb;  // 680, 550, 440 nm, W m^-2 sr^-1 nm^-1
  };
  std::map<std::string, std::vector<Measurement>> measured;
  {
    std::ifstream in(options.shared_dir + "/groundtruth/kider2014/photometric.csv");
    std::string line;
    std::getline(in, line);
    while (std::getline(in, line)) {
      auto f = SplitCsv(line);
      if (f.size() < 14) continue;
      double zenith = std::stod(f[2]), azimuth = std::stod(f[3]);
      measured[f[0]].push_back({SunDirectionFromElevationAzimuth(90.0 - zenith, azimuth),
                                {std::stod(f[13]), std::stod(f[12]), std::stod(f[11])}});
    }
  }
  std::vector<double> kider_totals;
  std::string kider_csv = "model,capture,rmse_mW_m2_sr_nm\n";
  for (const auto& [label, quality] : kider_models) {
    EffectSettings effects;
    effects.sun_disc = false;
    bool full = label.rfind("full", 0) == 0;
    effects.multiple_scattering = full;
    effects.ground = full;
    SkyRenderer renderer(vulkan, bruneton, quality, effects, {1, 1, 1});
    double sum_sq_rmse = 0.0;
    int count = 0;
    std::string per_capture;
    for (const auto& [id, capture] : captures) {
      const auto& samples = measured[id];
      if (samples.empty()) continue;
      std::vector<glm::dvec3> sample_dirs;
      for (const Measurement& m : samples) sample_dirs.push_back(m.dir);
      glm::dvec3 sun = SunDirectionFromElevationAzimuth(90.0 - capture.sun_zenith, capture.sun_azimuth);
      std::vector<float> gpu = renderer.RenderDirections(sun, sample_dirs);
      double sum_sq = 0.0;
      for (size_t i = 0; i < samples.size(); ++i)
        for (int c = 0; c < 3; ++c) {
          double d = 1000.0 * (gpu[4 * i + c] - samples[i].rgb[c]);
          sum_sq += d * d;
        }
      double rmse = std::sqrt(sum_sq / (3.0 * samples.size()));
      per_capture += fmt::format("{},{},{:.2f}\n", label, id, rmse);
      sum_sq_rmse += rmse * rmse;
      ++count;
    }
    double total = std::sqrt(sum_sq_rmse / std::max(count, 1));
    kider_totals.push_back(total);
    kider_rows.push_back(fmt::format("| {} | {} | {:.1f} |", label, count, total));
    kider_csv += per_capture;
  }
  // Every file through the one safe writer (exr_io.h): no link followed.
  WriteFileAtomically(options.out_dir + "/kider2014.csv", kider_csv);

  // 5. Files: CSV, plot, markdown.
  {
    std::ostringstream csv;
    csv << "case,integrator,view_steps,light_steps,sky_view_lut,sun_elevation_deg,rmse_mW_m2_sr_nm,"
           "max_relative_error,max_delta_e76,ms_per_megapixel\n";
    for (const CaseResult& r : results)
      csv << fmt::format("{},{},{},{},{},{},{:.6g},{:.6g},{:.6g},{:.6g}\n", r.name,
                         IntegratorName(r.quality.integrator), r.quality.view_steps, r.quality.light_steps,
                         r.quality.sky_view_lut ? fmt::format("{}x{}", r.quality.sky_view_width,
                                                              r.quality.sky_view_height)
                                                : "no",
                         r.elevation, r.rmse_mw, r.max_relative, r.max_delta_e, r.ms_per_mp);
    WriteFileAtomically(options.out_dir + "/accuracy.csv", csv.str());
  }
  {
    std::ostringstream data;
    for (const Summary& s : summaries)
      data << fmt::format("{:.6g} {:.6g} {} \"{}\"\n", s.ms_per_mp, std::max(s.day_error, 1e-7), s.pareto ? 1 : 0,
                          s.name);
    std::ostringstream front;
    std::vector<const Summary*> sorted;
    for (const Summary& s : summaries)
      if (s.pareto) sorted.push_back(&s);
    std::sort(sorted.begin(), sorted.end(), [](auto a, auto b) { return a->ms_per_mp < b->ms_per_mp; });
    for (const Summary* s : sorted) front << fmt::format("{:.6g} {:.6g}\n", s->ms_per_mp, std::max(s->day_error, 1e-7));
    std::ostringstream plot;
    plot << "set terminal pngcairo size 1100,750 noenhanced\n"
         << "set output '" << options.out_dir << "/accuracy.png'\n"
         << "set logscale xy\nset grid\n"
         << "set xlabel 'lavapipe time per megapixel (ms, 2 cores)'\n"
         << "set ylabel 'max relative error, upper hemisphere, sun 3..90 deg'\n"
         << "set title 'skybake: what accuracy costs (single scattering vs converged reference)'\n"
         << "set key top right\n"
         << "plot '" << options.out_dir << "/accuracy_front.dat' using 1:2 with lines lw 2 lc rgb '#cc3333' title 'Pareto front', \\\n"
         << "     '" << options.out_dir << "/accuracy_plot.dat' using 1:2:3 with points pt 7 ps 1.2 lc variable title 'cases', \\\n"
         << "     '" << options.out_dir << "/accuracy_plot.dat' using 1:2:4 with labels offset 0.5,0.5 left font ',7' notitle\n";
    WriteFileAtomically(options.out_dir + "/accuracy_plot.dat", data.str());
    WriteFileAtomically(options.out_dir + "/accuracy_front.dat", front.str());
    WriteFileAtomically(options.out_dir + "/accuracy.gnuplot", plot.str());
  }
  std::string plot_status = "written";
  if (std::system(fmt::format("gnuplot '{}/accuracy.gnuplot' 2>/dev/null", options.out_dir).c_str()) != 0)
    plot_status = "not written (gnuplot missing: apt-get install gnuplot-nox)";

  std::string md;
  md += fmt::format("## Cases (observer at {} m; worst over sun elevations 3..90 deg; every elevation in accuracy.csv)\n\n",
                    options.observer_altitude_m);
  md += "| case | ms per megapixel | max relative error | max Delta-E76 | worst incl. twilight (sun 1 .. -10 deg) | Pareto |\n";
  md += "| --- | ---: | ---: | ---: | ---: | :---: |\n";
  for (const Summary& s : summaries)
    md += fmt::format("| {} | {:.1f} | {:.2e} | {:.3f} | {:.2e} | {} |\n", s.name, s.ms_per_mp, s.day_error,
                      s.day_delta_e, s.all_error, s.pareto ? "yes" : "");
  md += "\n## Presets chosen from the front\n\n| preset | bound | case | max relative error | ms per megapixel |\n| --- | --- | --- | ---: | ---: |\n";
  for (const PresetChoice& p : presets) {
    if (p.choice)
      md += fmt::format("| `{}` | <= {:g}% | {} | {:.2e} | {:.1f} |\n", p.preset, p.bound * 100, p.choice->name,
                        p.choice->day_error, p.choice->ms_per_mp);
    else
      md += fmt::format("| `{}` | <= {:g}% | none of the cases meets it | | |\n", p.preset, p.bound * 100);
  }
  md += "\n## Reference convergence (segment 8 km vs 4 km, max relative difference)\n\n| sun elevation (deg) | max relative difference |\n| ---: | ---: |\n";
  for (const std::string& row : convergence_rows) md += row + "\n";
  md += "\n## Against the measured skies of Kider et al. 2014 (Bruneton's RMSE, 440/550/680 nm)\n\n| model | captures | RMSE mW/(m2 sr nm) |\n| --- | ---: | ---: |\n";
  for (const std::string& row : kider_rows) md += row + "\n";
  md += fmt::format("\nPlot {}: {}/accuracy.png\n", plot_status, options.out_dir);
  WriteFileAtomically(options.out_dir + "/accuracy_results.md", md);
  return md;
}

}  // namespace skybake
