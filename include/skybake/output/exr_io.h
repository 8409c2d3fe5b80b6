// Writing OpenEXR environment maps and PNG previews, safely: each file is
// written under a temporary name in its destination folder and renamed into
// place only once complete, so a crash never leaves a truncated file.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "skybake/base/errors.h"
#include "skybake/input/output_settings.h"

namespace skybake {

// RGBA float pixels, rows from the top.
struct RgbaImage {
  int width = 0;
  int height = 0;
  std::vector<float> rgba;      // RGBA float texels, rows from the top; empty when `view` is set
  const float* view = nullptr;  // or texels held elsewhere (SkyRenderer::RenderInPlace), laid out as `rgba`
  const float* data() const { return view ? view : rgba.data(); }
  size_t texels() const { return size_t(width) * size_t(height); }
};

constexpr double kHalfMax = 65504.0;

struct ExrWriteOptions {
  PixelType pixel_type = PixelType::kHalf;
  std::string compression = "zip";
  int zip_level = kDefaultZipLevel;               // deflate level 1..9 of zip and zips (docs/performance.md)
  int envmap = -1;                                // -1: none; 0: ENVMAP_LATLONG; 1: ENVMAP_CUBE
  double scale = 1.0;                             // multiplies every value before writing
  double white_luminance = 0.0;                   // cd/m^2 of RGB (1,1,1) after scaling; 0: not written
  std::map<std::string, std::string> attributes;  // provenance string attributes
  // The `chromaticities` attribute: CIE xy of red, green, blue and white
  // (Rec.709 and D65 unless the values are in another space, ACEScg say).
  std::array<float, 8> chromaticities = {0.64f, 0.33f, 0.30f, 0.60f, 0.15f, 0.06f, 0.3127f, 0.3290f};
  // none, zip and zips are encoded by skybake's libdeflate encoder; true
  // uses OpenEXR's own (zlib) encoder instead, for comparison.
  bool openexr_encoder = false;
};

// Largest value over the RGB channels of the images; throws OutputError if
// any value is NaN, infinite or negative (never written).
double CheckedMaxValue(const std::vector<const RgbaImage*>& images);

// The power-of-two scale that brings `max_value` within half range, 1 when it
// already fits; with OverflowPolicy::kRefuse, throws OutputError instead.
double HalfRangeScale(double max_value, OverflowPolicy policy);

// Encodes R, G, B channels into the bytes of an EXR file (`name` is for
// messages). Chunks are compressed on SetExrThreads threads.
std::string EncodeExr(const std::string& name, const RgbaImage& image, const ExrWriteOptions& options);

// One file of EncodeExrs.
struct ExrFile {
  std::string name;  // for messages
  const RgbaImage* image = nullptr;
  ExrWriteOptions options;
};

// Encodes several files at once (a frame's faces, strip and latlong): the
// chunks of every file are shared among SetExrThreads threads as each comes
// free, so a file whose lower half is uniform ground does not leave a thread
// idle. The bytes of each file, in order; the same bytes as EncodeExr of
// each file alone, on any number of threads.
std::vector<std::string> EncodeExrs(const std::vector<ExrFile>& files);

// Encodes and writes atomically; returns the size of the written file in bytes.
uint64_t WriteExr(const std::string& path, const RgbaImage& image, const ExrWriteOptions& options);

// Threads that compress the chunks of one file (OpenEXR's global thread pool
// for its own encoder; 0 or 1: the calling thread only). Idempotent and cheap
// when the size is unchanged.
void SetExrThreads(int threads);

// Writes an 8-bit sRGB PNG (EncodePngRgb8: libpng, png_io.h).
uint64_t WritePng(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb);

// Writes `bytes` to a temporary file beside `path`, syncs it and renames it
// over `path`. The one way skybake writes a file: the temporary has an
// unguessable name and is created with O_CREAT | O_EXCL | O_NOFOLLOW, so an
// existing file or a planted link is never opened or followed, and the
// rename replaces a link at `path` rather than writing through it. On any
// failure the temporary is removed and OutputError names the file, the
// system error and the fix (a full disk, a file-size limit).
void WriteFileAtomically(const std::string& path, std::string_view bytes);

// The same for a file given in pieces: `produce` calls the sink with each
// piece in turn (a manifest written from its frames' entries on disk, never
// whole in memory). An exception from `produce` removes the temporary and
// passes on.
using ByteSink = std::function<void(std::string_view)>;
void WriteFileAtomically(const std::string& path, const std::function<void(const ByteSink&)>& produce);

// Removes hidden temporaries (TemporaryPathFor) of the given file names in
// `dir` left by processes that no longer run (a killed bake), and links at
// such names (never skybake's); returns them.
std::vector<std::string> RemoveStaleTemporaries(const std::string& dir, const std::vector<std::string>& names);

// Temporary name beside `path` for a write in progress: hidden, tagged with
// the pid (for RemoveStaleTemporaries) and 64 random bits,
// `.sky_px.exr.tmp1234.0123456789abcdef`.
std::string TemporaryPathFor(const std::string& path);

// Creates a new file at a fresh TemporaryPathFor(path) (set in `temporary`)
// with O_CREAT | O_EXCL | O_NOFOLLOW, for writing; returns its descriptor,
// or -1 with errno set.
int CreateExclusiveFile(std::string& temporary, const std::string& path);

}  // namespace skybake
