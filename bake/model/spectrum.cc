#include "skybake/model/spectrum.h"

#include <algorithm>
#include <cmath>

#include "spectral_tables.h"

namespace skybake {
namespace {

using spectral_tables::kAtmosphere;
using spectral_tables::kAtmosphereRows;
using spectral_tables::kCie1931;
using spectral_tables::kCieRows;

// Linear interpolation in a table of rows sorted by lambda_nm; held beyond
// its ends when `hold`, else 0 there.
template <typename Row, typename Field>
double Interpolate(const Row* rows, int count, double lambda_nm, Field field, bool hold) {
  if (lambda_nm <= rows[0].lambda_nm) return hold || lambda_nm == rows[0].lambda_nm ? field(rows[0]) : 0.0;
  if (lambda_nm >= rows[count - 1].lambda_nm)
    return hold || lambda_nm == rows[count - 1].lambda_nm ? field(rows[count - 1]) : 0.0;
  int i = 0;
  while (rows[i + 1].lambda_nm < lambda_nm) ++i;
  const double t = (lambda_nm - rows[i].lambda_nm) / (rows[i + 1].lambda_nm - rows[i].lambda_nm);
  return field(rows[i]) * (1.0 - t) + field(rows[i + 1]) * t;
}

double Table(double lambda_nm, double spectral_tables::AtmosphereRow::*field) {
  return Interpolate(
      kAtmosphere, kAtmosphereRows, lambda_nm, [field](const auto& r) { return r.*field; }, true);
}

// The mean over [a, b] of a column read as the 10 nm bins it tabulates (the
// sun and ozone columns are 10 nm bin means): row i over lambda_i -+ 5 nm,
// the end rows held beyond the table.
double TableMean(double a, double b, double spectral_tables::AtmosphereRow::*field) {
  double sum = 0.0;
  for (int i = 0; i < kAtmosphereRows; ++i) {
    const double lo = i == 0 ? -1e9 : kAtmosphere[i].lambda_nm - 5.0;
    const double hi = i == kAtmosphereRows - 1 ? 1e9 : kAtmosphere[i].lambda_nm + 5.0;
    const double overlap = std::min(b, hi) - std::max(a, lo);
    if (overlap > 0.0) sum += overlap * kAtmosphere[i].*field;
  }
  return sum / (b - a);
}

// A style triplet (680, 550, 440 nm) at any wavelength: linear between the
// three, held beyond them.
double TripletAt(const Rgb& rgb, double lambda_nm) {
  struct Knot {
    double lambda_nm, value;
  };
  const Knot knots[3] = {{440.0, rgb[2]}, {550.0, rgb[1]}, {680.0, rgb[0]}};
  return Interpolate(
      knots, 3, lambda_nm, [](const Knot& k) { return k.value; }, true);
}

// A style coefficient at a wavelength (width 0: linear in the table) or over
// a bin of `width_nm` about it (the mean of the table's 10 nm bins), times the
// ratio of the style's to the table's at 680/550/440 nm, interpolated.
double ScaledAt(const Rgb& style, double spectral_tables::AtmosphereRow::*field, double lambda_nm, double width_nm) {
  Rgb ratio{};
  const double named[3] = {680.0, 550.0, 440.0};
  for (int c = 0; c < 3; ++c) {
    const double table = Table(named[c], field);
    ratio[c] = table > 0.0 ? style[c] / table : 1.0;
  }
  const double table = width_nm > 0.0 ? TableMean(lambda_nm - 0.5 * width_nm, lambda_nm + 0.5 * width_nm, field)
                                      : Table(lambda_nm, field);
  return table * TripletAt(ratio, lambda_nm);
}

std::array<double, 3> XyzOfChromaticity(const std::array<double, 2>& xy) {
  return {xy[0] / xy[1], 1.0, (1.0 - xy[0] - xy[1]) / xy[1]};
}

// Linear RGB to XYZ from the primaries and white point (SMPTE RP 177), white
// of luminance 1.
Matrix3 RgbToXyz(ColorSpace space) {
  if (space == ColorSpace::kXyz) return {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};  // its blue primary has y = 0
  const auto c = Chromaticities(space);
  Matrix3 p{};
  for (int primary = 0; primary < 3; ++primary) {
    const std::array<double, 3> xyz = XyzOfChromaticity(c[primary]);
    for (int row = 0; row < 3; ++row) p[row][primary] = xyz[row];
  }
  const std::array<double, 3> s = Apply(Inverse(p), XyzOfChromaticity(c[3]));
  for (int row = 0; row < 3; ++row)
    for (int primary = 0; primary < 3; ++primary) p[row][primary] *= s[primary];
  return p;
}

}  // namespace

Matrix3 Multiply(const Matrix3& a, const Matrix3& b) {
  Matrix3 m{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) m[i][j] += a[i][k] * b[k][j];
  return m;
}

Matrix3 Inverse(const Matrix3& m) {
  const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                     m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                     m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  Matrix3 r{};
  r[0][0] = (m[1][1] * m[2][2] - m[1][2] * m[2][1]) / det;
  r[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) / det;
  r[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) / det;
  r[1][0] = (m[1][2] * m[2][0] - m[1][0] * m[2][2]) / det;
  r[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) / det;
  r[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) / det;
  r[2][0] = (m[1][0] * m[2][1] - m[1][1] * m[2][0]) / det;
  r[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) / det;
  r[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) / det;
  return r;
}

std::array<double, 3> Apply(const Matrix3& m, const std::array<double, 3>& v) {
  return {m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2], m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
          m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2]};
}

SpectralBins WavelengthBins(int count) {
  SpectralBins bins;
  const double width = (kSpectralUpperNm - kSpectralLowerNm) / count;
  for (int k = 0; k < count; ++k) {
    bins.lower_nm.push_back(kSpectralLowerNm + k * width);
    bins.upper_nm.push_back(kSpectralLowerNm + (k + 1) * width);
    bins.centre_nm.push_back(kSpectralLowerNm + (k + 0.5) * width);
  }
  return bins;
}

SpectralBins BinsAt(const std::vector<double>& centre_nm, double width_nm) {
  SpectralBins bins;
  for (double c : centre_nm) {
    bins.centre_nm.push_back(c);
    bins.lower_nm.push_back(c - 0.5 * width_nm);
    bins.upper_nm.push_back(c + 0.5 * width_nm);
  }
  return bins;
}

std::array<double, 3> CieXyzBar(double lambda_nm) {
  return {Interpolate(
              kCie1931, kCieRows, lambda_nm, [](const auto& r) { return r.xbar; }, false),
          Interpolate(
              kCie1931, kCieRows, lambda_nm, [](const auto& r) { return r.ybar; }, false),
          Interpolate(
              kCie1931, kCieRows, lambda_nm, [](const auto& r) { return r.zbar; }, false)};
}

std::vector<std::array<double, 3>> CieWeights(const SpectralBins& bins) {
  std::vector<std::array<double, 3>> weights;
  for (int k = 0; k < bins.count(); ++k) {
    std::array<double, 3> w{};
    // The trapezoid rule is exact on each piece of the piecewise-linear table.
    for (int i = 0; i + 1 < kCieRows; ++i) {
      const double a = std::max(bins.lower_nm[k], kCie1931[i].lambda_nm);
      const double b = std::min(bins.upper_nm[k], kCie1931[i + 1].lambda_nm);
      if (!(b > a)) continue;
      const std::array<double, 3> fa = CieXyzBar(a), fb = CieXyzBar(b);
      for (int c = 0; c < 3; ++c) w[c] += 0.5 * (fa[c] + fb[c]) * (b - a);
    }
    for (double& v : w) v *= kLumensPerWatt;
    weights.push_back(w);
  }
  return weights;
}

std::array<std::array<double, 2>, 4> Chromaticities(ColorSpace space) {
  switch (space) {
    case ColorSpace::kAcesCg:  // AP1 primaries, ACES white (SMPTE ST 2065-1, S-2014-004)
      return {{{0.713, 0.293}, {0.165, 0.830}, {0.128, 0.044}, {0.32168, 0.33767}}};
    case ColorSpace::kAces2065:  // AP0 primaries, ACES white (SMPTE ST 2065-1)
      return {{{0.7347, 0.2653}, {0.0, 1.0}, {0.0001, -0.0770}, {0.32168, 0.33767}}};
    case ColorSpace::kRec2020:  // ITU-R BT.2020, D65
      return {{{0.708, 0.292}, {0.170, 0.797}, {0.131, 0.046}, {0.3127, 0.3290}}};
    case ColorSpace::kXyz:  // OpenEXR's chromaticities of XYZ data (ImfChromaticities.h)
      return {{{1.0, 0.0}, {0.0, 1.0}, {0.0, 0.0}, {1.0 / 3.0, 1.0 / 3.0}}};
    case ColorSpace::kRec709:
      break;
  }
  return {{{0.64, 0.33}, {0.30, 0.60}, {0.15, 0.06}, {0.3127, 0.3290}}};  // ITU-R BT.709, D65
}

Matrix3 XyzToRgb(ColorSpace space) { return Inverse(RgbToXyz(space)); }

Matrix3 Rec709To(ColorSpace space) {
  const Matrix3 to_xyz = RgbToXyz(ColorSpace::kRec709);
  if (space == ColorSpace::kRec709) return {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  if (space == ColorSpace::kXyz) return to_xyz;  // the light's XYZ, D65 white as measured
  // Bradford cone response (Lam 1985), the von Kries scaling between whites.
  const Matrix3 bradford = {{{0.8951, 0.2664, -0.1614}, {-0.7502, 1.7135, 0.0367}, {0.0389, -0.0685, 1.0296}}};
  const std::array<double, 3> from = Apply(bradford, XyzOfChromaticity(Chromaticities(ColorSpace::kRec709)[3]));
  const std::array<double, 3> to = Apply(bradford, XyzOfChromaticity(Chromaticities(space)[3]));
  Matrix3 scale{};
  for (int i = 0; i < 3; ++i) scale[i][i] = to[i] / from[i];
  const Matrix3 adapt = Multiply(Inverse(bradford), Multiply(scale, bradford));
  return Multiply(XyzToRgb(space), Multiply(adapt, to_xyz));
}

Matrix3 Rec709ToAcesCg() { return Rec709To(ColorSpace::kAcesCg); }

const std::vector<NamedColorSpace>& BuiltinColorSpaces() {
  static const std::vector<NamedColorSpace> spaces = {
      {"rec709", ColorSpace::kRec709, "linear Rec.709 (sRGB primaries, D65 white)"},
      {"acescg", ColorSpace::kAcesCg, "linear ACEScg (AP1 primaries, ACES white)"},
      {"aces2065-1", ColorSpace::kAces2065, "linear ACES2065-1 (AP0 primaries, ACES white)"},
      {"rec2020", ColorSpace::kRec2020, "linear Rec.2020 (BT.2020 primaries, D65 white)"},
      {"xyz", ColorSpace::kXyz, "CIE 1931 XYZ (D65-referred, no adaptation)"},
  };
  return spaces;
}

OutputColorSpace BuiltinOutputColorSpace(ColorSpace space) {
  OutputColorSpace o;
  for (const NamedColorSpace& n : BuiltinColorSpaces())
    if (n.space == space) {
      o.name = n.name;
      o.description = n.description;
    }
  o.chromaticities = Chromaticities(space);
  if (space != ColorSpace::kRec709) o.from_rec709 = Rec709To(space);
  return o;
}

std::array<double, 2> ChromaticityOf(const std::array<double, 3>& xyz) {
  const double sum = xyz[0] + xyz[1] + xyz[2];
  return {xyz[0] / sum, xyz[1] / sum};
}

AtmosphereParams AtmosphereAtWavelengths(const AtmosphereParams& style, const std::array<double, 3>& lambda_nm,
                                         const std::array<double, 3>& width_nm) {
  using Row = spectral_tables::AtmosphereRow;
  AtmosphereParams a = style;
  for (int c = 0; c < 3; ++c) {
    const double l = lambda_nm[c], w = width_nm[c];
    a.rayleigh_scattering_per_km[c] = ScaledAt(style.rayleigh_scattering_per_km, &Row::rayleigh_per_km, l, w);
    a.mie_scattering_per_km[c] = ScaledAt(style.mie_scattering_per_km, &Row::mie_scattering_per_km, l, w);
    a.mie_extinction_per_km[c] = ScaledAt(style.mie_extinction_per_km, &Row::mie_extinction_per_km, l, w);
    a.ozone_absorption_per_km[c] = ScaledAt(style.ozone_absorption_per_km, &Row::ozone_per_km, l, w);
    a.solar_irradiance[c] = ScaledAt(style.solar_irradiance, &Row::solar_irradiance, l, w);
    a.ground_albedo[c] = TripletAt(style.ground_albedo, l);
  }
  return a;
}

std::vector<SpectralGroup> SpectralGroups(const AtmosphereParams& style, const SpectralBins& bins) {
  const std::vector<std::array<double, 3>> weights = CieWeights(bins);
  const Matrix3 to_rgb = XyzToRgb(ColorSpace::kRec709);
  std::vector<SpectralGroup> groups;
  for (int first = 0; first < bins.count(); first += 3) {
    SpectralGroup g;
    std::array<double, 3> width{};
    for (int c = 0; c < 3; ++c) {
      const int k = first + c;
      g.bin[c] = k < bins.count() ? k : -1;
      const int sampled = std::min(k, bins.count() - 1);
      g.lambda_nm[c] = bins.centre_nm[sampled];
      width[c] = bins.upper_nm[sampled] - bins.lower_nm[sampled];
      if (g.bin[c] < 0) continue;
      const std::array<double, 3> rgb = Apply(to_rgb, weights[k]);
      for (int row = 0; row < 3; ++row) g.to_rgb[row][c] = rgb[row];
    }
    g.atmosphere = AtmosphereAtWavelengths(style, g.lambda_nm, width);
    groups.push_back(g);
  }
  return groups;
}

std::vector<Matrix3> ColourChangeShares(const std::vector<SpectralGroup>& groups) {
  auto transpose = [](const Matrix3& m) {
    Matrix3 t{};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) t[i][j] = m[j][i];
    return t;
  };
  Matrix3 gram{};
  for (const SpectralGroup& g : groups) {
    const Matrix3 p = Multiply(g.to_rgb, transpose(g.to_rgb));
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) gram[i][j] += p[i][j];
  }
  const Matrix3 inverse = Inverse(gram);
  std::vector<Matrix3> shares;
  for (const SpectralGroup& g : groups) shares.push_back(Multiply(transpose(g.to_rgb), inverse));
  return shares;
}

double Rec709Luminance(const std::array<double, 3>& rgb) {
  const Matrix3 m = RgbToXyz(ColorSpace::kRec709);
  return m[1][0] * rgb[0] + m[1][1] * rgb[1] + m[1][2] * rgb[2];
}

std::array<double, 3> XyzToLab(const std::array<double, 3>& xyz, const std::array<double, 3>& white) {
  auto f = [](double t) {
    constexpr double d = 6.0 / 29.0;
    return t > d * d * d ? std::cbrt(t) : t / (3.0 * d * d) + 4.0 / 29.0;
  };
  const double fx = f(xyz[0] / white[0]), fy = f(xyz[1] / white[1]), fz = f(xyz[2] / white[2]);
  return {116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)};
}

double DeltaE2000(const std::array<double, 3>& lab1, const std::array<double, 3>& lab2) {
  // Sharma, Wu, Dalal 2005, "The CIEDE2000 color-difference formula:
  // implementation notes", equations (1)-(17), kL = kC = kH = 1.
  constexpr double kPi = 3.14159265358979323846;
  auto deg = [](double rad) { return rad * 180.0 / kPi; };
  auto rad = [](double d) { return d * kPi / 180.0; };
  const double c1 = std::hypot(lab1[1], lab1[2]), c2 = std::hypot(lab2[1], lab2[2]);
  const double c_mean7 = std::pow(0.5 * (c1 + c2), 7.0);
  const double g = 0.5 * (1.0 - std::sqrt(c_mean7 / (c_mean7 + std::pow(25.0, 7.0))));
  const double a1 = (1.0 + g) * lab1[1], a2 = (1.0 + g) * lab2[1];
  const double cp1 = std::hypot(a1, lab1[2]), cp2 = std::hypot(a2, lab2[2]);
  auto hue = [&](double a, double b) {
    if (a == 0.0 && b == 0.0) return 0.0;
    double h = deg(std::atan2(b, a));
    return h < 0.0 ? h + 360.0 : h;
  };
  const double h1 = hue(a1, lab1[2]), h2 = hue(a2, lab2[2]);
  const double dl = lab2[0] - lab1[0], dc = cp2 - cp1;
  double dh = 0.0;
  if (cp1 * cp2 != 0.0) {
    dh = h2 - h1;
    if (dh > 180.0) dh -= 360.0;
    else if (dh < -180.0) dh += 360.0;
  }
  const double dH = 2.0 * std::sqrt(cp1 * cp2) * std::sin(rad(dh) / 2.0);
  const double l_mean = 0.5 * (lab1[0] + lab2[0]), cp_mean = 0.5 * (cp1 + cp2);
  double h_mean = h1 + h2;
  if (cp1 * cp2 != 0.0) {
    if (std::abs(h1 - h2) <= 180.0) h_mean = 0.5 * (h1 + h2);
    else h_mean = h1 + h2 < 360.0 ? 0.5 * (h1 + h2 + 360.0) : 0.5 * (h1 + h2 - 360.0);
  }
  const double t = 1.0 - 0.17 * std::cos(rad(h_mean - 30.0)) + 0.24 * std::cos(rad(2.0 * h_mean)) +
                   0.32 * std::cos(rad(3.0 * h_mean + 6.0)) - 0.20 * std::cos(rad(4.0 * h_mean - 63.0));
  const double d_theta = 30.0 * std::exp(-std::pow((h_mean - 275.0) / 25.0, 2.0));
  const double cp_mean7 = std::pow(cp_mean, 7.0);
  const double rc = 2.0 * std::sqrt(cp_mean7 / (cp_mean7 + std::pow(25.0, 7.0)));
  const double sl =
      1.0 + 0.015 * (l_mean - 50.0) * (l_mean - 50.0) / std::sqrt(20.0 + (l_mean - 50.0) * (l_mean - 50.0));
  const double sc = 1.0 + 0.045 * cp_mean, sh = 1.0 + 0.015 * cp_mean * t;
  const double rt = -std::sin(rad(2.0 * d_theta)) * rc;
  const double x = dl / sl, y = dc / sc, z = dH / sh;
  return std::sqrt(x * x + y * y + z * z + rt * y * z);
}

std::array<double, 3> Srgb8ToLab(const std::array<unsigned char, 3>& srgb) {
  std::array<double, 3> linear{};
  for (int c = 0; c < 3; ++c) {
    const double v = srgb[c] / 255.0;
    linear[c] = v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
  }
  return XyzToLab(Apply(RgbToXyz(ColorSpace::kRec709), linear),
                  XyzOfChromaticity(Chromaticities(ColorSpace::kRec709)[3]));
}

}  // namespace skybake
