// Weather without repetition (shaders/cloud_weather.glsl, clouds.h
// `tiling`) on lavapipe under the validation layer: a 300 km cloud shadow
// map of a cumulus layer has no repeat (its autocorrelation at every shift
// beyond 5 km stays below 0.3) and no lattice (no peak in its power
// spectrum), where the same layer with `tiling = true` has both.
//
// The measures (docs/clouds.md "Weather without repetition"):
// - autocorrelation: of the map less its mean, at shift s, the mean of
//   f(x) f(x + s) over the texels both hold, over the map's variance;
//   shifts whose overlap is at least a quarter of the map (up to 150 km
//   along one axis, 75 km along both), computed through a zero-padded FFT;
// - lattice peak ratio: the periodogram |F(k)|^2 of the map less its mean
//   under a Hann window, each frequency averaged with its 8 neighbours; for
//   each ring of integer radius r (in frequency bins, wavelengths from
//   100 km to 2.4 texels), the ring's maximum over its median; the ratio is
//   the largest over the rings. A field without a lattice has a smooth
//   spectrum (the 3 x 3 mean of exponential periodogram values keeps a ring's
//   maximum within a few times its median); a lattice puts its energy into
//   isolated peaks, orders of magnitude above their ring.
#include <algorithm>
#include <cmath>
#include <complex>
#include <vector>

#include <gtest/gtest.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <glm/glm.hpp>

#include "skybake/gpu/sky_renderer.h"
#include "skybake/input/config.h"
#include "skybake/model/cloud_shadow.h"
#include "skybake/model/clouds.h"
#include "skybake/model/tonemap.h"
#include "skybake/pipeline/pass_plan.h"
#include "test_support.h"

namespace skybake {
namespace {

// The lattice peak ratio's bound. A lattice holds its energy in single
// frequencies, orders of magnitude above their ring (the tiling cumulus
// below: about 25000 at its 30 km tile, about 1800 at its 4 km shape tile).
// A field without one has a ring's maximum within a few times its median
// (the 3 x 3 mean of periodogram values scattered exponentially about the
// spectrum), more on the small rings of the longest wavelengths and where
// the field is not isotropic. Measured 2026-12-07: the non-repeating
// cumulus 8.4 at most (at 17.6 km); a first, weaker warp 11.7, on the 32
// frequencies of the 75 km ring, with a residual 8.9 at its 4 km shape tile.
constexpr double kMaxLatticePeakRatio = 10.0;

// The cumulus of configs/styles/cumulus_noon.toml, draft quality, with
// `tiling` as given.
SkyStyle Cumulus(bool tiling) {
  const std::string toml = std::string(R"(
[quality]
preset = "draft"
[aoas]
seed = 21
[[cloud_layer]]
altitude_m = 1500.0
thickness_m = 1500.0
type = "cumulus"
coverage = 0.45
density_per_m = 0.05
)") + (tiling ? "tiling = true\n" : "");
  ConfigResult r = ParseSkyStyle(toml, "cloud_weather_test.toml");
  EXPECT_TRUE(r.ok()) << (r.errors.empty() ? "" : r.errors[0].Format());
  return PrunedStyle(r.style);
}

std::vector<float> ShadowMap(const SkyStyle& style, int n, double extent_m) {
  SkyRenderer r(testing::Vulkan(), StyledAtmosphere(style.atmosphere, style.aoas), style.quality, style.effects,
                OutputScale(style.output.units), false, ToAoasInputs(style.aoas, OutputScale(OutputUnits::kLuminance)),
                ToCloudInputs(style.clouds, style.aoas.seed, "", 0.0));
  // The Sun overhead: the map is the clouds' own pattern; 8 samples per crossing.
  const CloudShadowSettings s{.enabled = true, .resolution = n, .extent_m = extent_m, .steps = 8};
  return r.RenderCloudShadow(glm::dvec3(0.0, 1.0, 0.0), s);
}

// The map less its mean, as a one-channel float image of edge `size` (the map
// in its top-left corner, zeros around it), times `window` per texel.
OIIO::ImageBuf Centred(const std::vector<float>& map, int n, int size, bool hann) {
  double mean = 0.0;
  for (float v : map) mean += v;
  mean /= double(map.size());
  OIIO::ImageBuf buf(OIIO::ImageSpec(size, size, 1, OIIO::TypeDesc::FLOAT));
  OIIO::ImageBufAlgo::zero(buf);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const double w =
          hann ? (0.5 - 0.5 * std::cos(2.0 * M_PI * (x + 0.5) / n)) * (0.5 - 0.5 * std::cos(2.0 * M_PI * (y + 0.5) / n))
               : 1.0;
      const float v = float((map[size_t(y) * n + x] - mean) * w);
      buf.setpixel(x, y, &v);
    }
  return buf;
}

struct Peak {
  double value = -1.0;
  double shift_km = 0.0;
};

// The largest autocorrelation over shifts longer than `beyond_km` whose
// overlap is at least a quarter of the map.
Peak MaxAutocorrelation(const std::vector<float>& map, int n, double texel_km, double beyond_km) {
  const int size = 2 * n;
  const OIIO::ImageBuf f = OIIO::ImageBufAlgo::fft(Centred(map, n, size, false));
  OIIO::ImageBuf power(OIIO::ImageSpec(size, size, 2, OIIO::TypeDesc::FLOAT));
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      float c[2];
      f.getpixel(x, y, c);
      const float p[2] = {c[0] * c[0] + c[1] * c[1], 0.0f};
      power.setpixel(x, y, p);
    }
  const OIIO::ImageBuf ac = OIIO::ImageBufAlgo::ifft(power);  // unitary: sums scaled alike, the ratio cancels
  float zero = 0.0f;
  ac.getpixel(0, 0, &zero);
  Peak peak;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const int dx = x < n ? x : x - size, dy = y < n ? y : y - size;
      const double overlap = double(n - std::abs(dx)) * double(n - std::abs(dy));
      const double shift_km = texel_km * std::hypot(dx, dy);
      if (overlap < 0.25 * n * n || shift_km <= beyond_km) continue;
      float v = 0.0f;
      ac.getpixel(x, y, &v);
      // Mean over the overlap over the variance (the mean over all n^2).
      const double r = double(v) / overlap / (double(zero) / (double(n) * n));
      if (r > peak.value) peak = {r, shift_km};
    }
  return peak;
}

// The lattice peak ratio (above) and the wavelength of its ring, km.
Peak LatticePeakRatio(const std::vector<float>& map, int n, double texel_km) {
  const OIIO::ImageBuf f = OIIO::ImageBufAlgo::fft(Centred(map, n, n, true));
  std::vector<double> p(size_t(n) * n);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      float c[2];
      f.getpixel(x, y, c);
      p[size_t(y) * n + x] = double(c[0]) * c[0] + double(c[1]) * c[1];
    }
  std::vector<double> smooth(p.size());
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      double s = 0.0;
      for (int j = -1; j <= 1; ++j)
        for (int i = -1; i <= 1; ++i) s += p[size_t((y + j + n) % n) * n + (x + i + n) % n];
      smooth[size_t(y) * n + x] = s / 9.0;
    }
  const int r_min = std::max(3, int(std::ceil(n * texel_km / 100.0))), r_max = int(n / 2.4);
  std::vector<std::vector<double>> rings(size_t(r_max + 1));
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const int kx = x <= n / 2 ? x : x - n, ky = y <= n / 2 ? y : y - n;
      const int r = int(std::lround(std::hypot(kx, ky)));
      if (r >= r_min && r <= r_max) rings[size_t(r)].push_back(smooth[size_t(y) * n + x]);
    }
  Peak peak;
  for (int r = r_min; r <= r_max; ++r) {
    std::vector<double>& ring = rings[size_t(r)];
    std::nth_element(ring.begin(), ring.begin() + ring.size() / 2, ring.end());
    const double median = ring[ring.size() / 2];
    const double ratio = *std::max_element(ring.begin(), ring.end()) / std::max(median, 1e-30);
    if (ratio > peak.value) peak = {ratio, n * texel_km / r};
  }
  return peak;
}

// A 300 km map (512 texels of 586 m) of the cumulus layer: coverage and
// shape repeat nowhere, where the tiling layer repeats at its 30 km weather
// tile (and its 4 km shape tile) and shows the lattice.
TEST(WeatherWithoutRepetition, ShadowMapOf300KmHasNoRepeatAndNoLattice) {
  constexpr int kN = 512;
  constexpr double kExtentKm = 300.0, kTexelKm = kExtentKm / kN;
  const std::vector<float> free_map = ShadowMap(Cumulus(false), kN, kExtentKm * 1e3);
  const std::vector<float> tiled_map = ShadowMap(Cumulus(true), kN, kExtentKm * 1e3);
  const auto [lo, hi] = std::minmax_element(free_map.begin(), free_map.end());
  EXPECT_LT(*lo, 0.2f);  // clouds and gaps: the measures are not of a flat map
  EXPECT_GT(*hi, 0.9f);
  const Peak free_ac = MaxAutocorrelation(free_map, kN, kTexelKm, 5.0);
  const Peak tiled_ac = MaxAutocorrelation(tiled_map, kN, kTexelKm, 5.0);
  const Peak free_peak = LatticePeakRatio(free_map, kN, kTexelKm);
  const Peak tiled_peak = LatticePeakRatio(tiled_map, kN, kTexelKm);
  std::printf("non-repeating: autocorrelation max %.3f at %.1f km, lattice peak ratio %.1f at %.2f km\n", free_ac.value,
              free_ac.shift_km, free_peak.value, free_peak.shift_km);
  std::printf("tiling:        autocorrelation max %.3f at %.1f km, lattice peak ratio %.1f at %.2f km\n",
              tiled_ac.value, tiled_ac.shift_km, tiled_peak.value, tiled_peak.shift_km);
  EXPECT_LT(free_ac.value, 0.3);
  EXPECT_LT(free_peak.value, kMaxLatticePeakRatio);
  // The measures see the repetition they are meant to see.
  EXPECT_GT(tiled_ac.value, 0.9);
  EXPECT_GT(tiled_peak.value, 100.0 * kMaxLatticePeakRatio);
  // For the record: beyond the clouds' own size (5-10 km).
  const Peak free_far = MaxAutocorrelation(free_map, kN, kTexelKm, 15.0);
  std::printf("non-repeating: autocorrelation max %.3f at %.1f km beyond 15 km\n", free_far.value, free_far.shift_km);
  testing::ExpectNoValidationMessages();
}

}  // namespace
}  // namespace skybake
