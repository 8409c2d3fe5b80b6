// The spectral mode's CPU side (spectrum.h): its tables against the shared
// ground truth, the CIE integration against tabulated XYZ of measured
// spectra, white points, colour-space matrices, CIEDE2000 against Sharma's
// published pairs, and the atmosphere at named wavelengths.
#include "skybake/model/spectrum.h"

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "test_support.h"

namespace skybake {
namespace {

// Rows of a CSV file (comment lines skipped, the header row returned first).
std::vector<std::vector<std::string>> ReadCsv(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in) << path << " is missing (shared/groundtruth beside the checkout)";
  std::vector<std::vector<std::string>> rows;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> cells;
    std::stringstream s(line);
    std::string cell;
    while (std::getline(s, cell, ',')) cells.push_back(cell);
    rows.push_back(cells);
  }
  return rows;
}

std::array<double, 3> Xyz(const std::vector<std::array<double, 3>>& weights, const std::vector<double>& radiance) {
  std::array<double, 3> xyz{};
  for (size_t k = 0; k < weights.size(); ++k)
    for (int c = 0; c < 3; ++c) xyz[c] += weights[k][c] * radiance[k];
  return xyz;
}

TEST(SpectrumTest, TablesAreTheSharedGroundTruth) {
  const auto cie = ReadCsv(testing::SharedDir() + "/groundtruth/constants/cie1931_2deg_5nm.csv");
  ASSERT_EQ(cie.size(), 96u);
  for (size_t i = 1; i < cie.size(); ++i) {
    const std::array<double, 3> bar = CieXyzBar(std::stod(cie[i][0]));
    for (int c = 0; c < 3; ++c) EXPECT_EQ(bar[c], std::stod(cie[i][1 + c])) << cie[i][0] << " nm";
  }
  const auto demo = ReadCsv(testing::SharedDir() + "/groundtruth/constants/bruneton2017_demo_spectra.csv");
  ASSERT_EQ(demo.size(), 49u);
  // The default style's values are the table's at 680/550/440 nm, so the
  // atmosphere at any table wavelength is the table's row (in km^-1).
  const AtmosphereParams style;
  for (size_t i = 1; i < demo.size(); ++i) {
    const double l = std::stod(demo[i][0]);
    const AtmosphereParams a = AtmosphereAtWavelengths(style, {l, l, l});
    EXPECT_NEAR(a.solar_irradiance[0], std::stod(demo[i][1]), 2e-4 * std::stod(demo[i][1])) << l;
    EXPECT_NEAR(a.rayleigh_scattering_per_km[0], std::stod(demo[i][2]) * 1e3, 1e-4 * std::stod(demo[i][2]) * 1e3) << l;
    EXPECT_NEAR(a.mie_scattering_per_km[0], std::stod(demo[i][3]) * 1e3, 1e-9) << l;
    EXPECT_NEAR(a.mie_extinction_per_km[0], std::stod(demo[i][4]) * 1e3, 1e-9) << l;
    EXPECT_NEAR(a.ozone_absorption_per_km[0], std::stod(demo[i][6]) * 1e3, 2e-3 * std::stod(demo[i][6]) * 1e3) << l;
  }
}

// The CIE integration against the tabulated XYZ of measured skies:
// photometric.csv holds 683 sum_{360..830 nm} cmf L of each 1 nm Kider
// spectrum (computed apart from skybake); 1 nm bins at the same wavelengths.
TEST(SpectrumTest, CieIntegrationMatchesTabulatedXyzOfMeasuredSpectra) {
  const std::string dir = testing::SharedDir() + "/groundtruth/kider2014/";
  const auto spectra = ReadCsv(dir + "spectral_1nm/2013-05-27___11.45.00.csv");
  const auto photometric = ReadCsv(dir + "photometric.csv");
  ASSERT_GT(spectra.size(), 80u);
  std::map<std::string, std::array<double, 3>> tabulated;  // index -> XYZ
  for (size_t i = 1; i < photometric.size(); ++i)
    if (photometric[i][0] == "2013-05-27___11.45.00")
      tabulated[photometric[i][1]] = {std::stod(photometric[i][5]), std::stod(photometric[i][6]),
                                      std::stod(photometric[i][7])};
  std::vector<double> lambda;
  for (int l = 360; l <= 830; ++l) lambda.push_back(l);
  const auto weights = CieWeights(BinsAt(lambda, 1.0));
  const size_t first = 5 + 10;  // columns: index, zenith, azimuth, grid_i, grid_j, then L_350 ...
  int compared = 0;
  for (size_t row = 1; row < spectra.size(); ++row) {
    if (spectra[row][0] == "0") continue;  // photometric.csv corrects sample 0
    std::vector<double> radiance;
    for (size_t k = 0; k < lambda.size(); ++k) radiance.push_back(std::stod(spectra[row][first + k]));
    const std::array<double, 3> xyz = Xyz(weights, radiance);
    const std::array<double, 3>& want = tabulated.at(spectra[row][0]);
    // The tables' values carry 6 significant digits; the 1 nm bins at the
    // ends hold half a bin of the table (it starts at 360 nm).
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(xyz[c], want[c], 5e-4 * want[c]) << "direction " << spectra[row][0];
    ++compared;
  }
  EXPECT_EQ(compared, 80);
}

// A flat spectrum integrates to the equal-energy white point E (x = y = 1/3):
// the CIE 1931 functions have equal integrals (to the 5 nm table's rounding).
TEST(SpectrumTest, FlatSpectrumIsTheEqualEnergyWhite) {
  for (int n : {4, 8, 16, 48}) {
    const auto xyz = Xyz(CieWeights(WavelengthBins(n)), std::vector<double>(n, 1.0));
    const double sum = xyz[0] + xyz[1] + xyz[2];
    EXPECT_NEAR(xyz[0] / sum, 1.0 / 3.0, 3e-4) << n << " bins";
    EXPECT_NEAR(xyz[1] / sum, 1.0 / 3.0, 3e-4) << n << " bins";
    // 683 lm/W x the integral of ybar (106.86 nm for the 1931 functions).
    EXPECT_NEAR(xyz[1], 683.0 * 106.857, 683.0 * 0.05) << n << " bins";
  }
}

TEST(SpectrumTest, BinsCoverTheRangeAndLandOnTheTablesAt48) {
  const SpectralBins b = WavelengthBins(48);
  ASSERT_EQ(b.count(), 48);
  for (int k = 0; k < 48; ++k) EXPECT_DOUBLE_EQ(b.centre_nm[k], 360.0 + 10.0 * k);
  const SpectralBins four = WavelengthBins(4);
  EXPECT_DOUBLE_EQ(four.lower_nm[0], 355.0);
  EXPECT_DOUBLE_EQ(four.upper_nm[3], 835.0);
  EXPECT_DOUBLE_EQ(four.centre_nm[1], 535.0);
}

// The groups' shares of a change of colour (the colour principles under
// cloud layers, spectral_sky.h) combine back to that change: sum_g to_rgb[g]
// share[g] is the identity. The padding channel of the last group gets
// nothing, and a group the eye barely sees (48 bins: 800-830 nm) gets far
// less than the one at the middle of the spectrum.
TEST(SpectrumTest, ColourChangeSharesCombineToTheChange) {
  for (int n : {4, 8, 16, 47, 48}) {
    const std::vector<SpectralGroup> groups = SpectralGroups(AtmosphereParams(), WavelengthBins(n));
    const std::vector<Matrix3> shares = ColourChangeShares(groups);
    ASSERT_EQ(shares.size(), groups.size());
    Matrix3 sum{};
    for (size_t g = 0; g < groups.size(); ++g)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          for (int k = 0; k < 3; ++k) sum[i][j] += groups[g].to_rgb[i][k] * shares[g][k][j];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) EXPECT_NEAR(sum[i][j], i == j ? 1.0 : 0.0, 1e-12) << n << " bins, " << i << j;
    for (size_t g = 0; g < groups.size(); ++g)
      for (int c = 0; c < 3; ++c) {
        if (groups[g].bin[c] >= 0) continue;
        for (int j = 0; j < 3; ++j) EXPECT_EQ(shares[g][c][j], 0.0) << n << " bins, padding of group " << g;
      }
  }
  const std::vector<Matrix3> shares = ColourChangeShares(SpectralGroups(AtmosphereParams(), WavelengthBins(48)));
  auto norm = [](const Matrix3& m) {
    double s = 0.0;
    for (const auto& row : m)
      for (double x : row) s += x * x;
    return std::sqrt(s);
  };
  EXPECT_LT(norm(shares.back()), 1e-3 * norm(shares[7])) << "800-830 nm against 570-590 nm";
}

TEST(SpectrumTest, ColourSpaceMatrices) {
  // XYZ -> linear sRGB of IEC 61966-2-1 (the matrix Bruneton 2017 uses).
  const Matrix3 m = XyzToRgb(ColorSpace::kRec709);
  const double iec[3][3] = {{3.2406, -1.5372, -0.4986}, {-0.9689, 1.8758, 0.0415}, {0.0557, -0.2040, 1.0570}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(m[i][j], iec[i][j], 6e-4) << i << j;
  // Rec.709 -> ACEScg with Bradford adaptation (the published matrix, e.g.
  // the ACES documentation's sRGB to ACEScg: 0.6131 0.3395 0.0474 ...).
  const Matrix3 a = Rec709ToAcesCg();
  const double aces[3][3] = {{0.6131, 0.3395, 0.0474}, {0.0702, 0.9164, 0.0135}, {0.0206, 0.1096, 0.8698}};
  for (int i = 0; i < 3; ++i) {
    double row = 0.0;
    for (int j = 0; j < 3; ++j) {
      EXPECT_NEAR(a[i][j], aces[i][j], 2e-4) << i << j;
      row += a[i][j];
    }
    EXPECT_NEAR(row, 1.0, 1e-12) << "white stays white";
  }
  EXPECT_NEAR(Rec709Luminance({1.0, 1.0, 1.0}), 1.0, 1e-12);
}

TEST(SpectrumTest, DeltaE2000MatchesSharmaWuDalal) {
  // Sharma, Wu, Dalal 2005, Table 1 (the published test pairs).
  struct Pair {
    std::array<double, 3> a, b;
    double de;
  };
  const Pair pairs[] = {
      {{50.0, 2.6772, -79.7751}, {50.0, 0.0, -82.7485}, 2.0425},
      {{50.0, 3.1571, -77.2803}, {50.0, 0.0, -82.7485}, 2.8615},
      {{50.0, 2.8361, -74.0200}, {50.0, 0.0, -82.7485}, 3.4412},
      {{50.0, -1.3802, -84.2814}, {50.0, 0.0, -82.7485}, 1.0000},
      {{50.0, 0.0, 0.0}, {50.0, -1.0, 2.0}, 2.3669},
      {{50.0, 2.49, -0.001}, {50.0, -2.49, 0.0009}, 7.1792},
      {{50.0, 2.5, 0.0}, {73.0, 25.0, -18.0}, 27.1492},
      {{60.2574, -34.0099, 36.2677}, {60.4626, -34.1751, 39.4387}, 1.2644},
      {{22.7233, 20.0904, -46.6940}, {23.0331, 14.9730, -42.5619}, 2.0373},
      {{2.0776, 0.0795, -1.1350}, {0.9033, -0.0636, -0.5514}, 0.9082},
  };
  for (const Pair& p : pairs) {
    EXPECT_NEAR(DeltaE2000(p.a, p.b), p.de, 5e-5) << p.a[0] << " " << p.a[1] << " " << p.a[2];
    EXPECT_NEAR(DeltaE2000(p.b, p.a), p.de, 5e-5);
  }
  EXPECT_NEAR(DeltaE2000(Srgb8ToLab({200, 100, 50}), Srgb8ToLab({200, 100, 50})), 0.0, 1e-12);
  const auto white = Srgb8ToLab({255, 255, 255});
  EXPECT_NEAR(white[0], 100.0, 1e-9);
  EXPECT_NEAR(white[1], 0.0, 1e-9);
}

// At 680/550/440 nm the atmosphere is the style's, whatever the style: the
// spectral mode at those wavelengths is the three-channel renderer.
TEST(SpectrumTest, NamedWavelengthsKeepTheStylesCoefficients) {
  AtmosphereParams style;
  style.rayleigh_scattering_per_km = {4e-3, 11e-3, 40e-3};
  style.mie_scattering_per_km = {8e-3, 7e-3, 6e-3};
  style.mie_extinction_per_km = {9e-3, 8e-3, 7e-3};
  style.ozone_absorption_per_km = {0.5e-3, 2e-3, 0.1e-3};
  style.solar_irradiance = {1.0, 1.0, 1.0};
  style.ground_albedo = {0.3, 0.2, 0.1};
  const AtmosphereParams a = AtmosphereAtWavelengths(style, {680.0, 550.0, 440.0});
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(a.rayleigh_scattering_per_km[c], style.rayleigh_scattering_per_km[c], 1e-15);
    EXPECT_NEAR(a.mie_scattering_per_km[c], style.mie_scattering_per_km[c], 1e-15);
    EXPECT_NEAR(a.mie_extinction_per_km[c], style.mie_extinction_per_km[c], 1e-15);
    EXPECT_NEAR(a.ozone_absorption_per_km[c], style.ozone_absorption_per_km[c], 1e-15);
    EXPECT_NEAR(a.solar_irradiance[c], 1.0, 1e-14);
    EXPECT_DOUBLE_EQ(a.ground_albedo[c], style.ground_albedo[c]);
  }
  // Doubling Mie doubles it at every wavelength.
  AtmosphereParams doubled;
  doubled.mie_scattering_per_km = {7.992e-3, 7.992e-3, 7.992e-3};
  EXPECT_NEAR(AtmosphereAtWavelengths(doubled, {400.0, 500.0, 800.0}).mie_scattering_per_km[2], 7.992e-3, 1e-12);
  // A bin's coefficients are the tables' means over it: 48 bins take the rows
  // as they are; the second of 4 bins, 475..595 nm, the mean of the 12 rows
  // 480..590 nm.
  const auto demo = ReadCsv(testing::SharedDir() + "/groundtruth/constants/bruneton2017_demo_spectra.csv");
  ASSERT_GT(demo.size(), 48u) << "the 48 rows of the demo spectra";
  const std::vector<SpectralGroup> g48 = SpectralGroups(AtmosphereParams(), WavelengthBins(48));
  for (int k = 0; k < 48; ++k)
    EXPECT_NEAR(g48[k / 3].atmosphere.solar_irradiance[k % 3], std::stod(demo[1 + k][1]), 2e-4) << k;
  double mean = 0.0;
  for (int row = 13; row <= 24; ++row) mean += std::stod(demo[row][1]) / 12.0;  // 480..590 nm
  EXPECT_NEAR(SpectralGroups(AtmosphereParams(), WavelengthBins(4))[0].atmosphere.solar_irradiance[1], mean, 2e-4);
  // Groups of three; the last one padded.
  const std::vector<SpectralGroup> groups = SpectralGroups(AtmosphereParams(), WavelengthBins(4));
  ASSERT_EQ(groups.size(), 2u);
  EXPECT_EQ(groups[1].bin[0], 3);
  EXPECT_EQ(groups[1].bin[1], -1);
  EXPECT_EQ(groups[1].to_rgb[0][1], 0.0);
}

}  // namespace
}  // namespace skybake
