// The cloud formation's clock (cloud_formation.h, "The clock"): the
// automaton's state at a frame is a function of the frame's clock time from
// a documented origin (day_start_hour on the local clock of the frame's
// date), not of where its schedule starts; and its cover changes over 15-
// and 30-minute steps no faster than a wind-only layer's, without specks or
// a lattice in the shadow maps.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "skybake/base/errors.h"
#include "skybake/model/cloud_formation.h"
#include "schedule_fixtures.h"
#include "test_support.h"

namespace skybake {
namespace {

TEST(CloudFormationClock, TimeIsTheClockSinceTheDaysStart) {
  CloudFormation f;
  // No clock time: the seconds since the first frame, as given.
  EXPECT_DOUBLE_EQ(FormationTimeSeconds(f, std::nullopt, 5400.0), 5400.0);
  // 09:30 with the day starting at midnight: 9.5 h, whatever the schedule's start.
  EXPECT_DOUBLE_EQ(FormationTimeSeconds(f, 9.5 * 3600.0, 0.0), 9.5 * 3600.0);
  EXPECT_DOUBLE_EQ(FormationTimeSeconds(f, 9.5 * 3600.0, 7200.0), 9.5 * 3600.0);
  f.day_start_hour = 12.0;
  EXPECT_DOUBLE_EQ(FormationTimeSeconds(f, 12.0 * 3600.0, 0.0), 0.0);
  EXPECT_DOUBLE_EQ(FormationTimeSeconds(f, 18.0 * 3600.0, 0.0), 6.0 * 3600.0);
  // Before the day's start: the previous day's run, 21 h after its start.
  EXPECT_DOUBLE_EQ(FormationTimeSeconds(f, 9.0 * 3600.0, 0.0), 21.0 * 3600.0);
  // The coverage at a clock time is the same map whichever frame came first.
  const FormationCoverage late = FormationCoverageAt(f, nullptr, 3, FormationTimeSeconds(f, 15.0 * 3600.0, 0.0), 32);
  (void)FormationCoverageAt(f, nullptr, 3, FormationTimeSeconds(f, 17.0 * 3600.0, 0.0), 32);
  const FormationCoverage again =
      FormationCoverageAt(f, nullptr, 3, FormationTimeSeconds(f, 15.0 * 3600.0, 2.0 * 3600.0), 32);
  EXPECT_EQ(late.map, again.map);
  EXPECT_EQ(late.origin_m, again.origin_m);
}

// A formation whose lattices a frame reads (cells x (smoothing_steps + 2)
// steps) exceed the memory budget is refused before anything is written,
// with the estimate and the keys to lower: 512 x 512 x 64 cells over 66
// steps, 7 bytes a cell, about 7.4 GiB against the default 4 GiB.
TEST(CloudFormationClock, LatticesAboveTheMemoryBudgetAreRefusedUpFront) {
  namespace fs = std::filesystem;
  const std::string root = testing::FreshTempDir("cloud_formation_budget");
  const std::string style = testing::WriteFile(root, "style.toml", R"([[cloud_layer]]
altitude_m = 1500
thickness_m = 1200

[cloud_layer.formation]
enabled = true
cells = [512, 512, 64]
smoothing_steps = 64
)");
  const testing::CommandRun run = testing::RunSkybake("bake '" + style + "' --size 16 -q --out '" + root + "/out'");
  EXPECT_EQ(run.exit_code, int(kExitBudget)) << run.output;
  EXPECT_NE(run.output.find("MiB of it the cloud formations' lattices"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("lower [cloud_layer.formation] cells or smoothing_steps"), std::string::npos) << run.output;
  EXPECT_FALSE(fs::exists(root + "/out/manifest.json"));
  fs::remove_all(root);
}

// A formation layer with wind, drift and a cloud shadow map; float pixels,
// so that no sequence's half-float scale enters the values.
std::string ClockStyle() {
  return R"([quality]
preset = "draft"
cloud_view_steps = 16

[output]
pixel_type = "float"

[sun]
elevation_deg = 50.0

[[cloud_layer]]
altitude_m = 1500
thickness_m = 1200
coverage = 0.55
wind_m_s = [4.0, 1.0]

[cloud_layer.formation]
enabled = true
cells = [32, 32, 4]
steps_per_hour = 40
warmup_steps = 20
day_start_hour = 6.0
phase_probability = 0.005
velocity_cells_per_hour = [2.0, 1.0, 0.0]

[cloud_shadow]
enabled = true
resolution = 32
)";
}

// The decoded RGB of an EXR (pixel values only: the headers name the frame's
// number, which differs between schedules).
std::vector<float> Pixels(const std::string& path) {
  int w = 0, h = 0;
  std::vector<float> rgb;
  testing::ReadRgb(path, w, h, rgb);
  return rgb;
}

// 09:00 is frame 3 of a schedule from 08:00 every 30 minutes, frame 1 of one
// from 09:00 every 15 minutes, and the only frame of the first schedule's
// --frames 3:3 part: its sky and its cloud shadow map hold the same pixels,
// bit for bit, in all three.
TEST(CloudFormationClock, SchedulesSharingAClockTimeBakeTheSamePixels) {
  namespace fs = std::filesystem;
  const std::string root = testing::FreshTempDir("cloud_formation_clock");
  const std::string style = testing::WriteFile(root, "style.toml", ClockStyle());
  const std::string a = testing::WriteFile(root, "a.toml", testing::IthacaSchedule("08:00:00", "09:00:00", 30));
  const std::string b = testing::WriteFile(root, "b.toml", testing::IthacaSchedule("09:00:00", "09:30:00", 15));
  testing::BakeSequence16(style, a, root + "/a");
  testing::BakeSequence16(style, b, root + "/b");
  testing::BakeSequence16(style, a, root + "/a_part", "--frames 3:3");
  for (const char* kind : {"latlong", "cloudshadow"}) {
    const std::vector<float> at_a = Pixels(fmt::format("{}/a/sky_{}.0003.exr", root, kind));
    ASSERT_FALSE(at_a.empty()) << kind;
    EXPECT_TRUE(at_a == Pixels(fmt::format("{}/b/sky_{}.0001.exr", root, kind))) << kind << ": a 3 vs b 1";
    EXPECT_TRUE(at_a == Pixels(fmt::format("{}/a_part/sky_{}.0003.exr", root, kind))) << kind << ": a 3 vs part 3";
    // The clouds do change between the clock times (the comparison can fail).
    EXPECT_FALSE(at_a == Pixels(fmt::format("{}/b/sky_{}.0002.exr", root, kind))) << kind << ": 09:00 vs 09:15";
  }
  fs::remove_all(root);
}

// ---------------------------------------------------------------- over a day

// The R channel of a cloud shadow map (square), rows from the north edge.
std::vector<double> ShadowMap(const std::string& path, int& n) {
  int w = 0, h = 0;
  std::vector<float> rgb;
  if (!testing::ReadRgb(path, w, h, rgb) || w != h) return {};
  n = w;
  std::vector<double> r(size_t(w) * h);
  for (size_t i = 0; i < r.size(); ++i) r[i] = rgb[3 * i];
  return r;
}

// In-place radix-2 FFT of n complex values (re, im), n a power of two.
void Fft(std::vector<double>& re, std::vector<double>& im) {
  const size_t n = re.size();
  for (size_t i = 1, j = 0; i < n; ++i) {
    size_t bit = n >> 1;
    for (; j & bit; bit >>= 1) j ^= bit;
    j ^= bit;
    if (i < j) std::swap(re[i], re[j]), std::swap(im[i], im[j]);
  }
  for (size_t len = 2; len <= n; len <<= 1) {
    const double a = -2.0 * M_PI / double(len);
    for (size_t i = 0; i < n; i += len)
      for (size_t k = 0; k < len / 2; ++k) {
        const double c = std::cos(a * double(k)), s = std::sin(a * double(k));
        const size_t p = i + k, q = i + k + len / 2;
        const double xr = re[q] * c - im[q] * s, xi = re[q] * s + im[q] * c;
        re[q] = re[p] - xr, im[q] = im[p] - xi;
        re[p] += xr, im[p] += xi;
      }
  }
}

// The lattice measure: the power spectra of the maps (each less its mean,
// under a 2D Hann window so that a map that does not wrap leaks no edge into
// the spectrum) summed; for every ring of whole radius r = 4 .. n/2 - 1
// cycles per map, the largest bin of the ring over the ring's median. A
// lattice (a repeated tile, specks on a grid) puts its power into a few bins
// of a ring, which stand far above the ring; a field without one spreads it
// over the ring (a bin of one map's spectrum is exponentially distributed
// about the ring's mean: over the 2n^2 / pi bins of a 256 map the largest is
// expected near ln(2n^2 / pi) / ln 2 = 15 medians for a single map, less for
// a sum of maps). Returns the largest ratio and its ring.
std::pair<double, int> LatticePeak(const std::vector<std::vector<double>>& maps, int n) {
  std::vector<double> power(size_t(n) * n, 0.0);
  for (const std::vector<double>& m : maps) {
    const double mean = std::accumulate(m.begin(), m.end(), 0.0) / double(m.size());
    std::vector<double> re(size_t(n) * n), im(size_t(n) * n, 0.0);
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const double hann = (0.5 - 0.5 * std::cos(2.0 * M_PI * x / n)) * (0.5 - 0.5 * std::cos(2.0 * M_PI * y / n));
        re[size_t(y) * n + x] = (m[size_t(y) * n + x] - mean) * hann;
      }
    std::vector<double> r(n), i(n);
    for (int y = 0; y < n; ++y) {  // rows, then columns
      std::copy_n(re.begin() + size_t(y) * n, n, r.begin());
      std::copy_n(im.begin() + size_t(y) * n, n, i.begin());
      Fft(r, i);
      std::copy_n(r.begin(), n, re.begin() + size_t(y) * n);
      std::copy_n(i.begin(), n, im.begin() + size_t(y) * n);
    }
    for (int x = 0; x < n; ++x) {
      for (int y = 0; y < n; ++y) r[y] = re[size_t(y) * n + x], i[y] = im[size_t(y) * n + x];
      Fft(r, i);
      for (int y = 0; y < n; ++y) power[size_t(y) * n + x] += r[y] * r[y] + i[y] * i[y];
    }
  }
  std::vector<std::vector<double>> rings(size_t(n / 2));
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const int fx = x <= n / 2 ? x : x - n, fy = y <= n / 2 ? y : y - n;
      const int ring = int(std::lround(std::hypot(double(fx), double(fy))));
      if (ring >= 4 && ring < n / 2) rings[size_t(ring)].push_back(power[size_t(y) * n + x]);
    }
  std::pair<double, int> worst{0.0, 0};
  for (int ring = 4; ring < n / 2; ++ring) {
    std::vector<double>& bins = rings[size_t(ring)];
    const double top = *std::max_element(bins.begin(), bins.end());
    std::nth_element(bins.begin(), bins.begin() + bins.size() / 2, bins.end());
    const double median = bins[bins.size() / 2];
    if (median > 0.0 && top / median > worst.first) worst = {top / median, ring};
  }
  return worst;
}

// Above this a ring holds a lattice: 2x the largest ratio a single map
// without one is expected to reach (15, above), and 3x the 10.2 the
// wind-only afternoon layer's nine maps reach; a repeated 4 km shape tile
// under the formation's sparse cover reached 128 (before its warp).
constexpr double kLatticePeakRatio = 30.0;

// The lattice measure sees a lattice: a smooth random field (wind-only
// shadow-like blobs: a sum of random Gaussians) has no peak above the bound;
// the same field with one-texel specks 0.1 deep (a third of a blob's depth)
// on a 2 km grid (of a 32 km, 256-texel map: ring 16 and its harmonics at
// (16 a, 16 b)) has one.
TEST(CloudFormationClock, LatticeMeasureSeesSpecksOnAGrid) {
  const int n = 256;
  std::vector<double> field(size_t(n) * n, 1.0);
  uint64_t state = 12345;
  auto uniform = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return double(state >> 11) / 9007199254740992.0;
  };
  for (int b = 0; b < 300; ++b) {
    const double cx = uniform() * n, cy = uniform() * n, radius = 2.0 + 10.0 * uniform();
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
        field[size_t(y) * n + x] -= 0.3 * std::exp(-(std::pow(x - cx, 2) + std::pow(y - cy, 2)) / (radius * radius));
  }
  const std::pair<double, int> clean = LatticePeak({field}, n);
  std::vector<double> specks = field;
  for (int y = 0; y < n; y += 16)
    for (int x = 0; x < n; x += 16) specks[size_t(y) * n + x] -= 0.1;
  const std::pair<double, int> lattice = LatticePeak({specks}, n);
  std::printf("lattice measure: smooth field %.1f (ring %d), with 2 km specks %.1f (ring %d)\n", clean.first,
              clean.second, lattice.first, lattice.second);
  EXPECT_LT(clean.first, kLatticePeakRatio);
  EXPECT_GT(lattice.first, kLatticePeakRatio);
}

// The shipped afternoon_buildup style (a formation with wind and drift) with
// `edit` applied to its formation table: "off" turns the formation off (the
// same layer wind-only, the procedural weather), any other text is added to
// the table; baked 12:00 to 14:00 every 15 minutes into a fresh folder: its
// nine cloud shadow maps.
struct AfternoonMaps {
  std::vector<std::vector<double>> maps;
  int n = 0;
};
AfternoonMaps BakeAfternoon(const std::string& edit = "") {
  namespace fs = std::filesystem;
  const std::string root = testing::FreshTempDir("cloud_formation_day");
  const fs::path styles = fs::path(testing::SourceDir()) / "configs" / "styles";
  fs::copy_file(styles / "afternoon_buildup_mask.png", root + "/afternoon_buildup_mask.png");
  std::string text = testing::ReadFileBytes((styles / "afternoon_buildup.toml").string());
  const size_t on = text.find("enabled = true", text.find("[cloud_layer.formation]"));
  EXPECT_NE(on, std::string::npos);
  if (on != std::string::npos) text.replace(on, 14, edit == "off" ? "enabled = false" : "enabled = true\n" + edit);
  const std::string style = testing::WriteFile(root, "style.toml", text);
  const std::string schedule =
      testing::WriteFile(root, "day.toml", testing::IthacaSchedule("12:00:00", "14:00:00", 15));
  testing::BakeSequence16(style, schedule, root + "/out");
  AfternoonMaps m;
  for (int frame = 1; frame <= 9; ++frame) {
    m.maps.push_back(ShadowMap(fmt::format("{}/out/sky_cloudshadow.{:04d}.exr", root, frame), m.n));
    if (m.maps.back().empty()) ADD_FAILURE() << "frame " << frame;
  }
  fs::remove_all(root);
  return m;
}

// Pearson's correlation of two maps of the same size.
double Correlation(const std::vector<double>& a, const std::vector<double>& b) {
  const double ma = std::accumulate(a.begin(), a.end(), 0.0) / double(a.size());
  const double mb = std::accumulate(b.begin(), b.end(), 0.0) / double(b.size());
  double ab = 0.0, aa = 0.0, bb = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    ab += (a[i] - ma) * (b[i] - mb);
    aa += (a[i] - ma) * (a[i] - ma);
    bb += (b[i] - mb) * (b[i] - mb);
  }
  return aa > 0.0 && bb > 0.0 ? ab / std::sqrt(aa * bb) : 0.0;
}

// The mean correlation of each map with the one `apart` frames later.
double MeanCorrelation(const AfternoonMaps& m, size_t apart) {
  double sum = 0.0;
  size_t pairs = 0;
  for (size_t i = 0; i + apart < m.maps.size(); ++i, ++pairs) sum += Correlation(m.maps[i], m.maps[i + apart]);
  return pairs ? sum / double(pairs) : 0.0;
}

// Over 15 and 30 minutes (the frames one and two apart; a 30-minute
// schedule's frames are the same maps, the clock being absolute) the
// afternoon's formation, as the whole density of its layer and smoothed over
// the last hour (smoothing_steps = 20 at 20 steps per hour), changes its
// cloud shadow map no faster than the same layer wind-only does: the mean
// correlation of consecutive maps is at least the wind-only layer's. The
// shipped style (a coverage-only formation, its puffs carved by the shape
// noise) is measured and printed, not asserted: its cover is a few hundred
// metre puffs that the wind's 2.7 km in 15 minutes moves off themselves.
TEST(CloudFormationClock, CoverHoldsOverQuarterAndHalfHours) {
  const AfternoonMaps wind = BakeAfternoon("off");
  const AfternoonMaps density = BakeAfternoon("density = true\nsmoothing_steps = 20");
  const AfternoonMaps shipped = BakeAfternoon();
  auto print = [](const char* what, const AfternoonMaps& m) {
    std::printf("%s: consecutive shadow maps correlate %.3f at 15 min, %.3f at 30 min\n", what, MeanCorrelation(m, 1),
                MeanCorrelation(m, 2));
  };
  print("wind-only layer", wind);
  print("formation, whole density, smoothing_steps 20", density);
  print("shipped afternoon_buildup (coverage only; not asserted)", shipped);
  EXPECT_GE(MeanCorrelation(density, 1), MeanCorrelation(wind, 1));
  EXPECT_GE(MeanCorrelation(density, 2), MeanCorrelation(wind, 2));
  // The whole-density formation's maps hold no lattice either.
  EXPECT_LT(LatticePeak(density.maps, density.n).first, kLatticePeakRatio);
}

// The formation's shadow maps over the afternoon hold no lattice
// (LatticePeak over the nine maps; before the formation's shape was read
// through the warp, the repeated 4 km shape tile made ring 16, a 2 km
// lattice, stand 128 times above its ring's median).
TEST(CloudFormationClock, ShadowMapsHoldNoLattice) {
  const AfternoonMaps formation = BakeAfternoon();
  ASSERT_EQ(formation.maps.size(), 9u);
  const std::pair<double, int> peak = LatticePeak(formation.maps, formation.n);
  std::printf("afternoon formation: lattice peak %.1f x its ring's median (ring %d of %d)\n", peak.first, peak.second,
              formation.n / 2);
  EXPECT_LT(peak.first, kLatticePeakRatio);
}

}  // namespace
}  // namespace skybake
