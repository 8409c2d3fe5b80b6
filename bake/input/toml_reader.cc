#include "toml_reader.h"

#include <algorithm>
#include <cmath>

namespace skybake {

ConfigError LocatedError(const std::string& file, const toml::source_region& where, const std::string& key,
                         const std::string& message) {
  ConfigError e;
  e.file = file;
  if (where.begin) {
    e.line = int(where.begin.line);
    e.column = int(where.begin.column);
    if (where.path) e.file = *where.path;
  }
  e.key = key.empty() ? "\"\"" : key;  // a TOML key may be the empty string
  e.message = message;
  return e;
}

std::optional<toml::table> ParseTomlText(std::string_view text, const std::string& name,
                                         std::vector<ConfigError>& errors) {
  if (std::optional<ConfigError> deep = DeepKeyError(text, name)) {
    errors.push_back(*deep);
    return std::nullopt;
  }
  try {
    return toml::parse(text, name);
  } catch (const toml::parse_error& e) {
    ConfigError error;
    error.file = name;
    error.line = int(e.source().begin.line);
    error.column = int(e.source().begin.column);
    error.key = "(syntax)";
    error.message = std::string(e.description());
    errors.push_back(error);
    return std::nullopt;
  }
}

std::string TomlTypeName(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::string:
      return "a string";
    case toml::node_type::integer:
      return "an integer";
    case toml::node_type::floating_point:
      return "a number";
    case toml::node_type::boolean:
      return "a boolean";
    case toml::node_type::array:
      return "an array";
    case toml::node_type::table:
      return "a table";
    default:
      return "a date or time";
  }
}

void TomlReader::Error(const toml::node* node, const std::string& key, const std::string& message) {
  ErrorAt(node ? node->source() : toml::source_region{}, key, message);
}

void TomlReader::ErrorAt(const toml::source_region& where, const std::string& key, const std::string& message) {
  errors_.push_back(LocatedError(file_, where, key, message));
}

std::optional<double> TomlReader::Number(const toml::node& node, const std::string& key, const Range& range) {
  std::optional<double> value = node.value<double>();  // accepts integers too
  // An integer beyond 2^53 is still a number (toml++ refuses the inexact
  // conversion): the nearest double.
  if (!value && node.is_integer()) value = double(node.as_integer()->get());
  if (!value || node.is_boolean()) {
    Error(&node, key, fmt::format("expected a number, got {}", TomlTypeName(node)));
    return std::nullopt;
  }
  if (!std::isfinite(*value)) {
    Error(&node, key, fmt::format("must be a finite number (got {})", *value));
    return std::nullopt;
  }
  if (!range.Contains(*value)) {
    Error(&node, key, fmt::format("{} is out of range {}", *value, range.Describe()));
    return std::nullopt;
  }
  return value;
}

std::optional<std::vector<double>> TomlReader::NumberOrTriple(const toml::node& node, const std::string& key,
                                                              const Range& range) {
  if (node.is_number()) {
    std::optional<double> v = Number(node, key, range);
    if (!v) return std::nullopt;
    return std::vector<double>{*v};
  }
  const toml::array* array = node.as_array();
  if (!array || array->size() != 3) {
    Error(&node, key, "expected a number or an array of 3 numbers [680 nm, 550 nm, 440 nm]");
    return std::nullopt;
  }
  std::vector<double> values;
  for (size_t i = 0; i < 3; ++i) {
    std::optional<double> v = Number(*array->get(i), fmt::format("{}[{}]", key, i), range);
    if (!v) return std::nullopt;
    values.push_back(*v);
  }
  return values;
}

int EditDistance(std::string_view a, std::string_view b) {
  std::vector<int> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = int(j);
  for (size_t i = 1; i <= a.size(); ++i) {
    int diagonal = row[0];
    row[0] = int(i);
    for (size_t j = 1; j <= b.size(); ++j) {
      int up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1])});
      diagonal = up;
    }
  }
  return row[b.size()];
}

}  // namespace skybake
