// libskybake_oiio.so: the gallery's contact sheet and image reading through
// OpenImageIO (see oiio_module.h for why this is a module of its own).
#include "skybake/base/oiio_module.h"

#include <algorithm>
#include <cmath>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

namespace skybake {
namespace {

bool ComposeSheet(const std::vector<SheetCell>& cells, const SheetLayout& l, std::vector<uint8_t>& rgb, int& width,
                  int& height, std::string& error) {
  const int columns = std::max(1, std::min<int>(l.columns, int(cells.size())));
  const int rows = (int(cells.size()) + columns - 1) / columns;
  const int cell_w = l.tile_w + l.margin, cell_h = l.tile_h + l.label_height + l.margin;
  OIIO::ImageSpec spec(columns * cell_w + l.margin, rows * cell_h + l.margin, 3, OIIO::TypeDesc::FLOAT);
  OIIO::ImageBuf sheet(spec);
  const float background[3] = {0.08f, 0.08f, 0.09f};
  OIIO::ImageBufAlgo::fill(sheet, background);
  for (size_t i = 0; i < cells.size(); ++i) {
    const SheetCell& c = cells[i];
    const int x0 = l.margin + int(i % columns) * cell_w;
    const int y0 = l.margin + int(i / columns) * cell_h;
    OIIO::ImageBuf preview(c.preview_path);
    if (!preview.read(0, 0, true, OIIO::TypeDesc::FLOAT)) {
      error = "cannot read " + c.preview_path + ": " + preview.geterror();
      return false;
    }
    OIIO::ImageBuf sky = OIIO::ImageBufAlgo::cut(preview, OIIO::ROI(0, l.tile_w, 0, l.tile_h, 0, 1, 0, 3));
    if (!OIIO::ImageBufAlgo::paste(sheet, x0, y0 + l.label_height, 0, 0, sky)) {
      error = "cannot compose the contact sheet: " + sheet.geterror();
      return false;
    }
    // Two label lines, clipped to this cell.
    const float name_color[3] = {0.95f, 0.95f, 0.95f};
    const float detail_color[3] = {0.7f, 0.7f, 0.72f};
    OIIO::ROI cell(x0, x0 + l.tile_w, y0, y0 + l.label_height, 0, 1, 0, 3);
    bool ok = OIIO::ImageBufAlgo::render_text(sheet, x0 + 2, y0 + 17, c.name, l.name_size, l.name_font, name_color,
                                              OIIO::ImageBufAlgo::TextAlignX::Left,
                                              OIIO::ImageBufAlgo::TextAlignY::Baseline, 0, cell);
    ok = ok && OIIO::ImageBufAlgo::render_text(sheet, x0 + 2, y0 + 34, c.detail, l.detail_size, l.detail_font,
                                               detail_color, OIIO::ImageBufAlgo::TextAlignX::Left,
                                               OIIO::ImageBufAlgo::TextAlignY::Baseline, 0, cell);
    if (!ok) {
      error = "cannot draw the gallery labels (" + sheet.geterror() +
              "): install the DejaVu fonts (apt-get install fonts-dejavu-core)";
      return false;
    }
  }
  // The previews are sRGB-encoded already: the values as they are.
  width = spec.width;
  height = spec.height;
  rgb.assign(size_t(width) * height * 3, 0);
  std::vector<float> pixels(rgb.size());
  sheet.get_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, pixels.data());
  for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = uint8_t(std::lround(std::clamp(pixels[i], 0.0f, 1.0f) * 255.0f));
  return true;
}

bool ReadImage(const std::string& name, const std::string& bytes, uint64_t max_samples, int& width, int& height,
               int& channels, std::vector<float>& pixels, std::string& error) {
  OIIO::Filesystem::IOMemReader reader(const_cast<char*>(bytes.data()), bytes.size());
  OIIO::ImageSpec config;
  auto in = OIIO::ImageInput::open(name, &config, &reader);
  if (!in) {
    error = OIIO::geterror();
    return false;
  }
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.depth > 1) {
    error = "a 3D image (depth " + std::to_string(spec.depth) + "); expected a 2D image";
    return false;
  }
  // From the header, before decoding: a small file may declare a huge image.
  const uint64_t samples =
      uint64_t(std::max(spec.width, 0)) * uint64_t(std::max(spec.height, 0)) * uint64_t(std::max(spec.nchannels, 0));
  if (samples > max_samples) {
    error = std::to_string(spec.width) + " x " + std::to_string(spec.height) + " texels of " +
            std::to_string(spec.nchannels) + " channels, more than the " + std::to_string(max_samples) +
            " samples an input image may have (4096 x 4096 x 4)";
    return false;
  }
  width = spec.width;
  height = spec.height;
  channels = spec.nchannels;
  pixels.assign(size_t(width) * height * channels, 0.0f);
  bool ok = in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, pixels.data());
  if (!ok) error = in->geterror();
  in->close();
  return ok;
}

const OiioModule kModule = {ComposeSheet, ReadImage};

}  // namespace
}  // namespace skybake

extern "C" __attribute__((visibility("default"))) const skybake::OiioModule* skybake_oiio_module_v3() {
  return &skybake::kModule;
}
