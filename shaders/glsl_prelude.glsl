// GLSL side of the common GLSL/C++ subset used by the shared physics files
// (atmosphere.glsl, envmap.glsl). The C++ side of the same subset is
// include/skybake/model/glsl_compat.h, which defines the same names with double precision.
//
// Rules of the subset:
//   - scalars are `Real`, vectors are vec2/vec3/vec4 of Real;
//   - parameters are passed with IN(T) (read-only) or OUT(T) (written);
//   - structs are declared, then filled field by field (no constructors);
//   - no samplers, images or buffers: each side defines the LUT fetch
//     functions the shared code calls (see "Hooks" in atmosphere.glsl).
#ifndef SKYBAKE_GLSL_PRELUDE
#define SKYBAKE_GLSL_PRELUDE

#define Real float
#define IN(T) in T
#define OUT(T) out T
#define CONST_REAL const float

#endif
