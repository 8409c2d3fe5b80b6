// What the accuracy studies share (study.h).
#include "study.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include <fmt/format.h>

#include "skybake/gpu/sky_renderer.h"
#include "skybake/model/tonemap.h"
#include "skybake/output/exr_io.h"

namespace skybake {

std::string IntegratorName(int integrator) {
  switch (integrator) {
    case INTEGRATOR_MIDPOINT:
      return "midpoint";
    case INTEGRATOR_TRAPEZOID:
      return "trapezoid";
    case INTEGRATOR_SIMPSON:
      return "simpson";
    default:
      return "analytic";
  }
}

StudyCase MakeCase(int integrator, int view, int light, bool sky_view, int sw, int sh, int steps) {
  StudyCase c;
  c.quality.step_distribution = steps;
  c.quality.integrator = integrator;
  c.quality.view_steps = view;
  c.quality.light_steps = light;
  c.quality.sky_view_lut = sky_view;
  if (sky_view) {
    c.quality.sky_view_width = sw;
    c.quality.sky_view_height = sh;
  }
  c.name = IntegratorName(integrator) + " " + std::to_string(view) + "/" +
           (light > 0 ? std::to_string(light) : std::string("LUT"));
  if (steps == STEPS_QUADRATIC) c.name += " quadratic";
  if (sky_view) c.name += fmt::format(" sky-view {}x{}", sw, sh);
  return c;
}

glm::dvec3 DisplayLab(const glm::dvec3& radiance, const Rgb& to_luminance, double exposure) {
  glm::dvec3 lin;
  for (int c = 0; c < 3; ++c) lin[c] = AcesFilmic(radiance[c] * to_luminance[c] * exposure);
  // Linear sRGB -> XYZ (IEC 61966-2-1), white D65.
  double X = 0.4124 * lin.x + 0.3576 * lin.y + 0.1805 * lin.z;
  double Y = 0.2126 * lin.x + 0.7152 * lin.y + 0.0722 * lin.z;
  double Z = 0.0193 * lin.x + 0.1192 * lin.y + 0.9505 * lin.z;
  auto f = [](double t) { return t > 216.0 / 24389.0 ? std::cbrt(t) : (24389.0 / 27.0 * t + 16.0) / 116.0; };
  double fx = f(X / 0.95047), fy = f(Y / 1.0), fz = f(Z / 1.08883);
  return {116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)};
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

double TimePerMegapixel(VulkanContext& vulkan, const AtmosphereParams& atmosphere, const QualitySettings& quality,
                        const EffectSettings& effects, double sun_elevation_deg) {
  SkyRenderer renderer(vulkan, atmosphere, quality, effects, {1, 1, 1});
  renderer.PrecomputeLuts();
  double cost = double(quality.view_steps + 1) * double(std::max(quality.light_steps, 1));
  if (quality.sky_view_lut) cost = 4.0;
  int height = int(std::clamp(std::sqrt(4e8 / cost / 2.0), 32.0, 512.0));
  ViewRequest view{MAPPING_LATLONG, 2 * height, height, 0};
  std::vector<double> samples;
  for (int run = 0; run < 3; ++run) {
    // A new sun per run, as per frame of a time-lapse: a sky-view LUT is
    // rebuilt and counted in the frame's time.
    renderer.Render(SunDirectionFromElevationAzimuth(sun_elevation_deg + 0.5 * run, 180.0), {view});
    double ms = 0.0;
    for (const PassTiming& t : renderer.last_timings()) ms += t.gpu_ms;
    samples.push_back(ms / (2.0 * height * height * 1e-6));
  }
  return Median(samples);
}

std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream s(line);
  std::string field;
  while (std::getline(s, field, ',')) out.push_back(field);
  return out;
}

std::string PlotParetoFront(const std::string& out_dir, const std::string& stem, const std::vector<PlotPoint>& points,
                            const PlotLabels& labels) {
  std::ostringstream data, front;
  for (const PlotPoint& p : points)
    data << fmt::format("{:.6g} {:.6g} {} \"{}\"\n", p.cost, std::max(p.error, 1e-7), p.pareto ? 1 : 0, p.name);
  std::vector<const PlotPoint*> sorted;
  for (const PlotPoint& p : points)
    if (p.pareto) sorted.push_back(&p);
  std::sort(sorted.begin(), sorted.end(), [](auto a, auto b) { return a->cost < b->cost; });
  for (const PlotPoint* p : sorted) front << fmt::format("{:.6g} {:.6g}\n", p->cost, std::max(p->error, 1e-7));
  const std::string base = out_dir + "/" + stem;
  std::ostringstream plot;
  plot << "set terminal pngcairo size 1100,750 noenhanced\n"
       << "set output '" << base << ".png'\n"
       << "set logscale xy\nset grid\n"
       << "set xlabel '" << labels.x << "'\n"
       << "set ylabel '" << labels.y << "'\n"
       << "set title '" << labels.title << "'\n"
       << "set key top right\n"
       << "plot '" << base << "_front.dat' using 1:2 with lines lw 2 lc rgb '#cc3333' title 'Pareto front', \\\n"
       << "     '" << base << "_plot.dat' using 1:2:3 with points pt 7 ps 1.2 lc variable title 'cases', \\\n"
       << "     '" << base << "_plot.dat' using 1:2:4 with labels offset 0.5,0.5 left font ',7' notitle\n";
  WriteFileAtomically(base + "_plot.dat", data.str());
  WriteFileAtomically(base + "_front.dat", front.str());
  WriteFileAtomically(base + ".gnuplot", plot.str());
  if (std::system(fmt::format("gnuplot '{}.gnuplot' 2>/dev/null", base).c_str()) != 0)
    return "not written (gnuplot missing: apt-get install gnuplot-nox)";
  return "written";
}

}  // namespace skybake
