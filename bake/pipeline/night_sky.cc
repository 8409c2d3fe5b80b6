#include "skybake/pipeline/night_sky.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>

#include <fmt/format.h>
#include <glm/glm.hpp>
#include <OpenEXR/ImfEnvmap.h>
#include <toml++/toml.h>

#include "skybake/model/aoas.h"
#include "skybake/input/config.h"
#include "skybake/input/ephemeris.h"
#include "skybake/pipeline/gallery.h"
#include "skybake/pipeline/night_prune.h"
#include "skybake/pipeline/pass_plan.h"
#include "skybake/model/shared_glsl.h"
#include "skybake/input/schedule.h"

namespace skybake {
namespace {

double Luminance(const Rgb& c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

// Solid angle of the part of a cube face [u0, u1] x [v0, v1] (face
// coordinates in [-1, 1]): the integral of the area element.
double AreaElement(double u, double v) { return std::atan2(u * v, std::sqrt(u * u + v * v + 1.0)); }
double FaceRectSolidAngle(double u0, double u1, double v0, double v1) {
  return AreaElement(u1, v1) - AreaElement(u0, v1) - AreaElement(u1, v0) + AreaElement(u0, v0);
}

// Vulkan cube face selection (the specification's table, as envmap.cc):
// the face of `d` and its continuous texel position (centres at integers).
void VulkanFaceAndTexel(const glm::dvec3& d, int n, int& face, double& u, double& v) {
  const double ax = std::abs(d.x), ay = std::abs(d.y), az = std::abs(d.z);
  double sc, tc, ma;
  if (ax >= ay && ax >= az) {
    face = d.x > 0.0 ? 0 : 1;
    ma = ax;
    sc = d.x > 0.0 ? -d.z : d.z;
    tc = -d.y;
  } else if (ay >= az) {
    face = d.y > 0.0 ? 2 : 3;
    ma = ay;
    sc = d.x;
    tc = d.y > 0.0 ? d.z : -d.z;
  } else {
    face = d.z > 0.0 ? 4 : 5;
    ma = az;
    sc = d.z > 0.0 ? d.x : -d.x;
    tc = -d.y;
  }
  u = (sc / ma + 1.0) * 0.5 * n - 0.5;
  v = (tc / ma + 1.0) * 0.5 * n - 0.5;
}

Imath::Box2i Window(int w, int h) { return Imath::Box2i(Imath::V2i(0, 0), Imath::V2i(w - 1, h - 1)); }

// Bilinear neighbours of a continuous position on an integer grid; `ok`
// says which are inside.
struct Bilinear {
  int x[2], y[2];
  double w[2][2];
};
Bilinear BilinearAt(double u, double v) {
  Bilinear b;
  const double x0 = std::floor(u), y0 = std::floor(v);
  const double fx = u - x0, fy = v - y0;
  b.x[0] = int(x0);
  b.x[1] = int(x0) + 1;
  b.y[0] = int(y0);
  b.y[1] = int(y0) + 1;
  b.w[0][0] = (1 - fx) * (1 - fy);
  b.w[0][1] = fx * (1 - fy);
  b.w[1][0] = (1 - fx) * fy;
  b.w[1][1] = fx * fy;
  return b;
}

// Where the style's [night] keys are, for errors: the first given of
// `keys`, else the file alone.
ConfigError NightKeyError(const SkyStyle& style, const std::vector<std::string>& keys, const std::string& message) {
  ConfigError e;
  e.file = style.source_path;
  e.key = keys.front();
  e.message = message;
  try {
    const toml::table root = toml::parse_file(style.source_path);
    for (const std::string& k : keys) {
      toml::node_view<const toml::node> node = root.at_path(k);
      if (node) {
        e.key = k;
        e.line = int(node.node()->source().begin.line);
        e.column = int(node.node()->source().begin.column);
        break;
      }
    }
  } catch (const toml::parse_error&) {
    // The style was read before; a file changed since is located by name alone.
  }
  return e;
}

}  // namespace

std::string StarCataloguePathOf(const SkyStyle& style, const std::string& default_catalogue) {
  const std::string& given = style.night.star_catalogue;
  if (given.empty()) return default_catalogue;
  std::filesystem::path p(given);
  if (p.is_absolute() || style.source_path.empty() || !style.night.star_catalogue_set.empty()) return given;
  return (std::filesystem::path(style.source_path).parent_path() / p).string();
}

std::vector<ConfigError> CheckNightSky(const std::vector<const SkyStyle*>& styles, const Schedule* schedule,
                                       const std::string& default_catalogue) {
  std::vector<ConfigError> errors;
  const SkyStyle* night = nullptr;
  for (const SkyStyle* s : styles)
    if (s->night.Any()) {
      night = s;
      break;
    }
  if (!night) return errors;
  const std::vector<std::string> keys = {"night.stars", "night.moon", "night.moonlight"};
  if (!schedule || !schedule->clock_times || !schedule->place) {
    errors.push_back(NightKeyError(
        *night, keys,
        fmt::format("the night sky needs each frame's date, time and place (the stars and the Moon are placed for "
                    "them), and {}: bake with --schedule and a schedule of clock times ([schedule] date, "
                    "latitude_deg, longitude_deg, utc_offset_hours and times, e.g. configs/schedules/night.toml), or "
                    "turn night.stars, night.moon and night.moonlight off",
                    schedule ? schedule->source_path + " gives sun positions only" : "a single bake has none")));
    return errors;
  }
  std::vector<std::string> checked;
  for (const SkyStyle* s : styles) {
    if (!s->night.stars) continue;
    const std::string path = StarCataloguePathOf(*s, default_catalogue);
    if (std::find(checked.begin(), checked.end(), path) != checked.end()) continue;
    checked.push_back(path);
    std::string error;
    if (LoadStarCatalogue(path, error)) continue;
    if (!s->night.star_catalogue_set.empty()) {
      // Given on the command line: the error points at the argument.
      ConfigError e;
      e.file = s->night.star_catalogue_set;
      e.line = 1;
      e.column = 1;
      e.key = "night.star_catalogue";
      e.message = error;
      errors.push_back(e);
      continue;
    }
    errors.push_back(NightKeyError(*s, {"night.star_catalogue", "night.stars"}, error));
  }
  return errors;
}

double ViewTexelSolidAngle(const ViewRequest& view, int x, int y) {
  if (view.mapping == MAPPING_VULKAN_FACE) {
    const int n = view.width;
    return FaceRectSolidAngle(2.0 * x / n - 1.0, 2.0 * (x + 1) / n - 1.0, 2.0 * y / n - 1.0, 2.0 * (y + 1) / n - 1.0);
  }
  if (view.mapping == MAPPING_CUBE_STRIP) {
    // Imf::CubeMap puts texel centres at the face's edges: texel i covers
    // [i - 1/2, i + 1/2] / (n - 1) of the face, clipped to it. Strip texel
    // (x, y) is a face texel by a flip or a transpose, which keep this
    // symmetric measure.
    const int n = view.width;
    const Imath::Box2i window = Window(n, 6 * n);
    const Imf::CubeMapFace face = Imf::CubeMapFace(y / n);
    // The face texel at strip (x, y): pixelPosition is affine in the face position.
    const Imath::V2f p0 = Imf::CubeMap::pixelPosition(face, window, Imath::V2f(0, 0));
    const Imath::V2f px = Imf::CubeMap::pixelPosition(face, window, Imath::V2f(1, 0)) - p0;
    const Imath::V2f py = Imf::CubeMap::pixelPosition(face, window, Imath::V2f(0, 1)) - p0;
    const double det = double(px.x) * py.y - double(px.y) * py.x;
    const double dx = x - p0.x, dy = y - p0.y;
    const int i = int(std::lround((dx * py.y - dy * py.x) / det));
    const int j = int(std::lround((px.x * dy - px.y * dx) / det));
    const double s = n > 1 ? 2.0 / (n - 1) : 2.0;
    auto edge = [&](double k) { return std::clamp(k * s - 1.0, -1.0, 1.0); };
    return FaceRectSolidAngle(edge(i - 0.5), edge(i + 0.5), edge(j - 0.5), edge(j + 0.5));
  }
  if (view.mapping == MAPPING_LATLONG) {
    const int w = view.width, h = view.height;
    if (x == w - 1) return 0.0;  // the repeated meridian
    const double dlon = 2.0 * M_PI / (w - 1);
    auto lat = [&](double row) { return std::clamp(M_PI / 2 - M_PI * row / (h - 1), -M_PI / 2, M_PI / 2); };
    return dlon * (std::sin(lat(y - 0.5)) - std::sin(lat(y + 0.5)));
  }
  return 0.0;
}

namespace {

// The texels a source at unit `d` lands on in `view`, with their bilinear
// weights (before the renormalization within the view); none when it falls
// on another face.
struct SplatTarget {
  size_t index;
  double weight, solid_angle;
  int x, y;
};
void SplatTargets(const ViewRequest& view, const glm::dvec3& d, std::vector<SplatTarget>& targets) {
  targets.clear();
  const int w = view.width, h = view.height;
  if (view.mapping == MAPPING_VULKAN_FACE) {
    int face;
    double u, v;
    VulkanFaceAndTexel(d, w, face, u, v);
    if (face != view.face) return;
    const Bilinear b = BilinearAt(u, v);
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i)
        if (b.x[i] >= 0 && b.x[i] < w && b.y[j] >= 0 && b.y[j] < w && b.w[j][i] > 0.0)
          targets.push_back({size_t(b.y[j]) * w + b.x[i], b.w[j][i], 0.0, b.x[i], b.y[j]});
  } else if (view.mapping == MAPPING_CUBE_STRIP) {
    const Imath::Box2i window = Window(w, h);
    Imf::CubeMapFace face;
    Imath::V2f pif;
    Imf::CubeMap::faceAndPixelPosition(Imath::V3f(float(d.x), float(d.y), float(d.z)), window, face, pif);
    const Bilinear b = BilinearAt(pif.x, pif.y);
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i)
        if (b.x[i] >= 0 && b.x[i] < w && b.y[j] >= 0 && b.y[j] < w && b.w[j][i] > 0.0) {
          const Imath::V2f p = Imf::CubeMap::pixelPosition(face, window, Imath::V2f(float(b.x[i]), float(b.y[j])));
          const int px = int(std::lround(p.x)), py = int(std::lround(p.y));
          targets.push_back({size_t(py) * w + px, b.w[j][i], 0.0, px, py});
        }
  } else if (view.mapping == MAPPING_LATLONG) {
    const Imath::V2f p = Imf::LatLongMap::pixelPosition(Window(w, h), Imath::V3f(float(d.x), float(d.y), float(d.z)));
    const int period = w - 1;  // columns 0 and w - 1 are the same meridian
    double u = std::fmod(double(p.x), double(period));
    if (u < 0.0) u += period;
    const Bilinear b = BilinearAt(u, std::clamp(double(p.y), 0.0, double(h - 1)));
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        const int x = b.x[i] % period;
        if (b.y[j] >= 0 && b.y[j] < h && b.w[j][i] > 0.0)
          targets.push_back({size_t(b.y[j]) * w + x, b.w[j][i], 0.0, x, b.y[j]});
      }
  }
}

double LargestChannel(const Rgb& c) { return std::max({c[0], c[1], c[2]}); }

}  // namespace

namespace {

// Every source's targets in a view: targets[first[k], first[k + 1]) for
// source k (none for a dark source or one on another face).
struct ViewTargets {
  std::vector<SplatTarget> targets;
  std::vector<size_t> first;
};
ViewTargets TargetsOf(const ViewRequest& view, const std::vector<PointSource>& sources) {
  ViewTargets v;
  v.first.reserve(sources.size() + 1);
  std::vector<SplatTarget> one;
  for (const PointSource& s : sources) {
    v.first.push_back(v.targets.size());
    if (s.irradiance[0] <= 0.0 && s.irradiance[1] <= 0.0 && s.irradiance[2] <= 0.0) continue;
    SplatTargets(view, glm::normalize(s.direction), one);
    v.targets.insert(v.targets.end(), one.begin(), one.end());
  }
  v.first.push_back(v.targets.size());
  return v;
}

// The splat of the sources `which` (increasing indices; all when null).
std::vector<TexelAdd> SplatFromTargets(const ViewRequest& view, const std::vector<PointSource>& sources, ViewTargets& v,
                                       const std::vector<size_t>* which) {
  std::map<size_t, std::array<double, 3>> sums;
  const int w = view.width;
  const size_t count = which ? which->size() : sources.size();
  for (size_t n = 0; n < count; ++n) {
    const size_t k = which ? (*which)[n] : n;
    const PointSource& s = sources[k];
    const auto begin = v.targets.begin() + long(v.first[k]), end = v.targets.begin() + long(v.first[k + 1]);
    double total = 0.0;
    for (auto t = begin; t != end; ++t) {
      t->solid_angle = ViewTexelSolidAngle(view, t->x, t->y);
      if (t->solid_angle > 0.0) total += t->weight;
    }
    if (total <= 0.0) continue;
    for (auto t = begin; t != end; ++t) {
      if (t->solid_angle <= 0.0) continue;
      std::array<double, 3>& sum = sums[t->index];
      for (int c = 0; c < 3; ++c) sum[c] += s.irradiance[c] * t->weight / total / t->solid_angle;
      // The latlong's repeated meridian shows the same radiance.
      if (view.mapping == MAPPING_LATLONG && t->x == 0) {
        std::array<double, 3>& twin = sums[size_t(t->y) * w + (w - 1)];
        for (int c = 0; c < 3; ++c) twin[c] += s.irradiance[c] * t->weight / total / t->solid_angle;
      }
    }
  }
  std::vector<TexelAdd> adds;
  adds.reserve(sums.size());
  for (const auto& [index, rgb] : sums) {
    TexelAdd a;
    a.texel = index;
    for (int c = 0; c < 3; ++c) a.rgb[c] = float(rgb[c]);
    adds.push_back(a);
  }
  return adds;
}

}  // namespace

std::vector<TexelAdd> SplatPointSources(const ViewRequest& view, const std::vector<PointSource>& sources) {
  ViewTargets v = TargetsOf(view, sources);
  return SplatFromTargets(view, sources, v, nullptr);
}

std::vector<TexelAdd> BoundedSplat(const ViewRequest& view, const std::vector<PointSource>& sources, const float* rgba,
                                   double min_relative, SplatBound* bound_out) {
  const int w = view.width;
  ViewTargets v = TargetsOf(view, sources);
  // (texel, source) for every texel a source reaches, its twin included.
  struct Reach {
    size_t texel, source;
  };
  std::vector<Reach> reach;
  reach.reserve(v.targets.size() + v.targets.size() / 8);
  for (size_t k = 0; k < sources.size(); ++k)
    for (size_t i = v.first[k]; i < v.first[k + 1]; ++i) {
      const SplatTarget& t = v.targets[i];
      reach.push_back({t.index, k});
      if (view.mapping == MAPPING_LATLONG && t.x == 0) reach.push_back({size_t(t.y) * w + (w - 1), k});
    }
  std::sort(reach.begin(), reach.end(), [](const Reach& a, const Reach& b) {
    return a.texel != b.texel ? a.texel < b.texel : a.source < b.source;
  });
  // Each texel's load against its capacity (less a margin far wider than
  // float's rounding of the sums); the latlong's repeated meridian has
  // column 0's solid angle (it receives column 0's additions).
  SplatBound bound;
  std::vector<char> wanted(sources.size(), 0);
  for (size_t i = 0; i < reach.size();) {
    size_t j = i;
    double load = 0.0;
    for (; j < reach.size() && reach[j].texel == reach[i].texel; ++j)
      if (j == i || reach[j].source != reach[j - 1].source) load += LargestChannel(sources[reach[j].source].irradiance);
    const size_t texel = reach[i].texel;
    const int x = int(texel % w), y = int(texel / w);
    const double omega = ViewTexelSolidAngle(view, view.mapping == MAPPING_LATLONG && x == w - 1 ? 0 : x, y);
    const float* t = rgba + 4 * texel;
    const double capacity = min_relative * std::max({double(t[0]), double(t[1]), double(t[2])}) * omega * (1.0 - 1e-4);
    if (!(load < capacity)) {
      bound.open.push_back(texel);
      for (size_t m = i; m < j; ++m) wanted[reach[m].source] = 1;
    }
    i = j;
  }
  // The sources that reach an open texel, in their order (so each kept
  // texel's sum is formed as the whole splat forms it).
  for (size_t k = 0; k < sources.size(); ++k)
    if (wanted[k]) bound.sources.push_back(k);
  std::vector<TexelAdd> adds;
  if (!bound.sources.empty()) {
    adds = SplatFromTargets(view, sources, v, &bound.sources);
    std::erase_if(
        adds, [&](const TexelAdd& a) { return !std::binary_search(bound.open.begin(), bound.open.end(), a.texel); });
  }
  if (bound_out) *bound_out = std::move(bound);
  return adds;
}

double WeightedTexelLoad(const ViewRequest& view, const std::vector<PointSource>& sources, int x, int y) {
  const int w = view.width;
  const int own_x = view.mapping == MAPPING_LATLONG && x == w - 1 ? 0 : x;  // the repeated meridian
  std::vector<SplatTarget> targets;
  double load = 0.0;
  for (const PointSource& s : sources) {
    if (s.irradiance[0] <= 0.0 && s.irradiance[1] <= 0.0 && s.irradiance[2] <= 0.0) continue;  // as TargetsOf
    SplatTargets(view, glm::normalize(s.direction), targets);
    double total = 0.0, here = 0.0;
    for (const SplatTarget& t : targets) {
      if (ViewTexelSolidAngle(view, t.x, t.y) <= 0.0) continue;  // as SplatFromTargets
      total += t.weight;
      if (t.x == own_x && t.y == y) here += t.weight;
    }
    if (total > 0.0 && here > 0.0) load += LargestChannel(s.irradiance) * here / total;
  }
  return load;
}

SplatTiles::SplatTiles(const ViewRequest& view, const std::vector<float>& mu) : view_(view) {
  const int w = view.width, h = view.height;
  const bool strip = view.mapping == MAPPING_CUBE_STRIP;
  face_rows_ = strip ? w : h;  // a strip's tiles stay within one face
  tiles_x_ = (w + kSplatTileSize - 1) / kSplatTileSize;
  tiles_per_face_ = (face_rows_ + kSplatTileSize - 1) / kSplatTileSize;
  const int tiles = tiles_x_ * tiles_per_face_ * (strip ? 6 : 1);
  min_solid_angle_.resize(size_t(tiles));
  if (!mu.empty()) mu_range_.assign(2 * size_t(tiles), 0.0f);
  for (int t = 0; t < tiles; ++t) {
    int x0, x1, y0, y1;
    Rect(t, x0, x1, y0, y1);
    // The smallest solid angle is at a corner texel: a face's texel (and a
    // strip's, whose edge texels are halved) shrinks away from the face's
    // centre in each coordinate, a latlong's row towards either pole, and
    // the farthest column and row of a rectangle are at its ends. The
    // latlong's repeated meridian takes column 0's (it receives its
    // additions), which is every column's.
    double omega = std::numeric_limits<double>::infinity();
    for (int y : {y0, y1 - 1})
      for (int x : {x0, x1 - 1})
        omega = std::min(omega, ViewTexelSolidAngle(view, view.mapping == MAPPING_LATLONG ? 0 : x, y));
    min_solid_angle_[size_t(t)] = omega;
    if (mu.empty()) continue;
    float lo = 2.0f, hi = -2.0f;
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) {
        lo = std::min(lo, mu[size_t(y) * w + x]);
        hi = std::max(hi, mu[size_t(y) * w + x]);
      }
    mu_range_[2 * size_t(t)] = lo;
    mu_range_[2 * size_t(t) + 1] = hi;
  }
}

int SplatTiles::TileOf(int x, int y) const {
  const int face = y / face_rows_, row = y - face * face_rows_;
  return (face * tiles_per_face_ + row / kSplatTileSize) * tiles_x_ + x / kSplatTileSize;
}

void SplatTiles::Rect(int tile, int& x0, int& x1, int& y0, int& y1) const {
  const int tx = tile % tiles_x_, ty = tile / tiles_x_;
  const int face = ty / tiles_per_face_, row = (ty - face * tiles_per_face_) * kSplatTileSize;
  x0 = tx * kSplatTileSize;
  x1 = std::min(x0 + kSplatTileSize, view_.width);
  y0 = face * face_rows_ + row;
  y1 = face * face_rows_ + std::min(row + kSplatTileSize, face_rows_);
}

TileBound BoundByTiles(const ViewRequest& view, const SplatTiles& tiles, const std::vector<PointSource>& sources,
                       const std::vector<Rgb>& airglow, const float* rgba, double min_relative) {
  TileBound b;
  const int w = view.width;
  // Each source's load into every tile it has a target in (once per tile).
  std::vector<double> load(size_t(tiles.count()), 0.0);
  std::vector<int> first_tile(sources.size() + 1, 0);
  std::vector<int> reached;  // source k's tiles: reached[first_tile[k], first_tile[k + 1])
  std::vector<SplatTarget> targets;
  for (size_t k = 0; k < sources.size(); ++k) {
    first_tile[k] = int(reached.size());
    const PointSource& s = sources[k];
    if (s.irradiance[0] <= 0.0 && s.irradiance[1] <= 0.0 && s.irradiance[2] <= 0.0) continue;
    SplatTargets(view, glm::normalize(s.direction), targets);
    const size_t begin = reached.size();
    auto add = [&](int x, int y) {
      const int t = tiles.TileOf(x, y);
      if (std::find(reached.begin() + long(begin), reached.end(), t) == reached.end()) reached.push_back(t);
    };
    for (const SplatTarget& t : targets) {
      add(t.x, t.y);
      if (view.mapping == MAPPING_LATLONG && t.x == 0) add(w - 1, t.y);  // the repeated meridian
    }
    const double e = LargestChannel(s.irradiance);
    for (size_t i = begin; i < reached.size(); ++i) load[size_t(reached[i])] += e;
  }
  first_tile[sources.size()] = int(reached.size());
  // Each tile that may matter: its floor against the load and the glow.
  std::vector<char> open(size_t(tiles.count()), 0);
  for (int t = 0; t < tiles.count(); ++t) {
    const double glow = airglow.empty() ? 0.0 : AirglowMaxOver(airglow, tiles.min_mu(t), tiles.max_mu(t));
    if (load[size_t(t)] <= 0.0 && glow <= 0.0) continue;
    int x0, x1, y0, y1;
    tiles.Rect(t, x0, x1, y0, y1);
    const float floor = RectFloor(rgba, w, x0, x1, y0, y1);
    ++b.tiles_read;
    // The margins: SplatBound's, and a millionth for the glow's blend.
    const double capacity = min_relative * double(floor) * tiles.min_solid_angle(t) * (1.0 - 1e-4);
    if (load[size_t(t)] > 0.0 && !(load[size_t(t)] < capacity)) open[size_t(t)] = 1;
    if (glow > 0.0 && !(glow < min_relative * double(floor) * (1.0 - 1e-6))) b.airglow = true;
  }
  for (size_t k = 0; k < sources.size(); ++k)
    for (int i = first_tile[k]; i < first_tile[k + 1]; ++i)
      if (open[size_t(reached[size_t(i)])]) {
        b.sources.push_back(k);
        break;
      }
  b.splat = !b.sources.empty();
  return b;
}

float RectFloor(const float* rgba, int width, int x0, int x1, int y0, int y1) {
  float floor = std::numeric_limits<float>::infinity();
  for (int y = y0; y < y1; ++y) {
    const float* row = rgba + 4 * (size_t(y) * width);
    for (int x = x0; x < x1; ++x) floor = std::min(floor, std::max({row[4 * x], row[4 * x + 1], row[4 * x + 2]}));
  }
  return floor;
}

double AirglowMaxOver(const std::vector<Rgb>& table, double lo, double hi) {
  // The table's first and last entries for the range (as AirglowAt).
  auto index = [&](double mu) { return (std::clamp(mu, -1.0, 1.0) + 1.0) * 0.5 * double(table.size() - 1); };
  const size_t i0 = std::min(size_t(index(lo)), table.size() - 2);
  const size_t i1 = std::min(size_t(index(hi)), table.size() - 2) + 1;
  double m = 0.0;
  for (size_t i = i0; i <= i1; ++i) m = std::max(m, LargestChannel(table[i]));
  return m;
}

size_t ApplyTexelAdds(const std::vector<TexelAdd>& adds, const float* rgba_in, float* rgba_out, double min_relative) {
  size_t applied = 0;
  for (const TexelAdd& a : adds) {
    if (rgba_in && min_relative > 0.0) {
      const float* t = rgba_in + 4 * a.texel;
      const double current = std::max({double(t[0]), double(t[1]), double(t[2])});
      const double add = std::max({double(a.rgb[0]), double(a.rgb[1]), double(a.rgb[2])});
      if (add < min_relative * current) continue;
    }
    ++applied;
    if (!rgba_out) continue;
    float* t = rgba_out + 4 * a.texel;
    for (int c = 0; c < 3; ++c) t[c] += a.rgb[c];
  }
  return applied;
}

TransmittanceTable::TransmittanceTable(const AtmosphereParams& atmosphere, const QualitySettings& quality,
                                       const EffectSettings& effects) {
  // The shared GLSL's direct optical depth (shared_glsl.h), 256 points.
  const glsl::AtmosphereParameters atm = glsl::SharedAtmosphere(atmosphere, quality, effects);
  const double altitude_km = atmosphere.observer_altitude_m * 1e-3;
  const double r = atmosphere.bottom_radius_km + altitude_km;
  mu_horizon_ = -std::sqrt(std::max(0.0, 1.0 - (atmosphere.bottom_radius_km / r) * (atmosphere.bottom_radius_km / r)));
  constexpr int kEntries = 4096;
  table_.resize(kEntries);
  for (int i = 0; i < kEntries; ++i) {
    const double mu = mu_horizon_ + (1.0 - mu_horizon_) * i / (kEntries - 1);
    const glm::dvec3 t =
        glm::exp(-glsl::ComputeOpticalDepthToTopBoundary(atm, atm.bottom_radius + altitude_km, altitude_km, mu, 256));
    table_[i] = {t.x, t.y, t.z};
  }
}

Rgb TransmittanceTable::At(double mu) const {
  if (!(mu >= mu_horizon_)) return {0.0, 0.0, 0.0};
  const double f = std::min(1.0, (mu - mu_horizon_) / (1.0 - mu_horizon_)) * (table_.size() - 1);
  const size_t i = std::min(size_t(f), table_.size() - 2);
  const double a = f - double(i);
  Rgb out;
  for (int c = 0; c < 3; ++c) out[c] = table_[i][c] * (1.0 - a) + table_[i + 1][c] * a;
  return out;
}

double TransmittanceTable::LargestEntry() const {
  double m = 0.0;
  for (const Rgb& t : table_) m = std::max(m, LargestChannel(t));
  return m;
}

std::vector<Rgb> AirglowTable(const AtmosphereParams& atmosphere, const TransmittanceTable& t, double height_km,
                              double zenith_cd_m2, OutputUnits units) {
  const Rgb to_luminance = OutputScale(OutputUnits::kLuminance);
  const Rgb output = OutputScale(units);
  const double r = atmosphere.bottom_radius_km + atmosphere.observer_altitude_m * 1e-3;
  const double ratio = std::min(r / (atmosphere.bottom_radius_km + height_km), 1.0 - 1e-9);
  const Rgb zenith_t = t.At(1.0);
  std::vector<Rgb> table(kAirglowEntries);
  for (int i = 0; i < kAirglowEntries; ++i) {
    const double mu = -1.0 + 2.0 * i / (kAirglowEntries - 1);
    const double van_rhijn = 1.0 / std::sqrt(1.0 - ratio * ratio * (1.0 - mu * mu));
    const Rgb tr = t.At(mu);
    // Neutral in Rec.709 luminance, then the output units (as NightSkyRadiance).
    for (int c = 0; c < 3; ++c)
      table[i][c] =
          zenith_t[c] > 0.0 ? zenith_cd_m2 / to_luminance[c] * output[c] * van_rhijn * tr[c] / zenith_t[c] : 0.0;
  }
  return table;
}

Rgb AirglowAt(const std::vector<Rgb>& table, double mu) {
  const double f = (std::clamp(mu, -1.0, 1.0) + 1.0) * 0.5 * (table.size() - 1);
  const size_t i = std::min(size_t(f), table.size() - 2);
  const double a = f - double(i);
  // Behind the ground the table is zero: no blend across the horizon.
  if (table[i][1] == 0.0 || table[i + 1][1] == 0.0) return a < 0.5 ? table[i] : table[i + 1];
  Rgb out;
  for (int c = 0; c < 3; ++c) out[c] = table[i][c] * (1.0 - a) + table[i + 1][c] * a;
  return out;
}

std::vector<PointSource> MoonDiscSources(const glm::dvec3& moon_direction, double rho, const glm::dvec3& sun_direction,
                                         const Rgb& disc_irradiance, int samples_across) {
  const glm::dvec3 m = glm::normalize(moon_direction);
  const glm::dvec3 s = glm::normalize(sun_direction);
  const glm::dvec3 helper = std::abs(m.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
  const glm::dvec3 e1 = glm::normalize(glm::cross(helper, m));
  const glm::dvec3 e2 = glm::cross(m, e1);
  std::vector<PointSource> samples;
  std::vector<double> shade;
  double total = 0.0;
  const double step = 2.0 / samples_across;
  for (int j = 0; j < samples_across; ++j) {
    for (int i = 0; i < samples_across; ++i) {
      const double a = -1.0 + (i + 0.5) * step, b = -1.0 + (j + 0.5) * step;
      const double rr = a * a + b * b;
      if (rr >= 1.0) continue;
      // The Moon's surface normal at the sample, on the side facing the
      // observer (-m), the cosines of emission (mu) and incidence (mu0).
      const double mu = std::sqrt(1.0 - rr);
      const glm::dvec3 normal = a * e1 + b * e2 - mu * m;
      const double mu0 = glm::dot(normal, s);
      if (mu0 <= 0.0) continue;           // the night side (no earthshine)
      const double f = mu0 / (mu0 + mu);  // Lommel-Seeliger
      PointSource p;
      p.direction = glm::normalize(m + std::tan(rho) * (a * e1 + b * e2));
      samples.push_back(p);
      shade.push_back(f);
      total += f;
    }
  }
  if (total <= 0.0) return {};
  for (size_t k = 0; k < samples.size(); ++k)
    for (int c = 0; c < 3; ++c) samples[k].irradiance[c] = disc_irradiance[c] * shade[k] / total;
  return samples;
}

std::vector<PointSource> StarSources(const StarCatalogue& catalogue, double magnitude_limit, OutputUnits units,
                                     const TransmittanceTable& t, double julian_day_ut, const GeoLocation& place) {
  return StarSources(catalogue, magnitude_limit, units, t, J2000AxesAt(julian_day_ut, place));
}

std::vector<PointSource> StarSources(const StarCatalogue& catalogue, double magnitude_limit, OutputUnits units,
                                     const TransmittanceTable& t, const J2000Axes& axes) {
  const Rgb to_luminance = OutputScale(OutputUnits::kLuminance);
  const Rgb output = OutputScale(units);
  std::vector<PointSource> sources;
  for (const PlacedStar& s : PlaceStars(catalogue, magnitude_limit, axes, kStarMinElevationDeg)) {
    const Rgb tr = t.At(s.direction.y);
    PointSource p;
    p.direction = s.direction;
    // Luminance-normalized Rec.709 colour x lux -> spectral -> output units.
    for (int c = 0; c < 3; ++c) p.irradiance[c] = s.illuminance_lux * s.color[c] / to_luminance[c] * output[c] * tr[c];
    if (Luminance(tr) > 0.0) sources.push_back(p);
  }
  return sources;
}

NightFrame ComputeNightFrame(const SkyStyle& style, const StarCatalogue* catalogue, const TransmittanceTable& t,
                             double julian_day_ut, const GeoLocation& place, const glm::dvec3& sun,
                             const StarGrid* defer) {
  NightFrame night;
  night.daylight = sun.y > 0.0;
  const NightSettings& n = style.night;
  const Rgb to_luminance = OutputScale(OutputUnits::kLuminance);
  const Rgb output = OutputScale(style.output.units);
  if (n.stars && catalogue) {
    if (defer && night.daylight)
      night.pending = std::make_shared<PendingStars>(*catalogue, *defer, t, n.star_magnitude_limit, style.output.units,
                                                     julian_day_ut, place);
    else night.sources = StarSources(*catalogue, n.star_magnitude_limit, style.output.units, t, julian_day_ut, place);
    night.stars = night.sources.size();
  }
  if (n.moon || n.moonlight) {
    const MoonState moon = ComputeMoon(julian_day_ut, place, style.atmosphere.observer_altitude_m);
    night.moon = moon;
    const Rgb& solar = style.atmosphere.solar_irradiance;
    const double sun_lux =
        Luminance({solar[0] * to_luminance[0], solar[1] * to_luminance[1], solar[2] * to_luminance[2]});
    const double k = sun_lux > 0.0 ? moon.illuminance_lux / sun_lux : 0.0;
    Rgb disc{};
    for (int c = 0; c < 3; ++c) disc[c] = k * solar[c] * output[c];
    std::vector<PointSource> samples = MoonDiscSources(moon.sky.direction, moon.angular_radius_rad, sun, disc, 64);
    for (PointSource& p : samples) {
      const Rgb tr = t.At(p.direction.y);
      for (int c = 0; c < 3; ++c) {
        p.irradiance[c] *= tr[c];
        night.moon_irradiance[c] += p.irradiance[c];
      }
    }
    Rgb lum{};
    for (int c = 0; c < 3; ++c) lum[c] = night.moon_irradiance[c] / output[c] * to_luminance[c];
    night.moon_illuminance_lux = Luminance(lum);
    if (n.moon)
      for (const PointSource& p : samples)
        if (p.irradiance[0] > 0.0 || p.irradiance[1] > 0.0 || p.irradiance[2] > 0.0) night.sources.push_back(p);
    if (n.moonlight && sun.y < 0.0 && moon.sky.elevation_deg > -10.0) night.moonlight_scale = k;
  }
  return night;
}

NightSkyRenderer::NightSkyRenderer(VulkanContext& context) : context_(context) {}
NightSkyRenderer::~NightSkyRenderer() = default;

std::vector<std::vector<float>> NightSkyRenderer::MoonlitSky(const SkyStyle& style, const NightFrame& night,
                                                             const std::vector<ViewRequest>& views) {
  // The style's renderer with the Moon as its light: no disc (the Moon's is
  // splatted), no night dimming (that dims the Sun's sky).
  EffectSettings effects = style.effects;
  effects.sun_disc = false;
  effects.night_dimming = false;
  const AtmosphereParams atmosphere = StyledAtmosphere(style.atmosphere, style.aoas);
  const Rgb scale = OutputScale(style.output.units);
  const gpu::GpuAtmosphere key = ToGpuAtmosphere(atmosphere, style.quality, effects, scale);
  if (!moonlight_ || std::memcmp(&key, &moonlight_key_, sizeof key) != 0) {
    moonlight_ = std::make_unique<SkyRenderer>(context_, atmosphere, style.quality, effects, scale, false,
                                               ToAoasInputs(style.aoas, OutputScale(OutputUnits::kLuminance)));
    moonlight_key_ = key;
  }
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::vector<float>> sky = moonlight_->Render(night.moon->sky.direction, views, false);
  last_moonlight_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ++moonlight_renders_;
  for (std::vector<float>& v : sky)
    for (size_t i = 0; i < v.size(); ++i)
      if (i % 4 != 3) v[i] = float(double(v[i]) * night.moonlight_scale);
  return sky;
}

const std::vector<float>& NightSkyRenderer::TexelMu(const ViewRequest& view) {
  const std::array<int, 4> key = {view.mapping, view.width, view.height, view.face};
  auto it = texel_mu_.find(key);
  if (it != texel_mu_.end()) return it->second;
  std::vector<float> mu(size_t(view.width) * view.height);
  for (int y = 0; y < view.height; ++y)
    for (int x = 0; x < view.width; ++x) mu[size_t(y) * view.width + x] = float(ViewTexelDirection(view, x, y).y);
  return texel_mu_.emplace(key, std::move(mu)).first->second;
}

std::vector<TexelAdd> NightSkyRenderer::BoundedSplat(const ViewRequest& view, const std::vector<PointSource>& sources,
                                                     const float* rgba, bool daylight) {
  // By night nearly every source shows: the bound would find them all and
  // only add its own cost.
  if (!splat_bound_ || !daylight) {
    ++splats_run_;
    return SplatPointSources(view, sources);
  }
  SplatBound bound;
  std::vector<TexelAdd> adds = skybake::BoundedSplat(view, sources, rgba, kNightSplatMinRelative, &bound);
  ++(bound.sources.empty() ? splats_skipped_ : splats_run_);
  return adds;
}

TileBound NightSkyRenderer::Bound(const ViewRequest& view, const NightFrame& night,
                                  const std::vector<PointSource>& sources, const float* rgba) {
  // By night the stars and the glow show nearly everywhere: the bound
  // would open every tile and only add its own cost.
  if (!splat_bound_ || !tile_bound_ || !night.daylight) {
    TileBound all;
    all.airglow = !night.airglow.empty();
    all.splat = !sources.empty();
    for (size_t k = 0; k < sources.size(); ++k) all.sources.push_back(k);
    return all;
  }
  TileBound b =
      BoundByTiles(view, TilesOf(view, !night.airglow.empty()), sources, night.airglow, rgba, kNightSplatMinRelative);
  if (!b.splat) {
    ++splats_skipped_;
    ++tiles_skipped_;
  }
  return b;
}

const SplatTiles& NightSkyRenderer::TilesOf(const ViewRequest& view, bool with_mu) {
  const std::array<int, 5> key = {view.mapping, view.width, view.height, view.face, int(with_mu)};
  auto it = tiles_.find(key);
  if (it == tiles_.end()) {
    static const std::vector<float> none;
    it = tiles_.emplace(key, std::make_unique<SplatTiles>(view, with_mu ? TexelMu(view) : none)).first;
  }
  return *it->second;
}

const NightFrame* NightSkyRenderer::ForView(const ViewRequest& view, const NightFrame& night, const float* rgba,
                                            bool with_moon) {
  if (!night.pending) return &night;
  // Once a view has placed the frame's stars, the tile bound (which knows
  // each star's place) is the cheaper look at the views left: they go
  // through it as in a frame placed at once.
  if (night.pending->placed()) return &night.pending->Placed(night);
  if (splat_bound_ && tile_bound_) {
    const SplatTiles& tiles = TilesOf(view, false);
    const std::array<int, 4> key = {view.mapping, view.width, view.height, view.face};
    auto it = cones_.find(key);
    if (it == cones_.end()) {
      auto cones = std::make_unique<std::vector<RectCone>>();
      for (int t = 0; t < tiles.count(); ++t) {
        int x0, x1, y0, y1;
        tiles.Rect(t, x0, x1, y0, y1);
        cones->push_back(ConeOfRect(view, x0, x1, y0, y1));
      }
      it = cones_.emplace(key, std::move(cones)).first;
    }
    if (ClearsBeforePlacement(view, tiles, *it->second, night.pending->Light(night, with_moon), rgba,
                              kNightSplatMinRelative)) {
      ++cleared_before_placement_;
      return nullptr;
    }
  }
  return &night.pending->Placed(night);
}

namespace {

// Adds the airglow where it is at least kNightSplatMinRelative of the
// texel; returns whether any was (with `rgba_out` null: only tells).
bool AddAirglow(const std::vector<Rgb>& table, const std::vector<float>& mu, const float* rgba_in, float* rgba_out) {
  bool any = false;
  for (size_t i = 0; i < mu.size(); ++i) {
    const Rgb a = AirglowAt(table, mu[i]);
    const float* t = rgba_in + 4 * i;
    const double current = std::max({double(t[0]), double(t[1]), double(t[2])});
    const double add = std::max({a[0], a[1], a[2]});
    if (add <= 0.0 || add < kNightSplatMinRelative * current) continue;
    any = true;
    if (!rgba_out) return true;
    for (int c = 0; c < 3; ++c) rgba_out[4 * i + c] += float(a[c]);
  }
  return any;
}

// The sources `which` of `sources`, in their order (all when they are all).
std::vector<PointSource> SourcesOf(const std::vector<PointSource>& sources, const std::vector<size_t>& which) {
  if (which.size() == sources.size()) return sources;
  std::vector<PointSource> some;
  some.reserve(which.size());
  for (size_t k : which) some.push_back(sources[k]);
  return some;
}

}  // namespace

void NightSkyRenderer::AddToViews(const SkyStyle& style, const NightFrame& night, const std::vector<ViewRequest>& views,
                                  std::vector<RgbaImage>& images) {
  std::vector<std::vector<float>> moonlit;
  if (night.moonlight_scale > 0.0 && night.moon) moonlit = MoonlitSky(style, night, views);
  for (size_t i = 0; i < views.size(); ++i) {
    RgbaImage& image = images[i];
    auto own = [&]() {
      if (!image.view) return;
      image.rgba.assign(image.view, image.view + 4 * image.texels());
      image.view = nullptr;
    };
    if (!moonlit.empty()) {
      own();
      for (size_t k = 0; k < image.rgba.size(); ++k)
        if (k % 4 != 3) image.rgba[k] += moonlit[i][k];
    }
    // A day frame's stars wait for a view the bound before placement
    // cannot clear (night_prune.h).
    const NightFrame* frame = ForView(views[i], night, image.data(), true);
    if (!frame) continue;
    // The tile bound first (BoundByTiles): the glow and the splat only
    // where they may change a byte. Its floors, read before the glow, are
    // still floors after it (the glow only adds).
    const TileBound bound = Bound(views[i], *frame, frame->sources, image.data());
    if (bound.airglow) {
      const std::vector<float>& mu = TexelMu(views[i]);
      if (AddAirglow(frame->airglow, mu, image.data(), nullptr)) {
        own();
        AddAirglow(frame->airglow, mu, image.rgba.data(), image.rgba.data());
      }
    }
    if (!bound.splat) continue;
    // The sources that reach no open tile add nothing that is kept: every
    // texel they reach is in a closed tile, and every source reaching an
    // open tile is here, in its order (the same sums).
    const std::vector<TexelAdd> adds =
        BoundedSplat(views[i], SourcesOf(frame->sources, bound.sources), image.data(), frame->daylight);
    if (ApplyTexelAdds(adds, image.data(), nullptr, kNightSplatMinRelative) == 0) continue;
    own();
    ApplyTexelAdds(adds, image.rgba.data(), image.rgba.data(), kNightSplatMinRelative);
  }
}

void NightSkyRenderer::AddToFaces(const SkyStyle& style, const NightFrame& night, const std::vector<ViewRequest>& views,
                                  std::vector<std::vector<float>>& faces) {
  std::vector<std::vector<float>> moonlit;
  if (night.moonlight_scale > 0.0 && night.moon) moonlit = MoonlitSky(style, night, views);
  // The stars only: the Moon's disc is a directional light there, as the Sun's.
  const NightFrame* stars_of = nullptr;
  std::vector<PointSource> stars;
  for (size_t i = 0; i < views.size(); ++i) {
    if (!moonlit.empty())
      for (size_t k = 0; k < faces[i].size(); ++k)
        if (k % 4 != 3) faces[i][k] += moonlit[i][k];
    const NightFrame* frame = ForView(views[i], night, faces[i].data(), false);
    if (!frame) continue;
    if (frame != stars_of) {
      stars.assign(frame->sources.begin(), frame->sources.begin() + long(frame->stars));
      stars_of = frame;
    }
    const TileBound bound = Bound(views[i], *frame, stars, faces[i].data());
    if (bound.airglow) AddAirglow(frame->airglow, TexelMu(views[i]), faces[i].data(), faces[i].data());
    if (!bound.splat) continue;
    ApplyTexelAdds(BoundedSplat(views[i], SourcesOf(stars, bound.sources), faces[i].data(), frame->daylight),
                   faces[i].data(), faces[i].data(), kNightSplatMinRelative);
  }
}

void AddNightSkyPlan(const std::vector<SkyStyle>& frames, PassPlan& plan) {
  if (frames.empty() || !frames.front().night.Any()) return;
  const NightSettings& night = frames.front().night;
  const int day =
      int(std::count_if(frames.begin(), frames.end(), [](const SkyStyle& f) { return f.sun.elevation_deg > 0.0; }));
  const std::string pruned =
      day == 0 ? std::string("no frame has the Sun up: every view splatted")
               : fmt::format(
                     "in the {} of {} frames with the Sun up each view is first bounded before any star is "
                     "placed (the catalogue binned by J2000 position against each tile's darkest texel, and "
                     "star by star at a texel that the bins do not clear): a frame whose views no star, Moon "
                     "or glow can change places no star and splats nothing; "
                     "a view that may change then goes through the tile bound, skipped where no addition can "
                     "reach 2^-13 of a texel (the daylit sky outshines it)",
                     day, int(frames.size()));
  if (night.stars || night.moon)
    plan.passes.push_back({"star and Moon splat (host)",
                           fmt::format("{}{}4 texels a source", night.stars ? "stars to V " : "",
                                       night.stars ? fmt::format("{}, ", night.star_magnitude_limit) : ""),
                           "per frame; " + pruned, plan.frames, 0.0});
  if (night.airglow)
    plan.passes.push_back(
        {"airglow (host)", "every texel above the horizon", "per frame; " + pruned, plan.frames, 0.0});
}

const StarCatalogue& StarCatalogues::Get(const std::string& path) {
  auto it = loaded_.find(path);
  if (it != loaded_.end()) return it->second;
  std::string error;
  std::optional<StarCatalogue> c = LoadStarCatalogue(path, error);
  if (!c) {
    ConfigError e;
    e.file = path;
    e.key = "night.star_catalogue";
    e.message = error;
    throw ConfigFailure(error, {e});
  }
  return loaded_.emplace(path, std::move(*c)).first->second;
}

NightSkyBake::~NightSkyBake() = default;

std::unique_ptr<NightSkyBake> NightSkyBake::For(const std::vector<const SkyStyle*>& styles, const Schedule* schedule,
                                                const std::string& default_catalogue) {
  if (std::none_of(styles.begin(), styles.end(), [](const SkyStyle* s) { return s->night.Any(); })) return nullptr;
  const std::vector<ConfigError> errors = CheckNightSky(styles, schedule, default_catalogue);
  if (!errors.empty()) throw ConfigFailure(errors.front().message, errors);
  auto bake = std::unique_ptr<NightSkyBake>(new NightSkyBake());
  bake->place_ = *schedule->place;
  bake->default_catalogue_ = default_catalogue;
  for (const SkyStyle* s : styles)
    if (s->night.stars) bake->catalogues_.Get(StarCataloguePathOf(*s, default_catalogue));
  return bake;
}

std::optional<NightFrame> NightSkyBake::Frame(const SkyStyle& unpruned, const std::optional<CivilTime>& time,
                                              const glm::dvec3& sun) {
  if (!unpruned.night.Any() || !time) return std::nullopt;
  const auto start = std::chrono::steady_clock::now();
  const SkyStyle style = PrunedStyle(unpruned);
  // The transmittance table of the frame's atmosphere (a schedule's drift
  // makes a new one).
  const AtmosphereParams atmosphere = StyledAtmosphere(style.atmosphere, style.aoas);
  const gpu::GpuAtmosphere packed = ToGpuAtmosphere(atmosphere, style.quality, style.effects, {1.0, 1.0, 1.0});
  std::vector<unsigned char> key(sizeof packed);
  std::memcpy(key.data(), &packed, sizeof packed);
  const TransmittanceTable* table = nullptr;
  for (const auto& [k, t] : tables_)
    if (k == key) table = t.get();
  if (!table) {
    tables_.emplace_back(key, std::make_unique<TransmittanceTable>(atmosphere, style.quality, style.effects));
    table = tables_.back().second.get();
  }
  const StarCatalogue* catalogue = nullptr;
  const StarGrid* grid = nullptr;
  if (style.night.stars) {
    const std::string path = StarCataloguePathOf(style, default_catalogue_);
    catalogue = &catalogues_.Get(path);
    // The catalogue binned once per bake, for the bound before placement.
    std::unique_ptr<StarGrid>& g = grids_[{path, style.night.star_magnitude_limit, int(style.output.units)}];
    if (!g) g = std::make_unique<StarGrid>(*catalogue, style.night.star_magnitude_limit, style.output.units);
    grid = g.get();
  }
  NightFrame frame = ComputeNightFrame(style, catalogue, *table, JulianDayUt(*time), place_, sun, grid);
  // The glow's zenith luminance is the floor's, which the pruned style has
  // taken out of the shaders (PrunedStyle).
  if (style.night.airglow)
    frame.airglow = AirglowTable(atmosphere, *table, style.night.airglow_height_km,
                                 unpruned.effects.night_sky_luminance_cd_m2, style.output.units);
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return frame;
}

void NightSkyBake::RecordMoon(const SkyStyle& style, const NightFrame& night, ShRgb& sh_radiance_with_lights,
                              std::optional<MoonRecord>& record) const {
  if (!night.moon) return;
  const MoonState& m = *night.moon;
  MoonRecord r;
  r.direction = m.sky.direction;
  r.elevation_deg = m.sky.elevation_deg;
  r.azimuth_deg = m.sky.azimuth_deg;
  r.phase_angle_deg = m.phase_angle_deg;
  r.illuminated_fraction = m.illuminated_fraction;
  r.bright_limb_deg = m.bright_limb_deg;
  r.angular_radius_rad = m.angular_radius_rad;
  r.top_illuminance_lux = m.illuminance_lux;
  r.illuminance_lux = night.moon_illuminance_lux;
  r.irradiance = night.moon_irradiance;
  r.light = style.night.moonlight;
  if (r.light) AddDirectionalSource(sh_radiance_with_lights, r.direction, r.irradiance);
  record = r;
}

namespace {
double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}
}  // namespace

void NightSkyBake::AddToViews(NightSkyRenderer& renderer, const SkyStyle& style, const NightFrame& night,
                              const std::vector<ViewRequest>& views, std::vector<RgbaImage>& images) {
  const auto start = std::chrono::steady_clock::now();
  renderer.AddToViews(PrunedStyle(style), night, views, images);
  seconds_ += SecondsSince(start);
}

void NightSkyBake::AddToFaces(NightSkyRenderer& renderer, const SkyStyle& style, const NightFrame& night,
                              const std::vector<ViewRequest>& views, std::vector<std::vector<float>>& faces) {
  const auto start = std::chrono::steady_clock::now();
  renderer.AddToFaces(PrunedStyle(style), night, views, faces);
  seconds_ += SecondsSince(start);
}

void NightSkyBake::AddMoonToIbl(const SkyStyle& style, const NightFrame& night, IblRequest& request) {
  if (!night.moon || !style.ibl.include_sun || !(style.night.moon || style.night.moonlight)) return;
  request.moon = true;
  request.moon_direction = night.moon->sky.direction;
  request.moon_irradiance = night.moon_irradiance;
}

double NightSkyBake::TakeSeconds() {
  const double s = seconds_;
  seconds_ = 0.0;
  return s;
}

std::string NightSkyBake::Describe(const NightFrame& night) {
  std::string d =
      !night.pending ? fmt::format("{} stars", night.stars)
      : night.pending->placed()
          ? fmt::format("{} stars (placed for the views the daylight may not hide them in)", night.pending->stars())
          : std::string("no star placed (the daylit sky outshines them in every view)");
  if (night.moon)
    d += fmt::format(", Moon at {:.1f} deg, phase angle {:.1f} deg, {:.3g} lux{}", night.moon->sky.elevation_deg,
                     night.moon->phase_angle_deg, night.moon_illuminance_lux,
                     night.moonlight_scale > 0.0 ? ", moonlit sky rendered" : "");
  if (!night.airglow.empty()) d += ", airglow";
  return d;
}

}  // namespace skybake
