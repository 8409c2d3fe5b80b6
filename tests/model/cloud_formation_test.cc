// The cloud-formation automaton (cloud_formation.h): Dobashi 2000's rules on
// small hand-computed lattices, the extremes of its probabilities, its
// determinism, the density mask and its checks, and a sequence whose parts
// give the whole bake's frames byte for byte.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numeric>
#include <set>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <OpenImageIO/imageio.h>

#include "skybake/model/cloud_formation.h"
#include "skybake/model/clouds.h"
#include "skybake/input/config.h"
#include "schedule_fixtures.h"
#include "test_support.h"

namespace skybake {
namespace {

size_t Count(const std::vector<uint8_t>& v) { return size_t(std::count(v.begin(), v.end(), uint8_t(1))); }

// One ready cell next to one humid cell: the humid cell becomes ready (it
// has a ready neighbour), the ready cell becomes cloud and loses its
// readiness; one step later the humid cell is cloud, dry and not ready.
TEST(CloudFormationRules, TransitionSpreadsFromAReadyCellToAHumidNeighbour) {
  CloudLattice l(6, 6, 4);
  const size_t ready = l.Index(2, 2, 1), humid = l.Index(3, 2, 1);
  l.act[ready] = 1;
  l.hum[humid] = 1;
  ApplyFormationRules(l);
  EXPECT_EQ(l.cld[ready], 1);
  EXPECT_EQ(l.act[ready], 0);
  EXPECT_EQ(l.hum[humid], 1);  // hum' = hum AND NOT act: still humid
  EXPECT_EQ(l.act[humid], 1);  // act' = NOT act AND hum AND f_act
  EXPECT_EQ(l.cld[humid], 0);
  EXPECT_EQ(Count(l.cld), 1u);
  EXPECT_EQ(Count(l.act), 1u);
  ApplyFormationRules(l);
  EXPECT_EQ(l.cld[humid], 1);
  EXPECT_EQ(l.hum[humid], 0);
  EXPECT_EQ(l.act[humid], 0);
  EXPECT_EQ(Count(l.cld), 2u);
  EXPECT_EQ(Count(l.act), 0u);
  EXPECT_EQ(Count(l.hum), 0u);
  // Nothing is ready any more: the lattice stays as it is.
  const CloudLattice before = l;
  ApplyFormationRules(l);
  EXPECT_TRUE(l == before);
}

// Dobashi's neighbourhood: x +-1, +-2; y +-1, +-2; z +-1; z - 2 (below), but
// not z + 2 (above) and not the diagonals; x and y wrap, z does not.
TEST(CloudFormationRules, NeighbourhoodIsDobashis) {
  struct Case {
    int dx, dy, dz;
    bool spreads;
  };
  const Case cases[] = {{1, 0, 0, true},  {-1, 0, 0, true}, {2, 0, 0, true},  {-2, 0, 0, true},
                        {0, 1, 0, true},  {0, -1, 0, true}, {0, 2, 0, true},  {0, -2, 0, true},
                        {0, 0, 1, true},  {0, 0, -1, true}, {0, 0, -2, true}, {0, 0, 2, false},
                        {1, 1, 0, false}, {3, 0, 0, false}, {1, 0, 1, false}, {0, -3, 0, false}};
  for (const Case& c : cases) {
    CloudLattice l(8, 8, 6);
    const int x = 4, y = 4, z = 2;
    l.hum[l.Index(x, y, z)] = 1;
    l.act[l.Index(x + c.dx, y + c.dy, z + c.dz)] = 1;  // the neighbour at (x, y, z) - (-d): f_act looks at it
    ApplyFormationRules(l);
    EXPECT_EQ(l.act[l.Index(x, y, z)], c.spreads ? 1 : 0) << c.dx << " " << c.dy << " " << c.dz;
  }
  // Wrapping: a ready cell at x = 0 reaches a humid cell at x = nx - 1 and
  // x = nx - 2; it reaches two cells up (clouds grow upward) but not two
  // down, and z does not wrap (the top cell is not below the bottom one).
  CloudLattice l(8, 8, 5);
  l.act[l.Index(0, 3, 2)] = 1;
  l.hum[l.Index(7, 3, 2)] = 1;
  l.hum[l.Index(6, 3, 2)] = 1;
  l.hum[l.Index(0, 3, 4)] = 1;  // two above the ready cell
  l.hum[l.Index(0, 3, 0)] = 1;  // two below it
  l.act[l.Index(5, 5, 4)] = 1;  // the top: the bottom cell of its column is not its neighbour
  l.hum[l.Index(5, 5, 0)] = 1;
  ApplyFormationRules(l);
  EXPECT_EQ(l.act[l.Index(7, 3, 2)], 1);
  EXPECT_EQ(l.act[l.Index(6, 3, 2)], 1);
  EXPECT_EQ(l.act[l.Index(0, 3, 4)], 1);
  EXPECT_EQ(l.act[l.Index(0, 3, 0)], 0);
  EXPECT_EQ(l.act[l.Index(5, 5, 0)], 0);
}

// An enabled formation on a `cells` lattice, `warmup_steps` before the first
// frame at `steps_per_hour`, with the probabilities Pext, Phum and Pact; the
// rest as CloudFormation's defaults.
CloudFormation Formation(std::array<int, 3> cells, double steps_per_hour, int warmup_steps, double extinction,
                         double humidity, double phase) {
  return {.enabled = true,
          .cells = cells,
          .steps_per_hour = steps_per_hour,
          .warmup_steps = warmup_steps,
          .extinction_probability = extinction,
          .humidity_probability = humidity,
          .phase_probability = phase};
}

// Most tests': 32 x 32 x 6 cells from step 0, half of them humid.
CloudFormation Formation() {
  CloudFormation f = Formation({32, 32, 6}, 60.0, 0, 0.02, 0.05, 0.01);
  f.initial_humidity = 0.5;
  return f;
}

// Extinction probability 1 clears every cloud every step; with no humidity at
// the start and humidity probability 0 no cloud ever forms, however ready
// the cells are; the same settings with humidity do form clouds.
TEST(CloudFormationRules, ExtremesOfTheProbabilities) {
  CloudFormation f = Formation();
  const CloudLattice growing = SimulateFormation(f, nullptr, 7, 40);
  EXPECT_GT(Count(growing.cld), growing.Cells() / 20);  // the settings do make clouds

  CloudFormation cleared = f;
  cleared.extinction_probability = 1.0;
  cleared.phase_probability = 1.0;
  cleared.humidity_probability = 1.0;
  for (uint64_t steps : {1u, 2u, 5u, 40u})
    EXPECT_EQ(Count(SimulateFormation(cleared, nullptr, 7, steps).cld), 0u) << steps;
  const FormationCoverage c = FormationCoverageAt(cleared, nullptr, 7, 1234.0, 32);
  EXPECT_EQ(*std::max_element(c.map.begin(), c.map.end()), 0.0f);

  CloudFormation dry = f;
  dry.initial_humidity = 0.0;
  dry.humidity_probability = 0.0;
  dry.phase_probability = 1.0;
  const CloudLattice none = SimulateFormation(dry, nullptr, 7, 60);
  EXPECT_EQ(Count(none.cld), 0u);
  EXPECT_EQ(Count(none.hum), 0u);
  EXPECT_EQ(Count(none.act), 0u);
}

// The stochastic rules, by hand on a 4 x 4 x 2 lattice with probabilities 0
// and 1 only: extinction 1 clears the cloud the rules made, humidity 1 makes
// every cell humid again, phase 1 makes every humid cell ready.
TEST(CloudFormationRules, StochasticRulesAtProbabilitiesZeroAndOne) {
  CloudLattice l(4, 4, 2);
  l.act[l.Index(1, 1, 0)] = 1;
  l.hum[l.Index(2, 1, 0)] = 1;
  FormationThresholds t;
  const size_t columns = 16;
  t.ext.assign(columns, 0);
  t.hum.assign(columns, 0);
  t.act.assign(columns, 0);
  CloudLattice a = l;
  StepFormation(a, t, 1, 0);  // all probabilities 0: the rules alone
  CloudLattice rules = l;
  ApplyFormationRules(rules);
  EXPECT_TRUE(a == rules);
  t.ext.assign(columns, uint64_t(1) << 32);
  CloudLattice b = l;
  StepFormation(b, t, 1, 0);
  EXPECT_EQ(Count(b.cld), 0u);
  EXPECT_TRUE(b.act == rules.act && b.hum == rules.hum);
  t.ext.assign(columns, 0);
  t.hum.assign(columns, uint64_t(1) << 32);
  t.act.assign(columns, uint64_t(1) << 32);
  CloudLattice c = l;
  StepFormation(c, t, 1, 0);
  EXPECT_EQ(Count(c.hum), c.Cells());
  EXPECT_EQ(Count(c.act), c.Cells());
  EXPECT_TRUE(c.cld == rules.cld);
}

// The same seed gives the same lattice whether simulated in one go or
// continued from an earlier step (the process's cache), and a fresh process
// would too (the draws depend on seed, step, cell and channel only); another
// seed gives another lattice. The smoothed density lies in [0, 1].
TEST(CloudFormationRules, SameSeedSameLattice) {
  const CloudFormation f = Formation();
  const CloudLattice once = SimulateFormation(f, nullptr, 11, 50);
  (void)SimulateFormation(f, nullptr, 11, 20);
  const CloudLattice continued = SimulateFormation(f, nullptr, 11, 50);
  EXPECT_TRUE(once == continued);
  CloudLattice by_hand = InitialFormation(f, nullptr, 11);
  const FormationThresholds t = FormationThresholdsAt(f, nullptr, 0);
  for (uint64_t s = 0; s < 50; ++s) StepFormation(by_hand, t, 11, s);
  EXPECT_TRUE(by_hand == once);
  EXPECT_FALSE(SimulateFormation(f, nullptr, 12, 50) == once);
  EXPECT_EQ(FormationRandom(3, 4, 5, 1), FormationRandom(3, 4, 5, 1));
  EXPECT_NE(FormationRandom(3, 4, 5, 1), FormationRandom(3, 4, 5, 2));
  const std::vector<float> d = SmoothFormation(once, 1);
  EXPECT_GE(*std::min_element(d.begin(), d.end()), 0.0f);
  EXPECT_LE(*std::max_element(d.begin(), d.end()), 1.0f);
  // Smoothing keeps the amount of cloud (x, y wrap; z is cut, so compare a
  // smoothing in x and y only: one z layer).
  CloudFormation flat = f;
  flat.cells[2] = 1;
  const CloudLattice l1 = SimulateFormation(flat, nullptr, 11, 30);
  const std::vector<float> s1 = SmoothFormation(l1, 2);
  EXPECT_NEAR(std::accumulate(s1.begin(), s1.end(), 0.0), double(Count(l1.cld)), 1e-2);
}

// Clock time: step = warmup + steps_per_hour x hours, the coverage linear
// between two steps; the drift moves the origin by velocity x cell size.
TEST(CloudFormationRules, ClockTimeStepsAndDrift) {
  CloudFormation f = Formation();
  f.warmup_steps = 10;
  f.velocity_cells_per_hour = {2.0, -1.0, 0.0};
  const FormationCoverage a = FormationCoverageAt(f, nullptr, 5, 1800.0, 32);
  EXPECT_DOUBLE_EQ(a.step, 40.0);
  EXPECT_DOUBLE_EQ(a.origin_m[0], -15000.0 + 2.0 * 0.5 * 30000.0 / 32);
  EXPECT_DOUBLE_EQ(a.origin_m[1], -15000.0 - 1.0 * 0.5 * 30000.0 / 32);
  const FormationCoverage b = FormationCoverageAt(f, nullptr, 5, 1830.0, 32);  // step 40.5
  const FormationCoverage c = FormationCoverageAt(f, nullptr, 5, 1860.0, 32);  // step 41
  EXPECT_NE(a.map, c.map);
  for (size_t i = 0; i < a.map.size(); ++i) EXPECT_NEAR(b.map[i], 0.5f * (a.map[i] + c.map[i]), 1e-6f) << i;
}

// The mask's channels: where blue (extinction) is 1 and Pext is 1 no cloud
// stays; where red (humidity) and green (readiness) are 0 none forms; where
// all three allow it, clouds form. Two layers: velocity z moves from the
// first to the second.
// The density volume (FormationDensityAt) is the smoothed lattice itself
// when its size matches the lattice's: texel (column c, row r, level k) is
// cell (c, ny - 1 - r, k) (row 0 north), for a whole step; between two
// steps it is linear in time.
TEST(CloudFormationRules, DensityVolumeIsTheSmoothedLattice) {
  CloudFormation f = Formation({8, 8, 8}, 10.0, 6, 0.1, 0.3, 0.05);
  f.density = true;
  const uint32_t seed = 7;
  const CloudLattice at6 = SimulateFormation(f, nullptr, seed, 6), at7 = SimulateFormation(f, nullptr, seed, 7);
  const std::vector<float> d6 = SmoothFormation(at6, f.smoothing_cells), d7 = SmoothFormation(at7, f.smoothing_cells);
  const std::vector<float> v6 = FormationDensityAt(f, nullptr, seed, 0.0, 8);
  const std::vector<float> half = FormationDensityAt(f, nullptr, seed, 0.05 * 3600.0, 8);  // step 6.5
  ASSERT_EQ(v6.size(), 512u);
  float lo = 1.0f, hi = 0.0f;
  for (int r = 0; r < 8; ++r)
    for (int k = 0; k < 8; ++k)
      for (int c = 0; c < 8; ++c) {
        const size_t i = (size_t(r) * 8 + k) * 8 + c, cell = at6.Index(c, 7 - r, k);
        ASSERT_NEAR(v6[i], d6[cell], 1e-6) << c << " " << r << " " << k;
        ASSERT_NEAR(half[i], 0.5f * (d6[cell] + d7[cell]), 1e-6);
        lo = std::min(lo, v6[i]), hi = std::max(hi, v6[i]);
      }
  EXPECT_LT(lo, hi) << "a lattice with structure";
}

TEST(CloudFormationMask, ChannelsSetTheProbabilitiesPerColumn) {
  const std::string dir = testing::FreshTempDir("cloud_mask");
  // Layer 0: west half humid and ready, east half dry; layer 1 the reverse.
  testing::WriteTestImage(dir + "/mask.png", 32, 64, 3, [](int x, int y, int c) {
    const bool west = x < 16, first = y < 32;
    if (c == 2) return 0.0f;
    return (west == first) ? 1.0f : 0.0f;
  });
  CloudFormation f = Formation();
  f.mask_layers = 2;
  f.extinction_probability = 0.0;
  ASSERT_EQ(CheckCloudMask(dir + "/mask.png", f), "");
  const CloudMask mask = ReadCloudMask(dir + "/mask.png", f);
  auto clouds_in = [](const CloudLattice& l, bool west) {
    size_t n = 0;
    for (int z = 0; z < l.nz; ++z)
      for (int y = 0; y < l.ny; ++y)
        for (int x = 0; x < l.nx; ++x)
          if ((x < l.nx / 2) == west) n += l.cld[l.Index(x, y, z)];
    return n;
  };
  const CloudLattice l0 = SimulateFormation(f, &mask, 3, 40);
  EXPECT_GT(clouds_in(l0, true), 100u);
  EXPECT_EQ(clouds_in(l0, false), 0u);
  CloudFormation moving = f;
  moving.mask_layer = 1.0;
  const CloudLattice l1 = SimulateFormation(moving, &mask, 3, 40);
  EXPECT_EQ(clouds_in(l1, true), 0u);
  EXPECT_GT(clouds_in(l1, false), 100u);
  // Velocity z of one layer per half hour at 60 steps per hour: from step 30 on
  // the second layer; clouds then also form in the east.
  moving.mask_layer = 0.0;
  moving.velocity_cells_per_hour = {0.0, 0.0, 2.0};
  const CloudLattice l2 = SimulateFormation(moving, &mask, 3, 80);
  EXPECT_GT(clouds_in(l2, false), 100u);
  // Blue 1 with Pext 1: no cloud anywhere.
  testing::WriteTestImage(dir + "/clear.png", 32, 32, 4, [](int, int, int) { return 1.0f; });
  CloudFormation clear = Formation();
  clear.extinction_probability = 1.0;
  const CloudMask clear_mask = ReadCloudMask(dir + "/clear.png", clear);
  EXPECT_EQ(Count(SimulateFormation(clear, &clear_mask, 3, 40).cld), 0u);
  std::filesystem::remove_all(dir);
}

// A mask that is missing, of the wrong size or with too few channels stops
// the bake before any GPU work: exit code 3, the message names the path.
TEST(CloudFormationMask, BadMasksExitThreeWithThePath) {
  const std::string dir = testing::FreshTempDir("cloud_mask_bad");
  testing::WriteTestImage(dir + "/small.png", 16, 16, 3, [](int, int, int) { return 0.5f; });
  testing::WriteTestImage(dir + "/gray.exr", 32, 32, 1, [](int, int, int) { return 0.5f; });
  testing::WriteTestImage(dir + "/two.exr", 32, 32, 2, [](int, int, int) { return 0.5f; });
  testing::WriteTestImage(dir + "/good.png", 32, 32, 3, [](int, int, int) { return 0.5f; });
  const std::pair<const char*, const char*> cases[] = {
      {"missing.png", "no such file"},
      {"small.png", "16 x 16 texels"},
      {"gray.exr", "1 channel; a mask needs 3 or 4"},
      {"two.exr", "2 channels; a mask needs 3 or 4"},
  };
  for (const auto& [file, message] : cases) {
    const std::string style = dir + "/style.toml";
    std::ofstream(style) << fmt::format(
        "[[cloud_layer]]\n[cloud_layer.formation]\nenabled = true\ncells = [32, 32, 4]\nmask_image = \"{}\"\n", file);
    testing::CommandRun run = testing::RunSkybake("bake '" + style + "' --size 8 -q --out '" + dir + "/out'");
    EXPECT_EQ(run.exit_code, 3) << file << ": " << run.output;
    EXPECT_NE(run.output.find("cloud_layer[0].formation.mask_image: " + dir + "/" + file + ": " + message),
              std::string::npos)
        << run.output;
    EXPECT_FALSE(std::filesystem::exists(dir + "/out/sky_latlong.exr")) << file;
  }
  ConfigResult ok = ParseSkyStyle(
      "[[cloud_layer]]\n[cloud_layer.formation]\nenabled = true\ncells = [32, 32, 4]\nmask_image = \"good.png\"\n",
      dir + "/style.toml");
  EXPECT_TRUE(ok.ok()) << ok.errors[0].Format();
  std::filesystem::remove_all(dir);
}

// The keys: ranges checked with file:line:col, unknown keys refused, and a
// formation that is off leaves the resolved style as it was.
TEST(CloudFormationConfig, KeysAreCheckedAndOffIsUnchanged) {
  auto errors = [](const std::string& toml) {
    ConfigResult r = ParseSkyStyle(toml, "f.toml");
    std::vector<std::string> out;
    for (const ConfigError& e : r.errors) out.push_back(e.Format());
    return out;
  };
  std::vector<std::string> e = errors("[[cloud_layer]]\n[cloud_layer.formation]\nextinction_probability = 1.5\n");
  ASSERT_EQ(e.size(), 1u);
  EXPECT_NE(e[0].find("f.toml:3:26: cloud_layer[0].formation.extinction_probability: expected a number in [0, 1]"),
            std::string::npos)
      << e[0];
  e = errors("[[cloud_layer]]\n[cloud_layer.formation]\ncels = [1, 2, 3]\n");
  ASSERT_EQ(e.size(), 1u);
  EXPECT_NE(e[0].find("cloud_layer[0].formation.cels: unknown key 'cels'"), std::string::npos) << e[0];
  e = errors("[[cloud_layer]]\n[cloud_layer.formation]\nmask_layer = 2\n");
  ASSERT_EQ(e.size(), 1u);
  EXPECT_NE(e[0].find("beyond the last of the mask's 1 layer(s)"), std::string::npos) << e[0];
  const ConfigResult plain = ParseSkyStyle("[[cloud_layer]]\ncoverage = 0.4\n", "f.toml");
  const ConfigResult off =
      ParseSkyStyle("[[cloud_layer]]\ncoverage = 0.4\n[cloud_layer.formation]\nenabled = false\n", "f.toml");
  ASSERT_TRUE(plain.ok() && off.ok());
  EXPECT_EQ(plain.style.resolved_toml, off.style.resolved_toml);
  const ConfigResult on = ParseSkyStyle(
      "[[cloud_layer]]\ncoverage = 0.4\n[cloud_layer.formation]\nenabled = true\nphase_probability = 0.002\n",
      "f.toml");
  ASSERT_TRUE(on.ok());
  EXPECT_TRUE(on.style.clouds.layers[0].formation.enabled);
  EXPECT_EQ(on.style.clouds.layers[0].formation.phase_probability, 0.002);
  // The resolved style reads back to the same formation.
  const ConfigResult again = ParseSkyStyle(on.style.resolved_toml, "again.toml");
  ASSERT_TRUE(again.ok()) << again.errors[0].Format();
  EXPECT_EQ(again.style.resolved_toml, on.style.resolved_toml);
}

// A cloud layer takes its coverage from the automaton: frames of a schedule
// change as the lattice steps, and frame N of a sharded or partial bake
// (--shard, --frames) equals frame N of the whole bake byte for byte.
TEST(CloudFormationSequence, PartsGiveTheWholeBakesFramesByteForByte) {
  namespace fs = std::filesystem;
  const std::string root = testing::FreshTempDir("cloud_formation_sequence");
  const std::string style = root + "/style.toml", schedule = root + "/schedule.toml";
  std::ofstream(style) << R"([quality]
preset = "draft"
cloud_view_steps = 16

[[cloud_layer]]
altitude_m = 1500
thickness_m = 1200
coverage = 0.55

[cloud_layer.formation]
enabled = true
cells = [32, 32, 4]
steps_per_hour = 40
warmup_steps = 20
phase_probability = 0.005
velocity_cells_per_hour = [4.0, 0.0, 0.0]
)";
  std::ofstream(schedule) << testing::IthacaSchedule("12:00:00", "13:30:00", 30);
  testing::BakeSequence16(style, schedule, root + "/whole");
  testing::BakeSequence16(style, schedule, root + "/shards", "--shard 2/2");
  testing::BakeSequence16(style, schedule, root + "/frame3", "--frames 3:3");
  const std::set<std::string> whole = testing::FileNames(root + "/whole");
  ASSERT_TRUE(whole.count("sky_latlong.0003.exr"));
  size_t compared = 0;
  for (const std::string& dir : {root + "/shards", root + "/frame3"}) {
    std::set<std::string> images = testing::FileNames(dir);
    std::erase_if(images, [](const std::string& name) {
      return name.find(".exr") == std::string::npos && name.find(".png") == std::string::npos;
    });
    testing::ExpectSameBytes(dir, root + "/whole", images);
    compared += images.size();
  }
  EXPECT_GT(compared, 8u);
  EXPECT_NE(testing::ReadFileBytes(root + "/whole/sky_latlong.0001.exr"),
            testing::ReadFileBytes(root + "/whole/sky_latlong.0003.exr"));
  fs::remove_all(root);
}

}  // namespace
}  // namespace skybake
