// Cloud formation by a cellular automaton (Dobashi, Kaneda, Yamashita,
// Okita, Nishita 2000, "A Simple, Efficient Method for Realistic Animation
// of Clouds", SIGGRAPH 2000; the Unigine seed's "Clouds Formation
// Parameters", "Density Mask", "Clouds Velocity" and "Clouds Size").
//
// A lattice of cells over the ground, each with three booleans: cloud (cld),
// humidity (hum) and readiness for phase transition (act). One step applies
// Dobashi's transition rules
//   hum' = hum AND NOT act
//   cld' = cld OR act
//   act' = NOT act AND hum AND f_act
// (f_act: any of the neighbours x+-1, y+-1, z+-1, x+-2, y+-2, z-2 is
// ready; clouds spread sideways and grow upward), then the stochastic
// extension of the paper, with the per-cell probabilities of the density
// mask times the three artist probabilities of the seed:
//   cld'' = cld' AND NOT (rnd < p_ext)            extinction
//   hum'' = hum' OR (rnd < p_hum)                 humidity supply
//   act'' = act' OR (hum'' AND rnd < p_act)       spontaneous transition
// (the last needs humidity: the seed's first rule, "the cell should have
// positive humidity level"). The binary cloud field is smoothed (a box
// filter over space, linear between steps in time) into a continuous
// density; a cloud layer takes its coverage map from the column maximum of
// that density instead of the procedural weather noise.
//
// Determinism: the random numbers are a counter-based hash of (seed, step,
// cell, channel), so the lattice at step n follows from the style, the seed
// and n alone, on every run and machine.
//
// The clock (FormationTimeSeconds): a frame with a clock time (a schedule's
// times) is at t = its local clock time minus day_start_hour, in [0, 24) h:
// the automaton starts afresh every day at day_start_hour on the local clock
// (UTC + the schedule's utc_offset_hours) of the frame's date, after its
// warm-up steps, and a frame before that hour belongs to the previous day's
// run. The state at a clock time is thus a function of that clock time
// alone, not of where a schedule starts: any two schedules, shards or
// resumes holding the same clock time bake the same lattice, drift and wind
// offset for it. A frame is at step warmup_steps + steps_per_hour x t (so
// at most warmup + 24 x steps_per_hour steps from the origin; a process
// keeps its last lattice and continues from it when the next frame is
// later). A frame without a clock time (a single bake, a schedule of sun
// positions) is at t = hours since the sequence's first frame.
//
// Frame and units: lattice x = east, y = north, z = up; sizes in metres,
// velocity in cells (x, y) and mask layers (z) per hour of clock time.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "skybake/gpu_shared.h"

namespace skybake {

struct CloudLayer;

// The [cloud_layer.formation] table of a cloud layer (off by default).
struct CloudFormation {
  bool enabled = false;
  std::array<int, 3> cells = {64, 64, 8};                 // lattice cells east, north, up
  std::array<double, 2> size_m = {30000.0, 30000.0};      // lattice extent east, north; up spans the layer's thickness
  std::array<double, 2> origin_m = {-15000.0, -15000.0};  // [east, north] of its south-west corner at time 0
  double steps_per_hour = 30.0;                           // automaton steps per hour of clock time
  int warmup_steps = 30;                                  // steps simulated before time 0 (the day's start)
  // The temporal box filter (Dobashi 2000, section 4, smooths the density
  // over neighbouring steps as over cells): the density at step s is the
  // mean over the steps s - smoothing_steps .. s, 0..64 (0: step s alone).
  int smoothing_steps = 0;
  // The local clock hour of time 0 each day (see "The clock" above), 0..24.
  double day_start_hour = 0.0;
  double extinction_probability = 0.05;  // Pext, 0..1, per step and cloud cell (times the mask's blue)
  double humidity_probability = 0.02;    // Phum, 0..1, per step and dry cell (times the mask's red)
  double phase_probability = 0.001;      // Pact, 0..1, per step and humid cell (times the mask's green)
  double initial_humidity = 0.4;         // fraction of humid cells at step 0 (times the mask's red)
  int smoothing_cells = 1;               // box-filter radius of the smoothing, cells
  std::string mask_image;                // RGB mask (see below); "" = 1, 1, 1 everywhere
  int mask_layers = 1;                   // layers stacked top to bottom in the mask image
  double mask_layer = 0.0;               // the layer used at time 0 (fractions blend two layers)
  std::array<double, 3> velocity_cells_per_hour = {0.0, 0.0, 0.0};  // drift east, north; z: mask layers per hour
  // true: the automaton supplies the layer's whole density (its smoothed
  // lattice, FormationDensityAt), in place of the shape noise, the coverage
  // remap and the height profile; false: its coverage only.
  bool density = false;
};

// The density mask: per lattice column and layer, R = humidity, G = readiness
// for phase transition, B = extinction probability, each 0..1 (Unigine's
// "Density Mask"). An image of cells[0] x (cells[1] x mask_layers) texels,
// 3 or 4 channels (PNG values / 255, EXR values clamped to [0, 1]); layer 0
// on top, row 0 of a layer its north edge, column 0 its west edge.
struct CloudMask {
  int width = 0, height = 0, layers = 0;  // per layer width x height
  std::vector<float> rgb;                 // layers x height x width x 3
};

// "" when the mask at `path` fits `formation`, else what is wrong.
std::string CheckCloudMask(const std::string& path, const CloudFormation& formation);
// Reads the mask; throws std::runtime_error naming the path when it cannot.
CloudMask ReadCloudMask(const std::string& path, const CloudFormation& formation);

// The three booleans of every cell, index (z * ny + y) * nx + x.
struct CloudLattice {
  int nx = 0, ny = 0, nz = 0;
  std::vector<uint8_t> hum, act, cld;
  CloudLattice() = default;
  CloudLattice(int nx_, int ny_, int nz_);
  size_t Index(int x, int y, int z) const { return (size_t(z) * ny + y) * nx + x; }
  size_t Cells() const { return size_t(nx) * ny * nz; }
  bool operator==(const CloudLattice& o) const = default;
};

// Per-column thresholds of the stochastic rules at one step: a uniform
// 32-bit draw r passes when r < threshold (threshold 2^32: always).
struct FormationThresholds {
  std::vector<uint64_t> hum, act, ext;  // nx x ny each
};

// Dobashi's three deterministic rules, one step (x, y wrap: the lattice
// tiles; z is closed: nothing beyond the bottom and the top).
void ApplyFormationRules(CloudLattice& lattice);
// The counter-based random draw of one cell, step and channel (0 ext, 1 hum, 2 act).
uint32_t FormationRandom(uint32_t seed, uint64_t step, uint64_t cell, uint32_t channel);
// One whole step: the rules, then extinction, humidity and phase transition.
void StepFormation(CloudLattice& lattice, const FormationThresholds& thresholds, uint32_t seed, uint64_t step);

// The mask's probabilities at `step` (the mask layer moved by velocity z).
FormationThresholds FormationThresholdsAt(const CloudFormation& f, const CloudMask* mask, uint64_t step);
// Step 0: no cloud, no transition; humid where a draw is below
// initial_humidity x the mask's red.
CloudLattice InitialFormation(const CloudFormation& f, const CloudMask* mask, uint32_t seed);
// The lattice after `steps` steps from InitialFormation. A process keeps
// the last lattice of each formation and continues from it when asked for
// a later step (the result is the same either way).
CloudLattice SimulateFormation(const CloudFormation& f, const CloudMask* mask, uint32_t seed, uint64_t steps);
// The lattices of the steps first .. last (last - first + 1 of them); a
// process keeps them, and continues from the last when asked for later ones.
std::vector<CloudLattice> SimulateFormationSteps(const CloudFormation& f, const CloudMask* mask, uint32_t seed,
                                                 uint64_t first, uint64_t last);

// The binary cloud field smoothed into a continuous density in [0, 1]:
// the mean of cld over a box of (2r + 1)^3 cells (x, y wrapping, z cut at
// the ends), index as CloudLattice.
std::vector<float> SmoothFormation(const CloudLattice& lattice, int radius_cells);

// The formation's time of a frame, seconds: with the frame's local clock
// time `local_clock_s` (seconds since its date's midnight), the seconds
// since the last day_start_hour, in [0, 86400); without one, `since_first_s`
// (the seconds since the sequence's first frame).
double FormationTimeSeconds(const CloudFormation& f, std::optional<double> local_clock_s, double since_first_s);

// What a cloud layer takes from its formation at the formation's time
// `time_s` (FormationTimeSeconds): the coverage map (column maximum of the
// smoothed density, in space and over smoothing_steps, linear between the
// steps around the time), resampled
// to resolution^2 texels (row 0 north), and where it lies.
struct FormationCoverage {
  std::vector<float> map;
  double step = 0.0;                 // the automaton's (fractional) step at the time
  std::array<double, 2> origin_m{};  // [east, north] of the south-west corner, drift included
  std::array<double, 2> extent_m{};  // = size_m
};
FormationCoverage FormationCoverageAt(const CloudFormation& f, const CloudMask* mask, uint32_t seed, double time_s,
                                      int resolution);

// The smoothed density at the formation's time `time_s` (linear between the steps
// around it), resampled trilinearly to an n^3 volume over the lattice: x, y
// wrapping as the coverage map (column c east, row r from the north edge),
// z the layer's height fraction (level k at (k + 0.5) / n, clamped to the
// lattice's bottom and top cells); index (r * n + k) * n + c, the layout
// clouds.glsl's SampleVolume reads with (u, height fraction, v).
std::vector<float> FormationDensityAt(const CloudFormation& f, const CloudMask* mask, uint32_t seed, double time_s,
                                      int n);

// Whether a formation layer's shape and detail noise are read through the
// non-repeating warp of its weather_size_m (cloud_weather.glsl), as a weather
// image's are: unless the layer tiles, or reads no noise (shape and detail
// amounts 0; with formation.density the shape is not read). A noise tile
// repeated under a sparse cover is a lattice of specks.
bool FormationShapeWarped(const CloudLayer& layer);

// A layer with formation.enabled: its weather map becomes the formation's
// coverage at the formation's time `time_s` (appended to `weather_images`, placed by `out`'s
// weather and weather_origin as a weather image is); with formation.density
// also its density volume (FormationDensityAt, volume_resolution^3, after
// the map; out.weather.w = 2: it takes the shape volume's place).
// `style_dir` resolves a relative mask path.
void ApplyCloudFormation(const CloudLayer& layer, uint32_t seed, int resolution, double time_s,
                         const std::string& style_dir, gpu::GpuCloudLayer& out, std::vector<float>& weather_images,
                         int volume_resolution);

}  // namespace skybake
