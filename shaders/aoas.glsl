// The aesthetic principles of "Aesthetically-Oriented Atmospheric Scattering"
// (AOAS; Shen, Mallett, Shkurko, Eurographics 2019 short paper), written once
// in the common GLSL/C++ subset (see glsl_prelude.glsl) on top of the
// physical atmosphere of atmosphere.glsl. The compute shaders include it with
// Real = float; the CPU reference (bake/tools/reference/reference_model.cc) with Real = double.
//
// Spaces (paper section 3.2, fig. 3):
//   - skydome space: the model space of the single atmosphere skydome, centred
//     on the origin, radius R (the scene's units). The ground plane passes
//     through the centre, so the sky covers the whole upper hemisphere. The
//     baked map is the dome seen from its centre: texel direction w is the
//     dome fragment P^s_f = R w. +Y up, North = -Z, East = +X.
//   - Earth space: O'Neil's space, atmosphere thickness T = 1, Earth radius
//     r = bottom_radius / (top_radius - bottom_radius), Earth centre at O = 0.
//     The dome radius R corresponds to the thickness T, so a viewer at P^s_v
//     stands |P^s_v| / R atmosphere thicknesses above the ground.
//
// Every length of a principle (l_pt, s_noise, the perturbation grain) is in
// dome radii, so scaling the dome and the viewer together changes nothing
// (paper fig. 7).
//
// Hooks each side must define before including this file:
//   vec4 ShapeSegmentStart(int i);  // xyz unit direction, w fade radius (rad)
//   vec4 ShapeSegmentEnd(int i);    // xyz unit direction, w strength
//   int PerlinPermutation(int i);   // SKYBAKE_PERLIN_PERMUTATION[i], i in [0, 255]
#ifndef SKYBAKE_AOAS_GLSL
#define SKYBAKE_AOAS_GLSL

#include "aoas_parameters.glsl"

// ---------------------------------------------------------------- Improved Perlin noise

// p[i] of Perlin's doubled table p[512], for any i >= 0. The table is
// SKYBAKE_PERLIN_PERMUTATION of gpu_shared.h, read through the
// PerlinPermutation hook.
int PerlinHash(int i) { return PerlinPermutation(i & 255); }

// The quintic fade 6t^5 - 15t^4 + 10t^3 (Perlin 2002): zero first and second
// derivatives at t = 0 and 1, so the noise is C2 across lattice cells.
Real PerlinFade(Real t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

// Dot product of (x, y, z) with one of the 12 edge directions of a cube,
// (+-1, +-1, 0) and permutations, picked by the low 4 bits of `hash`: the
// 16 cases of Perlin's 2002 reference code, the 12 directions with (1,1,0),
// (-1,1,0), (0,-1,1), (0,-1,-1) repeated (as cases 12, 14, 13, 15).
Real PerlinGradient(int hash, Real x, Real y, Real z) {
  int h = hash & 15;
  Real u = h < 8 ? x : y;
  Real v = h < 4 ? y : ((h == 12 || h == 14) ? x : z);
  return ((h & 1) == 0 ? u : -u) + ((h & 2) == 0 ? v : -v);
}

// Improved Perlin noise at p: continuous (C2), zero at every lattice point,
// period 256 along each axis, range [-1, 1] (reached at cell centres).
Real ImprovedPerlinNoise(vec3 p) {
  vec3 cell = floor(p);
  int X = int(cell.x) & 255;
  int Y = int(cell.y) & 255;
  int Z = int(cell.z) & 255;
  Real x = p.x - cell.x;
  Real y = p.y - cell.y;
  Real z = p.z - cell.z;
  Real u = PerlinFade(x);
  Real v = PerlinFade(y);
  Real w = PerlinFade(z);
  int A = PerlinHash(X) + Y;
  int AA = PerlinHash(A) + Z;
  int AB = PerlinHash(A + 1) + Z;
  int B = PerlinHash(X + 1) + Y;
  int BA = PerlinHash(B) + Z;
  int BB = PerlinHash(B + 1) + Z;
  Real x00 = mix(PerlinGradient(PerlinHash(AA), x, y, z),
                 PerlinGradient(PerlinHash(BA), x - 1.0, y, z), u);
  Real x10 = mix(PerlinGradient(PerlinHash(AB), x, y - 1.0, z),
                 PerlinGradient(PerlinHash(BB), x - 1.0, y - 1.0, z), u);
  Real x01 = mix(PerlinGradient(PerlinHash(AA + 1), x, y, z - 1.0),
                 PerlinGradient(PerlinHash(BA + 1), x - 1.0, y, z - 1.0), u);
  Real x11 = mix(PerlinGradient(PerlinHash(AB + 1), x, y - 1.0, z - 1.0),
                 PerlinGradient(PerlinHash(BB + 1), x - 1.0, y - 1.0, z - 1.0), u);
  return mix(mix(x00, x10, v), mix(x01, x11, v), w);
}

// Sum of `octaves` octaves (frequency x2, amplitude x0.5 each), divided by
// the sum of the amplitudes: still in [-1, 1].
Real FractalPerlinNoise(vec3 p, int octaves) {
  Real sum = 0.0;
  Real amplitude = 1.0;
  Real total = 0.0;
  Real frequency = 1.0;
  for (int i = 0; i < octaves; ++i) {
    sum += amplitude * ImprovedPerlinNoise(p * frequency);
    total += amplitude;
    amplitude *= 0.5;
    frequency *= 2.0;
  }
  return sum / total;
}

// ---------------------------------------------------------------- single skydome (section 3.2)

// Apex direction (P^s_v - O) / |P^s_v - O| with O the dome centre. A viewer
// exactly at the centre has no apex direction: it is defined as up (+Y).
vec3 SkydomeApexDirection(vec3 viewer_position) {
  Real len = length(viewer_position);
  vec3 apex;
  apex.x = 0.0;
  apex.y = 1.0;
  apex.z = 0.0;
  if (len > 0.0) apex = viewer_position / len;
  return apex;
}

// Eq. 1: view direction from the viewer to a dome fragment, both in skydome
// space; the same direction in Earth space (fig. 6).
vec3 SkydomeViewDirection(vec3 fragment, vec3 viewer_position) {
  return normalize(fragment - viewer_position);
}

// Eq. 2 in Earth space units (thickness T = 1): P_v = P^s_v / R + r * apex.
// Its distance to the Earth centre is r + |P^s_v| / R, so the viewer's
// altitude above the ground is |P^s_v| / R thicknesses, formed here without
// subtracting r from |P_v|.
Real SkydomeViewerAltitude(IN(AtmosphereParameters) atm, IN(AoasParameters) aoas) {
  return length(aoas.viewer_position) / aoas.dome_radius * (atm.top_radius - atm.bottom_radius);
}

// Rotates v by the rotation that takes unit `apex` to +Y (the local zenith
// of atmosphere.glsl): v' = c v + a x v + a (a . v) / (1 + c), a = apex x Y,
// c = apex . Y. At apex = -Y (not reachable from a valid style) it turns
// half way round X.
vec3 RotateApexToZenith(vec3 v, vec3 apex) {
  vec3 up;
  up.x = 0.0;
  up.y = 1.0;
  up.z = 0.0;
  Real c = apex.y;
  if (c < -0.999999) {
    vec3 flipped;
    flipped.x = v.x;
    flipped.y = -v.y;
    flipped.z = -v.z;
    return flipped;
  }
  vec3 a = cross(apex, up);
  return c * v + cross(a, v) + a * (dot(a, v) / (1.0 + c));
}

// ---------------------------------------------------------------- ambiguity (eq. 5-6)

// rand() of eq. 6: three Improved Perlin noise fields in [-1, 1], keyed on
// the fragment position (so identical for a direction on any face or device),
// at feature size `perturbation_grain`, shifted by the seed.
vec3 PerturbationOffset(IN(AoasParameters) aoas, vec3 fragment) {
  vec3 q = fragment / (aoas.dome_radius * aoas.perturbation_grain) + aoas.perturbation_offset;
  vec3 shift_y;
  shift_y.x = 67.25;
  shift_y.y = 13.5;
  shift_y.z = 41.75;
  vec3 shift_z;
  shift_z.x = 29.5;
  shift_z.y = 83.25;
  shift_z.z = 7.0;
  vec3 offset;
  offset.x = ImprovedPerlinNoise(q);
  offset.y = ImprovedPerlinNoise(q + shift_y);
  offset.z = ImprovedPerlinNoise(q + shift_z);
  return offset * (aoas.l_pt * aoas.dome_radius);
}

// The perturbed view `perturbed` (unit) kept on the side of the horizon that
// the unperturbed view `view` (unit) is on, both before the skydome's turn
// to the zenith, `apex` the local zenith there. The horizon is the cosine
// mu_h = -sqrt(1 - (r_bottom / r)^2) of the observer at `altitude` (km; 0 on
// the ground): a view with mu = apex . view < mu_h meets the ground. The
// perturbation's change of mu, delta, is scaled by d^2 / (d^2 + delta^2),
// d = |mu_view - mu_h|: |delta| d^2 / (d^2 + delta^2) <= d / 2 < d, so the
// view never crosses the horizon, and far from it (d >> |delta|) the
// perturbation is kept whole (factor 1 - (delta / d)^2). The azimuthal part
// of the perturbation is kept everywhere. Ground texels then show ground and
// sky texels sky, as without ambiguity (issue 50, item 6).
vec3 KeepPerturbedViewOnSide(IN(AtmosphereParameters) atm, vec3 view, vec3 perturbed, vec3 apex,
                             Real altitude) {
  Real r = atm.bottom_radius + altitude;
  Real ratio = atm.bottom_radius / r;
  Real mu_h = -sqrt(max(1.0 - ratio * ratio, 0.0));
  Real mu_view = dot(view, apex);
  Real mu_perturbed = dot(perturbed, apex);
  Real d = abs(mu_view - mu_h);
  Real delta = mu_perturbed - mu_view;
  Real denom = d * d + delta * delta;
  if (denom <= 0.0) return view;
  Real mu = clamp(mu_view + delta * (d * d / denom), -1.0, 1.0);
  vec3 across = perturbed - apex * mu_perturbed;
  Real across_len = length(across);
  if (across_len < 1e-6) return perturbed;  // at the zenith or nadir, far from the horizon
  return apex * mu + across * (sqrt(max(1.0 - mu * mu, 0.0)) / across_len);
}

// ---------------------------------------------------------------- cloud complexity (eq. 7-8)

// Cloud amount in [0, 1] from eq. 7, noise = Perlin(P^s_f, S_noise): the
// fractal noise of the fragment in units of S_noise, plus the drift, mapped
// linearly from [threshold, 1] to [0, 1].
Real CloudNoiseAmount(IN(AoasParameters) aoas, vec3 fragment) {
  vec3 p = fragment / (aoas.dome_radius * aoas.s_noise) + aoas.noise_offset;
  Real n = FractalPerlinNoise(p, aoas.noise_octaves);
  return clamp((n - aoas.noise_threshold) / (1.0 - aoas.noise_threshold), 0.0, 1.0);
}

// ---------------------------------------------------------------- cloud shapes

// Angle between unit vectors, accurate at small and large angles.
Real AngleBetween(vec3 a, vec3 b) { return atan(length(cross(a, b)), dot(a, b)); }

// Angular distance from unit w to the great-circle arc from unit a to unit b
// (shorter arc; a == b is a point).
Real AngularDistanceToArc(vec3 w, vec3 a, vec3 b) {
  Real to_ends = min(AngleBetween(w, a), AngleBetween(w, b));
  vec3 n = cross(a, b);
  Real n_len = length(n);
  if (n_len < 1e-6) return to_ends;
  n = n / n_len;
  // Foot of w on the arc's great circle; inside the arc when it lies between
  // a and b going round n.
  vec3 foot = w - n * dot(w, n);
  if (dot(cross(a, foot), n) >= 0.0 && dot(cross(foot, b), n) >= 0.0)
    return min(to_ends, asin(min(abs(dot(w, n)), 1.0)));
  return to_ends;
}

// Cloud amount in [0, 1] from the user's shapes: each segment contributes
// strength * (1 - distance / radius), fading linearly to 0 at its radius;
// overlapping shapes take the largest contribution.
Real CloudShapeAmount(IN(AoasParameters) aoas, vec3 w) {
  Real amount = 0.0;
  for (int i = 0; i < aoas.shape_segment_count; ++i) {
    vec4 a = ShapeSegmentStart(i);
    vec4 b = ShapeSegmentEnd(i);
    Real d = AngularDistanceToArc(w, vec3(a), vec3(b));
    amount = max(amount, b.w * max(0.0, 1.0 - d / a.w));
  }
  return clamp(amount * aoas.shape_strength, 0.0, 1.0);
}

// ---------------------------------------------------------------- HSV (eq. 8)

// RGB -> HSV (hue in [0, 1), saturation in [0, 1], value = max channel) for
// non-negative, unbounded (HDR) RGB.
vec3 RgbToHsv(vec3 c) {
  Real v = max(c.x, max(c.y, c.z));
  Real lo = min(c.x, min(c.y, c.z));
  Real delta = v - lo;
  vec3 hsv;
  hsv.x = 0.0;
  hsv.y = 0.0;
  hsv.z = v;
  if (v > 0.0) hsv.y = delta / v;
  if (delta > 0.0) {
    Real h = 0.0;
    if (v == c.x) h = (c.y - c.z) / delta;
    else if (v == c.y) h = 2.0 + (c.z - c.x) / delta;
    else h = 4.0 + (c.x - c.y) / delta;
    h = h / 6.0;
    if (h < 0.0) h += 1.0;
    hsv.x = h;
  }
  return hsv;
}

vec3 HsvToRgb(vec3 hsv) {
  Real h6 = hsv.x * 6.0;
  Real sector = floor(h6);
  Real f = h6 - sector;
  Real v = hsv.z;
  Real p = v * (1.0 - hsv.y);
  Real q = v * (1.0 - hsv.y * f);
  Real t = v * (1.0 - hsv.y * (1.0 - f));
  int i = int(sector);
  if (i >= 6) i -= 6;
  vec3 c;
  if (i == 0) { c.x = v; c.y = t; c.z = p; }
  else if (i == 1) { c.x = q; c.y = v; c.z = p; }
  else if (i == 2) { c.x = p; c.y = v; c.z = t; }
  else if (i == 3) { c.x = p; c.y = q; c.z = v; }
  else if (i == 4) { c.x = t; c.y = p; c.z = v; }
  else { c.x = v; c.y = p; c.z = q; }
  return c;
}

// Eq. 8: c_hsv = RGB_to_HSV(c_rgb); c_s = c_s * factor; back to RGB.
vec3 ScaleSaturation(vec3 rgb, Real factor) {
  vec3 hsv = RgbToHsv(rgb);
  hsv.y = hsv.y * factor;
  return HsvToRgb(hsv);
}

// ---------------------------------------------------------------- the styled sky

// The principles that act on the colour of a texel, in order: the cloud
// saturation (eq. 7-8 and the shapes), judged in `color_scale` RGB, then the
// night floor. `radiance` is the physical radiance along texel direction `w`
// (unit) with the Sun along unit `sun`. The sky pass applies them to its own
// three wavelengths; the spectral mode's style pass (sky_style.comp) to the
// colour its wavelength groups combine to.
vec3 StyleSkyRadiance(IN(AtmosphereParameters) atm, IN(AoasParameters) aoas, vec3 radiance, vec3 w, vec3 sun) {
  if (aoas.cloud_noise || aoas.cloud_shapes) {
    Real keep = 1.0;
    // Noise clouds live in the sky half of the dome, above the ground plane.
    if (aoas.cloud_noise && w.y > 0.0)
      keep *= 1.0 - aoas.noise_strength * CloudNoiseAmount(aoas, w * aoas.dome_radius);
    if (aoas.cloud_shapes) keep *= 1.0 - CloudShapeAmount(aoas, w);
    vec3 color = radiance * aoas.color_scale;
    radiance = ScaleSaturation(color, keep) / aoas.color_scale;
  }
  if (atm.night) radiance = ApplyNightDimming(atm, radiance, w, sun);
  return radiance;
}

// Radiance of the styled sky for texel direction `w` (unit; the dome
// fragment R w seen from the dome centre) with the Sun along unit `sun`,
// in the units of ComputeSkyRadiance (read from the sky-view LUT with
// `use_sky_view`, as ComputeSkyRadianceFromSkyView). Applies, in order: the skydome
// transform (eq. 1-2), the perturbation (eq. 5-6), the physical radiance
// (the hue principle acts through atm.rayleigh_scattering), then the cloud
// saturation and the night floor (StyleSkyRadiance).
vec3 ComputeStyledSkyRadiance(IN(AtmosphereParameters) atm, IN(AoasParameters) aoas, vec3 w,
                              vec3 sun, bool use_sky_view) {
  AtmosphereParameters earth = atm;
  vec3 fragment = w * aoas.dome_radius;
  vec3 viewer;
  viewer.x = 0.0;
  viewer.y = 0.0;
  viewer.z = 0.0;
  if (aoas.skydome) {
    viewer = aoas.viewer_position;
    earth.observer_altitude = SkydomeViewerAltitude(atm, aoas);
  }
  // Without the skydome and the perturbation, eq. 1 gives back w exactly.
  vec3 view = w;
  vec3 apex = SkydomeApexDirection(viewer);
  if (aoas.skydome || aoas.ambiguity) {
    view = SkydomeViewDirection(fragment, viewer);
    if (aoas.ambiguity) {
      vec3 perturbed = SkydomeViewDirection(fragment + PerturbationOffset(aoas, fragment), viewer);
      view = KeepPerturbedViewOnSide(earth, view, perturbed, apex, earth.observer_altitude);
    }
  }
  vec3 sun_local = sun;
  if (aoas.skydome) {
    view = RotateApexToZenith(view, apex);
    sun_local = RotateApexToZenith(sun, apex);
  }
  // The sky-view LUT is built for the configured observer and Sun; the
  // skydome moves the observer and turns the Sun, so it ray-marches instead,
  // as does the low sky at twilight (TwilightMarchWeight) with its own steps.
  vec3 radiance;
#ifdef SKYBAKE_NO_TWILIGHT_MARCH
  const bool twilight_march = false;  // the sky-view variant: no ray march in its SPIR-V
#else
  Real twilight_weight = use_sky_view && !aoas.skydome ? TwilightMarchWeight(earth, view, sun_local) : 0.0;
  bool twilight_march = twilight_weight >= 1.0;
  if (twilight_weight > 0.0) earth.view_steps = earth.twilight_march_steps;
#endif
#ifdef SKYBAKE_NO_TWILIGHT_MARCH
  if (use_sky_view && !aoas.skydome && !twilight_march) radiance = ComputeSkyRadianceFromSkyView(earth, view, sun_local);
  else radiance = ComputeSkyRadiance(earth, view, sun_local);
#else
  // At the edge of the marched texels above the twilight band, the LUT's
  // value mixed with the march's: no seam where the march stops. One call
  // of each, so that the shader holds one ray march.
  bool read_lut = use_sky_view && !aoas.skydome && !twilight_march;
  bool march = !read_lut || twilight_weight > 0.0;
  vec3 lut_radiance = vec3(0.0);
  if (read_lut) lut_radiance = ComputeSkyRadianceFromSkyView(earth, view, sun_local);
  radiance = lut_radiance;
  if (march) radiance = ComputeSkyRadiance(earth, view, sun_local);
  if (read_lut && march) radiance = mix(lut_radiance, radiance, twilight_weight);
#endif
  return StyleSkyRadiance(atm, aoas, radiance, w, sun);
}

#endif  // SKYBAKE_AOAS_GLSL
