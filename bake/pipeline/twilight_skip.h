// Twilight frames whose march cannot show (private to the pipeline layer;
// the CLI runs it only with SKYBAKE_TWILIGHT_SKIP=1: on W2 it leaves one
// frame of 24 unmarched, and its probes cost more CPU time than that frame
// saves and add about 220 MiB of peak memory, docs/performance.md "Today").
//
// A sequence's half-float files hold every value times the sequence's half
// scale (exposure.h), to 11 significant bits: a half-float step is 2^-10 of
// the value's power of two (2^-24 below 2^-14). With the Sun deep in
// twilight (about -16 to -21 deg for the Earth) the twilight band march
// (pass_plan.h) changes the sky by less than that: it costs three to five
// day frames of work for files that are the same, or nearly, without it.
//
// Such a frame's views render without the march. Which frames: the frames
// the march would run in (SkyRenderer::MarchesTwilight), lowest Sun first,
// are probed with a 512 x 256 latlong rendered both ways (with the march
// and without); while every probe texel's two values, times the half scale,
// are less than a quarter of a half-float step apart (kTwilightProbeSteps),
// the frame is not marched; the first frame above it ends the search (the
// march matters more as the Sun rises: every frame above is marched). The
// margin of 4 is for the texels the probe's grid does not hit; a texel whose
// value lies that close to a rounding boundary of half floats may still
// round one step the other way (docs/performance.md counts them for W2).
// The SH views, the IBL maps and the engine images (float values, not
// scaled to half) are still marched, so their values do not change.
//
// Not decided (every frame marched) for float files, a single bake (its
// scale follows its own images), and a bake with a night sky or cloud
// layers (their light is added to the same texels). With the Sun as a light
// the sequence's scale is 1, lowered only for a frame whose own sky would
// overflow half floats (FrameHalfScale), which no twilight frame comes near.
#pragma once

#include <set>
#include <string>
#include <vector>

#include "renderer_cache.h"
#include "skybake/pipeline/render_plan.h"

namespace skybake {

struct TwilightSkip {
  std::set<int> frames;  // frame numbers whose views render without the twilight march
  int probed = 0;        // frames probed
  std::string report;    // for the exposure stage's line; "" when nothing was probed
};

// How far apart, in half-float steps, a probe texel's two values may be for the frame to go unmarched.
inline constexpr double kTwilightProbeSteps = 0.25;

// The largest difference of two renders of the same texels (RGBA), in
// half-float steps at the larger value times `scale`; +inf when a value is
// not finite.
double HalfStepsApart(const std::vector<float>& a, const std::vector<float>& b, double scale);

TwilightSkip ChooseTwilightSkips(const RenderPlan& plan, RendererCache& renderers, double half_scale, bool night_sky);

}  // namespace skybake
