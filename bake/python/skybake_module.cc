// The Python module `skybake` (docs/python.md): styles and schedules loaded,
// checked, planned and baked by the pipeline's own libraries, as the CLI
// does, without its binary.
//
//   errors     every skybake::Error becomes a skybake.Error subclass carrying
//              the exit code of its kind (README "Exit codes") and, for a
//              style or schedule, its located errors
//   progress   the --progress-json events (progress_report.h), each as a
//              dict, passed to a callback; the callback cancels the bake by
//              returning False or raising, and the bake then stops as a
//              killed one would (complete files, a manifest of the frames
//              done, no temporaries), which resume=True finishes
//   the GIL    released while the bake runs, taken again for the callback
#include <dlfcn.h>
#include <stdio.h>  // fopencookie

#include <array>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <map>
#include <new>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <pybind11/eval.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "build_commit.h"
#include "exr_arrays.h"
#include "ktx2_arrays.h"
#include "skybake/base/errors.h"
#include "skybake/base/file_door.h"
#include "skybake/base/oiio_module.h"
#include "skybake/gpu/vulkan_context.h"
#include "skybake/input/config.h"
#include "skybake/input/schedule.h"
#include "skybake/input/shard.h"
#include "skybake/pipeline/night_sky.h"
#include "skybake/pipeline/pass_plan.h"
#include "skybake/pipeline/pipeline.h"
#include "skybake/pipeline/progress_report.h"
#include "skybake/pipeline/render_plan.h"

namespace py = pybind11;

namespace skybake {
namespace {

// === Exceptions: defined in Python (plain classes an editor and `except`
// see as such), raised from C++ with their exit code and located errors.
constexpr const char* kExceptionClasses = R"(
import collections as _collections

Location = _collections.namedtuple("Location", "file line column key message")
Location.__doc__ = """Where a style or schedule is wrong: file, 1-based line and column (0 when
unknown), the dotted key (e.g. "atmosphere.mie.g") and the message."""


class Error(Exception):
    """A failure the user can act on. exit_code: the CLI's exit code of its kind (README
    "Exit codes"); errors: the located errors (Location tuples) of a style or schedule."""

    exit_code = 1

    def __init__(self, message, exit_code=None, errors=()):
        super().__init__(message)
        if exit_code is not None:
            self.exit_code = exit_code
        self.errors = list(errors)


class UsageError(Error):
    """A bad argument (exit code 2): frames or shard without a schedule, resume without one."""
    exit_code = 2


class StyleError(Error):
    """An invalid style or schedule (exit code 3); .errors lists every mistake, located."""
    exit_code = 3


class VulkanError(Error):
    """No Vulkan driver or device, a Vulkan failure, or validation messages (exit code 4)."""
    exit_code = 4


class OutputError(Error):
    """An output file could not be written: disk full, file-size limit, no permission (exit code 5)."""
    exit_code = 5


class FolderError(OutputError):
    """The output folder already holds the bake's files, or another bake is writing them
    (exit code 6): pass force=True or resume=True, or choose another folder."""
    exit_code = 6


class BudgetError(Error):
    """Over the memory or time budget (exit code 7; nothing was done), or out of memory."""
    exit_code = 7


class ManifestError(Error):
    """resume=True: the manifest lists a name this bake does not give that frame (exit code 8)."""
    exit_code = 8


class Cancel(Exception):
    """Raise from a progress callback (or return False from it) to cancel a bake; bake() raises
    it when its callback returned False. The folder is left as a killed bake leaves it: complete
    files, a manifest of the frames done, no temporaries; bake(..., resume=True) finishes a sequence."""
)";

struct PythonClasses {
  py::object location, error, usage, style, vulkan, output, folder, budget, manifest, cancel;
};
// Kept for the interpreter's life (never destroyed: no Python call at exit).
PythonClasses& Classes() {
  static PythonClasses* classes = new PythonClasses;
  return *classes;
}

py::object ClassOfExitCode(int code) {
  const PythonClasses& c = Classes();
  switch (code) {
    case kExitUsage:
      return c.usage;
    case kExitConfig:
      return c.style;
    case kExitVulkan:
      return c.vulkan;
    case kExitOutput:
      return c.output;
    case kExitExists:
      return c.folder;
    case kExitBudget:
      return c.budget;
    case kExitMerge:
      return c.manifest;
    default:
      return c.error;
  }
}

py::list Locations(const std::vector<ConfigError>& errors) {
  py::list list;
  for (const ConfigError& e : errors) list.append(Classes().location(e.file, e.line, e.column, e.key, e.message));
  return list;
}

// Sets the Python error (GIL held) of exit code `code`.
void SetError(int code, const std::string& message, const std::vector<ConfigError>& errors = {}) {
  py::object cls = ClassOfExitCode(code);
  py::object instance = cls(message, code, Locations(errors));
  PyErr_SetObject(cls.ptr(), instance.ptr());
}

// "N errors; nothing was baked" after each located error, as the CLI prints them.
std::string ErrorsText(const std::vector<ConfigError>& errors) {
  std::string text;
  for (const ConfigError& e : errors) text += e.Format() + "\n";
  return text + fmt::format("{} error{}; nothing was baked", errors.size(), errors.size() == 1 ? "" : "s");
}

[[noreturn]] void ThrowConfigErrors(const std::vector<ConfigError>& errors) {
  throw ConfigFailure(ErrorsText(errors), errors);
}

// The exit code and message of a failure, as the CLI maps them (main.cc).
struct FailureKind {
  int code = kExitInternal;
  std::string message;
};
FailureKind FailureOf(std::exception_ptr failure) {
  try {
    std::rethrow_exception(failure);
  } catch (const Error& e) {
    return {e.exit_code(), e.message()};
  } catch (const std::bad_alloc&) {
    return {kExitBudget,
            "out of memory: lower render.cube_size or render.latlong_height, or max_memory_mib so "
            "that the budget check refuses such bakes (README \"Limits\")"};
  } catch (const std::filesystem::filesystem_error& e) {
    return {kExitOutput, e.what()};
  } catch (const std::exception& e) {
    return {kExitInternal, std::string("internal error: ") + e.what() + " (please report it)"};
  } catch (...) {
    return {kExitInternal, "internal error (please report it)"};
  }
}

// Every skybake failure as its exception; Python's own errors pass through.
void TranslateException(std::exception_ptr failure) {
  try {
    std::rethrow_exception(failure);
  } catch (const py::error_already_set&) {
    throw;
  } catch (const py::builtin_exception&) {
    throw;
  } catch (const ConfigFailure& e) {
    SetError(e.exit_code(), e.message(), e.errors);
  } catch (const std::exception&) {
    const FailureKind f = FailureOf(std::current_exception());
    SetError(f.code, f.message);
  }
}

// === The environment, read once before the first Vulkan call, as main
// reads it (ReadEnvironment): the loader's driver choice, lavapipe's
// threads, the star catalogue, the validation switch, the shader switches.
struct Environment {
  std::string software_driver_selection;
  std::string lavapipe_threads;
  std::string star_catalogue = DefaultStarCataloguePath();
  bool validation = false;
  ShaderSwitches shaders;
};

bool EnvIs(const char* name, const char* value) {
  const char* v = std::getenv(name);
  return v && std::string(v) == value;
}

const Environment& ReadEnvironment() {
  static const Environment environment = [] {
    Environment env;
    EnvironmentVariables variables;
    for (const std::string& name : DriverEnvironmentVariableNames())
      if (const char* value = std::getenv(name.c_str())) variables[name] = value;
    env.software_driver_selection = SoftwareDriverSelection(ProbeDriverEnvironment(variables));
    if (!env.software_driver_selection.empty())
      ::setenv("VK_LOADER_DRIVERS_SELECT", env.software_driver_selection.c_str(), 1);
    env.lavapipe_threads = LavapipeThreadCount(variables, std::thread::hardware_concurrency());
    if (!env.lavapipe_threads.empty()) ::setenv("LP_NUM_THREADS", env.lavapipe_threads.c_str(), 1);
    if (const char* catalogue = std::getenv("SKYBAKE_STAR_CATALOGUE"); catalogue && *catalogue)
      env.star_catalogue = catalogue;
    const char* validation = std::getenv("SKYBAKE_VULKAN_VALIDATION");
    env.validation = validation && *validation && std::string(validation) != "0";
    env.shaders.generic = EnvIs("SKYBAKE_GENERIC_SHADERS", "1");
    env.shaders.sun_disc_pass = !EnvIs("SKYBAKE_SUN_DISC_PASS", "0");
    env.shaders.shadowed_clouds = !EnvIs("SKYBAKE_SHADOWED_CLOUDS", "0");
    env.shaders.twilight_rows = !EnvIs("SKYBAKE_TWILIGHT_ROWS", "0");
    env.shaders.texel_views = !EnvIs("SKYBAKE_TEXEL_VIEWS", "0");
    env.shaders.formation_read_always = EnvIs("SKYBAKE_FORMATION_READ", "1");
    return env;
  }();
  return environment;
}

// The OpenImageIO module (previews, glTF textures) is looked for in the
// folder of this module first (where it is installed beside it), unless
// SKYBAKE_MODULE_DIR names another.
void FindOiioModuleBesideThis() {
  if (const char* dir = std::getenv("SKYBAKE_MODULE_DIR")) {
    SetOiioModuleDir(dir);
    return;
  }
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&FindOiioModuleBesideThis), &info) && info.dli_fname)
    SetOiioModuleDir(std::filesystem::path(info.dli_fname).parent_path().string());
}

// === A style given as a dict: written as TOML text, every key quoted, so
// that the style reader checks it exactly as a file (wrong types get the
// same errors); what TOML cannot hold is an error at its key.
std::string TomlString(const std::string& text) {
  std::string out = "\"";
  for (char ch : text) {
    const unsigned char c = static_cast<unsigned char>(ch);
    if (c == '"' || c == '\\') out += {'\\', ch};
    else if (c < 0x20 || c == 0x7f) out += fmt::format("\\u{:04X}", c);
    else out += ch;
  }
  return out + "\"";
}

struct TomlWriter {
  std::string name;  // the style's name in errors
  std::vector<ConfigError> errors;

  void Fail(const std::string& key, const std::string& message) { errors.push_back({name, 0, 0, key, message}); }

  std::string Key(py::handle key, const std::string& path) {
    if (!py::isinstance<py::str>(key)) {
      Fail(path,
           fmt::format("a key must be a string, not {}", std::string(py::str(py::type::of(key).attr("__name__")))));
      return "\"\"";
    }
    return TomlString(key.cast<std::string>());
  }

  static std::string Join(const std::string& path, const std::string& key) {
    return path.empty() ? key : path + "." + key;
  }

  // A datetime.date, .time or .datetime as a TOML local date, local time,
  // local or offset date-time (a schedule's `date`, `times`): its isoformat.
  std::optional<std::string> DateOrTime(py::handle v, const std::string& key) {
    py::module_ datetime = py::module_::import("datetime");
    const bool is_datetime = py::isinstance(v, datetime.attr("datetime"));
    const bool is_time = py::isinstance(v, datetime.attr("time"));
    if (!is_datetime && !is_time && !py::isinstance(v, datetime.attr("date"))) return std::nullopt;
    if (is_time && !v.attr("tzinfo").is_none()) {
      Fail(key,
           "a time with a time zone has no TOML form: give a naive datetime.time (the schedule's "
           "utc_offset_hours places it)");
      return "0";
    }
    return v.attr("isoformat")().cast<std::string>();
  }

  // A value, inline (arrays and tables of arrays as inline arrays and tables).
  std::string Value(py::handle v, const std::string& key) {
    if (PyBool_Check(v.ptr())) return v.ptr() == Py_True ? "true" : "false";
    if (py::isinstance<py::str>(v)) return TomlString(v.cast<std::string>());
    if (std::optional<std::string> when = DateOrTime(v, key)) return *when;
    if (PyLong_Check(v.ptr()) || (PyIndex_Check(v.ptr()) && !PyFloat_Check(v.ptr())))
      return std::string(py::str(py::int_(py::reinterpret_borrow<py::object>(v))));
    if (PyFloat_Check(v.ptr()) || py::hasattr(v, "__float__")) {
      // Python's repr of a float is a TOML float ("1e-05", "inf", "nan");
      // one without '.', 'e', "inf" or "nan" ("1" from a numpy float) gets ".0".
      std::string text = py::repr(py::float_(py::reinterpret_borrow<py::object>(v)));
      if (text.find_first_of(".eEna") == std::string::npos) text += ".0";
      return text;
    }
    if (py::isinstance<py::dict>(v)) {
      std::string out = "{";
      bool first = true;
      for (auto [k, item] : py::reinterpret_borrow<py::dict>(v)) {
        const std::string quoted = Key(k, key);
        out += (first ? " " : ", ") + quoted + " = " +
               Value(item, Join(key, py::isinstance<py::str>(k) ? k.cast<std::string>() : "?"));
        first = false;
      }
      return out + (first ? "}" : " }");
    }
    if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) {
      std::string out = "[";
      size_t i = 0;
      for (py::handle item : v) {
        out += (i ? ", " : "") + Value(item, fmt::format("{}[{}]", key, i));
        ++i;
      }
      return out + "]";
    }
    Fail(key, fmt::format("{} cannot be written as TOML: give a bool, int, float, str, list, dict, or a "
                          "datetime.date, time or datetime",
                          std::string(py::str(py::type::of(v).attr("__name__")))));
    return "0";
  }

  // A table: its plain values, then each sub-table under its own header.
  void Table(const py::dict& table, const std::string& path, const std::string& header, std::string& out) {
    if (!header.empty()) out += "\n[" + header + "]\n";
    for (auto [k, item] : table)
      if (!py::isinstance<py::dict>(item)) {
        const std::string quoted = Key(k, path);
        out +=
            quoted + " = " + Value(item, Join(path, py::isinstance<py::str>(k) ? k.cast<std::string>() : "?")) + "\n";
      }
    for (auto [k, item] : table)
      if (py::isinstance<py::dict>(item)) {
        const std::string quoted = Key(k, path);
        const std::string key = py::isinstance<py::str>(k) ? k.cast<std::string>() : "?";
        Table(py::reinterpret_borrow<py::dict>(item), Join(path, key), header.empty() ? quoted : header + "." + quoted,
              out);
      }
  }
};

std::string StyleDictToToml(const py::dict& style, const std::string& name) {
  TomlWriter writer{name, {}};
  std::string text;
  writer.Table(style, "", "", text);
  if (!writer.errors.empty()) ThrowConfigErrors(writer.errors);
  return text;
}

// === Style and schedule objects.
struct PyStyle {
  std::string source;               // the file's path, or the name of a dict or text style
  std::optional<std::string> text;  // the TOML text of a style that is not a file
  std::vector<std::string> overrides;
  ConfigResult config;

  // The style with `extra` assignments after its own (size, engine, usd).
  ConfigResult With(const std::vector<std::string>& extra) const {
    std::vector<std::string> all = overrides;
    all.insert(all.end(), extra.begin(), extra.end());
    return text ? ParseSkyStyle(*text, source, all) : LoadSkyStyle(source, all);
  }
  // An inline [schedule] table, as the CLI reads one from a style file: in
  // the file, or in the text of a dict or text style.
  bool has_inline_schedule() const { return text ? TextHasSchedule(*text, source) : FileHasSchedule(source); }
};

PyStyle MakeStyle(std::string source, std::optional<std::string> text, std::vector<std::string> overrides) {
  const KeptReadScope kept;  // the OpenColorIO config as it is now (file_door.h)
  PyStyle style{std::move(source), std::move(text), std::move(overrides), {}};
  style.config = style.With({});
  if (!style.config.ok()) ThrowConfigErrors(style.config.errors);
  return style;
}

struct PySchedule {
  Schedule schedule;
};

PySchedule LoadScheduleOrThrow(const std::string& path) {
  ScheduleResult loaded = LoadSchedule(path);
  if (!loaded.ok()) ThrowConfigErrors(loaded.errors);
  return {std::move(loaded.schedule)};
}

// A style's inline schedule (has_inline_schedule), named as the style.
PySchedule InlineScheduleOrThrow(const PyStyle& style) {
  if (!style.text) return LoadScheduleOrThrow(style.source);
  ScheduleResult parsed = ParseSchedule(*style.text, style.source);
  if (!parsed.ok()) ThrowConfigErrors(parsed.errors);
  return {std::move(parsed.schedule)};
}

py::dict FrameOfSchedule(const ScheduleFrame& f) {
  py::dict d;
  d["number"] = f.number;
  d["time"] = f.time ? py::object(py::str(f.time->Iso8601())) : py::object(py::none());
  d["hours_from_start"] = f.hours_from_start;
  d["elevation_deg"] = f.elevation_deg;
  d["azimuth_deg"] = f.azimuth_deg;
  d["sun_direction"] = py::make_tuple(f.sun_direction.x, f.sun_direction.y, f.sun_direction.z);
  return d;
}

// === What a bake, check or plan reads, as main's LoadBake: the style with
// the extra assignments, the schedule (given, or inline in the style file),
// every frame's resolved style, the night sky's input; every error at once.
struct LoadedBake {
  ConfigResult config;
  std::optional<Schedule> schedule;
  std::string schedule_path;
  std::vector<SkyStyle> frame_styles;
  std::vector<ConfigError> warnings;
  std::vector<SkyStyle> Styles() const { return schedule ? frame_styles : std::vector<SkyStyle>{config.style}; }
};

LoadedBake Load(const PyStyle& style, const PySchedule* schedule, const std::vector<std::string>& extra) {
  const Environment& env = ReadEnvironment();
  LoadedBake bake;
  // Parsed again, so that its inputs (an OpenColorIO config) are as they are now.
  bake.config = style.With(extra);
  if (!bake.config.ok()) ThrowConfigErrors(bake.config.errors);
  bake.warnings = bake.config.warnings;
  if (schedule) bake.schedule = schedule->schedule;
  else if (style.has_inline_schedule()) bake.schedule = InlineScheduleOrThrow(style).schedule;
  if (bake.schedule) {
    bake.schedule_path = bake.schedule->source_path;
    std::vector<std::string> all = style.overrides;
    all.insert(all.end(), extra.begin(), extra.end());
    FrameStyles styles = style.text ? ResolveFrameStylesOfText(*style.text, style.source, all, *bake.schedule)
                                    : ResolveFrameStyles(style.source, all, *bake.schedule);
    if (!styles.ok()) ThrowConfigErrors(styles.errors);
    bake.warnings.insert(bake.warnings.end(), styles.warnings.begin(), styles.warnings.end());
    bake.frame_styles = std::move(styles.styles);
  }
  std::vector<const SkyStyle*> pointers;
  if (bake.schedule)
    for (const SkyStyle& s : bake.frame_styles) pointers.push_back(&s);
  else pointers.push_back(&bake.config.style);
  const std::vector<ConfigError> night =
      CheckNightSky(pointers, bake.schedule ? &*bake.schedule : nullptr, env.star_catalogue);
  if (!night.empty()) ThrowConfigErrors(night);
  return bake;
}

std::vector<std::string> ExtraOverrides(std::optional<int> size, const std::optional<std::string>& engine, bool usd) {
  std::vector<std::string> extra;
  if (size) {
    extra.push_back(fmt::format("render.cube_size={}", *size));
    extra.push_back(fmt::format("render.latlong_height={}", *size));
  }
  if (engine) extra.push_back("output.engine=" + *engine);
  if (usd) extra.push_back("usd.enabled=true");
  return extra;
}

// Every frame against the budget (BudgetError when over); the largest estimate.
ResourceEstimate CheckFrameBudgets(const LoadedBake& bake, const BakeOptions& options) {
  ResourceEstimate largest;
  for (const SkyStyle& style : bake.Styles()) {
    CheckBudget(style, options);
    const ResourceEstimate e = EstimateResources(style);
    largest.memory_mib = std::max(largest.memory_mib, e.memory_mib);
    largest.seconds = std::max(largest.seconds, e.seconds);
  }
  return largest;
}

std::optional<FrameRange> SelectPart(const LoadedBake& bake, const std::optional<std::string>& frames,
                                     const std::optional<std::string>& shard) {
  if (!frames && !shard) return std::nullopt;
  std::optional<FrameRange> range;
  std::optional<ShardSpec> spec;
  if (frames) range = ParseFrameRange(*frames);
  if (shard) spec = ParseShard(*shard);
  if (!bake.schedule)
    throw UsageError("frames and shard split a sequence bake: give a schedule (or a style with an inline [schedule])");
  return SelectFrames(*bake.schedule, range, spec);
}

// === Progress: the CLI's report (progress_report.h) writing its JSON
// lines into memory (a stdio stream of our own), each line handed to the
// callback as a dict; a callback that returns False or raises stops the
// bake by an exception from the pipeline's own callback.
struct CallbackStop {};

class PythonProgress {
 public:
  explicit PythonProgress(py::object callback) : callback_(std::move(callback)) {
    cookie_io_functions_t io{};
    io.write = &PythonProgress::Write;
    json_ = fopencookie(this, "w", io);
    if (!json_) throw std::runtime_error("fopencookie failed");
    report_.emplace(ProgressStyle::kQuiet, stderr, json_, SKYBAKE_VERSION, kBuildCommit);
    Deliver();  // the "start" event
  }
  ~PythonProgress() {
    report_.reset();
    std::fclose(json_);
  }
  PythonProgress(const PythonProgress&) = delete;
  PythonProgress& operator=(const PythonProgress&) = delete;

  // Called by the bake, without the GIL.
  void Attach(BakeOptions& options) {
    options.progress = [this](const StageReport& stage) {
      report_->Stage(stage);
      FromBake();
    };
    options.frame_progress = [this](const FrameProgress& frame) {
      report_->Frame(frame);
      FromBake();
    };
  }

  // With the GIL: the last event.
  void End(int exit_code, const std::string& error) {
    report_->End(exit_code, error);
    Deliver();
  }

  bool cancelled() const { return cancelled_; }
  // What the callback raised (Cancel, KeyboardInterrupt, any error), if it raised.
  std::optional<py::error_already_set>& raised() { return raised_; }

 private:
  static ssize_t Write(void* cookie, const char* bytes, size_t size) {
    static_cast<PythonProgress*>(cookie)->pending_.append(bytes, size);
    return ssize_t(size);
  }

  void FromBake() {
    py::gil_scoped_acquire gil;
    Deliver();
    if (!cancelled_ && PyErr_CheckSignals() != 0) {  // Ctrl-C while the bake runs
      raised_.emplace();
      cancelled_ = true;
    }
    if (cancelled_) throw CallbackStop{};
  }

  // Each complete line to the callback (GIL held).
  void Deliver() {
    for (size_t end; (end = pending_.find('\n')) != std::string::npos;) {
      const std::string line = pending_.substr(0, end);
      pending_.erase(0, end + 1);
      if (cancelled_ || callback_.is_none()) continue;
      try {
        py::object event = py::module_::import("json").attr("loads")(line);
        py::object answer = callback_(event);
        if (answer.ptr() == Py_False) cancelled_ = true;
      } catch (py::error_already_set& e) {
        raised_.emplace(std::move(e));
        cancelled_ = true;
      }
    }
  }

  py::object callback_;
  std::FILE* json_ = nullptr;
  std::optional<ProgressReport> report_;
  std::string pending_;
  bool cancelled_ = false;
  std::optional<py::error_already_set> raised_;
};

// === Results.
struct PyFile {
  std::string path, kind;
  uint64_t bytes = 0;
  std::string sha256;
};

struct PyFrame {
  int number = 0;
  py::object time = py::none();
  std::array<double, 3> sun_direction{};
  double sun_elevation_deg = 0.0, sun_azimuth_deg = 0.0, sun_illuminance_lux = 0.0;
  std::array<double, 3> sun_irradiance{};
  py::object sh_irradiance_with_sun = py::none(), sh_irradiance_without_sun = py::none();
  py::object moon = py::none();
  std::vector<PyFile> files;
  py::object latlong = py::none();
  py::object cube = py::none();
  py::dict faces;
  py::dict engine;
  py::dict ibl;                            // every IBL file's texels, by file name
  py::list ibl_specular;                   // the prefiltered levels, (6, N, N, 3) each
  py::object ibl_irradiance = py::none();  // (6, N, N, 3)
  double render_seconds = 0.0;
};

struct PyBake {
  std::string out, manifest_path;
  std::vector<PyFrame> frames;
  std::vector<PyFile> files;
  py::object manifest = py::none();
  double half_scale = 1.0, preview_ev100 = 0.0;
  py::list warnings, stages;
};

std::vector<PyFile> FilesOf(const std::vector<BakedFile>& files) {
  std::vector<PyFile> out;
  for (const BakedFile& f : files) out.push_back({f.path, f.kind, f.bytes, f.sha256});
  return out;
}

py::array_t<double> ShArray(const ShRgb& sh) {
  py::array_t<double> a({size_t(kShCoefficients), size_t(3)});
  auto m = a.mutable_unchecked<2>();
  for (int i = 0; i < kShCoefficients; ++i)
    for (int c = 0; c < 3; ++c) m(i, c) = sh[size_t(i)][size_t(c)];
  return a;
}

py::tuple Tuple3(const glm::dvec3& v) { return py::make_tuple(v.x, v.y, v.z); }
py::tuple Tuple3(const Rgb& v) { return py::make_tuple(v[0], v[1], v[2]); }

py::dict MoonOf(const MoonRecord& m) {
  py::dict d;
  d["direction"] = Tuple3(m.direction);
  d["elevation_deg"] = m.elevation_deg;
  d["azimuth_deg"] = m.azimuth_deg;
  d["phase_angle_deg"] = m.phase_angle_deg;
  d["illuminated_fraction"] = m.illuminated_fraction;
  d["bright_limb_deg"] = m.bright_limb_deg;
  d["angular_radius_rad"] = m.angular_radius_rad;
  d["top_illuminance_lux"] = m.top_illuminance_lux;
  d["illuminance_lux"] = m.illuminance_lux;
  d["irradiance"] = Tuple3(m.irradiance);
  d["light"] = m.light;
  return d;
}

py::array_t<float> ArrayOf(const RgbImage& image) {
  py::array_t<float> a({size_t(image.height), size_t(image.width), size_t(3)});
  std::memcpy(a.mutable_data(), image.rgb.data(), image.rgb.size() * sizeof(float));
  return a;
}

bool EndsWith(const std::string& path, const char* suffix) {
  const size_t n = std::strlen(suffix);
  return path.size() > n && path.compare(path.size() - n, n, suffix) == 0;
}
bool IsExr(const std::string& path) { return EndsWith(path, ".exr"); }
bool IsIbl(const BakedFile& f) { return f.kind == "ibl_specular" || f.kind == "ibl_irradiance" || f.kind == "ibl_dfg"; }

// The images of a frame's files read back (without the GIL), by file: its
// EXRs, and the mip levels of its IBL KTX2s.
struct FrameImages {
  std::map<std::string, RgbImage> exrs;
  std::map<std::string, std::vector<Ktx2Level>> ktx2s;
};

FrameImages ReadFrameImages(const std::vector<FrameResult>& frames) {
  FrameImages images;
  py::gil_scoped_release release;
  for (const FrameResult& frame : frames)
    for (const BakedFile& f : frame.files) {
      const bool map = f.kind == "latlong" || f.kind == "face" || f.kind == "cube" || f.kind == "engine" || IsIbl(f);
      if (map && IsExr(f.path)) images.exrs.emplace(f.path, ReadExrRgb(f.path));
      else if (IsIbl(f) && EndsWith(f.path, ".ktx2")) images.ktx2s.emplace(f.path, ReadKtx2Rgb(f.path));
    }
  return images;
}

// An IBL cube EXR (six faces stacked from the top, ibl_files.cc) as (6, N, N, 3).
py::array_t<float> CubeOfStacked(const RgbImage& image) {
  const size_t n = size_t(image.width);
  py::array_t<float> a({size_t(6), n, n, size_t(3)});
  std::memcpy(a.mutable_data(), image.rgb.data(), image.rgb.size() * sizeof(float));
  return a;
}

// A KTX2's mip levels: (6, N, N, 3) per level of a cube, (N, N, 3) of an image.
py::list LevelsOf(const std::vector<Ktx2Level>& levels) {
  py::list list;
  for (const Ktx2Level& l : levels) {
    const size_t n = size_t(l.size);
    py::array_t<float> a =
        l.faces == 6 ? py::array_t<float>({size_t(6), n, n, size_t(3)}) : py::array_t<float>({n, n, size_t(3)});
    std::memcpy(a.mutable_data(), l.rgb.data(), l.rgb.size() * sizeof(float));
    list.append(a);
  }
  return list;
}

// Frame.ibl, .ibl_specular and .ibl_irradiance: every IBL file by name; the levels
// and irradiance from the EXRs when written, else from the KTX2s.
void IblArraysOf(const FrameResult& f, const FrameImages& images, PyFrame& frame) {
  py::list exr_levels;
  for (const BakedFile& file : f.files) {
    if (!IsIbl(file)) continue;
    const py::str name(std::filesystem::path(file.path).filename().string());
    if (auto exr = images.exrs.find(file.path); exr != images.exrs.end()) {
      py::array_t<float> array = file.kind == "ibl_dfg" ? ArrayOf(exr->second) : CubeOfStacked(exr->second);
      frame.ibl[name] = array;
      if (file.kind == "ibl_specular") exr_levels.append(array);  // listed level 0 first (IblFileNames)
      else if (file.kind == "ibl_irradiance") frame.ibl_irradiance = array;
    } else if (auto ktx2 = images.ktx2s.find(file.path); ktx2 != images.ktx2s.end()) {
      py::list levels = LevelsOf(ktx2->second);
      frame.ibl[name] = levels;
      if (file.kind == "ibl_specular" && frame.ibl_specular.empty() && exr_levels.empty()) frame.ibl_specular = levels;
      else if (file.kind == "ibl_irradiance" && frame.ibl_irradiance.is_none()) frame.ibl_irradiance = levels[0];
    }
  }
  if (!exr_levels.empty()) frame.ibl_specular = exr_levels;
}

PyFrame FrameOf(const FrameResult& f, const FrameImages* images) {
  PyFrame frame;
  frame.number = f.number;
  if (f.time) frame.time = py::str(f.time->Iso8601());
  frame.sun_direction = {f.sun_direction.x, f.sun_direction.y, f.sun_direction.z};
  frame.sun_elevation_deg = f.sun_elevation_deg;
  frame.sun_azimuth_deg = f.sun_azimuth_deg;
  frame.sun_illuminance_lux = f.sun_illuminance_lux;
  frame.sun_irradiance = f.sun_irradiance;
  frame.sh_irradiance_with_sun = ShArray(f.sh_irradiance_with_sun);
  frame.sh_irradiance_without_sun = ShArray(f.sh_irradiance_without_sun);
  if (f.moon) frame.moon = MoonOf(*f.moon);
  frame.files = FilesOf(f.files);
  frame.render_seconds = f.render_seconds;
  if (images) {
    for (const BakedFile& file : f.files) {
      auto it = images->exrs.find(file.path);
      if (it == images->exrs.end() || IsIbl(file)) continue;
      py::array_t<float> array = ArrayOf(it->second);
      if (file.kind == "latlong" && frame.latlong.is_none()) frame.latlong = array;
      else if (file.kind == "cube") frame.cube = array;
      else if (file.kind == "face") frame.faces[py::str(std::filesystem::path(file.path).filename().string())] = array;
      else if (file.kind == "engine")
        frame.engine[py::str(std::filesystem::path(file.path).filename().string())] = array;
    }
    IblArraysOf(f, *images, frame);
  }
  return frame;
}

// === The module's functions.
PyStyle LoadStyle(py::object source, const std::vector<std::string>& overrides,
                  const std::optional<std::string>& name) {
  if (py::isinstance<py::dict>(source)) {
    const std::string style_name = name.value_or("<dict>");
    return MakeStyle(style_name, StyleDictToToml(py::reinterpret_borrow<py::dict>(source), style_name), overrides);
  }
  if (py::isinstance<py::str>(source) || py::hasattr(source, "__fspath__"))
    return MakeStyle(py::str(py::module_::import("os").attr("fspath")(source)).cast<std::string>(), std::nullopt,
                     overrides);
  throw py::type_error(
      "load_style: give a path (str or os.PathLike) or a dict of style keys; TOML text goes to "
      "parse_style");
}

py::list Check(const PyStyle& style, const PySchedule* schedule, double max_memory_mib, double max_frame_seconds) {
  const KeptReadScope kept;
  LoadedBake bake = Load(style, schedule, {});
  BakeOptions options;
  options.max_memory_mib = max_memory_mib;
  options.max_frame_seconds = max_frame_seconds;
  CheckFrameBudgets(bake, options);
  return Locations(bake.warnings);
}

py::dict Estimate(const PyStyle& style, const PySchedule* schedule, std::optional<int> size) {
  const KeptReadScope kept;
  LoadedBake bake = Load(style, schedule, ExtraOverrides(size, std::nullopt, false));
  ResourceEstimate largest;
  for (const SkyStyle& s : bake.Styles()) {
    const ResourceEstimate e = EstimateResources(s);
    largest.memory_mib = std::max(largest.memory_mib, e.memory_mib);
    largest.seconds = std::max(largest.seconds, e.seconds);
  }
  py::dict d;
  d["memory_mib"] = largest.memory_mib;
  d["seconds"] = largest.seconds;
  d["frames"] = bake.schedule ? bake.schedule->frames.size() : size_t(1);
  return d;
}

std::string Plan(const PyStyle& style, const PySchedule* schedule, std::optional<int> size,
                 const std::optional<std::string>& frames, const std::optional<std::string>& shard) {
  const KeptReadScope kept;
  const Environment& env = ReadEnvironment();
  LoadedBake bake = Load(style, schedule, ExtraOverrides(size, std::nullopt, false));
  const std::optional<FrameRange> part = SelectPart(bake, frames, shard);
  const RenderPlan render_plan =
      bake.schedule ? PlanSequenceBake(bake.frame_styles, *bake.schedule, part) : PlanSingleBake(bake.config.style);
  std::vector<double> hours;
  for (const FramePlan& f : render_plan.frames)
    if (render_plan.Bakes(f)) hours.push_back(f.hours_from_start);
  const PassPlan plan = PlanPasses(render_plan.BakedStyles(), env.shaders, hours);
  std::string what = style.source + (bake.schedule ? " with " + bake.schedule_path : "");
  if (part)
    what += fmt::format(" (frames {} to {} of {} to {})", part->first, part->last, bake.schedule->frames.front().number,
                        bake.schedule->frames.back().number);
  return FormatPlan(plan, what);
}

PyBake Bake(const PyStyle& style, const std::string& out, const PySchedule* schedule, std::optional<int> size,
            bool force, bool resume, py::object progress, bool vulkan_validation, bool arrays, int device,
            double max_memory_mib, double max_frame_seconds, const std::optional<std::string>& frames,
            const std::optional<std::string>& shard, const std::optional<std::string>& engine, bool usd) {
  const Environment& env = ReadEnvironment();
  // Every input (star catalogue, OpenColorIO config, weather and mask
  // images) read once in this bake, as the files are now: a bake after an
  // edit sees the edit (file_door.h, KeptReadScope).
  const KeptReadScope kept;
  // The progress events from the start, as --progress-json's: an error
  // found before the bake ends them too, with its exit code.
  PythonProgress report(progress);
  LoadedBake bake;
  BakeOptions options;
  try {
    // Parse and validate: every error at once, before any GPU work.
    bake = Load(style, schedule, ExtraOverrides(size, engine, usd));
    options.max_memory_mib = max_memory_mib;
    options.max_frame_seconds = max_frame_seconds;
    CheckFrameBudgets(bake, options);
    options.frames = SelectPart(bake, frames, shard);
    if (resume && !bake.schedule)
      throw UsageError(
          "resume continues a sequence bake: give a schedule (or a style with an inline [schedule]), "
          "or force=True to bake a single style again");
  } catch (const py::error_already_set&) {
    throw;
  } catch (...) {
    const FailureKind f = FailureOf(std::current_exception());
    report.End(f.code, f.message);
    throw;
  }
  options.out_dir = out;
  options.force = force;
  options.resume = resume;
  options.build_commit = kBuildCommit;
  options.vulkan.device_index = device;
  options.vulkan.validation = vulkan_validation || env.validation;
  options.vulkan.software_driver_selection = env.software_driver_selection;
  options.vulkan.lavapipe_threads = env.lavapipe_threads;
  options.shaders = env.shaders;
  options.star_catalogue = env.star_catalogue;

  // Bake, without the GIL; the progress callback takes it back.
  report.Attach(options);
  BakeResult result;
  std::exception_ptr failure;
  {
    py::gil_scoped_release release;
    try {
      result = bake.schedule ? BakeSequence(bake.frame_styles, *bake.schedule, options)
                             : BakeStyle(bake.config.style, options);
    } catch (...) {
      failure = std::current_exception();
    }
  }
  if (report.cancelled()) {
    if (report.raised()) throw *report.raised();
    PyErr_SetString(Classes().cancel.ptr(),
                    "the progress callback cancelled the bake: the folder holds the frames done (resume=True "
                    "finishes a sequence)");
    throw py::error_already_set();
  }
  if (failure) {
    const FailureKind f = FailureOf(failure);
    report.End(f.code, f.message);
    std::rethrow_exception(failure);
  }
  if (result.validation_messages > 0) {
    const std::string message = fmt::format("the Vulkan validation layer reported {} message{}",
                                            result.validation_messages, result.validation_messages == 1 ? "" : "s");
    report.End(kExitVulkan, message);
    throw VulkanUnavailable(message);
  }
  report.End(kExitOk, "");

  // The result: frames, files, the manifest as a dict, arrays when asked.
  FrameImages images;
  if (arrays) images = ReadFrameImages(result.frames);
  PyBake baked;
  baked.out = out;
  baked.manifest_path = result.manifest_path;
  for (const FrameResult& f : result.frames) baked.frames.push_back(FrameOf(f, arrays ? &images : nullptr));
  baked.files = FilesOf(result.files);
  baked.half_scale = result.half_scale;
  baked.preview_ev100 = result.preview_ev100;
  baked.warnings = Locations(bake.warnings);
  for (const StageReport& s : result.stages) baked.stages.append(py::make_tuple(s.name, s.seconds, s.detail));
  py::object open = py::module_::import("builtins").attr("open");
  py::object file = open(result.manifest_path, "r", py::arg("encoding") = "utf-8");
  baked.manifest = py::module_::import("json").attr("load")(file);
  file.attr("close")();
  return baked;
}

std::string Repr(const PyStyle& s) {
  return fmt::format("<skybake.Style {}{}>", s.source,
                     s.overrides.empty() ? "" : fmt::format(" +{} overrides", s.overrides.size()));
}

}  // namespace
}  // namespace skybake

namespace skybake {
namespace {

// The exception classes (defined in Python, kExceptionClasses) and their translation.
void RegisterExceptions(py::module_& m) {
  py::dict scope = m.attr("__dict__");
  py::exec(kExceptionClasses, scope);
  PythonClasses& c = Classes();
  c.location = m.attr("Location");
  c.error = m.attr("Error");
  c.usage = m.attr("UsageError");
  c.style = m.attr("StyleError");
  c.vulkan = m.attr("VulkanError");
  c.output = m.attr("OutputError");
  c.folder = m.attr("FolderError");
  c.budget = m.attr("BudgetError");
  c.manifest = m.attr("ManifestError");
  c.cancel = m.attr("Cancel");
  py::register_exception_translator(&TranslateException);
  FindOiioModuleBesideThis();
}

// Style, Schedule, File, Frame and Bake.
void RegisterTypes(py::module_& m) {
  py::class_<PyStyle>(m, "Style", "A loaded, validated sky style: load_style or parse_style give one.")
      .def_readonly("source", &PyStyle::source, "The style file's path, or the name of a dict or text style.")
      .def_readonly("text", &PyStyle::text, "The TOML text of a dict or text style; None for a file.")
      .def_readonly("overrides", &PyStyle::overrides, "The 'key.path=toml_value' assignments applied on top.")
      .def_property_readonly(
          "toml", [](const PyStyle& s) { return s.config.style.resolved_toml; },
          "Every key with its final value, as TOML (what the manifest's style_sha256 hashes).")
      .def_property_readonly(
          "warnings", [](const PyStyle& s) { return Locations(s.config.warnings); },
          "Not errors: the style bakes, but likely not as meant (Location tuples).")
      .def_property_readonly("has_schedule", &PyStyle::has_inline_schedule,
                             "Whether the style (a file, dict or text) has an inline [schedule] table (bake() then "
                             "bakes a sequence).")
      .def(
          "with_overrides",
          [](const PyStyle& s, const std::vector<std::string>& more) {
            std::vector<std::string> all = s.overrides;
            all.insert(all.end(), more.begin(), more.end());
            return MakeStyle(s.source, s.text, all);
          },
          py::arg("overrides"), "A new Style with more 'key.path=toml_value' assignments after these.")
      .def("__repr__", &Repr);

  py::class_<PySchedule>(m, "Schedule", "The frames of a time-lapse: load_schedule gives one.")
      .def_property_readonly(
          "path", [](const PySchedule& s) { return s.schedule.source_path; }, "The schedule file's path.")
      .def_property_readonly(
          "frames",
          [](const PySchedule& s) {
            py::list frames;
            for (const ScheduleFrame& f : s.schedule.frames) frames.append(FrameOfSchedule(f));
            return frames;
          },
          "Each frame as a dict: number, time (ISO 8601 or None), hours_from_start, elevation_deg, azimuth_deg "
          "(clockwise from North), sun_direction (+Y up, North -Z, East +X).")
      .def("__len__", [](const PySchedule& s) { return s.schedule.frames.size(); })
      .def("__repr__", [](const PySchedule& s) {
        return fmt::format("<skybake.Schedule {} ({} frames)>", s.schedule.source_path, s.schedule.frames.size());
      });

  py::class_<PyFile>(m, "File", "A file a bake wrote.")
      .def_readonly("path", &PyFile::path, "Its path (the output folder joined with its name).")
      .def_readonly("kind", &PyFile::kind,
                    "face, cube, latlong, preview, gltf, gltf_bin, glb, usd, manifest, timings, ...")
      .def_readonly("bytes", &PyFile::bytes, "Its size in bytes.")
      .def_readonly("sha256", &PyFile::sha256, "Its SHA-256 in hex, as the manifest records it ('' for the manifest).")
      .def("__repr__", [](const PyFile& f) { return fmt::format("<skybake.File {} {}>", f.kind, f.path); });

  py::class_<PyFrame>(m, "Frame", "One frame of a bake: its sun, lighting, files and, with arrays=True, its images.")
      .def_readonly("number", &PyFrame::number, "The frame's number in file names; 0 for a single bake.")
      .def_readonly("time", &PyFrame::time, "The frame's clock time (ISO 8601), or None.")
      .def_readonly("sun_direction", &PyFrame::sun_direction, "Unit vector towards the Sun: +Y up, North -Z, East +X.")
      .def_readonly("sun_elevation_deg", &PyFrame::sun_elevation_deg, "The Sun's elevation, degrees.")
      .def_readonly("sun_azimuth_deg", &PyFrame::sun_azimuth_deg, "The Sun's azimuth, degrees clockwise from North.")
      .def_readonly("illuminance_lux", &PyFrame::sun_illuminance_lux,
                    "The transmitted Sun's illuminance at the observer on a plane facing it, lux.")
      .def_readonly("irradiance", &PyFrame::sun_irradiance,
                    "The transmitted Sun's irradiance at the observer, RGB, in output units x sr.")
      .def_readonly("sh_with_sun", &PyFrame::sh_irradiance_with_sun,
                    "Irradiance SH (numpy (9, 3), E_lm per RGB), the Sun disc included.")
      .def_readonly("sh_without_sun", &PyFrame::sh_irradiance_without_sun,
                    "Irradiance SH (numpy (9, 3), E_lm per RGB) of the sky alone.")
      .def_readonly("moon", &PyFrame::moon,
                    "The Moon (dict: direction, elevation_deg, azimuth_deg, phase_angle_deg, illuminated_fraction, "
                    "angular_radius_rad, illuminance_lux, irradiance, light, ...) with night.moon, else None.")
      .def_readonly("files", &PyFrame::files, "The frame's files.")
      .def_readonly("latlong", &PyFrame::latlong,
                    "With arrays=True: the latlong EXR's texels, numpy float32 (H, 2H, 3), rows from the top, as "
                    "the file stores them (times its skybake:scale); else None.")
      .def_readonly("cube", &PyFrame::cube, "With arrays=True: the cube strip EXR's texels (when written), else None.")
      .def_readonly("faces", &PyFrame::faces,
                    "With arrays=True: each cube face EXR's texels, numpy float32 (N, N, 3), by file name.")
      .def_readonly("engine", &PyFrame::engine,
                    "With arrays=True and an engine preset: each of its EXRs' texels (the engine's own layout; "
                    "docs/engines.md), numpy float32 (H, W, 3), by file name.")
      .def_readonly("ibl", &PyFrame::ibl,
                    "With arrays=True and an IBL bake: every IBL file's texels by file name, as the file stores them "
                    "(times its skybake:scale): a cube EXR (a specular level, the irradiance) as numpy float32 (6, N, "
                    "N, 3), faces +X -X +Y -Y +Z -Z (Vulkan order), rows from the top; the DFG EXR as (N, N, 3); a "
                    "KTX2 as a list of its mip levels, level 0 first, each (6, N, N, 3) for a cube, (N, N, 3) for "
                    "the DFG table.")
      .def_readonly("ibl_specular", &PyFrame::ibl_specular,
                    "With arrays=True and ibl.specular: the GGX-prefiltered levels, level 0 (roughness 0) first, "
                    "each numpy float32 (6, N, N, 3), from the EXRs when written, else the KTX2's mip levels; else [].")
      .def_readonly("ibl_irradiance", &PyFrame::ibl_irradiance,
                    "With arrays=True and ibl.irradiance: the irradiance map E(n) / pi, numpy float32 (6, N, N, 3), "
                    "from the EXR when written, else the KTX2; else None.")
      .def_readonly("render_seconds", &PyFrame::render_seconds, "The frame's render time, s.")
      .def("__repr__", [](const PyFrame& f) {
        return fmt::format("<skybake.Frame {} sun {:.2f} deg>", f.number, f.sun_elevation_deg);
      });

  py::class_<PyBake>(m, "Bake", "What bake() produced.")
      .def_readonly("out", &PyBake::out, "The output folder.")
      .def_readonly("frames", &PyBake::frames, "Every frame baked, in order.")
      .def_readonly("files", &PyBake::files, "Every file: the frames', then the scene's, manifest.json, timings.json.")
      .def_readonly("manifest", &PyBake::manifest, "manifest.json, read back as a dict.")
      .def_readonly("manifest_path", &PyBake::manifest_path, "manifest.json's path.")
      .def_readonly("half_scale", &PyBake::half_scale,
                    "The power-of-two factor the EXRs were scaled by to fit half range.")
      .def_readonly("preview_ev100", &PyBake::preview_ev100, "The preview's exposure, EV100.")
      .def_readonly("warnings", &PyBake::warnings, "The style's and schedule's warnings (Location tuples).")
      .def_readonly("stages", &PyBake::stages, "Every stage as (name, seconds, detail).")
      .def("__repr__", [](const PyBake& b) {
        return fmt::format("<skybake.Bake {} ({} frames, {} files)>", b.out, b.frames.size(), b.files.size());
      });
}

// load_style, parse_style, load_schedule, check, estimate, plan and bake.
void RegisterFunctions(py::module_& m) {
  m.def("load_style", &LoadStyle, py::arg("source"), py::arg("overrides") = std::vector<std::string>{}, py::kw_only(),
        py::arg("name") = py::none(),
        "Loads and validates a style: `source` is a TOML file's path, or a dict of style keys (nested dicts are "
        "tables: {'sun': {'elevation_deg': 10}}), written as TOML and read exactly as a file, named `name` "
        "(default '<dict>') in errors and provenance; a [schedule] table in it (dates and times as datetime.date and "
        "datetime.time) makes a sequence, as in a file. `overrides` are 'key.path=toml_value' assignments, as the "
        "CLI's --set. Raises StyleError with every located error.");
  m.def(
      "parse_style",
      [](const std::string& text, const std::vector<std::string>& overrides, const std::string& name) {
        return MakeStyle(name, text, overrides);
      },
      py::arg("text"), py::arg("overrides") = std::vector<std::string>{}, py::arg("name") = "<text>",
      "Loads and validates a style from TOML text, named `name` in errors and provenance. Raises StyleError.");
  m.def(
      "load_schedule",
      [](py::object path) {
        return LoadScheduleOrThrow(py::str(py::module_::import("os").attr("fspath")(path)).cast<std::string>());
      },
      py::arg("path"),
      "Loads the [schedule] table of a file (a schedule file, or a style with an inline schedule): the frames of "
      "a time-lapse. Raises StyleError with every located error.");
  m.def("check", &Check, py::arg("style"), py::arg("schedule") = nullptr, py::kw_only(),
        py::arg("max_memory_mib") = 4096.0, py::arg("max_frame_seconds") = 3600.0,
        "Validates as `skybake check`: the style, the schedule (or the style's inline one) and every frame's "
        "style, the night sky's input, each frame against the budget. Returns the warnings (Location tuples); "
        "raises StyleError or BudgetError.");
  m.def("estimate", &Estimate, py::arg("style"), py::arg("schedule") = nullptr, py::kw_only(),
        py::arg("size") = py::none(),
        "The largest frame's estimate, as `skybake check` prints it: {'memory_mib', 'seconds' (of lavapipe time), "
        "'frames'}.");
  m.def("plan", &Plan, py::arg("style"), py::arg("schedule") = nullptr, py::kw_only(), py::arg("size") = py::none(),
        py::arg("frames") = py::none(), py::arg("shard") = py::none(),
        "The passes, LUT sizes, shader variant, estimated work and reuse of a bake, and why each effect is on: "
        "`skybake plan`'s text.");
  m.def("bake", &Bake, py::arg("style"), py::kw_only(), py::arg("out") = "out", py::arg("schedule") = nullptr,
        py::arg("size") = py::none(), py::arg("force") = false, py::arg("resume") = false,
        py::arg("progress") = py::none(), py::arg("vulkan_validation") = false, py::arg("arrays") = false,
        py::arg("device") = -1, py::arg("max_memory_mib") = 4096.0, py::arg("max_frame_seconds") = 3600.0,
        py::arg("frames") = py::none(), py::arg("shard") = py::none(), py::arg("engine") = py::none(),
        py::arg("usd") = false,
        "Bakes `style` into the folder `out`, as `skybake bake`: one frame, or a sequence with `schedule` (or the "
        "style file's inline schedule). size: --size (cube faces N, latlong 2N x N); force, resume, frames "
        "('FIRST:LAST'), shard ('I/N'), engine, usd, device, max_memory_mib, max_frame_seconds: the CLI's options. "
        "progress(event) receives each --progress-json event as a dict (start, stage, frame_start, frame_end with "
        "frame, of, seconds_per_frame, eta_s; end); returning False or raising cancels the bake (Cancel, or what "
        "it raised, is raised here), leaving the folder as a killed bake leaves it. vulkan_validation: the "
        "Khronos validation layer, any message raises VulkanError. arrays: read each frame's EXRs and IBL KTX2s "
        "back as numpy arrays (Frame.latlong, .faces, .cube, .engine, .ibl, .ibl_specular, .ibl_irradiance). The "
        "GIL is released while the bake runs. Returns a Bake.");
}

}  // namespace
}  // namespace skybake

PYBIND11_MODULE(skybake, m) {
  using namespace skybake;
  m.doc() =
      "skybake: physical, art-directable skies baked into HDR environment maps (OpenEXR cube faces, latlong, "
      "preview, glTF scene, manifest), with the command-line tool's own libraries.\n\n"
      "    style = skybake.load_style('configs/default.toml', ['sun.elevation_deg=10'])\n"
      "    result = skybake.bake(style, out='out', size=64, force=True, arrays=True)\n"
      "    result.frames[0].latlong   # numpy float32 (H, 2H, 3), the latlong EXR's texels\n\n"
      "Errors raise skybake.Error subclasses carrying the CLI's exit code (README \"Exit codes\") and the located "
      "errors; docs/python.md has the whole guide.";
  m.attr("__version__") = SKYBAKE_VERSION;
  m.attr("commit") = kBuildCommit;

  RegisterExceptions(m);
  RegisterTypes(m);
  RegisterFunctions(m);
}
