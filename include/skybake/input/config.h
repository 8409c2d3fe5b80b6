// Reading a sky style (style.h) from a TOML file. Every key is optional; a
// missing key keeps its default (see configs/default.toml, which lists them
// all with units).
//
// Errors are collected, not thrown one by one: a style with three mistakes
// reports all three, each with file:line:column and the key path.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "skybake/base/errors.h"
#include "skybake/input/style.h"

namespace skybake {

// A user error located in an input file.
struct ConfigError {
  std::string file;
  int line = 0;     // 1-based; 0 when unknown
  int column = 0;   // 1-based; 0 when unknown
  std::string key;  // dotted key path, e.g. "atmosphere.mie.g"
  std::string message;
  std::string Format() const;  // "file:line:col: key: message"
};

// A style or schedule that did not load, thrown where a caller cannot return
// its errors (the gallery's styles): the CLI prints every located error.
class ConfigFailure : public Error {
 public:
  ConfigFailure(const std::string& what, std::vector<ConfigError> e) : Error(what, kExitConfig), errors(std::move(e)) {}
  std::vector<ConfigError> errors;
};

struct ConfigResult {
  SkyStyle style;
  std::vector<ConfigError> errors;
  // Not errors: the style bakes, but likely not as meant (a quality preset
  // whose every key is given explicitly, so it changes nothing).
  std::vector<ConfigError> warnings;
  bool ok() const { return errors.empty(); }
};

// Reads a style from `path`, applies `overrides` ("key.path=toml_value", as
// given to --set) on top, validates, and resolves. Never throws for user errors.
ConfigResult LoadSkyStyle(const std::string& path, const std::vector<std::string>& overrides = {});

// The same from TOML text, with `name` used in error locations.
ConfigResult ParseSkyStyle(std::string_view toml_text, const std::string& name,
                           const std::vector<std::string>& overrides = {});

// The rule for every file name skybake writes into, or reads from, an output
// folder (output.basename, output.face_names, names read from manifests):
// 1 to 128 letters, digits, '_', '-', '.', '+', no "..", not starting with '.'.
bool IsPlainFileName(const std::string& name);

// `text` in single quotes for a message, with control characters, quotes
// and backslashes escaped (\n, \t, \x1b, \'), so nothing read from a file
// reaches the terminal raw.
std::string EscapedText(std::string_view text);

// Limits of a style or schedule file, checked before it is parsed: 16 MiB
// (a schedule of the documented 100,000 frames listed one by one is under
// 8 MiB) and dotted keys of at most 64 parts (skybake's have at most 5; the
// TOML parser recurses once per part and 50,000 overflow its stack).
inline constexpr size_t kMaxInputBytes = size_t(16) << 20;
inline constexpr size_t kMaxKeyParts = 64;

// Reads a style or schedule file (`what`: "style", "schedule") into `text`:
// a regular file (not a directory, device or pipe) of at most
// kMaxInputBytes; otherwise the error, at `(file)`.
std::optional<ConfigError> ReadInputFile(const std::string& path, const char* what, std::string& text);

// The error for a key of more than kMaxKeyParts parts in `text`, located.
std::optional<ConfigError> DeepKeyError(std::string_view text, const std::string& name);

// Whether the dotted key `key` ("a.b.c": 3 parts) has more than
// kMaxKeyParts parts; stops counting at the first part beyond, so a key of
// any length costs at most kMaxKeyParts + 1 dot searches. The one check of a
// `--set` key and of a quoted key in a schedule's `set`, `ramp` or
// `per_hour` ("a.b.c" = 1), both of which skybake splits at the dots.
bool KeyHasTooManyParts(std::string_view key);

}  // namespace skybake
