// The night sky's astronomy: where the stars and the Moon are for a clock
// time at a place, and how much light each sends. CPU only; no GPU.
//
// Positions come from libnova (Debian libnova-dev, already the solar
// position's library): the stars' J2000 catalogue coordinates precessed to
// the date (IAU 1976 precession, ln_get_equ_prec2), the Moon from ELP
// 2000-82B (ln_get_lunar_equ_coords) made topocentric with libnova's
// parallax (about 1 deg for the Moon), then the equatorial -> horizontal
// transform (libnova's azimuth counts from the South towards the West; here
// it is turned into a compass bearing, clockwise from North). No
// refraction: the sky model has none, as for the Sun (solar_position.h).
//
// Photometry:
// - A star of visual magnitude V gives the illuminance
//   E = kZeroMagnitudeIlluminanceLux x 10^(-0.4 V) at the top of the
//   atmosphere, with E(V = 0) = 2.54e-6 lux: Krisciunas & Schaefer 1991
//   (PASP 103, 1033), whose eq. 8 (the Moon's illuminance in foot-candles,
//   10^(-0.4 (3.84 + ...))) and eq. 9 (its V magnitude, -12.73 + ...) give
//   E = 10^(-0.4 (V + 16.57)) fc = 2.54e-6 lux x 10^(-0.4 V) (1 fc =
//   10.7639 lux); the same figure is Allen's "Astrophysical Quantities".
// - Colour from the B-V index: Ballesteros 2012 (EPL 97, 34008) turns B-V
//   into a black-body temperature, T = 4600 K (1 / (0.92 BV + 1.7) + 1 /
//   (0.92 BV + 0.62)); the Planckian locus approximation of Kim et al. 2002
//   (US patent 7,024,034; valid 1667..25000 K) gives its CIE 1931 xy; XYZ
//   -> linear Rec.709 by the sRGB matrix (IEC 61966-2-1), negative
//   channels clipped, then scaled to luminance 1 (Rec.709 weights).
// - The Moon's illuminance outside the atmosphere: Krisciunas & Schaefer
//   1991 eq. 8, I = 10^(-0.4 (3.84 + 0.026 |a| + 4e-9 a^4)) foot-candles
//   (a = phase angle, deg, 0 at full moon) at the mean distance
//   (384,400 km), scaled by the inverse square of the topocentric distance.
//   Their opposition surge (up to 35% brighter within 7 deg of full) is not
//   modelled.
//
// libnova keeps static caches: call from one thread at a time.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "skybake/model/atmosphere.h"
#include "skybake/model/solar_position.h"

namespace skybake {

// E(V = 0), lux (Krisciunas & Schaefer 1991 eq. 8-9, see above).
inline constexpr double kZeroMagnitudeIlluminanceLux = 2.54e-6;
inline constexpr double kLuxPerFootCandle = 10.7639;
inline constexpr double kMoonMeanDistanceKm = 384400.0;
inline constexpr double kMoonRadiusKm = 1737.4;  // IAU mean radius
inline constexpr double kKmPerAu = 149597870.7;
// B-V for a star without one in the catalogue: 0.6, about the catalogue's
// median (a G star).
inline constexpr double kDefaultBMinusV = 0.6;

// One star of a catalogue, J2000 (ICRS) coordinates.
struct CatalogueStar {
  double ra_j2000_deg = 0.0;   // right ascension, [0, 360)
  double dec_j2000_deg = 0.0;  // declination, [-90, 90]
  double v_magnitude = 0.0;    // Johnson V
  double b_minus_v = kDefaultBMinusV;
};

struct StarCatalogue {
  std::string path;
  std::vector<CatalogueStar> stars;  // in file order
  double faintest_magnitude = 0.0;
};

// Reads a d3-celestial star file (GeoJSON FeatureCollection of Points,
// coordinates [lon, lat] in degrees at J2000 with lon = RA for RA < 180 deg
// and RA - 360 otherwise; properties mag and bv, bv a string that may be
// empty). On failure returns nothing and sets `error` to what is wrong and
// the fix.
std::optional<StarCatalogue> LoadStarCatalogue(const std::string& path, std::string& error);
// The same from the file's text (`path` for messages); what the fuzzer
// (tests/fuzz/inputs_fuzz.cc) reads.
std::optional<StarCatalogue> ParseStarCatalogue(const std::string& text, const std::string& path, std::string& error);

// The catalogue night.star_catalogue = "" means unless the command line
// gives another (main: $SKYBAKE_STAR_CATALOGUE, passed in as
// BakeOptions::star_catalogue): d3-celestial's stars.8.json (41,411 stars
// to V = 8) where .ci/setup installs it (configs/stars/node_modules, in the
// source tree).
std::string DefaultStarCataloguePath();

// A direction in the observer's sky.
struct SkyDirection {
  double elevation_deg = 0.0;           // above the horizon, no refraction
  double azimuth_deg = 0.0;             // compass bearing, clockwise from North, [0, 360)
  glm::dvec3 direction{0.0, 1.0, 0.0};  // unit, skybake's frame (+Y up, North -Z, East +X)
};

// Apparent place of a J2000 position at `julian_day_ut`: precessed to the
// equinox of date, then horizontal for `place` (mean sidereal time of
// date; nutation, aberration and proper motion, each under 0.01 deg, left
// out).
SkyDirection HorizontalFromJ2000(double ra_j2000_deg, double dec_j2000_deg, double julian_day_ut,
                                 const GeoLocation& place);

// libnova's horizontal azimuth (from the South towards the West) as a
// compass bearing (from the North towards the East), [0, 360).
double CompassAzimuthFromLibnova(double libnova_azimuth_deg);

// E at the top of the atmosphere, lux.
double StarIlluminanceLux(double v_magnitude);

// Linear Rec.709 colour of unit luminance for a B-V index (clamped to
// [-0.4, 2.0], the range of stellar colours).
Rgb StarColorFromBMinusV(double b_minus_v);
// The black-body temperature Ballesteros 2012 gives a B-V index, K.
double TemperatureFromBMinusV(double b_minus_v);

// A star placed in one frame's sky, before the atmosphere.
struct PlacedStar {
  glm::dvec3 direction{0.0, 1.0, 0.0};
  double illuminance_lux = 0.0;  // top of the atmosphere
  Rgb color{1.0, 1.0, 1.0};      // linear Rec.709, luminance 1
};

// The world directions (skybake's frame) of the J2000 equatorial axes at
// `julian_day_ut` and `place` (RA 0 and 90 deg on the equator, the pole):
// precession and the horizontal transform, a rotation. A J2000 unit vector
// v is at v.x * x + v.y * y + v.z * z; a world direction d at J2000
// (d.x, d.y, d.z) . (x, y, z) (orthonormal to 1e-9).
struct J2000Axes {
  glm::dvec3 x{1.0, 0.0, 0.0}, y{0.0, 1.0, 0.0}, z{0.0, 0.0, 1.0};
  glm::dvec3 ToJ2000(const glm::dvec3& world) const;
};
J2000Axes J2000AxesAt(double julian_day_ut, const GeoLocation& place);
// The J2000 unit vector of (RA, Dec): x towards RA 0, z the pole.
glm::dvec3 UnitFromEquatorial(double ra_deg, double dec_deg);

// The catalogue's stars brighter than `magnitude_limit` and above the
// observer's astronomical horizon (elevation > `min_elevation_deg`).
std::vector<PlacedStar> PlaceStars(const StarCatalogue& catalogue, double magnitude_limit, double julian_day_ut,
                                   const GeoLocation& place, double min_elevation_deg);

struct MoonState {
  SkyDirection sky;                   // topocentric
  double phase_angle_deg = 0.0;       // Sun-Moon-Earth, 0 = full, 180 = new (libnova, degrees)
  double illuminated_fraction = 0.0;  // (1 + cos phase) / 2
  double bright_limb_deg = 0.0;       // position angle of the bright limb's midpoint, from celestial north through east
  double distance_km = 0.0;           // topocentric
  double angular_radius_rad = 0.0;    // from the Moon's radius and the topocentric distance
  double illuminance_lux = 0.0;       // outside the atmosphere, Krisciunas & Schaefer 1991 eq. 8
  double geocentric_elevation_deg = 0.0;  // without the parallax, for tests
  double geocentric_ra_deg = 0.0;         // of date, for tests
  double geocentric_dec_deg = 0.0;
  double geocentric_distance_km = 0.0;
  double ecliptic_elongation_deg = 0.0;  // Moon minus Sun ecliptic longitude, [0, 360)
};

// The Moon of one baked frame, as FrameResult and the manifest record it.
struct MoonRecord {
  glm::dvec3 direction{0.0, 1.0, 0.0};  // unit, towards the Moon (topocentric)
  double elevation_deg = 0.0;
  double azimuth_deg = 0.0;      // clockwise from North
  double phase_angle_deg = 0.0;  // 0 = full, 180 = new
  double illuminated_fraction = 0.0;
  double bright_limb_deg = 0.0;
  double angular_radius_rad = 0.0;
  double top_illuminance_lux = 0.0;  // outside the atmosphere (Krisciunas & Schaefer 1991)
  double illuminance_lux = 0.0;      // at the observer, after the atmosphere (0 below the horizon)
  Rgb irradiance{0.0, 0.0, 0.0};     // the same in output units x sr
  bool light = false;                // night.moonlight: a light of the scene (glTF, SH)
};

MoonState ComputeMoon(double julian_day_ut, const GeoLocation& place, double observer_altitude_m);

// Krisciunas & Schaefer 1991 eq. 8 in lux, at `distance_km`.
double MoonIlluminanceLux(double phase_angle_deg, double distance_km);

}  // namespace skybake
