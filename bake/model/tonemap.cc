#include "skybake/model/tonemap.h"

#include <algorithm>
#include <cmath>

namespace skybake {

double AcesFilmic(double x) {
  const double a = 2.51, b = 0.03, c = 2.43, d = 0.59, e = 0.14;
  return std::clamp((x * (a * x + b)) / (x * (c * x + d) + e), 0.0, 1.0);
}

double SrgbEncode(double v) {
  v = std::clamp(v, 0.0, 1.0);
  return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

double ExposureFromEv100(double ev100) { return 1.0 / (1.2 * std::exp2(ev100)); }

namespace {

// EV100 that maps the log-average luminance of rows [y0, y1) of a latlong
// to the photographic mid grey 0.18; texels brighter than 1e4 times the
// median (the sun disc) are left out of the average.
double MeteredEv100(const std::vector<float>& rgba, int width, int y0, int y1) {
  std::vector<double> luminance;
  for (int y = y0; y < y1; ++y) {
    for (int x = 0; x < width; ++x) {
      const float* p = &rgba[(size_t(y) * width + x) * 4];
      // Rec.709 luminance weights.
      luminance.push_back(0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]);
    }
  }
  if (luminance.empty()) return 0.0;
  std::vector<double> sorted = luminance;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  double median = sorted[sorted.size() / 2];
  double sum_log = 0.0;
  size_t count = 0;
  for (double l : luminance) {
    if (median > 0.0 && l > 1e4 * median) continue;
    sum_log += std::log(std::max(l, 1e-9));
    ++count;
  }
  double average = std::exp(sum_log / double(std::max<size_t>(count, 1)));
  // exposure * average = 0.18  =>  1 / (1.2 * 2^ev) = 0.18 / average
  return std::log2(average / (0.18 * 1.2));
}

// How far above mid grey the lower hemisphere may be exposed: 1 stop (0.36,
// which ACES maps to 0.50, sRGB 0.74), so that it is never near white.
constexpr double kLowerHemisphereStops = 1.0;

}  // namespace

double AutoEv100(const std::vector<float>& rgba, int width, int height) {
  const double sky = MeteredEv100(rgba, width, 0, height / 2);
  if (height / 2 == 0) return sky;
  // What the image shows below the horizon: from high altitude the sky above
  // is near black and the lit planet fills the lower half, which the sky's
  // exposure would make white. At ground level the ground is at most about
  // as bright as the sky and the sky decides alone.
  const double lower = MeteredEv100(rgba, width, height / 2, height) - kLowerHemisphereStops;
  return std::max(sky, lower);
}

std::vector<uint8_t> TonemapToSrgb8(const std::vector<float>& rgba, int width, int height, double exposure) {
  std::vector<uint8_t> out(size_t(width) * height * 3);
  for (size_t i = 0, n = size_t(width) * height; i < n; ++i) {
    for (int c = 0; c < 3; ++c) {
      double v = SrgbEncode(AcesFilmic(rgba[4 * i + c] * exposure));
      out[3 * i + c] = uint8_t(std::lround(v * 255.0));
    }
  }
  return out;
}

}  // namespace skybake
