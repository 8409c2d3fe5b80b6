// C++ side of the common GLSL/C++ subset (the GLSL side is
// shaders/glsl_prelude.glsl). Include this inside a namespace, after defining
// SKYBAKE_REAL to the scalar type, and before including a shared .glsl file:
//
//   namespace skybake::reference {
//   #define SKYBAKE_REAL double
//   #include "skybake/model/glsl_compat.h"
//   ... hooks ...
//   #include "atmosphere.glsl"
//   }
//
// glm provides the GLSL vector types and built-in functions with GLSL names.
// Included once per instantiation on purpose: no include guard.
using Real = SKYBAKE_REAL;
static_assert(std::is_floating_point_v<Real>);
using vec2 = glm::vec<2, Real, glm::defaultp>;
using vec3 = glm::vec<3, Real, glm::defaultp>;
using vec4 = glm::vec<4, Real, glm::defaultp>;
using ivec2 = glm::ivec2;
using glm::abs;
using glm::acos;
using glm::asin;
using glm::atan;
using glm::clamp;
using glm::cos;
using glm::cross;
using glm::dot;
using glm::exp;
using glm::exp2;
using glm::floor;
using glm::greaterThan;
using glm::length;
using glm::log2;
using glm::max;
using glm::min;
using glm::mix;
using glm::normalize;
using glm::sin;
using glm::smoothstep;
using glm::sqrt;
// GLSL converts double literals to float implicitly; these overloads do the
// same for scalar built-ins when Real is float (mixed float/double arguments).
template <class A, class B>
inline Real max(A a, B b) requires(std::is_arithmetic_v<A>&& std::is_arithmetic_v<B> && !std::is_same_v<A, B>) {
  return glm::max(Real(a), Real(b));
}
template <class A, class B>
inline Real min(A a, B b) requires(std::is_arithmetic_v<A>&& std::is_arithmetic_v<B> && !std::is_same_v<A, B>) {
  return glm::min(Real(a), Real(b));
}
template <class A, class B, class C>
inline Real clamp(A x, B lo,
                  C hi) requires(std::is_arithmetic_v<A>&& std::is_arithmetic_v<B>&& std::is_arithmetic_v<C> &&
                                 !(std::is_same_v<A, B> && std::is_same_v<B, C>)) {
  return glm::clamp(Real(x), Real(lo), Real(hi));
}
template <class A, class B, class C>
inline Real smoothstep(A lo, B hi,
                       C x) requires(std::is_arithmetic_v<A>&& std::is_arithmetic_v<B>&& std::is_arithmetic_v<C> &&
                                     !(std::is_same_v<A, B> && std::is_same_v<B, C>)) {
  return glm::smoothstep(Real(lo), Real(hi), Real(x));
}
// GLSL multiplies a float vector by a double literal (the literal becomes
// float); glm needs the scalar type to match.
template <glm::length_t L>
inline glm::vec<L, float, glm::defaultp> operator*(double a, const glm::vec<L, float, glm::defaultp>& v) {
  return float(a) * v;
}
template <glm::length_t L>
inline glm::vec<L, float, glm::defaultp> operator*(const glm::vec<L, float, glm::defaultp>& v, double a) {
  return v * float(a);
}
#ifndef IN
#define IN(T) const T&
#define OUT(T) T&
#define CONST_REAL constexpr Real
#endif
