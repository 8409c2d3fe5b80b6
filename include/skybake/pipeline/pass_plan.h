// The pass planner: from a resolved style (one per frame of a schedule) to
// the passes, LUTs and shader variant a bake runs, with the reason for each
// effect. Every effect is optional and costs nothing when a scene does not
// use it: an effect that is off, or whose strength is zero, is compiled out
// (specialization constants), and a LUT that nothing reads is not computed.
// Pruning never changes the image: tests compare a pruned effect with the
// same effect compiled in at zero strength.
#pragma once

#include <string>
#include <vector>

#include "skybake/input/config.h"
#include "skybake/gpu/sky_renderer.h"

namespace skybake {

struct EffectDecision {
  std::string name;    // "multiple scattering"
  bool requested;      // on in the style
  bool on;             // on after pruning: compiled into the shaders
  std::string reason;  // which keys decided it
};

struct PlannedPass {
  std::string name;
  std::string size;       // "256 x 64"
  std::string frequency;  // "once per atmosphere", "once per frame"
  int runs = 0;           // over the whole bake
  double samples = 0.0;   // medium samples per run (density evaluations)
};

struct PassPlan {
  int frames = 1;
  int atmospheres = 1;  // distinct atmospheres over the frames: LUT builds
  std::vector<EffectDecision> effects;
  std::vector<PlannedPass> passes;
  std::string variant;  // the specialization constants of the render shader
  double total_samples = 0.0;
  std::vector<std::string> reused;  // what is computed once and reused
};

// The style with every zero-strength or unused effect switched off: what the
// renderer is built with.
SkyStyle PrunedStyle(const SkyStyle& style);

// Whether the per-frame sky-view LUT is read (not with the skydome, which
// moves the observer and so ray-marches).
bool NeedsSkyViewLut(const SkyStyle& style);

// Whether a frame renders the latlong: for its EXR, its PNG preview, or the
// glTF scene's texture (the tone-mapped latlong PNG). The one place of the
// rule "the glTF texture needs a latlong".
bool RendersLatlong(const SkyStyle& style);

// Whether a frame writes the tone-mapped latlong PNG: the preview, which is
// also the glTF scene's texture.
bool WritesLatlongPng(const SkyStyle& style);

// The views one frame renders, in order: six Vulkan faces, the cube strip,
// the latlong (each only when enabled in `output`; the latlong also for the
// glTF texture, RendersLatlong). The planner, the resource estimate, the
// device-limit check and the renderer all read this list.
std::vector<ViewRequest> PlanViews(const SkyStyle& style);

// The share of a view's directions above the twilight band that the plan
// counts as marched at twilight (TwilightMarchWeight's texels where the
// sky-view LUT's logarithm bends between its rows): above the largest share
// the accuracy tests measure (6.65% of the sphere, production at 0 m, sun
// -7 deg: ConvergedReferenceTest.TwilightMarchAboveTheBandStaysWithinThePlansShare).
constexpr double kTwilightAboveBandShare = 0.07;

// `shaders`: the CLI's diagnostic switches, as the bake would get them.
// `hours_from_start`: each frame's clock time since the sequence's first
// (Schedule frames; empty: 0 h), for the cloud formation's step count.
PassPlan PlanPasses(const std::vector<SkyStyle>& frames, const ShaderSwitches& shaders = ShaderSwitches(),
                    const std::vector<double>& hours_from_start = {});

// The plan as `skybake plan` prints it.
std::string FormatPlan(const PassPlan& plan, const std::string& source);

}  // namespace skybake
