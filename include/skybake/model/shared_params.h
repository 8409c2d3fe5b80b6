// Fills the physical fields of an AtmosphereParameters of the shared
// GLSL/C++ code (shaders/atmosphere.glsl) from the host's AtmosphereParams,
// for any instantiation of that code on the CPU. The GPU side does the same
// from the uniform block (shaders/common.glsl, AtmosphereFromUniform).
#pragma once

#include "skybake/model/atmosphere.h"

namespace skybake {

template <class Atm>
void FillPhysicalParameters(const AtmosphereParams& a, Atm& atm) {
  using Vec3 = decltype(atm.rayleigh_scattering);
  auto v = [](const Rgb& c) { return Vec3(c[0], c[1], c[2]); };
  atm.bottom_radius = a.bottom_radius_km;
  atm.top_radius = a.top_radius_km;
  atm.observer_altitude = a.observer_altitude_m * 1e-3;
  atm.rayleigh_scattering = v(a.rayleigh_scattering_per_km);
  atm.rayleigh_scale_height = a.rayleigh_scale_height_km;
  atm.mie_scattering = v(a.mie_scattering_per_km);
  atm.mie_extinction = v(a.mie_extinction_per_km);
  atm.mie_scale_height = a.mie_scale_height_km;
  atm.mie_g = a.mie_g;
  atm.absorption_extinction = v(a.ozone_absorption_per_km);
  atm.ozone_peak_altitude = a.ozone_peak_altitude_km;
  atm.ozone_half_width = a.ozone_half_width_km;
  atm.ground_albedo = v(a.ground_albedo);
  atm.solar_irradiance = v(a.solar_irradiance);
  atm.sun_angular_radius = a.sun_angular_radius_rad;
  atm.limb_darkening = a.limb_darkening_u;
}

}  // namespace skybake
