// The cloud study of `skybake accuracy`: what each cloud quality setting
// (view steps, light steps, octaves, noise volume sizes, panorama size) costs
// in time and buys in accuracy. W3's cloud layer (configs/benchmark/w3.toml:
// one cumulus layer, 1500 to 3000 m, coverage 0.45, 0.05 per metre) is baked
// into a latlong on the GPU for every case and compared, over the texels that
// look above the horizon, with a converged reference: the same march with
// many more steps and the finest volumes. The reference shows its own
// convergence by halving each of its settings in turn. The cloud quality
// presets (CloudQualityPreset) are the cheapest cases on the Pareto front of
// (time, error) within each preset's bound (docs/accuracy.md, "Clouds").
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "skybake/gpu/vulkan_context.h"
#include "skybake/model/clouds.h"

namespace skybake {

struct CloudStudyOptions {
  std::string out_dir = "docs";  // cloud_study.csv, cloud_study_results.md, cloud_study.png
  bool quick = false;            // a few cases on a small latlong (the ctest smoke run)
  int latlong_height = 0;        // rows of the study's latlong; 0: 128 (quick: 24)
  int timing_runs = 0;           // renders timed per case (after its error renders), the median kept; 0: 2 (quick: 1)
  std::string only;              // when set, only the cases whose name contains it
  std::function<void(const std::string&)> progress;
};

struct CloudStudyCase {
  std::string name;
  CloudQuality quality;
  double mean_error = 0.0;     // worst over the sun elevations of mean |L - L_ref| / mean L_ref
  double rmse = 0.0;           // the same elevations' worst RMSE / mean L_ref
  double ms_per_mp = 0.0;      // the cloud passes' GPU time per megapixel of output, median (wall time on lavapipe)
  double cpu_ms_per_mp = 0.0;  // the process's CPU time of a render per megapixel, median: the front's cost
  bool pareto = false;         // on the front of (cpu_ms_per_mp, mean_error) among the march cases
};

// How far the reference is from converged: its error measure between the
// reference and the reference with one setting halved (steps) or with the
// volumes at half their size.
struct CloudConvergence {
  std::string change;
  double mean_error = 0.0;
  double rmse = 0.0;
};

struct CloudPresetChoice {
  std::string preset;
  double bound = 0.0;  // on mean_error
  int choice = -1;     // index into CloudStudyResult::cases; -1 when none meets the bound
};

struct CloudStudyResult {
  CloudQuality reference;
  std::vector<double> sun_elevations_deg;
  int latlong_height = 0;
  std::vector<CloudStudyCase> cases;     // the march settings (one latlong, no panorama)
  std::vector<CloudStudyCase> panorama;  // panorama sizes (latlong and six faces)
  std::vector<CloudConvergence> convergence;
  std::vector<CloudPresetChoice> presets;
  std::string markdown;
};

// The bounds of the presets on the mean relative error: draft 10%,
// production 5%, reference 1%.
std::vector<CloudPresetChoice> CloudPresetBounds();

// Runs the study on `vulkan`, writes its files into out_dir, returns the
// results (the markdown report among them).
CloudStudyResult RunCloudStudy(VulkanContext& vulkan, const CloudStudyOptions& options);

}  // namespace skybake
