// The tabulated spectra behind spectrum.h (spectral_tables.cc names their sources).
#pragma once

namespace skybake::spectral_tables {

struct AtmosphereRow {
  double lambda_nm;
  double solar_irradiance;       // W m^-2 nm^-1 at the top of the atmosphere
  double rayleigh_per_km;        // scattering at sea level
  double mie_scattering_per_km;  // at sea level
  double mie_extinction_per_km;
  double ozone_per_km;  // absorption at the tent peak
};
constexpr int kAtmosphereRows = 48;  // 360..830 nm every 10 nm
extern const AtmosphereRow kAtmosphere[kAtmosphereRows];

struct CieRow {
  double lambda_nm, xbar, ybar, zbar;
};
constexpr int kCieRows = 95;  // 360..830 nm every 5 nm
extern const CieRow kCie1931[kCieRows];

}  // namespace skybake::spectral_tables
