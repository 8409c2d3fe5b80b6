// The cloud panorama (cloud_panorama.h): when it is used, that a latlong of
// its size is bit for bit the marched one in its whole rows (the narrower rows
// close to it), and that the views resampled from
// it stay close to the views marched texel by texel, on lavapipe under the
// validation layer.
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <vector>

#include <gtest/gtest.h>
#include <glm/glm.hpp>

#include "skybake/gpu/cloud_panorama.h"
#include "skybake/model/clouds.h"
#include "skybake/input/config.h"
#include "skybake/model/envmap.h"
#include "skybake/pipeline/pass_plan.h"
#include "skybake/pipeline/pipeline.h"
#include "skybake/gpu/sky_renderer.h"
#include "test_support.h"

namespace skybake {
namespace {

TEST(CloudPanoramaChoice, TheFinestViewSetsItsSize) {
  // W3's views: six 512^2 faces, the 512 x 3072 strip, a 2048 x 1024 latlong.
  std::vector<ViewRequest> w3;
  for (int f = 0; f < 6; ++f) w3.push_back({MAPPING_VULKAN_FACE, 512, 512, f});
  w3.push_back({MAPPING_CUBE_STRIP, 512, 3072, 0});
  w3.push_back({MAPPING_LATLONG, 2048, 1024, 0});
  CloudPanorama p = ChooseCloudPanorama(w3, 1.0);
  EXPECT_EQ(p.width, 2048);
  EXPECT_EQ(p.height, 1024);
  // Faces and strip alone: pi / 2 x 512 = 804.2 -> 805 rows.
  std::vector<ViewRequest> cube(w3.begin(), w3.begin() + 7);
  p = ChooseCloudPanorama(cube, 1.0);
  EXPECT_EQ(p.height, 805);
  EXPECT_EQ(p.width, 1610);
  EXPECT_EQ(ChooseCloudPanorama(cube, 0.5).height, 403);
  // Not cheaper than marching: one latlong, or the six faces alone at scale 1.
  EXPECT_EQ(ChooseCloudPanorama({w3.back()}, 1.0).width, 0);
  EXPECT_EQ(ChooseCloudPanorama(std::vector<ViewRequest>(w3.begin(), w3.begin() + 6), 1.0).width, 0);
  // A quarter of one latlong's texels is.
  EXPECT_EQ(ChooseCloudPanorama({w3.back()}, 0.5).height, 512);
  // Off, explicit directions, too large.
  EXPECT_EQ(ChooseCloudPanorama(w3, 0.0).width, 0);
  std::vector<ViewRequest> with_directions = w3;
  with_directions.push_back({MAPPING_DIRECTIONS, 9, 1, 0});
  EXPECT_EQ(ChooseCloudPanorama(with_directions, 1.0).width, 0);
  EXPECT_EQ(ChooseCloudPanorama(w3, 2.5).width, 0) << "2560 rows > kMaxCloudPanoramaHeight";
}

SkyStyle Style(const std::string& toml) {
  ConfigResult r = ParseSkyStyle(toml, "cloud_panorama_test.toml");
  EXPECT_TRUE(r.ok()) << (r.errors.empty() ? "" : r.errors[0].Format());
  return PrunedStyle(r.style);
}

std::unique_ptr<SkyRenderer> MakeRenderer(const SkyStyle& style) {
  return std::make_unique<SkyRenderer>(testing::Vulkan(), StyledAtmosphere(style.atmosphere, style.aoas), style.quality,
                                       style.effects, OutputScale(style.output.units), false,
                                       ToAoasInputs(style.aoas, OutputScale(OutputUnits::kLuminance)),
                                       ToCloudInputs(style.clouds, style.aoas.seed, "", 0.0));
}

// Mean of |a - b| over the mean of b (RGB), every value clamped at 20 times
// b's mean first: the sun disc's texels (1e5 times the sky's radiance) would
// otherwise make the mean that of the disc alone.
double MeanRelativeDifference(const std::vector<float>& a, const std::vector<float>& b) {
  double mean = 0.0;
  for (size_t i = 0; i < b.size(); ++i)
    if (i % 4 != 3) mean += std::abs(double(b[i]));
  const double clamp = 20.0 * mean / double(b.size() / 4 * 3);
  double diff = 0.0, sum = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    if (i % 4 == 3) continue;
    const double va = std::min(double(a[i]), clamp), vb = std::min(double(b[i]), clamp);
    diff += std::abs(va - vb);
    sum += std::abs(vb);
  }
  return diff / sum;
}

TEST(CloudPanoramaChoice, TheRowBlocksRunInAnOrderThatMarchesEachOnce) {
  for (int n = 1; n <= 300; ++n) {
    const int stride = CloudPanoramaBlockStride(n);
    std::vector<int> seen(size_t(n), 0);
    for (int g = 0; g < n; ++g) ++seen[size_t((g * stride) % n)];
    EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), n) << n << " blocks, stride " << stride;
  }
  // W3's 512 marched rows in 64 blocks: a run of a quarter of the groups (one
  // of lavapipe's 4 threads) holds blocks from every quarter of the rows.
  const int stride = CloudPanoramaBlockStride(64);
  std::vector<int> quarters(4, 0);
  for (int g = 0; g < 16; ++g) ++quarters[size_t((g * stride) % 64 / 16)];
  for (int q : quarters) EXPECT_GE(q, 3) << "stride " << stride;
}

TEST(CloudPanoramaChoice, ARowMarchesItsWidthTimesTheCosineOfItsLatitude) {
  const CloudPanorama p{2048, 1024};
  // The equator's rows whole, the poles' the narrowest, width x cos + 1 between.
  EXPECT_EQ(CloudPanoramaRowWidth(p, 511), 2048);
  EXPECT_EQ(CloudPanoramaRowWidth(p, 512), 2048);
  EXPECT_EQ(CloudPanoramaRowWidth(p, 0), CLOUD_PANORAMA_MIN_ROW_WIDTH);
  EXPECT_EQ(CloudPanoramaRowWidth(p, 1023), CLOUD_PANORAMA_MIN_ROW_WIDTH);
  const double cos60 = std::sin(3.14159265358979 * 170.0 / 1023.0);  // row 170: latitude 60.1 deg
  EXPECT_EQ(CloudPanoramaRowWidth(p, 170), int(std::ceil(2048.0 * cos60)) + 1);
  // Over the whole sphere about 2 / pi of the texels of whole rows.
  const double share = double(CloudPanoramaMarchedTexels(p, {0, 1024})) / double(p.texels());
  EXPECT_NEAR(share, 2.0 / 3.14159265358979, 0.01);
}

TEST(CloudPanoramaChoice, OnlyTheRowsThatCanSeeABandAreMarched) {
  const CloudPanorama p{2048, 1024};
  const double radius_km = 6360.0;
  const std::vector<std::array<double, 2>> w3_band = {{1.5, 3.0}};
  auto mu = [&](int y) { return std::sin(-3.14159265358979 * (double(y) / 1023.0 - 0.5)); };
  // From the ground: the sky half and the rows within the margin below the
  // horizontal (0.02 in cosine: 6-7 rows); every row left out sees the ground.
  CloudPanoramaRows r = CloudPanoramaRowsSeeingBands(p, radius_km, 0.0, w3_band);
  EXPECT_EQ(r.begin, 0);
  EXPECT_GT(r.end, 512);
  EXPECT_LT(r.end, 512 + 10);
  EXPECT_LT(mu(r.end), -kCloudPanoramaRowMargin);
  EXPECT_GE(mu(r.end - 1), -kCloudPanoramaRowMargin);
  // 800 m up, below the band: the horizon dips (cosine -0.0159), so more rows.
  CloudPanoramaRows up = CloudPanoramaRowsSeeingBands(p, radius_km, 0.8, w3_band);
  EXPECT_GT(up.end, r.end);
  const double dip = -std::sqrt(1.0 - std::pow(radius_km / (radius_km + 0.8), 2));
  EXPECT_LT(mu(up.end), dip - kCloudPanoramaRowMargin);
  // Inside the band: every row.
  r = CloudPanoramaRowsSeeingBands(p, radius_km, 2.0, w3_band);
  EXPECT_EQ(r.begin, 0);
  EXPECT_EQ(r.end, 1024);
  // Above every band (an aircraft at 5 km): the rows below the margin above
  // the horizontal, down to the nadir.
  r = CloudPanoramaRowsSeeingBands(p, radius_km, 5.0, {{1.5, 3.0}, {4.0, 4.5}});
  EXPECT_GT(r.begin, 500);
  EXPECT_LT(r.begin, 512);
  EXPECT_LE(mu(r.begin), kCloudPanoramaRowMargin);
  EXPECT_GT(mu(r.begin - 1), kCloudPanoramaRowMargin);
  EXPECT_EQ(r.end, 1024);
  // Between two bands: every row.
  r = CloudPanoramaRowsSeeingBands(p, radius_km, 3.5, {{1.5, 3.0}, {4.0, 4.5}});
  EXPECT_EQ(r.begin, 0);
  EXPECT_EQ(r.end, 1024);
}

TEST(CloudPanoramaPass, LatlongIsTheMarchedOneAndTheCubeStaysClose) {
  const std::string layer = R"(
[quality]
preset = "draft"
cloud_view_steps = 16
cloud_light_steps = 3
[[cloud_layer]]
altitude_m = 1500
thickness_m = 1500
coverage = 0.5
# Large features, no detail: the resampling, not the aliasing of sub-texel
# detail (a quarter-texel shift of the marched directions alone changes
# a face by 4e-2 with 1.5 km detail).
shape_size_m = 60000
weather_size_m = 200000
detail_amount = 0.0
)";
  const SkyStyle panorama = Style(layer);
  SkyStyle direct = Style(layer);
  direct.clouds.quality.panorama_scale = 0.0;
  const glm::dvec3 sun = SunDirectionFromElevationAzimuth(30.0, 135.0);
  const int n = 64;
  std::vector<ViewRequest> views;
  for (int f = 0; f < 6; ++f) views.push_back({MAPPING_VULKAN_FACE, n, n, f});
  views.push_back({MAPPING_CUBE_STRIP, n, 6 * n, 0});
  views.push_back({MAPPING_LATLONG, 4 * n, 2 * n, 0});
  auto a = MakeRenderer(panorama)->Render(sun, views);
  std::unique_ptr<SkyRenderer> d = MakeRenderer(direct);
  auto b = d->Render(sun, views);
  ASSERT_EQ(a.size(), b.size());
  // The latlong of the panorama's size reads its own texels where a row is
  // whole (near the horizon): the same bytes there; the narrower rows along
  // the row, close to the marched ones.
  const CloudPanorama p = ChooseCloudPanorama(views, 1.0);
  ASSERT_EQ(p.width, 4 * n);
  int whole_rows = 0;
  for (int y = 0; y < p.height; ++y) {
    if (CloudPanoramaRowWidth(p, y) != p.width) continue;
    ++whole_rows;
    for (int i = 4 * y * p.width; i < 4 * (y + 1) * p.width; ++i) ASSERT_EQ(a.back()[i], b.back()[i]) << "row " << y;
  }
  EXPECT_GE(whole_rows, 2);
  EXPECT_LT(MeanRelativeDifference(a.back(), b.back()), 5e-2);
  // The cube resampled from it (bilinear, first order: the difference halves
  // when the sizes double, 2.6e-2 at n = 128), close to the marched cube;
  // the -Y face sees the ground alone, no cloud, in both.
  for (size_t v = 0; v + 1 < a.size(); ++v) {
    const double e = MeanRelativeDifference(a[v], b[v]);
    EXPECT_LT(e, 5e-2) << "view " << v;
    if (v != 3) {
      EXPECT_GT(e, 0.0) << "view " << v << " was resampled, not marched";
    }
    for (size_t i = 0; i < a[v].size(); ++i) ASSERT_TRUE(std::isfinite(a[v][i]) && a[v][i] >= 0.0f);
  }
  testing::ExpectNoValidationMessages();
}

}  // namespace
}  // namespace skybake
