// How the renderer's three wavelengths (680, 550, 440 nm) become linear
// Rec.709 in cd/m^2, one conversion per light path (docs/colour.md).
//
// Three samples of a spectrum say little about it between them, so every
// conversion assumes a spectral shape. One set of factors for every path
// (Bruneton 2017's sky factors, which assume sky light's shape) gives direct
// sunlight about +17% red. Instead each frame gets:
//   - `direct`: per channel, for direct sunlight and what clouds and the
//     ground scatter of it (the disc, the Sun's light, sunlit clouds, the
//     sunlit ground): the Sun's spectrum through the frame's own atmosphere,
//     integrated over 48 bins (the spectral mode's bins) against the CIE 1931
//     functions, divided by the same light at the three wavelengths. Exact
//     for the disc as the observer sees it.
//   - `sky`: a 3x3 matrix for light the air scatters: fitted, by weighted
//     least squares, to the single-scattered sky of the frame at 48 bins on
//     a probe of 72 directions (the shared GLSL's medium, geometry and phase
//     functions, in double), so that the matrix fits the spectra this
//     frame's sky is made of (reddened by a low Sun, shaped by ozone at
//     twilight).
// docs/colour.md gives the error of each option against the 48-bin spectral
// mode and what it costs.
#pragma once

#include <vector>

#include <glm/vec3.hpp>

#include "skybake/model/atmosphere.h"
#include "skybake/model/spectrum.h"

namespace skybake {

struct OutputConversion {
  Matrix3 sky{};  // rows: output RGB = sky * radiance, for light scattered by the air
  Rgb direct{};   // per channel: output = direct * radiance, for direct sunlight and its scatter by clouds and ground
};

// One conversion for every path: sky = diag(scale), direct = scale (the
// renderer's default; the spectral units' identity).
OutputConversion UniformOutputConversion(const Rgb& scale);

// Bruneton 2017's factors (lm/W per unit radiance at 680/550/440 nm):
// SKY_SPECTRAL_RADIANCE_TO_LUMINANCE, and SUN_SPECTRAL_RADIANCE_TO_LUMINANCE
// for the unattenuated solar spectrum.
Rgb BrunetonSkyFactors();
Rgb BrunetonSunFactors();

// The conversion for a frame of `atmosphere` (the style's, with its effects)
// with the Sun along unit `sun` (+Y up), to linear Rec.709 in cd/m^2. Where
// the frame holds no sunlit air to fit (deep night), the sky matrix is
// Bruneton's sky factors; where no direct sunlight reaches the observer or
// the air above it, `direct` is Bruneton's sun factors.
OutputConversion FrameOutputConversion(const AtmosphereParams& atmosphere, const EffectSettings& effects,
                                       const glm::dvec3& sun);

// The probe's directions for a Sun along `sun`: 9 elevations from 1 to 85
// deg above the horizontal, 8 azimuths from the Sun's over half a turn.
std::vector<glm::dvec3> SkyProbeDirections(const glm::dvec3& sun);

// The sky matrix that maps `samples` (radiance at 680/550/440 nm) onto
// `targets` (linear Rec.709), by least squares with each direction weighted
// by the inverse of its target's luminance. False (and `sky` untouched) when
// fewer than 12 directions are lit or the fit is not finite.
bool FitSkyMatrix(const std::vector<Rgb>& samples, const std::vector<Rgb>& targets, Matrix3& sky);

// The Sun's light at the observer, at normal incidence, through the frame's
// air: `luminance`, linear Rec.709 in cd/m^2 x sr (lux per channel), from
// the 48 bins (so the direct conversion's colour); `radiance`, the same at
// the three wavelengths in W m^-2 nm^-1 (the spectral units). Zero when the
// disc's centre is below the observer's horizon. For a style whose disc is
// not drawn (effects.sun_disc = false): its light stays.
struct SunLight {
  Rgb luminance{};
  Rgb radiance{};
};
SunLight SunLightAtObserver(const AtmosphereParams& atmosphere, const EffectSettings& effects, const glm::dvec3& sun);

}  // namespace skybake
