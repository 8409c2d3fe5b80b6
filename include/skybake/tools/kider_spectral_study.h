// Kider et al. 2014's measured skies scored with Bruneton's protocol as
// published (`skybake accuracy --only kider-spectral`): the model's spectral
// radiance at the 31 wavelengths 360 + 11.75 k nm up to 712.5 nm against
// the measurements, RMSE per capture over its 81 directions x 31
// wavelengths, then sqrt(mean RMSE^2) over the captures
// (docs/accuracy.md, "With Bruneton's protocol as published").
#pragma once

#include <string>
#include <vector>

#include "skybake/gpu/vulkan_context.h"
#include "skybake/tools/accuracy.h"

namespace skybake {

struct KiderSpectralScore {
  std::string model;     // "single scattering, midpoint 16/8", ...
  int captures = 0;      // scored (those of shared/groundtruth/kider2014 with framework40 samples)
  double rmse_mw = 0.0;  // mW m^-2 sr^-1 nm^-1
};

// Every model's score (with options.quick the single-scattering 16/8 model
// alone, the ctest smoke run); writes kider2014_spectral.csv into
// options.out_dir. Reads options.shared_dir.
std::vector<KiderSpectralScore> ScoreKiderSpectral(VulkanContext& vulkan, const AccuracyStudyOptions& options);

}  // namespace skybake
