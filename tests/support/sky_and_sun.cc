#include "sky_and_sun.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <fmt/format.h>
#include <glm/glm.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "skybake/model/spectrum.h"
#include "test_support.h"

namespace skybake::testing {
namespace {

using nlohmann::json;

// Rec.709 luminance of linear RGB (the first three values).
double Luminance(const std::vector<double>& rgb) { return Rec709Luminance({rgb[0], rgb[1], rgb[2]}); }

struct Latlong {
  int width = 0, height = 0;
  std::vector<float> rgb;

  double LuminanceAt(int x, int y) const {
    const float* p = &rgb[3 * (size_t(y) * width + x)];
    return Luminance({p[0], p[1], p[2]});
  }
};

// Luminance along `d`, bilinear between pixel centres, where OpenEXR's
// Imf::LatLongMap puts d: x = (0.5 - longitude / 2 pi)(w - 1), y = (0.5 -
// latitude / pi)(h - 1), longitude = atan2(x, z) (pixel centres on the
// image's edges: row 0 is the zenith, columns 0 and w - 1 both longitude pi).
double LuminanceAlong(const Latlong& l, const glm::dvec3& d) {
  const glm::dvec3 u = glm::normalize(d);
  const double latitude = std::asin(std::clamp(u.y, -1.0, 1.0));
  const double longitude = (u.x == 0.0 && u.z == 0.0) ? 0.0 : std::atan2(u.x, u.z);
  const double px = (0.5 - longitude / (2.0 * M_PI)) * (l.width - 1);
  const double py = (0.5 - latitude / M_PI) * (l.height - 1);
  const int x0 = std::clamp(int(std::floor(px)), 0, l.width - 2), y0 = std::clamp(int(std::floor(py)), 0, l.height - 2);
  const double fx = std::clamp(px - x0, 0.0, 1.0), fy = std::clamp(py - y0, 0.0, 1.0);
  return (1 - fy) * ((1 - fx) * l.LuminanceAt(x0, y0) + fx * l.LuminanceAt(x0 + 1, y0)) +
         fy * ((1 - fx) * l.LuminanceAt(x0, y0 + 1) + fx * l.LuminanceAt(x0 + 1, y0 + 1));
}

// Mean luminance over the pixels of a square pinhole camera of kProbeFovDeg
// and kProbeSize looking along `forward` (unit) with up `up`.
double ProbeView(const Latlong& l, const glm::dvec3& forward, const glm::dvec3& up) {
  const glm::dvec3 right = glm::normalize(glm::cross(forward, up));
  const glm::dvec3 true_up = glm::cross(right, forward);
  const double t = std::tan(kProbeFovDeg * M_PI / 360.0);
  double sum = 0.0;
  for (int j = 0; j < kProbeSize; ++j)
    for (int i = 0; i < kProbeSize; ++i) {
      const double sx = (2.0 * (i + 0.5) / kProbeSize - 1.0) * t, sy = (2.0 * (j + 0.5) / kProbeSize - 1.0) * t;
      sum += LuminanceAlong(l, forward + sx * right + sy * true_up);
    }
  return sum / (kProbeSize * kProbeSize);
}

// Horizontal illuminance of the upper hemisphere, L cos(theta) dOmega: row y
// stands for the latitudes within half a row of its own, latitude
// pi/2 - pi y / (h - 1), clipped to [0, pi/2] (a band's cos-weighted solid
// angle is pi (sin^2 hi - sin^2 lo)); columns by the trapezoid rule over
// their w - 1 intervals (the two edge columns are the same longitude).
double SkyHorizontalIlluminance(const Latlong& l) {
  const double row = M_PI / (l.height - 1);
  double e = 0.0;
  for (int y = 0; y < l.height; ++y) {
    const double latitude = M_PI / 2 - y * row;
    const double hi = std::min(M_PI / 2, latitude + row / 2), lo = std::max(0.0, latitude - row / 2);
    if (hi <= lo) continue;
    const double band = M_PI * (std::sin(hi) * std::sin(hi) - std::sin(lo) * std::sin(lo));
    double mean = 0.0;
    for (int x = 0; x < l.width; ++x)
      mean += l.LuminanceAt(x, y) * ((x == 0 || x == l.width - 1) ? 0.5 : 1.0) / (l.width - 1);
    e += band * mean;
  }
  return e;
}

glm::dvec3 Vec3(const json& a) { return {a[0].get<double>(), a[1].get<double>(), a[2].get<double>()}; }

}  // namespace

std::vector<glm::dvec3> SkyProbeDirections() {
  const double c = std::cos(M_PI / 3), s = std::sin(M_PI / 3);
  return {{0, s, -c}, {c, s, 0}, {0, s, c}, {-c, s, 0}};
}

std::string SkyProbeQuery() {
  std::string q;
  for (const glm::dvec3& d : SkyProbeDirections())
    q += fmt::format("{}{:.9f},{:.9f},{:.9f}", q.empty() ? "" : ";", d.x, d.y, d.z);
  return q;
}

double SkyAndSun::SunHorizontalLux() const { return sun_illuminance_lux * std::sin(sun_elevation_deg * M_PI / 180.0); }

double SkyAndSun::GltfLightHorizontalLux() const {
  return light_intensity * Luminance({light_color.r, light_color.g, light_color.b}) *
         std::sin(sun_elevation_deg * M_PI / 180.0);
}

double SkyAndSun::CardCdM2() const { return kGreyCardAlbedo / M_PI * (SunHorizontalLux() + sky_horizontal_lux); }

bool BakeSkyAndSun(const std::string& name, SkyAndSun& out) {
  const std::string dir = FreshTempDir(name);
  out.half_dir = dir + "/half";
  out.float_dir = dir + "/float";
  for (const auto& [type, folder] : {std::pair{"half", out.half_dir}, std::pair{"float", out.float_dir}}) {
    const CommandRun r = RunSkybake("bake " + SourceDir() +
                                    "/configs/default.toml --size 64 -q --vulkan-validation "
                                    "--set output.pixel_type=" +
                                    std::string(type) + " --out " + folder);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    if (r.exit_code != 0) return false;
  }
  const json manifest = json::parse(ReadFileBytes(out.float_dir + "/manifest.json"), nullptr, false);
  EXPECT_FALSE(manifest.is_discarded()) << out.float_dir << "/manifest.json";
  if (manifest.is_discarded()) return false;
  const json& sun = manifest["frames"][0]["sun"];
  out.sun_illuminance_lux = sun["illuminance_lux"].get<double>();
  out.sun_elevation_deg = sun["elevation_deg"].get<double>();
  out.sun_irradiance = Vec3(sun["irradiance"]);

  const json gltf = json::parse(ReadFileBytes(out.half_dir + "/sky.gltf"), nullptr, false);
  EXPECT_FALSE(gltf.is_discarded()) << out.half_dir << "/sky.gltf";
  if (gltf.is_discarded()) return false;
  for (const json& light : gltf["extensions"]["KHR_lights_punctual"]["lights"])
    if (light.value("name", "") == "sun") {
      out.light_intensity = light["intensity"].get<double>();
      out.light_color = Vec3(light["color"]);
    }
  EXPECT_GT(out.light_intensity, 0.0) << "no sun light in " << out.half_dir << "/sky.gltf";

  Latlong l;
  if (!ReadRgb(out.float_dir + "/sky_latlong.exr", l.width, l.height, l.rgb)) return false;
  out.sky_cd_m2 = 0.0;
  for (const glm::dvec3& d : SkyProbeDirections()) out.sky_cd_m2 += ProbeView(l, d, {0, 1, 0}) / 4.0;
  out.sky_horizontal_lux = SkyHorizontalIlluminance(l);
  return out.light_intensity > 0.0;
}

void ExpectClientMatchesFloatBake(const std::string& client, const SkyAndSun& bake, const std::vector<double>& sky,
                                  const std::vector<double>& card, const std::vector<double>& card_sun_only,
                                  const std::vector<double>& card_sky_only) {
  const double sky_seen = Luminance(sky), card_seen = Luminance(card);
  const double card_want = bake.CardCdM2();
  const double ratio_seen = card_seen / sky_seen, ratio_want = card_want / bake.sky_cd_m2;
  const double k = kGreyCardAlbedo / M_PI;
  std::printf(
      "%s: sky %.1f cd/m^2 (float32 bake %.1f, %+.2f%%); card %.1f cd/m^2 (%.1f, %+.2f%%); card/sky %.4f "
      "(%.4f, %+.2f%%)\n"
      "  card under the sun alone %.1f (float32 manifest %.1f, the glTF light's intensity x Y(colour) %.1f); "
      "under the sky alone %.1f (float32 latlong %.1f)\n",
      client.c_str(), sky_seen, bake.sky_cd_m2, 100.0 * (sky_seen / bake.sky_cd_m2 - 1.0), card_seen, card_want,
      100.0 * (card_seen / card_want - 1.0), ratio_seen, ratio_want, 100.0 * (ratio_seen / ratio_want - 1.0),
      Luminance(card_sun_only), k * bake.SunHorizontalLux(), k * bake.GltfLightHorizontalLux(),
      Luminance(card_sky_only), k * bake.sky_horizontal_lux);
  EXPECT_NEAR(sky_seen / bake.sky_cd_m2, 1.0, kClientTolerance) << client << ": the sky";
  EXPECT_NEAR(card_seen / card_want, 1.0, kClientTolerance) << client << ": the sunlit grey card";
  EXPECT_NEAR(ratio_seen / ratio_want, 1.0, kClientTolerance) << client << ": card / sky (the same units)";
}

}  // namespace skybake::testing
