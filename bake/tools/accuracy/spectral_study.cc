#include "skybake/tools/spectral_study.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "skybake/gpu/sky_renderer.h"
#include "skybake/input/style.h"
#include "skybake/model/spectrum.h"
#include "skybake/model/tonemap.h"
#include "skybake/output/exr_io.h"
#include "study.h"

namespace skybake {
namespace {

using Clock = std::chrono::steady_clock;

// The sky as a bake sees it: multiple scattering, the ground, production
// quality; no disc (its few texels would decide the exposure's metering).
struct Settings {
  QualitySettings quality = QualityPreset("production");
  EffectSettings effects;
  Settings() { effects.sun_disc = false; }
};

struct Render {
  std::vector<float> rgba;  // linear Rec.709, cd/m^2
  double frame_ms = 0.0;    // the frame's render (its sky-view LUTs included), wall clock
};

// Counts compared: 3 is the three-wavelength path; 48 the reference.
std::vector<int> Counts(bool quick) { return quick ? std::vector<int>{3, 4, 48} : std::vector<int>{3, 4, 8, 16, 48}; }

struct ColourError {
  double mean_delta_e = 0.0, p95_delta_e = 0.0, max_delta_e = 0.0;
  double mean_luminance = 0.0, max_luminance = 0.0;  // relative
};

// Over the upper hemisphere of a latlong (rows above the horizon): Delta E
// 2000 of the previews (one exposure for both), relative luminance error
// where the reference's luminance exceeds 1e-3 of its maximum.
ColourError Compare(const std::vector<float>& test, const std::vector<float>& ref, int width, int height,
                    double exposure) {
  const std::vector<uint8_t> a = TonemapToSrgb8(test, width, height, exposure);
  const std::vector<uint8_t> b = TonemapToSrgb8(ref, width, height, exposure);
  const int rows = height / 2;
  std::vector<double> de;
  double max_y = 0.0;
  for (size_t t = 0; t < size_t(width) * rows; ++t)
    max_y = std::max(max_y, Rec709Luminance({ref[4 * t], ref[4 * t + 1], ref[4 * t + 2]}));
  ColourError e;
  size_t lum_count = 0;
  for (size_t t = 0; t < size_t(width) * rows; ++t) {
    de.push_back(DeltaE2000(Srgb8ToLab({a[3 * t], a[3 * t + 1], a[3 * t + 2]}),
                            Srgb8ToLab({b[3 * t], b[3 * t + 1], b[3 * t + 2]})));
    const double y_ref = Rec709Luminance({ref[4 * t], ref[4 * t + 1], ref[4 * t + 2]});
    const double y = Rec709Luminance({test[4 * t], test[4 * t + 1], test[4 * t + 2]});
    if (y_ref > 1e-3 * max_y) {
      const double rel = std::abs(y - y_ref) / y_ref;
      e.max_luminance = std::max(e.max_luminance, rel);
      e.mean_luminance += rel;
      ++lum_count;
    }
  }
  for (double d : de) e.mean_delta_e += d;
  e.mean_delta_e /= double(de.size());
  e.mean_luminance /= double(std::max<size_t>(lum_count, 1));
  std::sort(de.begin(), de.end());
  e.p95_delta_e = de[size_t(0.95 * double(de.size() - 1))];
  e.max_delta_e = de.back();
  return e;
}

// The zenith's colour (the top row's mean) as linear Rec.709 normalised
// to luminance 1, and its CIE xy.
std::string ZenithColour(const std::vector<float>& rgba, int width) {
  std::array<double, 3> rgb{};
  for (int x = 0; x < width; ++x)
    for (int c = 0; c < 3; ++c) rgb[c] += rgba[4 * x + c] / width;
  const double y = Rec709Luminance(rgb);
  // xy from Rec.709 (IEC 61966-2-1 matrix rows).
  const double X = 0.4124 * rgb[0] + 0.3576 * rgb[1] + 0.1805 * rgb[2];
  const double Y = 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
  const double Z = 0.0193 * rgb[0] + 0.1192 * rgb[1] + 0.9505 * rgb[2];
  return fmt::format("{:.3g} cd/m^2, Rec.709 / Y = ({:.3f}, {:.3f}, {:.3f}), xy = ({:.4f}, {:.4f})", y, rgb[0] / y,
                     rgb[1] / y, rgb[2] / y, X / (X + Y + Z), Y / (X + Y + Z));
}

}  // namespace

std::string RunSpectralStudy(VulkanContext& vulkan, const AccuracyStudyOptions& options) {
  auto say = [&](const std::string& text) {
    if (options.progress) options.progress(text);
  };
  std::filesystem::create_directories(options.out_dir);
  AtmosphereParams atmosphere;  // Earth defaults: the tables' values at 680/550/440 nm
  atmosphere.observer_altitude_m = options.observer_altitude_m;
  const Settings settings;
  const int height = options.quick ? 32 : 256, width = 2 * height;
  const std::vector<ViewRequest> views = {{MAPPING_LATLONG, width, height, 0}};
  const std::vector<double> elevations = options.quick
                                             ? std::vector<double>{30.0, -4.0}
                                             : std::vector<double>{60.0, 30.0, 10.0, 3.0, 0.0, -2.0, -4.0, -6.0};
  const int repeats = options.quick ? 1 : 3;

  // Every count at every elevation; the time is the fastest of `repeats`
  // renders of the frame (each with its sky-view LUTs: the Sun is moved away
  // and back between them).
  std::map<int, std::map<double, Render>> renders;
  std::map<int, double> lut_ms;
  for (int n : Counts(options.quick)) {
    QualitySettings q = settings.quality;
    q.wavelengths = n;
    SkyRenderer renderer(vulkan, atmosphere, q, settings.effects, OutputScale(OutputUnits::kLuminance));
    Clock::time_point start = Clock::now();
    renderer.PrecomputeLuts();
    lut_ms[n] = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    for (double elevation : elevations) {
      const glm::dvec3 sun = SunDirectionFromElevationAzimuth(elevation, 180.0);
      Render r;
      r.frame_ms = 1e30;
      for (int k = 0; k < repeats; ++k) {
        if (k > 0)
          renderer.Render(SunDirectionFromElevationAzimuth(elevation + 1.0, 180.0), {{MAPPING_LATLONG, 4, 2, 0}});
        start = Clock::now();
        r.rgba = renderer.Render(sun, views)[0];
        r.frame_ms = std::min(r.frame_ms, std::chrono::duration<double, std::milli>(Clock::now() - start).count());
      }
      renders[n][elevation] = std::move(r);
    }
    say(fmt::format("spectral: {} wavelengths, LUTs {:.0f} ms, frame {:.0f} ms at sun {} deg", n, lut_ms[n],
                    renders[n][elevations.front()].frame_ms, elevations.front()));
  }

  // Errors against 48 bins, one exposure per elevation: the reference's.
  std::string csv =
      "wavelengths,sun_elevation_deg,ev100,mean_delta_e2000,p95_delta_e2000,max_delta_e2000,"
      "mean_relative_luminance_error,max_relative_luminance_error,frame_ms,lut_ms\n";
  std::map<int, ColourError> worst;
  std::map<int, double> mean_frame_ms;
  std::map<double, double> ev100;
  for (double elevation : elevations) {
    const std::vector<float>& ref = renders[48][elevation].rgba;
    ev100[elevation] = AutoEv100(ref, width, height);
    const double exposure = ExposureFromEv100(ev100[elevation]);
    for (int n : Counts(options.quick)) {
      const ColourError e = Compare(renders[n][elevation].rgba, ref, width, height, exposure);
      csv += fmt::format("{},{},{:.3f},{:.4g},{:.4g},{:.4g},{:.4g},{:.4g},{:.1f},{:.1f}\n", n, elevation,
                         ev100[elevation], e.mean_delta_e, e.p95_delta_e, e.max_delta_e, e.mean_luminance,
                         e.max_luminance, renders[n][elevation].frame_ms, lut_ms[n]);
      ColourError& w = worst[n];
      w.mean_delta_e = std::max(w.mean_delta_e, e.mean_delta_e);
      w.p95_delta_e = std::max(w.p95_delta_e, e.p95_delta_e);
      w.max_delta_e = std::max(w.max_delta_e, e.max_delta_e);
      w.mean_luminance = std::max(w.mean_luminance, e.mean_luminance);
      w.max_luminance = std::max(w.max_luminance, e.max_luminance);
      mean_frame_ms[n] += renders[n][elevation].frame_ms / double(elevations.size());
    }
  }
  WriteFileAtomically(options.out_dir + "/spectral.csv", csv);

  // Twilight pictures: sun -4 deg, the three-wavelength path, 48 bins, and
  // 48 bins without ozone (the Chappuis band's share of the blue zenith),
  // at one stated exposure.
  const double twilight = -4.0;
  std::string pictures;
  if (renders[48].count(twilight)) {
    QualitySettings q = settings.quality;
    q.wavelengths = 48;
    EffectSettings no_ozone = settings.effects;
    no_ozone.ozone = false;
    std::vector<float> no_ozone_rgba, no_ozone3;
    if (!options.quick) {
      SkyRenderer without(vulkan, atmosphere, q, no_ozone, OutputScale(OutputUnits::kLuminance));
      no_ozone_rgba = without.Render(SunDirectionFromElevationAzimuth(twilight, 180.0), views)[0];
      q.wavelengths = 3;
      SkyRenderer without3(vulkan, atmosphere, q, no_ozone, OutputScale(OutputUnits::kLuminance));
      no_ozone3 = without3.Render(SunDirectionFromElevationAzimuth(twilight, 180.0), views)[0];
    }
    const double ev = ev100[twilight];
    const double exposure = ExposureFromEv100(ev);
    struct Picture {
      std::string file, label;
      const std::vector<float>* rgba;
    };
    std::vector<Picture> list = {
        {"spectral_twilight_rgb3.png", "3 wavelengths (680/550/440 nm)", &renders[3][twilight].rgba},
        {"spectral_twilight_48.png", "48 bins", &renders[48][twilight].rgba}};
    if (!options.quick) {
      list.push_back({"spectral_twilight_48_no_ozone.png", "48 bins, ozone off", &no_ozone_rgba});
      list.push_back({"spectral_twilight_rgb3_no_ozone.png", "3 wavelengths, ozone off", &no_ozone3});
    }
    pictures += fmt::format(
        "Sun {} deg, observer at {} m, latlong {} x {} (the Sun below its "
        "centre: azimuth 180 deg, South), one exposure for all: EV100 {:.2f} (metered on the "
        "48-bin sky), ACES filmic, sRGB.\n\n| picture | zenith |\n| --- | --- |\n",
        twilight, options.observer_altitude_m, width, height, ev);
    for (const Picture& p : list) {
      WritePng(options.out_dir + "/" + p.file, width, height, TonemapToSrgb8(*p.rgba, width, height, exposure));
      pictures += fmt::format("| {} (`{}`) | {} |\n", p.label, p.file, ZenithColour(*p.rgba, width));
    }
  }

  std::string md = fmt::format(
      "## Spectral mode: colour error against 48 bins and what each count costs\n\n"
      "Observer at {} m, production quality, multiple scattering and ground on, sun disc off, latlong {} x {}, "
      "sun elevations {}. Per elevation one exposure (the 48-bin sky's auto exposure) for every count; Delta E "
      "2000 of the tone-mapped 8-bit previews over the upper hemisphere; luminance error where the 48-bin "
      "luminance exceeds 1e-3 of its maximum. Worst over the elevations (every one in spectral.csv):\n\n"
      "| wavelengths | mean Delta E 2000 | 95th pct | max | mean rel. luminance error | max | frame ms (mean) | "
      "LUTs ms |\n| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n",
      options.observer_altitude_m, width, height, fmt::join(elevations, ", "));
  for (int n : Counts(options.quick)) {
    const ColourError& w = worst[n];
    md += fmt::format("| {}{} | {:.2f} | {:.2f} | {:.2f} | {:.2e} | {:.2e} | {:.0f} | {:.0f} |\n", n,
                      n == 3 ? " (680/550/440 nm)" : "", w.mean_delta_e, w.p95_delta_e, w.max_delta_e, w.mean_luminance,
                      w.max_luminance, mean_frame_ms[n], lut_ms[n]);
  }
  md += "\n## Twilight pictures\n\n" + pictures;
  WriteFileAtomically(options.out_dir + "/spectral_results.md", md);
  return md;
}

std::string RunSpectralStudy(StudyContext& context) { return RunSpectralStudy(context.vulkan, context.options); }

}  // namespace skybake
