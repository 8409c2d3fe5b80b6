#include "skybake/model/solar_position.h"

#include <cmath>

#include <fmt/format.h>
#include <libnova/julian_day.h>
#include <libnova/nutation.h>
#include <libnova/precession.h>
#include <libnova/solar.h>
#include <libnova/transform.h>

#include "skybake/model/atmosphere.h"

namespace skybake {

std::string CivilTime::Iso8601() const {
  double offset_minutes_total = std::round(std::abs(utc_offset_hours) * 60.0);
  int offset_h = int(offset_minutes_total) / 60;
  int offset_m = int(offset_minutes_total) % 60;
  std::string seconds =
      second == std::floor(second) ? fmt::format("{:02d}", int(second)) : fmt::format("{:06.3f}", second);
  return fmt::format("{:04d}-{:02d}-{:02d}T{:02d}:{:02d}:{}{}{:02d}:{:02d}", year, month, day, hour, minute, seconds,
                     utc_offset_hours < 0.0 ? '-' : '+', offset_h, offset_m);
}

int DaysInMonth(int year, int month) {
  static const int kDays[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  if (month < 1 || month > 12) return 0;
  bool leap = (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
  return kDays[month - 1] + (month == 2 && leap ? 1 : 0);
}

// libnova caches its nutation (and the solar series built on it) by Julian
// day and reuses a value for a nearby day, so a result depends on the calls
// before it at the 1e-10 level. Computing each at a day far away first
// makes the next call at `julian_day_ut` compute afresh: a frame's Sun, stars
// and Moon are then the same whichever frames were computed before it (a
// shard of a sequence gives the unsharded bake's bytes). The lunar series
// keeps no cache (ln_get_lunar_geo_posn at a day gives the same bits
// whatever was computed before); its equatorial place reads the nutation.
void ResetLibnovaCaches(double julian_day_ut) {
  const double far = julian_day_ut + 400.0;
  ln_nutation nutation{};
  ln_get_nutation(far, &nutation);
  ln_equ_posn equatorial{};
  ln_get_solar_equ_coords(far, &equatorial);
  ln_lnlat_posn ecliptic{};
  ln_get_solar_ecl_coords(far, &ecliptic);
}

double JulianDayUt(const CivilTime& time) {
  // libnova takes the civil fields as UTC; the offset is applied in days
  // afterwards, which also carries across midnight and month ends.
  ln_date date{};
  date.years = time.year;
  date.months = time.month;
  date.days = time.day;
  date.hours = time.hour;
  date.minutes = time.minute;
  date.seconds = time.second;
  return ln_get_julian_day(&date) - time.utc_offset_hours / 24.0;
}

SolarPosition ComputeSolarPosition(const CivilTime& time, const GeoLocation& place) {
  SolarPosition result;
  result.julian_day_ut = JulianDayUt(time);
  // Apparent right ascension and declination of the Sun (VSOP87, nutation,
  // aberration). libnova uses the one Julian day for both the solar theory
  // (strictly TT) and sidereal time (UT); the ~69 s difference moves the Sun
  // by 0.0008 deg along the ecliptic, far below the tested 0.05 deg.
  // libnova 0.16 returns them referred to the J2000 equinox (against Meeus
  // example 25.b, 1992-10-13: RA 0.1 deg too large, the precession of 7.8
  // years), so they are precessed to the equinox of date before the
  // horizontal transform, which uses the sidereal time of date.
  ResetLibnovaCaches(result.julian_day_ut);
  ln_equ_posn equatorial_j2000{};
  ln_get_solar_equ_coords(result.julian_day_ut, &equatorial_j2000);
  ln_equ_posn equatorial{};
  ln_get_equ_prec2(&equatorial_j2000, JD2000, result.julian_day_ut, &equatorial);
  ln_lnlat_posn observer{};
  observer.lng = place.longitude_deg;  // libnova: east positive
  observer.lat = place.latitude_deg;
  ln_hrz_posn horizontal{};
  ln_get_hrz_from_equ(&equatorial, &observer, result.julian_day_ut, &horizontal);
  // libnova measures azimuth from South towards West; a compass bearing
  // starts at North and turns towards East.
  double azimuth = std::fmod(horizontal.az + 180.0, 360.0);
  if (azimuth < 0.0) azimuth += 360.0;
  result.azimuth_deg = azimuth;
  result.elevation_deg = horizontal.alt;
  result.direction = SunDirectionFromElevationAzimuth(result.elevation_deg, result.azimuth_deg);
  return result;
}

}  // namespace skybake
