// What every TOML reader of skybake shares (styles, config.cc; schedules,
// schedule.cc), so that both report a mistake alike: errors located at
// file:line:col with the dotted key, and an unknown key answered with the
// nearest known one ("did you mean"). Private to the input layer.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <toml++/toml.h>

#include "skybake/input/config.h"

namespace skybake {

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
