// The converged single-scattering reference of the accuracy study
// (tools/accuracy.h): the shared GLSL geometry and medium in double,
// integrated with composite Gauss-Legendre between the integrand's
// breakpoints.
#include "skybake/tools/accuracy.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include <glm/glm.hpp>

#include "skybake/model/shared_glsl.h"
#include "skybake/model/shared_params.h"

namespace skybake {
namespace converged {

// The shared geometry and medium functions (shared_glsl.h) with Mie and ozone
// on; their LUT hooks are never reached: this reference integrates every ray
// directly.
glsl::AtmosphereParameters FromParams(const AtmosphereParams& a) {
  glsl::AtmosphereParameters atm{};
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

using glsl::AtmosphereParameters;

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
void AddAltitudeCrossings(const AtmosphereParameters& atm, double r, double altitude, double mu, double a, double t_max,
                          std::vector<double>& out) {
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
std::vector<double> RayBreakpoints(const AtmosphereParameters& atm, double r, double altitude, double mu,
                                   double t_max) {
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
    for (int k = 0; k < kGaussOrder; ++k) sum += q.weights[k] * 0.5 * h * f(c + 0.5 * h * (q.nodes[k] + 1.0));
  }
  return sum;
}

glm::dvec3 OpticalDepth(const AtmosphereParameters& atm, double r, double altitude, double mu, double segment) {
  double t_max = glsl::DistanceToTopBoundary(atm, r, altitude, mu);
  std::vector<double> points = RayBreakpoints(atm, r, altitude, mu, t_max);
  glm::dvec3 depth(0.0);
  for (size_t i = 0; i + 1 < points.size(); ++i) {
    depth += Integrate(points[i], points[i + 1], segment, [&](double t) {
      return glsl::SampleMedium(atm, glsl::AltitudeAlongRay(atm, r, altitude, mu, t)).extinction;
    });
  }
  return depth;
}

// Sun transmittance with the same physics as the model: the transmittance to
// the top (along the horizon when the Sun is below it) times the visible
// fraction of the solar disc.
glm::dvec3 SunTransmittance(const AtmosphereParameters& atm, double r_t, double h, double mu_s, double segment) {
  double sin_theta_h = atm.bottom_radius / r_t;
  double cos_theta_h = -std::sqrt(std::max(h * (r_t + atm.bottom_radius), 0.0)) / r_t;
  double visible =
      glm::smoothstep(-sin_theta_h * atm.sun_angular_radius, sin_theta_h * atm.sun_angular_radius, mu_s - cos_theta_h);
  if (visible <= 0.0) return glm::dvec3(0.0);
  double mu_eff = std::max(mu_s, cos_theta_h);
  return glm::exp(-OpticalDepth(atm, r_t, h, mu_eff, segment)) * visible;
}

// The planet's shadow on the ray (r, altitude, mu) up to t_max, the Sun at
// mu_s with nu = cos(view, sun): where the sun visibility ramps, g(t) =
// +/-eps, found by sampling then bisection, added to `points`.
void AddShadowEdges(const AtmosphereParameters& atm, double r, double altitude, double mu, double mu_s, double nu,
                    double t_max, std::vector<double>& points) {
  auto shadow_offset = [&](double t, double sign) {
    double h = glsl::AltitudeAlongRay(atm, r, altitude, mu, t);
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
    double t_entry = glsl::DistanceToAtmosphereEntry(atm, r, altitude, mu);
    if (t_entry < 0.0) return glm::dvec3(0.0);
    mu = glm::clamp((r * mu + t_entry) / atm.top_radius, -1.0, 1.0);
    mu_s = glm::clamp((r * mu_s + t_entry * nu) / atm.top_radius, -1.0, 1.0);
    r = atm.top_radius;
    altitude = atm.top_radius - atm.bottom_radius;
  }
  bool ground = glsl::RayIntersectsGround(atm, r, altitude, mu);
  double t_max =
      ground ? glsl::DistanceToBottomBoundary(atm, r, altitude, mu) : glsl::DistanceToTopBoundary(atm, r, altitude, mu);
  std::vector<double> points = RayBreakpoints(atm, r, altitude, mu, t_max);
  AddShadowEdges(atm, r, altitude, mu, mu_s, nu, t_max, points);
  std::sort(points.begin(), points.end());

  const double rayleigh_phase = glsl::RayleighPhase(nu);
  const double mie_phase = glsl::MiePhase(atm.mie_g, view, sun);
  auto extinction = [&](double t) {
    return glsl::SampleMedium(atm, glsl::AltitudeAlongRay(atm, r, altitude, mu, t)).extinction;
  };
  auto source = [&](double t) {
    double alt = glsl::AltitudeAlongRay(atm, r, altitude, mu, t);
    double r_t = atm.bottom_radius + alt;
    double mu_s_t = glm::clamp((r * mu_s + t * nu) / r_t, -1.0, 1.0);
    glsl::MediumSample m = glsl::SampleMedium(atm, alt);
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
