// The [night] table of a style: the stars, the Moon's disc and moonlight
// (night_sky.h says what each adds and how). All off by default; a style
// with every one off resolves, bakes and records itself as one without the
// table.
#pragma once

#include <string>

namespace skybake {

// The style's [night] table (configs/default.toml).
struct NightSettings {
  bool stars = false;
  std::string star_catalogue;  // "" = DefaultStarCataloguePath(); relative to the style's folder
  // The --set argument that gave star_catalogue ("--set night.star_catalogue=..."),
  // or "" when the style file did: its errors point there, and a relative
  // path is then taken from the working directory, as any command-line path.
  std::string star_catalogue_set;
  double star_magnitude_limit = 6.5;  // V; stars fainter are left out; [-1.5, 14]
  bool moon = false;                  // the Moon's disc
  bool moonlight = false;             // the Moon as a second light (sky, SH, IBL, glTF)
  // The natural night-sky glow with the van Rhijn brightening towards the
  // horizon, replacing the flat floor of effects.night_dimming; its zenith
  // luminance is effects.night_sky_luminance_cd_m2.
  bool airglow = false;
  double airglow_height_km = 90.0;  // the emitting layer (Leinert et al. 1998: 90 km); (0, 500]
  bool Any() const { return stars || moon || moonlight || airglow; }
};

inline constexpr double kMinStarMagnitudeLimit = -1.5;  // brighter than Sirius (-1.44): no stars
inline constexpr double kMaxStarMagnitudeLimit = 14.0;  // d3-celestial's deepest file ends at 13.78

}  // namespace skybake
