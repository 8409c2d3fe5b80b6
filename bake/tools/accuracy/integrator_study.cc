// The integrator study (study.h): single scattering by every integrator and
// sample count on the GPU against the converged double-precision reference,
// each case timed on this machine; the Pareto front of (time, error) and the
// quality presets chosen from it.
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include <fmt/format.h>
#include <glm/glm.hpp>

#include "skybake/gpu/sky_renderer.h"
#include "skybake/input/config.h"
#include "skybake/output/exr_io.h"
#include "study.h"

namespace skybake {
namespace {

std::vector<StudyCase> StudyCases(bool quick) {
  std::vector<StudyCase> cases;
  const std::vector<std::pair<int, int>> paper =
      quick ? std::vector<std::pair<int, int>>{{16, 8}, {128, 64}}
            : std::vector<std::pair<int, int>>{{16, 8}, {32, 16}, {64, 32}, {128, 64}, {512, 256}};
  for (int integrator : {INTEGRATOR_MIDPOINT, INTEGRATOR_TRAPEZOID, INTEGRATOR_SIMPSON, INTEGRATOR_ANALYTIC})
    for (auto [v, l] : paper) cases.push_back(MakeCase(integrator, v, l));
  const std::vector<int> lut_steps =
      quick ? std::vector<int>{16, 64} : std::vector<int>{8, 16, 24, 32, 48, 64, 128, 256};
  for (int v : lut_steps) {
    cases.push_back(MakeCase(INTEGRATOR_ANALYTIC, v, 0));
    cases.push_back(MakeCase(INTEGRATOR_ANALYTIC, v, 0, false, 0, 0, STEPS_QUADRATIC));
  }
  if (!quick)
    for (int v : {16, 32, 64, 128}) {
      cases.push_back(MakeCase(INTEGRATOR_SIMPSON, v, 0));
      cases.push_back(MakeCase(INTEGRATOR_SIMPSON, v, 0, false, 0, 0, STEPS_QUADRATIC));
    }
  // A finer transmittance LUT (1024 x 256, 1024 quadrature points) removes
  // the interpolation floor of the 256 x 64 one.
  auto fine_lut = [](StudyCase c) {
    c.quality.transmittance_width = 1024;
    c.quality.transmittance_height = 256;
    c.quality.transmittance_steps = 1024;
    c.name += " T1024";
    return c;
  };
  if (!quick) {
    for (int v : {64, 128, 256}) {
      cases.push_back(fine_lut(MakeCase(INTEGRATOR_ANALYTIC, v, 0, false, 0, 0, STEPS_QUADRATIC)));
      cases.push_back(fine_lut(MakeCase(INTEGRATOR_SIMPSON, v, 0, false, 0, 0, STEPS_QUADRATIC)));
    }
    cases.push_back(fine_lut(MakeCase(INTEGRATOR_SIMPSON, 128, 0, true, 768, 432, STEPS_QUADRATIC)));
    cases.push_back(fine_lut(MakeCase(INTEGRATOR_SIMPSON, 128, 0, true, 1536, 864, STEPS_QUADRATIC)));
  }
  // The sky-view LUT: its resolution against its steps per texel (a frame
  // of a time-lapse pays for one LUT, whatever its output size).
  for (auto [w, h] : quick
                         ? std::vector<std::pair<int, int>>{{192, 108}}
                         : std::vector<std::pair<int, int>>{{192, 108}, {192, 216}, {256, 144}, {320, 180}, {384, 216}})
    for (int v : quick ? std::vector<int>{48} : std::vector<int>{24, 32, 48})
      cases.push_back(MakeCase(INTEGRATOR_ANALYTIC, v, 0, true, w, h, STEPS_QUADRATIC));
  if (!quick) cases.push_back(MakeCase(INTEGRATOR_ANALYTIC, 48, 0, true, 768, 432, STEPS_QUADRATIC));
  return cases;
}

// Directions of the study: the upper hemisphere, denser towards the horizon
// (where the integrals are hardest): elevations 0 .. 90 deg, azimuths every
// 15 deg, the zenith once.
std::vector<glm::dvec3> StudyDirections(bool quick) {
  std::vector<glm::dvec3> dirs;
  const std::vector<double> elevations = quick ? std::vector<double>{0.0, 5.0, 30.0}
                                               : std::vector<double>{0.0, 0.5, 2.0, 5.0, 10.0, 20.0, 35.0, 55.0, 75.0};
  double step = quick ? 45.0 : 15.0;
  for (double e : elevations)
    for (double a = 0.0; a < 360.0; a += step) dirs.push_back(SunDirectionFromElevationAzimuth(e, a));
  dirs.push_back({0.0, 1.0, 0.0});
  return dirs;
}

// Sun elevations (deg): by day (3..90 deg, the presets' front) and at
// twilight (1 .. -10 deg), where the Earth's shadow crosses the low sky.
std::vector<double> SunElevations(bool quick) {
  return quick ? std::vector<double>{90.0, 45.0, 10.0, 3.0, 0.0, -3.0}
               : std::vector<double>{90.0, 45.0, 10.0, 3.0, 1.0, 0.0, -1.0, -3.0, -6.0, -10.0};
}

// What the study measures: single scattering (no multiple scattering, no
// ground, no disc) of the Earth defaults, in spectral units, for every sun
// elevation in every direction.
struct StudySetup {
  AtmosphereParams atmosphere;
  EffectSettings single;
  std::vector<double> elevations;
  std::vector<glm::dvec3> dirs;
  std::vector<StudyCase> cases;
};

StudySetup MakeSetup(const AccuracyStudyOptions& options) {
  StudySetup s;
  s.atmosphere.observer_altitude_m = options.observer_altitude_m;
  s.single.multiple_scattering = false;
  s.single.sun_disc = false;
  s.single.ground = false;
  s.elevations = SunElevations(options.quick);
  s.dirs = StudyDirections(options.quick);
  s.cases = StudyCases(options.quick);
  if (!options.only.empty())
    std::erase_if(s.cases, [&](const StudyCase& c) { return c.name.find(options.only) == std::string::npos; });
  return s;
}

// The converged reference per sun elevation, and its own convergence
// (segment 8 km against 4 km) as markdown table rows.
struct ReferenceSkies {
  std::map<double, std::vector<glm::dvec3>> radiance;
  std::vector<std::string> convergence_rows;
};

ReferenceSkies ComputeReference(const StudyContext& context, const StudySetup& setup) {
  const std::vector<glm::dvec3>& dirs = setup.dirs;
  context.Say(fmt::format("reference: {} directions x {} sun elevations", dirs.size(), setup.elevations.size()));
  ReferenceSkies reference;
  ConvergedReference fine(setup.atmosphere, 4.0), coarse(setup.atmosphere, 8.0);
  for (double elevation : setup.elevations) {
    glm::dvec3 sun = SunDirectionFromElevationAzimuth(elevation, 180.0);
    std::vector<glm::dvec3> ref(dirs.size()), half(dirs.size());
    ParallelIndices(dirs.size(), [&](size_t i) {
      ref[i] = fine.Radiance(dirs[i], sun);
      half[i] = coarse.Radiance(dirs[i], sun);
    });
    // Over the values the study's errors are measured on: above 1e-4 of the maximum.
    double worst = 0.0, max_value = 0.0;
    for (const glm::dvec3& l : ref) max_value = std::max({max_value, l.x, l.y, l.z});
    for (size_t i = 0; i < dirs.size(); ++i)
      for (int c = 0; c < 3; ++c)
        if (ref[i][c] > 1e-4 * max_value) worst = std::max(worst, std::abs(half[i][c] - ref[i][c]) / ref[i][c]);
    reference.convergence_rows.push_back(fmt::format("| {} | {:.2e} |", elevation, worst));
    reference.radiance[elevation] = ref;
    context.Say(fmt::format("reference at {} deg: segment 8 km vs 4 km differ by {:.2e} at most", elevation, worst));
  }
  return reference;
}

struct CaseResult {
  std::string name;
  QualitySettings quality;
  double elevation = 0.0;
  double rmse_mw = 0.0;       // mW m^-2 sr^-1 nm^-1
  double max_relative = 0.0;  // over values above 1e-4 of the maximum
  double max_delta_e = 0.0;   // CIE76 after exposure + ACES
  double ms_per_mp = 0.0;     // lavapipe, GPU timestamps, median of 3
};

// The GPU's radiance `gpu` (RGBA per direction) against the reference's
// `ref` for one case at one sun elevation.
CaseResult CompareWithReference(const StudyCase& c, double elevation, double ms_per_mp, const std::vector<float>& gpu,
                                const std::vector<glm::dvec3>& ref) {
  const Rgb to_luminance = OutputScale(OutputUnits::kLuminance);
  double max_value = 0.0, log_sum = 0.0;
  for (const glm::dvec3& l : ref) {
    max_value = std::max({max_value, l.x, l.y, l.z});
    double y = 0.2126 * l.x * to_luminance[0] + 0.7152 * l.y * to_luminance[1] + 0.0722 * l.z * to_luminance[2];
    log_sum += std::log(std::max(y, 1e-9));
  }
  double exposure = 0.18 / std::exp(log_sum / double(ref.size()));
  CaseResult r;
  r.name = c.name;
  r.quality = c.quality;
  r.elevation = elevation;
  r.ms_per_mp = ms_per_mp;
  double sum_sq = 0.0;
  for (size_t i = 0; i < ref.size(); ++i) {
    glm::dvec3 g(gpu[4 * i], gpu[4 * i + 1], gpu[4 * i + 2]);
    for (int ch = 0; ch < 3; ++ch) {
      double diff = g[ch] - ref[i][ch];
      sum_sq += diff * diff;
      if (ref[i][ch] > 1e-4 * max_value) r.max_relative = std::max(r.max_relative, std::abs(diff) / ref[i][ch]);
    }
    glm::dvec3 lab_g = DisplayLab(g, to_luminance, exposure), lab_r = DisplayLab(ref[i], to_luminance, exposure);
    r.max_delta_e = std::max(r.max_delta_e, glm::length(lab_g - lab_r));
  }
  r.rmse_mw = 1000.0 * std::sqrt(sum_sq / (3.0 * ref.size()));
  return r;
}

// Every case on the GPU, timed, against the reference: one result per case
// and sun elevation.
std::vector<CaseResult> MeasureCases(StudyContext& context, const StudySetup& setup, const ReferenceSkies& reference) {
  std::vector<CaseResult> results;
  for (const StudyCase& c : setup.cases) {
    SkyRenderer renderer(context.vulkan, setup.atmosphere, c.quality, setup.single, {1, 1, 1});
    double ms_per_mp = TimePerMegapixel(context.vulkan, setup.atmosphere, c.quality, setup.single);
    for (double elevation : setup.elevations) {
      glm::dvec3 sun = SunDirectionFromElevationAzimuth(elevation, 180.0);
      std::vector<float> gpu = renderer.RenderDirections(sun, setup.dirs);
      results.push_back(CompareWithReference(c, elevation, ms_per_mp, gpu, reference.radiance.at(elevation)));
    }
    context.Say(fmt::format("{:<32} {:9.1f} ms/MP", c.name, ms_per_mp));
  }
  return results;
}

// A case over all sun elevations: worst over the daylight elevations (sun
// >= 3 deg) and over all, and whether it is on the Pareto front of (time,
// daylight error).
struct Summary {
  std::string name;
  QualitySettings quality;
  double ms_per_mp = 0.0, day_error = 0.0, all_error = 0.0, day_delta_e = 0.0;
  bool pareto = false;
};

std::vector<Summary> Summarize(const std::vector<StudyCase>& cases, const std::vector<CaseResult>& results) {
  std::vector<Summary> summaries;
  for (const StudyCase& c : cases) {
    Summary s;
    s.name = c.name;
    s.quality = c.quality;
    for (const CaseResult& r : results) {
      if (r.name != c.name) continue;
      s.ms_per_mp = r.ms_per_mp;
      s.all_error = std::max(s.all_error, r.max_relative);
      if (r.elevation >= 3.0) {
        s.day_error = std::max(s.day_error, r.max_relative);
        s.day_delta_e = std::max(s.day_delta_e, r.max_delta_e);
      }
    }
    summaries.push_back(s);
  }
  MarkParetoFront(summaries, &Summary::ms_per_mp, &Summary::day_error);
  return summaries;
}

// The quickest case on the front within each preset's error bound.
struct PresetChoice {
  std::string preset;
  double bound;
  const Summary* choice = nullptr;
};

std::vector<PresetChoice> ChoosePresets(const std::vector<Summary>& summaries) {
  std::vector<PresetChoice> presets = {{"draft", 0.05}, {"production", 0.01}, {"reference", 0.001}};
  for (PresetChoice& p : presets)
    for (const Summary& s : summaries)
      if (s.pareto && s.day_error <= p.bound && (!p.choice || s.ms_per_mp < p.choice->ms_per_mp)) p.choice = &s;
  return presets;
}

// accuracy.csv: every case at every sun elevation.
void WriteResultsCsv(const StudyContext& context, const std::vector<CaseResult>& results) {
  std::ostringstream csv;
  csv << "case,integrator,view_steps,light_steps,sky_view_lut,sun_elevation_deg,rmse_mW_m2_sr_nm,"
         "max_relative_error,max_delta_e76,ms_per_megapixel\n";
  for (const CaseResult& r : results)
    csv << fmt::format(
        "{},{},{},{},{},{},{:.6g},{:.6g},{:.6g},{:.6g}\n", r.name, IntegratorName(r.quality.integrator),
        r.quality.view_steps, r.quality.light_steps,
        r.quality.sky_view_lut ? fmt::format("{}x{}", r.quality.sky_view_width, r.quality.sky_view_height) : "no",
        r.elevation, r.rmse_mw, r.max_relative, r.max_delta_e, r.ms_per_mp);
  WriteFileAtomically(context.OutPath("accuracy.csv"), csv.str());
}

// accuracy.png: the cases and the front, through gnuplot.
void PlotFront(StudyContext& context, const std::vector<Summary>& summaries) {
  std::vector<PlotPoint> points;
  for (const Summary& s : summaries) points.push_back({s.ms_per_mp, s.day_error, s.pareto, s.name});
  const std::string status = PlotParetoFront(
      context.options.out_dir, "accuracy", points,
      {"lavapipe time per megapixel (ms, 2 cores)", "max relative error, upper hemisphere, sun 3..90 deg",
       "skybake: what accuracy costs (single scattering vs converged reference)"});
  context.notes.push_back(fmt::format("Plot {}: {}/accuracy.png", status, context.options.out_dir));
}

std::string Markdown(const AccuracyStudyOptions& options, const std::vector<Summary>& summaries,
                     const std::vector<PresetChoice>& presets, const ReferenceSkies& reference) {
  std::string md;
  md += fmt::format(
      "## Cases (observer at {} m; worst over sun elevations 3..90 deg; every elevation in accuracy.csv)\n\n",
      options.observer_altitude_m);
  md +=
      "| case | ms per megapixel | max relative error | max Delta-E76 | worst incl. twilight (sun 1 .. -10 deg) | "
      "Pareto |\n";
  md += "| --- | ---: | ---: | ---: | ---: | :---: |\n";
  for (const Summary& s : summaries)
    md += fmt::format("| {} | {:.1f} | {:.2e} | {:.3f} | {:.2e} | {} |\n", s.name, s.ms_per_mp, s.day_error,
                      s.day_delta_e, s.all_error, s.pareto ? "yes" : "");
  md +=
      "\n## Presets chosen from the front\n\n| preset | bound | case | max relative error | ms per megapixel |\n| --- "
      "| --- | --- | ---: | ---: |\n";
  for (const PresetChoice& p : presets) {
    if (p.choice)
      md += fmt::format("| `{}` | <= {:g}% | {} | {:.2e} | {:.1f} |\n", p.preset, p.bound * 100, p.choice->name,
                        p.choice->day_error, p.choice->ms_per_mp);
    else md += fmt::format("| `{}` | <= {:g}% | none of the cases meets it | | |\n", p.preset, p.bound * 100);
  }
  md +=
      "\n## Reference convergence (segment 8 km vs 4 km, max relative difference)\n\n| sun elevation (deg) | max "
      "relative difference |\n| ---: | ---: |\n";
  for (const std::string& row : reference.convergence_rows) md += row + "\n";
  return md;
}

}  // namespace

std::string RunIntegratorStudy(StudyContext& context) {
  const StudySetup setup = MakeSetup(context.options);
  const ReferenceSkies reference = ComputeReference(context, setup);
  const std::vector<CaseResult> results = MeasureCases(context, setup, reference);
  const std::vector<Summary> summaries = Summarize(setup.cases, results);
  const std::vector<PresetChoice> presets = ChoosePresets(summaries);
  WriteResultsCsv(context, results);
  PlotFront(context, summaries);
  return Markdown(context.options, summaries, presets, reference);
}

}  // namespace skybake
