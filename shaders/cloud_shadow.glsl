// Cloud shadows (include/skybake/model/cloud_shadow.h), after clouds.glsl: the
// optical depth of the clouds along the sun direction above a horizontal
// receiver, for the shadow map (cloud_shadow.comp) and for the ground the
// sky shows below the horizon (cloud_render.comp).
//
// Geometry: flat. Over a map's extent (tens of km) the planet's curvature
// would lower a layer by x^2 / 2R (18 m at 15 km from the centre); the flat
// column keeps the map periodic when the layers' tiles are, and makes the
// slant path of a layer of thickness H exactly H / cos(sun zenith).
#ifndef SKYBAKE_CLOUD_SHADOW_GLSL
#define SKYBAKE_CLOUD_SHADOW_GLSL

// Optical depth (dimensionless) from the receiver at horizontal world
// position `xz` and altitude `h0` (km) towards `sun` (sun.y > 0) through
// every band above it: `steps` midpoint samples per band crossing, the
// whole extinction (shape and detail) as the view march sees it.
float CloudShadowOpticalDepth(vec2 xz, float h0, vec3 sun, int steps) {
  float tau = 0.0;
  int bands = gpu_clouds.resolution.w;
  for (int b = 0; b < kCloudLayers; ++b) {
    if (b >= bands) continue;
    float lo = max(gpu_clouds.bands[b].x, h0), hi = gpu_clouds.bands[b].y;
    if (hi <= lo) continue;
    float dh = (hi - lo) / float(steps);
    float dt = dh / sun.y;  // path length per sample, km
    for (int k = 0; k < steps; ++k) {
      float h = lo + (float(k) + 0.5) * dh;
      vec2 p = xz + sun.xz * ((h - h0) / sun.y);
      tau += CloudExtinction(p, h, true) * dt;
    }
  }
  return tau;
}

// The sunlight the clouds take from the ground a texel shows (rays that hit
// the ground): (1 - T_shadow) x T_air x the ground's direct sunlit radiance
// (SunlitGroundSeen), per unit solar irradiance; 0 unless the style's
// cloud_shadow.ground is on (ground_shadow.x: the strength, .y: the steps), the
// ground is on and the Sun's centre is above the horizon.
// The pipelines of a style without it have it compiled out
// (kGroundCloudShadow): on lavapipe a branch not taken still runs, masked.
layout(constant_id = SPEC_GROUND_CLOUD_SHADOW) const bool kGroundCloudShadow = true;

vec3 GroundCloudShadowLoss(IN(AtmosphereParameters) atm, vec3 view, vec3 sun) {
  if (!kGroundCloudShadow) return vec3(0.0);
  if (gpu_clouds.ground_shadow.x <= 0.0 || !atm.ground || sun.y <= 0.0) return vec3(0.0);
  SkyRay ray = SetUpSkyRay(atm, view, sun);
  if (!ray.in_atmosphere || !ray.hits_ground || ray.altitude != atm.observer_altitude) return vec3(0.0);
  float t = ray.t_max;
  vec3 ground = vec3(0.0, ray.r, 0.0) + t * view;  // planet-centred, km
  float tau = CloudShadowOpticalDepth(ground.xz, 0.0, sun, int(gpu_clouds.ground_shadow.y));
  float lit = exp(-gpu_clouds.ground_shadow.x * tau);
  if (lit >= 1.0) return vec3(0.0);
  return (1.0 - lit) * SunlitGroundSeen(atm, ray);
}

#endif  // SKYBAKE_CLOUD_SHADOW_GLSL
