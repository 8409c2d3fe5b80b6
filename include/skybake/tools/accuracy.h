// What accuracy costs in time: the single-scattering integral computed by
// every integrator and sample count on the GPU, measured against a converged
// double-precision reference, timed on this machine; and the model against
// the measured skies of Kider et al. 2014 with Bruneton's RMSE protocol.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "skybake/model/atmosphere.h"

namespace skybake {

// Single scattering (no multiple scattering, no ground, no disc) in double
// precision with composite 8-point Gauss-Legendre quadrature on the view ray
// and on every sun ray. Both rays are split where the integrand is not smooth
// (the ozone tent's corners, the sun ray's closest approach to the ground,
// the planet's shadow on the view ray); `segment_km` is the longest
// sub-segment. Halving it is how the reference shows its own convergence.
class ConvergedReference {
 public:
  ConvergedReference(const AtmosphereParams& atmosphere, double segment_km);
  // Radiance along `view` for the Sun along `sun`, in the units of
  // solar_irradiance per steradian.
  glm::dvec3 Radiance(const glm::dvec3& view, const glm::dvec3& sun) const;
  // Transmittance from altitude (km) to the top of the atmosphere along mu.
  glm::dvec3 Transmittance(double altitude_km, double mu) const;

 private:
  AtmosphereParams atmosphere_;
  double segment_km_;
};

// Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_n).
void GaussLegendre(int n, std::vector<double>& nodes, std::vector<double>& weights);

struct AccuracyStudyOptions {
  std::string out_dir = "docs";  // accuracy.md, accuracy.csv, accuracy.png, kider2014.csv
  std::string shared_dir = "../shared";
  bool quick = false;                // fewer cases and directions (for tests)
  double observer_altitude_m = 0.0;  // the study's observer (0 m and 8000 m in docs/accuracy.md)
  std::string only;                  // when set, only the cases whose name contains it
  std::string study =
      "all";  // "sky" (integrators, Kider 2014), "clouds" (tools/cloud_study.h), "spectral", "twilight" or "all"
  std::function<void(const std::string&)> progress;
};

// Runs the whole study and writes its files. Returns the markdown report.
std::string RunAccuracyStudy(const AccuracyStudyOptions& options);

}  // namespace skybake
