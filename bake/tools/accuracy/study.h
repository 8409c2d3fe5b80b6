// The parts of the accuracy study (`skybake accuracy`, tools/accuracy.h) and
// what they share. `RunAccuracyStudy` (accuracy.cc) opens the Vulkan context
// once and runs each study in turn; each study is a file of its own with one
// function `std::string RunXStudy(StudyContext&)` that computes, writes its
// own files into the output folder and returns its markdown sections. A new
// study (clouds, spectral) is one more such file, declared here, and one call
// in RunAccuracyStudy. Private to the accuracy library.
#pragma once

#include <algorithm>
#include <string>
#include <thread>
#include <vector>

#include <glm/vec3.hpp>

#include "skybake/gpu/vulkan_context.h"
#include "skybake/model/atmosphere.h"
#include "skybake/tools/accuracy.h"

namespace skybake {

// What every study is given: the options, the one Vulkan context, and the
// lines for the report's end (where each plot went), in the order added.
struct StudyContext {
  const AccuracyStudyOptions& options;
  VulkanContext& vulkan;
  std::vector<std::string> notes;

  void Say(const std::string& text) const {
    if (options.progress) options.progress(text);
  }
  // `name` in the output folder.
  std::string OutPath(const std::string& name) const { return options.out_dir + "/" + name; }
};

// The studies, in the order of the report.
// Every integrator and sample count against the converged reference, timed:
// accuracy.csv, accuracy.png (and its gnuplot inputs); the tables of cases,
// presets and the reference's convergence.
std::string RunIntegratorStudy(StudyContext& context);
// The model against the measured skies of Kider et al. 2014: kider2014.csv
// and its table.
std::string RunKiderStudy(StudyContext& context);
// The spectral mode: colour error of 3, 4, 8, 16 wavelengths against 48 bins
// and their cost, twilight pictures (skybake/tools/spectral_study.h).
std::string RunSpectralStudy(StudyContext& context);
// The cloud settings against a converged cloud march (tools/cloud_study.h):
// cloud_study.csv, cloud_study.png; the tables of cases, the reference's
// convergence, the cloud presets and the panorama sizes.
std::string RunCloudQualityStudy(StudyContext& context);
// The presets and the sky-view variants tried at twilight (sun 3 .. -10 deg)
// against the converged reference, timed: twilight.csv and its table.
std::string RunTwilightStudy(StudyContext& context);
// Kider 2014 with Bruneton's protocol as published: 31 wavelengths
// 360..712.5 nm (kider2014_spectral.csv) beside Galaj & Wojciechowski's table.
std::string RunKiderSpectralStudy(StudyContext& context);

// One GPU configuration of a study, by name ("simpson 64/LUT quadratic").
struct StudyCase {
  std::string name;
  QualitySettings quality;
};

std::string IntegratorName(int integrator);
// A case with `view` steps on the view ray and `light` on each sun ray (0:
// the transmittance LUT), the sky-view LUT at sw x sh when `sky_view`.
StudyCase MakeCase(int integrator, int view, int light, bool sky_view = false, int sw = 0, int sh = 0,
                   int steps = STEPS_UNIFORM);

// fn(i) for i in [0, n) on every hardware thread.
template <class Fn>
void ParallelIndices(size_t n, Fn fn) {
  unsigned threads = std::max(1u, std::thread::hardware_concurrency());
  std::vector<std::thread> pool;
  for (unsigned t = 0; t < threads; ++t)
    pool.emplace_back([&, t] {
      for (size_t i = t; i < n; i += threads) fn(i);
    });
  for (auto& th : pool) th.join();
}

// CIE L*a*b* (D65) of a display sRGB colour after exposure and ACES.
glm::dvec3 DisplayLab(const glm::dvec3& radiance, const Rgb& to_luminance, double exposure);

double Median(std::vector<double> v);

// GPU time of one render per megapixel (lavapipe, GPU timestamps, median of
// 3 renders, each with its Sun moved 0.5 deg from `sun_elevation_deg`), with a
// latlong sized to the cost.
double TimePerMegapixel(VulkanContext& vulkan, const AtmosphereParams& atmosphere, const QualitySettings& quality,
                        const EffectSettings& effects, double sun_elevation_deg = 45.0);

std::vector<std::string> SplitCsv(const std::string& line);

// Sets `pareto` of each case: on the front of (cost, error) when no other
// case is as cheap and as accurate and better in one of the two.
template <class Case>
void MarkParetoFront(std::vector<Case>& cases, double Case::*cost, double Case::*error) {
  for (Case& c : cases) {
    c.pareto = true;
    for (const Case& o : cases)
      if (&o != &c && o.*cost <= c.*cost && o.*error <= c.*error && (o.*cost < c.*cost || o.*error < c.*error))
        c.pareto = false;
  }
}

// One case of a study on its (cost, error) plot.
struct PlotPoint {
  double cost = 0.0;   // the x axis (log scale: above 0)
  double error = 0.0;  // the y axis, drawn at 1e-7 at the least
  bool pareto = false;
  std::string name;
};
// The axes' and the plot's titles.
struct PlotLabels {
  std::string x, y, title;
};
// A study's cases and their Pareto front on log-log axes, through gnuplot:
// STEM_plot.dat, STEM_front.dat and STEM.gnuplot written into `out_dir`,
// which draw STEM.png there. Returns what became of the plot: "written", or
// "not written (...)" and why.
std::string PlotParetoFront(const std::string& out_dir, const std::string& stem, const std::vector<PlotPoint>& points,
                            const PlotLabels& labels);

}  // namespace skybake
