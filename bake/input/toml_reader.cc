#include "toml_reader.h"

#include <algorithm>

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
