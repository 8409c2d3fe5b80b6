// The cloud formation's host work against the time budget (formation_budget.h).
#include "skybake/pipeline/formation_budget.h"

#include <cmath>
#include <map>
#include <optional>

#include <fmt/format.h>

#include "skybake/base/errors.h"
#include "skybake/model/cloud_formation.h"
#include "skybake/model/clouds.h"

namespace skybake {
namespace {

// CPU seconds of one automaton step of one cell: 10-13 ns on the 2-core CI
// machine (one step of the 64 x 64 x 8 lattice of
// configs/styles/afternoon_buildup.toml, 32,768 cells, in 0.32-0.42 ms;
// docs/performance_history.md "Cloud formation and shadow map",
// build/tests/cloud_formation_benchmark --benchmark_filter=BM_FormationStep).
constexpr double kSecondsPerCellStep = 13e-9;

// The lattice a layer's formation steps: the cache of SimulateFormation
// keeps one per formation (its parameters, mask and seed).
std::string LatticeKey(size_t layer, const CloudFormation& f) {
  return fmt::format("{} {} {} {} {} {} {}", layer, f.cells[0], f.cells[1], f.cells[2], f.warmup_steps,
                     f.steps_per_hour, f.mask_image);
}

struct FrameWork {
  double cell_updates = 0.0;
  std::string layers;  // what steps, for the message
};

// The steps of one SimulateFormation call to `steps` from the cached lattice.
double Simulate(std::map<std::string, double>& cache, const std::string& key, double steps) {
  auto it = cache.find(key);
  const double from = it != cache.end() && it->second <= steps ? it->second : 0.0;
  cache[key] = steps;
  return steps - from;
}

FrameWork FrameFormationWork(const FramePlan& frame, std::map<std::string, double>& cache) {
  FrameWork work;
  const std::vector<CloudLayer> layers = ActiveCloudLayers(frame.style->clouds);
  for (size_t i = 0; i < layers.size(); ++i) {
    const CloudFormation& f = layers[i].formation;
    if (!f.enabled) continue;
    // The formation's own clock (FormationTimeSeconds: from the day's start
    // when the frame has a clock time), as ApplyCloudFormation steps it.
    const double t_s = FormationTimeSeconds(f, frame.style->clouds.local_clock_s, frame.CloudTimeSeconds());
    const double step = f.warmup_steps + f.steps_per_hour * std::max(t_s, 0.0) / 3600.0;
    const double n = std::floor(step);
    const std::string key = LatticeKey(i, f);
    // ApplyCloudFormation: the coverage at steps n (and n + 1 between two
    // steps), then with formation.density the volume at the same steps.
    double steps = 0.0;
    for (int pass = 0; pass < (f.density ? 2 : 1); ++pass) {
      steps += Simulate(cache, key, n);
      if (step > n) steps += Simulate(cache, key, n + 1.0);
    }
    const double cells = double(f.cells[0]) * f.cells[1] * f.cells[2];
    work.cell_updates += steps * cells;
    work.layers += fmt::format("{}{:.0f} steps of {} x {} x {} cells at {} m", work.layers.empty() ? "" : ", ", steps,
                               f.cells[0], f.cells[1], f.cells[2], layers[i].altitude_m);
  }
  return work;
}

// Each baked frame's work in the order the bake runs them: the reference
// frame's sky first (the sequence's exposure), then the frames; a frame's
// steps continue from the lattice the one before left.
template <typename Visit>
void ForEachFrameWork(const RenderPlan& plan, Visit visit) {
  std::map<std::string, double> cache;
  if (plan.sequence && plan.exposed && plan.reference < plan.frames.size())
    FrameFormationWork(plan.frames[plan.reference], cache);
  for (const FramePlan& frame : plan.frames)
    if (plan.Bakes(frame)) visit(frame, FrameFormationWork(frame, cache));
}

}  // namespace

FormationEstimate EstimateFormationWork(const RenderPlan& plan) {
  FormationEstimate busiest;
  ForEachFrameWork(plan, [&](const FramePlan& frame, const FrameWork& work) {
    if (work.cell_updates > busiest.cell_updates) {
      busiest.cell_updates = work.cell_updates;
      busiest.seconds = work.cell_updates * kSecondsPerCellStep;
      busiest.frame = frame.Label();
    }
  });
  return busiest;
}

FormationEstimate CheckFormationBudget(const RenderPlan& plan, const BakeOptions& options) {
  ForEachFrameWork(plan, [&](const FramePlan& frame, const FrameWork& work) {
    const double seconds = work.cell_updates * kSecondsPerCellStep;
    const double march = EstimateResources(*frame.style).seconds;
    if (seconds > 0.0 && !(seconds + march <= options.max_frame_seconds))
      throw BudgetError(fmt::format(
          "{}: the cloud formation needs an estimated {:.3g} cell updates ({}), about {:.0f} s of CPU time, which "
          "with its {:.0f} s of ray marching is above the budget of {:.0f} s per frame: lower [cloud_layer.formation] "
          "steps_per_hour or cells, put the schedule's frames closer in clock time, or raise --max-frame-seconds "
          "(README \"Limits\")",
          frame.Label(), work.cell_updates, work.layers, seconds, march, options.max_frame_seconds));
  });
  return EstimateFormationWork(plan);
}

}  // namespace skybake
