// The cloud formation step and the cloud shadow passes in the pass plan
// (pass_plan.h; cloud_formation.h, cloud_shadow.h). Private to the pipeline.
#pragma once

#include <vector>

#include "skybake/pipeline/pass_plan.h"

namespace skybake {

// Effects "cloud shadow map" and "ground cloud shadow", and the shadow map's
// GPU pass (medium samples: its resolution^2 x steps x bands density reads),
// when it runs: [cloud_shadow] on, with a cloud layer left after pruning and
// a strength above 0 (else the map is all ones, or all zeros with the Sun
// down, written without a pass).
void AddCloudShadowPlan(const SkyStyle& first, int frames, PassPlan& plan);

// The cloud march's passes over `views`: with a cloud panorama
// (gpu/cloud_panorama.h: quality.cloud_panorama_scale > 0 and cheaper than
// marching the views), "clouds panorama" (its size, the rows that can see a
// band, and their medium samples) and one "clouds <view> (resampled)" per
// view, no medium samples; else each view marches its own texels. Medium
// samples: at most view_steps per layer crossing, each lit sample
// light_steps more. Of the `frames`, the `shadowed` ones (every band in the
// Earth's shadow: CloudEarthShadowElevationDeg, below `shadow_below_deg`)
// march without the Sun's light march: the marching passes are listed again
// for them ("... in the Earth's shadow"), view_steps per layer crossing.
void AddCloudMarchPlan(const SkyStyle& first, int layers, const std::vector<ViewRequest>& views, int frames,
                       int shadowed, double shadow_below_deg, PassPlan& plan);

// Effect "cloud formation" and its CPU step per active layer with a
// formation: cells per step, and the steps simulated to reach the planned
// frames' times on the formation's clock (FormationTimeSeconds of each of
// `frames`, whose local clock time it reads, with `hours_from_start`, one
// per frame; empty: every frame at 0 h), from step 0 (a process, or a
// --shard / --frames part, simulates from the day's start). Not medium
// samples: not in the plan's total. `frames` is not empty.
void AddCloudFormationPlan(const std::vector<SkyStyle>& frames, const std::vector<double>& hours_from_start,
                           PassPlan& plan);

}  // namespace skybake
