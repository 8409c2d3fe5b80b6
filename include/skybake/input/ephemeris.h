// The night sky's ephemeris at the cost of a frame: the Moon from one
// evaluation of its series, and the stars placed with a frame's axes
// computed once (astronomy.h has the rest).
#pragma once

#include <vector>

#include <glm/vec3.hpp>

#include "skybake/input/astronomy.h"

namespace skybake {

// The Moon's geocentric place from one evaluation of libnova's ELP 2000-82B
// series (every term), and what follows from it and the Sun's place
// (libnova's VSOP87) by Meeus, "Astronomical Algorithms" (2nd ed., 1998):
// the equatorial place (eq. 13.3, 13.4, with libnova's obliquity), the
// phase angle (eq. 48.2, 48.3), the lit fraction (eq. 48.1) and the bright
// limb (eq. 48.5). Referred, as libnova refers them, to the J2000 mean
// ecliptic (tests/input/astronomy_test.cc compares each with libnova's own
// function over 1900-2100). ComputeMoon takes its Moon from here.
struct LunarEphemeris {
  double ecliptic_longitude_deg = 0.0;  // [0, 360), as ln_get_lunar_ecl_coords
  double ecliptic_latitude_deg = 0.0;
  double distance_km = 0.0;  // Earth's centre to the Moon's
  double ra_deg = 0.0;       // [0, 360), as ln_get_lunar_equ_coords (not precessed)
  double dec_deg = 0.0;
  double sun_ra_deg = 0.0;  // as ln_get_solar_equ_coords
  double sun_dec_deg = 0.0;
  double phase_angle_deg = 0.0;  // Sun-Moon-Earth, [0, 180]
  double illuminated_fraction = 0.0;
  double bright_limb_deg = 0.0;          // [0, 360), from celestial north through east
  double ecliptic_elongation_deg = 0.0;  // Moon minus Sun ecliptic longitude, [0, 360)
};
LunarEphemeris ComputeLunarEphemeris(double julian_day_ut);

// The world direction of the J2000 unit `v` with a frame's axes: the
// rotation PlaceStars places each star by (the same arithmetic, so the
// same bits).
glm::dvec3 WorldFromJ2000(const J2000Axes& axes, const glm::dvec3& v);

// PlaceStars with the frame's axes given (J2000AxesAt, computed once).
std::vector<PlacedStar> PlaceStars(const StarCatalogue& catalogue, double magnitude_limit, const J2000Axes& axes,
                                   double min_elevation_deg);

}  // namespace skybake
