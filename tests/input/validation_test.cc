// The table of bad inputs: each style or schedule below is refused before
// any GPU work with exactly the message shown (file:line:column, key path,
// the problem and how to fix it) and the exit code for its kind. Each case
// runs the binary twice, as `skybake check` and as `skybake bake`, which must
// say the same and create nothing.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "test_support.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;

struct BadInput {
  const char* name;
  const char* style;     // style.toml; nullptr: no such file
  const char* schedule;  // schedule.toml given with --schedule; nullptr: none; "MISSING": given, absent
  const char* args;      // more arguments
  int exit_code;
  const char* message;  // the whole output
};

void PrintTo(const BadInput& c, std::ostream* os) { *os << c.name; }

// A dotted key of 50,000 parts (100 KB): the TOML parser's recursion
// overflowed the stack on it (SIGSEGV) before the input limits.
const std::string kDeepKey = [] {
  std::string text = "a";
  for (int i = 0; i < 50000; ++i) text += ".a";
  return text + " = 1\n";
}();

// A quoted key of 20,000 dotted parts (40 KB) where skybake splits keys at
// the dots: a `--set` key, a schedule frame's `set`, a ramp and a rate. Each
// part cost a copy of the whole key before the part limit applied to them
// (gigabytes and minutes at 50,000 parts); now refused before any split.
std::string ManyPartKey() {
  std::string key = "sun";
  for (int i = 0; i < 20000; ++i) key += ".a";
  return key;
}
const std::string kManyPartSet = "--set " + ManyPartKey() + "=1";
const std::string kManyPartFrameSet =
    "[schedule]\n[[schedule.frames]]\nelevation_deg = 10\nazimuth_deg = 135\nset = { \"" + ManyPartKey() + "\" = 1 }\n";
const std::string kManyPartRamp =
    "[schedule]\nsun = { elevation_deg = [0, 10], azimuth_deg = 135 }\n[schedule.ramp]\n\"" + ManyPartKey() +
    "\" = [0, 1]\n";
const std::string kManyPartRate =
    "[schedule]\ndate = 2013-05-27\nlatitude_deg = 42.4\nlongitude_deg = -76.5\nutc_offset_hours = -4.0\n"
    "times = [09:00:00, 10:00:00]\n"
    "[schedule.per_hour]\n\"" +
    ManyPartKey() + "\" = 1\n";

// clang-format off
const BadInput kBadInputs[] = {
    // Finite but extreme values per key family (1e308, denormals): refused by
    // check with the key's range (configs/default.toml), never an internal
    // error after the GPU work.
    {"AtmosphereRadiusHuge", "[atmosphere]\nbottom_radius_km = 1e308\n", nullptr, "", 3,
         "skybake: error: style.toml:2:20: atmosphere.bottom_radius_km: 1e+308 is out of range [1, 1000000]\n"
         "skybake: 1 error; nothing was baked\n"},
    {"AtmosphereScaleHeightDenormal", "[atmosphere.rayleigh]\nscale_height_km = 5e-324\n", nullptr, "", 3,
         "skybake: error: style.toml:2:19: atmosphere.rayleigh.scale_height_km: 5e-324 is out of range [0.001, 1000]\n"
         "skybake: 1 error; nothing was baked\n"},
    {"AtmosphereMieScatteringHuge", "[atmosphere.mie]\nscattering_per_km = [1e308, 0, 0]\nextinction_per_km = [1e308, 0, 0]\n", nullptr, "", 3,
         "skybake: error: style.toml:2:22: atmosphere.mie.scattering_per_km[0]: 1e+308 is out of range [0, 1000]\n"
         "skybake: error: style.toml:3:22: atmosphere.mie.extinction_per_km[0]: 1e+308 is out of range [0, 1000]\n"
         "skybake: 2 errors; nothing was baked\n"},
    {"SunAzimuthHuge", "[sun]\nazimuth_deg = 1e308\n", nullptr, "", 3,
         "skybake: error: style.toml:2:15: sun.azimuth_deg: 1e+308 is out of range [-100000, 100000]\n"
         "skybake: 1 error; nothing was baked\n"},
    {"SunRadiusDenormal", "[sun]\nangular_radius_rad = 1e-310\n", nullptr, "", 3,
         "skybake: error: style.toml:2:22: sun.angular_radius_rad: 1e-310 is out of range [1e-06, 0.5]\n"
         "skybake: 1 error; nothing was baked\n"},
    {"SunIrradianceHuge", "[sun]\nirradiance = 1e300\n", nullptr, "", 3,
         "skybake: error: style.toml:2:14: sun.irradiance: 1e+300 is out of range [0, 10000]\n"
         "skybake: 1 error; nothing was baked\n"},
    {"EffectsStrengthHuge", "[effects]\nsun_disc_strength = 1e308\n", nullptr, "", 3,
         "skybake: error: style.toml:2:21: effects.sun_disc_strength: 1e+308 is out of range [0, 1000]\n"
         "skybake: 1 error; nothing was baked\n"},
    {"SceneDomeRadiusHuge", "[gltf]\nradius_m = 1e308\n", nullptr, "", 3,
         "skybake: error: style.toml:2:12: gltf.radius_m: 1e+308 is out of range [0.001, 100000000]\n"
         "skybake: 1 error; nothing was baked\n"},
    {"SceneDomeRadiusDenormal", "[gltf]\nradius_m = 4.9e-324\n", nullptr, "", 3,
         "skybake: error: style.toml:2:12: gltf.radius_m: 5e-324 is out of range [0.001, 100000000]\n"
         "skybake: 1 error; nothing was baked\n"},
    {"PreviewEv100Huge", "[preview]\nev100 = -1e308\n", nullptr, "", 3,
         "skybake: error: style.toml:2:9: preview.ev100: -1e+308 is out of range [-50, 50]\n"
         "skybake: 1 error; nothing was baked\n"},
    {"SetExtremeValue", "", nullptr, "--set atmosphere.top_radius_km=1.7976931348623157e308", 3,
         "skybake: error: --set atmosphere.top_radius_km=1.7976931348623157e308:1:5: atmosphere.top_radius_km: 1.7976931348623157e+308 is out of range [1, 1000000]\n"
         "skybake: 1 error; nothing was baked\n"},
    {"SetKeyOfManyParts", "", nullptr, kManyPartSet.c_str(), 3,
         "skybake: error: --set: sun.(...): the key has more than 64 dotted parts (skybake's keys have at most 5, e.g. atmosphere.rayleigh.scale_height_km): give a style key\n"
         "skybake: 1 error; nothing was baked\n"},
    {"ScheduleFrameSetKeyOfManyParts", "", kManyPartFrameSet.c_str(), "", 3,
         "skybake: error: schedule.toml:5:40017: schedule.frames[0].set.sun.(...): a style key of more than 64 dotted parts: skybake's keys have at most 5, e.g. \"atmosphere.mie.g\"\n"
         "skybake: 1 error; nothing was baked\n"},
    {"ScheduleRampKeyOfManyParts", "", kManyPartRamp.c_str(), "", 3,
         "skybake: error: schedule.toml:4:40009: schedule.ramp.sun.(...): a style key of more than 64 dotted parts: skybake's keys have at most 5, e.g. \"atmosphere.mie.g\"\n"
         "skybake: 1 error; nothing was baked\n"},
    {"ScheduleRateKeyOfManyParts", "", kManyPartRate.c_str(), "", 3,
         "skybake: error: schedule.toml:8:40009: schedule.per_hour.sun.(...): a style key of more than 64 dotted parts: skybake's keys have at most 5, e.g. \"atmosphere.mie.g\"\n"
         "skybake: 1 error; nothing was baked\n"},
    {"UnknownKeyWithSuggestion", R"toml([sun]
elevaton_deg = 10
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:2:1: sun.elevaton_deg: unknown key 'elevaton_deg' (did you mean 'sun.elevation_deg'?)\n"
         "skybake: 1 error; nothing was baked\n"},
    {"UnknownTableWithSuggestion", R"toml([atmosphre]
bottom_radius_km = 6360.0
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:1:2: atmosphre: unknown key 'atmosphre' (did you mean 'atmosphere'?)\n"
         "skybake: 1 error; nothing was baked\n"},
    {"StringForNumber", R"toml([sun]
elevation_deg = "high"
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:2:17: sun.elevation_deg: expected a number, got a string\n"
         "skybake: 1 error; nothing was baked\n"},
    {"IntegerForBoolean", R"toml([effects]
sun_disc = 1
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:2:12: effects.sun_disc: expected true or false, got an integer\n"
         "skybake: 1 error; nothing was baked\n"},
    {"RealForInteger", R"toml([render]
cube_size = 16.5
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:2:13: render.cube_size: expected an integer, got a number\n"
         "skybake: 1 error; nothing was baked\n"},
    {"NegativeBottomRadius", R"toml([atmosphere]
bottom_radius_km = -6360.0
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:2:20: atmosphere.bottom_radius_km: -6360 is out of range [1, 1000000]\n"
         "skybake: 1 error; nothing was baked\n"},
    {"NegativeScaleHeight", R"toml([atmosphere.rayleigh]
scale_height_km = -8.0
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:2:19: atmosphere.rayleigh.scale_height_km: -8 is out of range [0.001, 1000]\n"
         "skybake: 1 error; nothing was baked\n"},
    {"TopRadiusNotAboveBottom", R"toml([atmosphere]
bottom_radius_km = 6360.0
top_radius_km = 6360.0
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:3:17: atmosphere.top_radius_km: top radius 6360 km must be above the bottom radius 6360 km\n"
         "skybake: 1 error; nothing was baked\n"},
    {"MieGOne", R"toml([atmosphere.mie]
g = 1.0
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:2:5: atmosphere.mie.g: 1 is out of range (-1, 1)\n"
         "skybake: 1 error; nothing was baked\n"},
    {"MieGMinusOne", R"toml([atmosphere.mie]
g = -1.0
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:2:5: atmosphere.mie.g: -1 is out of range (-1, 1)\n"
         "skybake: 1 error; nothing was baked\n"},
    {"MieGNan", R"toml([atmosphere.mie]
g = nan
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:2:5: atmosphere.mie.g: must be a finite number (got nan)\n"
         "skybake: 1 error; nothing was baked\n"},
    {"ElevationInfinite", R"toml([sun]
elevation_deg = inf
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:2:17: sun.elevation_deg: must be a finite number (got inf)\n"
         "skybake: 1 error; nothing was baked\n"},
    {"TripleWithNan", R"toml([atmosphere]
ground_albedo = [0.1, nan, 0.1]
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:2:23: atmosphere.ground_albedo[1]: must be a finite number (got nan)\n"
         "skybake: 1 error; nothing was baked\n"},
    {"TripleOfTwo", R"toml([sun]
irradiance = [1.0, 2.0]
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:2:14: sun.irradiance: expected a number or an array of 3 numbers [680 nm, 550 nm, 440 nm]\n"
         "skybake: 1 error; nothing was baked\n"},
    {"CubeSizeZero", R"toml([render]
cube_size = 0
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:2:13: render.cube_size: 0 is out of range [1, 8192]\n"
         "skybake: 1 error; nothing was baked\n"},
    {"CubeSizeAboveLimit", R"toml([render]
cube_size = 8193
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:2:13: render.cube_size: 8193 is out of range [1, 8192]\n"
         "skybake: 1 error; nothing was baked\n"},
    {"LatlongHeightNegative", R"toml([render]
latlong_height = -1
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:2:18: render.latlong_height: -1 is out of range [1, 8192]\n"
         "skybake: 1 error; nothing was baked\n"},
    {"UnknownPreset", R"toml([quality]
preset = "ultra"
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:2:10: quality.preset: 'ultra' is not one of 'draft', 'production' or 'reference'\n"
         "skybake: 1 error; nothing was baked\n"},
    {"UnknownIntegrator", R"toml([quality]
integrator = "euler"
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:2:14: quality.integrator: 'euler' is not one of 'analytic', 'midpoint', 'trapezoid' or 'simpson'\n"
         "skybake: 1 error; nothing was baked\n"},
    {"ViewStepsZero", R"toml([quality]
view_steps = 0
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:2:14: quality.view_steps: 0 is out of range [1, 4096]\n"
         "skybake: 1 error; nothing was baked\n"},
    {"BasenameParentTraversal", R"toml([output]
basename = "../evil"
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:2:12: output.basename: '../evil' is not a plain file name: use letters, digits, '_', '-', '.', '+', no '/' or '..', not starting with '.' or '-', not a name Windows reserves (CON, NUL, COM1, ...)\n"
         "skybake: 1 error; nothing was baked\n"},
    {"BasenameAbsolute", R"toml([output]
basename = "/tmp/evil"
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:2:12: output.basename: '/tmp/evil' is not a plain file name: use letters, digits, '_', '-', '.', '+', no '/' or '..', not starting with '.' or '-', not a name Windows reserves (CON, NUL, COM1, ...)\n"
         "skybake: 1 error; nothing was baked\n"},
    {"BasenameSubfolder", R"toml([output]
basename = "a/b"
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:2:12: output.basename: 'a/b' is not a plain file name: use letters, digits, '_', '-', '.', '+', no '/' or '..', not starting with '.' or '-', not a name Windows reserves (CON, NUL, COM1, ...)\n"
         "skybake: 1 error; nothing was baked\n"},
    {"BasenameHidden", R"toml([output]
basename = ".sky"
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:2:12: output.basename: '.sky' is not a plain file name: use letters, digits, '_', '-', '.', '+', no '/' or '..', not starting with '.' or '-', not a name Windows reserves (CON, NUL, COM1, ...)\n"
         "skybake: 1 error; nothing was baked\n"},
    {"FaceNameTraversal", R"toml([output]
face_names = ["px", "nx", "py", "ny", "pz", "../../nz"]
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:2:45: output.face_names[5]: expected a plain file name (letters, digits, '_', '-', '.', '+')\n"
         "skybake: 1 error; nothing was baked\n"},
    {"FaceNamesFive", R"toml([output]
face_names = ["px", "nx", "py", "ny", "pz"]
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:2:14: output.face_names: expected an array of 6 file names\n"
         "skybake: 1 error; nothing was baked\n"},
    {"FaceNamesRepeated", R"toml([output]
face_names = ["px", "px", "py", "ny", "pz", "nz"]
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:2:14: output.face_names[1]: 'px' is given twice: each face is its own file\n"
         "skybake: 1 error; nothing was baked\n"},
    {"FaceNameClashesWithCubeStrip", R"toml([output]
face_names = ["cube", "nx", "py", "ny", "pz", "nz"]
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:2:14: output.face_names[0]: 'cube' is the name of another output file: choose another face name\n"
         "skybake: 1 error; nothing was baked\n"},
    {"MieExtinctionBelowScattering", R"toml([atmosphere.mie]
scattering_per_km = 0.005
extinction_per_km = 0.004
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:3:21: atmosphere.mie.extinction_per_km: extinction 0.004 must be at least the scattering 0.005 (channel 0)\n"
         "skybake: 1 error; nothing was baked\n"},
    {"SyntaxErrorUnclosedTable", R"toml([sun
elevation_deg = 10
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:1:5: (syntax): Error while parsing table header: expected ']', saw '\\n'\n"
         "skybake: 1 error; nothing was baked\n"},
    {"DuplicateKey", R"toml([sun]
elevation_deg = 10
elevation_deg = 20
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:3:17: (syntax): Error while parsing key-value pair: cannot redefine existing integer 'elevation_deg'\n"
         "skybake: 1 error; nothing was baked\n"},
    {"AllErrorsAtOnce", R"toml([sun]
elevation_deg = 91
[atmosphere.mie]
g = 2
[render]
cube_size = 0
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:4:5: atmosphere.mie.g: 2 is out of range (-1, 1)\n"
         "skybake: error: style.toml:2:17: sun.elevation_deg: 91 is out of range [-90, 90]\n"
         "skybake: error: style.toml:6:13: render.cube_size: 0 is out of range [1, 8192]\n"
         "skybake: 3 errors; nothing was baked\n"},
    {"SetWithoutValue", R"toml()toml",
     nullptr, "--set render.cube_size", 3,
         "skybake: error: --set: render.cube_size: expected key.path=value, e.g. --set sun.elevation_deg=10\n"
         "skybake: 1 error; nothing was baked\n"},
    {"SetTraversal", R"toml()toml",
     nullptr, "--set output.basename=../../etc/sky", 3,
         "skybake: error: --set output.basename=../../etc/sky:1:5: output.basename: '../../etc/sky' is not a plain file name: use letters, digits, '_', '-', '.', '+', no '/' or '..', not starting with '.' or '-', not a name Windows reserves (CON, NUL, COM1, ...)\n"
         "skybake: 1 error; nothing was baked\n"},
    {"MissingStyleFile", nullptr,
     nullptr, "", 3,
         "skybake: error: style.toml: (file): cannot open the style file: check the path\n"
         "skybake: 1 error; nothing was baked\n"},
    {"ScheduleEmptyTimes", R"toml()toml",
     R"toml([schedule]
date = 2013-05-27
latitude_deg = 42.4
longitude_deg = -76.5
utc_offset_hours = -4.0
times = []
)toml", "", 3,
         "skybake: error: schedule.toml:6:9: schedule.times: the list is empty\n"
         "skybake: 1 error; nothing was baked\n"},
    {"ScheduleQuotedTime", R"toml()toml",
     R"toml([schedule]
date = 2013-05-27
latitude_deg = 42.4
longitude_deg = -76.5
utc_offset_hours = -4.0
times = ["09:30"]
)toml", "", 3,
         "skybake: error: schedule.toml:6:10: schedule.times[0]: expected a local time such as 09:30:00 (TOML time, no quotes)\n"
         "skybake: 1 error; nothing was baked\n"},
    {"ScheduleTimeOutOfRange", R"toml()toml",
     R"toml([schedule]
date = 2013-05-27
latitude_deg = 42.4
longitude_deg = -76.5
utc_offset_hours = -4.0
times = [25:00:00]
)toml", "", 3,
         "skybake: error: schedule.toml:6:12: (syntax): Error while parsing time: expected hour between 0 to 59 (inclusive), saw 25\n"
         "skybake: 1 error; nothing was baked\n"},
    {"ScheduleQuotedDate", R"toml()toml",
     R"toml([schedule]
date = "2013-05-27"
latitude_deg = 42.4
longitude_deg = -76.5
utc_offset_hours = -4.0
times = [09:30:00]
)toml", "", 3,
         "skybake: error: schedule.toml:2:8: schedule.date: expected a date such as 2013-05-27 (TOML date, no quotes)\n"
         "skybake: 1 error; nothing was baked\n"},
    {"ScheduleNoFrames", R"toml()toml",
     R"toml([schedule]
first_frame = 1
)toml", "", 3,
         "skybake: error: schedule.toml:1:1: schedule: no frames: give `times`, `sun` or [[schedule.frames]]\n"
         "skybake: 1 error; nothing was baked\n"},
    {"ScheduleEmptyElevationList", R"toml()toml",
     R"toml([schedule]
sun = { elevation_deg = [], azimuth_deg = 135 }
)toml", "", 3,
         "skybake: error: schedule.toml:2:25: schedule.sun.elevation_deg: the list is empty\n"
         "skybake: 1 error; nothing was baked\n"},
    {"ScheduleZeroStep", R"toml()toml",
     R"toml([schedule]
sun = { elevation_deg = { start = 0, end = 10, step = 0 }, azimuth_deg = 135 }
)toml", "", 3,
         "skybake: error: schedule.toml:2:25: schedule.sun.elevation_deg: step 0 cannot go from 0 to 10: use a non-zero step with the sign of end - start\n"
         "skybake: 1 error; nothing was baked\n"},
    {"ScheduleUnknownKey", R"toml()toml",
     R"toml([schedule]
tiems = [09:30:00]
sun = { elevation_deg = 10, azimuth_deg = 135 }
)toml", "", 3,
         "skybake: error: schedule.toml:2:9: schedule.tiems: unknown key 'tiems' (did you mean 'times'?) (expected 'first_frame', 'date', 'latitude_deg', 'longitude_deg', 'utc_offset_hours', 'times', 'sun', 'frames', 'ramp', 'per_hour')\n"
         "skybake: 1 error; nothing was baked\n"},
    {"ScheduleLatitudeOutOfRange", R"toml()toml",
     R"toml([schedule]
date = 2013-05-27
latitude_deg = 95.0
longitude_deg = -76.5
utc_offset_hours = -4.0
times = [09:30:00]
)toml", "", 3,
         "skybake: error: schedule.toml:3:16: schedule.latitude_deg: latitude must be within [-90, 90]\n"
         "skybake: 1 error; nothing was baked\n"},
    {"ScheduleFrameSetsTraversalBasename", R"toml()toml",
     R"toml([schedule]
[[schedule.frames]]
elevation_deg = 10
azimuth_deg = 135
set = { "output.basename" = "../../evil" }
)toml", "", 3,
         "skybake: error: schedule.toml:5:29: output.basename: frame 1: '../../evil' is not a plain file name: use letters, digits, '_', '-', '.', '+', no '/' or '..', not starting with '.' or '-', not a name Windows reserves (CON, NUL, COM1, ...)\n"
         "skybake: 1 error; nothing was baked\n"},
    {"ScheduleRampPushesGOutOfRange", R"toml()toml",
     R"toml([schedule]
sun = { elevation_deg = [0, 10], azimuth_deg = 135 }
[schedule.ramp]
"atmosphere.mie.g" = [0.8, 1.2]
)toml", "", 3,
         "skybake: error: schedule.toml:4:22: atmosphere.mie.g: frame 2: 1.2 is out of range (-1, 1)\n"
         "skybake: 1 error; nothing was baked\n"},
    {"ScheduleMissingFile", R"toml()toml",
     "MISSING", "", 3,
         "skybake: error: schedule.toml: (file): cannot open the schedule file: check the path\n"
         "skybake: 1 error; nothing was baked\n"},
    {"ScheduleRampKeyWithEqualsSign", R"toml()toml",
     R"toml([schedule]
sun = { elevation_deg = [0, 10], azimuth_deg = 135 }
[schedule.ramp]
"atmosphere.mie.g=0.1" = [0.7, 0.8]
)toml", "", 3,
         "skybake: error: schedule.toml:4:26: schedule.ramp.atmosphere.mie.g=0.1: 'atmosphere.mie.g=0.1' is not a style key: use a dotted key such as \"atmosphere.mie.g\"\n"
         "skybake: 1 error; nothing was baked\n"},
    {"ScheduleFrameSetKeyWithSpace", R"toml()toml",
     R"toml([schedule]
[[schedule.frames]]
elevation_deg = 10
azimuth_deg = 135
set = { "sun.elevation_deg " = 5 }
)toml", "", 3,
         "skybake: error: schedule.toml:5:32: schedule.frames[0].set.sun.elevation_deg : 'sun.elevation_deg ' is not a style key: use a dotted key such as \"atmosphere.mie.g\"\n"
         "skybake: 1 error; nothing was baked\n"},
    {"DeepDottedKey", kDeepKey.c_str(), nullptr, "", 3,
         "skybake: error: style.toml:1:128: (syntax): a dotted key or table name of more than 64 parts: skybake's keys have at most 5, e.g. atmosphere.rayleigh.scale_height_km\n"
         "skybake: 1 error; nothing was baked\n"},
    {"StyleIsADirectory", "DIR", nullptr, "", 3,
         "skybake: error: style.toml: (file): is a directory: give a style TOML file\n"
         "skybake: 1 error; nothing was baked\n"},
    {"StyleIsADevice", "DEVZERO", nullptr, "", 3,
         "skybake: error: style.toml: (file): is not a regular file (a device, a pipe or a socket): give a style TOML file\n"
         "skybake: 1 error; nothing was baked\n"},
    {"ScheduleIsADirectory", "", "DIR", "", 3,
         "skybake: error: schedule.toml: (file): is a directory: give a schedule TOML file\n"
         "skybake: 1 error; nothing was baked\n"},
    {"SetReplacesATableByANumber", "", nullptr, "--set sun=1", 3,
         "skybake: error: --set sun=1:1:5: sun: expected a table ([sun] with its keys), got an integer\n"
         "skybake: 1 error; nothing was baked\n"},
    {"SetUnknownKeyIsLocatedAtTheSet", "", nullptr, "--set render.cube_sizes=64", 3,
         "skybake: error: --set render.cube_sizes=64:1:8: render.cube_sizes: unknown key 'cube_sizes' (did you mean 'render.cube_size'?)\n"
         "skybake: 1 error; nothing was baked\n"},
    {"SetUnknownTableIsLocatedAtTheSet", "", nullptr, "--set nosuch.key=1", 3,
         "skybake: error: --set nosuch.key=1:1:1: nosuch: unknown key 'nosuch'\n"
         "skybake: 1 error; nothing was baked\n"},
    {"SetReplacesATableByAnArray", "", nullptr, "--set render=[]", 3,
         "skybake: error: --set render=[]:1:5: render: expected a table ([render] with its keys), got an array\n"
         "skybake: 1 error; nothing was baked\n"},
    {"ScheduleFrameSetReplacesATable", "", R"toml([schedule]
[[schedule.frames]]
elevation_deg = 10
azimuth_deg = 135
set = { "sun" = 1 }
)toml", "", 3,
         "skybake: error: schedule.toml:5:17: sun: frame 1: expected a table ([sun] with its keys), got an integer\n"
         "skybake: 1 error; nothing was baked\n"},
    {"ScheduleRampReplacesATable", "", R"toml([schedule]
sun = { elevation_deg = [0, 10], azimuth_deg = 135 }
[schedule.ramp]
"atmosphere" = [0, 1]
)toml", "", 3,
         "skybake: error: schedule.toml:4:16: atmosphere: frame 1: expected a table ([atmosphere] with its keys), got an integer\n"
         "skybake: 1 error; nothing was baked\n"},
    {"ScheduleClockTimesOutOfOrder", "", R"toml([schedule]
date = 2013-05-27
latitude_deg = 42.4
longitude_deg = -76.5
utc_offset_hours = -4.0
times = [12:00:00, 09:00:00, 12:00:00]
)toml", "", 3,
         "skybake: error: schedule.toml:6:9: schedule.times: frame 2 (2013-05-27T09:00:00-04:00) is not after frame 1 (2013-05-27T12:00:00-04:00): give clock times in increasing order, each once\n"
         "skybake: 1 error; nothing was baked\n"},
    {"ScheduleFrameTimesRepeat", "", R"toml([schedule]
date = 2013-05-27
latitude_deg = 42.4
longitude_deg = -76.5
utc_offset_hours = -4.0
[[schedule.frames]]
time = 09:00:00
[[schedule.frames]]
time = 09:00:00
)toml", "", 3,
         "skybake: error: schedule.toml:6:1: schedule.frames: frame 2 (2013-05-27T09:00:00-04:00) is not after frame 1 (2013-05-27T09:00:00-04:00): give clock times in increasing order, each once\n"
         "skybake: 1 error; nothing was baked\n"},
    {"SetValueWithALineBreak", "", nullptr, "--set $'sun.elevation_deg=10\\nsun.azimuth_deg=5'", 3,
         "skybake: error: --set: sun.elevation_deg: the value has a line break, and what follows it would be ignored: give one value per --set\n"
         "skybake: 1 error; nothing was baked\n"},
    {"SetScheduleKey", "", nullptr, "--set schedule.first_frame=5", 3,
         "skybake: error: --set: schedule.first_frame: a schedule is not changed with --set (it would be ignored): edit the schedule file, or use its [schedule.ramp] or a frame's set\n"
         "skybake: 1 error; nothing was baked\n"},
    {"SetEmptyKeyPart", "", nullptr, "--set sun..elevation_deg=10", 3,
         "skybake: error: --set: sun..elevation_deg: empty part in the key path (two dots, or a leading dot): e.g. --set sun.elevation_deg=10\n"
         "skybake: 1 error; nothing was baked\n"},
    {"BasenameLeadingDash", R"toml([output]
basename = "-rf"
)toml", nullptr, "", 3,
         "skybake: error: style.toml:2:12: output.basename: '-rf' is not a plain file name: use letters, digits, '_', '-', '.', '+', no '/' or '..', not starting with '.' or '-', not a name Windows reserves (CON, NUL, COM1, ...)\n"
         "skybake: 1 error; nothing was baked\n"},
    {"BasenameWindowsReserved", R"toml([output]
basename = "nul"
)toml", nullptr, "", 3,
         "skybake: error: style.toml:2:12: output.basename: 'nul' is not a plain file name: use letters, digits, '_', '-', '.', '+', no '/' or '..', not starting with '.' or '-', not a name Windows reserves (CON, NUL, COM1, ...)\n"
         "skybake: 1 error; nothing was baked\n"},
    {"BasenameTooLong", R"toml([output]
basename = "aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa"
)toml", nullptr, "", 3,
         "skybake: error: style.toml:2:12: output.basename: a name of 153 characters is longer than the 128 a plain file name may have\n"
         "skybake: 1 error; nothing was baked\n"},
    {"FaceNameLeadingDash", R"toml([output]
face_names = ["-px", "nx", "py", "ny", "pz", "nz"]
)toml", nullptr, "", 3,
         "skybake: error: style.toml:2:15: output.face_names[0]: expected a plain file name (letters, digits, '_', '-', '.', '+')\n"
         "skybake: 1 error; nothing was baked\n"},
    {"FaceNameWindowsReserved", R"toml([output]
face_names = ["px", "nx", "py", "ny", "pz", "con"]
)toml", nullptr, "", 3,
         "skybake: error: style.toml:2:45: output.face_names[5]: expected a plain file name (letters, digits, '_', '-', '.', '+')\n"
         "skybake: 1 error; nothing was baked\n"},
    {"ControlCharacterInAValueIsEscaped", "[output]\nbasename = \"a\\u001b[2J\"\n", nullptr, "", 3,
         "skybake: error: style.toml:2:12: output.basename: 'a\\x1b[2J' is not a plain file name: use letters, digits, '_', '-', '.', '+', no '/' or '..', not starting with '.' or '-', not a name Windows reserves (CON, NUL, COM1, ...)\n"
         "skybake: 1 error; nothing was baked\n"},
    {"FaceNamesEqualUpToCase", R"toml([output]
face_names = ["px", "PX", "py", "ny", "pz", "nz"]
)toml", nullptr, "", 3,
         "skybake: error: style.toml:2:14: output.face_names[1]: 'px' and 'PX' differ only in case, one file on a case-insensitive file system: each face is its own file\n"
         "skybake: 1 error; nothing was baked\n"},
    {"ControlCharacterInAKeyIsEscaped", "\"sun\\u001b[2J\" = 1\n", nullptr, "", 3,
         "skybake: error: style.toml:1:1: sun\\x1b[2J: unknown key 'sun\\x1b[2J'\n"
         "skybake: 1 error; nothing was baked\n"},
    {"SetNumberOutOfRange", "", nullptr, "--set sun.elevation_deg=1e400", 3,
         "skybake: error: --set: sun.elevation_deg: 1e400 is not a number a double holds (at most about 1.8e308 in size): give a smaller value\n"
         "skybake: 1 error; nothing was baked\n"},
    {"LargeIntegerIsANumber", R"toml([sun]
elevation_deg = 9007199254740993
)toml", nullptr, "", 3,
         "skybake: error: style.toml:2:17: sun.elevation_deg: 9007199254740992 is out of range [-90, 90]\n"
         "skybake: 1 error; nothing was baked\n"},
    {"EmptyKey", R"toml("" = 0.007
)toml",
     nullptr, "", 3,
         "skybake: error: style.toml:1:1: \"\": unknown key ''\n"
         "skybake: 1 error; nothing was baked\n"},
};
// clang-format on

class BadInputs : public ::testing::TestWithParam<BadInput> {};

TEST_P(BadInputs, RefusedWithTheExactMessageAndExitCode) {
  const BadInput& c = GetParam();
  const std::string dir = testing::FreshTempDir(std::string("bad_") + c.name);
  // "DIR": a directory under the name; "DEVZERO": a link to /dev/zero.
  auto place = [&](const char* text, const std::string& path) {
    if (std::string(text) == "DIR") fs::create_directory(path);
    else if (std::string(text) == "DEVZERO") fs::create_symlink("/dev/zero", path);
    else if (std::string(text) != "MISSING") std::ofstream(path) << text;
  };
  if (c.style) place(c.style, dir + "/style.toml");
  std::string args = "style.toml";
  if (c.schedule) {
    place(c.schedule, dir + "/schedule.toml");
    args += " --schedule schedule.toml";
  }
  args += std::string(" ") + c.args;
  const std::string cd = "cd '" + dir + "' &&";

  testing::CommandRun check = testing::RunSkybake("check " + args, cd);
  EXPECT_EQ(check.exit_code, c.exit_code) << check.output;
  EXPECT_EQ(check.output, c.message);

  testing::CommandRun bake = testing::RunSkybake("bake " + args + " -q --out out", cd);
  EXPECT_EQ(bake.exit_code, c.exit_code) << bake.output;
  EXPECT_EQ(bake.output, c.message);
  EXPECT_FALSE(fs::exists(dir + "/out")) << "nothing is created";
  // Nothing escaped the folder either (the traversal cases aim at ../evil).
  EXPECT_FALSE(fs::exists(fs::path(dir).parent_path() / "evil_px.exr"));
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Table, BadInputs, ::testing::ValuesIn(kBadInputs),
                         [](const ::testing::TestParamInfo<BadInput>& info) { return std::string(info.param.name); });

TEST(BadInputs, TableHasAtLeastThirtyCases) { EXPECT_GE(std::size(kBadInputs), 30u); }

// Usage errors (exit 2) come from the command line itself.
TEST(BadInputs, SizeOutsideTheCommandLineRangeIsAUsageError) {
  const std::string style = testing::SourceDir() + "/configs/default.toml";
  for (const char* size : {"0", "8193", "-4"}) {
    testing::CommandRun run = testing::RunSkybake("bake '" + style + "' --size " + size + " --out /nonexistent/x");
    EXPECT_EQ(run.exit_code, 2) << size << ": " << run.output;
    EXPECT_NE(run.output.find("--size"), std::string::npos) << run.output;
  }
}

// A budget of nan compared false with every estimate and switched the
// check off; inf, 0 and negatives are no budget either.
// A name with an escape sequence (a style file named to clear the screen)
// is printed escaped, in what succeeds as in errors.
TEST(BadInputs, EscapeSequencesInNamesAreNotPrintedRaw) {
  const std::string dir = testing::FreshTempDir("escaped_name");
  const std::string name = "sky\x1b[2J\x07.toml";
  std::ofstream(dir + "/" + name) << "[sun]\nelevation_deg = 10\n";
  testing::CommandRun ok = testing::RunSkybake("check '" + name + "'", "cd '" + dir + "' &&");
  EXPECT_EQ(ok.exit_code, 0) << ok.output;
  EXPECT_NE(ok.output.find("\nsky\\x1b[2J\\x07.toml: ok\n"), std::string::npos) << ok.output;
  EXPECT_EQ(ok.output.find('\x1b'), std::string::npos) << ok.output;
  testing::CommandRun bad =
      testing::RunSkybake("check '" + name + "' --set sun.elevation_deg=100", "cd '" + dir + "' &&");
  EXPECT_EQ(bad.exit_code, 3) << bad.output;
  EXPECT_EQ(bad.output.find('\x1b'), std::string::npos) << bad.output;
  EXPECT_EQ(bad.output.find('\x07'), std::string::npos) << bad.output;
  fs::remove_all(dir);
}

TEST(BadInputs, BudgetsAreFiniteNumbersAboveZero) {
  const std::string style = testing::SourceDir() + "/configs/default.toml";
  for (const char* option : {"--max-memory-mib", "--max-frame-seconds"}) {
    for (const char* value : {"nan", "inf", "-1", "0"}) {
      testing::CommandRun run =
          testing::RunSkybake("bake '" + style + "' " + option + " " + value + " --out /nonexistent/x");
      EXPECT_EQ(run.exit_code, 2) << option << " " << value << ": " << run.output;
      EXPECT_EQ(run.output.rfind(std::string(option) + ": expected a finite number above 0, got " + value, 0), 0u)
          << run.output;
    }
  }
}

// A schedule ramp on a key given with --set silently won: now a warning at
// the ramp's place (the bake goes on with the ramp's values).
TEST(BadInputs, ScheduleRampOverASetKeyIsWarnedOf) {
  const std::string dir = testing::FreshTempDir("rampset");
  std::ofstream(dir + "/s.toml") << "[schedule]\nsun = { elevation_deg = [0, 10], azimuth_deg = 135 }\n"
                                    "[schedule.ramp]\n\"atmosphere.mie.g\" = [0.7, 0.8]\n";
  testing::CommandRun run = testing::RunSkybake("check '" + testing::SourceDir() +
                                                    "/configs/default.toml' --schedule "
                                                    "s.toml --set atmosphere.mie.g=0.5",
                                                "cd '" + dir + "' &&");
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("skybake: warning: s.toml:4:22: atmosphere.mie.g: the schedule sets this key per frame, "
                            "so --set atmosphere.mie.g=0.5 has no effect on it\n"),
            std::string::npos)
      << run.output;
  fs::remove_all(dir);
}

// An estimate just above the budget is shown with the digits that tell
// them apart ("needs 3 MiB ... above the budget of 3 MiB" before).
TEST(BadInputs, BudgetMessageTellsCloseNumbersApart) {
  const std::string style = testing::SourceDir() + "/configs/default.toml";
  testing::CommandRun run = testing::RunSkybake("check '" + style +
                                                "' --set render.cube_size=64 --set "
                                                "render.latlong_height=64 --max-memory-mib 3");
  EXPECT_EQ(run.exit_code, 7) << run.output;
  EXPECT_NE(run.output.find("an estimated 3.031 MiB of memory per frame (cube 64, latlong 128x64), above the budget "
                            "of 3.000 MiB"),
            std::string::npos)
      << run.output;
}

// --dry-run plans the part of the sequence that --frames / --shard select.
TEST(BadInputs, DryRunPlansOnlyTheSelectedFrames) {
  const std::string dir = testing::FreshTempDir("dryrun");
  std::ofstream(dir + "/s.toml") << "[schedule]\nsun = { elevation_deg = [1, 2, 3, 4], azimuth_deg = 135 }\n";
  const std::string bake = "bake '" + testing::SourceDir() + "/configs/default.toml' --schedule '" + dir +
                           "/s.toml' --dry-run --out '" + dir + "/out'";
  testing::CommandRun all = testing::RunSkybake(bake);
  testing::CommandRun part = testing::RunSkybake(bake + " --frames 2:3");
  ASSERT_EQ(all.exit_code, 0) << all.output;
  ASSERT_EQ(part.exit_code, 0) << part.output;
  EXPECT_NE(all.output.find("4 frames"), std::string::npos) << all.output;
  EXPECT_NE(part.output.find("2 frames"), std::string::npos) << part.output;
  EXPECT_NE(part.output.find("(frames 2 to 3 of 1 to 4): 2 frames"), std::string::npos) << part.output;
  EXPECT_FALSE(fs::exists(dir + "/out"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace skybake
