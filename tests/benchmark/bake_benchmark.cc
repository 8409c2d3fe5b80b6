// Times a whole bake and each of its passes on this machine: a 512^2 cube
// (six faces + strip) plus a 1024x512 latlong, default style. Reports
// medians over repetitions; GPU passes come from Vulkan timestamps.
//
//   build/tests/bake_benchmark [--benchmark_repetitions=N]
#include <filesystem>
#include <map>

#include <benchmark/benchmark.h>

#include "skybake/input/config.h"
#include "skybake/pipeline/pipeline.h"

namespace {

using namespace skybake;

void BM_BakeDefault512(benchmark::State& state) {
  ConfigResult config = LoadSkyStyle(std::string(SKYBAKE_SOURCE_DIR) + "/configs/default.toml",
                                     {"render.cube_size=512", "render.latlong_height=512"});
  if (!config.ok()) {
    state.SkipWithError("default style does not parse");
    return;
  }
  std::string out = (std::filesystem::temp_directory_path() / "skybake_bench").string();
  BakeOptions options;
  options.out_dir = out;
  options.force = true;  // every iteration bakes into the same folder
  std::map<std::string, double> stage_seconds, pass_ms;
  for (auto _ : state) {
    BakeResult result = BakeStyle(config.style, options);
    for (const StageReport& s : result.stages) stage_seconds[s.name] = s.seconds;
    for (const PassTiming& p : result.gpu_passes) pass_ms[p.name] = p.gpu_ms;
  }
  for (const auto& [name, seconds] : stage_seconds) state.counters["stage " + name + " s"] = seconds;
  for (const auto& [name, ms] : pass_ms) state.counters["gpu " + name + " ms"] = ms;
  std::filesystem::remove_all(out);
}
BENCHMARK(BM_BakeDefault512)->Unit(benchmark::kSecond)->Iterations(1)->Repetitions(3)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
