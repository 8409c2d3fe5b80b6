// The night sky's astronomy against published values and an independent
// computation: Meeus, "Astronomical Algorithms" (2nd ed., 1998), rigorous
// precession (eq. 21.2-21.4), mean sidereal time (eq. 12.4) and the
// horizontal transform (eq. 13.5-13.6), written here from the book and not
// through libnova. Known lunar phases from the published 2024 times
// (full moon 2024-04-23 23:49 UTC, new moon 2024-04-08 18:21 UTC, first
// quarter 2024-04-15 19:13 UTC, last quarter 2024-05-01 11:27 UTC).
#include "skybake/input/astronomy.h"
#include "skybake/input/ephemeris.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <glm/glm.hpp>
#include <libnova/lunar.h>
#include <libnova/solar.h>
#include <libnova/transform.h>

#include "skybake/tools/reference_model.h"

namespace skybake {
namespace {

constexpr double kDeg = M_PI / 180.0;

double Wrap360(double d) {
  d = std::fmod(d, 360.0);
  return d < 0.0 ? d + 360.0 : d;
}
double AngleDifference(double a, double b) {
  double d = std::fmod(a - b + 540.0, 360.0) - 180.0;
  return std::abs(d);
}

double JulianDay(int y, int mo, int d, int h, int mi) {
  CivilTime t;
  t.year = y;
  t.month = mo;
  t.day = d;
  t.hour = h;
  t.minute = mi;
  return JulianDayUt(t);
}

// --- Meeus, written independently of libnova
struct Equatorial {
  double ra_deg, dec_deg;
};
Equatorial MeeusPrecessFromJ2000(double ra_deg, double dec_deg, double jd) {
  const double t = (jd - 2451545.0) / 36525.0;
  const double arcsec = kDeg / 3600.0;
  const double zeta = (2306.2181 * t + 0.30188 * t * t + 0.017998 * t * t * t) * arcsec;
  const double z = (2306.2181 * t + 1.09468 * t * t + 0.018203 * t * t * t) * arcsec;
  const double theta = (2004.3109 * t - 0.42665 * t * t - 0.041833 * t * t * t) * arcsec;
  const double a0 = ra_deg * kDeg, d0 = dec_deg * kDeg;
  const double A = std::cos(d0) * std::sin(a0 + zeta);
  const double B = std::cos(theta) * std::cos(d0) * std::cos(a0 + zeta) - std::sin(theta) * std::sin(d0);
  const double C = std::sin(theta) * std::cos(d0) * std::cos(a0 + zeta) + std::cos(theta) * std::sin(d0);
  return {Wrap360((std::atan2(A, B) + z) / kDeg), std::asin(C) / kDeg};
}
double MeeusMeanSiderealDeg(double jd) {
  const double t = (jd - 2451545.0) / 36525.0;
  return Wrap360(280.46061837 + 360.98564736629 * (jd - 2451545.0) + 0.000387933 * t * t - t * t * t / 38710000.0);
}
struct Horizontal {
  double elevation_deg, compass_azimuth_deg;
};
Horizontal MeeusHorizontal(const Equatorial& e, double jd, double lat_deg, double lon_east_deg) {
  const double h = (MeeusMeanSiderealDeg(jd) + lon_east_deg - e.ra_deg) * kDeg;
  const double phi = lat_deg * kDeg, dec = e.dec_deg * kDeg;
  const double alt = std::asin(std::sin(phi) * std::sin(dec) + std::cos(phi) * std::cos(dec) * std::cos(h));
  const double az_south = std::atan2(std::sin(h), std::cos(h) * std::sin(phi) - std::tan(dec) * std::cos(phi));
  return {alt / kDeg, Wrap360(az_south / kDeg + 180.0)};
}

// Meeus example 13.b: Venus from the US Naval Observatory, 1987 April 10,
// 19:21:00 UT: A = 68.0337 deg (from the South, towards the West), h =
// 15.1249 deg. libnova's azimuth has the same origin; skybake's compass
// bearing is 180 deg more.
TEST(Astronomy, LibnovaAzimuthCountsFromTheSouthMeeusExample13b) {
  ln_equ_posn venus{347.3193375, -6.719892};
  ln_lnlat_posn observer{-(77.0 + 3.0 / 60 + 56.0 / 3600), 38.0 + 55.0 / 60 + 17.0 / 3600};
  ln_hrz_posn h{};
  ln_get_hrz_from_equ(&venus, &observer, JulianDay(1987, 4, 10, 19, 21), &h);
  EXPECT_NEAR(h.az, 68.0337, 0.01);
  EXPECT_NEAR(h.alt, 15.1249, 0.01);
  EXPECT_NEAR(CompassAzimuthFromLibnova(h.az), 248.0337, 0.01);
}

// Polaris (HIP 11767) stands within about 0.7 deg of the pole: its
// elevation is the latitude within 1 deg at any hour, north of the equator.
TEST(Astronomy, PolarisElevationIsTheLatitude) {
  const double ra = 37.9545, dec = 89.2641;  // d3-celestial stars.6.json, J2000
  for (double lat : {5.0, 20.0, 42.4, 60.0, 80.0})
    for (int hour = 0; hour < 24; hour += 3) {
      const SkyDirection d = HorizontalFromJ2000(ra, dec, JulianDay(2024, 4, 23, hour, 0), {lat, 13.4});
      EXPECT_NEAR(d.elevation_deg, lat, 1.0) << "latitude " << lat << " hour " << hour;
      EXPECT_LT(AngleDifference(d.azimuth_deg, 0.0), 1.0 / std::cos(lat * kDeg) + 0.1);
      EXPECT_NEAR(d.direction.y, std::sin(d.elevation_deg * kDeg), 1e-12);
      EXPECT_LT(d.direction.z, 0.0);  // North is -Z
    }
}

// Sirius (HIP 32349) from Greenwich against Meeus' formulas computed here.
TEST(Astronomy, SiriusAgainstMeeusPrecessionAndSiderealTime) {
  const double ra = 101.2872, dec = -16.7161;  // J2000
  const double lat = 51.4769, lon = -0.0005;
  for (int hour : {19, 21, 23}) {
    const double jd = JulianDay(2024, 1, 15, hour, 0);
    const SkyDirection d = HorizontalFromJ2000(ra, dec, jd, {lat, lon});
    const Horizontal m = MeeusHorizontal(MeeusPrecessFromJ2000(ra, dec, jd), jd, lat, lon);
    EXPECT_NEAR(d.elevation_deg, m.elevation_deg, 0.02) << hour;
    EXPECT_LT(AngleDifference(d.azimuth_deg, m.compass_azimuth_deg), 0.02) << hour;
  }
  // Culmination: the highest elevation over the night is 90 - latitude +
  // declination of date, due South.
  const Equatorial of_date = MeeusPrecessFromJ2000(ra, dec, JulianDay(2024, 1, 15, 23, 0));
  double best = -90.0, best_az = 0.0;
  for (int minute = 0; minute < 24 * 60; ++minute) {
    const SkyDirection d = HorizontalFromJ2000(ra, dec, JulianDay(2024, 1, 15, 12, 0) + minute / 1440.0, {lat, lon});
    if (d.elevation_deg > best) best = d.elevation_deg, best_az = d.azimuth_deg;
  }
  EXPECT_NEAR(best, 90.0 - lat + of_date.dec_deg, 0.01);
  EXPECT_NEAR(best_az, 180.0, 0.5);
  // Precession since J2000 moved it measurably (the test would see a missing precession).
  EXPECT_GT(std::abs(of_date.ra_deg - ra), 0.2);
}

// Meeus example 47.a, 1992 April 12 0h TD: apparent RA 134.688470, Dec
// 13.768368, distance 368409.7 km. libnova's lunar equatorial coordinates
// are referred to J2000 (0.1 deg off) and ComputeMoon precesses them.
TEST(Astronomy, MoonGeocentricPlaceMeeusExample47a) {
  const double jd = 2448724.5;  // TD; as UT it is off by 59 s (0.008 deg of the Moon's motion)
  const MoonState m = ComputeMoon(jd, {0.0, 0.0}, 0.0);
  EXPECT_NEAR(m.geocentric_ra_deg, 134.688470, 0.02);
  EXPECT_NEAR(m.geocentric_dec_deg, 13.768368, 0.02);
  // libnova sums the whole ELP 2000-82B, Meeus' example his abridged series.
  EXPECT_NEAR(m.geocentric_distance_km, 368409.7, 5.0);
  ln_equ_posn raw{};
  ln_get_lunar_equ_coords(jd, &raw);
  EXPECT_GT(std::abs(raw.ra - 134.688470), 0.05) << "libnova now gives the place of date: drop the precession";
}

// The topocentric Moon against the geocentric vector minus the observer's
// (a spherical Earth of 6378.14 km, Meeus eq. 12.4 sidereal time).
TEST(Astronomy, MoonParallaxAgainstVectorSubtraction) {
  const double lat = 42.4, lon = -76.5;
  for (int hour : {1, 5, 9, 13, 17, 21}) {
    const double jd = JulianDay(2024, 4, 23, hour, 0);
    const MoonState m = ComputeMoon(jd, {lat, lon}, 0.0);
    const double ra = m.geocentric_ra_deg * kDeg, dec = m.geocentric_dec_deg * kDeg;
    const glm::dvec3 moon = m.geocentric_distance_km *
                            glm::dvec3(std::cos(dec) * std::cos(ra), std::cos(dec) * std::sin(ra), std::sin(dec));
    const double lst = (MeeusMeanSiderealDeg(jd) + lon) * kDeg;
    const glm::dvec3 observer = 6378.14 * glm::dvec3(std::cos(lat * kDeg) * std::cos(lst),
                                                     std::cos(lat * kDeg) * std::sin(lst), std::sin(lat * kDeg));
    const glm::dvec3 topo = moon - observer;
    const Equatorial e{Wrap360(std::atan2(topo.y, topo.x) / kDeg), std::asin(topo.z / glm::length(topo)) / kDeg};
    const Horizontal h = MeeusHorizontal(e, jd, lat, lon);
    EXPECT_NEAR(m.sky.elevation_deg, h.elevation_deg, 0.03) << hour;
    EXPECT_LT(AngleDifference(m.sky.azimuth_deg, h.compass_azimuth_deg),
              0.05 / std::max(0.2, std::cos(h.elevation_deg * kDeg)));
    EXPECT_NEAR(m.distance_km, glm::length(topo), 5.0);
    // The parallax lowers the Moon by about 0.95 deg x cos(elevation).
    EXPECT_NEAR(m.geocentric_elevation_deg - m.sky.elevation_deg, 0.95 * std::cos(m.sky.elevation_deg * kDeg), 0.1);
  }
}

TEST(Astronomy, MoonPhaseAtKnownFullAndNewMoons) {
  const double full = JulianDay(2024, 4, 23, 23, 49), fresh = JulianDay(2024, 4, 8, 18, 21);
  const MoonState f = ComputeMoon(full, {0.0, 0.0}, 0.0);
  EXPECT_LT(f.phase_angle_deg, 6.0);  // degrees: the Moon's latitude keeps it from 0
  EXPECT_GT(f.illuminated_fraction, 0.99);
  EXPECT_LT(AngleDifference(f.ecliptic_elongation_deg, 180.0), 0.5);
  EXPECT_LT(f.phase_angle_deg, ComputeMoon(full - 1.0, {0.0, 0.0}, 0.0).phase_angle_deg);
  EXPECT_LT(f.phase_angle_deg, ComputeMoon(full + 1.0, {0.0, 0.0}, 0.0).phase_angle_deg);
  const MoonState n = ComputeMoon(fresh, {0.0, 0.0}, 0.0);
  EXPECT_GT(n.phase_angle_deg, 174.0);  // the day of a total solar eclipse: the Moon on the ecliptic
  EXPECT_LT(n.illuminated_fraction, 0.01);
  EXPECT_LT(AngleDifference(n.ecliptic_elongation_deg, 0.0), 0.5);
  // Quarters: half lit, phase angle near 90.
  const MoonState q1 = ComputeMoon(JulianDay(2024, 4, 15, 19, 13), {0.0, 0.0}, 0.0);
  EXPECT_NEAR(q1.illuminated_fraction, 0.5, 0.02);
  EXPECT_NEAR(q1.phase_angle_deg, 90.0, 2.0);
}

// The bright limb faces the Sun: at first quarter it is on the west
// (position angle near 270), at last quarter on the east (near 90); and it
// matches the Sun's position angle around the Moon computed from tangent-
// plane vectors.
TEST(Astronomy, MoonBrightLimbFacesTheSun) {
  struct Case {
    double jd, expected;
  };
  for (const Case& c : {Case{JulianDay(2024, 4, 15, 19, 13), 270.0}, Case{JulianDay(2024, 5, 1, 11, 27), 90.0},
                        Case{JulianDay(2024, 4, 12, 0, 0), 270.0}}) {
    const MoonState m = ComputeMoon(c.jd, {0.0, 0.0}, 0.0);
    EXPECT_LT(AngleDifference(m.bright_limb_deg, c.expected), 35.0);
    ln_equ_posn sun_j2000{}, moon_j2000{};
    ln_get_solar_equ_coords(c.jd, &sun_j2000);
    ln_get_lunar_equ_coords(c.jd, &moon_j2000);
    auto unit = [](const ln_equ_posn& e) {
      return glm::dvec3(std::cos(e.dec * kDeg) * std::cos(e.ra * kDeg), std::cos(e.dec * kDeg) * std::sin(e.ra * kDeg),
                        std::sin(e.dec * kDeg));
    };
    const glm::dvec3 mv = unit(moon_j2000), sv = unit(sun_j2000);
    const glm::dvec3 east = glm::normalize(glm::cross(glm::dvec3(0, 0, 1), mv));
    const glm::dvec3 north = glm::cross(mv, east);
    const double pa = Wrap360(std::atan2(glm::dot(sv, east), glm::dot(sv, north)) / kDeg);
    EXPECT_LT(AngleDifference(m.bright_limb_deg, pa), 1e-6);
  }
}

// ComputeLunarEphemeris evaluates ELP 2000-82B once and derives the rest;
// against libnova's own functions (each of which sums the series again) at
// 200 dates from 1900 to 2100, every phase. Where libnova sums fewer terms
// or misprints a formula the difference is bounded by what that costs:
// - ln_get_lunar_earth_dist drops the distance terms under 1e-5 x
//   384,748 km (3.8 km): up to 21 km over 1900-2100 against every term;
// - ln_get_lunar_phase takes the place with the terms under 1e-4 rad
//   dropped and that distance: up to 0.04 deg in the phase angle, 3e-4 in
//   the lit fraction;
// - ln_get_lunar_bright_limb writes sin(dec_sun x cos dec) for Meeus eq.
//   48.5's sin(dec_sun) x cos(dec): up to 1.3 deg. The test shows that this
//   misprint is the whole difference: eq. 48.5 with it, from libnova's own
//   places, is libnova's value to 1e-9 deg; without it, this one's.
TEST(Astronomy, LunarEphemerisMatchesLibnovaFrom1900To2100) {
  double worst_distance = 0.0, worst_phase = 0.0, worst_limb = 0.0;
  for (int i = 0; i < 200; ++i) {
    const double jd =
        2415020.5 + i * 365.2422 + 0.137 * i * i;  // 1900-01-01 + about a year, drifting through the month
    const LunarEphemeris e = ComputeLunarEphemeris(jd);
    ln_equ_posn moon_equ{}, sun_equ{};
    ln_get_lunar_equ_coords(jd, &moon_equ);
    ln_get_solar_equ_coords(jd, &sun_equ);
    ln_lnlat_posn moon_ecl{}, sun_ecl{};
    ln_get_lunar_ecl_coords(jd, &moon_ecl, 0.0);
    ln_get_solar_ecl_coords(jd, &sun_ecl);
    EXPECT_LT(AngleDifference(e.ra_deg, moon_equ.ra), 1e-9) << jd;
    EXPECT_NEAR(e.dec_deg, moon_equ.dec, 1e-9) << jd;
    EXPECT_LT(AngleDifference(e.sun_ra_deg, sun_equ.ra), 1e-9) << jd;
    EXPECT_NEAR(e.sun_dec_deg, sun_equ.dec, 1e-9) << jd;
    EXPECT_LT(AngleDifference(e.ecliptic_longitude_deg, moon_ecl.lng), 1e-9) << jd;
    EXPECT_NEAR(e.ecliptic_latitude_deg, moon_ecl.lat, 1e-9) << jd;
    EXPECT_LT(AngleDifference(e.ecliptic_elongation_deg, moon_ecl.lng - sun_ecl.lng), 1e-9) << jd;
    ln_rect_posn full{};
    ln_get_lunar_geo_posn(jd, &full, 0.0);
    EXPECT_NEAR(e.distance_km, std::sqrt(full.X * full.X + full.Y * full.Y + full.Z * full.Z), 1e-6) << jd;
    worst_distance = std::max(worst_distance, std::abs(e.distance_km - ln_get_lunar_earth_dist(jd)));
    EXPECT_LT(std::abs(e.distance_km - ln_get_lunar_earth_dist(jd)), 25.0) << jd;
    const double phase = ln_get_lunar_phase(jd);
    worst_phase = std::max(worst_phase, std::abs(e.phase_angle_deg - phase));
    EXPECT_NEAR(e.phase_angle_deg, phase, 0.05) << jd;
    EXPECT_NEAR(e.illuminated_fraction, ln_get_lunar_disk(jd), 4e-4) << jd;
    EXPECT_NEAR(e.illuminated_fraction, 0.5 * (1.0 + std::cos(e.phase_angle_deg * kDeg)), 1e-12) << jd;
    const double limb = ln_get_lunar_bright_limb(jd);
    worst_limb = std::max(worst_limb, AngleDifference(e.bright_limb_deg, limb));
    EXPECT_LT(AngleDifference(e.bright_limb_deg, limb), 1.5) << jd;
    const double ds = sun_equ.dec * kDeg, dm = moon_equ.dec * kDeg, dra = (sun_equ.ra - moon_equ.ra) * kDeg;
    const double x = std::cos(ds) * std::sin(dra);
    const double misprinted = std::atan2(x, std::sin(ds * std::cos(dm)) - std::cos(ds) * std::sin(dm) * std::cos(dra));
    const double meeus = std::atan2(x, std::sin(ds) * std::cos(dm) - std::cos(ds) * std::sin(dm) * std::cos(dra));
    EXPECT_LT(AngleDifference(misprinted / kDeg, limb), 1e-9) << jd;
    EXPECT_LT(AngleDifference(meeus / kDeg, e.bright_limb_deg), 1e-9) << jd;
  }
  // The bounds above are not loose: each difference is there.
  EXPECT_GT(worst_distance, 1.0);
  EXPECT_GT(worst_phase, 1e-3);
  EXPECT_GT(worst_limb, 0.1);
}

TEST(Astronomy, MoonAngularSizeFromItsDistance) {
  const double jd = JulianDay(2024, 4, 23, 23, 49);
  const MoonState m = ComputeMoon(jd, {-15.0, 0.0}, 0.0);
  const double sdiam_rad = ln_get_lunar_sdiam(jd) / 3600.0 * kDeg;  // geocentric semi-diameter, arcsec
  EXPECT_NEAR(m.angular_radius_rad / sdiam_rad, 1.0, 0.02);         // topocentric: up to 1.7% larger overhead
  EXPECT_GT(m.angular_radius_rad, 0.0042);
  EXPECT_LT(m.angular_radius_rad, 0.0049);
}

// Krisciunas & Schaefer 1991: the full moon gives 0.1..0.3 lux on the
// ground; here its top-of-atmosphere illuminance times the default
// atmosphere's transmittance (luminance-weighted) along its direction.
TEST(Astronomy, FullMoonIlluminanceNearPublishedValue) {
  const double jd = JulianDay(2024, 4, 23, 23, 49);
  const MoonState m = ComputeMoon(jd, {-15.0, 0.0}, 0.0);
  ASSERT_GT(m.sky.elevation_deg, 50.0);
  EXPECT_GT(m.illuminance_lux, 0.25);
  EXPECT_LT(m.illuminance_lux, 0.40);
  AtmosphereParams atmosphere;
  ReferenceModel model(atmosphere, QualitySettings(), EffectSettings(), {1.0, 1.0, 1.0});
  const glm::dvec3 t = model.TransmittanceDirect(0.0, m.sky.direction.y, 256);
  const double ground = m.illuminance_lux * (0.2126 * t.x + 0.7152 * t.y + 0.0722 * t.z);
  EXPECT_GT(ground, 0.1);
  EXPECT_LT(ground, 0.3);
  // A half moon is about a tenth of a full one (K&S: 2.2 mag fainter at 90 deg).
  EXPECT_NEAR(MoonIlluminanceLux(90.0, kMoonMeanDistanceKm) / MoonIlluminanceLux(0.0, kMoonMeanDistanceKm),
              std::pow(10.0, -0.4 * (0.026 * 90 + 4e-9 * std::pow(90.0, 4))), 1e-12);
}

// The V zero point is the one K&S's eq. 8 and 9 imply: the full moon's
// magnitude -12.73 gives its illuminance.
TEST(Astronomy, StarIlluminanceZeroPoint) {
  EXPECT_DOUBLE_EQ(StarIlluminanceLux(0.0), 2.54e-6);
  EXPECT_NEAR(StarIlluminanceLux(-12.73) / MoonIlluminanceLux(0.0, kMoonMeanDistanceKm), 1.0, 0.005);
  EXPECT_NEAR(StarIlluminanceLux(5.0) / StarIlluminanceLux(0.0), 0.01, 1e-12);  // 5 mag = 100 x
}

TEST(Astronomy, StarColourFromBMinusV) {
  // Ballesteros 2012: the Sun's B-V 0.65 -> about 5800 K.
  EXPECT_NEAR(TemperatureFromBMinusV(0.65), 5800.0, 250.0);
  EXPECT_GT(TemperatureFromBMinusV(-0.3), 15000.0);  // a B star
  EXPECT_LT(TemperatureFromBMinusV(1.6), 4000.0);    // an M star
  for (double bv = -0.4; bv <= 2.0; bv += 0.05) {
    const Rgb c = StarColorFromBMinusV(bv);
    for (double v : c) EXPECT_GE(v, 0.0);
    EXPECT_NEAR(0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2], 1.0, 1e-12);
  }
  const Rgb blue = StarColorFromBMinusV(-0.3), red = StarColorFromBMinusV(1.6), sun = StarColorFromBMinusV(0.65);
  EXPECT_GT(blue[2], blue[0]);
  EXPECT_GT(red[0], 2.0 * red[2]);
  EXPECT_NEAR(sun[0] / sun[2], 1.1, 0.2);  // a 5800 K black body is nearly white in Rec.709 (D65)
}

// PlaceStars' per-frame rotation matrix gives every star the place
// HorizontalFromJ2000 gives it one by one.
TEST(Astronomy, PlaceStarsMatchesThePerStarTransform) {
  StarCatalogue c;
  for (double ra = 3.0; ra < 360.0; ra += 37.0)
    for (double dec = -85.0; dec <= 85.0; dec += 17.0) c.stars.push_back({ra, dec, 1.0, 0.5});
  const double jd = JulianDay(2031, 7, 2, 3, 30);
  const GeoLocation place{-33.9, 18.4};
  const std::vector<PlacedStar> placed = PlaceStars(c, 6.0, jd, place, -90.0);
  ASSERT_EQ(placed.size(), c.stars.size());
  for (size_t i = 0; i < placed.size(); ++i) {
    const SkyDirection d = HorizontalFromJ2000(c.stars[i].ra_j2000_deg, c.stars[i].dec_j2000_deg, jd, place);
    EXPECT_LT(glm::length(placed[i].direction - d.direction), 1e-9) << i;
  }
}

TEST(Astronomy, LoadsTheInstalledCatalogue) {
  std::string error;
  const std::optional<StarCatalogue> c = LoadStarCatalogue(DefaultStarCataloguePath(), error);
  ASSERT_TRUE(c) << error << " (bash .ci/setup installs it)";
  EXPECT_EQ(c->stars.size(), 41411u);
  EXPECT_LE(c->faintest_magnitude, 8.0);
  double brightest = 99.0;
  for (const CatalogueStar& s : c->stars) brightest = std::min(brightest, s.v_magnitude);
  EXPECT_NEAR(brightest, -1.44, 0.01);  // Sirius
  // Above the horizon: about half of the stars to V = 6.
  const std::vector<PlacedStar> placed = PlaceStars(*c, 6.0, JulianDay(2024, 4, 23, 23, 49), {42.4, -76.5}, 0.0);
  EXPECT_GT(placed.size(), 1800u);
  EXPECT_LT(placed.size(), 3300u);
  for (const PlacedStar& p : placed) EXPECT_GT(p.direction.y, 0.0);
}

TEST(Astronomy, RefusesAMissingOrBrokenCatalogue) {
  std::string error;
  EXPECT_FALSE(LoadStarCatalogue("/nonexistent/stars.json", error));
  EXPECT_NE(error.find("night.star_catalogue"), std::string::npos) << error;
  const std::string path = (std::filesystem::temp_directory_path() / "skybake_broken_stars.json").string();
  {
    std::ofstream out(path);
    out << "{\"type\":\"FeatureCollection\",\"features\":[{\"geometry\":{\"coordinates\":[1,2]}}]}";
  }
  error.clear();
  EXPECT_FALSE(LoadStarCatalogue(path, error));
  EXPECT_NE(error.find("star 1"), std::string::npos) << error;
  {
    std::ofstream out(path);
    out << "not json";
  }
  EXPECT_FALSE(LoadStarCatalogue(path, error));
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace skybake
