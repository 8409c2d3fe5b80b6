#include "skybake/tools/cloud_study.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <tuple>
#include <utility>

#include <sys/resource.h>

#include <fmt/format.h>
#include <glm/glm.hpp>

#include "skybake/gpu/sky_renderer.h"
#include "skybake/input/config.h"
#include "skybake/model/aoas.h"
#include "skybake/model/view.h"
#include "skybake/output/exr_io.h"
#include "study.h"

namespace skybake {
namespace {

// W3's layer (configs/benchmark/w3.toml), the default atmosphere, production
// sky quality: the sky behind the clouds is the same in every case, so every
// difference is the clouds'.
constexpr char kStudyStyle[] = R"([[cloud_layer]]
altitude_m = 1500.0
thickness_m = 1500.0
type = "cumulus"
coverage = 0.45
density_per_m = 0.05
wind_m_s = [8.0, 2.0]
)";

struct Scene {
  SkyStyle style;
  AtmosphereParams atmosphere;
  EffectSettings effects;
  Rgb scale{};
};

Scene StudyScene() {
  ConfigResult loaded = ParseSkyStyle(kStudyStyle, "cloud study (the layer of configs/benchmark/w3.toml)");
  if (!loaded.ok()) throw std::runtime_error("cloud study style: " + loaded.errors.front().Format());
  Scene s;
  s.style = loaded.style;
  s.atmosphere = StyledAtmosphere(s.style.atmosphere, s.style.aoas);
  s.effects = s.style.effects;
  // No disc: its texels would dominate every mean and are not the clouds'.
  s.effects.sun_disc = false;
  s.scale = OutputScale(s.style.output.units);
  return s;
}

CloudQuality MakeQuality(int view, int light, int shape, int detail, int weather, int octaves = 8,
                         double panorama_scale = 0.0) {
  // Every light sample trilinear, unless a case says otherwise.
  return {.view_steps = view,
          .light_steps = light,
          .light_trilinear_steps = 256,
          .octaves = octaves,
          .shape_resolution = shape,
          .detail_resolution = detail,
          .weather_resolution = weather,
          .panorama_scale = panorama_scale,
          .light_volume_columns = 0};
}

std::string CaseName(const CloudQuality& q) {
  std::string name = fmt::format("{}/{} vol {}/{}/{}", q.view_steps, q.light_steps, q.shape_resolution,
                                 q.detail_resolution, q.weather_resolution);
  if (q.octaves != 8) name += fmt::format(" oct {}", q.octaves);
  if (q.light_trilinear_steps < q.light_steps) name += fmt::format(" tri {}", q.light_trilinear_steps);
  if (q.light_volume_columns > 0)
    name += fmt::format(" lv {}/{}/{}", q.light_volume_columns, q.light_volume_slices, q.light_volume_near_steps);
  return name;
}

using Images = std::vector<std::vector<float>>;

// One renderer per noise-volume size; the step counts, octaves and
// panorama scale are uniforms (SkyRenderer::UpdateClouds).
class Renderers {
 public:
  Renderers(VulkanContext& vulkan, const Scene& scene) : vulkan_(vulkan), scene_(scene) {}

  SkyRenderer& For(const CloudQuality& q) {
    CloudSettings clouds = scene_.style.clouds;
    clouds.quality = q;
    if (CloudLoopIterationsPerTexel(clouds) > kMaxCloudLoopIterations)
      throw std::runtime_error(fmt::format("cloud study: {} exceeds lavapipe's loop limit", CaseName(q)));
    CloudInputs inputs = ToCloudInputs(clouds, scene_.style.aoas.seed, "", 0.0);
    auto key = std::make_tuple(q.shape_resolution, q.detail_resolution, q.weather_resolution);
    auto it = renderers_.find(key);
    if (it != renderers_.end() && it->second->UpdateClouds(inputs)) return *it->second;
    auto renderer = std::make_unique<SkyRenderer>(vulkan_, scene_.atmosphere, scene_.style.quality, scene_.effects,
                                                  scene_.scale, false, AoasInputs(), inputs);
    SkyRenderer& r = *renderer;
    renderers_[key] = std::move(renderer);
    return r;
  }

 private:
  VulkanContext& vulkan_;
  const Scene& scene_;
  std::map<std::tuple<int, int, int>, std::unique_ptr<SkyRenderer>> renderers_;
};

// The cloud march's GPU time of the last render: the "clouds ..." passes
// (latlong, faces, panorama, resample); the noise volumes (once per bake)
// and the per-sun tables are not the settings' per-texel cost.
double CloudPassMs(const SkyRenderer& renderer) {
  double ms = 0.0;
  for (const PassTiming& t : renderer.last_timings())
    if (t.name.rfind("clouds ", 0) == 0) ms += t.gpu_ms;
  return ms;
}

// CPU time of this process, all threads (lavapipe's among them), seconds:
// on a shared machine the work's cost, where the GPU timestamps (wall time
// on lavapipe) also count the other processes' turns.
double ProcessCpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  if (v.empty()) return 0.0;
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Texels that look above the horizon (the lower half sees the ground and,
// from the ground, no cloud): where every error is measured.
std::vector<std::vector<char>> SkyMasks(const std::vector<ViewRequest>& views) {
  std::vector<std::vector<char>> masks;
  for (const ViewRequest& v : views) {
    std::vector<char> m(size_t(v.width) * v.height);
    for (int y = 0; y < v.height; ++y)
      for (int x = 0; x < v.width; ++x) m[size_t(y) * v.width + x] = ViewTexelDirection(v, x, y).y > 0.0;
    masks.push_back(std::move(m));
  }
  return masks;
}

struct StudyError {
  double mean = 0.0;  // sum |a - r| / sum r over the sky texels' RGB
  double rmse = 0.0;  // sqrt(mean (a - r)^2) / mean r
};

StudyError Compare(const Images& a, const Images& ref, const std::vector<std::vector<char>>& masks) {
  double sum_abs = 0.0, sum_sq = 0.0, sum_ref = 0.0, count = 0.0;
  for (size_t v = 0; v < ref.size(); ++v)
    for (size_t i = 0; i < masks[v].size(); ++i) {
      if (!masks[v][i]) continue;
      for (int c = 0; c < 3; ++c) {
        const double r = ref[v][4 * i + c], d = double(a[v][4 * i + c]) - r;
        sum_abs += std::abs(d);
        sum_sq += d * d;
        sum_ref += r;
        count += 1.0;
      }
    }
  StudyError e;
  if (sum_ref <= 0.0 || count == 0.0) return e;
  e.mean = sum_abs / sum_ref;
  e.rmse = std::sqrt(sum_sq / count) / (sum_ref / count);
  return e;
}

bool AllFinite(const Images& images) {
  for (const auto& image : images)
    for (float f : image)
      if (!std::isfinite(f)) return false;
  return true;
}

struct Renders {
  std::vector<Images> per_sun;  // one per sun elevation
  double ms_per_mp = 0.0;       // cloud passes' GPU time
  double cpu_ms_per_mp = 0.0;   // the process's CPU time of a whole render
};

Renders RenderCase(Renderers& renderers, const CloudQuality& q, const std::vector<glm::dvec3>& suns,
                   const std::vector<ViewRequest>& views, int timing_runs) {
  SkyRenderer& renderer = renderers.For(q);
  double texels = 0.0;
  for (const ViewRequest& v : views) texels += double(v.width) * v.height;
  Renders r;
  for (size_t s = 0; s < suns.size(); ++s) {
    r.per_sun.push_back(renderer.Render(suns[s], views, false));
    if (!AllFinite(r.per_sun.back()))
      throw std::runtime_error(fmt::format("cloud study: {} rendered a value that is not finite", CaseName(q)));
  }
  // Timed renders at the first sun, after the others: the noise volumes
  // (once per bake) and that sun's tables are built, so only the views and
  // the cloud passes run.
  std::vector<double> ms, cpu_ms;
  for (int run = 0; run < timing_runs; ++run) {
    const double cpu0 = ProcessCpuSeconds();
    renderer.Render(suns[0], views, false);
    cpu_ms.push_back(1e3 * (ProcessCpuSeconds() - cpu0));
    ms.push_back(CloudPassMs(renderer));
  }
  r.ms_per_mp = Median(ms) / (texels * 1e-6);
  r.cpu_ms_per_mp = Median(cpu_ms) / (texels * 1e-6);
  return r;
}

// The worst error over the sun elevations.
StudyError WorstError(const std::vector<Images>& a, const std::vector<Images>& ref,
                      const std::vector<std::vector<char>>& masks) {
  StudyError worst;
  for (size_t s = 0; s < ref.size(); ++s) {
    StudyError e = Compare(a[s], ref[s], masks);
    worst.mean = std::max(worst.mean, e.mean);
    worst.rmse = std::max(worst.rmse, e.rmse);
  }
  return worst;
}

std::vector<CloudQuality> MarchCases(bool quick) {
  std::vector<CloudQuality> cases;
  if (quick) {
    cases.push_back(MakeQuality(8, 2, 32, 16, 64));
    cases.push_back(MakeQuality(48, 6, 32, 16, 64));
    return cases;
  }
  // The steps at the production volumes (64/32/256): a low Sun's light
  // crosses the layer over kilometres, so light steps matter as much as
  // view steps.
  for (int view : {16, 32, 48, 64, 96})
    for (int light : {6, 12, 24}) cases.push_back(MakeQuality(view, light, 64, 32, 256));
  for (int view : {16, 48}) cases.push_back(MakeQuality(view, 3, 64, 32, 256));
  cases.push_back(MakeQuality(24, 12, 64, 32, 256));
  for (int view : {32, 48, 64}) cases.push_back(MakeQuality(view, 16, 64, 32, 256));
  // The draft volumes (48/24/128) with the cheaper steps, the reference
  // volumes (128/64/512) with the dearer ones.
  for (int view : {24, 32, 48})
    for (int light : {6, 12}) cases.push_back(MakeQuality(view, light, 48, 24, 128));
  for (auto [view, light] : {std::pair{64, 24}, {96, 24}, {128, 24}, {192, 24}, {96, 32}, {128, 32}, {192, 32}})
    cases.push_back(MakeQuality(view, light, 128, 64, 512));
  // One volume or the octaves changed from 48/12 at the production volumes.
  for (int shape : {32, 128}) cases.push_back(MakeQuality(48, 12, shape, 32, 256));
  cases.push_back(MakeQuality(48, 12, 64, 16, 256));
  cases.push_back(MakeQuality(48, 12, 64, 32, 128));
  for (int octaves : {2, 4}) cases.push_back(MakeQuality(48, 12, 64, 32, 256, octaves));
  // The light march's far samples at the nearest voxel
  // (quality.cloud_light_trilinear_steps): the first k trilinear.
  for (auto [view, light, trilinear] : {std::tuple{48, 24, 4},
                                        {48, 24, 8},
                                        {48, 24, 12},
                                        {24, 12, 3},
                                        {24, 12, 6},
                                        {32, 16, 4},
                                        {32, 24, 6},
                                        {48, 16, 4}}) {
    CloudQuality q = MakeQuality(view, light, 64, 32, 256);
    q.light_trilinear_steps = trilinear;
    cases.push_back(q);
  }
  // The light volume (quality.cloud_light_volume_*): columns / slices / exact
  // near steps, at production's and draft's steps.
  for (auto [view, light, trilinear, columns, slices, near] : {std::tuple{48, 24, 8, 512, 32, 2},
                                                               {48, 24, 8, 512, 16, 2},
                                                               {48, 24, 8, 384, 16, 2},
                                                               {48, 24, 8, 256, 32, 2},
                                                               {48, 24, 8, 256, 16, 2},
                                                               {48, 24, 8, 256, 16, 1},
                                                               {48, 24, 8, 512, 32, 0},
                                                               {48, 24, 8, 1024, 32, 2},
                                                               {24, 12, 3, 256, 16, 1},
                                                               {24, 12, 3, 512, 32, 2}}) {
    CloudQuality q = MakeQuality(view, light, 64, 32, 256);
    q.light_trilinear_steps = trilinear;
    q.light_volume_columns = columns;
    q.light_volume_slices = slices;
    q.light_volume_near_steps = near;
    cases.push_back(q);
  }
  return cases;
}

// The relative scatter of a case's CPU time per megapixel between runs on
// the shared machine (load 18-22: 48/12 at 6.7k-7.9k ms with other volumes
// whose cost is the same).
constexpr double kCloudTimeNoise = 0.10;

std::string Fixed(double v, int digits) { return fmt::format("{:.{}f}", v, digits); }

}  // namespace

std::vector<CloudPresetChoice> CloudPresetBounds() {
  return {{"draft", 0.10, -1}, {"production", 0.05, -1}, {"reference", 0.01, -1}};
}

namespace {

// What every stage of the study reads: its options, the renderers, the suns
// and the latlong every march case is measured on.
struct Study {
  Study(const CloudStudyOptions& o, Renderers& r) : options(o), renderers(r) {}
  const CloudStudyOptions& options;
  Renderers& renderers;
  int height = 0;       // rows of the latlong
  int timing_runs = 0;  // timed renders per case
  std::vector<glm::dvec3> suns;
  std::vector<ViewRequest> latlong;
  std::vector<std::vector<char>> latlong_masks;

  void Say(const std::string& text) const {
    if (options.progress) options.progress(text);
  }
};

Study SetUpStudy(const CloudStudyOptions& options, const Scene& scene, Renderers& renderers, CloudStudyResult& result) {
  Study study(options, renderers);
  study.height = options.latlong_height > 0 ? options.latlong_height : (options.quick ? 24 : 128);
  study.timing_runs = options.timing_runs > 0 ? options.timing_runs : (options.quick ? 1 : 2);
  result.latlong_height = study.height;
  // A high sun and a low one (long light paths through the layer, long view
  // paths through the air), the Sun's azimuth of the style.
  result.sun_elevations_deg = options.quick ? std::vector<double>{45.0} : std::vector<double>{45.0, 10.0};
  for (double e : result.sun_elevations_deg)
    study.suns.push_back(SunDirectionFromElevationAzimuth(e, scene.style.sun.azimuth_deg));
  study.latlong = {ViewRequest{MAPPING_LATLONG, 2 * study.height, study.height, 0}};
  study.latlong_masks = SkyMasks(study.latlong);
  return study;
}

// The reference's renders of the latlong at every sun.
Renders RenderReference(const Study& study, CloudStudyResult& result) {
  result.reference = study.options.quick ? MakeQuality(128, 24, 32, 16, 64) : MakeQuality(384, 64, 128, 64, 512);
  const CloudQuality& ref = result.reference;
  study.Say(fmt::format("clouds: reference {} on a {} x {} latlong, {} sun elevation(s)", CaseName(ref),
                        2 * study.height, study.height, study.suns.size()));
  return RenderCase(study.renderers, ref, study.suns, study.latlong, 0);
}

// The reference with its volumes' edges times num / den.
std::pair<std::string, CloudQuality> VolumesChange(const CloudQuality& ref, int num, int den) {
  CloudQuality q = ref;
  for (int* edge : {&q.shape_resolution, &q.detail_resolution, &q.weather_resolution}) *edge = *edge * num / den;
  return {fmt::format("volumes {}/{}/{} -> {}/{}/{}", ref.shape_resolution, ref.detail_resolution,
                      ref.weather_resolution, q.shape_resolution, q.detail_resolution, q.weather_resolution),
          q};
}

// The reference with one setting changed at a time: its steps halved and
// (full study) its volumes halved and doubled (the volumes are the model's
// noise sampled at their voxels, so the finer side shows how far 128/64/512
// is from the continuous noise), its octaves doubled.
std::vector<std::pair<std::string, CloudQuality>> ConvergenceChanges(const CloudQuality& ref, bool quick) {
  std::vector<std::pair<std::string, CloudQuality>> changes;
  CloudQuality q = ref;
  q.view_steps /= 2;
  changes.emplace_back(fmt::format("view steps {} -> {}", ref.view_steps, q.view_steps), q);
  q = ref;
  q.light_steps /= 2;
  changes.emplace_back(fmt::format("light steps {} -> {}", ref.light_steps, q.light_steps), q);
  if (quick) return changes;
  changes.push_back(VolumesChange(ref, 1, 2));
  changes.push_back(VolumesChange(ref, 2, 1));
  q = ref;
  q.octaves = 16;
  changes.emplace_back("octaves 8 -> 16", q);
  return changes;
}

void MeasureConvergence(const Study& study, const Renders& reference, CloudStudyResult& result) {
  for (const auto& [change, q] : ConvergenceChanges(result.reference, study.options.quick)) {
    Renders r = RenderCase(study.renderers, q, study.suns, study.latlong, 0);
    StudyError e = WorstError(r.per_sun, reference.per_sun, study.latlong_masks);
    result.convergence.push_back({change, e.mean, e.rmse});
    study.Say(fmt::format("clouds: reference with {}: {:.2e} from it", change, e.mean));
  }
}

// The march settings on the latlong (marched texel by texel), timed.
void MeasureMarchCases(const Study& study, const Renders& reference, CloudStudyResult& result) {
  for (const CloudQuality& q : MarchCases(study.options.quick)) {
    const std::string name = CaseName(q);
    if (!study.options.only.empty() && name.find(study.options.only) == std::string::npos) continue;
    Renders r = RenderCase(study.renderers, q, study.suns, study.latlong, study.timing_runs);
    StudyError e = WorstError(r.per_sun, reference.per_sun, study.latlong_masks);
    result.cases.push_back({name, q, e.mean, e.rmse, r.ms_per_mp, r.cpu_ms_per_mp, false});
    study.Say(fmt::format("clouds: {:<28} {:8.0f} CPU ms/MP {:8.0f} GPU ms/MP  mean error {:.2e}  RMSE {:.2e}", name,
                          r.cpu_ms_per_mp, r.ms_per_mp, e.mean, e.rmse));
  }
}

// Each preset: the cheapest case of the front within its bound; the front's
// cases within kCloudTimeNoise of that one's time are ties (the CPU time
// of one case repeated scatters by that much on the shared machine), and
// the tie with the lowest error is chosen.
void ChoosePresets(CloudStudyResult& result) {
  result.presets = CloudPresetBounds();
  for (CloudPresetChoice& p : result.presets) {
    int cheapest = -1;
    for (size_t i = 0; i < result.cases.size(); ++i) {
      const CloudStudyCase& c = result.cases[i];
      if (c.pareto && c.mean_error <= p.bound &&
          (cheapest < 0 || c.cpu_ms_per_mp < result.cases[size_t(cheapest)].cpu_ms_per_mp))
        cheapest = int(i);
    }
    p.choice = cheapest;
    if (cheapest < 0) continue;
    const double limit = (1.0 + kCloudTimeNoise) * result.cases[size_t(cheapest)].cpu_ms_per_mp;
    for (size_t i = 0; i < result.cases.size(); ++i) {
      const CloudStudyCase& c = result.cases[i];
      if (c.pareto && c.mean_error <= p.bound && c.cpu_ms_per_mp <= limit &&
          c.mean_error < result.cases[size_t(p.choice)].mean_error)
        p.choice = int(i);
    }
  }
}

// The panorama: a bake's views (the latlong and six faces of half its
// height, as W3), the clouds marched once into a panorama of `scale` times
// the finest view's height and resampled, against every view marched at
// the reference's steps.
void MeasurePanorama(const Study& study, CloudStudyResult& result) {
  std::vector<ViewRequest> views = study.latlong;
  for (int face = 0; face < 6; ++face)
    views.push_back(ViewRequest{MAPPING_VULKAN_FACE, study.height / 2, study.height / 2, face});
  const auto masks = SkyMasks(views);
  auto panorama_name = [](double scale) {
    return scale > 0.0 ? fmt::format("panorama {} x the finest view", scale) : std::string("every view marched");
  };
  const CloudStudyOptions& options = study.options;
  std::vector<double> scales;
  for (double scale : options.quick ? std::vector<double>{0.0, 1.0} : std::vector<double>{0.0, 0.5, 0.75, 1.0})
    if (options.only.empty() || panorama_name(scale).find(options.only) != std::string::npos) scales.push_back(scale);
  const Renders marched_ref =
      scales.empty() ? Renders{} : RenderCase(study.renderers, result.reference, study.suns, views, 0);
  const CloudQuality production = options.quick ? MakeQuality(48, 6, 32, 16, 64) : CloudQualityPreset("production");
  for (double scale : scales) {
    CloudQuality q = production;
    q.panorama_scale = scale;
    const std::string name = panorama_name(scale);
    Renders r = RenderCase(study.renderers, q, study.suns, views, study.timing_runs);
    StudyError e = WorstError(r.per_sun, marched_ref.per_sun, masks);
    result.panorama.push_back({name, q, e.mean, e.rmse, r.ms_per_mp, r.cpu_ms_per_mp, false});
    study.Say(fmt::format("clouds: {:<28} {:8.0f} CPU ms/MP {:8.0f} GPU ms/MP  mean error {:.2e}", name,
                          r.cpu_ms_per_mp, r.ms_per_mp, e.mean));
  }
}

// cloud_study.csv: every march case, then every panorama case.
void WriteCasesCsv(const std::string& out_dir, const CloudStudyResult& result) {
  std::ostringstream csv;
  csv << "case,view_steps,light_steps,octaves,shape_resolution,detail_resolution,weather_resolution,"
         "panorama_scale,cpu_ms_per_megapixel,gpu_ms_per_megapixel,mean_relative_error,relative_rmse,pareto\n";
  for (const auto* list : {&result.cases, &result.panorama})
    for (const CloudStudyCase& c : *list)
      csv << fmt::format("{},{},{},{},{},{},{},{},{:.6g},{:.6g},{:.6g},{:.6g},{}\n", c.name, c.quality.view_steps,
                         c.quality.light_steps, c.quality.octaves, c.quality.shape_resolution,
                         c.quality.detail_resolution, c.quality.weather_resolution, c.quality.panorama_scale,
                         c.cpu_ms_per_mp, c.ms_per_mp, c.mean_error, c.rmse, c.pareto ? 1 : 0);
  WriteFileAtomically(out_dir + "/cloud_study.csv", csv.str());
}

// cloud_study.png, the march cases and their front, through gnuplot; what
// became of it, for the report.
std::string WritePlot(const std::string& out_dir, const std::vector<CloudStudyCase>& cases) {
  if (cases.empty()) return "not written (no case)";
  std::vector<PlotPoint> points;
  for (const CloudStudyCase& c : cases)
    points.push_back({std::max(c.cpu_ms_per_mp, 1e-3), c.mean_error, c.pareto, c.name});
  return PlotParetoFront(out_dir, "cloud_study", points,
                         {"CPU time of a render per megapixel (ms, lavapipe, all threads)",
                          "mean relative error, sky half, worst sun elevation",
                          "skybake clouds: what accuracy costs (W3 layer vs converged reference)"});
}

// The report's first tables: the scene, the reference's convergence, the
// march cases.
std::string CasesMarkdown(const CloudStudyResult& result) {
  const int height = result.latlong_height;
  const CloudQuality& ref = result.reference;
  std::string elevations;
  for (double e : result.sun_elevations_deg) elevations += (elevations.empty() ? "" : ", ") + fmt::format("{}", e);
  std::string md;
  md += fmt::format(
      "## Clouds: W3's layer on a {} x {} latlong, sun elevations {} deg (worst of them), texels above the horizon\n\n",
      2 * height, height, elevations);
  md += fmt::format(
      "Reference: {} view / {} light steps, volumes {}/{}/{} (shape/detail/weather), {} octaves. Its "
      "convergence, each setting halved (the mean relative difference from the reference):\n\n",
      ref.view_steps, ref.light_steps, ref.shape_resolution, ref.detail_resolution, ref.weather_resolution,
      ref.octaves);
  md += "| change | mean relative difference | relative RMSE |\n| --- | ---: | ---: |\n";
  for (const CloudConvergence& c : result.convergence)
    md += fmt::format("| {} | {:.2e} | {:.2e} |\n", c.change, c.mean_error, c.rmse);
  md +=
      "\n| case (view/light steps, volumes shape/detail/weather) | CPU ms per megapixel | cloud passes' GPU ms "
      "per megapixel | mean relative error | relative RMSE | Pareto |\n| --- | ---: | ---: | ---: | ---: | :---: |\n";
  for (const CloudStudyCase& c : result.cases)
    md += fmt::format("| {} | {} | {} | {:.2e} | {:.2e} | {} |\n", c.name, Fixed(c.cpu_ms_per_mp, 0),
                      Fixed(c.ms_per_mp, 0), c.mean_error, c.rmse, c.pareto ? "yes" : "");
  return md;
}

// The presets' table, then the panorama's.
std::string PresetsAndPanoramaMarkdown(const CloudStudyResult& result) {
  std::string md = fmt::format(
      "\n### Cloud presets chosen from the front\n\nThe cheapest case of the front within each bound; cases of the "
      "front within {:g}% of its CPU time are ties, and the lowest error among them is chosen.\n\n",
      kCloudTimeNoise * 100);
  md +=
      "| preset | bound (mean relative error) | case | mean relative error | "
      "CPU ms per megapixel |\n| --- | --- | --- | ---: | ---: |\n";
  for (const CloudPresetChoice& p : result.presets) {
    if (p.choice >= 0) {
      const CloudStudyCase& c = result.cases[size_t(p.choice)];
      md += fmt::format("| `{}` | <= {:g}% | {} | {:.2e} | {} |\n", p.preset, p.bound * 100, c.name, c.mean_error,
                        Fixed(c.cpu_ms_per_mp, 0));
    } else {
      md += fmt::format("| `{}` | <= {:g}% | none of the cases meets it | | |\n", p.preset, p.bound * 100);
    }
  }
  md += fmt::format(
      "\n### The panorama (production steps; the latlong and six {}^2 faces; against every view marched at the "
      "reference's steps; time per megapixel of all the views)\n\n| case | CPU ms per megapixel | cloud passes' GPU ms "
      "per megapixel | mean relative error | relative RMSE |\n| --- | ---: | ---: | ---: | ---: |\n",
      result.latlong_height / 2);
  for (const CloudStudyCase& c : result.panorama)
    md += fmt::format("| {} | {} | {} | {:.2e} | {:.2e} |\n", c.name, Fixed(c.cpu_ms_per_mp, 0), Fixed(c.ms_per_mp, 0),
                      c.mean_error, c.rmse);
  return md;
}

}  // namespace

CloudStudyResult RunCloudStudy(VulkanContext& vulkan, const CloudStudyOptions& options) {
  std::filesystem::create_directories(options.out_dir);
  const Scene scene = StudyScene();
  Renderers renderers(vulkan, scene);
  CloudStudyResult result;
  const Study study = SetUpStudy(options, scene, renderers, result);
  // 1. The reference and its convergence: each setting changed in turn.
  const Renders reference = RenderReference(study, result);
  MeasureConvergence(study, reference, result);
  // 2. The march settings on one latlong, their Pareto front and the presets
  // chosen from it.
  MeasureMarchCases(study, reference, result);
  MarkParetoFront(result.cases, &CloudStudyCase::cpu_ms_per_mp, &CloudStudyCase::mean_error);
  ChoosePresets(result);
  // 3. The panorama sizes on a bake's views.
  MeasurePanorama(study, result);
  // 4. Files: the CSV, the plot, the report.
  WriteCasesCsv(options.out_dir, result);
  const std::string plot_status = WritePlot(options.out_dir, result.cases);
  result.markdown = CasesMarkdown(result) + PresetsAndPanoramaMarkdown(result) +
                    fmt::format("\nPlot {}: {}/cloud_study.png\n", plot_status, options.out_dir);
  WriteFileAtomically(options.out_dir + "/cloud_study_results.md", result.markdown);
  return result;
}

std::string RunCloudQualityStudy(StudyContext& context) {
  CloudStudyOptions options;
  options.out_dir = context.options.out_dir;
  options.quick = context.options.quick;
  options.only = context.options.only;
  options.progress = context.options.progress;
  return RunCloudStudy(context.vulkan, options).markdown;
}

}  // namespace skybake
