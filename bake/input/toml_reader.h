// What every TOML reader of skybake shares (styles, config.cc; schedules,
// schedule.cc), so that both report a mistake alike: errors located at
// file:line:col with the dotted key, and an unknown key answered with the
// nearest known one ("did you mean"). Private to the input layer.
#pragma once

#include <cmath>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "skybake/input/config.h"

namespace skybake {

// The documented range of a number key: [min, max], either end open.
struct Range {
  double min;
  double max;
  bool min_open;
  bool max_open;
  bool Contains(double v) const {
    if (min_open ? !(v > min) : !(v >= min)) return false;
    if (max_open ? !(v < max) : !(v <= max)) return false;
    return true;
  }
  std::string Describe() const {
    return fmt::format("{}{}, {}{}", min_open ? '(' : '[', min, max, max_open ? ')' : ']');
  }
};
constexpr Range kAnyFinite{-HUGE_VAL, HUGE_VAL, true, true};

// "a string", "an integer", "a number", ...: what a value is, for messages.
std::string TomlTypeName(const toml::node& node);

// The located errors of one TOML file and the value readers both readers
// share, so that a number or an RGB triple is refused alike in a style and
// in a schedule.
class TomlReader {
 public:
  TomlReader(std::string file, std::vector<ConfigError>& errors) : file_(std::move(file)), errors_(errors) {}

  // `message` about `key` at `node` (at no place when null).
  void Error(const toml::node* node, const std::string& key, const std::string& message);
  void ErrorAt(const toml::source_region& where, const std::string& key, const std::string& message);

  // A finite number within `range` (an integer too; one beyond 2^53 as the
  // nearest double), or nothing with the error reported: "expected a number,
  // got a string", "must be a finite number (got nan)", "... is out of range".
  std::optional<double> Number(const toml::node& node, const std::string& key, const Range& range = kAnyFinite);

  // A number (one value) or an RGB triple [680 nm, 550 nm, 440 nm] (three),
  // each a Number within `range` (an item's error names it as key[i]); or
  // nothing with the error reported.
  std::optional<std::vector<double>> NumberOrTriple(const toml::node& node, const std::string& key,
                                                    const Range& range = kAnyFinite);

  const std::string& file() const { return file_; }

 private:
  std::string file_;
  std::vector<ConfigError>& errors_;
};

// The error `message` about `key` at `where` in `file` (the region's own
// path when it has one; line and column 0 when unknown; the empty TOML key
// shown as "").
ConfigError LocatedError(const std::string& file, const toml::source_region& where, const std::string& key,
                         const std::string& message);

// `text` (read from `name`) parsed, or nothing with the error appended to
// `errors`: a key of too many parts (DeepKeyError), or a TOML syntax error at
// its line and column (key "(syntax)").
std::optional<toml::table> ParseTomlText(std::string_view text, const std::string& name,
                                         std::vector<ConfigError>& errors);

// Levenshtein distance: insertions, deletions and substitutions.
int EditDistance(std::string_view a, std::string_view b);

// " (did you mean 'x'?)" for the candidate nearest to `key`, when it is a
// near miss (at most a third of the key's length or 2 edits away, the first
// of equally near ones), else "".
template <class Names>
std::string DidYouMean(std::string_view key, const Names& candidates) {
  std::string best;
  int best_distance = 1 << 30;
  for (const auto& candidate : candidates) {
    const int d = EditDistance(key, candidate);
    if (d < best_distance) {
      best_distance = d;
      best = std::string(candidate);
    }
  }
  if (best.empty() || best_distance > std::max<int>(2, int(key.size()) / 3)) return "";
  return " (did you mean '" + best + "'?)";
}

}  // namespace skybake
