// The fuzz build parses styles without the OpenImageIO module: a weather
// image is reported as unreadable, so the parser's error path for it runs.
#include <stdexcept>

#include "skybake/model/clouds.h"

namespace skybake {

std::string CheckWeatherImage(const std::string&) { return "weather images are not read in the fuzz build"; }

std::vector<float> ReadWeatherImage(const std::string& path, int) {
  throw std::runtime_error(path + ": weather images are not read in the fuzz build");
}

}  // namespace skybake
