#include "exposure.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "skybake/model/envmap.h"
#include "skybake/model/tonemap.h"
#include "skybake/output/exr_io.h"
#include "skybake/pipeline/pass_plan.h"

namespace skybake {

std::vector<float> DisplayLuminance(const float* rgba, size_t texels, OutputUnits units) {
  std::vector<float> display(rgba, rgba + 4 * texels);
  if (units == OutputUnits::kLuminance) return display;
  Rgb to_luminance = OutputScale(OutputUnits::kLuminance);
  for (size_t i = 0; i < display.size(); ++i)
    if (i % 4 != 3) display[i] *= float(to_luminance[i % 4]);
  return display;
}

namespace {

// The largest value the sun disc can give a frame, in output units: its
// centre radiance unattenuated (transmittance <= 1), when the disc is on and
// its top is above the observer's horizon; nothing otherwise, nor under the
// AOAS skydome (which moves the observer and turns the Sun).
std::optional<double> VisibleDiscBound(const SkyStyle& unpruned, double elevation_deg) {
  const SkyStyle style = PrunedStyle(unpruned);
  if (!style.effects.sun_disc || style.aoas.skydome.enabled) return std::nullopt;
  const AtmosphereParams a = StyledAtmosphere(style.atmosphere, style.aoas);
  const double r = a.bottom_radius_km + a.observer_altitude_m * 1e-3;
  const double dip_deg = std::acos(std::min(a.bottom_radius_km / r, 1.0)) * 180.0 / M_PI;
  const double alpha = a.sun_angular_radius_rad;
  if (elevation_deg < -dip_deg - alpha * 180.0 / M_PI) return std::nullopt;
  // SunDiscRadiance at the centre (atmosphere.glsl): 1 / (pi alpha^2 (1 - u/3)).
  const double centre = 1.0 / (M_PI * alpha * alpha * (1.0 - a.limb_darkening_u / 3.0));
  const Rgb scale = OutputScale(style.output.units);
  double bound = 0.0;
  for (int c = 0; c < 3; ++c)
    bound = std::max(bound, a.solar_irradiance[c] * scale[c] * centre * style.effects.sun_disc_strength);
  return bound;
}

// The sequence's EV100 from its reference frame, and what chose it.
void ChooseEv100(const RenderPlan& plan, RendererCache& renderers, BakeExposure& exposure) {
  const FramePlan& ref = plan.frames[plan.reference];
  if (!plan.exposed) {
    exposure.source = "none (no preview or glTF texture)";
  } else if (ref.style->preview.auto_exposure) {
    const int h = ref.style->render.latlong_height;
    std::vector<float> latlong =
        renderers.Main(*ref.style, ref.CloudTimeSeconds(), ref.sun)
            .Render(ref.sun, {{MAPPING_LATLONG, 2 * h, h, 0}}, ref.style->output.sun == SunOutput::kMap)[0];
    exposure.ev100 = AutoEv100(DisplayLuminance(latlong.data(), latlong.size() / 4, ref.style->output.units), 2 * h, h);
    exposure.source = fmt::format("auto exposure of frame {} (highest sun), applied to every frame", ref.number);
  } else {
    exposure.ev100 = ref.style->preview.ev100;
    exposure.source = "preview.ev100";
  }
}

// The brightest texel of a frame is the sun disc's centre, or else the sky
// near it. While the disc is in the maps and above the horizon of some
// frame, its unattenuated centre radiance bounds the sequence without
// rendering; otherwise a coarse latlong plus the direction of the Sun's
// centre (the disc's, or the sky's brightest there without it) of every
// frame does.
double SequenceMaxValue(const RenderPlan& plan, RendererCache& renderers) {
  double max_value = 0.0;
  for (const FramePlan& frame : plan.frames)
    if (auto bound = VisibleDiscBound(*frame.style, frame.elevation_deg);
        bound && frame.style->output.sun == SunOutput::kMap) {
      // ibl.include_sun puts the Sun's energy into one texel of the
      // specular level 0: brighter than the disc by the ratio of their
      // solid angles when the texel is the smaller (ibl.h).
      const IblSettings& ibl = frame.style->ibl;
      double scale = 1.0;
      if (ibl.specular && ibl.include_sun) {
        const double a = frame.style->atmosphere.sun_angular_radius_rad;
        scale = std::max(1.0, M_PI * a * a / CubeTexelSolidAngle(0, 0, ibl.size));
      }
      max_value = std::max(max_value, *bound * scale);
    }
  if (max_value > 0.0) return max_value;
  for (const FramePlan& frame : plan.frames) {
    SkyRenderer& r = renderers.Main(*frame.style, frame.CloudTimeSeconds(), frame.sun);
    const bool disc = frame.style->output.sun == SunOutput::kMap;
    std::vector<float> coarse = r.Render(frame.sun, {{MAPPING_LATLONG, 128, 64, 0}}, disc)[0];
    std::vector<float> centre = r.RenderDirections(frame.sun, {frame.sun}, disc);
    RgbaImage a{128, 64, coarse}, b{1, 1, centre};
    max_value = std::max(max_value, CheckedMaxValue({&a, &b}));
  }
  return max_value;
}

}  // namespace

BakeExposure ChooseSequenceExposure(const RenderPlan& plan, RendererCache& renderers, StageTimer& timer) {
  BakeExposure exposure;
  if (!plan.sequence) return exposure;
  ChooseEv100(plan, renderers, exposure);
  // A factor 2 of margin; writing checks the bound. With the Sun as a
  // light the maps hold no disc: every frame is written unscaled unless its
  // own sky overflows (FrameHalfScale), so no frame is rendered twice here.
  if (plan.first().output.pixel_type == PixelType::kHalf && plan.first().output.sun == SunOutput::kMap)
    exposure.half_scale = HalfRangeScale(2.0 * SequenceMaxValue(plan, renderers), plan.first().output.overflow);
  timer.Finish("exposure", fmt::format("EV100 {} ({}), half scale {:.9g}",
                                       exposure.ev100 ? fmt::format("{:.2f}", *exposure.ev100) : "-", exposure.source,
                                       exposure.half_scale));
  return exposure;
}

}  // namespace skybake
