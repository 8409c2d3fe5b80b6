// The Kider study (study.h): the model against the measured skies of Kider
// et al. 2014, with Bruneton's RMSE protocol at 440/550/680 nm, observer at
// 0 m, Bruneton 2017's demo atmosphere.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <utility>

#include <fmt/format.h>

#include "skybake/gpu/sky_renderer.h"
#include "skybake/output/exr_io.h"
#include "study.h"

namespace skybake {
namespace {

struct KiderCapture {
  std::string id;
  double sun_zenith = 0.0, sun_azimuth = 0.0;
};

struct Measurement {
  glm::dvec3 dir;
  glm::dvec3 rgb;  // 680, 550, 440 nm, W m^-2 sr^-1 nm^-1
};

// captures.csv: each capture's sun (zenith, symmetry azimuth), by id.
std::map<std::string, KiderCapture> ReadCaptures(const std::string& shared_dir) {
  std::map<std::string, KiderCapture> captures;
  std::ifstream in(shared_dir + "/groundtruth/kider2014/captures.csv");
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    auto f = SplitCsv(line);
    if (f.size() < 7) continue;
    captures[f[0]] = {f[0], std::stod(f[4]), std::stod(f[6])};  // zenith, symmetry azimuth
  }
  return captures;
}

// photometric.csv: each capture's measured directions and radiance.
std::map<std::string, std::vector<Measurement>> ReadMeasurements(const std::string& shared_dir) {
  std::map<std::string, std::vector<Measurement>> measured;
  std::ifstream in(shared_dir + "/groundtruth/kider2014/photometric.csv");
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    auto f = SplitCsv(line);
    if (f.size() < 14) continue;
    double zenith = std::stod(f[2]), azimuth = std::stod(f[3]);
    measured[f[0]].push_back({SunDirectionFromElevationAzimuth(90.0 - zenith, azimuth),
                              {std::stod(f[13]), std::stod(f[12]), std::stod(f[11])}});
  }
  return measured;
}

// The models compared: Galaj's single scattering at few and many steps, and
// the full model at the production preset.
std::vector<std::pair<std::string, QualitySettings>> KiderModels() {
  QualitySettings galaj16 = MakeCase(INTEGRATOR_MIDPOINT, 16, 8).quality;
  QualitySettings galaj512 = MakeCase(INTEGRATOR_MIDPOINT, 512, 256).quality;
  return {{"single scattering, midpoint 16/8", galaj16},
          {"single scattering, midpoint 512/256", galaj512},
          {"full model: multiple scattering + ground + production preset", QualityPreset("production")}};
}

// The RMSE of one capture (mW m^-2 sr^-1 nm^-1) over its measured directions.
double CaptureRmse(SkyRenderer& renderer, const KiderCapture& capture, const std::vector<Measurement>& samples) {
  std::vector<glm::dvec3> sample_dirs;
  for (const Measurement& m : samples) sample_dirs.push_back(m.dir);
  glm::dvec3 sun = SunDirectionFromElevationAzimuth(90.0 - capture.sun_zenith, capture.sun_azimuth);
  std::vector<float> gpu = renderer.RenderDirections(sun, sample_dirs);
  double sum_sq = 0.0;
  for (size_t i = 0; i < samples.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      double d = 1000.0 * (gpu[4 * i + c] - samples[i].rgb[c]);
      sum_sq += d * d;
    }
  return std::sqrt(sum_sq / (3.0 * samples.size()));
}

}  // namespace

std::string RunKiderStudy(StudyContext& context) {
  context.Say("kider2014: 15 captures");
  AtmosphereParams bruneton;
  bruneton.top_radius_km = 6420.0;
  bruneton.ground_albedo = {0.1, 0.1, 0.1};
  const std::map<std::string, KiderCapture> captures = ReadCaptures(context.options.shared_dir);
  std::map<std::string, std::vector<Measurement>> measured = ReadMeasurements(context.options.shared_dir);
  std::vector<std::string> kider_rows;
  std::string kider_csv = "model,capture,rmse_mW_m2_sr_nm\n";
  for (const auto& [label, quality] : KiderModels()) {
    EffectSettings effects;
    effects.sun_disc = false;
    bool full = label.rfind("full", 0) == 0;
    effects.multiple_scattering = full;
    effects.ground = full;
    SkyRenderer renderer(context.vulkan, bruneton, quality, effects, {1, 1, 1});
    double sum_sq_rmse = 0.0;
    int count = 0;
    std::string per_capture;
    for (const auto& [id, capture] : captures) {
      const auto& samples = measured[id];
      if (samples.empty()) continue;
      double rmse = CaptureRmse(renderer, capture, samples);
      per_capture += fmt::format("{},{},{:.2f}\n", label, id, rmse);
      sum_sq_rmse += rmse * rmse;
      ++count;
    }
    double total = std::sqrt(sum_sq_rmse / std::max(count, 1));
    kider_rows.push_back(fmt::format("| {} | {} | {:.1f} |", label, count, total));
    kider_csv += per_capture;
  }
  // Every file through the one safe writer (exr_io.h): no link followed.
  WriteFileAtomically(context.OutPath("kider2014.csv"), kider_csv);

  std::string md =
      "\n## Against the measured skies of Kider et al. 2014 (Bruneton's RMSE, 440/550/680 nm)\n\n| model | captures | "
      "RMSE mW/(m2 sr nm) |\n| --- | ---: | ---: |\n";
  for (const std::string& row : kider_rows) md += row + "\n";
  return md;
}

}  // namespace skybake
