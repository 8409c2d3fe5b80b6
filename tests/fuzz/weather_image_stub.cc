// The fuzz build parses styles without the OpenImageIO module: a weather
// image or a formation's density mask is reported as unreadable, so the
// parser's error path for it runs.
#include <optional>
#include <stdexcept>

#include "skybake/model/cloud_formation.h"
#include "skybake/model/clouds.h"

namespace skybake {

std::string CheckWeatherImage(const std::string&) { return "weather images are not read in the fuzz build"; }

std::vector<float> ReadWeatherImage(const std::string& path, int) {
  throw std::runtime_error(path + ": weather images are not read in the fuzz build");
}

std::string CheckCloudMask(const std::string&, const CloudFormation&) {
  return "density masks are not read in the fuzz build";
}

// ToCloudInputs (model/clouds.cc) is never called by the parsers.
void ApplyCloudFormation(const CloudLayer&, uint32_t, int, double, const std::string&, gpu::GpuCloudLayer&,
                         std::vector<float>&, int) {
  throw std::logic_error("cloud formations are not simulated in the fuzz build");
}

double FormationTimeSeconds(const CloudFormation&, std::optional<double>, double) {
  throw std::logic_error("cloud formations are not simulated in the fuzz build");
}

}  // namespace skybake
