// Cirrus: the fibrous streaks of a `type = "cirrus"` layer (docs/clouds.md
// "Cirrus"), after clouds.glsl's spec constants; CloudPlaceOf
// (cloud_weather.glsl) calls it, so the density, the light march, the
// empty-space bounds and the shadow map all read the same streaks.
//
// Model: cirrus are thin ice clouds drawn out by the wind into long fibres,
// their fall streaks bent into hooks by the shear (cirrus uncinus). Here the
// layer's whole noise (weather, warp, shape and detail) is read in a frame
// squeezed along the streaks: a position's component along the unit vector
// `a` (the layer's mean wind, GpuCloudLayer.streaks.xy) is divided by the
// streak ratio R (streaks.z), so every feature of the noise is R times longer
// along the wind than across it. Before the squeeze, a point d km below the
// layer's top is moved along `a` by hook x d^2 (streaks.w, km^-1): crystals
// that fall at v_f from a head at the top through a wind that changes by s
// per km trail behind the head by s d^2 / (2 v_f) (the drift s z / v_f
// integrated over the fall), so the streaks bend with height.
//
// Units: km, world x and z (East = +X, North = -Z).
#ifndef SKYBAKE_CLOUD_CIRRUS_GLSL
#define SKYBAKE_CLOUD_CIRRUS_GLSL

// Where a cirrus layer reads its noise for world position q (km, the wind's
// offset already taken off) at altitude h (km).
vec2 CirrusStreakPosition(GpuCloudLayer layer, vec2 q, float h) {
  vec2 along = layer.streaks.xy;
  vec2 across = vec2(-along.y, along.x);
  float depth = max(layer.shell.y - h, 0.0);
  float a = (dot(q, along) + layer.streaks.w * depth * depth) / layer.streaks.z;
  return along * a + across * dot(q, across);
}

#endif  // SKYBAKE_CLOUD_CIRRUS_GLSL
