// The night sky's bound before the stars are placed: a day frame none of
// whose views a star, the Moon or the airglow can change places no star and
// splats nothing (night_sky.h has the bounds that follow placement).
//
// A view is cut into the tiles of SplatTiles and each tile into a cone: a
// direction and a radius that hold the centre of every texel in it and
// every point source with a splat target in it (ConeOfRect). Before
// placement, the stars in a cone are bounded from the catalogue itself,
// binned by J2000 position (StarGrid): a frame's placement is a rotation
// (J2000Axes, astronomy.h), so the stars near a world direction are those
// near its J2000 direction. A tile whose bound is under 2^-13 x its
// darkest texel x its smallest solid angle cannot take a byte, as in
// BoundByTiles; one that is not is cut in four, down to single texels
// (the latlong's polar rows, whose texels are tiny). A single texel that
// does not clear so is looked at star by star (UnplacedLight::table): its
// nearby stars placed and weighed as the splat would (WeightedTexelLoad).
// The airglow is bounded over each cone's range of mu. The Moon's disc
// samples, placed already, are bounded by their total over the disc's cone.
//
// When every tile of a view clears, the view is left as it is; when one
// does not, the frame's stars are placed (PendingStars, once) and that view
// and the ones after it go through BoundByTiles and SplatBound as in a
// frame placed at once, so the maps are the same bytes
// (tests/pipeline/night_sky_test.cc). Used while the Sun is up (by night nearly
// every tile takes a star).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include <glm/vec3.hpp>

#include "skybake/input/astronomy.h"
#include "skybake/pipeline/night_sky.h"

namespace skybake {

// StarSources with the frame's axes given (J2000AxesAt, computed once):
// PendingStars places its stars with the axes the bound used.
std::vector<PointSource> StarSources(const StarCatalogue& catalogue, double magnitude_limit, OutputUnits units,
                                     const TransmittanceTable& t, const J2000Axes& axes);

// The load of one texel (x, y) of `view` with the sources' weights: the
// sum over `sources` of the largest channel of each one's irradiance times
// its weight at the texel, renormalized within the view as the splat does
// (a latlong's last column takes its first's). The texel's addition
// (largest channel) is at most this over its solid angle; SplatBound's load
// is the same with every weight taken as 1.
double WeightedTexelLoad(const ViewRequest& view, const std::vector<PointSource>& sources, int x, int y);

// The catalogue's stars to a magnitude limit in cells of 0.5 deg of
// declination and right ascension (J2000), each cell the sum of its stars'
// E: the largest channel of the irradiance at the top of the atmosphere in
// `units`, as the splat forms it (StarSources) before the transmittance.
class StarGrid {
 public:
  StarGrid(const StarCatalogue& catalogue, double magnitude_limit, OutputUnits units);
  // At least the sum of E of the stars within `radius_rad` of the J2000
  // unit `direction`: the cells that meet the cone's box in declination and
  // right ascension (the box of a cap of radius r at declination d spans
  // d +- r and, off the poles, RA +- asin(sin r / cos d)).
  double SumWithin(const glm::dvec3& direction, double radius_rad) const;
  double total() const { return total_; }
  // A star of the grid: its J2000 unit vector (as PlaceStars forms it), its
  // irradiance at the top of the atmosphere in `units` (as StarSources forms
  // it before the transmittance) and E, its largest channel.
  struct Star {
    glm::dvec3 j2000{0.0, 0.0, 1.0};
    Rgb top{0.0, 0.0, 0.0};
    double e = 0.0;
  };
  // Every star within `radius_rad` of `direction` (and others of the same
  // cells), appended to `out`.
  void StarsWithin(const glm::dvec3& direction, double radius_rad, std::vector<Star>& out) const;

 private:
  static constexpr int kRows = 360, kColumns = 720;
  // Calls cells(row, a, b) for the columns [a, b] of each row of the cells
  // that meet the cone's box (a > b: the row wraps, [a, end) and [0, b]);
  // false when the cone holds a hemisphere or more (every cell).
  template <typename Cells>
  bool ForCellsWithin(const glm::dvec3& direction, double radius_rad, Cells cells) const;
  std::vector<double> prefix_;   // per row, kColumns + 1 running sums
  std::vector<uint32_t> first_;  // the stars of cell k: stars_[first_[k], first_[k + 1])
  std::vector<Star> stars_;
  double total_ = 0.0;
};

// A rectangle of a view's texels, columns [x0, x1) and rows [y0, y1)
// (within one face of a strip), as the bound sees it.
struct RectCone {
  glm::dvec3 centre{0.0, 1.0, 0.0};  // the direction of its middle texel
  double texel_radius_rad = 0.0;     // holds the direction of every texel centre in it
  // holds every point source with a splat target in it: the texel radius
  // plus the farthest a source is from its targets (one cell's diagonal:
  // 2 sqrt 2 / n on the face plane, or a latitude step plus a longitude
  // step at the widest row involved)
  double reach_rad = 0.0;
  double min_solid_angle = 0.0;         // sr, its smallest texel's (a corner's)
  float min_mu = -1.0f, max_mu = 1.0f;  // holds mu = cos(zenith angle) of its texels
};
RectCone ConeOfRect(const ViewRequest& view, int x0, int x1, int y0, int y1);

// What the bound knows of a frame before its stars are placed.
struct UnplacedLight {
  const StarGrid* stars = nullptr;  // null: no stars
  J2000Axes axes;
  double star_transmittance = 1.0;  // the transmittance table's largest entry
  double min_source_mu = -1.0;      // every star source is above it
  double moon_total = 0.0;          // the largest channels of the Moon's samples, summed
  glm::dvec3 moon_centre{0.0, 1.0, 0.0};
  double moon_radius_rad = 0.0;               // every sample is within it of the centre
  const std::vector<Rgb>* airglow = nullptr;  // null or empty: none
  // With it (and `stars`), a single texel the bound above does not clear
  // is looked at star by star: the grid's stars near it placed and
  // attenuated as StarSources places and attenuates them, with their
  // weights at the texel (WeightedTexelLoad).
  const TransmittanceTable* table = nullptr;
};

// Whether no addition of `light` can reach `min_relative` of a texel of
// `rgba` (the view's texels): every tile of `tiles` (with its cone in
// `cones`) clears, cut in four where needed. `rects_read`: how many
// rectangles' texels were read, when wanted.
bool ClearsBeforePlacement(const ViewRequest& view, const SplatTiles& tiles, const std::vector<RectCone>& cones,
                           const UnplacedLight& light, const float* rgba, double min_relative,
                           size_t* rects_read = nullptr);

// A day frame's stars, waiting (NightFrame::pending): placed on the first
// view that needs them.
class PendingStars {
 public:
  // Every reference outlives the frame (the bake's catalogue, grid and table).
  PendingStars(const StarCatalogue& catalogue, const StarGrid& grid, const TransmittanceTable& table,
               double magnitude_limit, OutputUnits units, double julian_day_ut, const GeoLocation& place);
  // `unplaced` with its stars placed (StarSources), before the Moon's
  // samples, as ComputeNightFrame orders them; placed by the first call.
  const NightFrame& Placed(const NightFrame& unplaced);
  bool placed() const { return placed_.has_value(); }
  size_t stars() const { return placed_ ? placed_->stars : 0; }
  // The bound's knowledge of `unplaced` (whose sources are the Moon's
  // samples alone); `with_moon` false leaves them out (the SH and IBL
  // faces, where the Moon is a directional light). The Moon's part is
  // found once.
  UnplacedLight Light(const NightFrame& unplaced, bool with_moon);

 private:
  const StarCatalogue& catalogue_;
  const StarGrid& grid_;
  const TransmittanceTable& table_;
  double magnitude_limit_;
  OutputUnits units_;
  J2000Axes axes_;
  std::optional<NightFrame> placed_;
  std::optional<UnplacedLight> light_[2];  // without and with the Moon
};

}  // namespace skybake
