// A JSON array kept on disk while it grows: a long sequence's manifest and
// timings.json list every frame, and a bake that held those lists in memory
// (and built them whole for every progress manifest) grew with its frames.
// The elements go, as text, to an unnamed file in the output folder
// (O_TMPFILE: gone when the bake ends, even when it is killed), and a
// document is written around them in pieces, never whole in memory, with
// the bytes nlohmann's dump(2) gives for the same document.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "skybake/output/exr_io.h"

namespace skybake {

class JsonArraySpool {
 public:
  // The file is made in `dir` (when it exists and its file system has
  // O_TMPFILE), else in the system's temporary folder (tmpfile).
  explicit JsonArraySpool(std::string dir);
  ~JsonArraySpool();
  JsonArraySpool(const JsonArraySpool&) = delete;
  JsonArraySpool& operator=(const JsonArraySpool&) = delete;

  // Appends an element, given as its dump(2) text (at indent 0). Throws
  // OutputError when the file cannot be made or written (a full disk).
  void Add(const std::string& element_text);
  size_t size() const { return count_; }
  // The array as it appears as the value of a top-level key of a dump(2)
  // document: "[]", or "[\n    " elements at indent 4 "\n  ]".
  void WriteArray(const ByteSink& write) const;

 private:
  void Open();

  std::string dir_;
  int fd_ = -1;
  uint64_t bytes_ = 0;
  size_t count_ = 0;
};

// `text` (a dump(2) text) with `indent` after each of its newlines: the
// same value dump(2) writes at that depth of a document.
std::string IndentedJson(const std::string& text, const std::string& indent);
// `text` with the one occurrence of `marker` replaced by `replacement`.
// Throws std::logic_error when `marker` is not in it.
std::string SplicedJson(const std::string& text, const std::string& marker, const std::string& replacement);

// Writes `document` (a dump(2) text whose top-level `key`s of `arrays` are
// empty arrays, `"key": []`) atomically to `path`, each such array filled
// from its spool (WriteFileAtomically). Throws std::logic_error when a key
// is not there as an empty top-level array.
void WriteJsonWithSpools(const std::string& path, const std::string& document,
                         const std::vector<std::pair<std::string, const JsonArraySpool*>>& arrays);

}  // namespace skybake
