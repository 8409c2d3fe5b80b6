// The cloud-formation automaton (cloud_formation.h): Dobashi 2000's rules,
// the density mask, the smoothing and the coverage map of a cloud layer.
#include "skybake/model/cloud_formation.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <mutex>
#include <stdexcept>

#include <fmt/format.h>

#include "skybake/base/file_door.h"
#include "skybake/model/clouds.h"

namespace skybake {

CloudLattice::CloudLattice(int nx_, int ny_, int nz_)
    : nx(nx_), ny(ny_), nz(nz_), hum(Cells(), 0), act(Cells(), 0), cld(Cells(), 0) {}

namespace {

// Reads the image and checks it against the formation: "" or what is wrong.
std::string LoadMask(const std::string& path, const CloudFormation& f, CloudMask* mask) {
  int width = 0, height = 0, channels = 0;
  std::vector<float> pixels;
  // Through the door (file_door.h): a regular file, read once per bake.
  if (std::string problem = ReadImageFile(path, width, height, channels, pixels); !problem.empty()) return problem;
  if (channels < 3)
    return fmt::format("{} channel{}; a mask needs 3 or 4 (R humidity, G phase readiness, B extinction)", channels,
                       channels == 1 ? "" : "s");
  if (width != f.cells[0] || height != f.cells[1] * f.mask_layers)
    return fmt::format(
        "{} x {} texels; {} layer(s) of the {} x {} lattice need {} x {} (formation.cells, "
        "formation.mask_layers)",
        width, height, f.mask_layers, f.cells[0], f.cells[1], f.cells[0], f.cells[1] * f.mask_layers);
  if (mask) {
    mask->width = f.cells[0];
    mask->height = f.cells[1];
    mask->layers = f.mask_layers;
    mask->rgb.resize(size_t(width) * height * 3);
    for (size_t i = 0; i < size_t(width) * height; ++i)
      for (int c = 0; c < 3; ++c) mask->rgb[3 * i + c] = std::clamp(pixels[i * channels + c], 0.0f, 1.0f);
  }
  return "";
}

uint64_t Threshold(double p) { return uint64_t(std::llround(std::clamp(p, 0.0, 1.0) * 4294967296.0)); }

uint64_t Mix64(uint64_t x) {  // splitmix64's finaliser
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ull;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebull;
  x ^= x >> 31;
  return x;
}

// The step index of the draws that set up step 0.
constexpr uint64_t kInitialStep = ~uint64_t(0);

}  // namespace

std::string CheckCloudMask(const std::string& path, const CloudFormation& formation) {
  return LoadMask(path, formation, nullptr);
}

CloudMask ReadCloudMask(const std::string& path, const CloudFormation& formation) {
  CloudMask mask;
  const std::string problem = LoadMask(path, formation, &mask);
  if (!problem.empty()) throw std::runtime_error(path + ": " + problem);
  return mask;
}

uint32_t FormationRandom(uint32_t seed, uint64_t step, uint64_t cell, uint32_t channel) {
  uint64_t h = Mix64((uint64_t(seed) << 2 | channel) ^ 0x9e3779b97f4a7c15ull);
  h = Mix64(h ^ (step * 0xd1b54a32d192ed03ull));
  h = Mix64(h ^ (cell * 0x8cb92ba72f3d8dd7ull));
  return uint32_t(h >> 32);
}

void ApplyFormationRules(CloudLattice& l) {
  const std::vector<uint8_t> act = l.act;  // the rules read step t, write step t + 1
  // Wrapped neighbour columns and rows, once (no modulo per cell).
  auto wrapped = [](int n, int d) {
    std::vector<int> w(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) w[size_t(i)] = ((i + d) % n + n) % n;
    return w;
  };
  const std::vector<int> xm1 = wrapped(l.nx, -1), xp1 = wrapped(l.nx, 1), xm2 = wrapped(l.nx, -2),
                         xp2 = wrapped(l.nx, 2);
  const std::vector<int> ym1 = wrapped(l.ny, -1), yp1 = wrapped(l.ny, 1), ym2 = wrapped(l.ny, -2),
                         yp2 = wrapped(l.ny, 2);
  const size_t layer = size_t(l.nx) * l.ny;
  for (int z = 0; z < l.nz; ++z) {
    const uint8_t* here = act.data() + z * layer;
    const uint8_t* below1 = z >= 1 ? here - layer : nullptr;
    const uint8_t* below2 = z >= 2 ? here - 2 * layer : nullptr;
    const uint8_t* above1 = z + 1 < l.nz ? here + layer : nullptr;
    for (int y = 0; y < l.ny; ++y) {
      const uint8_t* row = here + size_t(y) * l.nx;
      const uint8_t* r_m1 = here + size_t(ym1[y]) * l.nx;
      const uint8_t* r_p1 = here + size_t(yp1[y]) * l.nx;
      const uint8_t* r_m2 = here + size_t(ym2[y]) * l.nx;
      const uint8_t* r_p2 = here + size_t(yp2[y]) * l.nx;
      for (int x = 0; x < l.nx; ++x) {
        const size_t i = l.Index(x, y, z);
        const size_t c = size_t(y) * l.nx + x;
        uint8_t f_act = row[xp1[x]] | row[xm1[x]] | row[xp2[x]] | row[xm2[x]] | r_m1[x] | r_p1[x] | r_m2[x] | r_p2[x];
        if (below1) f_act |= below1[c];
        if (below2) f_act |= below2[c];
        if (above1) f_act |= above1[c];
        const uint8_t a = act[i], h = l.hum[i];
        l.hum[i] = h & uint8_t(!a);
        l.cld[i] = l.cld[i] | a;
        l.act[i] = uint8_t(!a) & h & f_act;
      }
    }
  }
}

void StepFormation(CloudLattice& l, const FormationThresholds& t, uint32_t seed, uint64_t step) {
  ApplyFormationRules(l);
  const size_t columns = size_t(l.nx) * l.ny;
  for (size_t i = 0, c = 0; i < l.Cells(); ++i, c = c + 1 == columns ? 0 : c + 1) {
    if (l.cld[i] && FormationRandom(seed, step, i, 0) < t.ext[c]) l.cld[i] = 0;
    if (!l.hum[i] && FormationRandom(seed, step, i, 1) < t.hum[c]) l.hum[i] = 1;
    if (!l.act[i] && l.hum[i] && FormationRandom(seed, step, i, 2) < t.act[c]) l.act[i] = 1;
  }
}

FormationThresholds FormationThresholdsAt(const CloudFormation& f, const CloudMask* mask, uint64_t step) {
  const size_t columns = size_t(f.cells[0]) * f.cells[1];
  std::array<std::vector<float>, 3> m;  // R, G, B per column
  for (std::vector<float>& c : m) c.assign(columns, 1.0f);
  if (mask && mask->layers > 0) {
    // The layer moves with velocity z (mask layers per hour of clock time),
    // held at the first and the last layer.
    const double hours = f.steps_per_hour > 0.0 ? std::max(0.0, double(step) - f.warmup_steps) / f.steps_per_hour : 0.0;
    const double layer = std::clamp(f.mask_layer + f.velocity_cells_per_hour[2] * hours, 0.0, double(mask->layers - 1));
    const int l0 = int(std::floor(layer)), l1 = std::min(l0 + 1, mask->layers - 1);
    const float w = float(layer - l0);
    for (size_t i = 0; i < columns; ++i)
      for (int c = 0; c < 3; ++c) {
        const float a = mask->rgb[(size_t(l0) * columns + i) * 3 + c];
        const float b = mask->rgb[(size_t(l1) * columns + i) * 3 + c];
        m[c][i] = a + (b - a) * w;
      }
  }
  // Lattice y runs north; mask rows run from the north edge.
  FormationThresholds t;
  t.hum.resize(columns);
  t.act.resize(columns);
  t.ext.resize(columns);
  for (int y = 0; y < f.cells[1]; ++y) {
    for (int x = 0; x < f.cells[0]; ++x) {
      const size_t cell = size_t(y) * f.cells[0] + x;
      const size_t texel = size_t(f.cells[1] - 1 - y) * f.cells[0] + x;
      t.hum[cell] = Threshold(f.humidity_probability * m[0][texel]);
      t.act[cell] = Threshold(f.phase_probability * m[1][texel]);
      t.ext[cell] = Threshold(f.extinction_probability * m[2][texel]);
    }
  }
  return t;
}

CloudLattice InitialFormation(const CloudFormation& f, const CloudMask* mask, uint32_t seed) {
  CloudLattice l(f.cells[0], f.cells[1], f.cells[2]);
  // The mask's red at step 0 scales the initial humidity: the thresholds
  // of a formation whose humidity probability is initial_humidity.
  CloudFormation initial = f;
  initial.humidity_probability = f.initial_humidity;
  const FormationThresholds t = FormationThresholdsAt(initial, mask, 0);
  const size_t columns = size_t(l.nx) * l.ny;
  for (size_t i = 0; i < l.Cells(); ++i) l.hum[i] = FormationRandom(seed, kInitialStep, i, 1) < t.hum[i % columns];
  return l;
}

namespace {

// Everything the lattice depends on, as text.
std::string FormationKey(const CloudFormation& f, const CloudMask* mask, uint32_t seed) {
  uint64_t mask_hash = 0;
  if (mask)
    for (float v : mask->rgb) mask_hash = Mix64(mask_hash ^ uint64_t(std::llround(double(v) * 1e9)));
  return fmt::format("{} {} {} {} {:a} {:a} {:a} {:a} {:a} {} {:a} {:a} {}", seed, f.cells[0], f.cells[1], f.cells[2],
                     f.steps_per_hour, f.extinction_probability, f.humidity_probability, f.phase_probability,
                     f.initial_humidity, f.mask_layers, f.mask_layer, f.velocity_cells_per_hour[2], mask_hash) +
         fmt::format(" {}", f.warmup_steps);
}

// The lattices of consecutive steps, from `first`.
struct CachedFormation {
  uint64_t first = 0;
  std::vector<CloudLattice> window;
};

}  // namespace

std::vector<CloudLattice> SimulateFormationSteps(const CloudFormation& f, const CloudMask* mask, uint32_t seed,
                                                 uint64_t first, uint64_t last) {
  static std::mutex mutex;
  static std::map<std::string, CachedFormation> cache;
  const std::string key = FormationKey(f, mask, seed);
  CachedFormation state;
  {
    std::lock_guard<std::mutex> lock(mutex);
    auto it = cache.find(key);
    if (it != cache.end() && !it->second.window.empty() && it->second.first <= first) state = it->second;
  }
  if (state.window.empty()) state = {0, {InitialFormation(f, mask, seed)}};
  const uint64_t latest = state.first + state.window.size() - 1;
  std::vector<CloudLattice> out;
  for (uint64_t s = first; s <= std::min(latest, last); ++s) out.push_back(state.window[s - state.first]);
  if (last > latest) {
    // The thresholds change only with the mask layer (velocity z).
    const bool moving_mask = mask && f.velocity_cells_per_hour[2] != 0.0;
    FormationThresholds thresholds = FormationThresholdsAt(f, mask, latest);
    CloudLattice lattice = state.window.back();
    for (uint64_t s = latest; s < last; ++s) {
      if (moving_mask) thresholds = FormationThresholdsAt(f, mask, s);
      StepFormation(lattice, thresholds, seed, s);
      if (s + 1 >= first) out.push_back(lattice);
    }
    std::lock_guard<std::mutex> lock(mutex);
    if (cache.size() > 16) cache.clear();
    cache[key] = {first, out};
  }
  return out;
}

CloudLattice SimulateFormation(const CloudFormation& f, const CloudMask* mask, uint32_t seed, uint64_t steps) {
  return SimulateFormationSteps(f, mask, seed, steps, steps).back();
}

std::vector<float> SmoothFormation(const CloudLattice& l, int r) {
  std::vector<float> a(l.Cells()), b(l.Cells());
  for (size_t i = 0; i < l.Cells(); ++i) a[i] = float(l.cld[i]);
  if (r <= 0) return a;
  // Separable box means: x and y wrap (the lattice tiles), z is cut at the
  // ends (the mean of the cells inside).
  const float wrap_norm = 1.0f / float(2 * r + 1);
  for (int z = 0; z < l.nz; ++z)
    for (int y = 0; y < l.ny; ++y)
      for (int x = 0; x < l.nx; ++x) {
        float s = 0.0f;
        for (int d = -r; d <= r; ++d) s += a[l.Index(((x + d) % l.nx + l.nx) % l.nx, y, z)];
        b[l.Index(x, y, z)] = s * wrap_norm;
      }
  for (int z = 0; z < l.nz; ++z)
    for (int y = 0; y < l.ny; ++y)
      for (int x = 0; x < l.nx; ++x) {
        float s = 0.0f;
        for (int d = -r; d <= r; ++d) s += b[l.Index(x, ((y + d) % l.ny + l.ny) % l.ny, z)];
        a[l.Index(x, y, z)] = s * wrap_norm;
      }
  for (int z = 0; z < l.nz; ++z)
    for (int y = 0; y < l.ny; ++y)
      for (int x = 0; x < l.nx; ++x) {
        float s = 0.0f;
        int n = 0;
        for (int d = -r; d <= r; ++d)
          if (z + d >= 0 && z + d < l.nz) s += a[l.Index(x, y, z + d)], ++n;
        b[l.Index(x, y, z)] = s / float(n);
      }
  return b;
}

namespace {

std::vector<float> ColumnMaximum(const CloudLattice& l, const std::vector<float>& density) {
  std::vector<float> column(size_t(l.nx) * l.ny, 0.0f);
  for (int z = 0; z < l.nz; ++z)
    for (size_t c = 0; c < column.size(); ++c) column[c] = std::max(column[c], density[size_t(z) * column.size() + c]);
  return column;
}

// The density at the whole steps around the fractional `step`: at n =
// floor(step) and, when step is past n, at n + 1 (else empty). Each is
// SmoothFormation's field, averaged over the steps s - smoothing_steps .. s
// (those from step 0; one step alone when smoothing_steps is 0).
struct DensitiesAround {
  CloudLattice lattice;  // the lattice at n (its size and indexing)
  std::vector<float> at, next;
  float w = 0.0f;  // the fraction of the way from n to n + 1
};
DensitiesAround DensitiesAt(const CloudFormation& f, const CloudMask* mask, uint32_t seed, double step) {
  DensitiesAround d;
  const uint64_t n = uint64_t(std::floor(step));
  d.w = float(step - double(n));
  const uint64_t k = uint64_t(std::max(f.smoothing_steps, 0));
  const uint64_t first = n >= k ? n - k : 0;
  const uint64_t last = d.w > 0.0f ? n + 1 : n;
  const std::vector<CloudLattice> lattices = SimulateFormationSteps(f, mask, seed, first, last);
  std::vector<std::vector<float>> smoothed;
  for (const CloudLattice& l : lattices) smoothed.push_back(SmoothFormation(l, f.smoothing_cells));
  auto mean = [&](uint64_t end) {
    const uint64_t lo = end >= k ? end - k : 0;
    std::vector<float> sum = smoothed[lo - first];
    for (uint64_t s = lo + 1; s <= end; ++s)
      for (size_t i = 0; i < sum.size(); ++i) sum[i] += smoothed[s - first][i];
    const float count = float(end - lo + 1);
    if (count > 1.0f)
      for (float& v : sum) v /= count;
    return sum;
  };
  d.lattice = lattices[n - first];
  d.at = mean(n);
  if (d.w > 0.0f) d.next = mean(n + 1);
  return d;
}

}  // namespace

double FormationTimeSeconds(const CloudFormation& f, std::optional<double> local_clock_s, double since_first_s) {
  if (!local_clock_s) return since_first_s;
  constexpr double kDay_s = 86400.0;
  const double t = std::fmod(*local_clock_s - f.day_start_hour * 3600.0, kDay_s);
  return t < 0.0 ? t + kDay_s : t;
}

FormationCoverage FormationCoverageAt(const CloudFormation& f, const CloudMask* mask, uint32_t seed, double time_s,
                                      int resolution) {
  FormationCoverage out;
  const double hours = std::max(time_s, 0.0) / 3600.0;
  out.step = f.warmup_steps + f.steps_per_hour * hours;
  const DensitiesAround d = DensitiesAt(f, mask, seed, out.step);
  std::vector<float> column = ColumnMaximum(d.lattice, d.at);
  if (d.w > 0.0f) {
    // Linear in time between step n and n + 1.
    const std::vector<float> next = ColumnMaximum(d.lattice, d.next);
    for (size_t i = 0; i < column.size(); ++i) column[i] += (next[i] - column[i]) * d.w;
  }
  // Bilinear, wrapping, at the map's texel centres; row 0 is the north edge.
  const int nx = f.cells[0], ny = f.cells[1];
  out.map.resize(size_t(resolution) * resolution);
  auto at = [&](int x, int y) { return column[size_t(((y % ny) + ny) % ny) * nx + ((x % nx) + nx) % nx]; };
  for (int row = 0; row < resolution; ++row) {
    const double v = (1.0 - (row + 0.5) / resolution) * ny - 0.5;
    const int y0 = int(std::floor(v));
    const double fy = v - y0;
    for (int col = 0; col < resolution; ++col) {
      const double u = (col + 0.5) / resolution * nx - 0.5;
      const int x0 = int(std::floor(u));
      const double fx = u - x0;
      const double a = at(x0, y0) * (1 - fx) + at(x0 + 1, y0) * fx;
      const double b = at(x0, y0 + 1) * (1 - fx) + at(x0 + 1, y0 + 1) * fx;
      out.map[size_t(row) * resolution + col] = float(a * (1 - fy) + b * fy);
    }
  }
  // The whole field drifts with velocity x, y (the mask with it).
  for (int a = 0; a < 2; ++a) {
    const double cell_m = f.size_m[a] / f.cells[a];
    out.origin_m[a] = f.origin_m[a] + f.velocity_cells_per_hour[a] * hours * cell_m;
    out.extent_m[a] = f.size_m[a];
  }
  return out;
}

std::vector<float> FormationDensityAt(const CloudFormation& f, const CloudMask* mask, uint32_t seed, double time_s,
                                      int n) {
  const double step = f.warmup_steps + f.steps_per_hour * std::max(time_s, 0.0) / 3600.0;
  DensitiesAround d = DensitiesAt(f, mask, seed, step);
  const CloudLattice& lattice = d.lattice;
  std::vector<float>& density = d.at;
  if (d.w > 0.0f)
    for (size_t i = 0; i < density.size(); ++i) density[i] += (d.next[i] - density[i]) * d.w;
  const int nx = lattice.nx, ny = lattice.ny, nz = lattice.nz;
  auto at = [&](int x, int y, int z) {
    return density[lattice.Index(((x % nx) + nx) % nx, ((y % ny) + ny) % ny, std::clamp(z, 0, nz - 1))];
  };
  std::vector<float> volume(size_t(n) * n * n);
  for (int row = 0; row < n; ++row) {
    const double v = (1.0 - (row + 0.5) / n) * ny - 0.5;
    const int y0 = int(std::floor(v));
    const double fy = v - y0;
    for (int k = 0; k < n; ++k) {
      const double z = std::clamp((k + 0.5) / n * nz - 0.5, 0.0, double(nz - 1));
      const int z0 = int(std::floor(z));
      const double fz = z - z0;
      for (int col = 0; col < n; ++col) {
        const double u = (col + 0.5) / n * nx - 0.5;
        const int x0 = int(std::floor(u));
        const double fx = u - x0;
        double value = 0.0;
        for (int dz = 0; dz < 2; ++dz)
          for (int dy = 0; dy < 2; ++dy)
            for (int dx = 0; dx < 2; ++dx)
              value += (dx ? fx : 1 - fx) * (dy ? fy : 1 - fy) * (dz ? fz : 1 - fz) * at(x0 + dx, y0 + dy, z0 + dz);
        volume[(size_t(row) * n + k) * n + col] = float(value);
      }
    }
  }
  return volume;
}

bool FormationShapeWarped(const CloudLayer& layer) {
  // The whole density (formation.density) reads the detail noise alone.
  const bool reads_noise = layer.detail_amount > 0.0 || (!layer.formation.density && layer.shape_amount > 0.0);
  return !layer.tiling && reads_noise;
}

void ApplyCloudFormation(const CloudLayer& layer, uint32_t seed, int resolution, double time_s,
                         const std::string& style_dir, gpu::GpuCloudLayer& o, std::vector<float>& weather_images,
                         int volume_resolution) {
  const CloudFormation& f = layer.formation;
  CloudMask mask;
  if (!f.mask_image.empty()) {
    std::filesystem::path p(f.mask_image);
    if (p.is_relative() && !style_dir.empty()) p = std::filesystem::path(style_dir) / p;
    mask = ReadCloudMask(p.string(), f);
  }
  const FormationCoverage c = FormationCoverageAt(f, f.mask_image.empty() ? nullptr : &mask, seed, time_s, resolution);
  // As a weather image: row 0, column 0 (the north-west corner) at world
  // x = west edge, z = -(north edge); km.
  o.weather = {float(layer.coverage), float(1e3 / c.extent_m[0]), float(1e3 / c.extent_m[1]), 1.0f};
  // z: its shape and detail noise read through the non-repeating warp of
  // the layer's weather_size_m (cloud_weather.glsl) as a weather image's
  // are (FormationShapeWarped); the coverage map and the density volume are
  // read as they are.
  const bool warped = FormationShapeWarped(layer);
  o.weather_origin = {float(c.origin_m[0] * 1e-3), float(-(c.origin_m[1] + c.extent_m[1]) * 1e-3),
                      warped ? float(layer.weather_size_m * 1e-3) : 0.0f, 0.0f};
  weather_images.insert(weather_images.end(), c.map.begin(), c.map.end());
  if (f.density) {
    o.weather.w = 2.0f;
    const std::vector<float> volume =
        FormationDensityAt(f, f.mask_image.empty() ? nullptr : &mask, seed, time_s, volume_resolution);
    weather_images.insert(weather_images.end(), volume.begin(), volume.end());
  }
}

}  // namespace skybake
