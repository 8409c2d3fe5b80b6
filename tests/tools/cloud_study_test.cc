// The cloud study of `skybake accuracy` (tools/cloud_study.h) in its quick
// form: a 48 x 24 latlong, two march cases, the reference's convergence and
// the panorama against every view marched. The full study (docs/accuracy.md,
// "Clouds") runs out of CI.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "skybake/tools/cloud_study.h"
#include "test_support.h"

namespace skybake {
namespace {

TEST(CloudStudyTest, QuickStudyMeasuresEveryCaseAgainstAConvergedReference) {
  CloudStudyOptions options;
  options.quick = true;
  options.out_dir = testing::FreshTempDir("cloud_study");
  CloudStudyResult r = RunCloudStudy(testing::Vulkan(), options);
  testing::ExpectNoValidationMessages();

  ASSERT_EQ(r.cases.size(), 2u);
  const CloudStudyCase& coarse = r.cases[0];  // 8 view / 2 light steps
  const CloudStudyCase& fine = r.cases[1];    // 48 / 6
  EXPECT_EQ(coarse.quality.view_steps, 8);
  EXPECT_EQ(fine.quality.view_steps, 48);
  for (const CloudStudyCase& c : r.cases) {
    EXPECT_TRUE(std::isfinite(c.mean_error) && std::isfinite(c.rmse)) << c.name;
    EXPECT_GT(c.mean_error, 0.0) << c.name;  // neither is the reference
    EXPECT_GT(c.ms_per_mp, 0.0) << c.name;   // lavapipe has timestamps
  }
  // More steps, closer to the reference; and the reference, each setting
  // halved, moves less than the finer case is from it: converged beyond it.
  EXPECT_GT(coarse.mean_error, 2.0 * fine.mean_error);
  ASSERT_EQ(r.convergence.size(), 2u);
  for (const CloudConvergence& c : r.convergence) {
    EXPECT_GT(c.mean_error, 0.0) << c.change;
    EXPECT_LT(c.mean_error, fine.mean_error) << c.change;
  }
  // The finer case is the faster's opposite: both on the front (one is
  // cheaper, the other better) unless the time measurement says otherwise;
  // at least one is on it.
  EXPECT_TRUE(coarse.pareto || fine.pareto);
  // Each preset's choice meets its bound.
  ASSERT_EQ(r.presets.size(), 3u);
  for (const CloudPresetChoice& p : r.presets)
    if (p.choice >= 0) {
      EXPECT_LE(r.cases[size_t(p.choice)].mean_error, p.bound) << p.preset;
      EXPECT_TRUE(r.cases[size_t(p.choice)].pareto) << p.preset;
    }
  // The panorama: every view marched, then one panorama resampled; the
  // resample adds an error but keeps it small.
  ASSERT_EQ(r.panorama.size(), 2u);
  EXPECT_EQ(r.panorama[0].quality.panorama_scale, 0.0);
  EXPECT_EQ(r.panorama[1].quality.panorama_scale, 1.0);
  for (const CloudStudyCase& c : r.panorama) {
    EXPECT_TRUE(std::isfinite(c.mean_error)) << c.name;
    EXPECT_LT(c.mean_error, 0.5) << c.name;
  }
  EXPECT_NE(r.markdown.find("## Clouds"), std::string::npos);
  EXPECT_NE(testing::ReadFileBytes(options.out_dir + "/cloud_study.csv").find("48/6 vol 32/16/64"), std::string::npos);
  EXPECT_EQ(testing::ReadFileBytes(options.out_dir + "/cloud_study_results.md"), r.markdown);
}

}  // namespace
}  // namespace skybake
