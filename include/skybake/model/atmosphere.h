// The physical atmosphere and the sky render settings, as the host sees them.
//
// Frame: +Y up, right-handed; North = -Z, East = +X (so +Z is South).
// Units are in the field names: lengths in km unless named _m, scattering
// and absorption coefficients in km^-1, angles in degrees unless named _rad.
// Defaults are the Earth values of Hillaire 2020 (demo) and Bruneton 2017
// (precomputed_atmospheric_scattering, demo.cc), as collected in
// shared/CONVENTIONS.md. RGB triplets are the wavelengths 680, 550, 440 nm.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "skybake/gpu_shared.h"

namespace skybake {

using Rgb = std::array<double, 3>;

struct AtmosphereParams {
  double bottom_radius_km = 6360.0;     // Hillaire 2020 and Bruneton 2017
  double top_radius_km = 6460.0;        // Hillaire 2020 (Bruneton 2017: 6420)
  double observer_altitude_m = 0.0;     // above bottom_radius_km
  Rgb ground_albedo = {0.1, 0.1, 0.1};  // Bruneton 2017 (Hillaire 2020: 0)

  Rgb rayleigh_scattering_per_km = {5.802e-3, 13.558e-3, 33.100e-3};  // both papers
  double rayleigh_scale_height_km = 8.0;

  Rgb mie_scattering_per_km = {3.996e-3, 3.996e-3, 3.996e-3};  // both papers
  Rgb mie_extinction_per_km = {4.440e-3, 4.440e-3, 4.440e-3};  // scattering + absorption
  double mie_scale_height_km = 1.2;
  double mie_g = 0.8;  // Cornette-Shanks anisotropy, Bruneton 2017

  Rgb ozone_absorption_per_km = {0.650e-3, 1.881e-3, 0.085e-3};  // at the peak, both papers
  double ozone_peak_altitude_km = 25.0;                          // tent: 0 at 10 km, 1 at 25 km, 0 at 40 km
  double ozone_half_width_km = 15.0;

  // Solar irradiance at the top of the atmosphere, W m^-2 nm^-1
  // (Bruneton 2017 demo; Hillaire 2020 normalises it to 1).
  Rgb solar_irradiance = {1.474, 1.8504, 1.91198};
  double sun_angular_radius_rad = 0.004675;  // both papers
  // Linear limb-darkening coefficient u, I(m) = I0 (1 - u (1 - m)):
  // 0.6 is the classical visible-band value (Eddington approximation).
  double limb_darkening_u = 0.6;
};

// Integration settings. The defaults are the `production` preset, chosen
// from the accuracy study (docs/accuracy.md): max relative error of
// single scattering over the upper hemisphere, sun 3..90 deg (3.65e-3).
struct QualitySettings {
  int view_steps = 32;                // ray-march steps per output texel (or sky-view texel)
  int transmittance_steps = 256;      // quadrature points per transmittance texel
  int multiscattering_steps = 20;     // Hillaire 2020 uses 20
  int multiscattering_sqrt_dirs = 8;  // 64 directions, Hillaire 2020
  int transmittance_width = 256;      // Hillaire 2020: 256 x 64
  int transmittance_height = 64;
  int multiscattering_size = 32;  // Hillaire 2020: 32 x 32
  int integrator = INTEGRATOR_ANALYTIC;
  // Sun transmittance at each view sample: 0 reads the transmittance LUT,
  // N > 0 marches N midpoint steps towards the Sun (Galaj 2019's light samples).
  int light_steps = 0;
  int step_distribution = STEPS_QUADRATIC;  // STEPS_UNIFORM is the paper's
  // In-scattering per output texel: ray-marched (false), or read from a
  // per-frame sky-view LUT of this size (Hillaire 2020 section 5.3).
  bool sky_view_lut = true;
  int sky_view_width = 256;
  int sky_view_height = 144;
  // Wavelengths rendered: 3 is the 680/550/440 nm path (RGB channels); 4..48
  // is the spectral mode (spectrum.h): that many bins over 355..835 nm,
  // rendered three at a time and integrated to CIE XYZ, then Rec.709.
  int wavelengths = 3;
  // At twilight (the Sun below this elevation, deg), the sky within this
  // elevation above the observer's horizon is ray-marched per texel instead
  // of read from the sky-view LUT: the Earth's shadow crosses it faster than
  // the LUT's rows resolve (docs/accuracy.md, "Twilight"). 0: off.
  double twilight_march_band_deg = 10.0;
  // View steps of that march, and of every texel's in a twilight frame
  // without the sky-view LUT (0: view_steps).
  int twilight_march_steps = 80;
  // The Sun's elevation (deg) below which a frame is twilight: its pipeline
  // marches the band and reads the view samples' sun transmittance from the
  // LUT in the logarithm (grazing sunlight, docs/accuracy.md "Twilight").
  // 0: the band's elevation.
  double twilight_sun_below_deg = 3.0;
};

// The Sun's elevation (deg) below which `q` renders a frame as twilight (0: never).
double TwilightSunElevationDeg(const QualitySettings& q);

// The Sun's depression below the horizontal (deg) beyond which an observer
// inside the atmosphere sees no sunlit air (radii in km, the observer's
// altitude above the bottom in km, the Sun's angular radius in rad): the
// view ray that reaches furthest towards the Sun grazes the horizon (the dip
// acos(R_b / r) below the horizontal) and leaves the top acos(R_b / R_t)
// beyond the point it grazes, where the horizon lies acos(R_b / R_t) below
// that point's horizontal; the Sun's disc sets there a radius later. Plus a
// margin of 0.5 deg, so that a frame past it has no view ray outside the
// umbra (TwilightMarchWeight's test, shaders/atmosphere.glsl) at float
// rounding either. From space (an observer above the top): 180 deg.
double SunlitAirDepressionDeg(double bottom_radius_km, double top_radius_km, double observer_altitude_km,
                              double sun_angular_radius_rad);

// Whether a Sun at `sun_elevation_deg` leaves sunlit air in the observer's
// view: above -SunlitAirDepressionDeg (always from space). A frame without
// renders with the day pipeline (SkyRenderer::MarchesTwilightBand, the
// reference model and the pass plan agree through this test).
bool SunlitAirInView(double sun_elevation_deg, double bottom_radius_km, double top_radius_km,
                     double observer_altitude_km, double sun_angular_radius_rad);

// The named presets, chosen from the accuracy study (docs/accuracy.md):
// "draft", "production" (the defaults of QualitySettings), "reference".
QualitySettings QualityPreset(const std::string& name);
std::vector<std::string> QualityPresetNames();

// Optional physical effects; each off effect is compiled out of the shaders.
struct EffectSettings {
  bool multiple_scattering = true;
  bool sun_disc = true;
  bool ground = true;                         // the sunlit ground and its bounce into multiple scattering
  bool mie = true;                            // aerosols
  bool ozone = true;                          // ozone absorption
  double multiple_scattering_strength = 1.0;  // artistic multiplier of Hillaire's Psi_ms
  double sun_disc_strength = 1.0;             // artistic multiplier of the disc radiance
  // Twilight and night dimming: from sun -6 deg to -18 deg the sky blends to a
  // night-sky floor of this luminance (cd/m^2; 1.7e-4 is a dark natural sky,
  // 22 mag/arcsec^2 by L = 10.8e4 x 10^(-0.4 m) cd/m^2).
  bool night_dimming = false;
  double night_dimming_strength = 1.0;
  double night_sky_luminance_cd_m2 = 1.7e-4;
};

// The night-sky floor as radiance in the renderer's spectral units (W m^-2
// sr^-1 nm^-1 at 680/550/440 nm), neutral in Rec.709, from its luminance.
Rgb NightSkyRadiance(const EffectSettings& effects);

// Whether the transmittance LUT is read: by the sun transmittance unless
// marched (light_steps > 0), by multiple scattering, the ground and the disc.
bool NeedsTransmittanceLut(const QualitySettings& quality, const EffectSettings& effects);

// Unit vector towards the Sun from its elevation above the horizon and its
// azimuth clockwise from North (compass bearing), in degrees.
glm::dvec3 SunDirectionFromElevationAzimuth(double elevation_deg, double azimuth_deg);

// Packs the parameters into the uniform block the shaders read. `output_scale`
// multiplies radiance per channel (see OutputUnits in config.h).
gpu::GpuAtmosphere ToGpuAtmosphere(const AtmosphereParams& atmosphere, const QualitySettings& quality,
                                   const EffectSettings& effects, const Rgb& output_scale);

}  // namespace skybake
