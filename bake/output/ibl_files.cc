// The files of the image-based lighting maps: names, EXR and KTX2 encoding.
#include "skybake/output/ibl_files.h"

#include <algorithm>
#include <optional>

#include <fmt/format.h>

#include "skybake/output/gltf_ibl.h"
#include "skybake/output/ktx2.h"
#include "skybake/output/manifest.h"

namespace skybake {

std::vector<IblFileName> IblFileNames(const SkyStyle& style, int number_in_name, bool with_dfg, int number_width) {
  const IblSettings& s = style.ibl;
  std::vector<IblFileName> names;
  if (!s.Requested()) return names;
  const std::string base = style.output.basename;
  const std::string number = FrameNumberSuffix(number_in_name, number_width);
  if (s.exr) {
    if (s.specular)
      for (int level = 0; level < IblLevelCount(s); ++level)
        names.push_back({fmt::format("{}_specular_m{}{}.exr", base, level, number), "ibl_specular"});
    if (s.irradiance) names.push_back({base + "_irradiance" + number + ".exr", "ibl_irradiance"});
    if (s.dfg && with_dfg) names.push_back({base + "_dfg.exr", "ibl_dfg"});
  }
  if (s.ktx2) {
    if (s.specular) names.push_back({base + "_specular" + number + ".ktx2", "ibl_specular"});
    if (s.irradiance) names.push_back({base + "_irradiance" + number + ".ktx2", "ibl_irradiance"});
    if (s.dfg && with_dfg) names.push_back({base + "_dfg.ktx2", "ibl_dfg"});
  }
  if (s.specular && style.gltf.enabled && style.gltf.image_based_light)
    for (int level = 0; level < IblLevelCount(s); ++level)
      for (const char* face : {"px", "nx", "py", "ny", "pz", "nz"})
        names.push_back({fmt::format("{}_specular_m{}_{}{}.png", base, level, face, number), "ibl_gltf"});
  return names;
}

std::vector<RgbaImage> IblImagesForRangeCheck(const IblMaps& maps) {
  std::vector<RgbaImage> images;
  for (const CubeLevel& level : maps.specular) images.push_back({level.size, 6 * level.size, StackFaces(level)});
  if (maps.irradiance.size > 0)
    images.push_back({maps.irradiance.size, 6 * maps.irradiance.size, StackFaces(maps.irradiance)});
  return images;
}

namespace {

// The radiance maps in the output's colour space (output.color_space): a
// copy through its matrix; the DFG table is not a colour and stays.
IblMaps InColorSpace(const IblMaps& rec709, const OutputColorSpace& space) {
  IblMaps maps = rec709;
  const Matrix3& m = space.from_rec709;
  auto convert = [&](CubeLevel& level) {
    for (std::vector<float>& face : level.faces)
      for (size_t t = 0; t + 3 < face.size(); t += 4) {
        const double r = face[t], g = face[t + 1], b = face[t + 2];
        for (int i = 0; i < 3; ++i) face[t + i] = float(m[i][0] * r + m[i][1] * g + m[i][2] * b);
      }
  };
  for (CubeLevel& level : maps.specular) convert(level);
  convert(maps.irradiance);
  return maps;
}

}  // namespace

std::vector<std::string> EncodeIblFiles(const IblMaps& rec709_maps, const SkyStyle& style,
                                        const ExrWriteOptions& rec709_exr, bool with_dfg) {
  const IblSettings& s = style.ibl;
  // The EXR and KTX2 maps in the output's colour space; the glTF's RGBD PNGs stay Rec.709.
  const OutputColorSpace& space = style.output.color_space;
  const bool luminance = style.output.units == OutputUnits::kLuminance;
  std::optional<IblMaps> converted;
  if (luminance && !space.IsRec709()) converted = InColorSpace(rec709_maps, space);
  const IblMaps& maps = converted ? *converted : rec709_maps;
  ExrWriteOptions exr = rec709_exr;
  if (converted) {
    for (int i = 0; i < 8; ++i) exr.chromaticities[i] = float(space.chromaticities[i / 2][i % 2]);
    exr.attributes["skybake:units"] = space.description + " luminance, cd/m^2 per 1.0 divided by skybake:scale";
    exr.attributes["skybake:color_space"] = space.name;
  }
  const int levels = IblLevelCount(s);
  const std::string layout =
      "six Vulkan cube faces (the Vulkan face-selection table, texel centres at (i + 0.5) / N) stacked from the "
      "top: +X -X +Y -Y +Z -Z; +Y up, North -Z, right-handed";
  const std::string sun = s.include_sun ? "included (its energy through the level's kernel, not clamped)"
                                        : "left out (the glTF scene's KHR_lights_punctual sun carries it)";
  std::vector<ExrFile> exrs;
  std::vector<RgbaImage> images;
  images.reserve(levels + 2);
  if (s.exr) {
    if (s.specular)
      for (int level = 0; level < levels; ++level) {
        const CubeLevel& l = maps.specular[level];
        images.push_back({l.size, 6 * l.size, StackFaces(l)});
        ExrWriteOptions o = exr;
        const double roughness = IblRoughness(level, levels);
        o.attributes["skybake:ibl"] = fmt::format(
            "GGX-prefiltered radiance (split sum, Karis 2013), N = V = R; level {} of {}; perceptual roughness {:.9g} "
            "= level / (levels - 1), alpha = roughness^2 = {:.9g}; {} samples, filtered importance sampling, mip bias "
            "{:.9g}",
            level, levels, roughness, roughness * roughness, level == 0 ? s.samples : IblLevelSamples(s, roughness),
            s.lod_bias);
        o.attributes["skybake:ibl_sun"] = sun;
        o.attributes["skybake:layout"] = layout;
        exrs.push_back({fmt::format("specular level {}", level), nullptr, o});
      }
    if (s.irradiance) {
      images.push_back({maps.irradiance.size, 6 * maps.irradiance.size, StackFaces(maps.irradiance)});
      ExrWriteOptions o = exr;
      o.attributes["skybake:ibl"] = fmt::format(
          "irradiance E(n) / pi: the radiance a white Lambertian surface of normal n reflects (multiply by the "
          "albedo; E itself is pi times the value, in lux for luminance output); {} cosine samples",
          s.irradiance_samples);
      o.attributes["skybake:ibl_sun"] = sun;
      o.attributes["skybake:layout"] = layout;
      exrs.push_back({"irradiance", nullptr, o});
    }
    if (s.dfg && with_dfg) {
      images.push_back({maps.dfg_size, maps.dfg_size, maps.dfg});
      ExrWriteOptions o;
      o.pixel_type = exr.pixel_type;
      o.compression = exr.compression;
      o.zip_level = exr.zip_level;
      o.attributes = {{"skybake:version", SKYBAKE_VERSION},
                      {"skybake:ibl",
                       fmt::format("split-sum DFG table (Karis 2013): column = N.V, row = perceptual roughness (texel "
                                   "centres, roughness 0 at the top), R = scale A, G = bias B: specular = prefiltered "
                                   "x (F0 A + B); GGX alpha = roughness^2, Smith-Schlick G with k = alpha / 2, "
                                   "Schlick Fresnel; {} samples",
                                   s.dfg_samples)}};
      exrs.push_back({"DFG table", nullptr, o});
    }
    for (size_t i = 0; i < exrs.size(); ++i) exrs[i].image = &images[i];
  }
  std::vector<std::string> encoded = EncodeExrs(exrs);
  if (s.ktx2) {
    Ktx2Options k;
    k.format = s.ktx2_format;
    k.zstd_level = s.ktx2_zstd_level;
    k.scale = exr.scale;
    k.metadata = {{"skybake:version", SKYBAKE_VERSION},
                  {"skybake:scale", exr.attributes.count("skybake:scale") ? exr.attributes.at("skybake:scale") : "1"},
                  {"skybake:units", exr.attributes.count("skybake:units") ? exr.attributes.at("skybake:units") : ""},
                  {"skybake:frame", "+Y up, North -Z, East +X; right-handed; faces in the KTX2 (Vulkan) order"}};
    if (luminance) {
      k.primaries = Ktx2Primaries(space);
      k.metadata["skybake:color_space"] = space.name;
      k.metadata["skybake:chromaticities"] =
          fmt::format("{} {} {} {} {} {} {} {}", space.chromaticities[0][0], space.chromaticities[0][1],
                      space.chromaticities[1][0], space.chromaticities[1][1], space.chromaticities[2][0],
                      space.chromaticities[2][1], space.chromaticities[3][0], space.chromaticities[3][1]);
    }
    if (s.specular) {
      Ktx2Options o = k;
      o.metadata["skybake:ibl"] = fmt::format(
          "GGX-prefiltered radiance (split sum, Karis 2013): mip level l of {} has perceptual roughness l / {}, "
          "alpha = roughness^2",
          levels, std::max(1, levels - 1));
      o.metadata["skybake:ibl_sun"] = sun;
      encoded.push_back(EncodeKtx2Cube(maps.specular, o));
    }
    if (s.irradiance) {
      Ktx2Options o = k;
      o.metadata["skybake:ibl"] = "irradiance E(n) / pi (a white Lambertian surface's radiance; E = pi x value)";
      o.metadata["skybake:ibl_sun"] = sun;
      encoded.push_back(EncodeKtx2Cube({maps.irradiance}, o));
    }
    if (s.dfg && with_dfg) {
      Ktx2Options o;
      o.format = KtxFormat::kRgba16f;
      o.zstd_level = s.ktx2_zstd_level;
      o.metadata = {{"skybake:version", SKYBAKE_VERSION},
                    {"skybake:ibl",
                     "split-sum DFG table: x = N.V, y = perceptual roughness (0 at the top), R = scale, "
                     "G = bias of F0"}};
      encoded.push_back(EncodeKtx2Image(maps.dfg_size, maps.dfg_size, maps.dfg, o));
    }
  }
  if (s.specular && style.gltf.enabled && style.gltf.image_based_light)
    for (int level = 0; level < levels; ++level)
      for (int face = 0; face < 6; ++face)
        encoded.push_back(EncodeRgbdFacePng(rec709_maps.specular[level].faces[face].data(),
                                            rec709_maps.specular[level].size, rec709_maps.gltf_scale));
  return encoded;
}

}  // namespace skybake
