// A sky style, resolved: the physical atmosphere, the sun, the render and
// output settings, the aesthetic principles and the cloud layers. Read from
// TOML by config.h; every key and its default is in configs/default.toml.
#pragma once

#include <string>

#include "skybake/input/night_settings.h"
#include "skybake/input/output_settings.h"
#include "skybake/model/aoas.h"
#include "skybake/model/atmosphere.h"
#include "skybake/model/cloud_shadow.h"
#include "skybake/model/clouds.h"

namespace skybake {

struct SunSettings {
  double elevation_deg = 45.0;  // above the horizon
  double azimuth_deg = 135.0;   // clockwise from North
};

struct RenderSettings {
  int cube_size = 512;       // cube face edge, texels
  int latlong_height = 512;  // latlong is 2 x height by height
  int device = -1;           // Vulkan device index; -1 = best available
};

struct SkyStyle {
  AtmosphereParams atmosphere;
  std::string quality_preset = "production";  // see QualityPreset()
  QualitySettings quality;
  EffectSettings effects;
  SunSettings sun;
  RenderSettings render;
  OutputSettings output;
  PreviewSettings preview;
  AoasSettings aoas;                 // the aesthetic principles (skydome, hue, ambiguity, clouds, shapes)
  CloudSettings clouds;              // volumetric [[cloud_layer]] tables and their sampling (clouds.h)
  CloudShadowSettings cloud_shadow;  // [cloud_shadow]: the frame's cloud shadow map (cloud_shadow.h)
  GltfSettings gltf;
  UsdSettings usd;
  IblSettings ibl;
  NightSettings night;        // stars, the Moon, moonlight (pipeline/night_sky.h)
  std::string source_path;    // where it was read from
  std::string resolved_toml;  // every key with its final value, for provenance
};

// Per-channel factor from spectral radiance to the chosen output units.
Rgb OutputScale(OutputUnits units);

}  // namespace skybake
