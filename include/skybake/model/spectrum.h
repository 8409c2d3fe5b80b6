// The spectral mode: the sky rendered at N wavelength bins instead of the
// three wavelengths 680/550/440 nm, and integrated against the CIE 1931
// 2-degree colour matching functions to XYZ, then to linear Rec.709 (or
// ACEScg) in cd/m^2.
//
// Bins: N equal bins over 355..835 nm, so that Bruneton's 48 wavelengths
// 360, 370, ..., 830 nm are the centres of 48 bins. Each bin is one
// wavelength of the renderer: its coefficients and solar irradiance are the
// tables' means over the bin, its colour the CIE functions' integral over it.
// The atmosphere at a wavelength comes from the tabulated spectra of
// Bruneton 2017's demo (spectral_tables.cc: ASTM G-173 sun, lambda^-4
// Rayleigh, Angstrom-0 Mie, IUP Bremen ozone), scaled so that the style's
// three-wavelength values are kept: at 680, 550 and 440 nm each coefficient
// is the style's; between them the ratio style / table is interpolated
// linearly in wavelength, beyond them it is held. The default style's
// coefficients are the table's at those wavelengths, so the ratios are 1.
// The renderer integrates three wavelengths at a time (its RGB channels):
// the bins are rendered in groups of three, each group an atmosphere of its own.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "skybake/model/atmosphere.h"

namespace skybake {

constexpr int kRgbWavelengths = 3;  // quality.wavelengths = 3: the 680/550/440 nm path
constexpr int kMinWavelengthBins = 4;
constexpr int kMaxWavelengthBins = 48;  // the tables' 10 nm spacing
constexpr double kSpectralLowerNm = 355.0;
constexpr double kSpectralUpperNm = 835.0;
constexpr double kLumensPerWatt = 683.0;  // maximum luminous efficacy (CIE)

// Wavelength bins, each [lower_nm, upper_nm) sampled at centre_nm.
struct SpectralBins {
  std::vector<double> centre_nm, lower_nm, upper_nm;
  int count() const { return int(centre_nm.size()); }
};

// `count` equal bins over 355..835 nm.
SpectralBins WavelengthBins(int count);

// Bins centred on given wavelengths with the given widths (nm), for tests and
// studies (named wavelengths, 1 nm measurements).
SpectralBins BinsAt(const std::vector<double>& centre_nm, double width_nm);

// The CIE 1931 2-degree matching functions at a wavelength (linear between
// the 5 nm table's rows, 0 outside 360..830 nm).
std::array<double, 3> CieXyzBar(double lambda_nm);

// 683 lm/W times the integral of each matching function over each bin
// (exact for the piecewise-linear table): XYZ in cd/m^2 of a spectrum that is
// L_k W m^-2 sr^-1 nm^-1 across bin k is sum_k weight[k] * L_k.
std::vector<std::array<double, 3>> CieWeights(const SpectralBins& bins);

// Linear RGB colour spaces of the output, built in: linear Rec.709 (sRGB
// primaries, D65), ACEScg (AP1, ACES white), ACES2065-1 (AP0, ACES white),
// linear Rec.2020 (D65) and CIE XYZ (D65-referred: the XYZ of the light as
// measured, no adaptation; OpenEXR's XYZ chromaticities, white (1/3, 1/3)).
enum class ColorSpace { kRec709, kAcesCg, kAces2065, kRec2020, kXyz };

// CIE xy chromaticities of a colour space's primaries and white point:
// red, green, blue, white (the EXR `chromaticities` attribute).
std::array<std::array<double, 2>, 4> Chromaticities(ColorSpace space);

using Matrix3 = std::array<std::array<double, 3>, 3>;  // rows
// 3x3 matrix products, inverse and application to a vector.
Matrix3 Multiply(const Matrix3& a, const Matrix3& b);
Matrix3 Inverse(const Matrix3& m);
std::array<double, 3> Apply(const Matrix3& m, const std::array<double, 3>& v);

// XYZ (the space's own white) to linear RGB of `space`.
Matrix3 XyzToRgb(ColorSpace space);
// Linear Rec.709 to linear `space`: Rec.709 -> XYZ, Bradford adaptation
// from D65 to the space's white (none for CIE XYZ), XYZ -> the space. In an
// RGB space white maps to white.
Matrix3 Rec709To(ColorSpace space);
Matrix3 Rec709ToAcesCg();  // Rec709To(ColorSpace::kAcesCg)

// The colour space of the output maps: its name (output.color_space: a
// built-in name or a colour space of an OpenColorIO config), a description
// for the files' units, the matrix from the renderer's linear Rec.709 and
// its primaries and white (the EXR `chromaticities`).
struct OutputColorSpace {
  std::string name = "rec709";
  std::string description = "linear Rec.709 (sRGB primaries, D65 white)";
  Matrix3 from_rec709 = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  std::array<std::array<double, 2>, 4> chromaticities = {{{0.64, 0.33}, {0.30, 0.60}, {0.15, 0.06}, {0.3127, 0.3290}}};
  bool IsRec709() const { return name == "rec709"; }
};
// The built-in spaces by name, in the order the docs list them.
struct NamedColorSpace {
  const char* name;
  ColorSpace space;
  const char* description;
};
const std::vector<NamedColorSpace>& BuiltinColorSpaces();
OutputColorSpace BuiltinOutputColorSpace(ColorSpace space);
// XYZ to the chromaticity xy of a colour (Y > 0).
std::array<double, 2> ChromaticityOf(const std::array<double, 3>& xyz);

// The atmosphere at three wavelengths (one renderer group): the style's
// atmosphere with every spectral coefficient, the albedo and the solar
// irradiance taken at `lambda_nm` as the header explains; with a width, each
// coefficient is the table's mean over that bin (its columns read as the
// 10 nm bins they tabulate: 48 bins take the rows as they are), else the table
// interpolated linearly at the wavelength.
AtmosphereParams AtmosphereAtWavelengths(const AtmosphereParams& style, const std::array<double, 3>& lambda_nm,
                                         const std::array<double, 3>& width_nm = {0.0, 0.0, 0.0});

// The bins in groups of three, each bin's coefficients its mean over the
// bin (AtmosphereAtWavelengths); the last group repeats its last wavelength
// (with weight 0) when N is not a multiple of three.
struct SpectralGroup {
  std::array<double, 3> lambda_nm{};
  std::array<int, 3> bin{};  // the bin of each channel; -1: padding
  AtmosphereParams atmosphere;
  // Rec.709 cd/m^2 = to_rgb * (radiance of the group's three channels).
  Matrix3 to_rgb{};
};
std::vector<SpectralGroup> SpectralGroups(const AtmosphereParams& style, const SpectralBins& bins);

// How the spectral mode hands a change of the combined colour back to the
// groups (SpectralSky, the colour principles under cloud layers): a change
// R of linear Rec.709 (cd/m^2) becomes the change share[g] * R of group g's
// radiance, and sum_g to_rgb[g] * share[g] is the identity, so the groups'
// changes combine to R. The split is the least-squares one (the smallest
// sum of squared radiance changes): share[g] = to_rgb[g]^T (sum_h to_rgb[h]
// to_rgb[h]^T)^-1, which gives little to the groups whose bins the eye
// barely sees (a group's own to_rgb, near singular there, is never inverted)
// and nothing to a group's padding channel.
std::vector<Matrix3> ColourChangeShares(const std::vector<SpectralGroup>& groups);

// Rec.709 luminance (cd/m^2) of linear Rec.709.
double Rec709Luminance(const std::array<double, 3>& rgb);

// CIE L*a*b* of XYZ against a reference white XYZ, and the CIE Delta E 2000
// colour difference of two L*a*b* colours (Sharma, Wu, Dalal 2005).
std::array<double, 3> XyzToLab(const std::array<double, 3>& xyz, const std::array<double, 3>& white_xyz);
double DeltaE2000(const std::array<double, 3>& lab1, const std::array<double, 3>& lab2);
// sRGB-encoded 8-bit colour to L*a*b* (D65 white), for comparing previews.
std::array<double, 3> Srgb8ToLab(const std::array<unsigned char, 3>& srgb);

}  // namespace skybake
