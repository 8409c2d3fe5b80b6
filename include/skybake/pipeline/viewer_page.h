// `skybake view DIR`: one HTML page beside a bake, DIR/view.html, that shows
// the sky around you in any browser with no network and no server: drag to
// look around, a slider for the exposure (stops), one to scrub a sequence's
// frames. Everything is inside the page: three.js, its EXRLoader and fflate
// (copied from the project's npm packages, tests/viewer/node_modules, as
// data: modules of an import map) and each frame's latlong (the EXR when
// the bake wrote one, else its PNG preview), base64, as long as the frames
// so far fit in `embed_mib`: a long sequence's later frames are referenced
// by their file names instead, and the page loads them when the frame
// slider reaches them, which a browser allows when the folder is served
// over HTTP (`python3 -m http.server` in DIR), not from file://. The first
// frame is always inside.
//
// The sky is drawn by a shader that reads the OpenEXR latlong with
// Imf::LatLongMap's own mapping (not three.js's equirect, which centres +X),
// in skybake's world: +Y up, North = -Z; the view starts facing North.
// Frames come from DIR/manifest.json; without one, from the
// BASE_latlong[.NNNN].exr files of DIR (a `skybake testpattern` folder).
#pragma once

#include <string>

namespace skybake {

struct ViewPageOptions {
  std::string dir;          // the bake's folder; the page is written there
  std::string three_dir;    // three.js's npm package folder (empty: the project's; main: $SKYBAKE_THREE_DIR)
  bool force = false;       // replace an existing view.html
  double embed_mib = 64.0;  // frames inside the page while their files total at most this, MiB (the first always)
};

// Writes DIR/view.html; returns its path. Throws OutputError (no frames,
// three.js missing: the message has the fix) or OutputExistsError.
std::string WriteViewPage(const ViewPageOptions& options);

}  // namespace skybake
