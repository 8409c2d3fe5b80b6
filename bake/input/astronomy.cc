#include "skybake/input/astronomy.h"
#include "skybake/input/ephemeris.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <libnova/earth.h>
#include <libnova/julian_day.h>
#include <libnova/lunar.h>
#include <libnova/nutation.h>
#include <libnova/parallax.h>
#include <libnova/precession.h>
#include <libnova/solar.h>
#include <libnova/transform.h>
#include <nlohmann/json.hpp>

#include "skybake/base/file_door.h"
#include "skybake/input/config.h"

namespace skybake {
namespace {

constexpr double kDeg = M_PI / 180.0;

// In [0, 360): a tiny negative angle plus 360 rounds to 360 itself, which
// is 0 (a star at lon -1e-20 had RA 360; found by crafting inputs_fuzz's
// seed tests/fuzz/catalogues/ra-tiny-negative.json).
double Wrap360(double deg) {
  double d = std::fmod(deg, 360.0);
  if (d < 0.0) d += 360.0;
  return d >= 360.0 ? 0.0 : d;
}

}  // namespace

double CompassAzimuthFromLibnova(double libnova_azimuth_deg) { return Wrap360(libnova_azimuth_deg + 180.0); }

namespace {

// Meeus eq. 13.3 and 13.4: equatorial (RA, Dec) from ecliptic (lambda,
// beta) with the obliquity eps, all in radians; RA in (-pi, pi].
void EquatorialFromEcliptic(double lambda, double beta, double eps, double& ra, double& dec) {
  ra = std::atan2(std::sin(lambda) * std::cos(eps) - std::tan(beta) * std::sin(eps), std::cos(lambda));
  dec = std::asin(std::sin(beta) * std::cos(eps) + std::cos(beta) * std::sin(eps) * std::sin(lambda));
}

SkyDirection FromLibnovaHorizontal(const ln_hrz_posn& h) {
  SkyDirection s;
  s.azimuth_deg = CompassAzimuthFromLibnova(h.az);
  s.elevation_deg = h.alt;
  s.direction = SunDirectionFromElevationAzimuth(s.elevation_deg, s.azimuth_deg);
  return s;
}

}  // namespace

std::optional<StarCatalogue> LoadStarCatalogue(const std::string& path, std::string& error) {
  // Through the door (file_door.h): a regular file, capped, read once per
  // process, so every frame of a bake draws the same stars.
  std::shared_ptr<const std::string> bytes;
  if (const std::string problem = ReadKept(path, kMaxCatalogueBytes, bytes); !problem.empty()) {
    error = fmt::format(
        "cannot read the star catalogue {}: it {}: give night.star_catalogue the path of a d3-celestial "
        "stars.*.json (bash .ci/setup installs configs/stars/node_modules/d3-celestial/data/stars.8.json)",
        EscapedText(path), problem == "no such file" ? "does not exist" : problem);
    return std::nullopt;
  }
  return ParseStarCatalogue(*bytes, path, error);
}

std::optional<StarCatalogue> ParseStarCatalogue(const std::string& text, const std::string& path, std::string& error) {
  nlohmann::json doc = nlohmann::json::parse(text, nullptr, false);
  if (doc.is_discarded() || !doc.is_object() || !doc.contains("features") || !doc["features"].is_array()) {
    error = fmt::format(
        "{} is not a d3-celestial star file (a GeoJSON FeatureCollection with \"features\"): give "
        "night.star_catalogue a stars.6.json, stars.8.json or stars.14.json of d3-celestial",
        EscapedText(path));
    return std::nullopt;
  }
  StarCatalogue catalogue;
  catalogue.path = path;
  catalogue.faintest_magnitude = -HUGE_VAL;
  size_t index = 0;
  for (const nlohmann::json& f : doc["features"]) {
    ++index;
    const nlohmann::json* coords = nullptr;
    const nlohmann::json* props = nullptr;
    if (f.is_object() && f.contains("geometry") && f["geometry"].is_object() && f["geometry"].contains("coordinates"))
      coords = &f["geometry"]["coordinates"];
    if (f.is_object() && f.contains("properties") && f["properties"].is_object()) props = &f["properties"];
    if (!coords || !props || !coords->is_array() || coords->size() < 2 || !(*coords)[0].is_number() ||
        !(*coords)[1].is_number() || !props->contains("mag") || !(*props)["mag"].is_number()) {
      error = fmt::format(
          "{}: star {} has no [lon, lat] coordinates or no numeric \"mag\": give "
          "night.star_catalogue an unmodified d3-celestial stars.*.json",
          EscapedText(path), index);
      return std::nullopt;
    }
    CatalogueStar s;
    const double lon = (*coords)[0].get<double>(), lat = (*coords)[1].get<double>();
    s.ra_j2000_deg = Wrap360(lon);
    s.dec_j2000_deg = lat;
    s.v_magnitude = (*props)["mag"].get<double>();
    if (!std::isfinite(lon) || !std::isfinite(lat) || std::abs(lat) > 90.0 || !std::isfinite(s.v_magnitude)) {
      error = fmt::format(
          "{}: star {} has coordinates or a magnitude out of range: give night.star_catalogue an "
          "unmodified d3-celestial stars.*.json",
          EscapedText(path), index);
      return std::nullopt;
    }
    if (props->contains("bv")) {
      const nlohmann::json& bv = (*props)["bv"];
      if (bv.is_number()) s.b_minus_v = bv.get<double>();
      if (bv.is_string() && !bv.get<std::string>().empty()) {
        char* end = nullptr;
        const std::string text = bv.get<std::string>();
        const double v = std::strtod(text.c_str(), &end);
        if (end && *end == '\0' && std::isfinite(v)) s.b_minus_v = v;
      }
    }
    catalogue.faintest_magnitude = std::max(catalogue.faintest_magnitude, s.v_magnitude);
    catalogue.stars.push_back(s);
  }
  if (catalogue.stars.empty()) {
    error = fmt::format("{} holds no stars: give night.star_catalogue a d3-celestial stars.*.json", EscapedText(path));
    return std::nullopt;
  }
  return catalogue;
}

std::string DefaultStarCataloguePath() {
#ifdef SKYBAKE_SOURCE_DIR
  return std::string(SKYBAKE_SOURCE_DIR) + "/configs/stars/node_modules/d3-celestial/data/stars.8.json";
#else
  return "configs/stars/node_modules/d3-celestial/data/stars.8.json";
#endif
}

SkyDirection HorizontalFromJ2000(double ra_j2000_deg, double dec_j2000_deg, double julian_day_ut,
                                 const GeoLocation& place) {
  ln_equ_posn j2000{ra_j2000_deg, dec_j2000_deg};
  ln_equ_posn of_date{};
  ln_get_equ_prec2(&j2000, JD2000, julian_day_ut, &of_date);
  ln_lnlat_posn observer{place.longitude_deg, place.latitude_deg};
  ln_hrz_posn h{};
  ln_get_hrz_from_equ(&of_date, &observer, julian_day_ut, &h);
  return FromLibnovaHorizontal(h);
}

double StarIlluminanceLux(double v_magnitude) {
  return kZeroMagnitudeIlluminanceLux * std::pow(10.0, -0.4 * v_magnitude);
}

double TemperatureFromBMinusV(double bv) {
  bv = std::clamp(bv, -0.4, 2.0);
  return 4600.0 * (1.0 / (0.92 * bv + 1.7) + 1.0 / (0.92 * bv + 0.62));
}

Rgb StarColorFromBMinusV(double bv) {
  const double t = std::clamp(TemperatureFromBMinusV(bv), 1667.0, 25000.0);
  const double t2 = t * t, t3 = t2 * t;
  // Kim et al. 2002: the Planckian locus in CIE 1931 xy.
  const double x = t <= 4000.0 ? -0.2661239e9 / t3 - 0.2343589e6 / t2 + 0.8776956e3 / t + 0.179910
                               : -3.0258469e9 / t3 + 2.1070379e6 / t2 + 0.2226347e3 / t + 0.240390;
  const double x2 = x * x, x3 = x2 * x;
  const double y = t <= 2222.0   ? -1.1063814 * x3 - 1.34811020 * x2 + 2.18555832 * x - 0.20219683
                   : t <= 4000.0 ? -0.9549476 * x3 - 1.37418593 * x2 + 2.09137015 * x - 0.16748867
                                 : 3.0817580 * x3 - 5.87338670 * x2 + 3.75112997 * x - 0.37001483;
  const double X = x / y, Y = 1.0, Z = (1.0 - x - y) / y;
  Rgb rgb = {3.2404542 * X - 1.5371385 * Y - 0.4985314 * Z, -0.9692660 * X + 1.8760108 * Y + 0.0415560 * Z,
             0.0556434 * X - 0.2040259 * Y + 1.0572252 * Z};
  for (double& c : rgb) c = std::max(c, 0.0);
  const double luminance = 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
  for (double& c : rgb) c /= luminance;
  return rgb;
}

glm::dvec3 UnitFromEquatorial(double ra_deg, double dec_deg) {
  const double ra = ra_deg * kDeg, dec = dec_deg * kDeg;
  return {std::cos(dec) * std::cos(ra), std::cos(dec) * std::sin(ra), std::sin(dec)};
}

J2000Axes J2000AxesAt(double julian_day_ut, const GeoLocation& place) {
  ResetLibnovaCaches(julian_day_ut);
  J2000Axes a;
  a.x = HorizontalFromJ2000(0.0, 0.0, julian_day_ut, place).direction;
  a.y = HorizontalFromJ2000(90.0, 0.0, julian_day_ut, place).direction;
  a.z = HorizontalFromJ2000(0.0, 90.0, julian_day_ut, place).direction;
  return a;
}

glm::dvec3 J2000Axes::ToJ2000(const glm::dvec3& world) const {
  return {glm::dot(world, x), glm::dot(world, y), glm::dot(world, z)};
}

glm::dvec3 WorldFromJ2000(const J2000Axes& axes, const glm::dvec3& v) {
  return v.x * axes.x + v.y * axes.y + v.z * axes.z;
}

std::vector<PlacedStar> PlaceStars(const StarCatalogue& catalogue, double magnitude_limit, double julian_day_ut,
                                   const GeoLocation& place, double min_elevation_deg) {
  return PlaceStars(catalogue, magnitude_limit, J2000AxesAt(julian_day_ut, place), min_elevation_deg);
}

std::vector<PlacedStar> PlaceStars(const StarCatalogue& catalogue, double magnitude_limit, const J2000Axes& axes,
                                   double min_elevation_deg) {
  // Precession and the horizontal transform are rotations: libnova turns
  // the three J2000 axes (RA 0 and 90 deg on the equator, the pole) into
  // world directions once per frame, and each star's J2000 unit vector is
  // rotated by the matrix they make (the same place as HorizontalFromJ2000
  // per star, to 1e-9; tests/input/astronomy_test.cc).
  const double min_y = std::sin(min_elevation_deg * kDeg);
  std::vector<PlacedStar> placed;
  for (const CatalogueStar& s : catalogue.stars) {
    if (s.v_magnitude > magnitude_limit) continue;
    const glm::dvec3 d = WorldFromJ2000(axes, UnitFromEquatorial(s.ra_j2000_deg, s.dec_j2000_deg));
    if (d.y <= min_y) continue;
    placed.push_back({d, StarIlluminanceLux(s.v_magnitude), StarColorFromBMinusV(s.b_minus_v)});
  }
  return placed;
}

double MoonIlluminanceLux(double phase_angle_deg, double distance_km) {
  const double a = std::abs(phase_angle_deg);
  const double foot_candles = std::pow(10.0, -0.4 * (3.84 + 0.026 * a + 4e-9 * a * a * a * a));
  const double r = kMoonMeanDistanceKm / distance_km;
  return foot_candles * kLuxPerFootCandle * r * r;
}

LunarEphemeris ComputeLunarEphemeris(double julian_day_ut) {
  ResetLibnovaCaches(julian_day_ut);
  LunarEphemeris e;
  // The one evaluation of ELP 2000-82B: rectangular geocentric, km, the
  // J2000 mean ecliptic and equinox (precision 0: every term, as
  // ln_get_lunar_equ_coords sums them).
  ln_rect_posn moon{};
  ln_get_lunar_geo_posn(julian_day_ut, &moon, 0.0);
  const double lambda = std::atan2(moon.Y, moon.X), beta = std::atan2(moon.Z, std::hypot(moon.X, moon.Y));
  e.ecliptic_longitude_deg = Wrap360(lambda / kDeg);
  e.ecliptic_latitude_deg = beta / kDeg;
  e.distance_km = std::sqrt(moon.X * moon.X + moon.Y * moon.Y + moon.Z * moon.Z);
  // libnova turns ecliptic into equatorial places with the obliquity of
  // its nutation (ln_get_equ_from_ecl); so does this, to match its places.
  ln_nutation nutation{};
  ln_get_nutation(julian_day_ut, &nutation);
  const double eps = nutation.ecliptic * kDeg;
  double ra = 0.0, dec = 0.0;
  EquatorialFromEcliptic(lambda, beta, eps, ra, dec);
  e.ra_deg = Wrap360(ra / kDeg);
  e.dec_deg = dec / kDeg;
  ln_lnlat_posn sun{};
  ln_get_solar_ecl_coords(julian_day_ut, &sun);
  const double sun_lambda = sun.lng * kDeg, sun_beta = sun.lat * kDeg;
  const double sun_km = ln_get_earth_solar_dist(julian_day_ut) * kKmPerAu;
  double sun_ra = 0.0, sun_dec = 0.0;
  EquatorialFromEcliptic(sun_lambda, sun_beta, eps, sun_ra, sun_dec);
  e.sun_ra_deg = Wrap360(sun_ra / kDeg);
  e.sun_dec_deg = sun_dec / kDeg;
  // Meeus eq. 48.2: the Moon's geocentric elongation psi from the Sun (the
  // angle between the two directions, from their cross and dot products so
  // that it stays exact near 0 and 180 deg), then eq. 48.3: the phase
  // angle i, tan i = R sin psi / (Delta - R cos psi).
  const glm::dvec3 to_moon = UnitFromEquatorial(e.ecliptic_longitude_deg, e.ecliptic_latitude_deg);
  const glm::dvec3 to_sun = UnitFromEquatorial(sun.lng, sun.lat);
  const double psi = std::atan2(glm::length(glm::cross(to_moon, to_sun)), glm::dot(to_moon, to_sun));
  const double phase = std::atan2(sun_km * std::sin(psi), e.distance_km - sun_km * std::cos(psi));
  e.phase_angle_deg = phase / kDeg;
  e.illuminated_fraction = 0.5 * (1.0 + std::cos(phase));  // eq. 48.1
  // Eq. 48.5: the position angle of the bright limb's midpoint.
  const double dra = sun_ra - ra;
  const double chi = std::atan2(std::cos(sun_dec) * std::sin(dra),
                                std::sin(sun_dec) * std::cos(dec) - std::cos(sun_dec) * std::sin(dec) * std::cos(dra));
  e.bright_limb_deg = Wrap360(chi / kDeg);
  e.ecliptic_elongation_deg = Wrap360(e.ecliptic_longitude_deg - sun.lng);
  return e;
}

MoonState ComputeMoon(double julian_day_ut, const GeoLocation& place, double observer_altitude_m) {
  MoonState m;
  const LunarEphemeris e = ComputeLunarEphemeris(julian_day_ut);
  // Geocentric place. libnova 0.16 refers it to the J2000 equinox, as its
  // solar coordinates (tests/input/astronomy_test.cc checks this against Meeus
  // example 47.a), so it is precessed to the date.
  ln_equ_posn j2000{e.ra_deg, e.dec_deg};
  ln_equ_posn geocentric{};
  ln_get_equ_prec2(&j2000, JD2000, julian_day_ut, &geocentric);
  const double distance_geocentric_km = e.distance_km;
  ln_lnlat_posn observer{place.longitude_deg, place.latitude_deg};
  ln_hrz_posn h{};
  ln_get_hrz_from_equ(&geocentric, &observer, julian_day_ut, &h);
  m.geocentric_elevation_deg = h.alt;
  m.geocentric_ra_deg = geocentric.ra;
  m.geocentric_dec_deg = geocentric.dec;
  m.geocentric_distance_km = distance_geocentric_km;
  // Topocentric: libnova's ln_get_parallax gives the shifts in RA and Dec
  // (degrees) for the observer's place on the geoid.
  ln_equ_posn shift{};
  ln_get_parallax(&geocentric, distance_geocentric_km / kKmPerAu, &observer, observer_altitude_m, julian_day_ut,
                  &shift);
  ln_equ_posn topocentric{geocentric.ra + shift.ra, geocentric.dec + shift.dec};
  ln_get_hrz_from_equ(&topocentric, &observer, julian_day_ut, &h);
  m.sky = FromLibnovaHorizontal(h);
  // Topocentric distance: the triangle Earth's centre, observer, Moon, with
  // the observer 6378.14 km from the centre (libnova's equatorial radius)
  // and the geocentric zenith angle between the two sides.
  const double r_km = 6378.14 + observer_altitude_m * 1e-3;
  m.distance_km = std::sqrt(distance_geocentric_km * distance_geocentric_km + r_km * r_km -
                            2.0 * distance_geocentric_km * r_km * std::sin(m.geocentric_elevation_deg * kDeg));
  m.angular_radius_rad = std::asin(kMoonRadiusKm / m.distance_km);
  m.phase_angle_deg = e.phase_angle_deg;
  m.illuminated_fraction = e.illuminated_fraction;
  m.bright_limb_deg = e.bright_limb_deg;
  m.illuminance_lux = MoonIlluminanceLux(m.phase_angle_deg, m.distance_km);
  m.ecliptic_elongation_deg = e.ecliptic_elongation_deg;
  return m;
}

}  // namespace skybake
