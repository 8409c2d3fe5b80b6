#include "skybake/output/usd_layer.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfStringAttribute.h>

#include "skybake/base/errors.h"
#include "skybake/input/frame_numbering.h"
#include "skybake/output/exr_io.h"

namespace skybake {

std::string UsdStringLiteral(std::string_view text) {
  std::string out = "\"";
  for (const char ch : text) {
    const unsigned char c = static_cast<unsigned char>(ch);
    switch (ch) {
      case '\\':
        out += "\\\\";
        break;
      case '"':
        out += "\\\"";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (c < 0x20 || c == 0x7f) out += fmt::format("\\x{:02x}", c);
        else out += ch;
    }
  }
  return out + "\"";
}

std::string UsdAssetPathLiteral(std::string_view path) {
  if (path.find('@') == std::string_view::npos) return "@" + std::string(path) + "@";
  std::string body;
  for (size_t i = 0; i < path.size(); ++i) {
    if (path.compare(i, 3, "@@@") == 0) {
      body += "\\@@@";
      i += 2;
    } else {
      body += path[i];
    }
  }
  return "@@@" + body + "@@@";
}

glm::dvec3 UsdRotateXyzTowards(const glm::dvec3& direction) {
  // Rx(a) takes +Z to (0, -sin a, cos a): a = -elevation lifts it to the
  // source's elevation; Ry(b) then takes (0, sin e, cos e) to
  // (cos e sin b, sin e, cos e cos b): b = atan2(d.x, d.z).
  const glm::dvec3 d = glm::normalize(direction);
  const double elevation = std::asin(std::clamp(d.y, -1.0, 1.0));
  const double b = std::atan2(d.x, d.z);
  return {-elevation * 180.0 / M_PI, b * 180.0 / M_PI, 0.0};
}

namespace {

// Floats as USD stores them (float: 9 significant digits round-trip),
// doubles with 17.
std::string Float(double v) { return fmt::format("{:.9g}", v); }
std::string Double(double v) { return fmt::format("{:.17g}", v); }
std::string Float3(const glm::dvec3& v) { return "(" + Float(v.x) + ", " + Float(v.y) + ", " + Float(v.z) + ")"; }

// A light key's intensity (lux) and colour (Rec.709 luminance 1): their
// product is the irradiance per channel. A dark key is white at 0.
double KeyIntensity(const UsdDistantKey& k) { return k.illuminance_lux > 0.0 ? k.illuminance_lux : 0.0; }
glm::dvec3 KeyColor(const UsdDistantKey& k) {
  if (k.illuminance_lux <= 0.0) return {1.0, 1.0, 1.0};
  return glm::dvec3(k.irradiance[0], k.irradiance[1], k.irradiance[2]) / k.illuminance_lux;
}

// The dome's exposure: -log2 of the file's scale, a power of two that the
// header records to 9 digits (2^-15 as 3.05175781e-05): the whole number
// it rounds to.
double DomeExposure(double texture_scale) {
  if (!(texture_scale > 0.0)) return 0.0;
  const double e = 0.0 - std::log2(texture_scale);
  return std::abs(e - std::round(e)) < 1e-6 ? std::round(e) + 0.0 : e;
}

// One attribute: `decl` (type and name) with its value, or in a sequence
// its time samples at the frame numbers. `values` holds each frame's value
// text, "" for a frame without a sample.
// With `color_space`, the attribute carries USD's colorSpace metadata: after
// a plain value, or on a declaration of its own before the time samples.
void Attribute(std::string& out, const std::string& indent, const std::string& decl, const UsdLayerDescription& layer,
               const std::vector<std::string>& values, const std::string& color_space = "") {
  const std::string metadata =
      color_space.empty() ? ""
                          : " (\n" + indent + "    colorSpace = " + UsdStringLiteral(color_space) + "\n" + indent + ")";
  if (!layer.sequence) {
    if (!values.front().empty()) out += indent + decl + " = " + values.front() + metadata + "\n";
    return;
  }
  std::vector<std::pair<int, std::string>> samples;
  for (size_t i = 0; i < layer.frames.size(); ++i)
    if (!values[i].empty()) samples.emplace_back(layer.frames[i].number, values[i]);
  if (samples.empty()) return;
  // A value the same in every frame needs no samples.
  const bool constant =
      samples.size() == layer.frames.size() &&
      std::all_of(samples.begin(), samples.end(), [&](const auto& s) { return s.second == samples.front().second; });
  if (constant) {
    out += indent + decl + " = " + samples.front().second + metadata + "\n";
    return;
  }
  if (!metadata.empty()) out += indent + decl + metadata + "\n";
  out += indent + decl + ".timeSamples = {\n";
  for (const auto& [number, v] : samples) out += fmt::format("{}    {}: {},\n", indent, number, v);
  out += indent + "}\n";
}

// Each frame's value text: `value(frame)`.
template <class ValueOf>
std::vector<std::string> PerFrame(const UsdLayerDescription& layer, ValueOf value) {
  std::vector<std::string> values;
  for (const UsdFrame& f : layer.frames) values.push_back(value(f));
  return values;
}

// The rotation keys of a light, with the azimuth angle kept continuous
// from one key to the next (no jump of 360 deg for interpolation to sweep).
std::vector<std::optional<glm::dvec3>> RotationKeys(const UsdLayerDescription& layer, bool moon) {
  std::vector<std::optional<glm::dvec3>> keys;
  std::optional<double> previous;
  for (const UsdFrame& f : layer.frames) {
    const UsdDistantKey* k = moon ? (f.moon ? &*f.moon : nullptr) : &f.sun;
    if (!k) {
      keys.emplace_back();
      continue;
    }
    glm::dvec3 r = UsdRotateXyzTowards(k->direction);
    if (previous) r.y += 360.0 * std::round((*previous - r.y) / 360.0);
    previous = r.y;
    keys.emplace_back(r);
  }
  return keys;
}

// A DistantLight for the Sun or the Moon.
void DistantLight(std::string& out, const UsdLayerDescription& layer, const char* name, bool moon) {
  const std::string in = "        ";
  auto key = [&](const UsdFrame& f) -> const UsdDistantKey* { return moon ? (f.moon ? &*f.moon : nullptr) : &f.sun; };
  out += fmt::format("    def DistantLight \"{}\" (\n", name);
  out += fmt::format(
      "        doc = \"{}: intensity x 2^exposure x color = illuminance per channel (lux, linear "
      "Rec.709) on a surface facing it (normalize); shines along -Z, +Z towards the {}\"\n",
      moon ? "The Moon" : "The Sun", moon ? "Moon" : "Sun");
  out += "    )\n    {\n";
  Attribute(out, in, "float inputs:angle", layer, PerFrame(layer, [&](const UsdFrame& f) {
              const UsdDistantKey* k = key(f);
              return k ? Float(k->angular_diameter_deg) : std::string();
            }));
  Attribute(out, in, "color3f inputs:color", layer,
            PerFrame(layer,
                     [&](const UsdFrame& f) {
                       const UsdDistantKey* k = key(f);
                       return Float3(k ? KeyColor(*k) : glm::dvec3(1.0));
                     }),
            UsdColorSpaceToken("rec709"));
  out += in + "float inputs:exposure = 0\n";
  Attribute(out, in, "float inputs:intensity", layer, PerFrame(layer, [&](const UsdFrame& f) {
              const UsdDistantKey* k = key(f);
              return Float(k ? KeyIntensity(*k) : 0.0);
            }));
  out += in + "bool inputs:normalize = 1\n";
  std::vector<std::string> rotations;
  for (const std::optional<glm::dvec3>& r : RotationKeys(layer, moon)) rotations.push_back(r ? Float3(*r) : "");
  Attribute(out, in, "float3 xformOp:rotateXYZ", layer, rotations);
  out += in + "uniform token[] xformOpOrder = [\"xformOp:rotateXYZ\"]\n";
  out += "    }\n";
}

// The /Sky prim's customData: provenance, then one dictionary per frame.
void SkyCustomData(std::string& out, const UsdLayerDescription& layer) {
  const std::string in = "            ";
  out += "    customData = {\n        dictionary skybake = {\n";
  out += in + "string commit = " + UsdStringLiteral(layer.commit) + "\n";
  const int width = FrameNumberWidth(layer.frames.back().number);
  for (const UsdFrame& f : layer.frames) {
    out += in + "dictionary " + (layer.sequence ? fmt::format("frame_{:0{}d}", f.number, width) : "frame") + " = {\n";
    const std::string f_in = in + "    ";
    out += f_in + "int frame = " + std::to_string(f.number) + "\n";
    out += f_in + "string latlong = " + UsdStringLiteral(f.latlong_file) + "\n";
    out += f_in + "double sun_azimuth_deg = " + Double(f.sun_azimuth_deg) + "\n";
    out += f_in + "double sun_elevation_deg = " + Double(f.sun_elevation_deg) + "\n";
    out += f_in + "double sun_illuminance_lux = " + Double(f.sun.illuminance_lux) + "\n";
    if (f.moon) out += f_in + "double moon_illuminance_lux = " + Double(f.moon->illuminance_lux) + "\n";
    out += f_in + "string style_sha256 = " + UsdStringLiteral(f.style_sha256) + "\n";
    out += f_in + "string time = " + UsdStringLiteral(f.time) + "\n";
    out += in + "}\n";
  }
  out += in + "string schedule = " + UsdStringLiteral(layer.schedule) + "\n";
  out += in + "string sequence_sha256 = " + UsdStringLiteral(layer.sequence_sha256) + "\n";
  out += in + "string style = " + UsdStringLiteral(layer.style) + "\n";
  out +=
      in + "string dome_color_space = " + UsdStringLiteral(UsdColorSpaceToken(layer.frames.front().color_space)) + "\n";
  out += in + "string light_color_space = " + UsdStringLiteral(UsdColorSpaceToken("rec709")) + "\n";
  out += in + "string units = \"dome: cd/m^2 (nits) = texel x intensity x 2^exposure; distant lights: lux\"\n";
  out += in + "string version = " + UsdStringLiteral(layer.version) + "\n";
  out += "        }\n    }\n";
}

}  // namespace

std::string UsdLayerText(const UsdLayerDescription& layer) {
  if (layer.frames.empty()) throw OutputError(fmt::format("{}.usda: a layer of no frames", layer.name));
  // One colour space for the dome's texture (one colorSpace on its attribute).
  for (const UsdFrame& f : layer.frames)
    if (f.color_space != layer.frames.front().color_space)
      throw OutputError(fmt::format(
          "{}.usda: frame {}'s latlong EXR is in {}, frame {}'s in {}: the dome's texture "
          "has one colour space; bake the frames with one output.color_space",
          layer.name, layer.frames.front().number, layer.frames.front().color_space, f.number, f.color_space));
  std::string out = "#usda 1.0\n(\n";
  out += "    defaultPrim = \"Sky\"\n";
  out += "    doc = " +
         UsdStringLiteral("skybake " + layer.version +
                          " sky: DomeLight (latlong EXR, cd/m^2) and "
                          "DistantLights (lux); +Y up, North -Z, East +X, metres") +
         "\n";
  if (layer.sequence) {
    out += fmt::format("    endTimeCode = {}\n", layer.frames.back().number);
    out += "    framesPerSecond = 24\n";
  }
  out += "    metersPerUnit = 1\n";
  if (layer.sequence) {
    out += fmt::format("    startTimeCode = {}\n", layer.frames.front().number);
    out += "    timeCodesPerSecond = 24\n";
  }
  out += "    upAxis = \"Y\"\n)\n\n";

  out += "def Xform \"Sky\" (\n";
  SkyCustomData(out, layer);
  out += ")\n{\n";
  bool has_moon = false;
  for (const UsdFrame& f : layer.frames) has_moon = has_moon || f.moon.has_value();

  // The dome: the latlong EXR in OpenEXR's layout, which is UsdLux's for a
  // latlong DomeLight with the pole along the stage's +Y.
  const std::string in = "        ";
  out += "    def DomeLight \"Dome\" (\n";
  out +=
      "        doc = \"The sky: emitted radiance (cd/m^2) = texel x intensity x 2^exposure; exposure = "
      "-log2(skybake:scale of the EXR). OpenEXR latlong layout, +Y pole, +Z at longitude 0: no transform\"\n";
  out += "    )\n    {\n";
  out += in + "color3f inputs:color = (1, 1, 1)\n";
  Attribute(out, in, "float inputs:exposure", layer,
            PerFrame(layer, [](const UsdFrame& f) { return Float(DomeExposure(f.texture_scale)); }));
  out += in + "float inputs:intensity = 1\n";
  out += in + "bool inputs:normalize = 0\n";
  Attribute(out, in, "asset inputs:texture:file", layer,
            PerFrame(layer, [](const UsdFrame& f) { return UsdAssetPathLiteral("./" + f.latlong_file); }),
            UsdColorSpaceToken(layer.frames.front().color_space));
  out += in + "token inputs:texture:format = \"latlong\"\n";
  out += "    }\n\n";
  DistantLight(out, layer, "Sun", false);
  if (has_moon) {
    out += "\n";
    DistantLight(out, layer, "Moon", true);
  }
  out += "}\n";
  return out;
}

std::string WriteUsdLayer(const UsdLayerDescription& layer) {
  const std::string path = (std::filesystem::path(layer.out_dir) / (layer.name + ".usda")).string();
  WriteFileAtomically(path, UsdLayerText(layer));
  return path;
}

std::string UsdColorSpaceToken(const std::string& skybake_name) {
  static const std::map<std::string, std::string> kCanonical = {{"rec709", "lin_rec709_scene"},
                                                                {"acescg", "lin_ap1_scene"},
                                                                {"aces2065-1", "lin_ap0_scene"},
                                                                {"rec2020", "lin_rec2020_scene"},
                                                                {"xyz", "lin_ciexyzd65_scene"}};
  const auto it = kCanonical.find(skybake_name);
  return it == kCanonical.end() ? skybake_name : it->second;
}

std::string ExrSkybakeColorSpace(const std::string& path) {
  try {
    Imf::InputFile in(path.c_str());
    const Imf::StringAttribute* name = in.header().findTypedAttribute<Imf::StringAttribute>("skybake:color_space");
    return name && !name->value().empty() ? name->value() : "rec709";
  } catch (const std::exception& e) {
    throw OutputError(fmt::format("{}: cannot read its header for the USD layer: {}", path, e.what()));
  }
}

double ExrSkybakeScale(const std::string& path) {
  try {
    Imf::InputFile in(path.c_str());
    const Imf::StringAttribute* scale = in.header().findTypedAttribute<Imf::StringAttribute>("skybake:scale");
    if (!scale) return 1.0;
    const double value = std::stod(scale->value());
    return value > 0.0 && std::isfinite(value) ? value : 1.0;
  } catch (const std::exception& e) {
    throw OutputError(fmt::format("{}: cannot read its header for the USD layer: {}", path, e.what()));
  }
}

}  // namespace skybake
