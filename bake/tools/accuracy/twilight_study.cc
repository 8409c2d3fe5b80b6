// The twilight study (study.h): each quality preset, and the variants of the
// sky-view path tried against the Earth's shadow, at the sun elevations where
// it crosses the low sky (3 .. -10 deg), against the converged
// double-precision reference; each case timed at a twilight and a daylight
// Sun. Single scattering (no multiple scattering, no ground, no disc), upper
// hemisphere, denser near the horizon than the integrator study (the
// shadow's edge lies 0..6 deg above it). `--study twilight`; `--only TEXT`
// keeps the cases whose name contains TEXT (`--only presets`: the three
// presets alone); `--observer-altitude-m` moves the observer. Writes
// twilight.csv.
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include <fmt/format.h>
#include <glm/glm.hpp>

#include "skybake/gpu/sky_renderer.h"
#include "skybake/output/exr_io.h"
#include "study.h"

namespace skybake {
namespace {

struct TwilightCase {
  std::string name;
  std::string preset;  // whose budget it is held to
  QualitySettings quality;
};

// The presets, then the variants of the two sky-view presets tried at
// twilight (docs/accuracy.md, "Twilight"): more rows, the sky ray-marched per
// texel (no LUT: the floor any LUT of those steps can reach), and the low
// sky marched per texel at twilight with the LUT elsewhere.
std::vector<TwilightCase> TwilightCases() {
  std::vector<TwilightCase> cases;
  for (const std::string& preset : QualityPresetNames()) cases.push_back({preset, preset, QualityPreset(preset)});
  auto variant = [&](const std::string& preset, const std::string& what, auto change) {
    TwilightCase c{preset + ", " + what, preset, QualityPreset(preset)};
    // The variant of a preset that already has a twilight band starts without it.
    c.quality.twilight_march_band_deg = 0.0;
    c.quality.twilight_march_steps = 0;
    c.quality.twilight_sun_below_deg = 0.0;
    change(c.quality);
    cases.push_back(c);
  };
  for (int rows : {288, 576})
    variant("production", fmt::format("LUT 256x{}", rows), [&](QualitySettings& q) { q.sky_view_height = rows; });
  for (int steps : {32, 64})
    variant("production", fmt::format("ray march {} steps, no LUT", steps), [&](QualitySettings& q) {
      q.sky_view_lut = false;
      q.view_steps = steps;
    });
  // What limits the 64-step march towards a Sun at 0..1 deg: the sun
  // transmittance's LUT (a finer one, or none: the Sun's path marched), or
  // the view integral's rule.
  variant("production", "ray march 64 steps, no LUT, transmittance LUT 1024x256", [&](QualitySettings& q) {
    q.sky_view_lut = false;
    q.view_steps = 64;
    q.transmittance_width = 1024;
    q.transmittance_height = 256;
  });
  variant("production", "ray march 64 steps, no LUT, sun path marched 64 steps", [&](QualitySettings& q) {
    q.sky_view_lut = false;
    q.view_steps = 64;
    q.light_steps = 64;
  });
  variant("production", "ray march 64 steps, no LUT, Simpson", [&](QualitySettings& q) {
    q.sky_view_lut = false;
    q.view_steps = 64;
    q.integrator = INTEGRATOR_SIMPSON;
  });
  for (double band : {6.0, 10.0})
    for (int steps : {32, 64})
      variant("production", fmt::format("band {:g} deg marched, {} steps", band, steps), [&](QualitySettings& q) {
        q.twilight_march_band_deg = band;
        q.twilight_march_steps = steps;
      });
  // A twilight frame (the Sun below 3 deg) reading the sun transmittance in
  // the logarithm, with the band marched (the LUT presets) or not.
  auto twilight = [](double band, int steps) {
    return [=](QualitySettings& q) {
      q.twilight_march_band_deg = band;
      q.twilight_march_steps = steps;
      q.twilight_sun_below_deg = 3.0;
    };
  };
  for (int steps : {32, 64})
    variant("production", fmt::format("band 10 deg marched, {} steps, Sun below 3 deg, log T", steps),
            twilight(10.0, steps));
  for (int rows : {432})
    variant("draft", fmt::format("LUT 192x{}", rows), [&](QualitySettings& q) { q.sky_view_height = rows; });
  for (double band : {6.0, 10.0})
    for (int steps : {24})
      variant("draft", fmt::format("band {:g} deg marched, {} steps", band, steps), [&](QualitySettings& q) {
        q.twilight_march_band_deg = band;
        q.twilight_march_steps = steps;
      });
  for (int steps : {24, 32})
    variant("draft", fmt::format("band 10 deg marched, {} steps, Sun below 3 deg, log T", steps),
            twilight(10.0, steps));
  variant("reference", "Sun below 3 deg, log T", twilight(0.0, 0));
  for (int steps : {128})
    variant("reference", fmt::format("Sun below 3 deg, log T, {} steps", steps), twilight(0.0, steps));
  return cases;
}

double Budget(const std::string& preset) { return preset == "draft" ? 0.05 : preset == "production" ? 0.01 : 0.001; }

// The low sky, where the shadow's edge is, on one side of the Sun's
// vertical plane (the sky is symmetric about it), and the zenith: the
// directions of accuracy_test's PresetsAgainstTheirBudgetsAtTwilight.
std::vector<glm::dvec3> TwilightDirections(bool quick, std::vector<glm::dvec2>& elevation_azimuth) {
  const std::vector<double> elevations =
      quick ? std::vector<double>{0.0, 1.0, 3.0, 6.0, 30.0}
            : std::vector<double>{0.0, 1.0, 2.0, 3.0, 4.0, 6.0, 10.0, 15.0, 20.0, 30.0};
  const std::vector<double> azimuths = quick ? std::vector<double>{0.0, 90.0, 180.0}
                                             : std::vector<double>{0.0, 30.0, 60.0, 75.0, 90.0, 120.0, 150.0, 180.0};
  std::vector<glm::dvec3> dirs;
  for (double e : elevations)
    for (double a : azimuths) {
      dirs.push_back(SunDirectionFromElevationAzimuth(e, a));
      elevation_azimuth.push_back({e, a});
    }
  dirs.push_back({0.0, 1.0, 0.0});
  elevation_azimuth.push_back({90.0, 0.0});
  return dirs;
}

std::vector<double> TwilightSunElevations(bool quick) {
  return quick ? std::vector<double>{3.0, -1.0, -6.0}
               : std::vector<double>{5.0, 3.0, 2.0, 1.0, 0.0, -1.0, -3.0, -6.0, -10.0};
}

struct TwilightResult {
  double max_relative = 0.0;
  glm::dvec2 worst{0.0};  // elevation, azimuth of the view (deg; the Sun at azimuth 180)
};

TwilightResult Compare(const std::vector<float>& gpu, const std::vector<glm::dvec3>& ref,
                       const std::vector<glm::dvec2>& where) {
  double max_value = 0.0;
  for (const glm::dvec3& l : ref) max_value = std::max({max_value, l.x, l.y, l.z});
  TwilightResult r;
  for (size_t i = 0; i < ref.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      if (!(ref[i][c] > 1e-4 * max_value)) continue;
      double e = std::abs(gpu[4 * i + c] - ref[i][c]) / ref[i][c];
      if (e > r.max_relative) r.max_relative = e, r.worst = where[i];
    }
  return r;
}

}  // namespace

std::string RunTwilightStudy(StudyContext& context) {
  const AccuracyStudyOptions& options = context.options;
  AtmosphereParams atmosphere;
  atmosphere.observer_altitude_m = options.observer_altitude_m;
  EffectSettings single;
  single.multiple_scattering = false;
  single.sun_disc = false;
  single.ground = false;
  std::vector<glm::dvec2> where;
  const std::vector<glm::dvec3> dirs = TwilightDirections(options.quick, where);
  const std::vector<double> suns = TwilightSunElevations(options.quick);
  std::vector<TwilightCase> cases = TwilightCases();
  if (options.quick) cases.resize(2);  // draft, production
  if (options.only == "presets") std::erase_if(cases, [&](const TwilightCase& c) { return c.name != c.preset; });
  else if (!options.only.empty())
    std::erase_if(cases, [&](const TwilightCase& c) { return c.name.find(options.only) == std::string::npos; });

  context.Say(fmt::format("twilight reference: {} directions x {} sun elevations", dirs.size(), suns.size()));
  ConvergedReference reference(atmosphere, 4.0);
  std::map<double, std::vector<glm::dvec3>> expected;
  for (double sun_elevation : suns) {
    const glm::dvec3 sun = SunDirectionFromElevationAzimuth(sun_elevation, 180.0);
    std::vector<glm::dvec3>& ref = expected[sun_elevation];
    ref.resize(dirs.size());
    ParallelIndices(dirs.size(), [&](size_t i) { ref[i] = reference.Radiance(dirs[i], sun); });
  }

  std::ostringstream csv;
  csv << "case,preset,budget,sun_elevation_deg,max_relative_error,worst_view_elevation_deg,"
         "worst_view_azimuth_from_sun_deg,ms_per_megapixel_sun_minus3,ms_per_megapixel_sun_45\n";
  std::string md = fmt::format(
      "## Twilight (observer at {} m; max relative error of single scattering over the upper hemisphere, "
      "values above 1e-4 of the maximum; lavapipe ms per megapixel of a latlong, sky-view LUT included)\n\n",
      options.observer_altitude_m);
  md += "| case | budget |";
  for (double s : suns) md += fmt::format(" sun {:g} |", s);
  md += " worst view (elevation, azimuth from the Sun) | ms/MP, sun -3 | ms/MP, sun 45 |\n| --- | ---: |";
  for (size_t i = 0; i < suns.size(); ++i) md += " ---: |";
  md += " --- | ---: | ---: |\n";
  for (const TwilightCase& c : cases) {
    const double budget = Budget(c.preset);
    SkyRenderer renderer(context.vulkan, atmosphere, c.quality, single, {1, 1, 1});
    const double ms_twilight = TimePerMegapixel(context.vulkan, atmosphere, c.quality, single, -3.0);
    const double ms_day = TimePerMegapixel(context.vulkan, atmosphere, c.quality, single, 45.0);
    md += fmt::format("| {} | {:g}% |", c.name, 100.0 * budget);
    TwilightResult worst_of_all;
    for (double sun_elevation : suns) {
      const glm::dvec3 sun = SunDirectionFromElevationAzimuth(sun_elevation, 180.0);
      TwilightResult r = Compare(renderer.RenderDirections(sun, dirs), expected.at(sun_elevation), where);
      if (r.max_relative > worst_of_all.max_relative) worst_of_all = r;
      md += r.max_relative > budget ? fmt::format(" **{:.2e}** |", r.max_relative)
                                    : fmt::format(" {:.2e} |", r.max_relative);
      csv << fmt::format("\"{}\",{},{},{},{:.6g},{},{},{:.6g},{:.6g}\n", c.name, c.preset, budget, sun_elevation,
                         r.max_relative, r.worst.x, 180.0 - r.worst.y, ms_twilight, ms_day);
    }
    md += fmt::format(" {:g}, {:g} | {:.1f} | {:.1f} |\n", worst_of_all.worst.x, 180.0 - worst_of_all.worst.y,
                      ms_twilight, ms_day);
    context.Say(fmt::format("{:<44} worst {:.2e}  {:7.1f} ms/MP at sun -3, {:7.1f} at 45", c.name,
                            worst_of_all.max_relative, ms_twilight, ms_day));
  }
  md += "\nBold: the preset's budget is missed. Every case at every elevation: twilight.csv.\n";
  WriteFileAtomically(context.OutPath("twilight.csv"), csv.str());
  return md;
}

}  // namespace skybake
