// The parameters of the aesthetic principles (aoas.glsl), in the common
// GLSL/C++ subset: apart from the functions so that the C++ side can declare
// those (include/skybake/model/shared_glsl.h) without compiling them again.
#ifndef SKYBAKE_AOAS_PARAMETERS_GLSL
#define SKYBAKE_AOAS_PARAMETERS_GLSL

struct AoasParameters {
  Real dome_radius;              // R, scene units (> 0)
  vec3 viewer_position;          // P^s_v, scene units, inside the dome
  Real l_pt;                     // perturbation neighbourhood half size, dome radii
  Real perturbation_grain;       // feature size of the random field rand(), dome radii
  vec3 perturbation_offset;      // seed offset of rand(), noise space
  Real s_noise;                  // cloud noise feature size S_noise, dome radii
  int noise_octaves;             // fractal octaves, >= 1
  Real noise_threshold;          // noise below this makes no cloud, in [-1, 1)
  Real noise_strength;           // 0: no cloud, 1: noise peaks fully desaturated
  vec3 noise_offset;             // drift + seed offset, noise space
  Real shape_strength;           // scales every shape's strength
  int shape_segment_count;       // segments read through the hooks
  vec3 color_scale;              // radiance -> RGB in which saturation is judged
  bool skydome;                  // eq. 1-2: viewer position and Earth-space transform
  bool ambiguity;                // eq. 5-6: perturbed view directions
  bool cloud_noise;              // eq. 7-8: Improved Perlin noise on saturation
  bool cloud_shapes;             // user points / polylines fading linearly
};

#endif  // SKYBAKE_AOAS_PARAMETERS_GLSL
