// The parameters of the physical atmosphere (atmosphere.glsl) and a sample
// of its medium, in the common GLSL/C++ subset: apart from the functions so
// that the C++ side can declare those (include/skybake/model/shared_glsl.h)
// without compiling them again. Units as in atmosphere.glsl.
#ifndef SKYBAKE_ATMOSPHERE_PARAMETERS_GLSL
#define SKYBAKE_ATMOSPHERE_PARAMETERS_GLSL

struct AtmosphereParameters {
  Real bottom_radius;           // km, planet radius
  Real top_radius;              // km, top of the atmosphere
  Real observer_altitude;       // km above bottom_radius
  vec3 rayleigh_scattering;     // km^-1 at altitude 0
  Real rayleigh_scale_height;   // km
  vec3 mie_scattering;          // km^-1 at altitude 0
  vec3 mie_extinction;          // km^-1 at altitude 0 (scattering + absorption)
  Real mie_scale_height;        // km
  Real mie_g;                   // Cornette-Shanks anisotropy, in (-1, 1)
  vec3 absorption_extinction;   // ozone, km^-1 at the tent peak
  Real ozone_peak_altitude;     // km
  Real ozone_half_width;        // km
  vec3 ground_albedo;           // Lambertian, unitless
  vec3 solar_irradiance;        // at the top of the atmosphere, output units
  Real sun_angular_radius;      // rad
  Real limb_darkening;          // u of the linear law I(m) = I0 (1 - u (1 - m))
  int transmittance_width;      // texels along mu
  int transmittance_height;     // texels along r
  int multiscattering_width;    // texels along mu_s
  int multiscattering_height;   // texels along altitude
  int view_steps;               // ray-march steps per output texel
  int transmittance_steps;      // quadrature points per transmittance texel
  int multiscattering_steps;    // ray-march steps per multi-scattering direction
  int multiscattering_sqrt_dirs;// directions per multi-scattering texel = this^2
  int integrator;               // INTEGRATOR_* of gpu_shared.h
  int light_steps;              // 0: sun transmittance from the LUT; N: N-step march
  int step_distribution;        // STEPS_UNIFORM or STEPS_QUADRATIC (gpu_shared.h)
  int sky_view_width;           // sky-view LUT texels along the azimuth from the Sun
  int sky_view_height;          // sky-view LUT texels along the zenith angle
  Real twilight_march_band;     // rad; 0: every texel reads the sky-view LUT
  int twilight_march_steps;     // view steps of the twilight band's march
  Real twilight_sun_sine;       // sine of the Sun's elevation below which a frame is twilight
  bool transmittance_log;       // the view samples' sun transmittance read in log (twilight frames)
  bool multiple_scattering;     // add Hillaire's multiple-scattering term
  bool sun_disc;                // add the limb-darkened solar disc
  bool ground;                  // add the sunlit Lambertian ground
  bool mie;                     // aerosols present
  bool ozone;                   // ozone absorption present
  Real multiple_scattering_strength;  // multiplies Psi_ms
  Real sun_disc_strength;       // multiplies the disc radiance
  bool night;                   // twilight and night dimming
  vec3 night_radiance;          // night-sky floor, units of solar_irradiance per sr
  Real night_strength;          // 0: off .. 1: the full night look
};

struct MediumSample {
  vec3 rayleigh_scattering;  // km^-1
  vec3 mie_scattering;       // km^-1
  vec3 extinction;           // km^-1, all three constituents
};

#endif  // SKYBAKE_ATMOSPHERE_PARAMETERS_GLSL
