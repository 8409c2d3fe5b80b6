// What each effect costs: lavapipe time per megapixel of a 1024 x 512
// latlong frame (sky-view LUT of the frame + render, GPU timestamps) with and
// without the effect, and the once-per-atmosphere LUT time. Medians of the
// benchmark's repetitions.
//
//   build/tests/effects_benchmark --benchmark_repetitions=5
//       --benchmark_report_aggregates_only=true
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "skybake/model/aoas.h"
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

// The base style: the default physical sky, production preset.
const char* kBase = "[atmosphere]\nground_albedo = 0.1\n";

void BM_Frame(benchmark::State& state, std::string toml) {
  ConfigResult config = ParseSkyStyle(std::string(kBase) + toml, "benchmark.toml");
  if (!config.ok()) {
    state.SkipWithError(config.errors[0].Format().c_str());
    return;
  }
  const SkyStyle style = PrunedStyle(config.style);
  SkyRenderer renderer(Context(), StyledAtmosphere(style.atmosphere, style.aoas), style.quality, style.effects,
                       OutputScale(style.output.units), false,
                       ToAoasInputs(style.aoas, OutputScale(OutputUnits::kLuminance)));
  renderer.PrecomputeLuts();
  double lut_ms = 0.0;
  for (const PassTiming& t : renderer.last_timings()) lut_ms += t.gpu_ms;
  const ViewRequest view{MAPPING_LATLONG, 1024, 512, 0};
  double elevation = 30.0;
  for (auto _ : state) {
    // A new sun each frame, as in a time-lapse: the sky-view LUT is rebuilt.
    elevation += 0.25;
    renderer.Render(SunDirectionFromElevationAzimuth(elevation, 150.0), {view});
    double ms = 0.0;
    for (const PassTiming& t : renderer.last_timings()) ms += t.gpu_ms;
    state.SetIterationTime(ms * 1e-3);
    state.counters["ms_per_MP"] = ms / (1024.0 * 512.0 * 1e-6);
  }
  state.counters["LUTs_ms"] = lut_ms;
}

// Each effect with and without it; "without" compiles it out.
#define EFFECT(name, with, without)                                 \
  BENCHMARK_CAPTURE(BM_Frame, name##_with, std::string(with))       \
      ->UseManualTime()                                             \
      ->Unit(benchmark::kMillisecond)                               \
      ->Iterations(3);                                              \
  BENCHMARK_CAPTURE(BM_Frame, name##_without, std::string(without)) \
      ->UseManualTime()                                             \
      ->Unit(benchmark::kMillisecond)                               \
      ->Iterations(3)

EFFECT(multiple_scattering, "", "[effects]\nmultiple_scattering = false\n");
EFFECT(mie, "", "[effects]\nmie = false\n");
EFFECT(ozone, "", "[effects]\nozone = false\n");
EFFECT(ground, "", "[effects]\nground = false\n");
EFFECT(sun_disc, "", "[effects]\nsun_disc = false\n");
EFFECT(hue, "[hue]\nenabled = true\ncolor = \"#ffcc33\"\n", "");
EFFECT(ambiguity, "[ambiguity]\nenabled = true\n", "");
EFFECT(cloud_noise, "[clouds]\nenabled = true\n", "");
EFFECT(cloud_shapes,
       "[shapes]\nenabled = true\n[[shapes.shape]]\nkind = \"spline\"\nclosed = true\n"
       "points = [[40.0, 170.0], [30.0, 190.0], [20.0, 170.0], [30.0, 150.0]]\n",
       "");
EFFECT(skydome, "[skydome]\nenabled = true\nviewer_position = [0.0, 0.3, 0.0]\n", "");

}  // namespace

BENCHMARK_MAIN();
