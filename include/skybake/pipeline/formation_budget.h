// The host work of the cloud formation automaton (cloud_formation.h) that a
// bake plans, against the time budget (--max-frame-seconds), before any work:
// a schedule whose frames lie far apart in clock time makes the automaton
// step for hours on the CPU, work the ray-march estimate (EstimateResources)
// does not count.
#pragma once

#include <string>

#include "skybake/pipeline/pipeline.h"
#include "skybake/pipeline/render_plan.h"

namespace skybake {

// The busiest frame's automaton work: cell updates (steps x cells, summed
// over its layers) and their estimated CPU seconds.
struct FormationEstimate {
  double cell_updates = 0.0;
  double seconds = 0.0;
  std::string frame;  // FramePlan::Label() of the busiest frame; "" without a formation
};

// Steps a frame simulates follow the process's cache of lattices
// (SimulateFormation): from the last lattice when the frame's step is not
// before it, else from step 0 (a part's first frame, a frame earlier in time
// than the one before it). The reference frame (the sequence's exposure) is
// simulated first. A lower bound when the layers share one lattice.
FormationEstimate EstimateFormationWork(const RenderPlan& plan);

// EstimateFormationWork, plus the frame's ray-march seconds, against
// options.max_frame_seconds: a BudgetError (exit 7) naming the frame, its
// steps and the fix when over. Returns the estimate.
FormationEstimate CheckFormationBudget(const RenderPlan& plan, const BakeOptions& options);

}  // namespace skybake
