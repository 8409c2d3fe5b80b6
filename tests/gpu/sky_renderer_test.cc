// The lavapipe renderer (float32) against the double-precision CPU reference
// compiled from the same source, under the Khronos validation layer.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <thread>

#include <gtest/gtest.h>
#include <glm/glm.hpp>

#include "skybake/model/envmap.h"
#include "skybake/tools/reference_model.h"
#include "skybake/gpu/sky_renderer.h"
#include "test_support.h"

namespace skybake {
namespace {

struct Comparison {
  double max_relative_error = 0.0;
  size_t compared = 0;
  size_t skipped = 0;
};

// Relative error per channel wherever the reference exceeds `floor` times
// the image maximum (the criterion).
Comparison Compare(const std::vector<float>& gpu, const std::vector<double>& ref, double floor) {
  double max_value = 0.0;
  for (size_t i = 0; i < ref.size(); ++i)
    if (i % 4 != 3) max_value = std::max(max_value, ref[i]);
  Comparison c;
  for (size_t i = 0; i < ref.size(); ++i) {
    if (i % 4 == 3) continue;
    if (ref[i] <= floor * max_value) {
      ++c.skipped;
      continue;
    }
    c.max_relative_error = std::max(c.max_relative_error, std::abs(gpu[i] - ref[i]) / ref[i]);
    ++c.compared;
  }
  return c;
}

void ExpectFiniteNonNegative(const std::vector<float>& image, const std::string& what) {
  size_t bad = 0;
  for (float v : image)
    if (!std::isfinite(v) || v < 0.0f) ++bad;
  EXPECT_EQ(bad, 0u) << what << ": NaN, Inf or negative values";
}

std::vector<ViewRequest> TestViews() {
  std::vector<ViewRequest> views = {{MAPPING_LATLONG, 64, 32, 0}, {MAPPING_CUBE_STRIP, 16, 96, 0}};
  for (int face = 0; face < 6; ++face) views.push_back({MAPPING_VULKAN_FACE, 16, 16, face});
  return views;
}

TEST(SkyRendererTest, GpuMatchesDoubleReference) {
  const AtmosphereParams atmosphere;  // Earth defaults
  const QualitySettings quality;
  const EffectSettings effects;
  const Rgb scale = {1.0, 1.0, 1.0};
  SkyRenderer renderer(testing::Vulkan(), atmosphere, quality, effects, scale);
  ReferenceModel reference(atmosphere, quality, effects, scale);
  reference.PrecomputeLuts();
  const std::vector<ViewRequest> views = TestViews();
  for (double elevation : {60.0, 10.0, 2.0, -4.0}) {
    glm::dvec3 sun = SunDirectionFromElevationAzimuth(elevation, 135.0);
    std::vector<std::vector<float>> gpu = renderer.Render(sun, views);
    size_t compared = 0, total = 0;
    double worst = 0.0;
    for (size_t v = 0; v < views.size(); ++v) {
      std::string what = "elevation " + std::to_string(elevation) + " view " + std::to_string(v);
      ExpectFiniteNonNegative(gpu[v], what);
      Comparison c = Compare(gpu[v], reference.RenderView(sun, views[v]), 1e-4);
      EXPECT_LE(c.max_relative_error, 1e-3) << what << " (" << c.compared << " values compared)";
      compared += c.compared;
      total += c.compared + c.skipped;
      worst = std::max(worst, c.max_relative_error);
    }
    // The criterion must cover the sky, not only a few texels: at least the
    // upper hemisphere (the unlit ground below a set sun may fall under the floor).
    EXPECT_GE(compared * 5, total * 2) << "elevation " << elevation;
    std::printf("sun elevation %5.1f deg: max relative error %.3g over %zu of %zu values\n", elevation, worst, compared,
                total);
  }
  EXPECT_EQ(renderer.counters().transmittance_lut_builds, 1);
  EXPECT_EQ(renderer.counters().multiscattering_lut_builds, 1);
  testing::ExpectNoValidationMessages();
}

TEST(SkyRendererTest, GrazingRaysMatchReference) {
  // Directions at and around the horizon, where the ray length jumps from
  // the top boundary to the ground: exactly horizontal, +/-1e-6, +/-1e-3 rad.
  const AtmosphereParams atmosphere;
  QualitySettings sky_view;
  sky_view.sky_view_lut = true;
  for (const QualitySettings& quality : {QualitySettings{}, sky_view}) {
    EffectSettings effects;
    effects.sun_disc = false;
    SkyRenderer renderer(testing::Vulkan(), atmosphere, quality, effects, {1, 1, 1});
    ReferenceModel reference(atmosphere, quality, effects, {1, 1, 1});
    reference.PrecomputeLuts();
    std::vector<glm::dvec3> dirs;
    for (double azimuth = 0.0; azimuth < 360.0; azimuth += 30.0) {
      for (double elevation_rad : {0.0, 1e-6, -1e-6, 1e-3, -1e-3, 0.02}) {
        dirs.push_back(SunDirectionFromElevationAzimuth(elevation_rad * 180.0 / M_PI, azimuth));
      }
    }
    for (double sun_elevation : {60.0, 2.0, -4.0}) {
      glm::dvec3 sun = SunDirectionFromElevationAzimuth(sun_elevation, 100.0);
      reference.PrepareSun(sun);
      std::vector<float> gpu = renderer.RenderDirections(sun, dirs);
      ExpectFiniteNonNegative(gpu, "grazing");
      std::vector<double> ref;
      for (const glm::dvec3& d : dirs) {
        glm::dvec3 l = reference.Radiance(glm::dvec3(glm::vec3(d)), sun);  // same float-rounded direction
        ref.insert(ref.end(), {l.x, l.y, l.z, 1.0});
      }
      Comparison c = Compare(gpu, ref, 1e-4);
      EXPECT_LE(c.max_relative_error, 1e-3)
          << "sun elevation " << sun_elevation << " sky-view " << quality.sky_view_lut;
    }
  }
  testing::ExpectNoValidationMessages();
}

TEST(SkyRendererTest, SunDiscMatchesReferenceAndIsLimbDarkened) {
  const AtmosphereParams atmosphere;
  const QualitySettings quality;
  const EffectSettings effects;
  SkyRenderer renderer(testing::Vulkan(), atmosphere, quality, effects, {1, 1, 1});
  ReferenceModel reference(atmosphere, quality, effects, {1, 1, 1});
  reference.PrecomputeLuts();
  glm::dvec3 sun = SunDirectionFromElevationAzimuth(30.0, 200.0);
  // Directions across the disc, at fractions of the angular radius from its
  // centre (rotated about an axis perpendicular to the sun direction).
  glm::dvec3 axis = glm::normalize(glm::cross(sun, glm::dvec3(0, 1, 0)));
  std::vector<double> fractions = {0.0, 0.3, 0.6, 0.9, 0.99};
  std::vector<glm::dvec3> dirs;
  for (double f : fractions) {
    double angle = f * atmosphere.sun_angular_radius_rad;
    dirs.push_back(sun * std::cos(angle) + glm::cross(axis, sun) * std::sin(angle));
  }
  std::vector<float> gpu = renderer.RenderDirections(sun, dirs);
  for (size_t i = 0; i < dirs.size(); ++i) {
    glm::dvec3 ref = reference.Radiance(glm::dvec3(glm::vec3(dirs[i])), sun);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(gpu[4 * i + c] / ref[c], 1.0, 1e-3) << i << " " << c;
    if (i > 0) {
      EXPECT_LT(gpu[4 * i + 1], gpu[4 * (i - 1) + 1]) << "limb darkening at " << fractions[i];
    }
  }
  testing::ExpectNoValidationMessages();
}

TEST(SkyRendererTest, CubeSeamsAreAsSmoothAsFaceInteriors) {
  // Across every face edge, neighbouring texels (found through the Vulkan
  // face-selection table) differ no more than neighbours inside a face.
  const int n = 32;
  EffectSettings effects;
  effects.sun_disc = false;  // the disc is a deliberate discontinuity
  SkyRenderer renderer(testing::Vulkan(), AtmosphereParams{}, QualitySettings{}, effects, {1, 1, 1});
  std::vector<ViewRequest> views;
  for (int face = 0; face < 6; ++face) views.push_back({MAPPING_VULKAN_FACE, n, n, face});
  for (double elevation : {45.0, 3.0}) {
    glm::dvec3 sun = SunDirectionFromElevationAzimuth(elevation, 30.0);
    std::vector<std::vector<float>> faces = renderer.Render(sun, views);
    auto value = [&](int face, int x, int y) {
      const float* p = &faces[face][(size_t(y) * n + x) * 4];
      return glm::dvec3(p[0], p[1], p[2]);
    };
    auto relative = [](glm::dvec3 a, glm::dvec3 b) {
      glm::dvec3 d = glm::abs(a - b) / glm::max(glm::max(a, b), glm::dvec3(1e-30));
      return std::max({d.x, d.y, d.z});
    };
    double interior = 0.0, seam = 0.0;
    int seam_pairs = 0;
    for (int face = 0; face < 6; ++face) {
      for (int y = 0; y < n; ++y) {
        for (int x = 0; x < n; ++x) {
          if (x + 1 < n) interior = std::max(interior, relative(value(face, x, y), value(face, x + 1, y)));
          if (y + 1 < n) interior = std::max(interior, relative(value(face, x, y), value(face, x, y + 1)));
          // Step one texel beyond each edge and find the texel on the neighbour face.
          const int steps[4][2] = {{-1, 0}, {1, 0}, {0, -1}, {0, 1}};
          for (const auto& s : steps) {
            int xs = x + s[0], ys = y + s[1];
            if (xs >= 0 && xs < n && ys >= 0 && ys < n) continue;
            double sc = 2.0 * (xs + 0.5) / n - 1.0, tc = 2.0 * (ys + 0.5) / n - 1.0;
            // Face basis from the table: direction = major + sc * S + tc * T.
            static const double kBasis[6][3][3] = {
                {{1, 0, 0}, {0, 0, -1}, {0, -1, 0}}, {{-1, 0, 0}, {0, 0, 1}, {0, -1, 0}},
                {{0, 1, 0}, {1, 0, 0}, {0, 0, 1}},   {{0, -1, 0}, {1, 0, 0}, {0, 0, -1}},
                {{0, 0, 1}, {1, 0, 0}, {0, -1, 0}},  {{0, 0, -1}, {-1, 0, 0}, {0, -1, 0}}};
            glm::dvec3 major(kBasis[face][0][0], kBasis[face][0][1], kBasis[face][0][2]);
            glm::dvec3 S(kBasis[face][1][0], kBasis[face][1][1], kBasis[face][1][2]);
            glm::dvec3 T(kBasis[face][2][0], kBasis[face][2][1], kBasis[face][2][2]);
            glm::dvec3 d = glm::normalize(major + sc * S + tc * T);
            // The neighbour: the texel of another face whose direction is closest.
            int best_face = -1, bx = 0, by = 0;
            double best = 1e9;
            for (int f = 0; f < 6; ++f) {
              if (f == face) continue;
              for (int yy = 0; yy < n; ++yy)
                for (int xx = 0; xx < n; ++xx) {
                  double dist = glm::length(VulkanCubeTexelDirection(f, xx, yy, n) - d);
                  if (dist < best) {
                    best = dist;
                    best_face = f;
                    bx = xx;
                    by = yy;
                  }
                }
            }
            seam = std::max(seam, relative(value(face, x, y), value(best_face, bx, by)));
            ++seam_pairs;
          }
        }
      }
    }
    EXPECT_EQ(seam_pairs, 6 * 4 * n);
    EXPECT_LE(seam, interior) << "sun elevation " << elevation;
    EXPECT_GT(interior, 0.0);
  }
  testing::ExpectNoValidationMessages();
}

TEST(SkyRendererTest, ValuesAreFiniteForEveryEffectCombination) {
  for (int mask = 0; mask < 8; ++mask) {
    EffectSettings effects;
    effects.multiple_scattering = mask & 1;
    effects.sun_disc = mask & 2;
    effects.ground = mask & 4;
    SkyRenderer renderer(testing::Vulkan(), AtmosphereParams{}, QualitySettings{}, effects, {1, 1, 1});
    for (double elevation : {90.0, 0.0, -18.0}) {
      auto images = renderer.Render(SunDirectionFromElevationAzimuth(elevation, 0.0), TestViews());
      for (const auto& image : images) ExpectFiniteNonNegative(image, "effects " + std::to_string(mask));
    }
  }
  testing::ExpectNoValidationMessages();
}

}  // namespace
}  // namespace skybake

namespace skybake {
namespace {

// The per-frame sky-view LUT path and every integrator, GPU against the
// double reference running the same algorithm.
TEST(SkyRendererTest, IntegratorsAndSkyViewPathMatchReference) {
  const AtmosphereParams atmosphere;
  std::vector<QualitySettings> variants;
  for (int integrator : {INTEGRATOR_ANALYTIC, INTEGRATOR_MIDPOINT, INTEGRATOR_TRAPEZOID, INTEGRATOR_SIMPSON}) {
    QualitySettings q;
    q.integrator = integrator;
    q.view_steps = 24;
    q.light_steps = integrator == INTEGRATOR_ANALYTIC ? 0 : 8;
    variants.push_back(q);
  }
  QualitySettings sky_view;
  sky_view.sky_view_lut = true;
  sky_view.sky_view_width = 96;
  sky_view.sky_view_height = 54;
  variants.push_back(sky_view);
  const ViewRequest view{MAPPING_LATLONG, 32, 16, 0};
  for (const QualitySettings& q : variants) {
    SkyRenderer renderer(testing::Vulkan(), atmosphere, q, EffectSettings{}, {1, 1, 1});
    ReferenceModel reference(atmosphere, q, EffectSettings{}, {1, 1, 1});
    reference.PrecomputeLuts();
    for (double elevation : {30.0, 2.0}) {
      glm::dvec3 sun = SunDirectionFromElevationAzimuth(elevation, 135.0);
      reference.PrepareSun(sun);
      std::vector<float> gpu = renderer.Render(sun, {view})[0];
      ExpectFiniteNonNegative(gpu, "variant");
      Comparison c = Compare(gpu, reference.RenderView(sun, view), 1e-4);
      EXPECT_LE(c.max_relative_error, 1e-3)
          << "integrator " << q.integrator << " sky-view " << q.sky_view_lut << " elevation " << elevation;
    }
  }
  testing::ExpectNoValidationMessages();
}

}  // namespace
}  // namespace skybake

namespace skybake {
namespace {

// The shader variants compiled with the presets' quality fixed (analytic
// integrator, sky-view LUT) against the generic shaders specialized at run
// time to the same settings: the same values to float rounding (seen: under
// 1e-6 relative), for suns high, at the horizon and below it, from the ground
// and from above the atmosphere, with every effect on.
TEST(SkyRendererTest, ShaderVariantsMatchGenericShaders) {
  QualitySettings quality;
  quality.sky_view_lut = true;
  quality.sky_view_width = 96;
  quality.sky_view_height = 54;
  EffectSettings effects;
  effects.night_dimming = true;
  std::vector<ViewRequest> views = TestViews();
  for (double altitude_m : {200.0, 120000.0}) {
    AtmosphereParams atmosphere;
    atmosphere.observer_altitude_m = altitude_m;
    std::vector<std::vector<float>> images[2];
    for (int generic = 0; generic < 2; ++generic) {
      ShaderSwitches shaders;
      shaders.generic = generic;
      SkyRenderer renderer(testing::Vulkan(), atmosphere, quality, effects, {1, 1, 1}, false, AoasInputs(),
                           CloudInputs(), shaders);
      EXPECT_EQ(renderer.counters().variant_pipelines, generic ? 0 : renderer.counters().pipelines);
      for (double elevation : {45.0, 0.3, -3.0, -12.0})
        for (std::vector<float>& image : renderer.Render(SunDirectionFromElevationAzimuth(elevation, 135.0), views))
          images[generic].push_back(std::move(image));
    }
    ASSERT_EQ(images[0].size(), images[1].size());
    for (size_t v = 0; v < images[0].size(); ++v) {
      const std::vector<float>& variant = images[0][v];
      const std::vector<float>& generic = images[1][v];
      ExpectFiniteNonNegative(variant, "variant");
      float max_value = 0.0f;
      for (float x : generic) max_value = std::max(max_value, x);
      double worst = 0.0;
      for (size_t i = 0; i < generic.size(); ++i) {
        if (i % 4 == 3 || generic[i] <= 1e-6f * max_value) continue;
        worst = std::max(worst, double(std::abs(variant[i] - generic[i])) / generic[i]);
      }
      EXPECT_LE(worst, testing::kSkyViewLutStorageStep) << "altitude " << altitude_m << " m, image " << v;
    }
  }
}

// TexelsNearDirection must hold every texel within the angle, wherever the
// direction falls: face centres, edges and corners, the poles and the seam
// of the latlong, and between them; checked against every texel's direction.
TEST(SkyRendererTest, TexelsNearDirectionHoldEveryTexelWithinTheAngle) {
  std::vector<ViewRequest> views = {{MAPPING_LATLONG, 256, 128, 0}, {MAPPING_CUBE_STRIP, 64, 384, 0}};
  for (int face = 0; face < 6; ++face) views.push_back({MAPPING_VULKAN_FACE, 64, 64, face});
  std::vector<glm::dvec3> directions = {{0, 1, 0}, {0, -1, 0}, {0, 0, -1}, {1, 1, 1}, {-1, 1, 0}, {1, 0.001, 0}};
  for (int i = 0; i < 40; ++i) {
    const double z = std::cos(0.7 * i) * 0.999, phi = 2.399963 * i;  // a golden-angle spiral
    directions.push_back({std::sqrt(1 - z * z) * std::cos(phi), z, std::sqrt(1 - z * z) * std::sin(phi)});
  }
  for (double angle : {0.0093, 0.05}) {
    for (glm::dvec3 d : directions) {
      d = glm::normalize(d);
      for (const ViewRequest& v : views) {
        const std::vector<TexelRect> rects = TexelsNearDirection(v, d, angle);
        long long covered = 0, inside = 0;
        for (const TexelRect& r : rects) covered += (long long)(r.x1 - r.x0) * (r.y1 - r.y0);
        for (int y = 0; y < v.height; ++y) {
          for (int x = 0; x < v.width; ++x) {
            const glm::dvec3 t = ViewTexelDirection(v, x, y);
            if (std::atan2(glm::length(glm::cross(t, d)), glm::dot(t, d)) > angle) continue;
            ++inside;
            bool held = false;
            for (const TexelRect& r : rects) held = held || (x >= r.x0 && x < r.x1 && y >= r.y0 && y < r.y1);
            ASSERT_TRUE(held) << "mapping " << v.mapping << " face " << v.face << " texel " << x << "," << y
                              << " direction " << d.x << "," << d.y << "," << d.z << " angle " << angle;
          }
        }
        // Disjoint rectangles, and for a small disc away from the poles (where
        // a latlong row of tiles is all one point) a few 16^2 tiles at most.
        for (size_t a = 0; a < rects.size(); ++a)
          for (size_t b = a + 1; b < rects.size(); ++b)
            EXPECT_TRUE(rects[a].x1 <= rects[b].x0 || rects[b].x1 <= rects[a].x0 || rects[a].y1 <= rects[b].y0 ||
                        rects[b].y1 <= rects[a].y0);
        if (inside > 0 && angle < 0.01 && std::abs(d.y) < 0.9) {
          EXPECT_LE(covered, 12 * 16 * 16) << "mapping " << v.mapping << " face " << v.face;
        }
      }
    }
  }
}

// RowsReachingElevations holds every row with a texel whose elevation lies in
// the range (every texel checked), and for a narrow range near the horizon
// leaves most rows of the views out (the test is not vacuous).
TEST(SkyRendererTest, RowsReachingElevationsHoldEveryRowWithATexelInRange) {
  std::vector<ViewRequest> views = {{MAPPING_LATLONG, 256, 128, 0},
                                    {MAPPING_CUBE_STRIP, 64, 384, 0},
                                    {MAPPING_CUBE_STRIP, 1000, 6000, 0},
                                    {MAPPING_VULKAN_FACE, 7, 7, 4}};
  for (int face = 0; face < 6; ++face) views.push_back({MAPPING_VULKAN_FACE, 300, 300, face});
  const double deg = M_PI / 180.0;
  for (const auto& [low, high] : std::vector<std::pair<double, double>>{
           {-0.1 * deg, 30.0 * deg}, {-3.0 * deg, 50.0 * deg}, {40.0 * deg, 40.01 * deg}, {-90 * deg, -89 * deg}}) {
    long long rows = 0, kept = 0;
    for (const ViewRequest& v : views) {
      const std::vector<RowRange> runs = RowsReachingElevations(v, low, high);
      for (size_t i = 0; i < runs.size(); ++i) {
        EXPECT_LT(runs[i].begin, runs[i].end);
        if (i > 0) {
          EXPECT_LT(runs[i - 1].end, runs[i].begin) << "runs in order, apart";
        }
        kept += runs[i].end - runs[i].begin;
      }
      rows += v.height;
      for (int y = 0; y < v.height; ++y) {
        bool needed = false;
        for (int x = 0; x < v.width && !needed; ++x) {
          const glm::dvec3 d = ViewTexelDirection(v, x, y);
          const double e = std::atan2(d.y, std::hypot(d.x, d.z));
          needed = e >= low && e <= high;
        }
        bool held = false;
        for (const RowRange& r : runs) held = held || (y >= r.begin && y < r.end);
        if (needed) {
          ASSERT_TRUE(held) << "mapping " << v.mapping << " face " << v.face << " row " << y;
        }
      }
    }
    if (high - low < 35.0 * deg) {
      EXPECT_LT(kept, rows / 2) << low / deg << " .. " << high / deg << " deg";
    }
  }
}

// A twilight frame renders with the twilight pipeline only the rows that can
// hold a marched texel (SkyRenderer::TwilightRows) and the others with the
// day pipeline: the same bytes as the twilight pipeline over every row
// (SKYBAKE_TWILIGHT_ROWS=0, ShaderSwitches::twilight_rows off) in every
// view, at Suns from just below the twilight threshold to past the last
// sunlit air, from the ground, from 8 km and from space, with the default
// band and a wide one (whose rows reach into the +Y face). Most texels
// take the day pipeline, and the band's march shows (against band 0) from
// inside the atmosphere, so the test is not vacuous.
TEST(SkyRendererTest, TwilightRowsKeepTheBytesOfTheWholeTwilightPass) {
  std::vector<ViewRequest> views = {{MAPPING_LATLONG, 128, 64, 0}, {MAPPING_CUBE_STRIP, 40, 240, 0}};
  for (int face = 0; face < 6; ++face) views.push_back({MAPPING_VULKAN_FACE, 40, 40, face});
  for (double altitude_m : {0.0, 8000.0, 120000.0}) {
    for (double band : {10.0, 40.0}) {
      AtmosphereParams atmosphere;
      atmosphere.observer_altitude_m = altitude_m;
      QualitySettings quality = QualityPreset("production");
      quality.twilight_march_band_deg = band;
      QualitySettings no_band = quality;
      no_band.twilight_march_band_deg = 0.0;
      auto renderer = [&](const QualitySettings& q, bool rows) {
        ShaderSwitches shaders;
        shaders.twilight_rows = rows;
        return std::make_unique<SkyRenderer>(testing::Vulkan(), atmosphere, q, EffectSettings(), Rgb{1, 1, 1}, false,
                                             AoasInputs(), CloudInputs(), shaders);
      };
      std::unique_ptr<SkyRenderer> split = renderer(quality, true), whole = renderer(quality, false);
      std::unique_ptr<SkyRenderer> lut = renderer(no_band, true);
      bool marched = false;
      for (double elevation : {2.9, -0.5, -4.0, -9.0, -15.0, -20.0}) {
        const glm::dvec3 sun = SunDirectionFromElevationAzimuth(elevation, 100.0);
        const std::vector<std::vector<float>> a = split->Render(sun, views), b = whole->Render(sun, views);
        const std::vector<std::vector<float>> c = lut->Render(sun, views);
        for (size_t v = 0; v < views.size(); ++v) {
          EXPECT_TRUE(a[v] == b[v]) << altitude_m << " m, band " << band << " deg, Sun " << elevation << " deg, view "
                                    << v;
          marched = marched || a[v] != c[v];
        }
      }
      // From space the band lies above the limb, where rays miss the air: nothing to march.
      EXPECT_EQ(marched, altitude_m < 1e5) << altitude_m << " m, band " << band << ": the band's march shows";
      const RenderCounters& on = split->counters();
      const RenderCounters& off = whole->counters();
      EXPECT_EQ(off.twilight_texels, off.sky_texels) << "every texel with the twilight pipeline";
      EXPECT_EQ(on.sky_texels, off.sky_texels);
      EXPECT_GT(on.twilight_texels, 0);
      if (band < 20.0 && altitude_m < 1e5) {
        EXPECT_LT(on.twilight_texels, on.sky_texels * 6 / 10) << altitude_m << " m: most rows by day";
      }
    }
  }
  testing::ExpectNoValidationMessages();
}

// The sun disc added by its own pass over the texels near the Sun equals the
// disc tested by every texel of the sky pass (SKYBAKE_SUN_DISC_PASS=0), with
// the Sun at a cube corner, on a face edge, on the latlong seam, near the
// zenith, on the horizon, in twilight with night dimming, and for an
// observer in space.
TEST(SkyRendererTest, SunDiscPassMatchesDiscInTheSkyPass) {
  QualitySettings quality;  // production: the sky-view LUT
  EffectSettings effects;
  effects.night_dimming = true;
  const std::vector<ViewRequest> views = [] {
    std::vector<ViewRequest> v = {{MAPPING_LATLONG, 512, 256, 0}, {MAPPING_CUBE_STRIP, 128, 768, 0}};
    for (int face = 0; face < 6; ++face) v.push_back({MAPPING_VULKAN_FACE, 128, 128, face});
    return v;
  }();
  const std::vector<glm::dvec3> suns = {glm::normalize(glm::dvec3(1, 1, 1)),        // cube corner
                                        glm::normalize(glm::dvec3(1, 0.2, -1)),     // +X/-Z edge
                                        glm::normalize(glm::dvec3(0, 0.3, -1)),     // latlong seam
                                        glm::normalize(glm::dvec3(0.01, 1, 0.02)),  // near the zenith
                                        SunDirectionFromElevationAzimuth(0.1, 70.0),
                                        SunDirectionFromElevationAzimuth(-0.4, 250.0)};
  for (double altitude_m : {0.0, 150000.0}) {
    AtmosphereParams atmosphere;
    atmosphere.observer_altitude_m = altitude_m;
    ShaderSwitches no_disc_pass;
    no_disc_pass.sun_disc_pass = false;
    SkyRenderer inline_disc(testing::Vulkan(), atmosphere, quality, effects, {1, 1, 1}, false, AoasInputs(),
                            CloudInputs(), no_disc_pass);
    SkyRenderer disc_pass(testing::Vulkan(), atmosphere, quality, effects, {1, 1, 1});
    EXPECT_EQ(disc_pass.counters().pipelines, inline_disc.counters().pipelines + 1);
    for (const glm::dvec3& sun : suns) {
      const auto a = inline_disc.Render(sun, views);
      const int dispatches = disc_pass.counters().sun_disc_dispatches;
      const auto b = disc_pass.Render(sun, views);
      EXPECT_GT(disc_pass.counters().sun_disc_dispatches, dispatches);
      for (size_t v = 0; v < views.size(); ++v) {
        double worst = 0.0;
        for (size_t i = 0; i < a[v].size(); ++i) {
          if (i % 4 == 3) continue;
          worst = std::max(worst, std::abs(double(a[v][i]) - double(b[v][i])) / std::max(double(a[v][i]), 1e-30));
        }
        // The same LUT and the same disc; the sum is rounded in another order.
        EXPECT_LE(worst, 1e-5) << "altitude " << altitude_m << " sun " << sun.x << "," << sun.y << "," << sun.z
                               << " view " << v;
        ExpectFiniteNonNegative(b[v], "disc pass");
      }
    }
  }
  testing::ExpectNoValidationMessages();
}

TEST(SkyRendererTest, RenderInPlaceHoldsTexelsUntilReleased) {
  QualitySettings quality;  // production: the sky-view LUT and the sun-disc pass
  EffectSettings effects;
  SkyRenderer renderer(testing::Vulkan(), AtmosphereParams(), quality, effects, {1, 1, 1});
  const std::vector<ViewRequest> views = {
      {MAPPING_LATLONG, 256, 128, 0}, {MAPPING_CUBE_STRIP, 64, 384, 0}, {MAPPING_VULKAN_FACE, 64, 64, 2}};
  const glm::dvec3 noon = SunDirectionFromElevationAzimuth(60.0, 180.0);
  const glm::dvec3 dusk = SunDirectionFromElevationAzimuth(2.0, 290.0);
  const auto copied_noon = renderer.Render(noon, views);
  const auto copied_dusk = renderer.Render(dusk, views);
  auto same = [&](const RenderedViews& r, const std::vector<std::vector<float>>& copies, const char* what) {
    ASSERT_EQ(r.views.size(), copies.size()) << what;
    for (size_t v = 0; v < copies.size(); ++v)
      EXPECT_EQ(std::memcmp(r.views[v], copies[v].data(), copies[v].size() * sizeof(float)), 0)
          << what << " view " << v;
  };
  EXPECT_FALSE(renderer.HoldsFrames());
  RenderedViews first = renderer.RenderInPlace(noon, views);
  same(first, copied_noon, "noon in place");
  EXPECT_TRUE(renderer.HoldsFrames());
  // The next frames render elsewhere while the first is held, and also
  // Render and RenderDirections (the SH views of a bake) leave it alone.
  RenderedViews second = renderer.RenderInPlace(dusk, views);
  renderer.Render(dusk, {{MAPPING_VULKAN_FACE, 64, 64, 0}}, false);
  renderer.RenderDirections(dusk, {dusk});
  same(first, copied_noon, "noon held while dusk renders");
  same(second, copied_dusk, "dusk in place");
  for (size_t v = 0; v < views.size(); ++v) EXPECT_NE(first.views[v], second.views[v]);
  // Released on another thread (as a bake's writer does): the memory is used again.
  const float* first_memory = first.views[0];
  std::thread([hold = std::move(first.hold)]() mutable { hold.reset(); }).join();
  first.views.clear();
  RenderedViews third = renderer.RenderInPlace(noon, views);
  EXPECT_EQ(third.views[0], first_memory);
  same(third, copied_noon, "noon again in the released memory");
  same(second, copied_dusk, "dusk still held");
  second = RenderedViews();
  third = RenderedViews();
  EXPECT_FALSE(renderer.HoldsFrames());
  testing::ExpectNoValidationMessages();
}

}  // namespace
}  // namespace skybake
