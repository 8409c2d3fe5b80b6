// The pass planner: plans contain exactly the expected passes, LUTs are built
// once per atmosphere, and pruning never changes the image (an effect at
// zero strength compiled in equals the effect compiled out).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include <gtest/gtest.h>

#include "skybake/gpu/cloud_panorama.h"
#include <glm/glm.hpp>

#include "skybake/model/aoas.h"
#include "skybake/model/clouds.h"
#include "skybake/pipeline/engine_files.h"
#include "skybake/pipeline/pass_plan.h"
#include "skybake/pipeline/pipeline.h"
#include "skybake/gpu/sky_renderer.h"
#include "test_support.h"

namespace skybake {
namespace {

SkyStyle Style(const std::string& toml, const std::vector<std::string>& overrides = {}) {
  ConfigResult r = ParseSkyStyle(toml, "plan_test.toml", overrides);
  EXPECT_TRUE(r.ok()) << (r.errors.empty() ? "" : r.errors[0].Format());
  return r.style;
}

std::vector<std::string> PassNames(const PassPlan& plan) {
  std::vector<std::string> names;
  for (const PlannedPass& p : plan.passes) names.push_back(p.name);
  return names;
}

const EffectDecision& Effect(const PassPlan& plan, const std::string& name) {
  for (const EffectDecision& e : plan.effects)
    if (e.name == name) return e;
  static EffectDecision missing{"missing", false, false, ""};
  return missing;
}

const std::vector<std::string> kRenderPasses = {"render face 0",     "render face 1", "render face 2",
                                                "render face 3",     "render face 4", "render face 5",
                                                "render cube strip", "render latlong"};

std::vector<std::string> With(std::vector<std::string> head, const std::vector<std::string>& tail) {
  head.insert(head.end(), tail.begin(), tail.end());
  return head;
}

TEST(PassPlanTest, DefaultStyleRunsEveryPhysicalPass) {
  PassPlan plan = PlanPasses({Style("[atmosphere]\nground_albedo = 0.1\n")});
  EXPECT_EQ(PassNames(plan),
            With(With({"transmittance LUT", "multiple-scattering LUT", "sky-view LUT"}, kRenderPasses), {"sun disc"}));
  for (const char* e : {"multiple scattering", "Mie (aerosols)", "ozone", "ground bounce", "sun disc"})
    EXPECT_TRUE(Effect(plan, e).on) << e;
  for (const char* e :
       {"skydome (AOAS 3.2)", "hue override", "ambiguity (eq. 5-6)", "cloud noise (eq. 7-8)", "cloud shapes"})
    EXPECT_FALSE(Effect(plan, e).on) << e;
  EXPECT_NE(plan.variant.find("multiple_scattering=true"), std::string::npos) << plan.variant;
  EXPECT_NE(plan.variant.find("sky_render from the built-in sky-view variant"), std::string::npos) << plan.variant;
  EXPECT_NE(plan.variant.find("LUT shaders from the built-in analytic variants"), std::string::npos) << plan.variant;
  EXPECT_NE(plan.variant.find("sun disc: compiled out of sky_render"), std::string::npos) << plan.variant;
}

// An engine preset's images are rendered once more along the engine's
// directions (engine_files.h): the plan lists each, the estimate counts
// their samples and memory, and the budget check sees them.
TEST(PassPlanTest, EngineImagesAreInThePlanTheEstimateAndTheBudget) {
  const std::string outputs = "[render]\ncube_size = 256\nlatlong_height = 512\n";
  const SkyStyle plain = Style(outputs);
  const SkyStyle unity = Style(outputs + "[output]\nengine = 'unity'\n");
  const SkyStyle godot = Style(outputs + "[output]\nengine = 'godot'\n");
  EXPECT_TRUE(PlanEngineImages(plain).empty());
  const std::vector<EngineImageSize> faces = PlanEngineImages(unity);
  ASSERT_EQ(faces.size(), 6u);
  for (const EngineImageSize& e : faces) EXPECT_EQ(e.width * e.height, 256 * 256) << e.suffix;
  const std::vector<EngineImageSize> panorama = PlanEngineImages(godot);
  ASSERT_EQ(panorama.size(), 1u);
  EXPECT_EQ(panorama[0].width, 1024);
  EXPECT_EQ(panorama[0].height, 512);

  const PassPlan with = PlanPasses({unity}), without = PlanPasses({plain});
  const std::vector<std::string> names = PassNames(with);
  for (const EngineImageSize& e : faces)
    EXPECT_NE(std::find(names.begin(), names.end(), "render engine " + e.suffix), names.end()) << e.suffix;
  // Six faces more, each texel one sky-view LUT read (the default style).
  EXPECT_DOUBLE_EQ(with.total_samples - without.total_samples, 6.0 * 256 * 256);
  EXPECT_DOUBLE_EQ(EstimateResources(unity).samples - EstimateResources(plain).samples, 6.0 * 256 * 256);
  // Memory: directions (24 bytes) and RGBA float pixels (16) a texel.
  const double extra = EstimateResources(unity).memory_mib - EstimateResources(plain).memory_mib;
  EXPECT_NEAR(extra, 40.0 * 6 * 256 * 256 / (1024.0 * 1024.0), 1e-9);
  std::printf("engine unity at 256: +%.1f MiB estimated\n", extra);

  BakeOptions options;
  options.max_memory_mib = 0.5 * (EstimateResources(unity).memory_mib + EstimateResources(plain).memory_mib);
  EXPECT_NO_THROW(CheckBudget(plain, options));
  EXPECT_THROW(CheckBudget(unity, options), BudgetError) << "the preset's images are over the budget";

  const testing::CommandRun run =
      testing::RunSkybake("plan " + testing::SourceDir() + "/configs/default.toml --set output.engine=godot");
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("render engine " + panorama[0].suffix), std::string::npos) << run.output;
}

// A glTF-only bake (no latlong EXR, no preview) still renders the latlong:
// the scene's texture is its tone-mapped PNG. The plan, its estimate and the
// renderer read the same view list, so the plan shows the pass and the
// estimate counts its texels, as for a bake that also writes the latlong EXR.
TEST(PassPlanTest, GltfOnlyBakePlansTheLatlongItsTextureNeeds) {
  const std::string outputs = "[output]\nfaces = true\ncube_strip = false\npreview = false\n";
  const SkyStyle gltf_only = Style(outputs + "latlong = false\n[gltf]\nenabled = true\n");
  const SkyStyle with_exr = Style(outputs + "latlong = true\n[gltf]\nenabled = true\n");
  const SkyStyle neither = Style(outputs + "latlong = false\n[gltf]\nenabled = false\n");
  const std::vector<std::string> names = PassNames(PlanPasses({gltf_only}));
  EXPECT_NE(std::find(names.begin(), names.end(), "render latlong"), names.end());
  const std::vector<std::string> none = PassNames(PlanPasses({neither}));
  EXPECT_EQ(std::find(none.begin(), none.end(), "render latlong"), none.end());

  const std::vector<ViewRequest> views = PlanViews(gltf_only);
  ASSERT_EQ(views.size(), 7u);
  EXPECT_EQ(views.back().mapping, int(MAPPING_LATLONG));
  EXPECT_EQ(views.back().width, 2 * gltf_only.render.latlong_height);
  EXPECT_EQ(views.back().height, gltf_only.render.latlong_height);
  EXPECT_TRUE(WritesLatlongPng(gltf_only));
  EXPECT_FALSE(RendersLatlong(neither));

  // The estimate: the latlong's samples, as many as with the EXR asked for.
  EXPECT_EQ(PlanPasses({gltf_only}).total_samples, PlanPasses({with_exr}).total_samples);
  EXPECT_EQ(EstimateResources(gltf_only).samples, EstimateResources(with_exr).samples);
  EXPECT_GT(EstimateResources(gltf_only).samples, EstimateResources(neither).samples);
  EXPECT_GT(EstimateResources(gltf_only).memory_mib, EstimateResources(neither).memory_mib);

  // skybake plan, as a user runs it.
  const testing::CommandRun run = testing::RunSkybake(
      "plan " + testing::SourceDir() +
      "/configs/default.toml --set output.latlong=false --set output.preview=false --set gltf.enabled=true");
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("render latlong"), std::string::npos) << run.output;
}

// The environment's shader switches are read once, by the CLI, and reach the
// planner as they reach the renderer: the plan of the default style names the
// generic shaders with SKYBAKE_GENERIC_SHADERS=1 and has no sun-disc pass with
// SKYBAKE_SUN_DISC_PASS=0; the library itself reads no environment.
TEST(PassPlanTest, EnvironmentSwitchesReachThePlanThroughTheCli) {
  const std::string style = testing::SourceDir() + "/configs/default.toml";
  const testing::CommandRun plain = testing::RunSkybake("plan " + style);
  ASSERT_EQ(plain.exit_code, 0) << plain.output;
  EXPECT_NE(plain.output.find("sky_render from the built-in sky-view variant"), std::string::npos) << plain.output;
  EXPECT_NE(plain.output.find("near the Sun"), std::string::npos) << plain.output;
  const testing::CommandRun generic = testing::RunSkybake("plan " + style, "SKYBAKE_GENERIC_SHADERS=1");
  ASSERT_EQ(generic.exit_code, 0) << generic.output;
  EXPECT_NE(generic.output.find("sky_render generic, specialized at pipeline creation"), std::string::npos)
      << generic.output;
  const testing::CommandRun no_pass = testing::RunSkybake("plan " + style, "SKYBAKE_SUN_DISC_PASS=0");
  ASSERT_EQ(no_pass.exit_code, 0) << no_pass.output;
  EXPECT_EQ(no_pass.output.find("near the Sun"), std::string::npos) << no_pass.output;

  ShaderSwitches generic_switches;
  generic_switches.generic = true;
  const SkyStyle s = Style("");
  EXPECT_NE(PlanPasses({s}, generic_switches).variant.find("sky_render generic"), std::string::npos);
  EXPECT_NE(PlanPasses({s}).variant.find("sky_render from the built-in sky-view variant"), std::string::npos);
}

// The disc has a pass of its own only where nothing acts on it after it is
// added: clouds scale the saturation of the sky with the disc in it, and the
// ambiguity moves the direction it is seen along.
TEST(PassPlanTest, SunDiscPassOnlyWhereNothingActsOnTheDisc) {
  for (const char* toml : {"[clouds]\nenabled = true\n", "[ambiguity]\nenabled = true\n"}) {
    PassPlan plan = PlanPasses({Style(toml)});
    EXPECT_EQ(PassNames(plan), With({"transmittance LUT", "multiple-scattering LUT", "sky-view LUT"}, kRenderPasses))
        << toml;
    EXPECT_EQ(plan.variant.find("sun disc: compiled out"), std::string::npos) << toml;
  }
}

// The reference preset (Simpson, ray march per texel) is outside the built-in
// variants: the plan says the generic shaders are used.
TEST(PassPlanTest, ReferencePresetUsesTheGenericShaders) {
  PassPlan plan = PlanPasses({Style("[quality]\npreset = \"reference\"\n")});
  EXPECT_NE(plan.variant.find("sky_render generic"), std::string::npos) << plan.variant;
  EXPECT_NE(plan.variant.find("LUT shaders generic"), std::string::npos) << plan.variant;
}

TEST(PassPlanTest, UnreadLutsAreNotComputed) {
  // No multiple scattering: no multiple-scattering LUT.
  PassPlan no_ms = PlanPasses({Style("[effects]\nmultiple_scattering = false\n")});
  EXPECT_EQ(PassNames(no_ms), With(With({"transmittance LUT", "sky-view LUT"}, kRenderPasses), {"sun disc"}));
  // Ray-marching every texel: no sky-view LUT.
  PassPlan march = PlanPasses({Style("[quality]\nsky_view_lut = false\n")});
  EXPECT_EQ(PassNames(march), With({"transmittance LUT", "multiple-scattering LUT"}, kRenderPasses));
  // Sun transmittance marched and nothing else reading the transmittance LUT.
  PassPlan marched =
      PlanPasses({Style("[quality]\nsky_view_lut = false\nlight_steps = 8\n[effects]\nmultiple_scattering = false\n"
                        "sun_disc = false\nground = false\n")});
  EXPECT_EQ(PassNames(marched), kRenderPasses);
  // The skydome moves the observer: its texels ray-march, no sky-view LUT.
  PassPlan dome = PlanPasses({Style("[skydome]\nenabled = true\nviewer_position = [0.0, 0.3, 0.0]\n")});
  EXPECT_EQ(PassNames(dome), With({"transmittance LUT", "multiple-scattering LUT"}, kRenderPasses));
  // Only a latlong requested: one render pass.
  PassPlan latlong = PlanPasses({Style("[output]\nfaces = false\ncube_strip = false\n")});
  EXPECT_EQ(PassNames(latlong),
            With({"transmittance LUT", "multiple-scattering LUT", "sky-view LUT"}, {"render latlong", "sun disc"}));
}

TEST(PassPlanTest, ZeroStrengthEffectsArePrunedWithTheirReason) {
  PassPlan plan = PlanPasses(
      {Style("[atmosphere]\nground_albedo = 0.0\n[atmosphere.mie]\nscattering_per_km = 0.0\nextinction_per_km = 0.0\n"
             "[atmosphere.ozone]\nabsorption_per_km = 0.0\n[effects]\nmultiple_scattering_strength = 0.0\n"
             "sun_disc_strength = 0.0\n[clouds]\nenabled = true\nstrength = 0.0\n")});
  for (const char* e :
       {"multiple scattering", "Mie (aerosols)", "ozone", "ground bounce", "sun disc", "cloud noise (eq. 7-8)"}) {
    EXPECT_TRUE(Effect(plan, e).requested) << e;
    EXPECT_FALSE(Effect(plan, e).on) << e;
  }
  EXPECT_EQ(Effect(plan, "ozone").reason, "atmosphere.ozone.absorption_per_km is 0");
  EXPECT_EQ(PassNames(plan), With({"transmittance LUT", "sky-view LUT"}, kRenderPasses));
  EXPECT_NE(plan.variant.find("mie=false ozone=false"), std::string::npos) << plan.variant;
}

TEST(NightDimmingTest, NightSkyIsTheFloorAndDayIsUntouched) {
  // Sun at -25 deg, full strength: the sky above the horizon is the neutral
  // night floor of 1.7e-4 cd/m^2 (luminance output), the ground black; by day
  // the effect changes nothing.
  SkyStyle night = Style("[effects]\nnight_dimming = true\n");
  SkyStyle plain = Style("");
  auto render = [](const SkyStyle& s, double elevation) {
    SkyRenderer r(testing::Vulkan(), s.atmosphere, s.quality, s.effects, OutputScale(s.output.units), false,
                  ToAoasInputs(s.aoas, OutputScale(OutputUnits::kLuminance)));
    return r.Render(SunDirectionFromElevationAzimuth(elevation, 90.0), {{MAPPING_LATLONG, 32, 16, 0}})[0];
  };
  std::vector<float> dark = render(night, -25.0);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 32; ++x) {
      const float* p = &dark[(size_t(y) * 32 + x) * 4];
      for (int c = 0; c < 3; ++c) {
        if (y < 7) {
          EXPECT_NEAR(p[c], 1.7e-4, 1e-9) << x << " " << y;  // rows above the horizon
        } else if (y > 8) {
          EXPECT_EQ(p[c], 0.0f) << x << " " << y;  // rows below it
        }
      }
    }
  std::vector<float> day_a = render(night, 20.0), day_b = render(plain, 20.0);
  for (size_t i = 0; i < day_a.size(); ++i) EXPECT_EQ(day_a[i], day_b[i]);
  testing::ExpectNoValidationMessages();
}

TEST(PassPlanTest, LutsAreBuiltOncePerAtmosphereOfASchedule) {
  std::vector<SkyStyle> same, changing;
  for (int i = 0; i < 12; ++i) {
    same.push_back(Style("", {"sun.elevation_deg=" + std::to_string(5 * i)}));
    changing.push_back(Style("", {"atmosphere.mie.g=" + std::to_string(0.5 + 0.01 * i)}));
  }
  PassPlan a = PlanPasses(same);
  EXPECT_EQ(a.atmospheres, 1);
  EXPECT_EQ(a.passes[0].runs, 1);   // transmittance LUT
  EXPECT_EQ(a.passes[2].runs, 12);  // sky-view LUT, per frame
  EXPECT_FALSE(a.reused.empty());
  EXPECT_EQ(PlanPasses(changing).atmospheres, 12);
}

// Pruning never changes the output: for every effect, the effect compiled in
// at zero strength renders what the pruned style (effect compiled out)
// renders, to float rounding.
struct Equivalence {
  std::string effect;
  std::string zero_strength_toml;
};

// The cloud panorama (gpu/cloud_panorama.h) is listed with its size, the
// rows it marches and their medium samples, and the views read from it with
// none; with quality.cloud_panorama_scale = 0 every view marches its own
// texels; without a cloud layer (or with it pruned) there is no cloud pass.
// Views: six 64^2 faces, the 64 x 384 strip, a 256 x 128 latlong, so the
// panorama is 256 x 128 and, from the ground, marches rows 0 to 64 (row 65's
// cosine, -0.037, is past the 0.02 margin below the horizon).
TEST(PassPlanTest, CloudPanoramaIsListedWithItsRowsAndCost) {
  const std::string layer =
      "[render]\ncube_size = 64\nlatlong_height = 128\n"
      "[[cloud_layer]]\naltitude_m = 1500\nthickness_m = 1500\ncoverage = COVERAGE\n";
  auto style = [&](const std::string& coverage, const std::string& more = "") {
    std::string t = layer;
    t.replace(t.find("COVERAGE"), 8, coverage);
    return Style(t + more);
  };
  auto pass = [](const PassPlan& p, const std::string& name) -> const PlannedPass* {
    for (const PlannedPass& x : p.passes)
      if (x.name == name) return &x;
    return nullptr;
  };
  const SkyStyle on = style("0.45");
  const CloudQuality& cq = on.clouds.quality;
  const PassPlan plan = PlanPasses({on, on});
  const PlannedPass* panorama = pass(plan, "clouds panorama");
  ASSERT_NE(panorama, nullptr) << FormatPlan(plan, "on");
  // Each row marches width x cos(latitude) + 1 texels (CloudPanoramaRowWidth):
  // over the sky half about 2 / pi of the whole rows.
  const size_t texels = CloudPanoramaMarchedTexels({256, 128}, {0, 65});
  EXPECT_GT(texels, 0.6 * 256 * 65);
  EXPECT_LT(texels, 0.75 * 256 * 65);
  EXPECT_EQ(panorama->size, "256 x 128, rows 0 to 64 marched, " + std::to_string(texels) + " texels");
  EXPECT_EQ(panorama->runs, 2);
  EXPECT_EQ(panorama->samples, double(texels) * cq.view_steps * (1.0 + cq.light_steps));
  const PlannedPass* latlong = pass(plan, "clouds latlong (resampled)");
  ASSERT_NE(latlong, nullptr);
  EXPECT_EQ(latlong->samples, 0.0);
  EXPECT_NE(pass(plan, "clouds face 5 (resampled)"), nullptr);
  EXPECT_EQ(pass(plan, "clouds latlong"), nullptr);
  EXPECT_NE(FormatPlan(plan, "on").find("clouds panorama"), std::string::npos);
  // The light volume, once per frame (clouds.h, CloudLightVolume).
  const PlannedPass* volume = pass(plan, "cloud light volume");
  ASSERT_NE(volume, nullptr) << FormatPlan(plan, "on");
  EXPECT_EQ(volume->samples, double(cq.light_volume_columns) * cq.light_volume_columns * (cq.light_volume_slices - 1) *
                                 kCloudLightVolumeSubsteps);
  EXPECT_EQ(pass(PlanPasses({style("0.45", "[quality]\ncloud_light_volume_columns = 0\n")}), "cloud light volume"),
            nullptr);
  // Two bands: the renderer keeps the exact march (CloudLightVolumeOn), and
  // the plan lists no volume.
  const SkyStyle two_bands = style("0.45", "[[cloud_layer]]\naltitude_m = 6000\nthickness_m = 300\n");
  EXPECT_FALSE(CloudLightVolumeOn(CloudGeometryUniform(two_bands.clouds)));
  EXPECT_TRUE(CloudLightVolumeOn(CloudGeometryUniform(on.clouds)));
  EXPECT_EQ(pass(PlanPasses({two_bands}), "cloud light volume"), nullptr) << FormatPlan(PlanPasses({two_bands}), "two");
  // 2 km up, inside the layer: every row.
  EXPECT_EQ(pass(PlanPasses({style("0.45", "[atmosphere]\nobserver_altitude_m = 2000\n")}), "clouds panorama")->size,
            "256 x 128, rows 0 to 127 marched, " + std::to_string(CloudPanoramaMarchedTexels({256, 128}, {0, 128})) +
                " texels");
  // Off: each view marches its own texels.
  const PassPlan marched = PlanPasses({style("0.45", "[quality]\ncloud_panorama_scale = 0.0\n")});
  EXPECT_EQ(pass(marched, "clouds panorama"), nullptr);
  ASSERT_NE(pass(marched, "clouds latlong"), nullptr);
  EXPECT_EQ(pass(marched, "clouds latlong")->samples, 256.0 * 128.0 * cq.view_steps * (1.0 + cq.light_steps));
  EXPECT_GT(marched.total_samples, PlanPasses({on}).total_samples);
  // Pruned (coverage 0) or no layer: no cloud pass at all.
  for (const SkyStyle& none : {style("0.0"), Style("[render]\ncube_size = 64\nlatlong_height = 128\n")}) {
    const PassPlan p = PlanPasses({none});
    EXPECT_EQ(pass(p, "clouds panorama"), nullptr);
    EXPECT_EQ(pass(p, "clouds latlong"), nullptr);
    EXPECT_EQ(pass(p, "clouds latlong (resampled)"), nullptr);
  }
}

// The frames whose every cloud band is in the Earth's shadow (the Sun below
// CloudEarthShadowElevationDeg: -3.80 deg for a 3 km top from the ground)
// are listed in the effect "clouds in the Earth's shadow" with the bound, and
// the panorama pass again for them without the light march's samples; off
// with SKYBAKE_SHADOWED_CLOUDS=0 (ShaderSwitches::shadowed_clouds) or when no
// frame is that dark. `skybake plan` prints the same.
TEST(PassPlanTest, CloudFramesInTheEarthsShadowAreListed) {
  const std::string layer =
      "[render]\ncube_size = 64\nlatlong_height = 128\n"
      "[[cloud_layer]]\naltitude_m = 1500\nthickness_m = 1500\ncoverage = 0.45\n";
  auto at = [&](double elevation_deg) { return Style(layer, {"sun.elevation_deg=" + std::to_string(elevation_deg)}); };
  auto pass = [](const PassPlan& p, const std::string& name) -> const PlannedPass* {
    for (const PlannedPass& x : p.passes)
      if (x.name == name) return &x;
    return nullptr;
  };
  const std::vector<SkyStyle> frames = {at(10.0), at(-3.7), at(-3.9), at(-12.0), at(-3.75)};
  const PassPlan plan = PlanPasses(frames);
  const EffectDecision& effect = Effect(plan, "clouds in the Earth's shadow");
  EXPECT_TRUE(effect.on) << FormatPlan(plan, "frames");
  EXPECT_NE(effect.reason.find("2 of 5 frames (plan order 2-3) with the Sun below -3.80 deg"), std::string::npos)
      << effect.reason;
  const PlannedPass* lit = pass(plan, "clouds panorama");
  const PlannedPass* dark = pass(plan, "clouds panorama in the Earth's shadow");
  ASSERT_NE(lit, nullptr);
  ASSERT_NE(dark, nullptr) << FormatPlan(plan, "frames");
  EXPECT_EQ(lit->runs, 3);
  EXPECT_EQ(dark->runs, 2);
  const CloudQuality& cq = frames[0].clouds.quality;
  EXPECT_EQ(dark->samples * (1.0 + cq.light_steps), lit->samples);
  EXPECT_EQ(dark->size, lit->size);
  EXPECT_NE(FormatPlan(plan, "frames").find("clouds panorama in the Earth's shadow"), std::string::npos);
  // Switched off: every frame marches the Sun's light.
  ShaderSwitches off;
  off.shadowed_clouds = false;
  const PassPlan full = PlanPasses(frames, off);
  EXPECT_FALSE(Effect(full, "clouds in the Earth's shadow").on);
  EXPECT_EQ(pass(full, "clouds panorama in the Earth's shadow"), nullptr);
  EXPECT_EQ(pass(full, "clouds panorama")->runs, 5);
  EXPECT_GT(full.total_samples, plan.total_samples);
  // No frame below the bound.
  const PassPlan day = PlanPasses({at(10.0), at(-3.7)});
  EXPECT_FALSE(Effect(day, "clouds in the Earth's shadow").on);
  EXPECT_NE(Effect(day, "clouds in the Earth's shadow").reason.find("no frame with the Sun below -3.80 deg"),
            std::string::npos);
  EXPECT_EQ(pass(day, "clouds panorama in the Earth's shadow"), nullptr);
}

// The twilight band's march (PlanTwilightBand) in a twilight frame: from
// the ground it covers 0..10 deg, a fraction sin(10 deg) / 2 of the
// directions; from 8 km the band reaches from the horizon, acos(R / r) =
// 2.87 deg below the horizontal, to 10 deg above it (InTwilightMarchBand),
// so the band's fraction grows by sin(2.87 deg) / 2; both add the
// kTwilightAboveBandShare of the directions marched above the band.
TEST(PassPlanTest, TwilightBandEstimateReachesTheHorizonFromAltitude) {
  auto band = [](const PassPlan& p) -> const PlannedPass* {
    for (const PlannedPass& x : p.passes)
      if (x.name == "twilight band march") return &x;
    return nullptr;
  };
  const PassPlan ground = PlanPasses({Style("[sun]\nelevation_deg = -3.0\n")});
  const PassPlan high =
      PlanPasses({Style("[sun]\nelevation_deg = -3.0\n[atmosphere]\nobserver_altitude_m = 8000.0\n")});
  const PassPlan day = PlanPasses({Style("[sun]\nelevation_deg = 20.0\n")});
  ASSERT_NE(band(ground), nullptr) << FormatPlan(ground, "frames");
  ASSERT_NE(band(high), nullptr) << FormatPlan(high, "frames");
  EXPECT_EQ(band(day), nullptr) << FormatPlan(day, "frames");
  EXPECT_EQ(band(ground)->size, "0..10 deg above the horizon");
  EXPECT_EQ(band(high)->size, "the horizon (2.87 deg below the horizontal) to 10 deg above the horizontal");
  const double dip = std::acos(6360.0 / 6368.0);
  const double ground_fraction = 0.5 * std::sin(10.0 * M_PI / 180.0) + kTwilightAboveBandShare;
  EXPECT_NEAR(band(high)->samples / band(ground)->samples, 1.0 + 0.5 * std::sin(dip) / ground_fraction, 1e-9);
}

// The cloud formation's CPU step and the cloud shadow map's pass are listed
// with their cost: the formation simulates from step 0 to the last planned
// frame's step (warm-up 5 + 10 per hour x 1.25 h = 17.5: 18 steps) of
// 16 x 16 x 4 = 1024 cells, outside the medium-sample total; the map's pass
// reads the density 64^2 x 8 steps x the merged bands per frame. Off, or
// with every layer pruned, neither is planned.
TEST(PassPlanTest, CloudFormationAndShadowMapAreListedWithTheirCost) {
  const std::string layer = R"(
[[cloud_layer]]
altitude_m = 1000
thickness_m = 500
coverage = COVERAGE
[cloud_layer.formation]
enabled = FORMATION
cells = [16, 16, 4]
steps_per_hour = 10.0
warmup_steps = 5
)";
  auto style = [&](const std::string& coverage, bool formation, bool shadow, const std::string& more = "") {
    std::string t = layer;
    t.replace(t.find("COVERAGE"), 8, coverage);
    t.replace(t.find("FORMATION"), 9, formation ? "true" : "false");
    if (shadow) t += "\n[cloud_shadow]\nenabled = true\nresolution = 64\nsteps = 8\n";
    return Style(t + more);
  };
  const std::vector<double> hours = {0.0, 0.5, 1.25};
  const SkyStyle on = style("0.5", true, true);
  const PassPlan plan = PlanPasses({on, on, on}, ShaderSwitches(), hours);
  auto pass = [](const PassPlan& p, const std::string& name) -> const PlannedPass* {
    for (const PlannedPass& x : p.passes)
      if (x.name == name) return &x;
    return nullptr;
  };
  const PlannedPass* formation = pass(plan, "cloud formation (CPU) at 1000 m");
  ASSERT_NE(formation, nullptr) << FormatPlan(plan, "on");
  EXPECT_EQ(formation->runs, 18);
  EXPECT_EQ(formation->samples, 1024.0);
  const PlannedPass* map = pass(plan, "cloud shadow map");
  ASSERT_NE(map, nullptr);
  EXPECT_EQ(map->runs, 3);
  EXPECT_EQ(map->samples, 64.0 * 64.0 * 8.0);
  EXPECT_TRUE(Effect(plan, "cloud formation").on);
  EXPECT_TRUE(Effect(plan, "cloud shadow map").on);
  EXPECT_TRUE(Effect(plan, "ground cloud shadow").on);
  EXPECT_NE(FormatPlan(plan, "on").find("cloud formation (CPU) at 1000 m"), std::string::npos);
  // The map's samples are in the total, the formation's cell updates are not.
  const PassPlan no_shadow = PlanPasses({style("0.5", true, false)}, ShaderSwitches(), {1.25});
  const PassPlan no_formation = PlanPasses({style("0.5", false, false)}, ShaderSwitches(), {1.25});
  EXPECT_EQ(PlanPasses({on}, ShaderSwitches(), {1.25}).total_samples, no_shadow.total_samples + 64.0 * 64.0 * 8.0);
  EXPECT_EQ(no_shadow.total_samples, no_formation.total_samples);
  // Without a clock (a single style): the warm-up alone.
  EXPECT_EQ(pass(PlanPasses({on}), "cloud formation (CPU) at 1000 m")->runs, 5);
  // A second, separate layer is a second band of the map's march.
  const SkyStyle two = style("0.5", true, true, "[[cloud_layer]]\naltitude_m = 6000\nthickness_m = 300\n");
  EXPECT_EQ(pass(PlanPasses({two}), "cloud shadow map")->samples, 64.0 * 64.0 * 8.0 * 2.0);

  // Pruned: coverage 0 removes the layer, its formation and the map's pass.
  const PassPlan pruned = PlanPasses({style("0.0", true, true)});
  EXPECT_EQ(pass(pruned, "cloud formation (CPU) at 1000 m"), nullptr);
  EXPECT_EQ(pass(pruned, "cloud shadow map"), nullptr);
  EXPECT_TRUE(Effect(pruned, "cloud formation").requested);
  EXPECT_FALSE(Effect(pruned, "cloud formation").on);
  EXPECT_FALSE(Effect(pruned, "cloud shadow map").on);
  EXPECT_NE(Effect(pruned, "cloud shadow map").reason.find("all ones"), std::string::npos);
  // Off: neither, and the effects say so.
  const PassPlan off = PlanPasses({style("0.5", false, false)});
  EXPECT_EQ(pass(off, "cloud shadow map"), nullptr);
  EXPECT_FALSE(Effect(off, "cloud formation").requested);
  EXPECT_EQ(Effect(off, "cloud shadow map").reason, "switched off in the style");
  // A ground shadow needs a ground the sky shows.
  const PassPlan no_ground = PlanPasses({style("0.5", true, true, "[atmosphere]\nground_albedo = 0.0\n")});
  EXPECT_FALSE(Effect(no_ground, "ground cloud shadow").on);
  EXPECT_TRUE(Effect(no_ground, "cloud shadow map").on);
}

class PruningEquivalenceTest : public ::testing::TestWithParam<Equivalence> {};

TEST_P(PruningEquivalenceTest, ZeroStrengthEqualsCompiledOut) {
  const Equivalence& eq = GetParam();
  const bool sets_atmosphere = eq.zero_strength_toml.find("[atmosphere]") != std::string::npos;
  SkyStyle zero = Style(eq.zero_strength_toml + (sets_atmosphere ? "" : "\n[atmosphere]\nground_albedo = 0.1\n"));
  SkyStyle pruned = PrunedStyle(zero);
  const Rgb scale = OutputScale(zero.output.units);
  auto make = [&](const SkyStyle& s) {
    return std::make_unique<SkyRenderer>(testing::Vulkan(), StyledAtmosphere(s.atmosphere, s.aoas), s.quality,
                                         s.effects, scale, false,
                                         ToAoasInputs(s.aoas, OutputScale(OutputUnits::kLuminance)));
  };
  auto compiled_in = make(zero);
  auto compiled_out = make(pruned);
  const std::vector<ViewRequest> views = {{MAPPING_LATLONG, 64, 32, 0}, {MAPPING_VULKAN_FACE, 16, 16, 2}};
  for (double elevation : {35.0, 3.0, -12.0}) {
    glm::dvec3 sun = SunDirectionFromElevationAzimuth(elevation, 160.0);
    auto a = compiled_in->Render(sun, views);
    auto b = compiled_out->Render(sun, views);
    double worst = 0.0, max_value = 0.0;
    for (size_t v = 0; v < views.size(); ++v)
      for (size_t i = 0; i < a[v].size(); ++i) max_value = std::max(max_value, double(b[v][i]));
    for (size_t v = 0; v < views.size(); ++v)
      for (size_t i = 0; i < a[v].size(); ++i) {
        if (i % 4 == 3) continue;
        double diff = std::abs(double(a[v][i]) - double(b[v][i]));
        worst = std::max(worst, diff / std::max(double(b[v][i]), 1e-6 * max_value));
      }
    // Float rounding, a handful of ulps of float32, which the sky-view LUT
    // may turn into one step of its stored precision.
    EXPECT_LE(worst, testing::kSkyViewLutStorageStep) << eq.effect << " at sun " << elevation;
    std::printf("%-22s sun %4.1f: pruned vs zero strength max relative difference %.2e\n", eq.effect.c_str(), elevation,
                worst);
  }
  const EffectSettings& z = zero.effects;
  const EffectSettings& p = pruned.effects;
  const bool differs = z.multiple_scattering != p.multiple_scattering || z.mie != p.mie || z.ozone != p.ozone ||
                       z.ground != p.ground || z.sun_disc != p.sun_disc || z.night_dimming != p.night_dimming ||
                       zero.aoas.clouds.enabled != pruned.aoas.clouds.enabled ||
                       zero.aoas.shapes.enabled != pruned.aoas.shapes.enabled ||
                       zero.aoas.ambiguity.enabled != pruned.aoas.ambiguity.enabled ||
                       zero.aoas.hue.enabled != pruned.aoas.hue.enabled;
  EXPECT_TRUE(differs) << eq.effect << ": the pruned style must compile the effect out";
  testing::ExpectNoValidationMessages();
}

INSTANTIATE_TEST_SUITE_P(
    Effects, PruningEquivalenceTest,
    ::testing::Values(Equivalence{"multiple_scattering", "[effects]\nmultiple_scattering_strength = 0.0"},
                      Equivalence{"mie", "[atmosphere.mie]\nscattering_per_km = 0.0\nextinction_per_km = 0.0"},
                      Equivalence{"ozone", "[atmosphere.ozone]\nabsorption_per_km = 0.0"},
                      Equivalence{"ground", "[effects]\nground = true\n[atmosphere]\nground_albedo = 0.0"},
                      Equivalence{"sun_disc", "[effects]\nsun_disc_strength = 0.0"},
                      Equivalence{"night_dimming", "[effects]\nnight_dimming = true\nnight_dimming_strength = 0.0"},
                      Equivalence{"hue", "[hue]\nenabled = true\ncolor = \"#ff3300\"\nstrength = 0.0"},
                      Equivalence{"ambiguity", "[ambiguity]\nenabled = true\nl_pt = 0.0"},
                      Equivalence{"cloud_noise", "[clouds]\nenabled = true\nstrength = 0.0"},
                      Equivalence{"cloud_shapes",
                                  "[shapes]\nenabled = true\nstrength = 0.0\n[[shapes.shape]]\nkind = \"point\"\n"
                                  "points = [[30.0, 160.0]]"}),
    [](const ::testing::TestParamInfo<Equivalence>& info) { return info.param.effect; });

}  // namespace
}  // namespace skybake
