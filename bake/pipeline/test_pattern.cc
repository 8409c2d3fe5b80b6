#include "skybake/pipeline/test_pattern.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "skybake/base/errors.h"
#include "skybake/input/engine_preset.h"
#include "skybake/model/envmap.h"
#include "skybake/pipeline/pipeline.h"

namespace skybake {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A 5 x 7 bitmap of the few glyphs the pattern writes, rows from the top,
// bit 4 the leftmost column.
const std::array<uint8_t, 7>* Glyph(char c) {
  static const std::array<uint8_t, 7> kPlus = {0x00, 0x04, 0x04, 0x1f, 0x04, 0x04, 0x00};
  static const std::array<uint8_t, 7> kMinus = {0x00, 0x00, 0x00, 0x1f, 0x00, 0x00, 0x00};
  static const std::array<uint8_t, 7> kX = {0x11, 0x11, 0x0a, 0x04, 0x0a, 0x11, 0x11};
  static const std::array<uint8_t, 7> kY = {0x11, 0x11, 0x0a, 0x04, 0x04, 0x04, 0x04};
  static const std::array<uint8_t, 7> kZ = {0x1f, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1f};
  static const std::array<uint8_t, 7> kN = {0x11, 0x19, 0x15, 0x13, 0x11, 0x11, 0x11};
  static const std::array<uint8_t, 7> kE = {0x1f, 0x10, 0x10, 0x1e, 0x10, 0x10, 0x1f};
  static const std::array<uint8_t, 7> kS = {0x0f, 0x10, 0x10, 0x0e, 0x01, 0x01, 0x1e};
  static const std::array<uint8_t, 7> kW = {0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0a};
  switch (c) {
    case '+':
      return &kPlus;
    case '-':
      return &kMinus;
    case 'X':
      return &kX;
    case 'Y':
      return &kY;
    case 'Z':
      return &kZ;
    case 'N':
      return &kN;
    case 'E':
      return &kE;
    case 'S':
      return &kS;
    case 'W':
      return &kW;
    default:
      return nullptr;
  }
}

// True when (a, b) (right, up) falls on a lit cell of `text` drawn centred
// at (ca, cb) with glyph height `h`.
bool OnText(const std::string& text, double a, double b, double ca, double cb, double h) {
  const double cell = h / 7.0;
  const double advance = 6.0 * cell;
  const double width = advance * double(text.size()) - cell;
  const double left = ca - 0.5 * width, top = cb + 0.5 * h;
  const int col = int(std::floor((a - left) / cell));
  const int row = int(std::floor((top - b) / cell));
  if (row < 0 || row >= 7 || col < 0) return false;
  const size_t index = size_t(col / 6);
  const int x = col % 6;
  if (index >= text.size() || x >= 5) return false;
  const std::array<uint8_t, 7>* g = Glyph(text[index]);
  return g && ((*g)[size_t(row)] >> (4 - x)) & 1;
}

const glm::dvec3 kAxes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};

// The face's right and top, seen from inside (test_pattern.h).
void FaceFrame(int face, glm::dvec3& right, glm::dvec3& top) {
  if (face == 2) {
    right = {1, 0, 0}, top = {0, 0, 1};
  } else if (face == 3) {
    right = {1, 0, 0}, top = {0, 0, -1};
  } else {
    right = glm::cross(kAxes[face], glm::dvec3(0, 1, 0)), top = {0, 1, 0};
  }
}

std::string AxisName(const glm::dvec3& v) {
  for (int f = 0; f < 6; ++f)
    if (glm::dot(v, kAxes[f]) > 0.5) return CubeFaceLabel(f);
  return "";
}

}  // namespace

glm::dvec3 TestPatternFaceColor(int face) {
  static const glm::dvec3 kColors[6] = {{0.8, 0.1, 0.1}, {0.1, 0.7, 0.7}, {0.1, 0.8, 0.1},
                                        {0.7, 0.1, 0.7}, {0.1, 0.1, 0.8}, {0.7, 0.7, 0.1}};
  return kColors[face];
}

glm::dvec3 TestPatternColor(const glm::dvec3& direction) {
  const glm::dvec3 d = glm::normalize(direction);
  const double elevation_deg = std::asin(std::clamp(d.y, -1.0, 1.0)) * 180.0 / kPi;
  // The horizon.
  if (std::abs(elevation_deg) < 1.0) return {1, 1, 1};  // 2 degrees: a row of any latlong 90 high or more
  // Compass letters, 3 to 9 degrees up, in the view's own frame.
  if (elevation_deg > 3.0 && elevation_deg < 9.0) {            // 6 degrees tall
    double azimuth_deg = std::atan2(d.x, -d.z) * 180.0 / kPi;  // clockwise from North
    const char* letters = "NESW";
    for (int k = 0; k < 4; ++k) {
      double offset = azimuth_deg - 90.0 * k;
      offset -= 360.0 * std::round(offset / 360.0);
      if (std::abs(offset) < 5.0 && OnText(std::string(1, letters[k]), offset, elevation_deg, 0.0, 6.0, 6.0))
        return {1, 1, 1};
    }
  }
  int face = 0;
  const double ax = std::abs(d.x), ay = std::abs(d.y), az = std::abs(d.z);
  if (ax >= ay && ax >= az) face = d.x > 0 ? 0 : 1;
  else if (ay >= az) face = d.y > 0 ? 2 : 3;
  else face = d.z > 0 ? 4 : 5;
  glm::dvec3 right, top;
  FaceFrame(face, right, top);
  const double m = glm::dot(d, kAxes[face]);
  const double a = glm::dot(d, right) / m, b = glm::dot(d, top) / m;  // [-1, 1] across the face
  const bool text = OnText(CubeFaceLabel(face), a, b, 0.0, 0.35, 0.3) ||
                    OnText(AxisName(right), a, b, 0.75, 0.0, 0.16) || OnText(AxisName(top), a, b, 0.0, 0.8, 0.16);
  return text ? glm::dvec3(0.0) : TestPatternFaceColor(face);
}

double TestPatternMemoryMiB(const TestPatternOptions& options) {
  const double n = options.size;
  // Six faces, the strip (6N x N) and the latlong (2N x N); the preset's
  // images by their kinds (the layout of a 1 x 1 pattern).
  double texels = 14.0 * n * n, largest = 6.0 * n * n;
  if (const EnginePreset* preset = FindEnginePreset(options.engine))
    for (const EngineImage& e : EngineImages(*preset, 1, 1)) {
      const double t = e.kind == "latlong" ? 2.0 * n * n : e.kind == "cube strip" ? 6.0 * n * n : n * n;
      texels += t;
      largest = std::max(largest, t);
    }
  return (24.0 * texels + 32.0 * largest) / (1024.0 * 1024.0);
}

std::vector<std::string> WriteTestPattern(const TestPatternOptions& options) {
  const int n = options.size;
  if (const double mib = TestPatternMemoryMiB(options); !(mib <= options.max_memory_mib))
    throw BudgetError(
        fmt::format("testpattern --size {}{} needs an estimated {:.0f} MiB of memory (every image's "
                    "directions, the largest image's pixels and file), above the budget of {:.0f} MiB: "
                    "lower --size, or raise --max-memory-mib (README \"Limits\"); nothing was written",
                    n, options.engine == "none" ? "" : " --engine " + options.engine, mib, options.max_memory_mib));
  struct Image {
    std::string name;
    std::vector<glm::dvec3> directions;
    int width, height, envmap;
    std::string mapping;
  };
  std::vector<Image> images;
  const char* faces[6] = {"px", "nx", "py", "ny", "pz", "nz"};
  for (int f = 0; f < 6; ++f) {
    Image image{options.basename + "_" + faces[f] + ".exr", {}, n, n, -1, "Vulkan cube map face (sc, tc) table"};
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) image.directions.push_back(VulkanCubeTexelDirection(f, x, y, n));
    images.push_back(std::move(image));
  }
  images.push_back({options.basename + "_cube.exr", CubeStripDirections(n), n, 6 * n, 1, "OpenEXR Imf::CubeMap"});
  Image latlong{options.basename + "_latlong.exr", {}, 2 * n, n, 0, "OpenEXR Imf::LatLongMap"};
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < 2 * n; ++x) latlong.directions.push_back(LatLongDirection(x, y, 2 * n, n));
  images.push_back(std::move(latlong));
  if (const EnginePreset* preset = FindEnginePreset(options.engine))
    for (EngineImage& e : EngineImages(*preset, n, n))
      images.push_back({options.basename + "_" + preset->name + "_" + e.suffix + ".exr", std::move(e.directions),
                        e.width, e.height, e.envmap, e.mapping});
  std::filesystem::create_directories(options.out_dir);
  std::vector<std::string> paths;
  for (const Image& image : images) paths.push_back((std::filesystem::path(options.out_dir) / image.name).string());
  if (!options.force)
    for (const std::string& path : paths)
      if (std::filesystem::exists(std::filesystem::symlink_status(path)))
        throw OutputExistsError(
            fmt::format("{} already exists: pass --force to overwrite, or choose another --out", path));
  for (size_t i = 0; i < images.size(); ++i) {
    RgbaImage rgba{images[i].width, images[i].height, {}, nullptr};
    rgba.rgba.reserve(4 * images[i].directions.size());
    for (const glm::dvec3& d : images[i].directions) {
      const glm::dvec3 c = TestPatternColor(d);
      rgba.rgba.insert(rgba.rgba.end(), {float(c.x), float(c.y), float(c.z), 1.0f});
    }
    ExrWriteOptions exr;
    exr.envmap = images[i].envmap;
    exr.attributes = {{"skybake:version", SKYBAKE_VERSION},
                      {"skybake:test_pattern",
                       "faces tinted and named, axes at their right and top edges, horizon, "
                       "N E S W (docs/engines.md)"},
                      {"skybake:frame", "+Y up, North -Z, East +X; right-handed"},
                      {"skybake:engine_mapping", images[i].mapping}};
    WriteExr(paths[i], rgba, exr);
  }
  return paths;
}

}  // namespace skybake
