// skybake's own encoder of scanline EXR files without compression or with
// ZIP/ZIPS: pixels are laid out, predicted and deflated chunk by chunk with
// libdeflate, on several threads, and OpenEXRCore writes the header, the
// chunks and the offset table. Against OpenEXR 3.1's own (zlib) encoder at
// the same level: half the time on 2 threads and files a quarter smaller
// (the codec table of docs/performance.md). Any OpenEXR reader decodes the
// result (tests/output/exr_io_test.cc checks it against OpenEXR's encoder bit for
// bit).
#pragma once

#include <string>

#include "skybake/output/exr_io.h"

namespace skybake {

// True when EncodeExrDeflate handles `compression` ("none", "zip", "zips").
bool DeflateEncoderHandles(const std::string& compression);

// The bytes of EXR files of R, G, B (ExrFile::name is for messages; each
// file's compression is one DeflateEncoderHandles accepts), their chunks
// compressed on `threads` threads (at least 1), taken in turn as each
// thread comes free.
std::vector<std::string> EncodeExrsDeflate(const std::vector<const ExrFile*>& files, int threads);

}  // namespace skybake
