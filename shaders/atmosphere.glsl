// The physical atmosphere, written once in the common GLSL/C++ subset (see
// glsl_prelude.glsl). The compute shaders include it with Real = float; the
// CPU reference (bake/tools/reference/reference_model.cc) includes it with Real = double.
//
// Model: Hillaire 2020, "A Scalable and Production Ready Sky and Atmosphere
// Rendering Technique" (EGSR 2020), with the LUT parametrisation of Bruneton
// 2017 ("precomputed_atmospheric_scattering"):
//   - Rayleigh scattering, exponential density, no absorption;
//   - Mie scattering and absorption, exponential density, Cornette-Shanks phase;
//   - ozone absorption in a tent profile (no scattering);
//   - transmittance LUT (r, mu), multiple-scattering LUT (altitude, mu_s),
//     and the in-scattered radiance ray-marched per output texel.
//
// Frames and units: lengths in km, coefficients in km^-1, angles in radians.
// Positions are planet-centred; the observer stands on the +Y axis, so the
// local zenith is +Y. r = distance to the planet centre, mu = cosine of the
// view zenith angle, mu_s = cosine of the sun zenith angle, nu = cosine of the
// angle between the view and sun directions.
//
// Numerical care (Earth scale in float32):
//   - r is always carried together with `altitude` = r - bottom_radius, and
//     every difference of nearly equal radii is formed from altitudes;
//   - ray-sphere distances use the root that involves no subtraction of
//     nearly equal terms (the "q" form of the quadratic);
//   - 1 - nu and 1 + nu come from |v - s|^2 / 2 and |v + s|^2 / 2.
//
// Hooks each side must define before including this file:
//   vec3 TransmittanceLutTexel(int x, int y);
//   vec3 MultipleScatteringLutTexel(int x, int y);
//   vec3 SkyViewLutTexel(int x, int y);
#ifndef SKYBAKE_ATMOSPHERE_GLSL
#define SKYBAKE_ATMOSPHERE_GLSL

CONST_REAL kPi = 3.14159265358979323846;

#include "atmosphere_parameters.glsl"

// ---------------------------------------------------------------- medium


MediumSample SampleMedium(IN(AtmosphereParameters) atm, Real altitude) {
  Real h = max(altitude, 0.0);
  Real rayleigh_density = exp(-h / atm.rayleigh_scale_height);
  MediumSample m;
  m.rayleigh_scattering = atm.rayleigh_scattering * rayleigh_density;
  m.mie_scattering = vec3(0.0);
  m.extinction = m.rayleigh_scattering;
  if (atm.mie) {
    Real mie_density = exp(-h / atm.mie_scale_height);
    m.mie_scattering = atm.mie_scattering * mie_density;
    m.extinction += atm.mie_extinction * mie_density;
  }
  if (atm.ozone) {
    Real ozone_density = max(0.0, 1.0 - abs(h - atm.ozone_peak_altitude) / atm.ozone_half_width);
    m.extinction += atm.absorption_extinction * ozone_density;
  }
  return m;
}

// ---------------------------------------------------------------- geometry

Real ClampCosine(Real mu) { return clamp(mu, -1.0, 1.0); }

// Altitude of the point at distance t along the ray (r, mu), from
// r_t^2 - R_b^2 = altitude (r + R_b) + t (2 r mu + t), without forming
// r_t - R_b from two nearly equal radii.
Real AltitudeAlongRay(IN(AtmosphereParameters) atm, Real r, Real altitude, Real mu,
                      Real t) {
  Real excess = altitude * (r + atm.bottom_radius) + t * (2.0 * r * mu + t);
  Real r_t = sqrt(max(atm.bottom_radius * atm.bottom_radius + excess, 0.0));
  return excess / (r_t + atm.bottom_radius);
}

// Distance from a point inside the atmosphere (r <= top_radius) to the top
// boundary along mu. The discriminant is (R_t - r)(R_t + r) + (r mu)^2.
Real DistanceToTopBoundary(IN(AtmosphereParameters) atm, Real r, Real altitude,
                           Real mu) {
  Real top_minus_r = max((atm.top_radius - atm.bottom_radius) - altitude, 0.0);
  Real c = top_minus_r * (atm.top_radius + r);  // R_t^2 - r^2 >= 0
  Real discriminant = c + (r * mu) * (r * mu);
  Real root = sqrt(max(discriminant, 0.0));
  if (mu > 0.0) return c / (root + r * mu);
  return root - r * mu;
}

// True when the ray (r, mu) hits the ground.
bool RayIntersectsGround(IN(AtmosphereParameters) atm, Real r, Real altitude, Real mu) {
  Real discriminant = (r * mu) * (r * mu) - altitude * (r + atm.bottom_radius);
  return mu < 0.0 && discriminant >= 0.0;
}

// Distance to the ground along a ray that hits it (RayIntersectsGround).
Real DistanceToBottomBoundary(IN(AtmosphereParameters) atm, Real r, Real altitude,
                              Real mu) {
  Real c = altitude * (r + atm.bottom_radius);  // r^2 - R_b^2 >= 0
  Real discriminant = max((r * mu) * (r * mu) - c, 0.0);
  return c / (sqrt(discriminant) - r * mu);
}

// For an observer above the top boundary: distance to where the ray enters
// the atmosphere, or -1 when it misses it.
Real DistanceToAtmosphereEntry(IN(AtmosphereParameters) atm, Real r, Real altitude,
                               Real mu) {
  Real c = (altitude - (atm.top_radius - atm.bottom_radius)) * (r + atm.top_radius);
  Real discriminant = (r * mu) * (r * mu) - c;
  if (mu >= 0.0 || discriminant < 0.0) return -1.0;
  return c / (sqrt(discriminant) - r * mu);
}

// ---------------------------------------------------------------- LUT access

// Maps [0, 1] to texel-centre coordinates of a texture of `size` texels, so
// that 0 and 1 fall on the centres of the first and last texels.
Real TextureCoordFromUnitRange(Real x, int size) {
  return 0.5 / Real(size) + x * (1.0 - 1.0 / Real(size));
}

Real UnitRangeFromTextureCoord(Real u, int size) {
  return (u - 0.5 / Real(size)) / (1.0 - 1.0 / Real(size));
}

// Bilinear interpolation computed by hand from texel fetches (hardware
// filtering quantises its weights to 1/256 on lavapipe): the four texels
// around `uv` in a width x height table, and the weights between them.
struct LutBilinear {
  int x0;
  int y0;
  int x1;
  int y1;
  Real fx;
  Real fy;
};

LutBilinear LutBilinearAt(vec2 uv, int width, int height) {
  Real x = clamp(uv.x, 0.0, 1.0) * Real(width) - 0.5;
  Real y = clamp(uv.y, 0.0, 1.0) * Real(height) - 0.5;
  Real x0f = clamp(floor(x), 0.0, Real(width - 1));
  Real y0f = clamp(floor(y), 0.0, Real(height - 1));
  LutBilinear b;
  b.fx = clamp(x - x0f, 0.0, 1.0);
  b.fy = clamp(y - y0f, 0.0, 1.0);
  b.x0 = int(x0f);
  b.y0 = int(y0f);
  b.x1 = min(b.x0 + 1, width - 1);
  b.y1 = min(b.y0 + 1, height - 1);
  return b;
}

vec3 SampleTransmittanceLut(IN(AtmosphereParameters) atm, vec2 uv) {
  LutBilinear b = LutBilinearAt(uv, atm.transmittance_width, atm.transmittance_height);
  vec3 lower = mix(TransmittanceLutTexel(b.x0, b.y0), TransmittanceLutTexel(b.x1, b.y0), b.fx);
  vec3 upper = mix(TransmittanceLutTexel(b.x0, b.y1), TransmittanceLutTexel(b.x1, b.y1), b.fx);
  return mix(lower, upper, b.fy);
}

// The same read with the optical depth -log T interpolated instead of T:
// along grazing rays near the ground T falls as exp(-tau) with tau up to ~10
// (blue, the horizon) and changing by ~0.5 per texel of the 256 x 64 LUT,
// where a linear mix of T overestimates it by up to tau^2 / 8 ~ 3%; tau itself
// is smooth there (docs/accuracy.md, "Twilight"). A texel at or below 1e-30
// (float32 denormals) keeps the linear mix.
vec3 SampleTransmittanceLutLog(IN(AtmosphereParameters) atm, vec2 uv) {
  LutBilinear b = LutBilinearAt(uv, atm.transmittance_width, atm.transmittance_height);
  vec3 t00 = TransmittanceLutTexel(b.x0, b.y0), t10 = TransmittanceLutTexel(b.x1, b.y0);
  vec3 t01 = TransmittanceLutTexel(b.x0, b.y1), t11 = TransmittanceLutTexel(b.x1, b.y1);
  vec3 linear = mix(mix(t00, t10, b.fx), mix(t01, t11, b.fx), b.fy);
  vec3 floor_value = vec3(1e-30);
  vec3 lowest = min(min(t00, t10), min(t01, t11));
  vec3 logarithmic = exp2(mix(mix(log2(max(t00, floor_value)), log2(max(t10, floor_value)), b.fx),
                              mix(log2(max(t01, floor_value)), log2(max(t11, floor_value)), b.fx), b.fy));
  return mix(linear, logarithmic, vec3(greaterThan(lowest, floor_value)));
}

vec3 SampleMultipleScatteringLut(IN(AtmosphereParameters) atm, vec2 uv) {
  LutBilinear b = LutBilinearAt(uv, atm.multiscattering_width, atm.multiscattering_height);
  vec3 lower = mix(MultipleScatteringLutTexel(b.x0, b.y0), MultipleScatteringLutTexel(b.x1, b.y0), b.fx);
  vec3 upper = mix(MultipleScatteringLutTexel(b.x0, b.y1), MultipleScatteringLutTexel(b.x1, b.y1), b.fx);
  return mix(lower, upper, b.fy);
}

// ---------------------------------------------------------------- transmittance LUT

// Bruneton 2017 parametrisation: x_r = rho / H, x_mu = (d - d_min) / (d_max - d_min),
// with H the distance to the top along the horizon seen from the ground,
// rho the same from radius r, d the distance to the top along mu.
vec2 TransmittanceUvFromRMu(IN(AtmosphereParameters) atm, Real r, Real altitude,
                            Real mu) {
  Real thickness = atm.top_radius - atm.bottom_radius;
  Real H = sqrt(thickness * (atm.top_radius + atm.bottom_radius));
  Real rho = sqrt(max(altitude * (r + atm.bottom_radius), 0.0));
  Real d = DistanceToTopBoundary(atm, r, altitude, mu);
  Real d_min = max(thickness - altitude, 0.0);
  Real d_max = rho + H;
  Real x_mu = 0.0;
  if (d_max > d_min) x_mu = (d - d_min) / (d_max - d_min);
  Real x_r = rho / H;
  vec2 uv;
  uv.x = TextureCoordFromUnitRange(x_mu, atm.transmittance_width);
  uv.y = TextureCoordFromUnitRange(x_r, atm.transmittance_height);
  return uv;
}

struct RadiusAndCosine {
  Real r;
  Real altitude;
  Real mu;
};

RadiusAndCosine RMuFromTransmittanceTexel(IN(AtmosphereParameters) atm, int x, int y) {
  Real thickness = atm.top_radius - atm.bottom_radius;
  Real H = sqrt(thickness * (atm.top_radius + atm.bottom_radius));
  Real x_mu = UnitRangeFromTextureCoord((Real(x) + 0.5) / Real(atm.transmittance_width),
                                        atm.transmittance_width);
  Real x_r = UnitRangeFromTextureCoord((Real(y) + 0.5) / Real(atm.transmittance_height),
                                       atm.transmittance_height);
  Real rho = H * x_r;
  RadiusAndCosine result;
  result.r = sqrt(rho * rho + atm.bottom_radius * atm.bottom_radius);
  result.altitude = rho * rho / (result.r + atm.bottom_radius);
  Real d_min = max(thickness - result.altitude, 0.0);
  Real d_max = rho + H;
  Real d = d_min + x_mu * (d_max - d_min);
  // H^2 - rho^2 = R_t^2 - r^2 = d_min (R_t + r): formed from d_min so that the
  // top row (d_min -> 0) does not divide two rounding errors.
  result.mu = 1.0;
  if (d > 0.0)
    result.mu = ClampCosine((d_min * (atm.top_radius + result.r) - d * d) / (2.0 * result.r * d));
  return result;
}

// Optical depth (dimensionless, per channel) from (r, mu) to the top of the
// atmosphere, composite midpoint rule with `steps` points.
vec3 ComputeOpticalDepthToTopBoundary(IN(AtmosphereParameters) atm, Real r,
                                      Real altitude, Real mu, int steps) {
  Real t_max = DistanceToTopBoundary(atm, r, altitude, mu);
  Real dt = t_max / Real(steps);
  vec3 depth = vec3(0.0);
  for (int i = 0; i < steps; ++i) {
    Real t = (Real(i) + 0.5) * dt;
    depth += SampleMedium(atm, AltitudeAlongRay(atm, r, altitude, mu, t)).extinction;
  }
  return depth * dt;
}

vec3 ComputeTransmittanceLutTexel(IN(AtmosphereParameters) atm, int x, int y) {
  RadiusAndCosine rm = RMuFromTransmittanceTexel(atm, x, y);
  return exp(-ComputeOpticalDepthToTopBoundary(atm, rm.r, rm.altitude, rm.mu,
                                               atm.transmittance_steps));
}

vec3 GetTransmittanceToTopBoundary(IN(AtmosphereParameters) atm, Real r, Real altitude,
                                   Real mu) {
  return SampleTransmittanceLut(atm, TransmittanceUvFromRMu(atm, r, altitude, mu));
}

// The fraction of the solar disc above the horizon at radius r (Bruneton
// 2017), which keeps the terminator continuous.
Real SunVisibleFraction(IN(AtmosphereParameters) atm, Real r, Real altitude, Real mu_s) {
  Real sin_theta_h = atm.bottom_radius / r;
  Real cos_theta_h = -sqrt(max(altitude * (r + atm.bottom_radius), 0.0)) / r;
  return smoothstep(-sin_theta_h * atm.sun_angular_radius, sin_theta_h * atm.sun_angular_radius,
                    mu_s - cos_theta_h);
}

// Transmittance to the Sun, times the fraction of the solar disc above the horizon.
vec3 GetTransmittanceToSun(IN(AtmosphereParameters) atm, Real r, Real altitude,
                           Real mu_s) {
  return GetTransmittanceToTopBoundary(atm, r, altitude, mu_s) * SunVisibleFraction(atm, r, altitude, mu_s);
}

// ---------------------------------------------------------------- phase functions

// Rayleigh phase function, sr^-1.
Real RayleighPhase(Real nu) { return 3.0 / (16.0 * kPi) * (1.0 + nu * nu); }

// Cornette-Shanks phase function, sr^-1. The denominator 1 + g^2 - 2 g nu is
// formed as (1 - g)^2 + 2 g (1 - nu) for g >= 0 and (1 + g)^2 - 2 g (1 + nu)
// for g < 0: both sums of non-negative terms, exact near g = +/-1.
Real MiePhase(Real g, vec3 view, vec3 sun) {
  vec3 d_minus = view - sun;
  vec3 d_plus = view + sun;
  Real one_minus_nu = 0.5 * dot(d_minus, d_minus);
  Real one_plus_nu = 0.5 * dot(d_plus, d_plus);
  Real nu = 1.0 - one_minus_nu;
  Real denom = (1.0 - g) * (1.0 - g) + 2.0 * g * one_minus_nu;
  if (g < 0.0) denom = (1.0 + g) * (1.0 + g) - 2.0 * g * one_plus_nu;
  Real k = 3.0 / (8.0 * kPi) * (1.0 - g * g) / (2.0 + g * g);
  return k * (1.0 + nu * nu) / (denom * sqrt(denom));
}

// ---------------------------------------------------------------- quadrature helpers

// (1 - exp(-x)) / x for x >= 0, accurate as x -> 0 (series below 0.01,
// where 1 - exp(-x) would lose digits in float32).
Real OneMinusExpOverX(Real x) {
  if (x < 0.01) return 1.0 - x * (0.5 - x * (1.0 / 6.0 - x / 24.0));
  return (1.0 - exp(-x)) / x;
}

vec3 OneMinusExpOverX3(vec3 x) {
  vec3 result;
  result.x = OneMinusExpOverX(x.x);
  result.y = OneMinusExpOverX(x.y);
  result.z = OneMinusExpOverX(x.z);
  return result;
}

// ---------------------------------------------------------------- multiple-scattering LUT

struct MultipleScatteringTerms {
  vec3 second_order;  // L_2nd order of Hillaire eq. 6, per unit solar irradiance
  vec3 transfer;      // f_ms of Hillaire eq. 8
};

// One direction of Hillaire's eq. 6 and eq. 8: isotropic phase, sunlit
// medium plus the sunlit Lambertian ground at the end of the ray.
MultipleScatteringTerms IntegrateMultipleScatteringRay(IN(AtmosphereParameters) atm,
                                                       Real r, Real altitude, vec3 view,
                                                       vec3 sun) {
  Real mu = view.y;
  Real mu_s = sun.y;
  Real nu = dot(view, sun);
  bool hits_ground = RayIntersectsGround(atm, r, altitude, mu);
  Real t_max = hits_ground ? DistanceToBottomBoundary(atm, r, altitude, mu)
                           : DistanceToTopBoundary(atm, r, altitude, mu);
  Real dt = t_max / Real(atm.multiscattering_steps);
  CONST_REAL isotropic_phase = 1.0 / (4.0 * kPi);
  vec3 transmittance = vec3(1.0);
  MultipleScatteringTerms terms;
  terms.second_order = vec3(0.0);
  terms.transfer = vec3(0.0);
  for (int i = 0; i < atm.multiscattering_steps; ++i) {
    Real t = (Real(i) + 0.5) * dt;
    Real h = AltitudeAlongRay(atm, r, altitude, mu, t);
    Real r_t = atm.bottom_radius + h;
    Real mu_s_t = ClampCosine((r * mu_s + t * nu) / r_t);
    MediumSample m = SampleMedium(atm, h);
    vec3 scattering = m.rayleigh_scattering + m.mie_scattering;
    vec3 step_integral = dt * OneMinusExpOverX3(m.extinction * dt);  // int_0^dt exp(-sigma s) ds
    vec3 sun_transmittance = GetTransmittanceToSun(atm, r_t, h, mu_s_t);
    terms.second_order += transmittance * scattering * sun_transmittance * isotropic_phase * step_integral;
    terms.transfer += transmittance * scattering * step_integral;
    transmittance *= exp(-m.extinction * dt);
  }
  if (hits_ground) {
    Real mu_s_ground = ClampCosine((r * mu_s + t_max * nu) / atm.bottom_radius);
    vec3 sun_transmittance = GetTransmittanceToSun(atm, atm.bottom_radius, 0.0, mu_s_ground);
    terms.second_order += transmittance * sun_transmittance * max(mu_s_ground, 0.0) *
                          atm.ground_albedo / kPi;
  }
  return terms;
}

// Psi_ms of Hillaire eq. 10 for texel (x, y): x along mu_s in [-1, 1],
// y along altitude in [0, top - bottom]. Directions sample the sphere
// uniformly on a sqrt_dirs x sqrt_dirs stratified grid.
vec3 ComputeMultipleScatteringLutTexel(IN(AtmosphereParameters) atm, int x, int y) {
  Real mu_s = -1.0 + 2.0 * (Real(x) + 0.5) / Real(atm.multiscattering_width);
  Real altitude = (atm.top_radius - atm.bottom_radius) * (Real(y) + 0.5) /
                  Real(atm.multiscattering_height);
  Real r = atm.bottom_radius + altitude;
  vec3 sun;
  sun.x = sqrt(max(1.0 - mu_s * mu_s, 0.0));
  sun.y = mu_s;
  sun.z = 0.0;
  int n = atm.multiscattering_sqrt_dirs;
  vec3 second_order = vec3(0.0);
  vec3 transfer = vec3(0.0);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      Real cos_theta = 1.0 - 2.0 * (Real(i) + 0.5) / Real(n);
      Real sin_theta = sqrt(max(1.0 - cos_theta * cos_theta, 0.0));
      Real phi = 2.0 * kPi * (Real(j) + 0.5) / Real(n);
      vec3 view;
      view.x = sin_theta * cos(phi);
      view.y = cos_theta;
      view.z = sin_theta * sin(phi);
      MultipleScatteringTerms terms = IntegrateMultipleScatteringRay(atm, r, altitude, view, sun);
      second_order += terms.second_order;
      transfer += terms.transfer;
    }
  }
  Real inv_count = 1.0 / Real(n * n);
  second_order *= inv_count;
  transfer *= inv_count;
  return second_order / (vec3(1.0) - min(transfer, vec3(0.999)));
}

vec3 GetMultipleScattering(IN(AtmosphereParameters) atm, Real altitude, Real mu_s) {
  vec2 uv;
  uv.x = 0.5 + 0.5 * mu_s;
  uv.y = altitude / (atm.top_radius - atm.bottom_radius);
  return SampleMultipleScatteringLut(atm, uv);
}

// ---------------------------------------------------------------- sky radiance

// Radiance of the limb-darkened solar disc at angle `theta` from its centre,
// per unit solar irradiance: I(m) = I0 (1 - u (1 - m)), m = sqrt(1 - (theta/alpha)^2),
// normalised so that the disc integrates to the irradiance:
// I0 = 1 / (pi alpha^2 (1 - u / 3)).
Real SunDiscRadiance(IN(AtmosphereParameters) atm, Real theta) {
  Real alpha = atm.sun_angular_radius;
  if (theta >= alpha) return 0.0;
  Real x = theta / alpha;
  Real m = sqrt(max(1.0 - x * x, 0.0));
  Real u = atm.limb_darkening;
  return (1.0 - u * (1.0 - m)) / (kPi * alpha * alpha * (1.0 - u / 3.0));
}

// Transmittance from (r_t, mu_s_t) to the Sun, times the visible fraction of
// the disc: from the LUT, or (light_steps > 0) by a midpoint march of
// light_steps steps, Galaj 2019's "light samples".
// In a twilight frame (atm.transmittance_log) the LUT is read in the
// logarithm (SampleTransmittanceLutLog): the Sun's light there crosses the
// low air at grazing angles, where T is far from linear between texels.
vec3 SunTransmittance(IN(AtmosphereParameters) atm, Real r_t, Real h, Real mu_s_t) {
  if (atm.light_steps <= 0 && atm.transmittance_log)
    return SampleTransmittanceLutLog(atm, TransmittanceUvFromRMu(atm, r_t, h, mu_s_t)) *
           SunVisibleFraction(atm, r_t, h, mu_s_t);
  if (atm.light_steps <= 0) return GetTransmittanceToSun(atm, r_t, h, mu_s_t);
  Real sin_theta_h = atm.bottom_radius / r_t;
  Real cos_theta_h = -sqrt(max(h * (r_t + atm.bottom_radius), 0.0)) / r_t;
  Real visible = smoothstep(-sin_theta_h * atm.sun_angular_radius,
                            sin_theta_h * atm.sun_angular_radius, mu_s_t - cos_theta_h);
  if (visible <= 0.0) return vec3(0.0);
  // With the Sun partly set (its centre below the horizon at this point) the
  // light that reaches it grazes the horizon: march along the horizon ray,
  // as the transmittance LUT's read clamps to it, not through the ground.
  return exp(-ComputeOpticalDepthToTopBoundary(atm, r_t, h, max(mu_s_t, cos_theta_h), atm.light_steps)) * visible;
}

// The view ray of one texel after moving an observer above the atmosphere to
// where the ray enters it.
struct SkyRay {
  Real r;
  Real altitude;
  Real mu;
  Real mu_s;
  Real nu;
  bool in_atmosphere;
  bool hits_ground;
  Real t_max;
};

// The ray at the observer, before any move: in the atmosphere, not yet
// traced to the ground, no length.
SkyRay SkyRayAtObserver(IN(AtmosphereParameters) atm, vec3 view, vec3 sun) {
  SkyRay ray;
  ray.altitude = atm.observer_altitude;
  ray.r = atm.bottom_radius + ray.altitude;
  ray.mu = ClampCosine(view.y);
  ray.mu_s = ClampCosine(sun.y);
  ray.nu = ClampCosine(dot(view, sun));
  ray.in_atmosphere = true;
  ray.hits_ground = false;
  ray.t_max = 0.0;
  return ray;
}

SkyRay SetUpSkyRay(IN(AtmosphereParameters) atm, vec3 view, vec3 sun) {
  SkyRay ray = SkyRayAtObserver(atm, view, sun);
  if (ray.altitude > atm.top_radius - atm.bottom_radius) {
    Real t_entry = DistanceToAtmosphereEntry(atm, ray.r, ray.altitude, ray.mu);
    if (t_entry < 0.0) {
      ray.in_atmosphere = false;
      return ray;
    }
    Real r_entry = atm.top_radius;
    ray.mu = ClampCosine((ray.r * ray.mu + t_entry) / r_entry);
    ray.mu_s = ClampCosine((ray.r * ray.mu_s + t_entry * ray.nu) / r_entry);
    ray.r = r_entry;
    ray.altitude = atm.top_radius - atm.bottom_radius;
  }
  ray.hits_ground = RayIntersectsGround(atm, ray.r, ray.altitude, ray.mu);
  ray.t_max = ray.hits_ground ? DistanceToBottomBoundary(atm, ray.r, ray.altitude, ray.mu)
                              : DistanceToTopBoundary(atm, ray.r, ray.altitude, ray.mu);
  return ray;
}

// In-scattering source (per unit solar irradiance, sr^-1 km^-1) and
// extinction at distance t along the ray.
struct ScatteringSample {
  vec3 source;
  vec3 extinction;
};

ScatteringSample SampleScattering(IN(AtmosphereParameters) atm, IN(SkyRay) ray,
                                  Real rayleigh_phase, Real mie_phase, Real t) {
  Real h = AltitudeAlongRay(atm, ray.r, ray.altitude, ray.mu, t);
  Real r_t = atm.bottom_radius + h;
  Real mu_s_t = ClampCosine((ray.r * ray.mu_s + t * ray.nu) / r_t);
  MediumSample m = SampleMedium(atm, h);
  vec3 sun_transmittance = SunTransmittance(atm, r_t, h, mu_s_t);
  ScatteringSample sample_;
  sample_.source = (m.rayleigh_scattering * rayleigh_phase + m.mie_scattering * mie_phase) *
                   sun_transmittance;
  if (atm.multiple_scattering)
    sample_.source += (m.rayleigh_scattering + m.mie_scattering) *
                      (GetMultipleScattering(atm, h, mu_s_t) * atm.multiple_scattering_strength);
  sample_.extinction = m.extinction;
  return sample_;
}

struct InScattering {
  vec3 radiance;       // per unit solar irradiance
  vec3 transmittance;  // along the whole ray
};

// Where the view samples go: t(u) for u in [0, 1] over a segment of length
// `len`, uniform or quadratic (u^2 puts them near the segment's start, where
// a horizontal ray's density is: its altitude grows as t^2 / 2R). dt/du is
// the Jacobian of the mapping.
Real StepPosition(IN(AtmosphereParameters) atm, Real len, Real u) {
  return atm.step_distribution == STEPS_QUADRATIC ? len * u * u : len * u;
}
Real StepJacobian(IN(AtmosphereParameters) atm, Real len, Real u) {
  return atm.step_distribution == STEPS_QUADRATIC ? 2.0 * len * u : len;
}

// The integral L = int_{t_a}^{t_b} T(t_a, t) S(t) dt with n steps placed by
// StepPosition from t_a, with the rule atm.integrator, added to `result`
// (its transmittance is T(0, t_a) on entry and T(0, t_b) on return).
InScattering IntegrateInScatteringSegment(IN(AtmosphereParameters) atm, IN(SkyRay) ray,
                                          Real rayleigh_phase, Real mie_phase, Real t_a,
                                          Real t_b, int n, InScattering result) {
  Real du = 1.0 / Real(n);
  Real len = t_b - t_a;
  if (atm.integrator == INTEGRATOR_ANALYTIC || atm.integrator == INTEGRATOR_MIDPOINT) {
    Real t_start = t_a;
    for (int i = 0; i < n; ++i) {
      Real t_end = t_a + StepPosition(atm, len, Real(i + 1) * du);
      Real t_mid = t_a + StepPosition(atm, len, (Real(i) + 0.5) * du);
      Real dt = t_end - t_start;
      ScatteringSample s = SampleScattering(atm, ray, rayleigh_phase, mie_phase, t_mid);
      if (atm.integrator == INTEGRATOR_ANALYTIC) {
        // Hillaire 2020 eq. 5 per step: the source is constant over the step
        // and the transmittance is integrated exactly, int_0^dt exp(-sigma s) ds.
        result.radiance += result.transmittance * s.source * (dt * OneMinusExpOverX3(s.extinction * dt));
      } else {
        // Midpoint rule: integrand at the step's sample, T from the optical
        // depth accumulated by the same rule.
        result.radiance += result.transmittance * exp(-s.extinction * (t_mid - t_start)) * s.source * dt;
      }
      result.transmittance *= exp(-s.extinction * dt);
      t_start = t_end;
    }
  } else if (atm.integrator == INTEGRATOR_TRAPEZOID) {
    // Nodes u_i = i du in the mapped variable, integrand f(t(u)) dt/du; the
    // optical depth to each node by the same rule.
    ScatteringSample previous = SampleScattering(atm, ray, rayleigh_phase, mie_phase, t_a);
    Real w_previous = StepJacobian(atm, len, 0.0);
    vec3 depth = vec3(0.0);
    vec3 radiance = 0.5 * du * w_previous * previous.source;
    for (int i = 1; i <= n; ++i) {
      Real u = Real(i) * du;
      Real w = StepJacobian(atm, len, u);
      ScatteringSample s = SampleScattering(atm, ray, rayleigh_phase, mie_phase, t_a + StepPosition(atm, len, u));
      depth += 0.5 * du * (w_previous * previous.extinction + w * s.extinction);
      Real weight = i == n ? 0.5 * du : du;
      radiance += weight * w * exp(-depth) * s.source;
      previous = s;
      w_previous = w;
    }
    result.radiance += result.transmittance * radiance;
    result.transmittance *= exp(-depth);
  } else {
    // Simpson: weights du/3 (1, 4, 2, 4, ..., 4, 1) on nodes u_i = i du. The
    // optical depth to each node is integrated to the same order: over a
    // pair of steps by Simpson, to the middle node by the three-point rule
    // int_{u0}^{u1} f = du/12 (5 f0 + 8 f1 - f2).
    ScatteringSample s0 = SampleScattering(atm, ray, rayleigh_phase, mie_phase, t_a);
    Real w0 = StepJacobian(atm, len, 0.0);
    vec3 depth = vec3(0.0);
    vec3 radiance = (du / 3.0) * w0 * s0.source;
    for (int i = 0; i < n; i += 2) {
      Real u1 = Real(i + 1) * du;
      Real u2 = Real(i + 2) * du;
      Real w1 = StepJacobian(atm, len, u1);
      Real w2 = StepJacobian(atm, len, u2);
      ScatteringSample s1 = SampleScattering(atm, ray, rayleigh_phase, mie_phase, t_a + StepPosition(atm, len, u1));
      ScatteringSample s2 = SampleScattering(atm, ray, rayleigh_phase, mie_phase, t_a + StepPosition(atm, len, u2));
      vec3 e0 = w0 * s0.extinction;
      vec3 e1 = w1 * s1.extinction;
      vec3 e2 = w2 * s2.extinction;
      vec3 depth_mid = depth + (du / 12.0) * (5.0 * e0 + 8.0 * e1 - e2);
      depth += (du / 3.0) * (e0 + 4.0 * e1 + e2);
      Real end_weight = i + 2 == n ? 1.0 : 2.0;
      radiance += (du / 3.0) * (4.0 * w1 * exp(-max(depth_mid, vec3(0.0))) * s1.source +
                                end_weight * w2 * exp(-depth) * s2.source);
      s0 = s2;
      w0 = w2;
    }
    result.radiance += result.transmittance * radiance;
    result.transmittance *= exp(-depth);
  }
  return result;
}

// Where the ray leaves the planet's umbra: g(t) = mu_s(t) - cos(theta_h(t))
// + (R_b / r_t) alpha is negative where no part of the solar disc is above
// the horizon (SunTransmittance's visibility is 0 there). Returns t with
// g(t) < 0 <= g(t + 1e-6 t_max), or 0 when the ray starts outside the umbra
// or never leaves it. The umbra is convex, so a ray that starts inside it
// crosses its edge at most once, and bisection finds the crossing.
Real UmbraValue(IN(AtmosphereParameters) atm, IN(SkyRay) ray, Real t) {
  Real h = AltitudeAlongRay(atm, ray.r, ray.altitude, ray.mu, t);
  Real r_t = atm.bottom_radius + h;
  Real mu_s_t = (ray.r * ray.mu_s + t * ray.nu) / r_t;
  Real cos_theta_h = -sqrt(max(h * (r_t + atm.bottom_radius), 0.0)) / r_t;
  return mu_s_t - cos_theta_h + (atm.bottom_radius / r_t) * atm.sun_angular_radius;
}

Real UmbraExitDistance(IN(AtmosphereParameters) atm, IN(SkyRay) ray) {
  if (UmbraValue(atm, ray, 0.0) >= 0.0 || UmbraValue(atm, ray, ray.t_max) < 0.0) return 0.0;
  Real lo = 0.0;
  Real hi = ray.t_max;
  for (int i = 0; i < 20; ++i) {  // 1e-6 of the ray: under a metre on a 1000 km ray
    Real mid = 0.5 * (lo + hi);
    if (UmbraValue(atm, ray, mid) < 0.0) lo = mid;
    else hi = mid;
  }
  return lo;
}

// The single-scattering integral L = int_0^t_max T(t) S(t) dt with
// `view_steps` steps placed by StepPosition, with the rule atm.integrator.
// A ray that starts in the planet's umbra (twilight) is split where it
// leaves it: the steps that the unsplit mapping puts before that point stay
// there, up to half of them (the shadowed medium still scatters multiply and
// attenuates), the rest are placed from the umbra's edge, so that no step straddles the
// Earth's shadow, where the source rises by orders of magnitude within a
// few km (docs/accuracy.md, "Twilight").
InScattering IntegrateInScattering(IN(AtmosphereParameters) atm, IN(SkyRay) ray, vec3 view,
                                   vec3 sun) {
  InScattering result;
  result.radiance = vec3(0.0);
  result.transmittance = vec3(1.0);
  int n = atm.view_steps;
  bool simpson = atm.integrator == INTEGRATOR_SIMPSON;
  if (simpson) n += n % 2;  // Simpson needs an even count
  Real rayleigh_phase = RayleighPhase(ray.nu);
  Real mie_phase = atm.mie ? MiePhase(atm.mie_g, view, sun) : 0.0;
  int granule = simpson ? 2 : 1;
  Real t_split = 0.0;
  if (n >= 2 * granule) t_split = UmbraExitDistance(atm, ray);
  // One segment [0, t_max] with n steps, or two split at t_split. The
  // segments go through one call in a loop: the compiler inlines each call
  // of the integrator (every rule), so a second and third call site would
  // copy it (the sky-view LUT shader's SPIR-V, docs/performance.md).
  int n_first = n;
  Real t_first = ray.t_max;
  if (t_split > 0.0) {
    Real fraction = t_split / ray.t_max;
    if (atm.step_distribution == STEPS_QUADRATIC) fraction = sqrt(fraction);
    // At most half the steps in the shadow: a ray nearly parallel to the
    // shadow's axis leaves it far out, where the unsplit mapping has only a
    // step or two left for the lit part and its penumbra.
    n_first = int(floor(fraction * Real(n / granule) + 0.5)) * granule;
    n_first = clamp(n_first, granule, (n / (2 * granule)) * granule);
    t_first = t_split;
  }
  int segments = t_split > 0.0 ? 2 : 1;
  for (int k = 0; k < segments; ++k) {
    Real t_a = k == 0 ? 0.0 : t_first;
    Real t_b = k == 0 ? t_first : ray.t_max;
    int steps = k == 0 ? n_first : n - n_first;
    result = IntegrateInScatteringSegment(atm, ray, rayleigh_phase, mie_phase, t_a, t_b, steps, result);
  }
  return result;
}

// Radiance of the sunlit Lambertian ground at the end of a ray that hits it,
// per unit solar irradiance, before the view transmittance.
vec3 GroundRadiance(IN(AtmosphereParameters) atm, IN(SkyRay) ray) {
  Real mu_s_ground = ClampCosine((ray.r * ray.mu_s + ray.t_max * ray.nu) / atm.bottom_radius);
  vec3 sun_transmittance = GetTransmittanceToSun(atm, atm.bottom_radius, 0.0, mu_s_ground);
  return sun_transmittance * max(mu_s_ground, 0.0) * atm.ground_albedo / kPi;
}

// The sunlit ground's radiance as the viewer sees it at the end of `ray`
// (which hits the ground from the observer): GroundRadiance times T_air, the
// air's transmittance from the viewer to the ground, from the transmittance
// LUT (the ratio of the two rays to the top, Bruneton 2008); per unit solar
// irradiance.
vec3 SunlitGroundSeen(IN(AtmosphereParameters) atm, IN(SkyRay) ray) {
  Real mu_ground = ClampCosine((ray.r * ray.mu + ray.t_max) / atm.bottom_radius);
  vec3 to_top_ground = GetTransmittanceToTopBoundary(atm, atm.bottom_radius, 0.0, -mu_ground);
  vec3 to_top_viewer = GetTransmittanceToTopBoundary(atm, ray.r, ray.altitude, -ray.mu);
  vec3 air = min(to_top_ground / max(to_top_viewer, vec3(1e-30)), vec3(1.0));
  return air * GroundRadiance(atm, ray);
}

// Radiance reaching the observer along unit direction `view` (world frame,
// +Y up) with the Sun along unit `sun`, without the solar disc, and the
// transmittance along the view ray (0 where it hits the ground).
InScattering ComputeSkyRadianceWithoutSun(IN(AtmosphereParameters) atm, vec3 view, vec3 sun) {
  SkyRay ray = SetUpSkyRay(atm, view, sun);
  InScattering result;
  result.radiance = vec3(0.0);
  result.transmittance = vec3(1.0);
  if (!ray.in_atmosphere) return result;
  result = IntegrateInScattering(atm, ray, view, sun);
  if (ray.hits_ground) {
    if (atm.ground) result.radiance += result.transmittance * GroundRadiance(atm, ray);
    result.transmittance = vec3(0.0);  // the Sun is behind the ground
  }
  return result;
}

// Whether `view` may see the disc: a cheap test that keeps the disc's
// arcsine and transmittance read off every texel but the few near the Sun.
// The margin of twice the radius leaves the exact test to SunDiscRadiance.
bool NearSunDisc(IN(AtmosphereParameters) atm, vec3 view, vec3 sun) {
  return dot(view, sun) > cos(min(2.0 * atm.sun_angular_radius, kPi));
}

vec3 SunDiscContribution(IN(AtmosphereParameters) atm, vec3 view, vec3 sun, vec3 transmittance) {
  vec3 d = view - sun;
  Real theta = 2.0 * asin(min(0.5 * length(d), 1.0));
  return transmittance * (SunDiscRadiance(atm, theta) * atm.sun_disc_strength);
}

// Radiance along `view` in the units of solar_irradiance, ray-marched.
vec3 ComputeSkyRadiance(IN(AtmosphereParameters) atm, vec3 view, vec3 sun) {
  InScattering sky = ComputeSkyRadianceWithoutSun(atm, view, sun);
  vec3 radiance = sky.radiance;
  if (atm.sun_disc && NearSunDisc(atm, view, sun))
    radiance += SunDiscContribution(atm, view, sun, sky.transmittance);
  return radiance * atm.solar_irradiance;
}

// Twilight and night dimming (an artistic effect): between the end of civil
// twilight (sun at -6 deg) and astronomical night (-18 deg) the sky blends,
// by night_strength, from the physical sky to a night-sky floor (airglow and
// starlight) above the horizon and to black below it.
// The blend weight: 0 by day, night_strength at night.
Real NightDimmingWeight(IN(AtmosphereParameters) atm, vec3 sun) {
  // 1 - smoothstep(sin(-18 deg), sin(-6 deg), sun.y): 0 by day, 1 at night.
  Real night = 1.0 - smoothstep(-0.30901699437494740, -0.10452846326765347, sun.y);
  return atm.night_strength * night;
}

vec3 ApplyNightDimming(IN(AtmosphereParameters) atm, vec3 radiance, vec3 view, vec3 sun) {
  Real k = NightDimmingWeight(atm, sun);
  vec3 floor_radiance = view.y > 0.0 ? atm.night_radiance : vec3(0.0);
  return radiance * (1.0 - k) + floor_radiance * k;
}

// ---------------------------------------------------------------- sky-view LUT

// Hillaire 2020 section 5.3: the sky seen from the observer, per frame, in a
// frame where the Sun has azimuth 0. x: azimuth from the Sun in [0, pi]
// (the sky is symmetric about the Sun's vertical plane); y: zenith angle,
// with a square-root mapping that puts texels near the horizon, the upper
// half above it and the lower half below it.
struct SkyViewCoordinates {
  Real azimuth;       // from the Sun, [0, pi]
  Real zenith_angle;  // [0, pi]
};

// Zenith angle of the horizon seen by the observer (>= pi/2).
Real HorizonZenithAngle(IN(AtmosphereParameters) atm) {
  Real h = atm.observer_altitude;
  Real r = atm.bottom_radius + h;
  if (h > atm.top_radius - atm.bottom_radius) {
    // From space the "horizon" is the limb of the atmosphere's top.
    return kPi - asin(min(atm.top_radius / r, 1.0));
  }
  // pi/2 + asin(sqrt(r^2 - R_b^2) / r): the small angle below the horizontal
  // formed from the altitude, not from R_b / r ~ 1 (which rounds to 1 in
  // float32 for observers below a few metres).
  return 0.5 * kPi + asin(min(sqrt(max(h * (r + atm.bottom_radius), 0.0)) / r, 1.0));
}

vec2 SkyViewUvFromDirection(IN(AtmosphereParameters) atm, Real zenith_angle, Real azimuth) {
  Real horizon = HorizonZenithAngle(atm);
  vec2 uv;
  uv.x = clamp(azimuth / kPi, 0.0, 1.0);
  if (zenith_angle < horizon) {
    Real x = clamp(zenith_angle / horizon, 0.0, 1.0);
    uv.y = 0.5 * (1.0 - sqrt(1.0 - x));
  } else {
    Real x = clamp((zenith_angle - horizon) / (kPi - horizon), 0.0, 1.0);
    uv.y = 0.5 + 0.5 * sqrt(x);
  }
  return uv;
}

SkyViewCoordinates SkyViewDirectionFromTexel(IN(AtmosphereParameters) atm, int x, int y) {
  Real horizon = HorizonZenithAngle(atm);
  // Texel centres in each half, so that no texel straddles the horizon.
  int half_height = atm.sky_view_height / 2;
  SkyViewCoordinates c;
  c.azimuth = kPi * Real(x) / Real(atm.sky_view_width - 1);
  if (y < half_height) {
    Real v = Real(y) / Real(half_height - 1);  // 0 at the zenith, 1 at the horizon
    Real s = 1.0 - v;
    c.zenith_angle = horizon * (1.0 - s * s);
  } else {
    // Just below the horizon on the first row: the limit seen from the ground side.
    Real v = Real(y - half_height) / Real(atm.sky_view_height - half_height - 1);
    c.zenith_angle = horizon + (kPi - horizon) * max(v * v, 1e-6);
  }
  return c;
}

vec3 ViewFromSkyViewCoordinates(IN(SkyViewCoordinates) c) {
  vec3 view;
  view.x = sin(c.zenith_angle) * cos(c.azimuth);
  view.y = cos(c.zenith_angle);
  view.z = sin(c.zenith_angle) * sin(c.azimuth);
  return view;
}

vec3 SunInSkyViewFrame(Real mu_s) {
  vec3 sun;
  sun.x = sqrt(max(1.0 - mu_s * mu_s, 0.0));
  sun.y = mu_s;
  sun.z = 0.0;
  return sun;
}

// One texel of the sky-view LUT: the radiance without the disc, per unit
// solar irradiance, for the Sun at cosine zenith mu_s.
vec3 ComputeSkyViewLutTexel(IN(AtmosphereParameters) atm, int x, int y, Real mu_s) {
  SkyViewCoordinates c = SkyViewDirectionFromTexel(atm, x, y);
  vec3 view = ViewFromSkyViewCoordinates(c);
  if (y < atm.sky_view_height / 2) {
    // The horizon row must stay on the sky side: cos(horizon) rounds below
    // the exact horizon cosine in float32, so clamp to the latter, formed
    // without cancellation (0 exactly for an observer on the ground), moved
    // up by 1e-5 of itself so that the ground test of the exactly tangent ray
    // is not left to rounding.
    Real h = atm.observer_altitude;
    Real r = atm.bottom_radius + h;
    Real mu_horizon = -sqrt(max(h * (r + atm.bottom_radius), 0.0)) / r * (1.0 - 1e-5);
    if (h <= atm.top_radius - atm.bottom_radius && view.y < mu_horizon) {
      Real horizontal = length(vec2(view.x, view.z));
      Real scale = horizontal > 0.0 ? sqrt(max(1.0 - mu_horizon * mu_horizon, 0.0)) / horizontal : 0.0;
      view.x *= scale;
      view.z *= scale;
      view.y = mu_horizon;
    }
  }
  return ComputeSkyRadianceWithoutSun(atm, view, SunInSkyViewFrame(mu_s)).radiance;
}

// The sky half's row coordinate of `zenith_angle` in the sky-view LUT (0 at
// the zenith, half its height - 1 at the horizon), rows closer near the horizon.
Real SkyViewLutSkyRow(IN(AtmosphereParameters) atm, Real zenith_angle) {
  Real s = sqrt(max(1.0 - clamp(zenith_angle / HorizonZenithAngle(atm), 0.0, 1.0), 0.0));
  return (1.0 - s) * Real(atm.sky_view_height / 2 - 1);
}

// Bilinear read of the sky-view LUT, by hand, never across the horizon: the
// grid is exact at texel centres, which SkyViewDirectionFromTexel places on
// the zenith, the horizon (from either side) and the nadir.
// `ground` selects the half: it comes from the same ray test as the march
// (RayIntersectsGround), not from comparing rounded angles.
vec3 SampleSkyViewLut(IN(AtmosphereParameters) atm, Real zenith_angle, Real azimuth, bool ground) {
  Real horizon = HorizonZenithAngle(atm);
  int half_height = atm.sky_view_height / 2;
  Real fy = 0.0;
  int y0 = 0;
  int y_last = 0;
  if (!ground) {
    Real y = SkyViewLutSkyRow(atm, zenith_angle);
    y0 = int(min(floor(y), Real(half_height - 2)));
    fy = y - Real(y0);
    y_last = half_height - 1;
  } else {
    Real v = sqrt(clamp((zenith_angle - horizon) / (kPi - horizon), 0.0, 1.0));
    Real y = v * Real(atm.sky_view_height - half_height - 1);
    int local = int(min(floor(y), Real(atm.sky_view_height - half_height - 2)));
    fy = y - Real(local);
    y0 = half_height + local;
    y_last = atm.sky_view_height - 1;
  }
  int y1 = min(y0 + 1, y_last);
  Real x = clamp(azimuth / kPi, 0.0, 1.0) * Real(atm.sky_view_width - 1);
  int x0 = int(min(floor(x), Real(atm.sky_view_width - 2)));
  Real fx = x - Real(x0);
  int x1 = x0 + 1;
  vec3 t00 = SkyViewLutTexel(x0, y0), t10 = SkyViewLutTexel(x1, y0);
  vec3 t01 = SkyViewLutTexel(x0, y1), t11 = SkyViewLutTexel(x1, y1);
  // In the logarithm of the radiance where all four are positive: across
  // the Earth's shadow at twilight the sky dims by orders of magnitude within
  // a few texels, nearly exponentially, which a linear mix overestimates by
  // tens of percent (docs/accuracy.md, "Twilight"); where a texel is black
  // or nearly (below 1e-30: night, float32 denormals) the mix stays linear.
  vec3 linear = mix(mix(t00, t10, fx), mix(t01, t11, fx), fy);
  vec3 lowest = min(min(t00, t10), min(t01, t11));
  vec3 floor_value = vec3(1e-30);
  vec3 logarithmic = exp2(mix(mix(log2(max(t00, floor_value)), log2(max(t10, floor_value)), fx),
                              mix(log2(max(t01, floor_value)), log2(max(t11, floor_value)), fx), fy));
  return mix(linear, logarithmic, vec3(greaterThan(lowest, floor_value)));
}

// The solar disc seen along `view`, per unit solar irradiance, through the
// transmittance LUT: zero away from the disc and where the ground hides it.
vec3 SunDiscThroughAtmosphere(IN(AtmosphereParameters) atm, vec3 view, vec3 sun) {
  vec3 disc = vec3(0.0);
  if (NearSunDisc(atm, view, sun)) {
    SkyRay ray = SetUpSkyRay(atm, view, sun);
    if (ray.in_atmosphere && !ray.hits_ground) {
      disc = SunDiscContribution(atm, view, sun, GetTransmittanceToTopBoundary(atm, ray.r, ray.altitude, ray.mu));
    } else if (!ray.in_atmosphere) {
      disc = SunDiscContribution(atm, view, sun, vec3(1.0));
    }
  }
  return disc;
}

// The azimuth between the horizontal projections of view and sun (rad, 0 to
// pi): the sky-view LUT's column coordinate.
Real SkyViewAzimuth(vec3 view, vec3 sun) {
  Real cos_part = view.x * sun.x + view.z * sun.z;
  Real sin_part = abs(view.x * sun.z - view.z * sun.x);
  Real azimuth = 0.0;
  if (sin_part > 0.0 || cos_part != 0.0) azimuth = atan(sin_part, cos_part);
  return azimuth;
}

// The sky-view LUT's own estimate of its error along `view` (above the
// horizon): the second difference of log2 radiance down its columns at the
// two rows SampleSkyViewLut mixes, the larger, over both columns it reads
// and every channel. The read mixes the logarithm linearly, so where the
// logarithm is quadratic over a row spacing its error midway between the
// rows is an eighth of that second difference (in ln: times ln 2). Above the
// twilight band this is where the Earth's shadow's upper edge, and the
// grazing sunlight just outside it, bend the sky's logarithm between rows.
// kTwilightLutCurvature (log2) is chosen from the dense twilight sweep
// (docs/accuracy.md, "The Earth's shadow's edge above the band"): 0.03 keeps
// production within 1% and draft within 5% at sun -0.5 .. -10 deg from 0 to
// 12 km; 0.05 missed 1% at 0 m, sun -10 deg (1.08e-2). It runs up to
// kTwilightEdgeReach above the band's top, where the sweep found the LUT's
// misses (none above 21.3 deg elevation up to 45 deg).
const Real kTwilightLutCurvature = 0.03;
const Real kTwilightEdgeReach = 20.0 * kPi / 180.0;

Real SkyViewLutLogCurvature(IN(AtmosphereParameters) atm, vec3 view, vec3 sun) {
  int last_row = atm.sky_view_height / 2 - 1;
  Real y = SkyViewLutSkyRow(atm, atan(length(vec2(view.x, view.z)), view.y));
  int y0 = int(min(floor(y), Real(last_row - 1)));
  int below = max(y0 - 1, 0);
  int above = min(y0 + 2, last_row);
  Real x = clamp(SkyViewAzimuth(view, sun) / kPi, 0.0, 1.0) * Real(atm.sky_view_width - 1);
  int x0 = int(min(floor(x), Real(atm.sky_view_width - 2)));
  vec3 floor_value = vec3(1e-30);
  vec3 curvature = vec3(0.0);
  for (int column = x0; column <= x0 + 1; ++column) {
    vec3 l0 = log2(max(SkyViewLutTexel(column, below), floor_value));
    vec3 l1 = log2(max(SkyViewLutTexel(column, y0), floor_value));
    vec3 l2 = log2(max(SkyViewLutTexel(column, y0 + 1), floor_value));
    vec3 l3 = log2(max(SkyViewLutTexel(column, above), floor_value));
    if (y0 > 0) curvature = max(curvature, abs(l0 - 2.0 * l1 + l2));
    if (y0 + 2 <= last_row) curvature = max(curvature, abs(l1 - 2.0 * l2 + l3));
  }
  return max(curvature.x, max(curvature.y, curvature.z));
}

// How much of `view`'s radiance is ray-marched per texel rather than read
// from the sky-view LUT (1: marched, 0: read, between: both, mixed): at
// twilight (the Sun below the elevation of atm.twilight_sun_sine), the sky
// from the observer's horizon up to twilight_march_band above it, where the
// Earth's shadow and the band above it fall by orders of magnitude within
// the spacing of the LUT's rows (docs/accuracy.md, "Twilight"). Hillaire
// 2020 section 5.3 suggests the same fall-back for accuracy. The band's top
// is raised by the horizon's dip (HorizonZenithAngle - pi/2: 0 at sea level,
// 2.9 deg at 8 km): from altitude the horizon drops below the horizontal
// while the shadow's edge above it stands that much higher. Above the band,
// the texels where the LUT's logarithm bends between its rows
// (SkyViewLutLogCurvature) are marched too, mixed with the LUT's value where
// the bend is between half kTwilightLutCurvature and kTwilightLutCurvature,
// so that no seam shows where the march stops.
// A ray that lies wholly in the planet's umbra (UmbraValue below 0 at both
// its ends; the umbra is convex, so then at every point between) sees no
// sunlit air: its light is multiple scattering alone, which varies slowly
// and which the LUT holds, so it reads the LUT. That is the sky away from the
// Sun once it is some 10 deg down, and the whole sky at night (from sea level,
// the Sun more than about 20 deg down).
Real TwilightMarchWeight(IN(AtmosphereParameters) atm, vec3 view, vec3 sun) {
  if (!(atm.twilight_march_band > 0.0) || sun.y >= atm.twilight_sun_sine) return 0.0;
  Real horizon = HorizonZenithAngle(atm);
  Real above_horizon = horizon - atan(length(vec2(view.x, view.z)), view.y);
  if (!(above_horizon >= 0.0)) return 0.0;
  SkyRay ray = SetUpSkyRay(atm, view, sun);
  if (!ray.in_atmosphere || (UmbraValue(atm, ray, 0.0) < 0.0 && UmbraValue(atm, ray, ray.t_max) < 0.0)) return 0.0;
  Real top = atm.twilight_march_band + (horizon - 0.5 * kPi);
  if (above_horizon < top) return 1.0;
  if (above_horizon >= top + kTwilightEdgeReach) return 0.0;
  return smoothstep(0.5 * kTwilightLutCurvature, kTwilightLutCurvature, SkyViewLutLogCurvature(atm, view, sun));
}

// The elevations (rad above the horizontal) between which
// TwilightMarchWeight can be above 0: from the horizon (the dip below the
// horizontal) up to the band's top plus kTwilightEdgeReach, which the dip
// raises as much as it lowers the horizon. The host renders the rows of a
// view outside them with the day pipeline (SkyRenderer::TwilightRows).
vec2 TwilightMarchElevations(IN(AtmosphereParameters) atm) {
  return vec2(0.5 * kPi - HorizonZenithAngle(atm), atm.twilight_march_band + kTwilightEdgeReach);
}

// Radiance along `view` read from the sky-view LUT (built for this Sun), plus
// the solar disc seen through the transmittance LUT.
vec3 ComputeSkyRadianceFromSkyView(IN(AtmosphereParameters) atm, vec3 view, vec3 sun) {
  // Angles from atan2 of sine and cosine parts: acos loses half the digits
  // near 0 and pi (at the zenith, and next to the sun's vertical plane).
  Real horizontal = length(vec2(view.x, view.z));
  Real zenith_angle = atan(horizontal, view.y);
  Real azimuth = SkyViewAzimuth(view, sun);
  // Whether the ray hits the ground: the test of SetUpSkyRay, which for an
  // observer inside the atmosphere (every texel takes the same branch) needs
  // none of the ray's distances.
  bool ground = false;
  if (atm.observer_altitude > atm.top_radius - atm.bottom_radius) {
    SkyRay ray = SetUpSkyRay(atm, view, sun);
    ground = ray.in_atmosphere && ray.hits_ground;
  } else {
    ground = RayIntersectsGround(atm, atm.bottom_radius + atm.observer_altitude, atm.observer_altitude,
                                 ClampCosine(view.y));
  }
  vec3 radiance = SampleSkyViewLut(atm, zenith_angle, azimuth, ground);
  if (atm.sun_disc) radiance += SunDiscThroughAtmosphere(atm, view, sun);
  return radiance * atm.solar_irradiance;
}

#endif  // SKYBAKE_ATMOSPHERE_GLSL
