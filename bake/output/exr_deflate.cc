#include "exr_deflate.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <bit>
#include <cstring>
#include <memory>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <Imath/half.h>
#include <OpenEXR/openexr.h>
#include <libdeflate.h>

#if defined(__x86_64__)
#include <cpuid.h>
#include <immintrin.h>
#endif

namespace skybake {
namespace {

static_assert(std::endian::native == std::endian::little, "EXR pixel data is little-endian");

// Scanlines per chunk, by the OpenEXR file format: 16 for ZIP, 1 for ZIPS and
// for no compression.
int LinesPerChunk(const std::string& compression) { return compression == "zip" ? 16 : 1; }

exr_compression_t CoreCompression(const std::string& compression) {
  if (compression == "zip") return EXR_COMPRESSION_ZIP;
  if (compression == "zips") return EXR_COMPRESSION_ZIPS;
  return EXR_COMPRESSION_NONE;
}

// Half-float bits of `in` x `scale`, rounded to nearest even like
// Imath::half(float).
void ToHalfPortable(const float* in, size_t n, float scale, uint16_t* out) {
  for (size_t i = 0; i < n; ++i) out[i] = half(in[i] * scale).bits();
}

#if defined(__x86_64__)
// The same, eight at a time by the F16C instruction (the same rounding).
__attribute__((target("avx,f16c"))) void ToHalfF16c(const float* in, size_t n, float scale, uint16_t* out) {
  const __m256 s = _mm256_set1_ps(scale);
  size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    const __m256 v = _mm256_mul_ps(_mm256_loadu_ps(in + i), s);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + i), _mm256_cvtps_ph(v, _MM_FROUND_TO_NEAREST_INT));
  }
  ToHalfPortable(in + i, n - i, scale, out + i);
}
#endif

void ToHalf(const float* in, size_t n, float scale, uint16_t* out) {
#if defined(__x86_64__)
  // F16C: CPUID leaf 1, ECX bit 29 (Intel SDM vol. 2A, CPUID). Asked of the
  // CPU directly: clang's __builtin_cpu_supports knows no "f16c".
  static const bool f16c = [] {
    unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;
    return __builtin_cpu_supports("avx") && __get_cpuid(1, &eax, &ebx, &ecx, &edx) && (ecx & (1u << 29)) != 0;
  }();
  if (f16c) return ToHalfF16c(in, n, scale, out);
#endif
  ToHalfPortable(in, n, scale, out);
}

// Bytes of one chunk as the file stores them uncompressed: for each scanline,
// the channels in name order (B, G, R), each a row of little-endian values.
void LayOutChunk(const RgbaImage& image, int y0, int lines, bool half_pixels, float scale, uint8_t* out,
                 std::vector<uint16_t>& row_half) {
  const int w = image.width;
  row_half.resize(size_t(w) * 4);
  for (int y = y0; y < y0 + lines; ++y) {
    const float* row = image.data() + size_t(y) * w * 4;
    if (half_pixels) ToHalf(row, size_t(w) * 4, scale, row_half.data());
    for (int channel : {2, 1, 0}) {  // B, G, R
      if (half_pixels) {
        for (int x = 0; x < w; ++x) {
          std::memcpy(out, &row_half[4 * size_t(x) + channel], 2);
          out += 2;
        }
      } else {
        for (int x = 0; x < w; ++x) {
          const float v = row[4 * x + channel] * scale;
          std::memcpy(out, &v, 4);
          out += 4;
        }
      }
    }
  }
}

// The ZIP predictor of the EXR format: the even bytes, then the odd bytes,
// each byte replaced by its difference from the previous one plus 128.
void Predict(const uint8_t* raw, size_t n, uint8_t* out) {
  const size_t half_n = (n + 1) / 2;
  for (size_t i = 0; i < half_n; ++i) out[i] = raw[2 * i];
  for (size_t i = 0; 2 * i + 1 < n; ++i) out[half_n + i] = raw[2 * i + 1];
  uint8_t previous = out[0];
  for (size_t i = 1; i < n; ++i) {
    const uint8_t current = out[i];
    out[i] = uint8_t(current - previous + 128);
    previous = current;
  }
}

// Half pixels: the predictor's output straight from the image, without the
// chunk's raw bytes (LayOutChunk then Predict give the same bytes). The raw
// bytes are the chunk's values in file order, two little-endian bytes each,
// so the predictor's even bytes are the values' low bytes and its odd bytes
// their high bytes. `split` holds those, `out` gets their differences.
void PredictHalfChunk(const RgbaImage& image, int y0, int lines, float scale, uint8_t* split, uint8_t* out,
                      std::vector<uint16_t>& row_half) {
  const int w = image.width;
  row_half.resize(size_t(w) * 4);
  const size_t count = size_t(lines) * w * 3;  // values in the chunk
  uint8_t* lo = split;
  uint8_t* hi = split + count;
  for (int y = y0; y < y0 + lines; ++y) {
    ToHalf(image.data() + size_t(y) * w * 4, size_t(w) * 4, scale, row_half.data());
    const uint16_t* h = row_half.data();
    for (int channel : {2, 1, 0}) {  // B, G, R
      for (int x = 0; x < w; ++x) {
        const uint16_t v = h[4 * x + channel];
        lo[x] = uint8_t(v);
        hi[x] = uint8_t(v >> 8);
      }
      lo += w;
      hi += w;
    }
  }
  const size_t n = 2 * count;
  out[0] = split[0];
  for (size_t i = 1; i < n; ++i) out[i] = uint8_t(split[i] - split[i - 1] + 128);
}

struct CompressorDeleter {
  void operator()(libdeflate_compressor* c) const { libdeflate_free_compressor(c); }
};

// One libdeflate compressor per thread and level (a compressor is not
// shareable between threads; allocating one costs more than a small chunk).
// Its output depends on the chunk and the level only.
libdeflate_compressor* ThreadCompressor(int level) {
  thread_local std::unique_ptr<libdeflate_compressor, CompressorDeleter> compressor;
  thread_local int compressor_level = -1;
  if (!compressor || compressor_level != level) {
    compressor.reset(libdeflate_alloc_compressor(level));
    if (!compressor) throw std::bad_alloc();
    compressor_level = level;
  }
  return compressor.get();
}

// Bytes of one scanline of `file` as stored uncompressed: B, G, R.
size_t LineBytes(const ExrFile& file) {
  return size_t(file.image->width) * 3 * (file.options.pixel_type == PixelType::kHalf ? 2 : 4);
}

struct Chunk {
  int y = 0;
  std::vector<uint8_t> bytes;  // as stored: deflated, or raw when that is not smaller
};

// One thread's buffers, grown to the largest chunk it has met.
class ChunkEncoder {
 public:
  // Chunk `index` of `file` (chunks of `lines_per_chunk` lines).
  void Encode(const ExrFile& file, int lines_per_chunk, size_t index, Chunk& chunk) {
    const RgbaImage& image = *file.image;
    const ExrWriteOptions& options = file.options;
    const bool half_pixels = options.pixel_type == PixelType::kHalf;
    const bool deflate = options.compression != "none";
    const float scale = float(options.scale);
    const size_t line_bytes = LineBytes(file);
    chunk.y = int(index) * lines_per_chunk;
    const int lines = std::min(lines_per_chunk, image.height - chunk.y);
    const size_t n = line_bytes * lines;
    if (raw_.size() < n) {
      raw_.resize(n);
      predicted_.resize(n);
    }
    if (deflate) {
      libdeflate_compressor* compressor = ThreadCompressor(options.zip_level);
      packed_.resize(std::max(packed_.size(), libdeflate_zlib_compress_bound(compressor, n)));
      if (half_pixels) {
        PredictHalfChunk(image, chunk.y, lines, scale, raw_.data(), predicted_.data(), row_half_);
      } else {
        LayOutChunk(image, chunk.y, lines, false, scale, raw_.data(), row_half_);
        Predict(raw_.data(), n, predicted_.data());
      }
      const size_t size = libdeflate_zlib_compress(compressor, predicted_.data(), n, packed_.data(), packed_.size());
      // A chunk that does not shrink is stored raw; readers tell the two
      // apart by comparing its size with the uncompressed size.
      if (size > 0 && size < n) {
        chunk.bytes.assign(packed_.begin(), packed_.begin() + size);
        return;
      }
      if (!half_pixels) {  // raw_ holds the chunk's bytes already
        chunk.bytes.assign(raw_.begin(), raw_.begin() + n);
        return;
      }
    }
    LayOutChunk(image, chunk.y, lines, half_pixels, scale, raw_.data(), row_half_);
    chunk.bytes.assign(raw_.begin(), raw_.begin() + n);
  }

 private:
  std::vector<uint8_t> raw_, predicted_, packed_;
  std::vector<uint16_t> row_half_;
};

struct Sink {
  std::string bytes;
  std::string error;
};

int64_t WriteToSink(exr_const_context_t, void* user_data, const void* buffer, uint64_t size, uint64_t offset,
                    exr_stream_error_func_ptr_t) {
  auto* sink = static_cast<Sink*>(user_data);
  if (offset + size > sink->bytes.size()) sink->bytes.resize(offset + size);
  std::memcpy(sink->bytes.data() + offset, buffer, size);
  return int64_t(size);
}

// The sink of the file this thread assembles. The error handler must not
// ask the context for its user data: OpenEXRCore calls it with the
// context's lock held (exr_attr_set_string with a name too long, say), and
// exr_get_user_data takes the same lock, so the bake would hang.
thread_local Sink* assembling_sink = nullptr;

void RecordError(exr_const_context_t, exr_result_t code, const char* message) {
  if (assembling_sink) assembling_sink->error = fmt::format("{} ({})", message, exr_get_error_code_as_string(code));
}

// The file around its encoded chunks: OpenEXRCore writes the header, the
// chunks in order and the offset table into memory.
std::string AssembleExr(const ExrFile& file, const std::vector<Chunk>& chunks) {
  const std::string& name = file.name;
  const RgbaImage& image = *file.image;
  const ExrWriteOptions& options = file.options;
  Sink sink;
  size_t chunk_bytes = 0;
  for (const Chunk& chunk : chunks) chunk_bytes += chunk.bytes.size() + 8;
  sink.bytes.reserve(chunk_bytes + 16 * 1024);  // chunks, their offsets, a header of a few KiB
  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  init.user_data = &sink;
  init.write_fn = &WriteToSink;
  init.error_handler_fn = &RecordError;
  assembling_sink = &sink;
  struct Unset {
    ~Unset() { assembling_sink = nullptr; }
  } unset;
  exr_context_t context = nullptr;
  auto check = [&](exr_result_t result, const char* what) {
    if (result == EXR_ERR_SUCCESS) return;
    std::string message = sink.error.empty() ? exr_get_default_error_message(result) : sink.error;
    if (context) exr_finish(&context);
    throw OutputError(fmt::format("cannot encode {} ({}): {}", name, what, message));
  };
  check(exr_start_write(&context, name.c_str(), EXR_WRITE_FILE_DIRECTLY, &init), "starting");
  int part = 0;
  check(exr_add_part(context, nullptr, EXR_STORAGE_SCANLINE, &part), "adding the part");
  check(exr_initialize_required_attr_simple(context, part, image.width, image.height,
                                            CoreCompression(options.compression)),
        "the required attributes");
  const exr_pixel_type_t type = options.pixel_type == PixelType::kHalf ? EXR_PIXEL_HALF : EXR_PIXEL_FLOAT;
  for (const char* channel : {"B", "G", "R"})
    check(exr_result_t(exr_add_channel(context, part, channel, type, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1)), "a channel");
  // The primaries and white of the options (Rec.709 and D65 unless told).
  const std::array<float, 8>& xy = options.chromaticities;
  const exr_attr_chromaticities_t primaries{xy[0], xy[1], xy[2], xy[3], xy[4], xy[5], xy[6], xy[7]};
  check(exr_attr_set_chromaticities(context, part, "chromaticities", &primaries), "chromaticities");
  if (options.envmap >= 0) check(exr_attr_set_envmap(context, part, "envmap", exr_envmap_t(options.envmap)), "envmap");
  if (options.white_luminance > 0.0)
    check(exr_attr_set_float(context, part, "whiteLuminance", float(options.white_luminance)), "whiteLuminance");
  for (const auto& [key, value] : options.attributes)
    check(exr_attr_set_string(context, part, key.c_str(), value.c_str()), key.c_str());
  check(exr_write_header(context), "the header");
  for (const Chunk& chunk : chunks)
    check(exr_write_scanline_chunk(context, part, chunk.y, chunk.bytes.data(), chunk.bytes.size()), "a chunk");
  const exr_result_t finished = exr_finish(&context);
  context = nullptr;
  check(finished, "the offset table");
  return std::move(sink.bytes);
}

}  // namespace

bool DeflateEncoderHandles(const std::string& compression) {
  return compression == "none" || compression == "zip" || compression == "zips";
}

std::vector<std::string> EncodeExrsDeflate(const std::vector<const ExrFile*>& files, int threads) {
  // Work items: runs of a file's chunks of about 64 KiB of pixels or more
  // (one ZIP chunk of a 512-texel face holds 48 KiB of half pixels, of a
  // 2048-texel latlong 192 KiB), handed out in file order as threads come
  // free.
  struct Item {
    size_t file, first, last;
  };
  std::vector<std::vector<Chunk>> chunks(files.size());
  std::vector<Item> items;
  for (size_t f = 0; f < files.size(); ++f) {
    const ExrFile& file = *files[f];
    if (!DeflateEncoderHandles(file.options.compression))
      throw OutputError(fmt::format("cannot encode {}: compression {} is not ZIP, ZIPS or none", file.name,
                                    file.options.compression));
    const int lines = LinesPerChunk(file.options.compression);
    const size_t count = size_t((file.image->height + lines - 1) / lines);
    chunks[f].resize(count);
    const size_t per_item = std::max<size_t>(1, (64 * 1024) / std::max<size_t>(LineBytes(file) * size_t(lines), 1));
    for (size_t first = 0; first < count; first += per_item)
      items.push_back({f, first, std::min(count, first + per_item)});
  }
  std::atomic<size_t> next{0};
  std::atomic<bool> failed{false};
  const size_t workers = std::clamp<size_t>(size_t(std::max(threads, 1)), 1, std::max<size_t>(items.size(), 1));
  std::vector<std::exception_ptr> failures(workers);
  auto work = [&](size_t w) {
    try {
      ChunkEncoder encoder;
      for (size_t i; !failed && (i = next.fetch_add(1)) < items.size();) {
        const Item& item = items[i];
        const ExrFile& file = *files[item.file];
        for (size_t c = item.first; c < item.last; ++c)
          encoder.Encode(file, LinesPerChunk(file.options.compression), c, chunks[item.file][c]);
      }
    } catch (...) {
      failures[w] = std::current_exception();
      failed = true;
    }
  };
  std::vector<std::thread> helpers;
  for (size_t w = 1; w < workers; ++w) helpers.emplace_back(work, w);
  work(0);
  for (std::thread& t : helpers) t.join();
  for (const std::exception_ptr& failure : failures)
    if (failure) std::rethrow_exception(failure);

  // Each file's chunks freed once it is assembled: float chunks barely
  // compress, and a frame's are 27 MB.
  std::vector<std::string> encoded;
  for (size_t f = 0; f < files.size(); ++f) {
    encoded.push_back(AssembleExr(*files[f], chunks[f]));
    std::vector<Chunk>().swap(chunks[f]);
  }
  return encoded;
}

}  // namespace skybake
