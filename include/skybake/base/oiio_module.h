// The OpenImageIO half of skybake, in a module loaded on first use.
//
// Linking OpenImageIO pulls in some 260 shared libraries whose start-up
// costs about 0.3 s per process on the 2-core machine (docs/performance.md),
// more than the whole W1 budget's share for it. A bake loads them only for
// what needs OpenImageIO: the gallery's contact sheet (its labels) and cloud
// weather or formation images; PNGs are written with libpng
// (output/png_io.h). The module is built beside the binaries
// (libskybake_oiio.so) and found from SetOiioModuleDir (main: SKYBAKE_MODULE_DIR) or the directory of
// the running executable.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace skybake {

// One labelled tile of a contact sheet: the upper half of a preview PNG.
struct SheetCell {
  std::string preview_path, name, detail;
};

struct SheetLayout {
  int tile_w = 0, tile_h = 0, columns = 1, margin = 8, label_height = 40;
  int name_size = 17, detail_size = 12;
  std::string name_font = "DejaVuSans-Bold", detail_font = "DejaVuSans";
};

// The module's entry points; each returns false with a message in `error`.
struct OiioModule {
  bool (*compose_sheet)(const std::vector<SheetCell>& cells, const SheetLayout& layout, std::vector<uint8_t>& rgb,
                        int& width, int& height, std::string& error);
  // Any 2D image OpenImageIO reads from memory (EXR, PNG, TIFF, ...): the
  // file's `bytes` (read through the door, file_door.h; `name`, its path,
  // picks the format), its first subimage as floats, channels interleaved,
  // values as stored (no colour conversion). Refused from its header, before
  // any pixel is decoded, when width x height x channels exceeds
  // `max_samples`.
  bool (*read_image)(const std::string& name, const std::string& bytes, uint64_t max_samples, int& width, int& height,
                     int& channels, std::vector<float>& pixels, std::string& error);
};

// Loads the module once (thread-safe); throws OutputError naming the file
// and the fix when it cannot.
const OiioModule& LoadOiioModule();

// The folder LoadOiioModule looks in first, before the executable's: main
// passes $SKYBAKE_MODULE_DIR here before any thread starts (the library
// reads no environment). Has no effect once the module is loaded.
void SetOiioModuleDir(const std::string& dir);

}  // namespace skybake

// The module's one exported symbol. Its name carries the version of
// OiioModule's layout: a change of the struct renames it, so a binary never
// calls into a module of another layout (an older libskybake_oiio.so left
// beside it is passed over, with the name in the error).
extern "C" const skybake::OiioModule* skybake_oiio_module_v3();
