// The LUT hooks of a test's own instantiation of the shared GLSL, for the
// precisions shared_glsl.h does not offer (float beside double) and the
// functions it does not declare: a transmittance of 1, no multiple
// scattering, an empty sky-view LUT; the geometry, medium and noise
// functions the tests call never read them. Include inside a namespace after
// defining SKYBAKE_REAL, then include the .glsl files; no include guard, on
// purpose (one copy per instantiation, as glsl_compat.h).
#include "skybake/model/glsl_compat.h"

vec3 TransmittanceLutTexel(int, int) { return vec3(Real(1)); }
vec3 MultipleScatteringLutTexel(int, int) { return vec3(Real(0)); }
vec3 SkyViewLutTexel(int, int) { return vec3(Real(0)); }
