#include "skybake/pipeline/gallery.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include <sys/stat.h>

#include <fmt/format.h>

#include "skybake/base/file_door.h"
#include "skybake/input/config.h"
#include "skybake/output/exr_io.h"
#include "skybake/output/output_lock.h"
#include "skybake/base/oiio_module.h"
#include "skybake/input/schedule.h"
#include "skybake/pipeline/formation_budget.h"
#include "skybake/pipeline/night_sky.h"
#include "skybake/pipeline/render_plan.h"

namespace skybake {
namespace {

constexpr int kLabelHeight = 40;  // pixels above each tile: name, then principles
constexpr int kMargin = 8;        // pixels between tiles
constexpr int kNameSize = 17;
constexpr int kDetailSize = 12;
constexpr const char* kNameFont = "DejaVuSans-Bold";
constexpr const char* kDetailFont = "DejaVuSans";

// OUT/NAME, a style's folder in the gallery: made here, and refused when
// the name is taken by anything but a folder; a link planted there (to a
// folder outside --out) is not followed. OUT itself is the user's and may
// be a link.
std::string StyleFolder(const std::string& out_dir, const std::string& name) {
  const std::string dir = (std::filesystem::path(out_dir) / name).string();
  if (!FolderNameProblem(name).empty())
    throw OutputError(
        fmt::format("{} cannot be a style's folder in the gallery: rename the style file", EscapedText(dir)));
  if (::mkdir(dir.c_str(), 0777) != 0 && errno != EEXIST)
    throw OutputError(
        fmt::format("cannot make the folder {} ({}): choose a writable --out", EscapedText(dir), std::strerror(errno)));
  struct stat st {};
  if (::lstat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode))
    throw OutputExistsError(
        fmt::format("{} is {}, not a folder: the gallery writes each style into a folder of "
                    "--out; remove it, or choose another --out",
                    EscapedText(dir), S_ISLNK(st.st_mode) ? "a symbolic link" : "a file"));
  return dir;
}

}  // namespace

std::vector<std::string> StyleFilesIn(const std::string& dir) {
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    if (entry.is_regular_file() && entry.path().extension() == ".toml") files.push_back(entry.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

std::string DescribePrinciples(const SkyStyle& style) {
  const AoasSettings& a = style.aoas;
  std::vector<std::string> parts;
  if (a.skydome.enabled) parts.push_back("skydome");
  if (a.hue.enabled) parts.push_back(a.hue.color.empty() ? "hue vector" : "hue " + a.hue.color);
  if (a.ambiguity.enabled) parts.push_back(fmt::format("ambiguity l_pt {:g}", a.ambiguity.l_pt));
  if (a.clouds.enabled) parts.push_back(fmt::format("clouds s_noise {:g}", a.clouds.s_noise));
  if (a.shapes.enabled)
    parts.push_back(fmt::format("{} shape{}", a.shapes.shapes.size(), a.shapes.shapes.size() == 1 ? "" : "s"));
  for (const CloudLayer& l : ActiveCloudLayers(style.clouds))
    parts.push_back(fmt::format("{} {:g} km", CloudTypeName(l.type), l.altitude_m * 1e-3));
  const NightSettings& n = style.night;
  if (n.stars) parts.push_back("stars");
  if (n.moonlight) parts.push_back("moonlight");
  else if (n.moon) parts.push_back("Moon");
  if (n.airglow) parts.push_back("airglow");
  // A night style's sun comes from its clock time: to a tenth of a degree.
  parts.push_back(n.Any() ? fmt::format("sun {:.1f} deg", style.sun.elevation_deg)
                          : fmt::format("sun {:g} deg", style.sun.elevation_deg));
  std::string out;
  for (size_t i = 0; i < parts.size(); ++i) out += (i ? ", " : "") + parts[i];
  return out;
}

std::optional<GalleryFrame> GalleryFrameOf(const std::string& path, const std::vector<std::string>& overrides,
                                           const std::string& star_catalogue, std::vector<ConfigError>& errors) {
  if (!FileHasSchedule(path)) return std::nullopt;
  ScheduleResult loaded = LoadSchedule(path);
  if (!loaded.ok()) {
    errors.insert(errors.end(), loaded.errors.begin(), loaded.errors.end());
    return std::nullopt;
  }
  GalleryFrame frame{{}, loaded.schedule};
  frame.schedule.frames.resize(1);
  FrameStyles styles = ResolveFrameStyles(path, overrides, frame.schedule);
  if (!styles.ok()) {
    errors.insert(errors.end(), styles.errors.begin(), styles.errors.end());
    return std::nullopt;
  }
  frame.style = styles.styles.front();
  const std::vector<ConfigError> night = CheckNightSky({&frame.style}, &frame.schedule, star_catalogue);
  if (!night.empty()) {
    errors.insert(errors.end(), night.begin(), night.end());
    return std::nullopt;
  }
  return frame;
}

namespace {

// A style's overrides in the gallery: --set, then its latlong preview only.
std::vector<std::string> GalleryOverrides(const std::string& path, const GalleryOptions& options) {
  std::vector<std::string> overrides = options.overrides;
  const std::string name = std::filesystem::path(path).stem().string();
  for (const std::string& o :
       {std::string("output.faces=false"), std::string("output.cube_strip=false"), std::string("output.latlong=false"),
        std::string("output.preview=true"), std::string("gltf.enabled=false"),
        fmt::format("output.basename=\"{}\"", name), fmt::format("render.latlong_height={}", options.latlong_height)})
    overrides.push_back(o);
  return overrides;
}

// Every style's frame against the budget (BudgetError naming the style)
// before the first is baked: a gallery is refused whole, not after the
// styles before the one over budget.
void CheckGalleryBudgets(const std::vector<std::string>& style_paths, const GalleryOptions& options) {
  for (const std::string& path : style_paths) {
    const std::vector<std::string> overrides = GalleryOverrides(path, options);
    ConfigResult config = LoadSkyStyle(path, overrides);
    if (!config.ok()) throw ConfigFailure(path + " is not a valid style", config.errors);
    std::vector<ConfigError> errors;
    const std::optional<GalleryFrame> frame = GalleryFrameOf(path, overrides, options.bake.star_catalogue, errors);
    try {
      if (frame) {
        const std::vector<SkyStyle> styles = {frame->style};  // the plan points into it
        const RenderPlan plan = PlanSequenceBake(styles, frame->schedule, std::nullopt);
        CheckBudget(frame->style, options.bake);
        CheckFormationBudget(plan, options.bake);
      } else {
        CheckBudget(config.style, options.bake);
        CheckFormationBudget(PlanSingleBake(config.style), options.bake);
      }
    } catch (const BudgetError& e) {
      throw BudgetError(fmt::format("gallery style {}: {}; nothing was baked", path, e.what()));
    }
  }
}

}  // namespace

GalleryResult BakeGallery(const std::vector<std::string>& style_paths, const GalleryOptions& options) {
  GalleryResult result;
  CheckGalleryBudgets(style_paths, options);
  std::filesystem::create_directories(options.out_dir);
  // The sheet, like every style's files, is new unless --force; a link at
  // its name counts as a file (it is replaced, never followed). Locked
  // against another gallery writing it.
  const std::string sheet_path = (std::filesystem::path(options.out_dir) / "gallery.png").string();
  const OutputLock lock = OutputLock::Claim(options.out_dir, {"gallery.png"});
  std::error_code ec;
  if (!options.bake.force && std::filesystem::exists(std::filesystem::symlink_status(sheet_path, ec)))
    throw OutputExistsError(
        fmt::format("{} already exists: pass --force to replace the gallery, or choose another --out", sheet_path));

  // Bake each style's latlong preview only.
  for (const std::string& path : style_paths) {
    const std::string name = std::filesystem::path(path).stem().string();
    const std::vector<std::string> overrides = GalleryOverrides(path, options);
    ConfigResult config = LoadSkyStyle(path, overrides);
    if (!config.ok()) throw ConfigFailure(path + " is not a valid style", config.errors);
    BakeOptions bake = options.bake;
    bake.out_dir = StyleFolder(options.out_dir, name);  // preview + manifest
    // A style with its own [schedule] (a date, a time and a place: the
    // night styles) is baked at its schedule's first frame, as a sequence of
    // that one frame.
    BakeResult baked;
    std::string principles;
    std::vector<ConfigError> errors;
    if (std::optional<GalleryFrame> frame = GalleryFrameOf(path, overrides, bake.star_catalogue, errors)) {
      baked = BakeSequence({frame->style}, frame->schedule, bake);
      principles = DescribePrinciples(frame->style);
      if (const std::optional<CivilTime>& t = frame->schedule.frames.front().time)
        principles += fmt::format(", {:04}-{:02}-{:02} {:02}:{:02}", t->year, t->month, t->day, t->hour, t->minute);
    } else if (!errors.empty()) {
      throw ConfigFailure(path + " has an invalid [schedule] or night sky", errors);
    } else {
      baked = BakeStyle(config.style, bake);
      principles = DescribePrinciples(config.style);
    }
    result.validation_messages += baked.validation_messages;
    GalleryEntry entry{name, path, principles, ""};
    for (const BakedFile& f : baked.files)
      if (f.kind == "preview") entry.preview = f.path;
    result.entries.push_back(entry);
  }

  // Lay the upper halves out in a grid, each under its label (OpenImageIO module).
  SheetLayout layout;
  layout.tile_w = 2 * options.latlong_height;
  layout.tile_h = options.latlong_height / 2;
  layout.columns = options.columns;
  layout.margin = kMargin;
  layout.label_height = kLabelHeight;
  layout.name_size = kNameSize;
  layout.detail_size = kDetailSize;
  layout.name_font = kNameFont;
  layout.detail_font = kDetailFont;
  std::vector<SheetCell> cells;
  for (const GalleryEntry& e : result.entries) cells.push_back({e.preview, e.name, e.principles});
  std::vector<uint8_t> rgb;
  int width = 0, height = 0;
  std::string error;
  if (!LoadOiioModule().compose_sheet(cells, layout, rgb, width, height, error)) throw OutputError(error);
  WritePng(sheet_path, width, height, rgb);
  result.contact_sheet = sheet_path;
  return result;
}

}  // namespace skybake
