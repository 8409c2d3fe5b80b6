// Helpers shared by the tests: one Vulkan context per test binary, always
// with the Khronos validation layer, and never skipped: lavapipe is always
// installable, so a missing device fails with the command that fixes it.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "skybake/gpu/vulkan_context.h"

namespace skybake::testing {

// The context, created on first use. Fails the test (fatal) when Vulkan or
// the validation layer is missing.
VulkanContext& Vulkan();

// Asserts that the validation layer has said nothing since the last call.
void ExpectNoValidationMessages();

// Relative step of a sky-view LUT texel as stored: PackSkyViewTexel
// (shaders/common.glsl) keeps 12 mantissa bits, rounded, so two renders whose
// LUTs differ by float rounding alone may store a texel one step, 2^-12,
// apart. Comparisons of two GPU renders that read the sky-view LUT allow it.
inline constexpr double kSkyViewLutStorageStep = 1.0 / 4096.0;

// Path of the repository's configs/ and of shared/ beside the checkout.
std::string SourceDir();
std::string SharedDir();

// The skybake binary run through a shell: `shell_prefix` goes before it
// (environment, `cd dir &&`, `ulimit -f N;`), `args` after it.
struct CommandRun {
  int exit_code = -1;  // -1 when killed by a signal
  std::string output;  // stdout and stderr together
};
CommandRun RunSkybake(const std::string& args, const std::string& shell_prefix = "");

// Any shell command: its exit status and its stdout and stderr together.
std::pair<int, std::string> RunCommand(const std::string& command);

// A page of tests/viewer opened in headless Chromium by run_page.mjs, with
// `dir` served and its screenshot written to `png`: the page's report line
// ({"chromium_exit", "report", "requests", ...}), or null after adding a test
// failure (the command failed or printed no report).
nlohmann::json RunViewerPage(const std::string& page, const std::string& dir, const std::string& png,
                             const std::string& query);

// A new, empty folder under the temporary directory, unique to this process.
std::string FreshTempDir(const std::string& name);

// Writes `text` to DIR/NAME and returns that path (a test failure naming it
// when it cannot be written).
std::string WriteFile(const std::string& dir, const std::string& name, const std::string& text);

// A file's bytes ("" when it cannot be read), and the names in a folder
// (none when it does not exist).
std::string ReadFileBytes(const std::string& path);
std::set<std::string> FileNames(const std::string& dir);

// A sequence bake from the command line: `skybake bake STYLE --schedule
// SCHEDULE --size 16 -q --vulkan-validation --out OUT EXTRA`, expected to
// exit 0 (a test failure with its output when not).
void BakeSequence16(const std::string& style, const std::string& schedule, const std::string& out,
                    const std::string& extra = "");

// The sequence baked whole into ROOT/whole and in two shards into
// ROOT/SHARDS (BakeSequence16), then `merge-manifest ROOT/SHARDS`; returns
// merge-manifest's exit code.
int BakeWholeAndTwoShards(const std::string& style, const std::string& schedule, const std::string& root,
                          const std::string& shards);

// Expects `dir/NAME` to hold the bytes of `reference_dir/NAME` for each of
// `names` (a test failure naming the file when not).
void ExpectSameBytes(const std::string& dir, const std::string& reference_dir, const std::set<std::string>& names);

// An image file (PNG: 8 bits, else float; by its extension) of w x h pixels
// and `channels` channels, value(x, y, channel) each, through OpenImageIO.
void WriteTestImage(const std::string& path, int w, int h, int channels,
                    const std::function<float(int, int, int)>& value);

// The first three channels of an image file through OpenImageIO, rows from
// the top, converted to the vector's type (float, or 8 bits), and its size;
// with `string_attributes`, its string attributes too. False, after a test
// failure naming the file, when the file cannot be opened (then nothing is
// set).
bool ReadRgb(const std::string& path, int& width, int& height, std::vector<float>& rgb,
             std::map<std::string, std::string>* string_attributes = nullptr);
bool ReadRgb(const std::string& path, int& width, int& height, std::vector<unsigned char>& rgb);

// The OpenGL 4.6 / Vulkan specifications' "Cube Map Face Selection": the
// major axis of `r` picks the face (0..5: +X -X +Y -Y +Z -Z), then (sc, tc)
// from the table give s, t in [0, 1]. Written from the table,
// independently of the mapping code the tests check.
struct CubeFaceHit {
  int face;
  double s, t;
};
CubeFaceHit SpecCubeFace(const glm::dvec3& r);

}  // namespace skybake::testing
