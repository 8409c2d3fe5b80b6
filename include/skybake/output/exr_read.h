// An OpenEXR file skybake wrote, read back through the door (file_door.h):
// the cloud shadow map under the glTF ground, a frame's EXR for the Python
// module's arrays. The file is opened non-blocking, checked to be a regular
// file (a FIFO planted at its name is refused, not waited on; a link is not
// followed), read whole within kMaxExrFileBytes, and its data window checked
// against kMaxExrPixels from the header before any pixel is allocated; the
// pixels are decoded from the bytes read, never from the name again.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace skybake {

// 1 GiB: a 16384 x 8192 RGBA half EXR stored without compression.
inline constexpr uint64_t kMaxExrFileBytes = uint64_t(1) << 30;
// 2^28 pixels: 16384 x 16384, the largest image skybake writes.
inline constexpr uint64_t kMaxExrPixels = uint64_t(1) << 28;

// The RGBA of `path` as float, rows from the top, interleaved. "" or the
// problem as a phrase that completes "PATH ..." ("is a FIFO (named pipe),
// not a regular file", "is not an OpenEXR file (...)").
std::string ReadExrRgba(const std::string& path, int& width, int& height, std::vector<float>& rgba);

// The data window's size of an OpenEXR file already read into `bytes`
// (the viewer page's frames): "" or the problem, as for ReadExrRgba.
std::string ExrSizeOfBytes(const std::string& bytes, int& width, int& height);

}  // namespace skybake
