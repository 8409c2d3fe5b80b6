#include "twilight_skip.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "skybake/pipeline/pass_plan.h"

namespace skybake {
namespace {

// Frame numbers as runs: "1-3, 94-96".
std::string Runs(const std::set<int>& frames) {
  std::string out;
  const std::vector<int> f(frames.begin(), frames.end());
  for (size_t i = 0; i < f.size();) {
    size_t j = i;
    while (j + 1 < f.size() && f[j + 1] == f[j] + 1) ++j;
    out += (out.empty() ? "" : ", ") + (j == i ? std::to_string(f[i]) : fmt::format("{}-{}", f[i], f[j]));
    i = j + 1;
  }
  return out;
}

}  // namespace

double HalfStepsApart(const std::vector<float>& a, const std::vector<float>& b, double scale) {
  double worst = 0.0;
  for (size_t i = 0; i < a.size() && i < b.size(); ++i) {
    if (i % 4 == 3) continue;
    const double x = double(a[i]) * scale, y = double(b[i]) * scale;
    if (!std::isfinite(x) || !std::isfinite(y)) return INFINITY;
    const double larger = std::max(std::fabs(x), std::fabs(y));
    // A half float's step: 2^-24 among the subnormals (below 2^-14), else 2^(exponent - 10).
    const double step = larger < 0x1p-14 ? 0x1p-24 : std::ldexp(1.0, std::ilogb(larger) - 10);
    worst = std::max(worst, std::fabs(x - y) / step);
  }
  return worst;
}

TwilightSkip ChooseTwilightSkips(const RenderPlan& plan, RendererCache& renderers, double half_scale, bool night_sky) {
  TwilightSkip skip;
  const SkyStyle& first = plan.first();
  if (!plan.sequence || night_sky || first.output.pixel_type != PixelType::kHalf) return skip;
  // The frames the march would run in, lowest Sun first.
  std::vector<const FramePlan*> candidates;
  for (const FramePlan& frame : plan.frames) {
    if (!plan.Bakes(frame) || !ActiveCloudLayers(PrunedStyle(*frame.style).clouds).empty()) continue;
    if (renderers.Main(*frame.style, frame.CloudTimeSeconds(), frame.sun).MarchesTwilight(frame.sun))
      candidates.push_back(&frame);
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const FramePlan* a, const FramePlan* b) { return a->elevation_deg < b->elevation_deg; });
  double highest_skipped = -90.0, closest = 0.0;
  for (const FramePlan* frame : candidates) {
    SkyRenderer& r = renderers.Main(*frame->style, frame->CloudTimeSeconds(), frame->sun);
    const std::vector<ViewRequest> probe = {{MAPPING_LATLONG, 512, 256, 0}};
    std::vector<float> renders[2];
    for (int march : {1, 0}) {
      r.set_twilight_march(march == 1);
      renders[march] = r.Render(frame->sun, probe, true)[0];
    }
    r.set_twilight_march(true);
    ++skip.probed;
    const double apart = HalfStepsApart(renders[1], renders[0], half_scale);
    if (!(apart < kTwilightProbeSteps)) break;
    skip.frames.insert(frame->number);
    highest_skipped = std::max(highest_skipped, frame->elevation_deg);
    closest = std::max(closest, apart);
  }
  if (skip.probed == 0) return skip;
  skip.report = skip.frames.empty()
                    ? fmt::format("twilight march in every frame ({} probed)", skip.probed)
                    : fmt::format(
                          "no twilight march in frames {} (Sun at or below {:.1f} deg: their probes with and "
                          "without it at most {:.3f} of a half-float step apart; {} probed)",
                          Runs(skip.frames), highest_skipped, closest, skip.probed);
  return skip;
}

}  // namespace skybake
