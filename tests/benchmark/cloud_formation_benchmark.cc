// What the cloud-formation automaton and the cloud shadow map cost per
// frame (docs/performance_history.md "Cloud formation and shadow map"):
//   - one automaton step of a 64 x 64 x 8 lattice (CPU, one thread);
//   - a frame of configs/styles/afternoon_buildup.toml at the end of its
//     schedule (18:00, step 20 + 6 h x 20 = 140) simulated from step 0, as
//     a part of a sharded bake does for its first frame; and the next frame
//     (30 minutes, 10 steps later) continued from the process's lattice, as
//     every later frame does; both with the smoothing and coverage map;
//   - with formation.density, the next frame's 64^3 density volume too;
//   - the 256 x 256 shadow map of that style on lavapipe (GPU timestamps).
//
//   build/tests/cloud_formation_benchmark --benchmark_repetitions=3
//       --benchmark_report_aggregates_only=true
#include <string>

#include <benchmark/benchmark.h>

#include "skybake/model/cloud_formation.h"
#include "skybake/model/cloud_shadow.h"
#include "skybake/model/clouds.h"
#include "skybake/input/config.h"
#include "skybake/pipeline/pass_plan.h"
#include "skybake/gpu/sky_renderer.h"
#include "skybake/gpu/vulkan_context.h"

namespace {

using namespace skybake;

VulkanContext& Context() {
  static VulkanContext context(VulkanOptions{});
  return context;
}

const SkyStyle& Afternoon() {
  static const SkyStyle style = [] {
    ConfigResult config = LoadSkyStyle(std::string(SKYBAKE_SOURCE_DIR) + "/configs/styles/afternoon_buildup.toml");
    if (!config.ok()) throw std::runtime_error(config.errors[0].Format());
    return PrunedStyle(config.style);
  }();
  return style;
}

std::string StyleDir() { return std::string(SKYBAKE_SOURCE_DIR) + "/configs/styles"; }

void BM_FormationStep(benchmark::State& state) {
  const CloudFormation& f = Afternoon().clouds.layers[0].formation;
  const CloudMask mask = ReadCloudMask(StyleDir() + "/" + f.mask_image, f);
  CloudLattice lattice = SimulateFormation(f, &mask, 16, 40);
  const FormationThresholds t = FormationThresholdsAt(f, &mask, 40);
  uint64_t step = 40;
  for (auto _ : state) StepFormation(lattice, t, 16, step++);
  state.counters["cells"] = double(lattice.Cells());
}
BENCHMARK(BM_FormationStep)->Unit(benchmark::kMillisecond);

// The layer's weather map at `hours` after the first frame, from the
// layer's CloudInputs as the bake builds them.
void Frame(double hours) {
  const SkyStyle& style = Afternoon();
  const CloudInputs in = ToCloudInputs(style.clouds, style.aoas.seed, StyleDir(), hours * 3600.0);
  benchmark::DoNotOptimize(in.weather_images.data());
}

// The process keeps the latest lattice of each formation and starts again
// from step 0 for an earlier time: each iteration is 3 minutes (one step)
// before the last, from 18:00 (step 140) on, so each simulates from step 0.
void BM_FormationFrameFromStepZero(benchmark::State& state) {
  double hours = 6.05;
  for (auto _ : state) {
    hours -= 0.05;
    Frame(hours);
  }
}
BENCHMARK(BM_FormationFrameFromStepZero)->Unit(benchmark::kMillisecond)->Iterations(6);

void BM_FormationNextFrame(benchmark::State& state) {
  double hours = 0.0;
  Frame(hours);
  for (auto _ : state) {
    hours += 0.5;  // the schedule's 30 minutes: 10 steps on from the last frame
    Frame(hours);
  }
}
BENCHMARK(BM_FormationNextFrame)->Unit(benchmark::kMillisecond)->Iterations(12);

// The same with the temporal filter over the last hour (smoothing_steps =
// 20 at 20 steps per hour): each frame smooths 22 lattices instead of 2.
void BM_FormationNextFrameSmoothed(benchmark::State& state) {
  SkyStyle style = Afternoon();
  style.clouds.layers[0].formation.smoothing_steps = int(state.range(0));
  double hours = 0.0;
  auto frame = [&] {
    const CloudInputs in = ToCloudInputs(style.clouds, style.aoas.seed, StyleDir(), hours * 3600.0);
    benchmark::DoNotOptimize(in.weather_images.data());
  };
  frame();
  for (auto _ : state) {
    hours += 0.5;
    frame();
  }
}
BENCHMARK(BM_FormationNextFrameSmoothed)->Arg(0)->Arg(20)->Unit(benchmark::kMillisecond)->Iterations(12);

// With formation.density: the next frame's density volume as well, the
// smoothed lattice resampled to 64^3 (FormationDensityAt), 30 minutes on
// from the last frame like BM_FormationNextFrame.
void BM_FormationDensityNextFrame(benchmark::State& state) {
  const SkyStyle& style = Afternoon();
  const CloudFormation& f = style.clouds.layers[0].formation;
  const CloudMask mask = ReadCloudMask(StyleDir() + "/" + f.mask_image, f);
  const uint32_t seed = style.aoas.seed;
  const int n = int(state.range(0));
  double hours = 0.0;
  benchmark::DoNotOptimize(FormationDensityAt(f, &mask, seed, hours * 3600.0, n).data());
  for (auto _ : state) {
    hours += 0.5;
    benchmark::DoNotOptimize(FormationDensityAt(f, &mask, seed, hours * 3600.0, n).data());
  }
  state.counters["voxels"] = double(n) * n * n;
}
BENCHMARK(BM_FormationDensityNextFrame)->Arg(64)->Unit(benchmark::kMillisecond)->Iterations(12);

void BM_ShadowMap(benchmark::State& state) {
  const SkyStyle& style = Afternoon();
  SkyRenderer renderer(Context(), StyledAtmosphere(style.atmosphere, style.aoas), style.quality, style.effects,
                       OutputScale(style.output.units), false,
                       ToAoasInputs(style.aoas, OutputScale(OutputUnits::kLuminance)),
                       ToCloudInputs(style.clouds, style.aoas.seed, StyleDir(), 3.0 * 3600.0));
  renderer.PrecomputeLuts();
  double elevation = 40.0;
  for (auto _ : state) {
    elevation += 0.5;
    renderer.RenderCloudShadow(SunDirectionFromElevationAzimuth(elevation, 200.0), style.cloud_shadow);
    double ms = 0.0;
    for (const PassTiming& t : renderer.last_timings()) ms += t.gpu_ms;
    state.SetIterationTime(ms * 1e-3);
  }
  state.counters["texels"] = double(style.cloud_shadow.resolution) * style.cloud_shadow.resolution;
  state.counters["steps_per_band"] = style.cloud_shadow.steps;
}
BENCHMARK(BM_ShadowMap)->Unit(benchmark::kMillisecond)->UseManualTime()->Iterations(5);

}  // namespace

BENCHMARK_MAIN();
