#include "skybake/pipeline/night_prune.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "skybake/input/ephemeris.h"
#include "skybake/input/style.h"
#include "skybake/model/view.h"

namespace skybake {
namespace {

// Float's rounding of the directions the splat looks up (Imf's V3f) and of
// the texels' mu, with room to spare.
constexpr double kAngleMarginRad = 1e-5;

double AngleBetween(const glm::dvec3& a, const glm::dvec3& b) {
  return std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0, 1.0));
}

// The largest cos(latitude) of a latlong's rows [a, b] (continuous,
// clamped to the view).
double LatLongMaxCos(const ViewRequest& view, double a, double b) {
  const double last = double(view.height - 1);
  a = std::clamp(a, 0.0, last);
  b = std::clamp(b, 0.0, last);
  auto lat = [&](double row) { return last > 0.0 ? M_PI / 2 - M_PI * row / last : 0.0; };
  if (lat(a) >= 0.0 && lat(b) <= 0.0) return 1.0;
  return std::max(std::cos(lat(a)), std::cos(lat(b)));
}

}  // namespace

StarGrid::StarGrid(const StarCatalogue& catalogue, double magnitude_limit, OutputUnits units) {
  const Rgb to_luminance = OutputScale(OutputUnits::kLuminance);
  const Rgb output = OutputScale(units);
  std::vector<double> cells(size_t(kRows) * kColumns, 0.0);
  std::vector<std::pair<uint32_t, Star>> binned;
  for (const CatalogueStar& s : catalogue.stars) {
    if (s.v_magnitude > magnitude_limit) continue;  // as PlaceStars
    const double lux = StarIlluminanceLux(s.v_magnitude);
    const Rgb color = StarColorFromBMinusV(s.b_minus_v);
    Rgb top{};
    for (int c = 0; c < 3; ++c) top[c] = lux * color[c] / to_luminance[c] * output[c];  // as StarSources
    const double e = std::max({top[0], top[1], top[2]});
    // The cell of the unit vector placement rotates.
    const glm::dvec3 v = UnitFromEquatorial(s.ra_j2000_deg, s.dec_j2000_deg);
    const double dec = std::asin(std::clamp(v.z, -1.0, 1.0));
    double ra = std::atan2(v.y, v.x);
    if (ra < 0.0) ra += 2.0 * M_PI;
    const int row = std::clamp(int((dec + M_PI / 2) / (M_PI / kRows)), 0, kRows - 1);
    const int column = std::clamp(int(ra / (2.0 * M_PI / kColumns)), 0, kColumns - 1);
    const uint32_t cell = uint32_t(row * kColumns + column);
    cells[cell] += e;
    total_ += e;
    binned.push_back({cell, {v, top, e}});
  }
  prefix_.assign(size_t(kRows) * (kColumns + 1), 0.0);
  for (int r = 0; r < kRows; ++r)
    for (int c = 0; c < kColumns; ++c)
      prefix_[size_t(r) * (kColumns + 1) + c + 1] =
          prefix_[size_t(r) * (kColumns + 1) + c] + cells[size_t(r) * kColumns + c];
  std::stable_sort(binned.begin(), binned.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  first_.assign(size_t(kRows) * kColumns + 1, 0);
  for (const auto& [cell, star] : binned) ++first_[cell + 1];
  for (size_t k = 1; k < first_.size(); ++k) first_[k] += first_[k - 1];
  stars_.reserve(binned.size());
  for (const auto& [cell, star] : binned) stars_.push_back(star);
}

template <typename Cells>
bool StarGrid::ForCellsWithin(const glm::dvec3& direction, double radius_rad, Cells cells) const {
  const double r = radius_rad + 1e-6;
  if (r >= M_PI / 2) return false;
  const glm::dvec3 d = glm::normalize(direction);
  const double dec = std::asin(std::clamp(d.z, -1.0, 1.0));
  double ra = std::atan2(d.y, d.x);
  if (ra < 0.0) ra += 2.0 * M_PI;
  const double lo = dec - r, hi = dec + r;
  const double row_step = M_PI / kRows, column_step = 2.0 * M_PI / kColumns;
  const int row0 = std::max(0, int(std::floor((lo + M_PI / 2) / row_step)));
  const int row1 = std::min(kRows - 1, int(std::floor((hi + M_PI / 2) / row_step)));
  // A cap over a pole spans every right ascension.
  const bool pole = hi >= M_PI / 2 || lo <= -M_PI / 2;
  const double half = pole ? M_PI : std::asin(std::min(1.0, std::sin(r) / std::cos(dec)));
  const int c0 = int(std::floor((ra - half) / column_step)), c1 = int(std::floor((ra + half) / column_step));
  for (int row = row0; row <= row1; ++row) {
    if (c1 - c0 + 1 >= kColumns) {
      cells(row, 0, kColumns - 1);
      continue;
    }
    // Columns c0..c1 modulo the row.
    cells(row, ((c0 % kColumns) + kColumns) % kColumns, ((c1 % kColumns) + kColumns) % kColumns);
  }
  return true;
}

double StarGrid::SumWithin(const glm::dvec3& direction, double radius_rad) const {
  double sum = 0.0;
  const bool some = ForCellsWithin(direction, radius_rad, [&](int row, int a, int b) {
    const double* p = &prefix_[size_t(row) * (kColumns + 1)];
    sum += a <= b ? p[b + 1] - p[a] : (p[kColumns] - p[a]) + p[b + 1];
  });
  if (!some) return total_ * (1.0 + 1e-9);
  // The running sums' rounding, against the sum of the same stars formed
  // another way.
  return sum * (1.0 + 1e-9);
}

void StarGrid::StarsWithin(const glm::dvec3& direction, double radius_rad, std::vector<Star>& out) const {
  auto take = [&](size_t cell0, size_t cell1) {  // cells [cell0, cell1)
    out.insert(out.end(), stars_.begin() + long(first_[cell0]), stars_.begin() + long(first_[cell1]));
  };
  const bool some = ForCellsWithin(direction, radius_rad, [&](int row, int a, int b) {
    const size_t base = size_t(row) * kColumns;
    if (a <= b) {
      take(base + size_t(a), base + size_t(b) + 1);
    } else {
      take(base + size_t(a), base + kColumns);
      take(base, base + size_t(b) + 1);
    }
  });
  if (!some) out.insert(out.end(), stars_.begin(), stars_.end());
}

RectCone ConeOfRect(const ViewRequest& view, int x0, int x1, int y0, int y1) {
  RectCone c;
  const int xm = (x0 + x1 - 1) / 2, ym = (y0 + y1 - 1) / 2;
  c.centre = glm::normalize(ViewTexelDirection(view, xm, ym));
  const int corners_x[2] = {x0, x1 - 1}, corners_y[2] = {y0, y1 - 1};
  double rho = M_PI;
  if (view.mapping == MAPPING_LATLONG) {
    // From the middle texel along its meridian to a texel's row, then
    // along that row's parallel (an arc no shorter than the great circle).
    const double h = double(std::max(view.height - 1, 1)), w = double(std::max(view.width - 1, 1));
    const double dlat = M_PI / h, dlon = 2.0 * M_PI / w;
    const double rows = double(std::max(ym - y0, y1 - 1 - ym)), columns = double(std::max(xm - x0, x1 - 1 - xm));
    c.texel_radius_rad = std::min(M_PI, rows * dlat + columns * dlon * LatLongMaxCos(view, y0, y1 - 1));
    // A source lies between its target rows: y - 1 .. y + 1.
    rho = dlat + dlon * LatLongMaxCos(view, y0 - 1.0, double(y1));
  } else {
    // A face's (and a strip's) texel directions are points of the face's
    // plane; the angle from one direction is quasi-convex over the plane
    // (its sublevel sets are the plane's sections of convex cones), so its
    // largest over a rectangle is at a corner.
    for (int y : corners_y)
      for (int x : corners_x)
        c.texel_radius_rad = std::max(c.texel_radius_rad, AngleBetween(c.centre, ViewTexelDirection(view, x, y)));
    // The source and its targets are in one cell of the grid of texel
    // centres on the plane at distance 1 (or more) from the eye: the angle
    // is at most the cell's diagonal.
    const int n = view.width;
    if (view.mapping == MAPPING_VULKAN_FACE) rho = 2.0 * std::sqrt(2.0) / n;
    else if (n > 1) rho = 2.0 * std::sqrt(2.0) / (n - 1);
  }
  c.reach_rad = std::min(M_PI, c.texel_radius_rad + rho + kAngleMarginRad);
  // The smallest solid angle at a corner (as SplatTiles).
  c.min_solid_angle = std::numeric_limits<double>::infinity();
  for (int y : corners_y)
    for (int x : corners_x)
      c.min_solid_angle =
          std::min(c.min_solid_angle, ViewTexelSolidAngle(view, view.mapping == MAPPING_LATLONG ? 0 : x, y));
  const double elevation = std::asin(std::clamp(c.centre.y, -1.0, 1.0));
  const double r = c.texel_radius_rad + kAngleMarginRad;
  c.min_mu = float(std::sin(std::max(-M_PI / 2, elevation - r)) - 1e-6);
  c.max_mu = float(std::sin(std::min(M_PI / 2, elevation + r)) + 1e-6);
  return c;
}

namespace {

// ClearsBeforePlacement's walk over one view.
struct PreBound {
  const ViewRequest& view;
  const UnplacedLight& light;
  const float* rgba;
  double min_relative;
  size_t rects_read = 0;
  size_t exact_texels = 0;  // single texels looked at star by star
  std::vector<StarGrid::Star> near;
  std::vector<PointSource> placed;

  // At least the load of any texel of the rectangle (its sources' largest
  // channels summed): every source with a target in it is in its cone.
  double Load(const RectCone& c) const { return StarBound(c) + MoonBound(c); }

  // The Moon's part of Load: all its samples where its disc may reach.
  double MoonBound(const RectCone& c) const {
    if (light.moon_total > 0.0 &&
        AngleBetween(c.centre, light.moon_centre) <= c.reach_rad + light.moon_radius_rad + kAngleMarginRad)
      return light.moon_total;
    return 0.0;
  }

  // The stars' part of Load.
  double StarBound(const RectCone& c) const {
    if (!light.stars) return 0.0;
    const double top = std::asin(std::clamp(c.centre.y, -1.0, 1.0)) + c.reach_rad;
    if (top < M_PI / 2 && std::sin(top) < light.min_source_mu - 1e-9) return 0.0;
    return light.stars->SumWithin(light.axes.ToJ2000(c.centre), c.reach_rad) * light.star_transmittance;
  }

  // At least the stars' load of texel (x, y) (whose cone is `c`) with their
  // weights: the stars of the grid's cells near it placed and attenuated
  // as StarSources places and attenuates them (the same arithmetic: the
  // same directions, so the same splat targets, and the same irradiances;
  // it leaves out a star under kStarMinElevationDeg or of zero
  // transmittance). Without the table, the bound of Load.
  double ExactStarLoad(int x, int y, const RectCone& c) {
    if (!light.stars) return 0.0;
    if (!light.table) return StarBound(c);
    ++exact_texels;
    near.clear();
    light.stars->StarsWithin(light.axes.ToJ2000(c.centre), c.reach_rad, near);
    const double min_y = std::sin(kStarMinElevationDeg * M_PI / 180.0);
    placed.clear();
    for (const StarGrid::Star& s : near) {
      const glm::dvec3 d = WorldFromJ2000(light.axes, s.j2000);
      if (d.y <= min_y) continue;
      const Rgb t = light.table->At(d.y);
      PointSource p{d, {s.top[0] * t[0], s.top[1] * t[1], s.top[2] * t[2]}};
      if (p.irradiance[0] > 0.0 || p.irradiance[1] > 0.0 || p.irradiance[2] > 0.0) placed.push_back(p);
    }
    // With room for rounding to spare.
    return WeightedTexelLoad(view, placed, x, y) * (1.0 + 1e-9);
  }

  bool Clears(int x0, int x1, int y0, int y1, const RectCone& c) {
    const double load = Load(c);
    const double glow =
        light.airglow && !light.airglow->empty() ? AirglowMaxOver(*light.airglow, c.min_mu, c.max_mu) : 0.0;
    if (load <= 0.0 && glow <= 0.0) return true;
    ++rects_read;
    const double floor = RectFloor(rgba, view.width, x0, x1, y0, y1);
    // The margins of BoundByTiles.
    const double capacity = min_relative * floor * c.min_solid_angle * (1.0 - 1e-4);
    const bool stars_clear = load <= 0.0 || load < capacity;
    const bool glow_clear = glow <= 0.0 || glow < min_relative * floor * (1.0 - 1e-6);
    if (stars_clear && glow_clear) return true;
    if (x1 - x0 <= 1 && y1 - y0 <= 1) return glow_clear && MoonBound(c) + ExactStarLoad(x0, y0, c) < capacity;
    const int xm = x1 - x0 > 1 ? (x0 + x1) / 2 : x1, ym = y1 - y0 > 1 ? (y0 + y1) / 2 : y1;
    const int xs[3] = {x0, xm, x1}, ys[3] = {y0, ym, y1};
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        if (xs[i] >= xs[i + 1] || ys[j] >= ys[j + 1]) continue;
        if (!Clears(xs[i], xs[i + 1], ys[j], ys[j + 1], ConeOfRect(view, xs[i], xs[i + 1], ys[j], ys[j + 1])))
          return false;
      }
    return true;
  }
};

}  // namespace

bool ClearsBeforePlacement(const ViewRequest& view, const SplatTiles& tiles, const std::vector<RectCone>& cones,
                           const UnplacedLight& light, const float* rgba, double min_relative, size_t* rects_read) {
  PreBound b{view, light, rgba, min_relative};
  // The tiles the Moon's disc reaches first: where a view does not clear,
  // it is most often there (the daytime Moon), and the walk stops at once.
  std::vector<int> order;
  order.reserve(size_t(tiles.count()));
  if (light.moon_total > 0.0)
    for (int t = 0; t < tiles.count(); ++t)
      if (AngleBetween(cones[size_t(t)].centre, light.moon_centre) <=
          cones[size_t(t)].reach_rad + light.moon_radius_rad + kAngleMarginRad)
        order.push_back(t);
  const size_t moon_tiles = order.size();
  for (int t = 0; t < tiles.count(); ++t)
    if (!std::binary_search(order.begin(), order.begin() + long(moon_tiles), t)) order.push_back(t);
  bool clear = true;
  for (size_t i = 0; i < order.size() && clear; ++i) {
    int x0, x1, y0, y1;
    tiles.Rect(order[i], x0, x1, y0, y1);
    clear = b.Clears(x0, x1, y0, y1, cones[size_t(order[i])]);
  }
  if (rects_read) *rects_read = b.rects_read;
  return clear;
}

PendingStars::PendingStars(const StarCatalogue& catalogue, const StarGrid& grid, const TransmittanceTable& table,
                           double magnitude_limit, OutputUnits units, double julian_day_ut, const GeoLocation& place)
    : catalogue_(catalogue),
      grid_(grid),
      table_(table),
      magnitude_limit_(magnitude_limit),
      units_(units),
      axes_(J2000AxesAt(julian_day_ut, place)) {}

const NightFrame& PendingStars::Placed(const NightFrame& unplaced) {
  if (placed_) return *placed_;
  NightFrame f = unplaced;
  f.pending = nullptr;
  std::vector<PointSource> stars = StarSources(catalogue_, magnitude_limit_, units_, table_, axes_);
  f.stars = stars.size();
  stars.insert(stars.end(), unplaced.sources.begin(), unplaced.sources.end());
  f.sources = std::move(stars);
  placed_ = std::move(f);
  return *placed_;
}

UnplacedLight PendingStars::Light(const NightFrame& unplaced, bool with_moon) {
  std::optional<UnplacedLight>& cached = light_[with_moon ? 1 : 0];
  if (cached) {
    UnplacedLight l = *cached;
    l.airglow = &unplaced.airglow;
    return l;
  }
  UnplacedLight& l = cached.emplace();
  l.stars = &grid_;
  l.axes = axes_;
  l.star_transmittance = table_.LargestEntry();
  l.table = &table_;
  l.min_source_mu = std::max(std::sin(kStarMinElevationDeg * M_PI / 180.0), table_.mu_horizon());
  if (with_moon && unplaced.moon)
    for (const PointSource& p : unplaced.sources) {
      l.moon_total += std::max({p.irradiance[0], p.irradiance[1], p.irradiance[2]});
      l.moon_radius_rad = std::max(l.moon_radius_rad, AngleBetween(p.direction, unplaced.moon->sky.direction));
    }
  if (unplaced.moon) l.moon_centre = unplaced.moon->sky.direction;
  l.airglow = &unplaced.airglow;
  return l;
}

}  // namespace skybake
