#include "skybake/gallery.h"

#include <algorithm>
#include <filesystem>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <fmt/format.h>

#include "skybake/exr_io.h"

namespace skybake {
namespace {

constexpr int kLabelHeight = 40;  // pixels above each tile: name, then principles
constexpr int kMargin = 8;        // pixels between tiles
constexpr int kNameSize = 17;
constexpr int kDetailSize = 12;
constexpr const char* kNameFont = "DejaVuSans-Bold";
constexpr const char* kDetailFont = "DejaVuSans";

}  // namespace

std::vector<std::string> StyleFilesIn(const std::string& dir) {
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    if (entry.is_regular_file() && entry.path().extension() == ".toml")
      files.push_back(entry.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

std::string DescribePrinciples(const SkyStyle& style) {
  const AoasSettings& a = style.aoas;
  std::vector<std::string> parts;
  if (a.skydome.enabled) parts.push_back("skydome");
  if (a.hue.enabled) parts.push_back(a.hue.color.empty() ? "hue vector" : "hue " + a.hue.color);
  if (a.ambiguity.enabled) parts.push_back(fmt::format("ambiguity l_pt {:g}", a.ambiguity.l_pt));
  if (a.clouds.enabled) parts.push_back(fmt::format("clouds s_noise {:g}", a.clouds.s_noise));
  if (a.shapes.enabled)
    parts.push_back(fmt::format("{} shape{}", a.shapes.shapes.size(), a.shapes.shapes.size() == 1 ? "" : "s"));
  parts.push_back(fmt::format("sun {:g} deg", style.sun.elevation_deg));
  std::string out;
  for (size_t i = 0; i < parts.size(); ++i) out += (i ? ", " : "") + parts[i];
  return out;
}

GalleryResult BakeGallery(const std::vector<std::string>& style_paths, const GalleryOptions& options) {
  GalleryResult result;
  std::filesystem::create_directories(options.out_dir);

  // Bake each style's latlong preview only.
  for (const std::string& path : style_paths) {
    std::vector<std::string> overrides = options.overrides;
    std::string name = std::filesystem::path(path).stem().string();
    for (const std::string& o :
         {std::string("output.faces=false"), std::string("output.cube_strip=false"),
          std::string("output.latlong=false"), std::string("output.preview=true"),
          std::string("gltf.enabled=false"),
          fmt::format("output.basename=\"{}\"", name),
          fmt::format("render.latlong_height={}", options.latlong_height)})
      overrides.push_back(o);
    ConfigResult config = LoadSkyStyle(path, overrides);
    if (!config.ok()) throw ConfigFailure(path + " is not a valid style", config.errors);
    BakeOptions bake = options.bake;
    bake.out_dir = (std::filesystem::path(options.out_dir) / name).string();  // preview + manifest
    BakeResult baked = BakeStyle(config.style, bake);
    result.validation_messages += baked.validation_messages;
    GalleryEntry entry{name, path, DescribePrinciples(config.style), ""};
    for (const BakedFile& f : baked.files)
      if (f.kind == "preview") entry.preview = f.path;
    result.entries.push_back(entry);
  }

  // Lay the upper halves out in a grid, each under its label.
  const int tile_w = 2 * options.latlong_height;
  const int tile_h = options.latlong_height / 2;
  const int columns = std::max(1, std::min<int>(options.columns, int(result.entries.size())));
  const int rows = (int(result.entries.size()) + columns - 1) / columns;
  const int cell_w = tile_w + kMargin, cell_h = tile_h + kLabelHeight + kMargin;
  OIIO::ImageSpec spec(columns * cell_w + kMargin, rows * cell_h + kMargin, 3, OIIO::TypeDesc::FLOAT);
  OIIO::ImageBuf sheet(spec);
  const float background[3] = {0.08f, 0.08f, 0.09f};
  OIIO::ImageBufAlgo::fill(sheet, background);
  for (size_t i = 0; i < result.entries.size(); ++i) {
    const GalleryEntry& e = result.entries[i];
    const int x0 = kMargin + int(i % columns) * cell_w;
    const int y0 = kMargin + int(i / columns) * cell_h;
    OIIO::ImageBuf preview(e.preview);
    if (!preview.read(0, 0, true, OIIO::TypeDesc::FLOAT))
      throw OutputError(fmt::format("cannot read {}: {}", e.preview, preview.geterror()));
    OIIO::ImageBuf sky = OIIO::ImageBufAlgo::cut(preview, OIIO::ROI(0, tile_w, 0, tile_h, 0, 1, 0, 3));
    if (!OIIO::ImageBufAlgo::paste(sheet, x0, y0 + kLabelHeight, 0, 0, sky))
      throw OutputError("cannot compose the contact sheet: " + sheet.geterror());
    // Two label lines, clipped to this cell.
    const float name_color[3] = {0.95f, 0.95f, 0.95f};
    const float detail_color[3] = {0.7f, 0.7f, 0.72f};
    OIIO::ROI cell(x0, x0 + tile_w, y0, y0 + kLabelHeight, 0, 1, 0, 3);
    bool ok = OIIO::ImageBufAlgo::render_text(sheet, x0 + 2, y0 + 17, e.name, kNameSize, kNameFont,
                                              name_color, OIIO::ImageBufAlgo::TextAlignX::Left,
                                              OIIO::ImageBufAlgo::TextAlignY::Baseline, 0, cell);
    ok = ok && OIIO::ImageBufAlgo::render_text(sheet, x0 + 2, y0 + 34, e.principles, kDetailSize,
                                               kDetailFont, detail_color,
                                               OIIO::ImageBufAlgo::TextAlignX::Left,
                                               OIIO::ImageBufAlgo::TextAlignY::Baseline, 0, cell);
    if (!ok)
      throw OutputError(
          fmt::format("cannot draw the gallery labels ({}): install the DejaVu fonts "
                      "(apt-get install fonts-dejavu-core)", sheet.geterror()));
  }
  // The previews are sRGB-encoded already: write the values as they are.
  std::string sheet_path = (std::filesystem::path(options.out_dir) / "gallery.png").string();
  std::vector<uint8_t> rgb(size_t(spec.width) * spec.height * 3);
  std::vector<float> pixels(rgb.size());
  sheet.get_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, pixels.data());
  for (size_t i = 0; i < rgb.size(); ++i)
    rgb[i] = uint8_t(std::lround(std::clamp(pixels[i], 0.0f, 1.0f) * 255.0f));
  WritePng(sheet_path, spec.width, spec.height, rgb);
  result.contact_sheet = sheet_path;
  return result;
}

}  // namespace skybake
