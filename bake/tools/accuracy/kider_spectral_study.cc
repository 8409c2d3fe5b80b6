// The Kider study with Bruneton's protocol as published (study.h): the
// model's spectral radiance at the 31 wavelengths 360 + 11.75 k nm up to
// 712.5 nm (k = 0..30) against the measurements at the same wavelengths
// (shared/groundtruth/kider2014/framework40/: point samples of the 1 nm
// data, as clear-sky-models takes them, all 15 captures), 81 directions,
// observer at 0 m; RMSE over the 81 x 31 samples per capture, then
// sqrt(mean RMSE^2) over the captures. The model atmosphere is the one of
// the three-wavelength Kider study (Bruneton 2017's demo), its coefficients
// at each wavelength from the demo's tabulated spectra (spectrum.h).
#include <cmath>
#include <fstream>
#include <map>

#include <fmt/format.h>

#include "skybake/tools/kider_spectral_study.h"
#include "skybake/gpu/sky_renderer.h"
#include "skybake/model/spectrum.h"
#include "skybake/output/exr_io.h"
#include "study.h"

namespace skybake {
namespace {

constexpr int kProtocolWavelengths = 31;  // 360 .. 712.5 nm

struct SpectralCapture {
  double sun_zenith = 0.0, sun_azimuth = 0.0;  // captures.csv: zenith, symmetry azimuth
  std::vector<glm::dvec3> directions;
  std::vector<std::vector<double>> radiance;  // [direction][k], W m^-2 sr^-1 nm^-1
};

std::map<std::string, SpectralCapture> ReadSpectralCaptures(const std::string& shared_dir) {
  std::map<std::string, SpectralCapture> captures;
  const std::string dir = shared_dir + "/groundtruth/kider2014/";
  std::ifstream in(dir + "captures.csv");
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    auto f = SplitCsv(line);
    if (f.size() < 7) continue;
    SpectralCapture c;
    c.sun_zenith = std::stod(f[4]);
    c.sun_azimuth = std::stod(f[6]);
    std::ifstream samples(dir + "framework40/" + f[0] + ".csv");
    std::string row;
    while (std::getline(samples, row)) {
      if (row.empty() || row[0] == '#' || row.rfind("index", 0) == 0) continue;
      auto s = SplitCsv(row);
      if (s.size() < size_t(5 + kProtocolWavelengths)) continue;
      c.directions.push_back(SunDirectionFromElevationAzimuth(90.0 - std::stod(s[1]), std::stod(s[2])));
      std::vector<double> l;
      for (int k = 0; k < kProtocolWavelengths; ++k) l.push_back(std::stod(s[5 + k]));
      c.radiance.push_back(l);
    }
    if (!c.directions.empty()) captures[f[0]] = c;
  }
  return captures;
}

}  // namespace

std::vector<KiderSpectralScore> ScoreKiderSpectral(VulkanContext& vulkan, const AccuracyStudyOptions& options) {
  auto say = [&](const std::string& text) {
    if (options.progress) options.progress(text);
  };
  AtmosphereParams bruneton;  // as RunKiderStudy
  bruneton.top_radius_km = 6420.0;
  bruneton.ground_albedo = {0.1, 0.1, 0.1};
  const std::map<std::string, SpectralCapture> captures = ReadSpectralCaptures(options.shared_dir);
  say(fmt::format("kider2014, 31 wavelengths 360..712.5 nm: {} captures", captures.size()));
  std::vector<double> lambda;
  for (int k = 0; k < kProtocolWavelengths; ++k) lambda.push_back(360.0 + 11.75 * k);
  // Point wavelengths (width 0): the tables interpolated at each, as the
  // framework samples its spectra.
  const std::vector<SpectralGroup> groups = SpectralGroups(bruneton, BinsAt(lambda, 0.0));

  std::vector<std::pair<std::string, QualitySettings>> models = {
      {"single scattering, midpoint 16/8", MakeCase(INTEGRATOR_MIDPOINT, 16, 8).quality},
      {"single scattering, midpoint 512/256", MakeCase(INTEGRATOR_MIDPOINT, 512, 256).quality},
      {"full model: multiple scattering + ground + production preset", QualityPreset("production")}};
  if (options.quick) models.resize(1);
  std::string csv = "model,capture,rmse_mW_m2_sr_nm\n";
  std::vector<KiderSpectralScore> scores;
  for (const auto& [label, quality] : models) {
    EffectSettings effects;
    effects.sun_disc = false;
    const bool full = label.rfind("full", 0) == 0;
    effects.multiple_scattering = full;
    effects.ground = full;
    // Every capture's radiance [capture][direction][k], group by group.
    std::map<std::string, std::vector<std::vector<double>>> model;
    for (const SpectralGroup& g : groups) {
      SkyRenderer renderer(vulkan, g.atmosphere, quality, effects, {1, 1, 1});
      for (const auto& [id, c] : captures) {
        const glm::dvec3 sun = SunDirectionFromElevationAzimuth(90.0 - c.sun_zenith, c.sun_azimuth);
        const std::vector<float> gpu = renderer.RenderDirections(sun, c.directions);
        auto& m = model[id];
        m.resize(c.directions.size(), std::vector<double>(kProtocolWavelengths, 0.0));
        for (size_t i = 0; i < c.directions.size(); ++i)
          for (int ch = 0; ch < 3; ++ch)
            if (g.bin[ch] >= 0) m[i][g.bin[ch]] = gpu[4 * i + ch];
      }
    }
    double sum_sq_rmse = 0.0;
    for (const auto& [id, c] : captures) {
      double sum_sq = 0.0;
      for (size_t i = 0; i < c.directions.size(); ++i)
        for (int k = 0; k < kProtocolWavelengths; ++k) {
          const double d = 1000.0 * (model[id][i][k] - c.radiance[i][k]);
          sum_sq += d * d;
        }
      const double rmse = std::sqrt(sum_sq / double(c.directions.size() * kProtocolWavelengths));
      csv += fmt::format("{},{},{:.2f}\n", label, id, rmse);
      sum_sq_rmse += rmse * rmse;
    }
    const double total = std::sqrt(sum_sq_rmse / double(std::max<size_t>(captures.size(), 1)));
    scores.push_back({label, int(captures.size()), total});
    say(fmt::format("kider2014 spectral: {}: {:.1f} mW/(m2 sr nm)", label, total));
  }
  WriteFileAtomically(options.out_dir + "/kider2014_spectral.csv", csv);
  return scores;
}

std::string RunKiderSpectralStudy(StudyContext& context) {
  std::string md =
      "\n## Against the measured skies of Kider et al. 2014 (Bruneton's protocol: 31 wavelengths 360..712.5 nm)\n\n"
      "| model | captures | RMSE mW/(m2 sr nm) |\n| --- | ---: | ---: |\n";
  for (const KiderSpectralScore& s : ScoreKiderSpectral(context.vulkan, context.options))
    md += fmt::format("| {} | {} | {:.1f} |\n", s.model, s.captures, s.rmse_mw);
  md +=
      "| Galaj & Wojciechowski 2019, single scattering 16/8 | | 31.3-33.7 |\n"
      "| Galaj & Wojciechowski 2019, single scattering 512/256 | | 25.6 |\n";
  return md;
}

}  // namespace skybake
