// The night sky in the maps: stars, the Moon's disc and moonlight, added to
// the rendered sky of a frame whose clock time and place are known (a
// schedule of clock times). Every part is off by default; with all of it
// off nothing here runs and the outputs are byte for byte those of a style
// without a [night] table.
//
// - Stars (night.stars): the catalogue's stars brighter than
//   night.star_magnitude_limit (astronomy.h), each an irradiance at the top
//   of the atmosphere times the atmosphere's own transmittance along its
//   direction (the shared transmittance integral of shaders/atmosphere.glsl,
//   in double, tabulated over the cosine of the zenith angle), zero below the
//   ground. Each is splatted bilinearly into the texels around its
//   direction with weights divided by the texels' solid angles, so its
//   energy (sum of radiance x solid angle) equals its irradiance at every
//   resolution and moves continuously between frames (no popping). Stars
//   are added to every frame: by day they fall below the sky's radiance by
//   the physics alone; an addition under 2^-13 of a texel's own value (a
//   quarter of half float's resolution) is left out, so a day frame's maps
//   are not copied at all; while the Sun is up two bounds find where that
//   is certain: by tiles first (BoundByTiles, which skips whole views), then
//   by texels (SplatBound), and only what reaches the others is splatted.
// - The Moon (night.moon): its disc, of the angular radius from its
//   topocentric distance, lit by the Sun with the Lommel-Seeliger law
//   L ~ mu0 / (mu0 + mu) (mu0, mu: cosines of incidence and emission; the
//   classic law for the lunar regolith, e.g. Hapke 2012 "Theory of
//   Reflectance and Emittance Spectroscopy" sec. 9.4, without Hapke's
//   opposition surge), scaled so that the disc's integral is the Krisciunas
//   & Schaefer 1991 illuminance at its phase (astronomy.h). Its spectrum is
//   the Sun's (the Moon's slight reddening is not modelled; no earthshine).
//   The disc is sampled on a grid in its own plane and each sample splatted
//   as a star, with its own transmittance (a Moon at the horizon sinks
//   behind the ground sample by sample).
// - Moonlight (night.moonlight): the Moon as a second light of the
//   scattering: the same renderer, with the Moon's direction as the light's
//   and neither sun disc nor night dimming, its output times
//   E_moon / E_sun (their illuminances at the top of the atmosphere), added
//   to the maps, to the SH and to the IBL source; so a moonlit sky is a
//   dim blue daylit sky. Rendered while the Sun is below the horizon and the
//   Moon above -10 deg (lunar twilight); above the horizon the Sun's sky is
//   over 2^11 times brighter (tests/pipeline/night_sky_test.cc) and it adds nothing
//   a half float can hold. Volumetric cloud layers are not lit by the Moon.
//
// Frame: skybake's, +Y up, North -Z, East +X. Irradiances are in the
// output units times sr (as FrameResult::sun_irradiance).
#pragma once

#include <array>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include <glm/vec3.hpp>

#include "skybake/input/astronomy.h"
#include "skybake/model/atmosphere.h"
#include "skybake/output/exr_io.h"
#include "skybake/input/night_settings.h"
#include "skybake/model/sh.h"
#include "skybake/gpu/ibl.h"
#include "skybake/gpu/sky_renderer.h"

namespace skybake {

struct SkyStyle;
struct ConfigError;
struct Schedule;
class StarGrid;
class PendingStars;
struct RectCone;

// Relative addition below which a splat is left out (see above).
inline constexpr double kNightSplatMinRelative = 1.0 / 8192.0;

// The catalogue path a style names (resolved against its folder), or
// `default_catalogue` when it names none (night.star_catalogue = "").
std::string StarCataloguePathOf(const SkyStyle& style, const std::string& default_catalogue);

// Errors of the night sky found before any GPU work: a catalogue that is
// missing, unreadable or not a star file; night features in a bake whose
// frames have no clock time and place (a single bake, or a schedule of sun
// positions). `styles`: every frame's style; `schedule`: null for a single
// bake. Each error is located at the style's [night] key.
std::vector<ConfigError> CheckNightSky(const std::vector<const SkyStyle*>& styles, const Schedule* schedule,
                                       const std::string& default_catalogue);

// A point source at the observer: unit direction and irradiance (output
// units x sr), after the atmosphere.
struct PointSource {
  glm::dvec3 direction{0.0, 1.0, 0.0};
  Rgb irradiance{0.0, 0.0, 0.0};
};

// Solid angle, sr, of texel (x, y) of a view (latlong, cube strip or face).
// A latlong's last column repeats its first (longitude -pi = +pi): it is
// given 0, so the sum over the view is 4 pi.
double ViewTexelSolidAngle(const ViewRequest& view, int x, int y);

// One texel's addition.
struct TexelAdd {
  size_t texel = 0;  // index into the view's texels (row-major from the top)
  float rgb[3] = {0.0f, 0.0f, 0.0f};
};

// The bilinear, energy-conserving splat of `sources` into `view`: for each
// source the four texels around its direction (in the face it falls on; a
// latlong wraps in longitude and writes the repeated column too), weights
// renormalized within the view, radiance = irradiance x weight / solid
// angle. Additions to one texel are summed.
std::vector<TexelAdd> SplatPointSources(const ViewRequest& view, const std::vector<PointSource>& sources);

// Adds `adds` to RGBA texels. With `rgba_in` (the view's current texels),
// an addition whose largest channel is under `min_relative` of the texel's
// largest channel is dropped; returns how many were applied.
size_t ApplyTexelAdds(const std::vector<TexelAdd>& adds, const float* rgba_in, float* rgba_out, double min_relative);

// The bound that spares a frame the splat when it cannot change the maps
// (a day frame's stars and Moon under a bright sky). A texel's load is the
// sum of the largest channel of the irradiance of every source that has it
// among its targets (a latlong's repeated meridian with column 0); a
// texel's addition (largest channel) is at most its load over its solid
// angle (a source's weights are at most 1), so where the load is under
// min_relative x (the texel's largest channel) x (its solid angle)
// ApplyTexelAdds drops the addition. Only the sources that reach the other
// ("open") texels need the splat, and only their additions to open texels
// are kept: each texel kept gets the same sum, formed in the same order, as
// in the whole splat, so the maps are byte for byte the same
// (tests/pipeline/night_sky_test.cc). No open texel: nothing to splat. The bound
// costs the texel lookups of the splat (shared with it), a sort of the
// texels reached and one solid angle per texel.
struct SplatBound {
  std::vector<size_t> sources;  // the indices of those that reach an open texel, increasing
  std::vector<size_t> open;     // the open texels, increasing
};
// SplatPointSources through the bound: its additions to the open texels.
// `rgba`: the view's texels as they are before the splat; `bound`: what it
// found, when wanted.
std::vector<TexelAdd> BoundedSplat(const ViewRequest& view, const std::vector<PointSource>& sources, const float* rgba,
                                   double min_relative, SplatBound* bound = nullptr);

// The first, coarse look, before any splat (a day frame then pays neither
// the splat nor SplatBound's per-texel work): the view's texels in tiles of
// kSplatTileSize^2 (a cube strip's within one face), each with its smallest
// solid angle (from its corner texels: a texel's solid angle falls away from
// the face's centre, and a latlong row's towards the poles) and the range of
// mu = cos(zenith angle) of its texels. A tile's load is the sum of the
// largest channel of the irradiance of every source with a splat target in
// it, its floor the smallest largest channel of its texels; where the load
// is under min_relative x floor x smallest solid angle (less the margin of
// SplatBound), no texel of the tile can take an addition (a texel's load is
// at most its tile's). The airglow, at most the largest entry of its table
// over the tile's range of mu, is under min_relative x floor there, or it
// may show. Costs one target lookup per source and one read of the texels
// of the tiles a source or the glow reaches.
inline constexpr int kSplatTileSize = 16;
class SplatTiles {
 public:
  // `mu`: the view's texel mu (row-major), for the airglow's ranges; may be empty.
  SplatTiles(const ViewRequest& view, const std::vector<float>& mu);
  int count() const { return int(min_solid_angle_.size()); }
  int TileOf(int x, int y) const;
  // The tile's texels: columns [x0, x1), rows [y0, y1).
  void Rect(int tile, int& x0, int& x1, int& y0, int& y1) const;
  double min_solid_angle(int tile) const { return min_solid_angle_[size_t(tile)]; }
  float min_mu(int tile) const { return mu_range_.empty() ? -1.0f : mu_range_[2 * size_t(tile)]; }
  float max_mu(int tile) const { return mu_range_.empty() ? 1.0f : mu_range_[2 * size_t(tile) + 1]; }

 private:
  ViewRequest view_;
  int tiles_x_ = 0, tiles_per_face_ = 0, face_rows_ = 0;
  std::vector<double> min_solid_angle_;
  std::vector<float> mu_range_;
};
struct TileBound {
  bool splat = false;           // some tile a source reaches may take an addition
  bool airglow = false;         // some tile may take the glow
  std::vector<size_t> sources;  // the sources with a target in such a tile, increasing
  size_t tiles_read = 0;        // tiles whose texels were read
};
// `airglow`: the glow's table (AirglowTable), or empty.
TileBound BoundByTiles(const ViewRequest& view, const SplatTiles& tiles, const std::vector<PointSource>& sources,
                       const std::vector<Rgb>& airglow, const float* rgba, double min_relative);

// The darkest texel of a rectangle of RGBA texels (row width `width`):
// the smallest of their largest channels, over columns [x0, x1) and rows
// [y0, y1).
float RectFloor(const float* rgba, int width, int x0, int x1, int y0, int y1);

// The atmosphere's transmittance from the observer to space along a
// direction, as a table over mu = cos(zenith angle): the shared integral
// (ReferenceModel::TransmittanceDirect, 256 steps) at 4096 values of mu,
// read linearly; zero where the ray meets the ground.
class TransmittanceTable {
 public:
  TransmittanceTable(const AtmosphereParams& atmosphere, const QualitySettings& quality, const EffectSettings& effects);
  Rgb At(double mu) const;
  // The largest entry of any channel: no At is above it.
  double LargestEntry() const;
  // Rays below it meet the ground (At is zero there).
  double mu_horizon() const { return mu_horizon_; }

 private:
  std::vector<Rgb> table_;
  double mu_horizon_ = 0.0;  // rays below it meet the ground
};

// What the night adds to one frame.
struct NightFrame {
  std::vector<PointSource> sources;    // stars and samples of the Moon's disc, attenuated
  size_t stars = 0;                    // of which stars
  std::optional<MoonState> moon;       // with night.moon or night.moonlight
  Rgb moon_irradiance{0.0, 0.0, 0.0};  // the Moon at the observer, output units x sr (after the atmosphere)
  double moon_illuminance_lux = 0.0;   // the same as illuminance
  double moonlight_scale = 0.0;        // E_moon / E_sun at the top of the atmosphere; 0: no moonlit sky this frame
  bool daylight = false;               // the Sun above the horizon: splats go through SplatBound
  // A day frame's stars before placement (night_prune.h): `sources` holds
  // the Moon's samples alone and `stars` is 0 until a view needs the stars
  // (PendingStars::Placed). Null when the stars are placed (or off).
  std::shared_ptr<PendingStars> pending;
  // With night.airglow: the glow's radiance by mu = cos(zenith angle) of
  // the view (output units), AirglowTable.
  std::vector<Rgb> airglow;
};

// The night-sky glow of a thin layer at `height_km` above the ground of
// `atmosphere` with zenith luminance `zenith_cd_m2` (neutral), seen through
// the atmosphere, at kAirglowEntries values of mu from -1 to 1: the van
// Rhijn 1921 brightening V(z) = 1 / sqrt(1 - (r / (R + h))^2 sin^2 z)
// (r: the observer's radius, R: the ground's) times the transmittance
// relative to the zenith's (Leinert et al. 1998, A&AS 127, 1, sec. 9); zero
// behind the ground. In `output` units.
inline constexpr int kAirglowEntries = 2048;
std::vector<Rgb> AirglowTable(const AtmosphereParams& atmosphere, const TransmittanceTable& t, double height_km,
                              double zenith_cd_m2, OutputUnits output);
// The table read at `mu` (nearest entry below, linear).
Rgb AirglowAt(const std::vector<Rgb>& table, double mu);
// At least the largest channel of AirglowAt over mu in [lo, hi]: the
// largest of the entries that range reads.
double AirglowMaxOver(const std::vector<Rgb>& table, double lo, double hi);

// Stars are placed above this elevation (the splat's targets near the
// horizon), and shown where the transmittance is not zero.
inline constexpr double kStarMinElevationDeg = -5.0;
// The catalogue's stars to `magnitude_limit` placed at `julian_day_ut` and
// `place`, attenuated by `t`, in `units` (x sr): the splat's star sources.
std::vector<PointSource> StarSources(const StarCatalogue& catalogue, double magnitude_limit, OutputUnits units,
                                     const TransmittanceTable& t, double julian_day_ut, const GeoLocation& place);

// The night of one frame at `julian_day_ut` and `place`, with the Sun along
// `sun` (unit). `catalogue` is needed with night.stars. `style`: pruned.
// With `defer` (the catalogue's StarGrid) and the Sun up, the stars wait
// (NightFrame::pending) for a view that needs them.
NightFrame ComputeNightFrame(const SkyStyle& style, const StarCatalogue* catalogue, const TransmittanceTable& t,
                             double julian_day_ut, const GeoLocation& place, const glm::dvec3& sun,
                             const StarGrid* defer = nullptr);

// The Moon's disc as point sources (before the atmosphere) with total
// irradiance `disc_irradiance` (output units x sr, at the top of the
// atmosphere): Lommel-Seeliger with the Sun along `sun`; `samples_across`
// grid points across the disc.
std::vector<PointSource> MoonDiscSources(const glm::dvec3& moon, double angular_radius_rad, const glm::dvec3& sun,
                                         const Rgb& disc_irradiance, int samples_across);

// Adds a frame's night to rendered views: the point sources, and with
// moonlight the moonlit sky (rendered here). A view whose texels change is
// copied first (images[i].view cleared, rgba filled); the others are left
// where they are. Owns the moonlight renderer (built on first use).
class NightSkyRenderer {
 public:
  explicit NightSkyRenderer(VulkanContext& context);
  ~NightSkyRenderer();

  // `style`: pruned; `views` and `images` in the same order.
  void AddToViews(const SkyStyle& style, const NightFrame& night, const std::vector<ViewRequest>& views,
                  std::vector<RgbaImage>& images);
  // The same for faces held in vectors (SH and IBL sources, no sun disc).
  void AddToFaces(const SkyStyle& style, const NightFrame& night, const std::vector<ViewRequest>& views,
                  std::vector<std::vector<float>>& faces);

  int moonlight_renders() const { return moonlight_renders_; }
  // With false, every splat runs whole (neither BoundByTiles nor
  // SplatBound; by night SplatBound is not used anyway) and the glow is
  // checked texel by texel: for the test that the bounds change no byte.
  void set_splat_bound(bool on) { splat_bound_ = on; }
  // With false, only the tile bound is off (SplatBound still runs by day):
  // what a day frame paid before it, for the measurement.
  void set_tile_bound(bool on) { tile_bound_ = on; }
  // Views (and faces) whose splat the bounds skipped altogether (of which
  // the tile bound alone, BoundByTiles), and those splatted (in part or
  // whole), since construction.
  size_t splats_skipped() const { return splats_skipped_; }
  size_t splats_skipped_by_tiles() const { return tiles_skipped_; }
  size_t splats_run() const { return splats_run_; }
  // Views (and faces) of frames with their stars pending that the bound
  // before placement (night_prune.h) cleared: neither stars placed nor
  // anything splatted or copied for them.
  size_t views_cleared_before_placement() const { return cleared_before_placement_; }
  double last_moonlight_seconds() const { return last_moonlight_seconds_; }

 private:
  std::vector<std::vector<float>> MoonlitSky(const SkyStyle& style, const NightFrame& night,
                                             const std::vector<ViewRequest>& views);
  // mu = cos(zenith angle) of every texel of a view, computed once.
  const std::vector<float>& TexelMu(const ViewRequest& view);
  // The splat of `sources` into `view` over `rgba`, through the bound while
  // the Sun is up (SplatBound).
  std::vector<TexelAdd> BoundedSplat(const ViewRequest& view, const std::vector<PointSource>& sources,
                                     const float* rgba, bool daylight);
  // What may change `rgba` (the view's texels): BoundByTiles, or with the
  // bounds off everything.
  TileBound Bound(const ViewRequest& view, const NightFrame& night, const std::vector<PointSource>& sources,
                  const float* rgba);
  // The frame to add to the view: null when its stars are pending and the
  // bound before placement clears the view, else the frame with its stars
  // placed. `with_moon`: the Moon's samples are splatted here.
  const NightFrame* ForView(const ViewRequest& view, const NightFrame& night, const float* rgba, bool with_moon);
  const SplatTiles& TilesOf(const ViewRequest& view, bool with_mu);
  bool splat_bound_ = true, tile_bound_ = true;
  size_t splats_skipped_ = 0, splats_run_ = 0, tiles_skipped_ = 0, cleared_before_placement_ = 0;
  std::map<std::array<int, 5>, std::unique_ptr<SplatTiles>> tiles_;
  std::map<std::array<int, 4>, std::unique_ptr<std::vector<RectCone>>> cones_;  // per view, of TilesOf(view, false)
  VulkanContext& context_;
  std::map<std::array<int, 4>, std::vector<float>> texel_mu_;
  std::unique_ptr<SkyRenderer> moonlight_;
  gpu::GpuAtmosphere moonlight_key_{};
  int moonlight_renders_ = 0;
  double last_moonlight_seconds_ = 0.0;
};

// The night sky's host passes in the pass plan (`skybake plan`): the star
// and Moon splat and the airglow, per frame, with what prunes them: the
// tile bound (BoundByTiles) in the frames with the Sun up, which skips
// every view where no addition can reach 2^-13 of a texel.
struct PassPlan;
void AddNightSkyPlan(const std::vector<SkyStyle>& frames, PassPlan& plan);

// Catalogues by path, loaded once per bake; throws ConfigFailure when one
// cannot be read.
class StarCatalogues {
 public:
  const StarCatalogue& Get(const std::string& path);

 private:
  std::map<std::string, StarCatalogue> loaded_;
};

// The night sky of a bake (pipeline.cc): made before any GPU work, it reads
// the catalogues (throws ConfigFailure when one cannot be read) and then
// serves each frame. Null when no frame has any of it.
class NightSkyBake {
 public:
  ~NightSkyBake();
  // `default_catalogue`: the catalogue of a style that names none
  // (BakeOptions::star_catalogue).
  static std::unique_ptr<NightSkyBake> For(const std::vector<const SkyStyle*>& styles, const Schedule* schedule,
                                           const std::string& default_catalogue);

  // The frame's night (CPU), or nothing when its style has none. `style`
  // as given (pruned here), `time` the frame's clock time.
  std::optional<NightFrame> Frame(const SkyStyle& style, const std::optional<CivilTime>& time, const glm::dvec3& sun);
  // The frame's record of the Moon, and its light added to the SH of the
  // sky with the Sun (the Moon's disc is a directional light there, as the
  // Sun's) when night.moonlight.
  void RecordMoon(const SkyStyle& style, const NightFrame& night, ShRgb& sh_radiance_with_lights,
                  std::optional<MoonRecord>& record) const;
  // The Moon as the IBL's second point source (IblRequest::moon) when the
  // style has the Moon (night.moon or night.moonlight) and
  // ibl.include_sun: the maps then hold the Moon's energy as the Sun's.
  static void AddMoonToIbl(const SkyStyle& style, const NightFrame& night, IblRequest& request);
  // Host time spent in Frame, AddToViews and AddToFaces (the moonlit
  // renders included) since the last call, s; and what a frame adds, for
  // the progress line.
  double TakeSeconds();
  static std::string Describe(const NightFrame& night);
  // `renderer`: the bake's, made after (and so destroyed before) its Vulkan context.
  void AddToViews(NightSkyRenderer& renderer, const SkyStyle& style, const NightFrame& night,
                  const std::vector<ViewRequest>& views, std::vector<RgbaImage>& images);
  void AddToFaces(NightSkyRenderer& renderer, const SkyStyle& style, const NightFrame& night,
                  const std::vector<ViewRequest>& views, std::vector<std::vector<float>>& faces);

 private:
  double seconds_ = 0.0;
  GeoLocation place_;
  std::string default_catalogue_;
  StarCatalogues catalogues_;
  std::vector<std::pair<std::vector<unsigned char>, std::unique_ptr<TransmittanceTable>>> tables_;
  std::map<std::tuple<std::string, double, int>, std::unique_ptr<StarGrid>> grids_;  // by catalogue, limit, units
};

}  // namespace skybake
