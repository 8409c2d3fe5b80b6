#include "cloud_formation_config.h"

#include <cmath>

#include <fmt/format.h>

namespace skybake {

void ReadCloudFormation(const toml::node& node, const std::string& path, CloudFormation& out,
                        const FormationError& error) {
  const toml::table* t = node.as_table();
  if (!t) {
    error(&node, path, "expected a table [cloud_layer.formation] of the automaton's keys");
    return;
  }
  CloudFormation f = out;
  auto number = [&](const toml::node& v, const std::string& key_path, double lo, double hi, double& to) {
    std::optional<double> x = v.value<double>();
    if (!x || v.is_boolean() || !std::isfinite(*x) || *x < lo || *x > hi) {
      error(&v, key_path, fmt::format("expected a number in [{}, {}]", lo, hi));
      return;
    }
    to = *x;
  };
  auto integer = [&](const toml::node& v, const std::string& key_path, int lo, int hi, int& to) {
    if (!v.is_integer() || v.as_integer()->get() < lo || v.as_integer()->get() > hi) {
      error(&v, key_path, fmt::format("expected an integer in [{}, {}]", lo, hi));
      return;
    }
    to = int(v.as_integer()->get());
  };
  auto numbers = [&](const toml::node& v, const std::string& key_path, size_t count, const char* shape,
                     const auto& each) {
    const toml::array* a = v.as_array();
    if (!a || a->size() != count) {
      error(&v, key_path, fmt::format("expected {}", shape));
      return;
    }
    for (size_t j = 0; j < count; ++j) each(*a->get(j), fmt::format("{}[{}]", key_path, j), j);
  };
  for (const auto& [key, value] : *t) {
    const std::string k(key.str());
    const std::string p = path + "." + k;
    if (k == "enabled") {
      if (!value.is_boolean()) error(&value, p, "expected true or false");
      else f.enabled = value.as_boolean()->get();
    } else if (k == "density") {
      if (!value.is_boolean())
        error(&value, p, "expected true (the automaton's whole density) or false (its coverage)");
      else f.density = value.as_boolean()->get();
    } else if (k == "cells") {
      numbers(value, p, 3, "[east, north, up] cell counts", [&](const toml::node& v, const std::string& q, size_t j) {
        integer(v, q, j < 2 ? 4 : 1, j < 2 ? 512 : 64, f.cells[j]);
      });
    } else if (k == "size_m") {
      numbers(value, p, 2, "[east, north] extent in m",
              [&](const toml::node& v, const std::string& q, size_t j) { number(v, q, 10.0, 1e7, f.size_m[j]); });
    } else if (k == "origin_m") {
      numbers(value, p, 2, "[east, north] of the south-west corner in m",
              [&](const toml::node& v, const std::string& q, size_t j) { number(v, q, -1e7, 1e7, f.origin_m[j]); });
    } else if (k == "velocity_cells_per_hour") {
      numbers(value, p, 3, "[east, north] in cells per hour and [up] in mask layers per hour",
              [&](const toml::node& v, const std::string& q, size_t j) {
                number(v, q, -1e4, 1e4, f.velocity_cells_per_hour[j]);
              });
    } else if (k == "steps_per_hour") {
      number(value, p, 0.0, 3600.0, f.steps_per_hour);
    } else if (k == "day_start_hour") {
      number(value, p, 0.0, 24.0, f.day_start_hour);
    } else if (k == "warmup_steps") {
      integer(value, p, 0, 100000, f.warmup_steps);
    } else if (k == "extinction_probability") {
      number(value, p, 0.0, 1.0, f.extinction_probability);
    } else if (k == "humidity_probability") {
      number(value, p, 0.0, 1.0, f.humidity_probability);
    } else if (k == "phase_probability") {
      number(value, p, 0.0, 1.0, f.phase_probability);
    } else if (k == "initial_humidity") {
      number(value, p, 0.0, 1.0, f.initial_humidity);
    } else if (k == "smoothing_steps") {
      integer(value, p, 0, 64, f.smoothing_steps);
    } else if (k == "smoothing_cells") {
      integer(value, p, 0, 8, f.smoothing_cells);
    } else if (k == "mask_image") {
      if (!value.is_string() || value.as_string()->get().empty())
        error(&value, p, "expected the path of an RGB mask image (relative to the style file)");
      else f.mask_image = value.as_string()->get();
    } else if (k == "mask_layers") {
      integer(value, p, 1, 256, f.mask_layers);
    } else if (k == "mask_layer") {
      number(value, p, 0.0, 255.0, f.mask_layer);
    } else {
      error(
          &value, p,
          fmt::format("unknown key '{}' (a formation has enabled, cells, size_m, origin_m, steps_per_hour, "
                      "day_start_hour, warmup_steps, extinction_probability, humidity_probability, phase_probability, "
                      "initial_humidity, smoothing_cells, smoothing_steps, mask_image, mask_layers, mask_layer, "
                      "velocity_cells_per_hour, density)",
                      k));
    }
  }
  if (f.mask_layer > f.mask_layers - 1) {
    error(t->get("mask_layer") ? t->get("mask_layer") : &node, path + ".mask_layer",
          fmt::format("{} is beyond the last of the mask's {} layer(s): at most {}", f.mask_layer, f.mask_layers,
                      f.mask_layers - 1));
    return;
  }
  out = f;
}

toml::table CloudFormationToml(const CloudFormation& f) {
  toml::table t;
  if (!f.enabled) return t;
  t.insert("enabled", true);
  t.insert("cells", toml::array{int64_t(f.cells[0]), int64_t(f.cells[1]), int64_t(f.cells[2])});
  t.insert("size_m", toml::array{f.size_m[0], f.size_m[1]});
  t.insert("origin_m", toml::array{f.origin_m[0], f.origin_m[1]});
  t.insert("steps_per_hour", f.steps_per_hour);
  t.insert("warmup_steps", int64_t(f.warmup_steps));
  t.insert("day_start_hour", f.day_start_hour);
  t.insert("extinction_probability", f.extinction_probability);
  t.insert("humidity_probability", f.humidity_probability);
  t.insert("phase_probability", f.phase_probability);
  t.insert("initial_humidity", f.initial_humidity);
  t.insert("smoothing_cells", int64_t(f.smoothing_cells));
  if (f.smoothing_steps > 0) t.insert("smoothing_steps", int64_t(f.smoothing_steps));
  if (!f.mask_image.empty()) {
    t.insert("mask_image", f.mask_image);
    t.insert("mask_layers", int64_t(f.mask_layers));
    t.insert("mask_layer", f.mask_layer);
  }
  t.insert("velocity_cells_per_hour",
           toml::array{f.velocity_cells_per_hour[0], f.velocity_cells_per_hour[1], f.velocity_cells_per_hour[2]});
  if (f.density) t.insert("density", true);  // absent: coverage only, as before the key existed
  return t;
}

}  // namespace skybake
