// skybake: bakes physical, art-directable skies into HDR environment maps.
//
//   skybake bake <style.toml> [--schedule day.toml] [--out DIR] [--size N] [--set key=value ...]
//                [--force | --resume] [--max-memory-mib M] [--max-frame-seconds S]
//                [--frames FIRST:LAST] [--shard I/N]
//   skybake merge-manifest DIR [--force] [--sizes-only]
//   skybake check <style.toml> [--schedule day.toml] [--set key=value ...]
//   skybake gallery [styles_dir] [--out DIR] [--size H] [--set key=value ...]
//   skybake devices
//   skybake --version
//
// main reads as the pipeline: parse, validate, bake (device, pipelines,
// LUTs, render, files, preview), report.

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "skybake/base/file_door.h"
#include "skybake/pipeline/formation_budget.h"
#include "skybake/tools/accuracy.h"
#include "skybake/input/config.h"
#include "skybake/output/exr_io.h"
#include "skybake/pipeline/gallery.h"
#include "skybake/output/manifest.h"
#include "skybake/pipeline/pipeline.h"
#include "skybake/pipeline/pass_plan.h"
#include "skybake/pipeline/render_plan.h"
#include "skybake/input/schedule.h"
#include "skybake/input/shard.h"
#include "skybake/base/oiio_module.h"
#include "skybake/gpu/vulkan_context.h"
#include "skybake/input/engine_preset.h"
#include "skybake/pipeline/test_pattern.h"
#include "skybake/pipeline/viewer_page.h"
#include "skybake/pipeline/night_sky.h"
#include "skybake/pipeline/progress_report.h"

#include "build_commit.h"

namespace {

using namespace skybake;

// The first error this run reported, for the progress stream's last event.
std::string first_error;

void PrintError(const std::string& message) {
  if (first_error.empty()) first_error = message;
  std::fprintf(stderr, "skybake: error: %s\n", Printable(message).c_str());
}

void PrintErrors(const std::vector<ConfigError>& errors) {
  for (const ConfigError& e : errors) PrintError(e.Format());
  std::fprintf(stderr, "skybake: %zu error%s; nothing was baked\n", errors.size(), errors.size() == 1 ? "" : "s");
}

bool EnvFlag(const char* name) {
  const char* v = std::getenv(name);
  return v && *v && std::string(v) != "0";
}

bool EnvIs(const char* name, const char* value) {
  const char* v = std::getenv(name);
  return v && std::string(v) == value;
}

int RunDevices(const std::string& software_driver_selection, const std::string& lavapipe_threads) {
  std::vector<DeviceInfo> devices = VulkanContext::ListDevices();
  if (devices.empty()) {
    std::fprintf(stderr,
                 "skybake: error: no Vulkan device found; on Debian 'apt-get install libvulkan1 "
                 "mesa-vulkan-drivers'\n");
    return kExitVulkan;
  }
  for (const DeviceInfo& d : devices) {
    std::printf("%d  %-40s %-15s Vulkan %s  %s\n", d.index, d.name.c_str(), d.type.c_str(), d.api_version.c_str(),
                d.usable ? "usable" : ("rejected: " + d.rejected_because).c_str());
  }
  if (!software_driver_selection.empty())
    std::printf(
        "(software driver only: this machine has no GPU device node; SKYBAKE_ALL_VULKAN_DRIVERS=1 loads "
        "every installed driver)\n");
  const bool lavapipe = std::any_of(devices.begin(), devices.end(), IsLavapipe);
  if (lavapipe && !lavapipe_threads.empty())
    std::printf("(lavapipe: %s threads, twice the hardware threads; LP_NUM_THREADS sets another count)\n",
                lavapipe_threads.c_str());
  return kExitOk;
}

struct BakeArgs {
  std::string style_path;
  std::string out_dir = "out";
  std::string schedule_path;  // empty: the style's inline [schedule], if any
  int size = 0;
  int device = -1;
  std::vector<std::string> overrides;
  bool quiet = false;         // errors only: no progress, no warnings
  std::string progress_json;  // --progress-json PATH: JSON lines of progress events, or ""
  bool validation = false;
  bool force = false;
  bool resume = false;
  double max_memory_mib = 4096.0;
  double max_frame_seconds = 3600.0;
  bool dry_run = false;              // print the plan instead of baking
  std::string frames;                // --frames FIRST:LAST, empty: every frame
  std::string shard;                 // --shard I/N, empty: no split
  ShaderSwitches shaders;            // from the environment (main)
  std::vector<std::string> engines;  // --engine NAME[,NAME...], repeatable: output.engine
  bool usd = false;                  // --usd: usd.enabled
  // From the environment (main, ReadEnvironment): the loader's driver
  // choice, lavapipe's thread count, the default star catalogue.
  std::string software_driver_selection;
  std::string lavapipe_threads;       // LP_NUM_THREADS main set, or ""
  std::string pipeline_cache_folder;  // PipelineCacheFolder, or "" when SKYBAKE_PIPELINE_CACHE=0
  std::string star_catalogue = DefaultStarCataloguePath();
  std::optional<int> stop_after_frame;  // $SKYBAKE_STOP_AFTER_FRAME: BakeOptions::stop_after_frame (farm tests)
};

enum class Mode { kBake, kCheck, kPlan };

// The style and overrides of --size, --engine and --set, in the order given.
std::vector<std::string> StyleOverrides(const BakeArgs& args) {
  std::vector<std::string> overrides = args.overrides;
  if (args.size > 0) {
    overrides.push_back(fmt::format("render.cube_size={}", args.size));
    overrides.push_back(fmt::format("render.latlong_height={}", args.size));
  }
  if (!args.engines.empty()) {
    // Every preset named, in the order given, as one TOML string.
    std::string list;
    for (const std::string& name : args.engines) list += (list.empty() ? "" : ",") + name;
    overrides.push_back("output.engine=\"" + list + "\"");
  }
  if (args.usd) overrides.push_back("usd.enabled=true");
  return overrides;
}

// What a bake reads: the style and, with a schedule (its own file, or
// inline in the style), every frame's resolved style.
struct LoadedBake {
  ConfigResult config;
  std::string schedule_path;
  std::optional<Schedule> schedule;
  std::vector<SkyStyle> frame_styles;

  // The styles baked: every frame's, or the one style.
  std::vector<SkyStyle> Styles() const { return schedule ? frame_styles : std::vector<SkyStyle>{config.style}; }
};

// Reads and checks the style, the schedule and every frame's style, printing
// every error at once; false when there were errors (nothing may be baked).
bool LoadBake(const BakeArgs& args, LoadedBake& bake) {
  const std::vector<std::string> overrides = StyleOverrides(args);
  bake.config = LoadSkyStyle(args.style_path, overrides);
  if (!bake.config.ok()) {
    PrintErrors(bake.config.errors);
    return false;
  }
  if (!args.quiet)
    for (const ConfigError& w : bake.config.warnings)
      std::fprintf(stderr, "skybake: warning: %s\n", Printable(w.Format()).c_str());
  // A schedule makes a sequence: every frame's style is resolved and checked
  // before any GPU work.
  bake.schedule_path = args.schedule_path;
  if (bake.schedule_path.empty() && FileHasSchedule(args.style_path)) bake.schedule_path = args.style_path;
  if (bake.schedule_path.empty()) return true;
  ScheduleResult loaded = LoadSchedule(bake.schedule_path);
  if (!loaded.ok()) {
    PrintErrors(loaded.errors);
    return false;
  }
  FrameStyles styles = ResolveFrameStyles(args.style_path, overrides, loaded.schedule);
  if (!args.quiet)
    for (const ConfigError& w : styles.warnings)
      std::fprintf(stderr, "skybake: warning: %s\n", Printable(w.Format()).c_str());
  if (!styles.ok()) {
    PrintErrors(styles.errors);
    return false;
  }
  bake.schedule = std::move(loaded.schedule);
  bake.frame_styles = std::move(styles.styles);
  return true;
}

// The night sky: its catalogue readable, its frames clock times at a place
// (night_sky.h); false when not (the errors printed).
bool CheckNight(const BakeArgs& args, const LoadedBake& bake) {
  std::vector<const SkyStyle*> styles;
  if (bake.schedule)
    for (const SkyStyle& style : bake.frame_styles) styles.push_back(&style);
  else styles.push_back(&bake.config.style);
  const std::vector<ConfigError> night_errors =
      CheckNightSky(styles, bake.schedule ? &*bake.schedule : nullptr, args.star_catalogue);
  if (night_errors.empty()) return true;
  PrintErrors(night_errors);
  return false;
}

// Every frame's memory and time estimate against the budget (a BudgetError
// when over), before any GPU work; returns the largest of each.
ResourceEstimate CheckFrameBudgets(const LoadedBake& bake, const BakeOptions& options) {
  ResourceEstimate largest;
  for (const SkyStyle& style : bake.Styles()) {
    CheckBudget(style, options);
    ResourceEstimate e = EstimateResources(style);
    if (e.memory_mib > largest.memory_mib) largest.memory_mib = e.memory_mib;
    if (e.seconds > largest.seconds) largest.seconds = e.seconds;
  }
  return largest;
}

// `skybake plan` (or --dry-run): the passes, LUTs and shader variant the
// bake would run, and why; of the part that --frames / --shard select, when
// given.
int PrintPlan(const BakeArgs& args, const LoadedBake& bake, const std::optional<FrameRange>& part) {
  const std::optional<Schedule>& schedule = bake.schedule;
  const RenderPlan bake_plan =
      schedule ? PlanSequenceBake(bake.frame_styles, *schedule, part) : PlanSingleBake(bake.config.style);
  std::vector<double> planned_hours;  // the cloud formation's steps follow the clock
  for (const FramePlan& f : bake_plan.frames)
    if (bake_plan.Bakes(f)) planned_hours.push_back(f.hours_from_start);
  PassPlan plan = PlanPasses(bake_plan.BakedStyles(), args.shaders, planned_hours);
  std::string what = args.style_path + (schedule ? " with " + bake.schedule_path : "");
  if (part)
    what += fmt::format(" (frames {} to {} of {} to {})", part->first, part->last, schedule->frames.front().number,
                        schedule->frames.back().number);
  std::printf("%s", FormatPlan(plan, what).c_str());
  return kExitOk;
}

// `skybake check`: the largest estimate per frame, and that the style is ok.
int PrintCheck(const BakeArgs& args, const LoadedBake& bake, const ResourceEstimate& largest,
               const FormationEstimate& formation) {
  std::printf("estimate per frame: %.0f MiB of memory (budget %.0f), %.1f s of lavapipe time (budget %.0f)\n",
              largest.memory_mib, args.max_memory_mib, largest.seconds, args.max_frame_seconds);
  if (!formation.frame.empty())
    std::printf("cloud formation: %.3g cell updates in its busiest frame (%s), about %.1f s of CPU time\n",
                formation.cell_updates, formation.frame.c_str(), formation.seconds);
  if (bake.schedule)
    std::printf("%s with %s: ok, %zu frames\n", Printable(args.style_path).c_str(),
                Printable(bake.schedule_path).c_str(), bake.schedule->frames.size());
  else std::printf("%s: ok\n", Printable(args.style_path).c_str());
  return kExitOk;
}

// One line a file, as each frame's are recorded and, at the end, the scene's,
// manifest's and timings'.
void PrintFiles(const std::vector<BakedFile>& files) {
  for (const BakedFile& f : files)
    std::printf("%s  %s  %llu bytes\n", f.kind.c_str(), Printable(f.path).c_str(), (unsigned long long)f.bytes);
}

// The bake's options from the command line (and the environment main read).
// The device, its driver and thread count, the shader switches, the
// star catalogue and the build's commit: what every command that bakes
// takes from the arguments and the environment alike.
void SetDeviceOptions(const BakeArgs& args, BakeOptions& options) {
  options.build_commit = kBuildCommit;
  options.vulkan.device_index = args.device;
  options.vulkan.validation = args.validation;
  options.vulkan.software_driver_selection = args.software_driver_selection;
  options.vulkan.lavapipe_threads = args.lavapipe_threads;
  options.vulkan.pipeline_cache_folder = args.pipeline_cache_folder;
  options.shaders = args.shaders;
  options.star_catalogue = args.star_catalogue;
  options.stop_after_frame = args.stop_after_frame;
}

void SetBakeOptions(const BakeArgs& args, const std::optional<FrameRange>& part, ProgressReport& progress,
                    BakeOptions& options) {
  options.out_dir = args.out_dir;
  options.force = args.force;
  options.resume = args.resume;
  options.frames = part;
  SetDeviceOptions(args, options);
  // Stages and frames to the progress report (lines, the live line, JSON).
  progress.Attach(options);
  // A frame's files are printed as they are recorded, and not kept: a long
  // sequence's memory stays flat. On a terminal, below the live line.
  options.keep_frame_records = false;
  options.frame_files = [&progress](const std::vector<BakedFile>& files) {
    progress.Suspend();
    PrintFiles(files);
    std::fflush(stdout);
    progress.Resume();
  };
}

// The last files, then anything the validation layer said.
int ReportBake(const BakeResult& result, bool quiet) {
  PrintFiles(result.files);
  if (result.half_scale != 1.0 && !quiet)
    std::fprintf(stderr,
                 "skybake: warning: values exceeded half range; EXRs were scaled by as little as %.9g "
                 "(each records its own scale as skybake:scale and whiteLuminance)\n",
                 result.half_scale);
  if (result.validation_messages > 0) {
    PrintError(fmt::format("the Vulkan validation layer reported {} message{}", result.validation_messages,
                           result.validation_messages == 1 ? "" : "s"));
    return kExitVulkan;
  }
  return kExitOk;
}

// `progress` is the bake's report (null for check and plan).
int RunBake(const BakeArgs& args, Mode mode, ProgressReport* progress = nullptr) {
  // Parse and validate: every error at once, before any GPU work.
  std::optional<FrameRange> frames;
  std::optional<ShardSpec> shard;
  if (!args.frames.empty()) frames = ParseFrameRange(args.frames);
  if (!args.shard.empty()) shard = ParseShard(args.shard);
  LoadedBake bake;
  if (!LoadBake(args, bake) || !CheckNight(args, bake)) return kExitConfig;
  // Budget: every frame's memory and time estimate, before any GPU work.
  BakeOptions options;
  options.max_memory_mib = args.max_memory_mib;
  options.max_frame_seconds = args.max_frame_seconds;
  const ResourceEstimate largest = CheckFrameBudgets(bake, options);
  // Shard: the part of the sequence this run bakes (README "Scale-out").
  std::optional<FrameRange> part;
  if (frames || shard) {
    if (!bake.schedule)
      throw UsageError(
          "--frames and --shard split a sequence bake: give --schedule (or a style with an inline "
          "[schedule])");
    part = SelectFrames(*bake.schedule, frames, shard);
  }
  if (args.resume && !bake.schedule) {
    PrintError(
        "--resume continues a sequence bake: give --schedule (or a style with an inline [schedule]), or use "
        "--force to bake a single style again");
    return kExitUsage;
  }
  // The cloud formation's host work, frame by frame in the order they bake.
  const FormationEstimate formation = CheckFormationBudget(
      bake.schedule ? PlanSequenceBake(bake.frame_styles, *bake.schedule, part) : PlanSingleBake(bake.config.style),
      options);
  if (mode == Mode::kPlan || args.dry_run) return PrintPlan(args, bake, part);
  if (mode == Mode::kCheck) return PrintCheck(args, bake, largest, formation);

  // Bake: device, pipelines, LUTs, render, files, preview; then report.
  SetBakeOptions(args, part, *progress, options);
  const BakeResult result =
      bake.schedule ? BakeSequence(bake.frame_styles, *bake.schedule, options) : BakeStyle(bake.config.style, options);
  return ReportBake(result, args.quiet);
}

int RunMergeManifest(const MergeOptions& options) {
  // Check every part, then write the scene and manifest.json.
  MergeResult result = MergeShardManifests(options);
  for (const std::string& part : result.parts) std::printf("part      %s\n", Printable(part).c_str());
  for (const BakedFile& f : result.scene_files)
    std::printf("%s  %s  %llu bytes\n", f.kind.c_str(), Printable(f.path).c_str(), (unsigned long long)f.bytes);
  std::printf("manifest  %s  %d frames from %zu part%s\n", Printable(result.manifest_path).c_str(), result.frames,
              result.parts.size(), result.parts.size() == 1 ? "" : "s");
  return kExitOk;
}

struct GalleryArgs {
  std::string styles_dir = "configs/styles";
  std::string out_dir = "out/gallery";
  int size = 192;
  int columns = 2;
};

int RunGallery(const GalleryArgs& gallery, const BakeArgs& args) {
  // Parse and validate every style first: nothing is baked if one is wrong.
  std::vector<std::string> styles = StyleFilesIn(gallery.styles_dir);
  if (styles.empty()) {
    std::fprintf(stderr, "skybake: error: no .toml styles in %s\n", Printable(gallery.styles_dir).c_str());
    return kExitUsage;
  }
  std::vector<ConfigError> errors;
  for (const std::string& path : styles) {
    ConfigResult config = LoadSkyStyle(path, args.overrides);
    errors.insert(errors.end(), config.errors.begin(), config.errors.end());
    if (config.ok())
      GalleryFrameOf(path, args.overrides, args.star_catalogue, errors);  // its own [schedule], night sky
  }
  if (!errors.empty()) {
    PrintErrors(errors);
    return kExitConfig;
  }

  // Bake each style's preview, then lay out the labelled contact sheet.
  GalleryOptions options;
  options.out_dir = gallery.out_dir;
  options.latlong_height = gallery.size;
  options.columns = gallery.columns;
  options.overrides = args.overrides;
  SetDeviceOptions(args, options.bake);
  options.bake.force = args.force;
  options.bake.max_memory_mib = args.max_memory_mib;
  options.bake.max_frame_seconds = args.max_frame_seconds;
  size_t done = 0;
  if (!args.quiet) {
    options.bake.progress = [&done, &styles](const StageReport& s) {
      if (s.name != "preview") return;
      std::fprintf(stderr, "skybake: gallery %zu/%zu %s (%s)\n", done + 1, styles.size(),
                   Printable(styles[done]).c_str(), Printable(s.detail).c_str());
      ++done;
    };
  }
  GalleryResult result = BakeGallery(styles, options);

  // Report: every style with its principles, then the sheet.
  for (const GalleryEntry& e : result.entries)
    std::printf("style    %-24s %s\n", Printable(e.name).c_str(), Printable(e.principles).c_str());
  std::printf("gallery  %s\n", Printable(result.contact_sheet).c_str());
  if (result.validation_messages > 0) {
    std::fprintf(stderr, "skybake: error: the Vulkan validation layer reported %d messages\n",
                 result.validation_messages);
    return kExitVulkan;
  }
  return kExitOk;
}

// A budget is a finite number above 0 (nan compares false with every
// bound and would switch the budget off).
// A finite number above 0 (or, with `zero`, at or above 0): NaN and
// infinities are refused.
CLI::Validator FiniteNumber(bool zero) {
  return CLI::Validator(
      [zero](std::string& text) -> std::string {
        double value = 0.0;
        if (!CLI::detail::lexical_cast(text, value) || !std::isfinite(value) || !(zero ? value >= 0.0 : value > 0.0))
          return std::string("expected a finite number ") + (zero ? "at or above 0" : "above 0") + ", got " + text;
        return "";
      },
      zero ? "NONNEGATIVE" : "POSITIVE");
}
CLI::Validator FinitePositive() { return FiniteNumber(false); }

void AddStyleOptions(CLI::App* cmd, BakeArgs& args) {
  const CLI::Validator finite_positive = FinitePositive();
  cmd->add_option("style", args.style_path, "Sky style TOML file (see configs/default.toml)")->required();
  cmd->add_option("--set", args.overrides, "Override a style key, e.g. --set sun.elevation_deg=10 (repeatable)");
  cmd->add_option("--schedule", args.schedule_path,
                  "Schedule TOML: bake a frame-numbered sequence (default: the style's inline "
                  "[schedule], if it has one)");
  cmd->add_option("--max-memory-mib", args.max_memory_mib,
                  "Memory budget per frame in MiB; larger bakes are refused (README \"Limits\")")
      ->capture_default_str()
      ->check(finite_positive);
  cmd->add_option("--max-frame-seconds", args.max_frame_seconds,
                  "Time budget per frame in estimated lavapipe seconds; longer bakes are refused")
      ->capture_default_str()
      ->check(finite_positive);
}

// The command line: every subcommand's options, and which one was given.
struct Cli {
  BakeArgs args;
  GalleryArgs gallery_args;
  TestPatternOptions pattern;
  ViewPageOptions view_options;
  MergeOptions merge_options;
  bool sizes_only = false;
  AccuracyStudyOptions study;
  CLI::App *bake = nullptr, *check = nullptr, *plan = nullptr, *gallery = nullptr, *testpattern = nullptr,
           *view = nullptr, *merge = nullptr, *devices = nullptr, *accuracy = nullptr;
  // A bake's progress report, and the file of its JSON lines (or null).
  std::FILE* progress_file = nullptr;
  std::unique_ptr<ProgressReport> progress;
};

// bake, check and plan: a style (and its schedule) each.
void AddBakeCommands(CLI::App& app, Cli& cli) {
  cli.bake = app.add_subcommand(
      "bake",
      "Bake a style (or a sequence, with --schedule) into EXR cube faces, cube strip, latlong, a PNG "
      "preview, a glTF scene and manifest.json");
  AddStyleOptions(cli.bake, cli.args);
  cli.bake->add_option("--out", cli.args.out_dir, "Output folder")->capture_default_str();
  cli.bake
      ->add_option("--size", cli.args.size,
                   "Cube face size N; also sets the latlong to 2N x N (default: the style's, 512)")
      ->check(CLI::Range(1, 8192));
  cli.bake->add_option("--device", cli.args.device, "Vulkan device index from 'skybake devices' (default: best)");
  CLI::Option* force =
      cli.bake->add_flag("--force", cli.args.force,
                         "Overwrite the files of a previous bake in --out (without it, existing files stop the bake)");
  cli.bake
      ->add_flag(
          "--resume", cli.args.resume,
          "Sequence: keep the frames whose files match their checksums in the manifest in --out (manifest.json, or "
          "the shard's), bake the rest")
      ->excludes(force);
  cli.bake
      ->add_option("--frames", cli.args.frames,
                   "Sequence: bake only frames FIRST to LAST (inclusive), numbered as in file names (from "
                   "schedule.first_frame); writes manifest.shard-FIRST-LAST.json, no scene")
      ->type_name("FIRST:LAST");
  cli.bake
      ->add_option("--shard", cli.args.shard,
                   "Sequence: bake shard I of N (I = 1..N), a contiguous block of nearly equal size of the frames "
                   "(of --frames, if given); join the parts with merge-manifest (README \"Scale-out\")")
      ->type_name("I/N");
  {
    std::string engines;
    for (const std::string& name : EngineNames()) engines += (engines.empty() ? "" : "|") + name;
    cli.bake
        ->add_option("--engine", cli.args.engines,
                     "Also write the files these engines load the right way up, all from the same render: one "
                     "name, a list separated by commas, or the option repeated (output.engine; docs/engines.md)")
        ->type_name(engines)
        ->allow_extra_args(false)
        ->check(CLI::Validator(
            [](std::string& value) -> std::string {
              // Each name of a list separated by commas is a preset.
              const std::vector<std::string> names = EngineNames();
              for (const std::string& name : SplitEngineList(value))
                if (std::find(names.begin(), names.end(), name) == names.end())
                  return fmt::format(
                      "'{}' is not an engine preset: give one or more of {{{}}}, separated by "
                      "commas or as --engine repeated",
                      name, fmt::join(names, ","));
              return std::string();
            },
            "ENGINE[,ENGINE...]"));
  }
  cli.bake->add_flag("--usd", cli.args.usd,
                     "Also write NAME.usda, a USD layer: a DomeLight of the latlong EXRs and DistantLights for the "
                     "Sun and Moon, time-sampled over a sequence (usd.enabled; docs/usd.md)");
  cli.bake->add_flag("--dry-run", cli.args.dry_run, "Print the pass plan (as 'skybake plan') and bake nothing");
  cli.bake->add_flag("--quiet,-q", cli.args.quiet,
                     "Errors only on stderr: no progress, no warnings (the files written still go to stdout)");
  cli.bake
      ->add_option("--progress-json", cli.args.progress_json,
                   "Also write progress as JSON lines to PATH, one object per event (start, stage, frame_start, "
                   "frame_end with the rate and time left, end with the exit code), each flushed as it happens; "
                   "/dev/fd/N writes to an open file descriptor. Checked before anything else: a PATH that cannot "
                   "be written stops the bake (exit 5) with nothing touched")
      ->type_name("PATH");
  cli.bake->add_flag("--vulkan-validation", cli.args.validation,
                     "Load the Khronos validation layer; any message fails the bake (also "
                     "SKYBAKE_VULKAN_VALIDATION=1)");

  cli.check = app.add_subcommand("check", "Validate a style without baking");
  AddStyleOptions(cli.check, cli.args);

  cli.plan = app.add_subcommand(
      "plan",
      "Print the passes, LUT sizes, shader variant, estimated work and reuse of a bake, and why each "
      "effect is on (also: bake --dry-run)");
  AddStyleOptions(cli.plan, cli.args);
}

void AddGalleryCommand(CLI::App& app, Cli& cli) {
  cli.gallery =
      app.add_subcommand("gallery", "Bake every style of a folder and write one labelled contact sheet (gallery.png)");
  cli.gallery->add_option("styles", cli.gallery_args.styles_dir, "Folder of style TOML files")->capture_default_str();
  cli.gallery->add_option("--out", cli.gallery_args.out_dir, "Output folder")->capture_default_str();
  cli.gallery->add_option("--size", cli.gallery_args.size, "Latlong height H of each style (2H x H)")
      ->capture_default_str()
      ->check(CLI::Range(8, 2048));
  cli.gallery->add_option("--columns", cli.gallery_args.columns, "Tiles per row")
      ->capture_default_str()
      ->check(CLI::Range(1, 16));
  cli.gallery->add_option("--set", cli.args.overrides, "Override a key in every style (repeatable)");
  cli.gallery->add_option("--device", cli.args.device, "Vulkan device index from 'skybake devices'");
  cli.gallery
      ->add_option("--max-memory-mib", cli.args.max_memory_mib,
                   "Memory budget per style in MiB; a gallery with a style over it is refused (exit 7) "
                   "before any is baked")
      ->capture_default_str()
      ->check(FinitePositive());
  cli.gallery
      ->add_option("--max-frame-seconds", cli.args.max_frame_seconds,
                   "Time budget per style in estimated seconds; as --max-memory-mib")
      ->capture_default_str()
      ->check(FinitePositive());
  cli.gallery->add_flag("--force", cli.args.force,
                        "Replace a previous gallery in --out (its sheet and every style's files)");
  cli.gallery->add_flag("--quiet,-q", cli.args.quiet, "No progress lines");
  cli.gallery->add_flag("--vulkan-validation", cli.args.validation, "Load the Khronos validation layer");
}

// testpattern, view, merge-manifest, devices, accuracy.
void AddToolCommands(CLI::App& app, Cli& cli) {
  cli.testpattern =
      app.add_subcommand("testpattern",
                         "Write an orientation test pattern (faces named, axes, horizon, N E S W) as a bake's files, "
                         "through an engine preset: check the preset in your engine (docs/engines.md)");
  cli.testpattern->add_option("--out", cli.pattern.out_dir, "Output folder")->capture_default_str();
  cli.testpattern->add_option("--engine", cli.pattern.engine, "Engine preset whose files to write too")
      ->check(CLI::IsMember(EngineNames()));
  cli.testpattern->add_option("--size", cli.pattern.size, "Cube face size N; the latlong is 2N x N")
      ->capture_default_str()
      ->check(CLI::Range(8, 4096));
  cli.testpattern->add_flag("--force", cli.pattern.force, "Overwrite the pattern's files in --out");
  cli.testpattern
      ->add_option("--max-memory-mib", cli.pattern.max_memory_mib,
                   "Memory budget in MiB; a larger pattern is refused (exit 7) before any file")
      ->capture_default_str()
      ->check(FinitePositive());

  cli.view = app.add_subcommand(
      "view",
      "Write DIR/view.html: the bake's sky in one self-contained page (three.js inside, no network): drag "
      "to look around, exposure, frames");
  cli.view->add_option("dir", cli.view_options.dir, "A bake's --out folder (or a testpattern folder)")->required();
  cli.view->add_flag("--force", cli.view_options.force, "Replace an existing view.html");
  cli.view
      ->add_option("--embed-mib", cli.view_options.embed_mib,
                   "Frames inside the page while their files total at most this many MiB (the first always); "
                   "later ones are loaded from their files when the page is served over HTTP")
      ->capture_default_str()
      ->check(FiniteNumber(true));

  cli.merge = app.add_subcommand(
      "merge-manifest",
      "Join the shard manifests (manifest.shard-FIRST-LAST.json, from bake --shard or --frames) of a folder into "
      "manifest.json and write the glTF scene, equal to an unsharded bake's; checks that the parts are of one "
      "bake, cover every frame once, and that every listed file is there with its SHA-256");
  cli.merge->add_option("dir", cli.merge_options.dir, "Folder holding every part's files and shard manifest")
      ->required();
  cli.merge->add_flag("--force", cli.merge_options.force, "Replace an existing manifest.json and glTF scene");
  cli.merge->add_flag("--sizes-only", cli.sizes_only,
                      "Check listed files by size only, without reading them for SHA-256");

  cli.devices = app.add_subcommand("devices", "List Vulkan devices and whether skybake can use them");

  cli.accuracy = app.add_subcommand(
      "accuracy", "Run the accuracy-versus-time study of every integrator and write its tables and plot");
  cli.accuracy->add_option("--out", cli.study.out_dir, "Folder for accuracy_results.md, accuracy.csv, accuracy.png")
      ->capture_default_str();
  cli.accuracy->add_option("--shared", cli.study.shared_dir, "Folder holding groundtruth/kider2014")
      ->capture_default_str();
  cli.accuracy->add_flag("--quick", cli.study.quick, "Fewer cases and directions (a smoke run)");
  cli.accuracy->add_option("--only", cli.study.only,
                           "Only the cases whose name contains this text, e.g. \"sky-view\"; \"spectral\" or "
                           "\"kider-spectral\": that study alone");
  cli.accuracy
      ->add_option("--study", cli.study.study,
                   "Which studies: sky (integrators, Kider 2014), clouds (cloud settings: cloud_study.csv), "
                   "spectral (wavelength counts: spectral.csv), twilight (presets and sky-view variants at sun "
                   "3..-10 deg: twilight.csv), all")
      ->capture_default_str()
      ->check(CLI::IsMember({"all", "sky", "clouds", "spectral", "twilight"}));
  cli.accuracy->add_option("--observer-altitude-m", cli.study.observer_altitude_m, "Observer altitude of the study (m)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1e6));
}

// The environment, read here alone and passed in (docs/architecture.md).
// Single-threaded still: the only point where the environment may change.
// The Vulkan loader reads VK_LOADER_DRIVERS_SELECT when the first instance
// is made, so the driver choice is set here, before any Vulkan call.
// The persistent pipeline cache's folder (gpu/pipeline_cache.h): the XDG
// Base Directory's user cache, $XDG_CACHE_HOME/skybake or ~/.cache/skybake;
// "" (no cache) with SKYBAKE_PIPELINE_CACHE=0 or with neither variable set.
std::string PipelineCacheFolder() {
  if (EnvIs("SKYBAKE_PIPELINE_CACHE", "0")) return "";
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg == '/') return std::string(xdg) + "/skybake";
  if (const char* home = std::getenv("HOME"); home && *home) return std::string(home) + "/.cache/skybake";
  return "";
}

void ReadEnvironment(BakeArgs& args) {
  EnvironmentVariables variables;
  for (const std::string& name : DriverEnvironmentVariableNames())
    if (const char* value = std::getenv(name.c_str())) variables[name] = value;
  args.software_driver_selection = SoftwareDriverSelection(ProbeDriverEnvironment(variables));
  if (!args.software_driver_selection.empty())
    ::setenv("VK_LOADER_DRIVERS_SELECT", args.software_driver_selection.c_str(), 1);
  // Lavapipe reads LP_NUM_THREADS when its device is made.
  args.lavapipe_threads = LavapipeThreadCount(variables, std::thread::hardware_concurrency());
  if (!args.lavapipe_threads.empty()) ::setenv("LP_NUM_THREADS", args.lavapipe_threads.c_str(), 1);
  if (const char* dir = std::getenv("SKYBAKE_MODULE_DIR")) SetOiioModuleDir(dir);
  if (const char* catalogue = std::getenv("SKYBAKE_STAR_CATALOGUE"); catalogue && *catalogue)
    args.star_catalogue = catalogue;
  if (const char* stop = std::getenv("SKYBAKE_STOP_AFTER_FRAME"); stop && *stop)
    args.stop_after_frame = std::atoi(stop);
  args.pipeline_cache_folder = PipelineCacheFolder();
  args.validation = args.validation || EnvFlag("SKYBAKE_VULKAN_VALIDATION");
  args.shaders.generic = EnvIs("SKYBAKE_GENERIC_SHADERS", "1");
  args.shaders.sun_disc_pass = !EnvIs("SKYBAKE_SUN_DISC_PASS", "0");
  args.shaders.shadowed_clouds = !EnvIs("SKYBAKE_SHADOWED_CLOUDS", "0");
  args.shaders.twilight_rows = !EnvIs("SKYBAKE_TWILIGHT_ROWS", "0");
  args.shaders.texel_views = !EnvIs("SKYBAKE_TEXEL_VIEWS", "0");
  args.shaders.formation_read_always = EnvIs("SKYBAKE_FORMATION_READ", "1");
  // Off unless asked for: on W2 it leaves one frame of 24 unmarched and costs more than that frame (probes,
  // and 224 MiB more peak memory; docs/performance.md, "Today").
  args.shaders.twilight_skip = EnvIs("SKYBAKE_TWILIGHT_SKIP", "1");
}

int RunCommand(Cli& cli) {
  if (cli.devices->parsed()) return RunDevices(cli.args.software_driver_selection, cli.args.lavapipe_threads);
  if (cli.accuracy->parsed()) {
    cli.study.progress = [](const std::string& line) { std::fprintf(stderr, "skybake: %s\n", line.c_str()); };
    std::string report = RunAccuracyStudy(cli.study);
    std::printf("%s", report.c_str());
    return kExitOk;
  }
  if (cli.check->parsed()) return RunBake(cli.args, Mode::kCheck);
  if (cli.plan->parsed()) return RunBake(cli.args, Mode::kPlan);
  if (cli.gallery->parsed()) return RunGallery(cli.gallery_args, cli.args);
  if (cli.view->parsed()) {
    if (const char* three = std::getenv("SKYBAKE_THREE_DIR")) cli.view_options.three_dir = three;
    std::printf("%s\n", Printable(WriteViewPage(cli.view_options)).c_str());
    return kExitOk;
  }
  if (cli.testpattern->parsed()) {
    for (const std::string& path : WriteTestPattern(cli.pattern)) std::printf("%s\n", Printable(path).c_str());
    return kExitOk;
  }
  if (cli.merge->parsed()) {
    cli.merge_options.verify_checksums = !cli.sizes_only;
    return RunMergeManifest(cli.merge_options);
  }
  // The bake's progress: its JSON lines' file opened before anything else,
  // so that a path that cannot be written stops the bake with nothing
  // touched; a live line on a terminal, lines in a log, nothing with -q.
  if (!cli.args.progress_json.empty()) {
    // Through the door (file_door.h): a FIFO no process reads is refused,
    // not waited on.
    int fd = -1;
    if (const std::string problem = OpenStreamOutput(cli.args.progress_json, fd); !problem.empty())
      throw OutputError(fmt::format("--progress-json {} cannot be written: it {}; nothing was baked",
                                    cli.args.progress_json, problem));
    cli.progress_file = ::fdopen(fd, "w");
    if (!cli.progress_file) {
      const int error = errno;
      ::close(fd);
      throw OutputError(fmt::format("--progress-json {} cannot be written: {}; nothing was baked",
                                    cli.args.progress_json, std::strerror(error)));
    }
  }
  const ProgressStyle style = cli.args.quiet               ? ProgressStyle::kQuiet
                              : isatty(STDERR_FILENO) == 1 ? ProgressStyle::kLiveLine
                                                           : ProgressStyle::kLines;
  cli.progress = std::make_unique<ProgressReport>(style, stderr, cli.progress_file, SKYBAKE_VERSION, kBuildCommit);
  return RunBake(cli.args, Mode::kBake, cli.progress.get());
}

// Runs the command given; maps every error to its exit code.
int RunReportingErrors(Cli& cli) {
  try {
    return RunCommand(cli);
  } catch (const Error& e) {
    // Every user error of every layer (base/errors.h): its message, its exit code.
    if (const auto* config = dynamic_cast<const ConfigFailure*>(&e)) PrintErrors(config->errors);
    else PrintError(e.message());
    return e.exit_code();
  } catch (const std::bad_alloc&) {
    PrintError(
        "out of memory: lower render.cube_size or render.latlong_height, or --max-memory-mib so that the "
        "budget check refuses such bakes (README \"Limits\")");
    return kExitBudget;
  } catch (const std::filesystem::filesystem_error& e) {
    PrintError(e.what());
    return kExitOutput;
  } catch (const std::exception& e) {
    if (first_error.empty()) first_error = std::string("internal error: ") + e.what();
    std::fprintf(stderr, "skybake: internal error: %s (please report it)\n", Printable(e.what()).c_str());
    return kExitInternal;
  }
}

// `skybake --version`: the version and the commit it was built from. Alone
// only: beside a subcommand or another option it is a usage error (it would
// otherwise be unclear whether the rest ran).
int RunVersion(int argc, char** argv) {
  if (argc != 2) {
    std::string rest;
    for (int i = 1; i < argc; ++i)
      if (std::string_view(argv[i]) != "--version") rest += std::string(rest.empty() ? "" : " ") + argv[i];
    std::fprintf(stderr,
                 "skybake: error: --version takes no subcommand or other option (given: %s): run "
                 "'skybake --version' alone\n",
                 Printable(rest.empty() ? "--version twice" : rest).c_str());
    return kExitUsage;
  }
  std::printf("skybake %s (commit %s)\n", SKYBAKE_VERSION, kBuildCommit);
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (std::string_view(argv[i]) == "--version") return RunVersion(argc, argv);
  KeepFrameMemoryInHeap();
  CLI::App app{
      "skybake " SKYBAKE_VERSION
      ": bakes physical, art-directable skies (AOAS on a Hillaire 2020 atmosphere) "
      "into OpenEXR environment maps with Vulkan compute.\n"
      "Exit codes: 0 ok, 1 internal error, 2 usage, 3 invalid style or schedule, 4 Vulkan, 5 output "
      "(disk full, permissions), 6 outputs exist (--force, --resume), 7 over the memory or time budget, 8 shard "
      "manifests that do not merge."};
  app.require_subcommand(1);
  // Handled before parsing (RunVersion); here for the help.
  app.add_flag("--version")
      ->description("Print the version and the git commit skybake was built from, and exit (alone only)");
  app.get_formatter()->column_width(34);
  Cli cli;
  AddBakeCommands(app, cli);
  AddGalleryCommand(app, cli);
  AddToolCommands(app, cli);

  // A file-size limit (ulimit -f) makes write() fail with EFBIG, reported
  // like a full disk, instead of killing the process mid-file.
  std::signal(SIGXFSZ, SIG_IGN);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    int code = app.exit(e);
    return code == 0 ? kExitOk : kExitUsage;
  }
  ReadEnvironment(cli.args);
  const int code = RunReportingErrors(cli);
  // The progress stream's last event: how the bake ended.
  if (cli.progress) cli.progress->End(code, first_error);
  if (cli.progress_file) std::fclose(cli.progress_file);
  return code;
}
