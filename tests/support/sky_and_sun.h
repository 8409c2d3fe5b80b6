// The default bake's sky and Sun shown together by real clients (issue 48:
// three.js, Babylon.js and Blender, in tests/engine_*_test.cc). The default
// style is baked twice: in half floats (what users load: `sky_latlong.exr`
// and the glTF sun) and in float32 (the reference). A client that shows the
// half bake's sky and lights an up-facing grey card with its sun and sky, at
// one exposure, must see what the float32 bake predicts, in cd/m^2:
//   sky    the float32 latlong along the views: four, 60 degrees up,
//          towards North, East, South and West, averaged. Clients differ
//          in the azimuth their panorama puts at its centre (quarter turns)
//          and in handedness (x mirrored); the four views' mean is the same
//          under both. (The zenith alone would be too: but Cycles blends a
//          panorama's top row with its bottom row within half a texel of the
//          pole, so a view of the pole shows some of the ground.)
//   card   albedo / pi x (E_sun + E_sky): E_sun = the manifest's
//          illuminance_lux x sin(elevation), E_sky = the float32 latlong's
//          upper hemisphere, L cos(theta) dOmega. Both are invariant under
//          the turns and mirrors about the vertical by which clients differ.
// World frame as skybake's: +Y up.
#pragma once

#include <string>
#include <vector>

#include <glm/vec3.hpp>

namespace skybake::testing {

// The grey card: linear albedo, Lambertian, facing up.
inline constexpr double kGreyCardAlbedo = 0.18;
// The square views the clients render: vertical field of view and pixels a side.
inline constexpr double kProbeFovDeg = 4.0;
inline constexpr int kProbeSize = 16;
// What the tests hold the clients to: each luminance, and the card-to-sky
// ratio (the "same units" property), within 5% of the float32 bake's.
inline constexpr double kClientTolerance = 0.05;

struct SkyAndSun {
  std::string half_dir;   // the default bake, half floats
  std::string float_dir;  // the same style with output.pixel_type = float

  // The float32 bake's manifest, frames[0].sun.
  double sun_illuminance_lux = 0.0;  // at normal incidence
  double sun_elevation_deg = 0.0;
  glm::dvec3 sun_irradiance{0.0};  // Rec.709, per channel, lux-like (its Y is illuminance_lux)

  // The half bake's glTF sun as written (KHR_lights_punctual): intensity, lux, and linear colour.
  double light_intensity = 0.0;
  glm::dvec3 light_color{0.0};

  // From the float32 latlong: the sky views' mean luminance (the probe
  // camera's pixels, each the latlong bilinearly at its direction), and the
  // sky's horizontal illuminance.
  double sky_cd_m2 = 0.0;
  double sky_horizontal_lux = 0.0;

  // The Sun's illuminance on the card, from the float32 manifest.
  double SunHorizontalLux() const;
  // What the glTF light gives the card in a client that lights with
  // intensity x colour (three.js, Babylon.js, Cycles): intensity x Y(colour)
  // x sin(elevation).
  double GltfLightHorizontalLux() const;
  // The card's luminance the float32 bake predicts.
  double CardCdM2() const;
};

// The sky views' directions, skybake's world (+Y up, North -Z), and the
// same as a page's query value "x,y,z;x,y,z;...".
std::vector<glm::dvec3> SkyProbeDirections();
std::string SkyProbeQuery();

// Bakes configs/default.toml at --size 64 with the validation layer on, into
// FreshTempDir(name)/half and /float, and reads SkyAndSun from the two. False
// after a test failure naming what failed.
bool BakeSkyAndSun(const std::string& name, SkyAndSun& out);

// Prints the client's figures against the float32 bake's and expects the
// sky, the card and their ratio within kClientTolerance. `sky` (the mean of
// the sky views) and `card` are the client's mean linear RGB, already divided by the one exposure
// factor the client was shown at; `card_sun_only` and `card_sky_only` the
// card under each light alone (printed, to say which term is off when one
// is).
void ExpectClientMatchesFloatBake(const std::string& client, const SkyAndSun& bake, const std::vector<double>& sky,
                                  const std::vector<double>& card, const std::vector<double>& card_sun_only,
                                  const std::vector<double>& card_sky_only);

}  // namespace skybake::testing
