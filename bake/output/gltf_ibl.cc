#include "skybake/output/gltf_ibl.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>

#include <libdeflate.h>

namespace skybake {
namespace {

void Put32(std::string& out, uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(char((v >> shift) & 0xff));
}

void Chunk(std::string& out, const char type[4], const std::string& data) {
  Put32(out, uint32_t(data.size()));
  std::string body(type, 4);
  body += data;
  out += body;
  Put32(out, libdeflate_crc32(0, body.data(), body.size()));
}

// PNG of 8-bit RGBA rows (PNG specification, filter 0 on every row).
std::string EncodePngRgba(const std::vector<uint8_t>& rgba, int width, int height) {
  std::string raw;
  raw.reserve(size_t(height) * (1 + 4 * size_t(width)));
  for (int y = 0; y < height; ++y) {
    raw.push_back(0);
    raw.append(reinterpret_cast<const char*>(rgba.data()) + size_t(y) * 4 * width, size_t(4) * width);
  }
  std::unique_ptr<libdeflate_compressor, void (*)(libdeflate_compressor*)> c(libdeflate_alloc_compressor(9),
                                                                             libdeflate_free_compressor);
  if (!c) throw std::bad_alloc();
  std::string z(libdeflate_zlib_compress_bound(c.get(), raw.size()), '\0');
  z.resize(libdeflate_zlib_compress(c.get(), raw.data(), raw.size(), z.data(), z.size()));
  std::string png("\x89PNG\r\n\x1a\n", 8);
  std::string header;
  Put32(header, uint32_t(width));
  Put32(header, uint32_t(height));
  header += std::string("\x08\x06\x00\x00\x00", 5);  // 8 bits, RGBA, deflate, filter 0, no interlace
  Chunk(png, "IHDR", header);
  Chunk(png, "IDAT", z);
  Chunk(png, "IEND", "");
  return png;
}

}  // namespace

double GltfIblScale(const ShRgb& sh) {
  // Average radiance: L_00 Y_00 with E_00 = pi L_00 (Ramamoorthi & Hanrahan 2001), Y_00 = 1 / (2 sqrt(pi)).
  const double y00 = 0.5 / std::sqrt(M_PI);
  const double average = std::max({sh[0][0], sh[0][1], sh[0][2]}) / M_PI * y00;
  if (!(average > 0.0) || !std::isfinite(average)) return 1.0;
  return std::exp2(std::floor(std::log2(4.0 / average)));
}

std::string EncodeRgbdFacePng(const float* rgba, int size, double scale) {
  std::vector<uint8_t> out(size_t(size) * size * 4);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const float* t = rgba + 4 * (size_t(y) * size + (size - 1 - x));  // flipped about the vertical axis
      double v[3];
      for (int c = 0; c < 3; ++c) v[c] = std::max(0.0, double(t[c]) * scale);
      const double peak = std::max({v[0], v[1], v[2], 1e-12});
      const double d = std::clamp(std::floor(std::max(255.0 / peak, 1.0)), 1.0, 255.0);
      uint8_t* o = &out[4 * (size_t(y) * size + x)];
      for (int c = 0; c < 3; ++c)
        o[c] = uint8_t(std::lround(255.0 * std::pow(std::min(v[c] * d / 255.0, 1.0), 1.0 / 2.2)));
      o[3] = uint8_t(d);
    }
  return EncodePngRgba(out, size, size);
}

void DecodeRgbd(const uint8_t rgbd[4], double rgb[3]) {
  const double d = std::max(1, int(rgbd[3])) / 255.0;
  for (int c = 0; c < 3; ++c) rgb[c] = std::pow(rgbd[c] / 255.0, 2.2) / d;
}

int PngWidth(const std::string& bytes) {
  if (bytes.size() < 24 || bytes.compare(0, 8, std::string("\x89PNG\r\n\x1a\n", 8)) != 0) return 0;
  int w = 0;
  for (int i = 16; i < 20; ++i) w = (w << 8) | static_cast<unsigned char>(bytes[size_t(i)]);
  return w;
}

}  // namespace skybake
