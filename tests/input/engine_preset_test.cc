// Engine presets (engine_preset.h): every face and panorama texel of every
// preset checked against the engine's own lookup formula, written here from
// the engine's source or documentation (docs/engines.md) and independently
// of bake/engine_preset.cc, which builds the images from the inverse
// direction. Presets that load here are also checked in the engine
// (engine_blender_test.cc, engine_threejs_test.cc). And the CLI: unknown
// names and impossible combinations refused before any GPU work; the files
// of a bake listed in its manifest, kept by --resume.
#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <glm/glm.hpp>

#include "skybake/input/config.h"
#include "skybake/input/engine_preset.h"
#include "skybake/output/exr_io.h"
#include "skybake/pipeline/engine_files.h"
#include "skybake/pipeline/test_pattern.h"
#include "test_support.h"

namespace skybake {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Each preset: the engine's lookup vector for a skybake world direction,
// and the cube face (OpenGL numbering) each of its face files must hold.
struct FaceConvention {
  glm::dvec3 (*lookup)(glm::dvec3);
  std::vector<int> faces;
};
std::map<std::string, FaceConvention> FaceConventions() {
  return {
      // three.js: glTF axes kept; CubeTexture sampled at (flipEnvMap * x, y, z),
      // flipEnvMap = -1 (backgroundCube.glsl.js, envmap_fragment.glsl.js);
      // CubeTextureLoader order px, nx, py, ny, pz, nz.
      {"threejs", {[](glm::dvec3 d) { return glm::dvec3(-d.x, d.y, d.z); }, {0, 1, 2, 3, 4, 5}}},
      // Babylon.js: left-handed, the glTF root mirrors x; CubeTexture files px, py, pz, nx, ny, nz.
      {"babylon", {[](glm::dvec3 d) { return glm::dvec3(-d.x, d.y, d.z); }, {0, 2, 4, 1, 3, 5}}},
      // Unity: left-handed, glTF x negated; 6 Sided skybox Front [+Z], Back [-Z], Left [+X], Right [-X], Up, Down.
      {"unity", {[](glm::dvec3 d) { return glm::dvec3(-d.x, d.y, d.z); }, {4, 5, 0, 1, 2, 3}}},
      // Unreal: glTF (x, y, z) -> UE (x, z, y); ECubeFace PosX..NegZ.
      {"unreal", {[](glm::dvec3 d) { return glm::dvec3(d.x, d.z, d.y); }, {0, 1, 2, 3, 4, 5}}},
      // Filament: cmgen's faces, skybake's Vulkan cube as is (docs/ibl.md).
      {"filament", {[](glm::dvec3 d) { return d; }, {0, 1, 2, 3, 4, 5}}},
  };
}

// Each panorama: (u, v) of a skybake world direction, v = 0 on the file's top row.
std::map<std::string, glm::dvec2 (*)(glm::dvec3)> PanoramaConventions() {
  return {
      // three.js equirectUv (common.glsl.js): u = atan(z, x) / 2 pi + 0.5,
      // v = asin(y) / pi + 0.5; EXRLoader stores rows bottom-up with flipY
      // false, so v = 1 is the file's top row.
      {"threejs",
       [](glm::dvec3 d) {
         return glm::dvec2(std::atan2(d.z, d.x) / (2 * kPi) + 0.5, 1.0 - (std::asin(d.y) / kPi + 0.5));
       }},
      // Blender: glTF import (x, y, z) -> (x, -z, y); Cycles
      // direction_to_equirectangular: u = 0.5 - atan2(y, x) / 2 pi,
      // v = 1 - acos(z) / pi with v = 1 the image's top row.
      {"blender",
       [](glm::dvec3 d) {
         const glm::dvec3 b(d.x, -d.z, d.y);
         return glm::dvec2(0.5 - std::atan2(b.y, b.x) / (2 * kPi), std::acos(b.z) / kPi);
       }},
      // Godot 4 sky shader: SKY_COORDS = (atan(x, -z) wrapped to [0, 2 pi), acos(y)) / (2 pi, pi), v = 0 top.
      {"godot",
       [](glm::dvec3 d) {
         double u = std::atan2(d.x, -d.z);
         if (u < 0.0) u += 2 * kPi;
         return glm::dvec2(u / (2 * kPi), std::acos(d.y) / kPi);
       }},
      // Unreal long-lat (TextureCompressorModule): u = (1 + atan2(x, -y) / pi) / 2,
      // v = acos(z) / pi in UE axes (x, z, y) of the glTF direction.
      {"unreal",
       [](glm::dvec3 d) {
         const glm::dvec3 ue(d.x, d.z, d.y);
         return glm::dvec2((1.0 + std::atan2(ue.x, -ue.y) / kPi) / 2.0, std::acos(ue.z) / kPi);
       }},
  };
}

double Wrapped(double u) { return u - std::floor(u); }

TEST(EnginePresetTest, EveryFaceTexelIsWhereTheEngineLooksItUp) {
  const int n = 8;
  const std::map<std::string, FaceConvention> conventions = FaceConventions();
  int checked_presets = 0;
  for (const EnginePreset& preset : EnginePresets()) {
    if (preset.faces.empty()) continue;
    ASSERT_TRUE(conventions.count(preset.name)) << preset.name << " has faces but no convention in this test";
    const FaceConvention& c = conventions.at(preset.name);
    std::vector<EngineImage> images = EngineImages(preset, n, 4);
    ASSERT_EQ(c.faces.size(), preset.faces.size());
    for (size_t f = 0; f < preset.faces.size(); ++f) {
      const EngineImage& image = images[f];
      ASSERT_EQ(image.suffix, preset.faces[f]);
      ASSERT_EQ(image.width, n);
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          const testing::CubeFaceHit hit = testing::SpecCubeFace(c.lookup(image.directions[size_t(y) * n + x]));
          ASSERT_EQ(hit.face, c.faces[f]) << preset.name << " " << preset.faces[f] << " texel " << x << "," << y;
          EXPECT_NEAR(hit.s, (x + 0.5) / n, 1e-12) << preset.name << " " << preset.faces[f];
          EXPECT_NEAR(hit.t, (y + 0.5) / n, 1e-12) << preset.name << " " << preset.faces[f];
        }
    }
    ++checked_presets;
  }
  EXPECT_EQ(checked_presets, 5);
}

TEST(EnginePresetTest, EveryPanoramaTexelIsWhereTheEngineLooksItUp) {
  const int h = 16, w = 2 * h;
  const auto conventions = PanoramaConventions();
  int checked = 0;
  for (const EnginePreset& preset : EnginePresets()) {
    if (!preset.latlong || preset.name == "exrenvmap") continue;
    ASSERT_TRUE(conventions.count(preset.name)) << preset.name << " has a panorama but no convention in this test";
    std::vector<EngineImage> images = EngineImages(preset, 4, h);
    const EngineImage& image = images[preset.faces.size()];
    ASSERT_EQ(image.suffix, "latlong");
    ASSERT_EQ(image.width, w);
    ASSERT_EQ(image.height, h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const glm::dvec3 d = image.directions[size_t(y) * w + x];
        EXPECT_NEAR(glm::length(d), 1.0, 1e-12);
        const glm::dvec2 uv = conventions.at(preset.name)(d);
        // u wraps: compare on the circle.
        const double du = Wrapped(uv.x - (x + 0.5) / w + 0.5) - 0.5;
        EXPECT_NEAR(du, 0.0, 1e-9) << preset.name << " texel " << x << "," << y;
        EXPECT_NEAR(uv.y, (y + 0.5) / h, 1e-9) << preset.name << " texel " << x << "," << y;
      }
    ++checked;
  }
  EXPECT_EQ(checked, 4);
}

// The traps the issue names, stated as where things land.
TEST(EnginePresetTest, KnownTraps) {
  // three.js: its px file shows skybake's -X (CubeTexture swaps +X and -X).
  const EnginePreset* three = FindEnginePreset("threejs");
  ASSERT_TRUE(three);
  std::vector<EngineImage> t = EngineImages(*three, 2, 2);
  EXPECT_LT(t[0].directions[0].x, -0.5);
  // Unity names +X "Left": the Left file is +X in Unity's axes, -X of skybake's (glTF x negated).
  const EnginePreset* unity = FindEnginePreset("unity");
  ASSERT_TRUE(unity);
  EXPECT_EQ(unity->faces[2], "Left");
  EXPECT_LT(EngineImages(*unity, 2, 2)[2].directions[0].x, -0.5);
  // Babylon's order interleaves: its second file is py.
  EXPECT_EQ(FindEnginePreset("babylon")->faces[1], "py");
  // Blender's equirect centre faces +X (skybake +X, Blender +X); OpenEXR's faces +Z.
  std::vector<EngineImage> b = EngineImages(*FindEnginePreset("blender"), 2, 64);
  const glm::dvec3 centre = b[0].directions[size_t(32) * 128 + 64];
  EXPECT_GT(centre.x, 0.99);
  // Godot wants a panorama, not faces.
  EXPECT_TRUE(FindEnginePreset("godot")->faces.empty());
  EXPECT_TRUE(FindEnginePreset("godot")->latlong);
  EXPECT_EQ(FindEnginePreset("bogus"), nullptr);
}

std::string Style() { return testing::SourceDir() + "/configs/default.toml"; }

TEST(EnginePresetCliTest, UnknownNamesAndImpossibleCombinationsAreRefusedBeforeGpuWork) {
  {
    const std::string dir = testing::FreshTempDir("engine_bad");
    testing::CommandRun r = testing::RunSkybake("bake " + Style() + " --engine unreal5 --out " + dir);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("unity,unreal,godot,blender,threejs,babylon,filament,exrenvmap"), std::string::npos)
        << r.output;
    EXPECT_TRUE(testing::FileNames(dir).empty());
  }
  struct Case {
    std::string set, message;
  };
  for (const Case& c : std::vector<Case>{
           {"output.engine=unreal5", "output.engine: 'unreal5' is not one of"},
           {"output.engine=threejs --set 'output.face_names=[\"threejs_px\",\"nx\",\"py\",\"ny\",\"pz\",\"nz\"]'",
            "output.engine: face name 'threejs_px' makes sky_threejs_px.exr, a file of the threejs preset: choose "
            "another face name"},
       }) {
    const std::string dir = testing::FreshTempDir("engine_bad");
    testing::CommandRun r = testing::RunSkybake("bake " + Style() + " --set " + c.set + " --out " + dir);
    EXPECT_EQ(r.exit_code, 3) << c.set << "\n" << r.output;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << c.set << "\n" << r.output;
    EXPECT_EQ(r.output.find("device"), std::string::npos) << "no GPU work: " << r.output;
    EXPECT_TRUE(testing::FileNames(dir).empty()) << c.set;
  }
  // In a style file: file:line:col.
  const std::string dir = testing::FreshTempDir("engine_bad_file");
  const std::string style = testing::WriteFile(dir, "style.toml", "[output]\nengine = \"unity3d\"\n");
  testing::CommandRun r = testing::RunSkybake("bake " + style + " --out " + dir + "/out");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find(style + ":2:10: output.engine: 'unity3d' is not one of"), std::string::npos) << r.output;
}

struct Exr {
  int width = 0, height = 0;
  std::vector<float> rgb;
  std::map<std::string, std::string> attributes;
};
Exr ReadExr(const std::string& path) {
  Exr e;
  testing::ReadRgb(path, e.width, e.height, e.rgb, &e.attributes);
  return e;
}

// A bake with a preset: its files in the manifest with their kind, the
// frame's scale and provenance, the mapping named in each file; the
// exrenvmap preset's latlong and strip are the bake's own OpenEXR files
// rendered again (same texels to float rounding of the directions).
TEST(EnginePresetCliTest, BakeWritesThePresetsFiles) {
  const std::string dir = testing::FreshTempDir("engine_bake");
  for (const std::string engine : {"threejs", "exrenvmap"}) {
    const std::string out = dir + "/" + engine;
    testing::CommandRun r = testing::RunSkybake("bake " + Style() +
                                                " --size 16 -q --vulkan-validation --set "
                                                "output.pixel_type=float --engine " +
                                                engine + " --out " + out);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const std::string manifest = testing::ReadFileBytes(out + "/manifest.json");
    std::vector<std::string> names = engine == "threejs"
                                         ? std::vector<std::string>{"px", "nx", "py", "ny", "pz", "nz", "latlong"}
                                         : std::vector<std::string>{"latlong", "cube"};
    size_t last = 0;
    for (const std::string& s : names) {
      const std::string file = "sky_" + engine + "_" + s + ".exr";
      const size_t at = manifest.find("\"" + file + "\"");
      ASSERT_NE(at, std::string::npos) << file << "\n" << manifest;
      EXPECT_GT(at, last) << file << " in load order";
      last = at;
      EXPECT_NE(manifest.find("\"engine\"", at), std::string::npos);
      Exr e = ReadExr(out + "/" + file);
      EXPECT_FALSE(e.attributes["skybake:engine_mapping"].empty()) << file;
      EXPECT_FALSE(e.attributes["skybake:config"].empty()) << file;
      EXPECT_NE(e.attributes["skybake:config"].find("engine = '" + engine + "'"), std::string::npos);
    }
    if (engine == "exrenvmap") {
      for (const char* s : {"latlong", "cube"}) {
        Exr mine = ReadExr(out + "/sky_" + std::string(s) + ".exr");
        Exr theirs = ReadExr(out + "/sky_exrenvmap_" + std::string(s) + ".exr");
        ASSERT_EQ(mine.rgb.size(), theirs.rgb.size());
        double worst = 0.0;
        for (size_t i = 0; i < mine.rgb.size(); ++i)
          worst = std::max(worst, std::abs(mine.rgb[i] - theirs.rgb[i]) / std::max(1e-3, double(mine.rgb[i])));
        EXPECT_LT(worst, 2e-3) << s;
      }
    }
  }
}

// Several presets in one bake (`--engine threejs,babylon --engine blender`):
// every preset's files, in the order named, from the frame's one renderer.
// three.js and Babylon.js look up a cube the same way (g = (-x, y, z)) and
// three.js's equirect and Blender's are the same panorama, so those files
// must hold the same pixels; and each preset's pixels are those of a bake
// with that preset alone.
TEST(EnginePresetCliTest, SeveralPresetsInOneBakeComeFromOneRender) {
  const std::string dir = testing::FreshTempDir("engine_several");
  const std::string common = "bake " + Style() + " --size 16 --vulkan-validation --set output.pixel_type=float";
  testing::CommandRun r =
      testing::RunSkybake(common + " --engine threejs,babylon --engine blender --out " + dir + "/several");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // One engine stage for the three presets' images.
  size_t stages = 0;
  for (size_t at = r.output.find("skybake: engine "); at != std::string::npos;
       at = r.output.find("skybake: engine ", at + 1))
    ++stages;
  EXPECT_EQ(stages, 1u) << r.output;
  EXPECT_NE(r.output.find("14 images for threejs,babylon,blender"), std::string::npos) << r.output;

  const std::string manifest = testing::ReadFileBytes(dir + "/several/manifest.json");
  size_t last = 0;
  for (const char* file : {"sky_threejs_px.exr", "sky_threejs_nz.exr", "sky_threejs_latlong.exr", "sky_babylon_px.exr",
                           "sky_babylon_nz.exr", "sky_blender_latlong.exr"}) {
    const size_t at = manifest.find("\"" + std::string(file) + "\"");
    ASSERT_NE(at, std::string::npos) << file << "\n" << manifest;
    EXPECT_GT(at, last) << file << " in the order the presets are named";
    last = at;
  }
  auto pixels = [&](const std::string& folder, const std::string& file) {
    Exr e = ReadExr(dir + "/" + folder + "/" + file);
    EXPECT_FALSE(e.rgb.empty()) << folder << "/" << file;
    return e.rgb;
  };
  for (const char* face : {"px", "nx", "py", "ny", "pz", "nz"})
    EXPECT_EQ(pixels("several", std::string("sky_threejs_") + face + ".exr"),
              pixels("several", std::string("sky_babylon_") + face + ".exr"))
        << face << ": three.js's and Babylon.js's faces differ";
  EXPECT_EQ(pixels("several", "sky_threejs_latlong.exr"), pixels("several", "sky_blender_latlong.exr"))
      << "three.js's and Blender's equirects differ";
  for (const char* engine : {"threejs", "babylon"}) {
    testing::CommandRun alone = testing::RunSkybake(common + " -q --engine " + engine + " --out " + dir + "/" + engine);
    ASSERT_EQ(alone.exit_code, 0) << alone.output;
    SkyStyle style;  // basename "sky", as configs/default.toml
    style.output.engine = engine;
    for (const std::string& name : EngineFileNames(style, 0))
      EXPECT_EQ(pixels("several", name), pixels(engine, name)) << name;
  }
}

// Bad preset names among several are refused before any GPU work: on the
// command line with exit code 2 and the names, in output.engine with exit
// code 3 and the key.
TEST(EnginePresetCliTest, BadNamesAmongSeveralAreRefusedBeforeGpuWork) {
  for (const std::string args :
       {"--engine threejs,unreal5", "--engine threejs --engine unreal5", "--engine threejs,", "--engine none"}) {
    const std::string dir = testing::FreshTempDir("engine_several_bad");
    testing::CommandRun r = testing::RunSkybake("bake " + Style() + " " + args + " --out " + dir);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.output;
    EXPECT_NE(r.output.find("unity,unreal,godot,blender,threejs,babylon,filament,exrenvmap"), std::string::npos)
        << args << "\n"
        << r.output;
    EXPECT_EQ(r.output.find("device"), std::string::npos) << "no GPU work: " << r.output;
    EXPECT_TRUE(testing::FileNames(dir).empty()) << args;
  }
  struct Case {
    std::string set, message;
  };
  for (const Case& c : std::vector<Case>{
           {"'output.engine=\"threejs, unreal5\"'", "output.engine: 'unreal5' is not one of"},
           {"'output.engine=\"threejs,none\"'", "output.engine: 'none' cannot be given with other presets"},
           {"'output.engine=\"threejs,,babylon\"'", "output.engine: '' is not one of"},
       }) {
    const std::string dir = testing::FreshTempDir("engine_several_bad");
    testing::CommandRun r = testing::RunSkybake("bake " + Style() + " --set " + c.set + " --out " + dir);
    EXPECT_EQ(r.exit_code, 3) << c.set << "\n" << r.output;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << c.set << "\n" << r.output;
    EXPECT_EQ(r.output.find("device"), std::string::npos) << "no GPU work: " << r.output;
    EXPECT_TRUE(testing::FileNames(dir).empty()) << c.set;
  }
}

// The engine files' half scale (EngineFileScale): the bake's own while they
// fit in it, else a smaller power of two of their own.
TEST(EnginePresetTest, EngineFileScaleIsTheBakesUnlessTheyNeedASmallerOne) {
  EXPECT_EQ(EngineFileScale(1000.0, 1.0, PixelType::kHalf, OverflowPolicy::kScale), 1.0);
  EXPECT_EQ(EngineFileScale(65504.0 * 4.0, 0.25, PixelType::kHalf, OverflowPolicy::kScale), 0.25);
  EXPECT_EQ(EngineFileScale(65504.0 * 4.0 + 1.0, 0.25, PixelType::kHalf, OverflowPolicy::kScale), 0.125);
  EXPECT_EQ(EngineFileScale(1e9, 1.0, PixelType::kFloat, OverflowPolicy::kScale), 1.0);
  EXPECT_THROW(EngineFileScale(1e9, 1.0, PixelType::kHalf, OverflowPolicy::kRefuse), OutputError);
}

// A preset never changes the half-float scale of the bake's own files. Here
// the bake writes 16 x 16 faces only, whose texels are far wider than the sun
// disc (each holds a fraction of its light, so the faces fit in half floats
// unscaled), while Godot's 2048 x 1024 panorama has texels inside the disc
// (its full radiance, above the half maximum). Before EngineFileScale the
// panorama's brightest texel set the scale of every file of the frame: the
// faces went from 1 to 2^-16.
TEST(EnginePresetCliTest, PresetKeepsTheHalfScaleOfTheBakesOwnFiles) {
  const std::string dir = testing::FreshTempDir("engine_scale");
  // The disc in the maps (output.sun = "map"): the panorama's texels inside it need a scale.
  const std::string sizes =
      " --set output.latlong=false --set output.preview=false --set output.cube_strip=false "
      "--set gltf.enabled=false --set render.cube_size=16 --set render.latlong_height=1024 "
      "--set output.sun=map";
  for (const char* engine : {"", "godot"}) {
    const std::string out = dir + "/" + (*engine ? engine : "none");
    testing::CommandRun r = testing::RunSkybake("bake " + Style() + sizes + " -q --out " + out +
                                                (*engine ? std::string(" --engine ") + engine : std::string()));
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  const std::string none = dir + "/none", godot = dir + "/godot";
  EXPECT_NE(testing::ReadFileBytes(none + "/manifest.json").find("\"half_scale\": 1.0"), std::string::npos);
  EXPECT_NE(testing::ReadFileBytes(godot + "/manifest.json").find("\"half_scale\": 1.0"), std::string::npos);
  for (const char* face : {"px", "nx", "py", "ny", "pz", "nz"}) {
    Exr a = ReadExr(none + "/sky_" + std::string(face) + ".exr"),
        b = ReadExr(godot + "/sky_" + std::string(face) + ".exr");
    EXPECT_EQ(b.attributes["skybake:scale"], "1") << face;
    EXPECT_EQ(a.rgb, b.rgb) << face << ": the same pixels with the preset as without";
  }
  Exr pano = ReadExr(godot + "/sky_godot_latlong.exr");
  ASSERT_FALSE(pano.rgb.empty());
  const double scale = std::stod(pano.attributes["skybake:scale"]);
  EXPECT_LT(scale, 1.0) << "the panorama's own, smaller scale";
  double brightest = 0.0;
  for (float v : pano.rgb) {
    ASSERT_TRUE(std::isfinite(v));
    brightest = std::max(brightest, double(v));
  }
  EXPECT_LE(brightest, 65504.0);
  std::printf("panorama: skybake:scale %g, brightest %g cd/m^2 unscaled\n", scale, brightest / scale);
  EXPECT_GT(brightest / scale, 65504.0) << "the disc's radiance, which needs the scale";
}

// A sequence with a preset resumes: every frame's engine files verified by checksum.
TEST(EnginePresetCliTest, ResumeVerifiesTheEngineFiles) {
  const std::string dir = testing::FreshTempDir("engine_resume");
  const std::string schedule = testing::WriteFile(
      dir, "schedule.toml",
      "[schedule]\nsun = { elevation_deg = { start = 20, end = 30, step = 10 }, azimuth_deg = 135 }\n");
  const std::string args =
      "bake " + Style() + " --schedule " + schedule + " --size 8 --engine godot --out " + dir + "/out";
  testing::CommandRun first = testing::RunSkybake(args);
  ASSERT_EQ(first.exit_code, 0) << first.output;
  EXPECT_TRUE(testing::FileNames(dir + "/out").count("sky_godot_latlong.0002.exr"));
  testing::CommandRun again = testing::RunSkybake(args + " --resume");
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_NE(again.output.find("files verified by checksum"), std::string::npos) << again.output;
  EXPECT_NE(first.output.find("skybake: engine "), std::string::npos) << first.output;
  EXPECT_EQ(again.output.find("skybake: engine "), std::string::npos) << "nothing rendered again: " << again.output;
}

// The test pattern: each face's tint below the horizon, the horizon white,
// each face's name in black above its centre, reading the right way round
// from inside (its first glyph, the sign, on the left as seen from the
// centre: towards the face's right = cross(axis, +Y) is the axis letter).
TEST(TestPatternTest, FacesHorizonAndLabels) {
  const glm::dvec3 axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (int f = 0; f < 6; ++f) {
    const glm::dvec3 d = f == 2 || f == 3 ? axes[f] : axes[f] + glm::dvec3(0, -0.18, 0);
    EXPECT_EQ(TestPatternColor(d), TestPatternFaceColor(f)) << f;
  }
  EXPECT_EQ(TestPatternColor({0.3, 0.0, -1.0}), glm::dvec3(1.0));
  // "+X" on the +X face, seen from inside: right is +Z. The '+' (left
  // glyph) has its bar across the full glyph width, the 'X' not on its middle row.
  auto black_on_row = [](double b, double a0, double a1) {
    int black = 0;
    for (double a = a0; a <= a1; a += 0.002)
      if (TestPatternColor({1.0, b, a}) == glm::dvec3(0.0)) ++black;
    return black;
  };
  const double cell = 0.3 / 7.0, middle = 0.35;  // the centre of glyph row 3 of 7: the text is centred at b = 0.35
  // Left glyph spans a in [-5.5, -0.5] cells, right glyph [0.5, 5.5]: '+' fills its middle row, 'X' one cell.
  EXPECT_GT(black_on_row(middle, -5.4 * cell, -0.6 * cell), 2 * black_on_row(middle, 0.6 * cell, 5.4 * cell));
  EXPECT_GT(black_on_row(middle, 0.6 * cell, 5.4 * cell), 0);
}

TEST(TestPatternTest, CommandWritesEveryPresetsFilesAndKeepsExistingOnes) {
  const std::string dir = testing::FreshTempDir("pattern");
  testing::CommandRun r = testing::RunSkybake("testpattern --engine unity --size 16 --out " + dir);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* f : {"sky_px.exr", "sky_cube.exr", "sky_latlong.exr", "sky_unity_Front.exr", "sky_unity_Down.exr"})
    EXPECT_TRUE(testing::FileNames(dir).count(f)) << f;
  const std::string before = testing::ReadFileBytes(dir + "/sky_unity_Left.exr");
  testing::CommandRun again = testing::RunSkybake("testpattern --engine unity --size 32 --out " + dir);
  EXPECT_EQ(again.exit_code, 6) << again.output;
  EXPECT_NE(again.output.find("--force"), std::string::npos) << again.output;
  EXPECT_EQ(testing::ReadFileBytes(dir + "/sky_unity_Left.exr"), before);
  testing::CommandRun bad = testing::RunSkybake("testpattern --engine unity3d --out " + dir);
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
}

}  // namespace
}  // namespace skybake
