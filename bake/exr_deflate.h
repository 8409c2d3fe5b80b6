// skybake's own encoder of scanline EXR files without compression or with
// ZIP/ZIPS: pixels are laid out, predicted and deflated chunk by chunk with
// libdeflate, on several threads, and OpenEXRCore writes the header, the
// chunks and the offset table. Against OpenEXR 3.1's own (zlib) encoder at
// the same level: half the time on 2 threads and files a quarter smaller
// (the codec table of docs/performance.md). Any OpenEXR reader decodes the
// result (tests/exr_io_test.cc checks it against OpenEXR's encoder bit for
// bit).
#pragma once

#include <string>

#include "skybake/exr_io.h"

namespace skybake {

// True when EncodeExrDeflate handles `compression` ("none", "zip", "zips").
bool DeflateEncoderHandles(const std::string& compression);

// The bytes of an EXR file of R, G, B (`name` is for messages), compressed on
// `threads` threads (at least 1).
std::string EncodeExrDeflate(const std::string& name, const RgbaImage& image, const ExrWriteOptions& options,
                             int threads);

}  // namespace skybake
