// Where the Sun is, seen from a place on Earth at a clock time.
//
// The astronomy is libnova's (Debian libnova-dev): VSOP87 solar coordinates
// with nutation and aberration (Meeus, "Astronomical Algorithms", ch. 25),
// apparent sidereal time, then the equatorial -> horizontal transform. The
// result is the geometric (airless) direction: the sky model has no
// refraction, so neither has the sun that drives it.
//
// libnova keeps static caches (nutation), so call this from one thread at a
// time; repeated calls agree to about 1e-5 degrees, not bit for bit.
//
// Conventions: latitude north positive, longitude east positive, degrees.
// Azimuth is a compass bearing, clockwise from North (East = 90). The world
// frame is skybake's: +Y up, North = -Z, East = +X.
#pragma once

#include <string>

#include <glm/vec3.hpp>

namespace skybake {

// A civil (wall-clock) time at a fixed offset from UTC.
struct CivilTime {
  int year = 2000;
  int month = 1;   // 1..12
  int day = 1;     // 1..31
  int hour = 0;    // 0..23
  int minute = 0;  // 0..59
  double second = 0.0;
  double utc_offset_hours = 0.0;  // local = UTC + offset; EDT is -4

  // "2013-05-27T09:30:00-04:00" (ISO 8601 with the offset).
  std::string Iso8601() const;
};

struct GeoLocation {
  double latitude_deg = 0.0;   // north positive, -90..90
  double longitude_deg = 0.0;  // east positive, -180..180
};

struct SolarPosition {
  double elevation_deg = 0.0;           // above the horizon (90 - zenith)
  double azimuth_deg = 0.0;             // clockwise from North, [0, 360)
  double julian_day_ut = 0.0;           // the instant, Julian day (UT)
  glm::dvec3 direction{0.0, 1.0, 0.0};  // unit vector towards the Sun, world frame
};

// Julian day (UT) of a civil time.
double JulianDayUt(const CivilTime& time);

// Makes libnova's next nutation and solar computation at `julian_day_ut`
// compute afresh instead of reusing a cached nearby day (solar_position.cc):
// positions then do not depend on what was computed before them.
void ResetLibnovaCaches(double julian_day_ut);

// The Sun's geometric position at `time` seen from `place`.
SolarPosition ComputeSolarPosition(const CivilTime& time, const GeoLocation& place);

// Days in `month` of `year` (proleptic Gregorian), for validating dates.
int DaysInMonth(int year, int month);

}  // namespace skybake
