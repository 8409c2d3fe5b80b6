// The spectral mode in the accuracy study: the colour error of three
// wavelengths and of 4, 8, 16 bins against a converged 48-bin render (CIE
// Delta E 2000 of the tone-mapped preview, relative luminance error), the
// time each count costs, and twilight pictures (three channels against the
// spectral mode, ozone on and off).
#pragma once

#include <string>

#include "skybake/gpu/vulkan_context.h"
#include "skybake/tools/accuracy.h"

namespace skybake {

// Writes spectral.csv, spectral_results.md and the pictures
// spectral_twilight_*.png into options.out_dir; returns the markdown.
std::string RunSpectralStudy(VulkanContext& vulkan, const AccuracyStudyOptions& options);

}  // namespace skybake
