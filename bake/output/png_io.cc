#include "skybake/output/png_io.h"

#include <csetjmp>

#include <png.h>

#include "skybake/base/errors.h"

namespace skybake {
namespace {

void AppendToString(png_structp png, png_bytep data, png_size_t length) {
  static_cast<std::string*>(png_get_io_ptr(png))->append(reinterpret_cast<const char*>(data), length);
}

void NoFlush(png_structp) {}

// libpng reports an error by longjmp to the setjmp below; its message is
// kept for the OutputError.
void KeepError(png_structp png, png_const_charp message) {
  static_cast<std::string*>(png_get_error_ptr(png))->assign(message);
  png_longjmp(png, 1);
}

void IgnoreWarning(png_structp, png_const_charp) {}

// The encoding itself, with no object that has a destructor between the
// setjmp and libpng's calls (a longjmp skips destructors).
bool Encode(int width, int height, const uint8_t* rgb, png_bytep* rows, std::string& out, std::string& error) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &error, KeepError, IgnoreWarning);
  if (!png) {
    error = "out of memory";
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (!info || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, info ? &info : nullptr);
    if (error.empty()) error = "out of memory";
    return false;
  }
  png_set_write_fn(png, &out, AppendToString, NoFlush);
  png_set_IHDR(png, info, png_uint_32(width), png_uint_32(height), 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_ABSOLUTE);
  png_text software{};
  software.compression = PNG_TEXT_COMPRESSION_NONE;
  software.key = const_cast<png_charp>("Software");
  software.text = const_cast<png_charp>("skybake " SKYBAKE_VERSION);
  png_set_text(png, info, &software, 1);
  for (int y = 0; y < height; ++y) rows[y] = const_cast<png_bytep>(rgb + size_t(y) * 3 * size_t(width));
  png_set_rows(png, info, rows);
  png_write_png(png, info, PNG_TRANSFORM_IDENTITY, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

}  // namespace

std::string EncodePngRgb8(int width, int height, const std::vector<uint8_t>& rgb) {
  if (width <= 0 || height <= 0 || rgb.size() != size_t(width) * size_t(height) * 3)
    throw OutputError("cannot encode a PNG of " + std::to_string(width) + " x " + std::to_string(height) +
                      " pixels from " + std::to_string(rgb.size()) + " bytes");
  std::vector<png_bytep> rows(static_cast<size_t>(height));
  std::string out, error;
  if (!Encode(width, height, rgb.data(), rows.data(), out, error)) throw OutputError("libpng: " + error);
  return out;
}

}  // namespace skybake
