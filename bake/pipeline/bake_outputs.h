// The bake's outputs before any GPU work (private to the pipeline layer):
// within budget, the folder and the lock on the planned files, nothing in
// the way that the renames at the end could not replace, no previous bake
// overwritten unless asked to, stale temporaries of a killed bake removed.
#pragma once

#include <string>

#include "resume.h"
#include "skybake/output/output_lock.h"
#include "skybake/pipeline/pipeline.h"
#include "skybake/pipeline/render_plan.h"
#include "stage_timer.h"

namespace skybake {

// `name` in options.out_dir.
std::string OutputPath(const BakeOptions& options, const std::string& name);

// Every frame within budget (BudgetError), the output folder there
// (OutputError), and the lock on the planned files, held to the end of the
// bake (any exit, kill -9 included, releases it): another live bake writing
// any of them into this folder stops this one here (exit 6); parts of one
// sequence, whose files differ, go ahead side by side.
OutputLock ClaimOutputs(const RenderPlan& plan, const BakeOptions& options);

// What is in the way of the planned files (OutputError, OutputExistsError),
// the previous manifest with --resume, the stale temporaries removed (into
// result.removed_temporaries); reports the "outputs" stage.
PreviousBake PrepareOutputs(const RenderPlan& plan, const BakeOptions& options, StageTimer& timer, BakeResult& result);

}  // namespace skybake
