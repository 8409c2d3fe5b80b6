// The style gallery: bakes a set of styles at preview size and lays their
// tone-mapped skies out on one labelled contact sheet (PNG).
//
// Each tile is the upper half of the style's latlong preview (the sky above
// the ground plane, all 360 degrees of azimuth; South in the middle, North at
// both ends), under a label with the style's name and the AOAS principles it
// uses. A style with its own [schedule] (a date, a time and a place, as the
// night styles configs/styles/night_*.toml) is baked at its schedule's first
// frame, so its stars and Moon are placed; its label adds the night sky's
// parts and the clock time. Labels are drawn with OpenImageIO's text renderer (FreeType and the
// DejaVu fonts, Debian package fonts-dejavu-core).
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "skybake/input/schedule.h"
#include "skybake/pipeline/pipeline.h"

namespace skybake {

struct GalleryOptions {
  std::string out_dir = "out/gallery";
  int latlong_height = 192;  // each style's latlong is 2H x H
  int columns = 2;
  std::vector<std::string> overrides;  // --set, applied to every style
  BakeOptions bake;                    // device, validation, progress; bake.force replaces a previous gallery
};

struct GalleryEntry {
  std::string name;        // the style file's stem
  std::string path;        // the style file
  std::string principles;  // e.g. "hue, clouds, shapes"
  std::string preview;     // its latlong preview PNG
};

struct GalleryResult {
  std::vector<GalleryEntry> entries;
  std::string contact_sheet;  // the labelled PNG
  int validation_messages = 0;
};

// The .toml files of `dir`, sorted by name.
std::vector<std::string> StyleFilesIn(const std::string& dir);

// The AOAS principles a style turns on, as a short list ("physical" if none).
std::string DescribePrinciples(const SkyStyle& style);

// A style with its own [schedule]: the schedule cut to its first frame and
// that frame's style; nothing for a style without one, or when `errors`
// gets the schedule's, the frame's or the night sky's errors (CheckNightSky
// with `star_catalogue`).
struct GalleryFrame {
  SkyStyle style;
  Schedule schedule;
};
std::optional<GalleryFrame> GalleryFrameOf(const std::string& path, const std::vector<std::string>& overrides,
                                           const std::string& star_catalogue, std::vector<ConfigError>& errors);

// Bakes every style into out_dir/<style>/ (its latlong preview and its
// manifest) and writes out_dir/gallery.png. Throws ConfigFailure for an
// invalid style or schedule (and a night sky without its catalogue), and
// what BakeStyle and BakeSequence throw.
GalleryResult BakeGallery(const std::vector<std::string>& style_paths, const GalleryOptions& options);

}  // namespace skybake
