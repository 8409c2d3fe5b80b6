// Cloud bands shadow each other (clouds.glsl, CloudOpticalDepthToSun):
// the sunlight of a sample is attenuated by the bands above its own, on
// lavapipe under the validation layer.
#include <memory>
#include <string>

#include <gtest/gtest.h>
#include <glm/glm.hpp>

#include "skybake/model/clouds.h"
#include "skybake/input/config.h"
#include "skybake/model/envmap.h"
#include "skybake/pipeline/pass_plan.h"
#include "skybake/pipeline/pipeline.h"
#include "skybake/gpu/sky_renderer.h"
#include "test_support.h"

namespace skybake {
namespace {

// The radiance (RGB mean) seen straight down from 5 km, sun at 45 deg, of a
// style: the view ray crosses only the lower deck at 1-2 km. Every light
// sample is marched (no light volume, which a style of one band would read
// and one of two bands would not), so one deck and two compare alike.
double NadirRadiance(const std::string& layers) {
  const std::string toml =
      "[quality]\npreset = \"draft\"\ncloud_light_volume_columns = 0\n[atmosphere]\nobserver_altitude_m = 5000\n" +
      layers;
  ConfigResult parsed = ParseSkyStyle(toml, "cloud_band_shadow_test.toml");
  EXPECT_TRUE(parsed.ok()) << (parsed.errors.empty() ? "" : parsed.errors[0].Format());
  const SkyStyle style = PrunedStyle(parsed.style);
  SkyRenderer renderer(testing::Vulkan(), StyledAtmosphere(style.atmosphere, style.aoas), style.quality, style.effects,
                       OutputScale(style.output.units), false,
                       ToAoasInputs(style.aoas, OutputScale(OutputUnits::kLuminance)),
                       ToCloudInputs(style.clouds, style.aoas.seed, "", 0.0));
  const glm::dvec3 sun = SunDirectionFromElevationAzimuth(45.0, 135.0);
  const std::vector<float> r = renderer.RenderDirections(sun, {glm::dvec3(0.0, -1.0, 0.0)});
  return (double(r[0]) + r[1] + r[2]) / 3.0;
}

// A flat, closed slab: coverage 1, no shape, no detail.
std::string Slab(double altitude_m, double thickness_m, double density_per_m) {
  return "[[cloud_layer]]\ntype = \"custom\"\nprofile = [0.0, 0.0, 1.0, 1.0]\ncoverage = 1.0\nshape_amount = 0.0\n"
         "detail_amount = 0.0\naltitude_m = " +
         std::to_string(altitude_m) + "\nthickness_m = " + std::to_string(thickness_m) +
         "\ndensity_per_m = " + std::to_string(density_per_m) + "\n";
}

TEST(CloudBandShadow, AnUpperDeckDarkensTheSunlightOfTheLowerOne) {
  const std::string lower = Slab(1000, 1000, 0.02);
  const double alone = NadirRadiance(lower);
  // Above the observer, out of the view ray's way: it can only act through
  // the lower deck's sunlight. Optical depth 1 vertically, 1.41 along the Sun.
  const double thin_above = NadirRadiance(lower + Slab(8000, 500, 0.002));
  const double thick_above = NadirRadiance(lower + Slab(8000, 500, 0.02));
  EXPECT_GT(alone, 0.0);
  EXPECT_LT(thin_above, 0.9 * alone) << "the upper deck shades the lower one";
  EXPECT_LT(thick_above, thin_above) << "a denser deck shades more";
  // Still lit by the sky (the ambient table knows no cloud): dim, not black.
  EXPECT_GT(thick_above, 0.01 * alone);
  // A deck below the lower one does not shade it.
  const double below = NadirRadiance(lower + Slab(200, 300, 0.02));
  EXPECT_NEAR(below, alone, 1e-6 * alone);
  testing::ExpectNoValidationMessages();
}

}  // namespace
}  // namespace skybake
