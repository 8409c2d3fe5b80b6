// The JSON array spool (output/json_spool.h): a document written around
// arrays kept on disk has the bytes nlohmann's dump(2) gives the whole
// document, and leaves no file behind; a streamed atomic write that fails
// leaves nothing either.
#include <filesystem>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "skybake/output/exr_io.h"
#include "skybake/output/json_spool.h"
#include "test_support.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// An element with nested objects and arrays, and strings that look like the
// markers the writer looks for.
json Element(int i) {
  return {{"frame", i},
          {"name", "\n  \"frames\": [] and \"stages\": []\n"},
          {"files", json::array({{{"file", "a.exr"}, {"bytes", 10 * i}}, {{"file", "b"}, {"sha", "ff"}}})},
          {"sh", json::array({json::array({0.1 * i, -2.5e-300, 3.0}), json::array()})},
          {"empty", json::object()},
          {"unicode", "\xc3\xa9t\xc3\xa9"}};
}

TEST(JsonSpool, WritesTheBytesDumpGivesTheWholeDocument) {
  const std::string dir = testing::FreshTempDir("jsonspool");
  for (int n : {0, 1, 2, 5}) {
    JsonArraySpool frames(dir), stages(dir);
    json whole = {{"complete", false}, {"part", {{"frames", 3}}}, {"zzz", "last"}};
    whole["frames"] = json::array();
    whole["stages"] = json::array();
    json head = whole;
    for (int i = 0; i < n; ++i) {
      whole["frames"].push_back(Element(i));
      frames.Add(Element(i).dump(2));
      if (i % 2 == 0) {
        whole["stages"].push_back({{"stage", i}});
        stages.Add(json({{"stage", i}}).dump(2));
      }
    }
    EXPECT_EQ(frames.size(), size_t(n));
    const std::string path = dir + "/doc.json";
    WriteJsonWithSpools(path, head.dump(2) + "\n", {{"frames", &frames}, {"stages", &stages}});
    EXPECT_EQ(testing::ReadFileBytes(path), whole.dump(2) + "\n") << n << " elements";
    // Twice: the spools are read again, unchanged.
    WriteJsonWithSpools(path, head.dump(2) + "\n", {{"frames", &frames}, {"stages", &stages}});
    EXPECT_EQ(testing::ReadFileBytes(path), whole.dump(2) + "\n") << n << " elements, written again";
  }
  // The spools had no name: only the document is in the folder.
  EXPECT_EQ(testing::FileNames(dir), std::set<std::string>{"doc.json"});
  JsonArraySpool frames(dir);
  EXPECT_THROW(WriteJsonWithSpools(dir + "/x.json", json({{"frames", 1}}).dump(2), {{"frames", &frames}}),
               std::logic_error);
  fs::remove_all(dir);
}

// In a folder that does not exist (O_TMPFILE fails), the spool is made in
// the system's temporary folder and works the same.
TEST(JsonSpool, FallsBackToTheSystemTemporaryFolder) {
  const std::string dir = testing::FreshTempDir("jsonspool-fallback");
  JsonArraySpool frames(dir + "/missing");
  frames.Add("1");
  frames.Add("[\n  2\n]");
  WriteJsonWithSpools(dir + "/doc.json", "{\n  \"frames\": []\n}\n", {{"frames", &frames}});
  EXPECT_EQ(testing::ReadFileBytes(dir + "/doc.json"), json({{"frames", {1, {2}}}}).dump(2) + "\n");
  fs::remove_all(dir);
}

// A write in pieces that fails part way leaves neither the file nor its
// temporary, and an existing file as it was.
TEST(JsonSpool, FailedStreamedWriteLeavesNothing) {
  const std::string dir = testing::FreshTempDir("streamedwrite");
  const std::string path = dir + "/m.json";
  WriteFileAtomically(path, "old");
  EXPECT_THROW(WriteFileAtomically(path,
                                   [](const ByteSink& write) {
                                     write("new, in part");
                                     throw std::runtime_error("the producer failed");
                                   }),
               std::runtime_error);
  EXPECT_EQ(testing::ReadFileBytes(path), "old");
  EXPECT_EQ(testing::FileNames(dir), std::set<std::string>{"m.json"});
  WriteFileAtomically(path, [](const ByteSink& write) {
    write("a");
    write("");
    write("bc");
  });
  EXPECT_EQ(testing::ReadFileBytes(path), "abc");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace skybake
