// Replays every input of tests/fuzz/regressions/ and configs/ through the parser
// invariants of the fuzz target (tests/fuzz/parser_invariants.h), so that a crasher
// found once stays fixed in every build, not only in the clang fuzz build.
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "input_invariants.h"
#include "parser_invariants.h"
#include "test_support.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;

TEST(FuzzRegression, EveryRegressionAndSeedHoldsTheInvariants) {
  size_t replayed = 0;
  for (const char* folder : {"/tests/fuzz/regressions", "/configs", "/configs/schedules"}) {
    for (const auto& entry : fs::directory_iterator(testing::SourceDir() + folder)) {
      if (!entry.is_regular_file() || entry.path().extension() == ".md") continue;
      std::ifstream in(entry.path(), std::ios::binary);
      std::stringstream text;
      text << in.rdbuf();
      SCOPED_TRACE(entry.path().string());
      fuzz::CheckParsers(text.str());  // aborts, failing the test, if an invariant breaks
      ++replayed;
    }
  }
  EXPECT_GE(replayed, 6u);
}

// The star catalogue reader on the seeds and crashers of inputs_fuzz.
TEST(FuzzRegression, EveryCatalogueSeedHoldsTheInvariants) {
  size_t replayed = 0;
  for (const auto& entry : fs::directory_iterator(testing::SourceDir() + "/tests/fuzz/catalogues")) {
    if (!entry.is_regular_file() || entry.path().extension() == ".md") continue;
    std::ifstream in(entry.path(), std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    SCOPED_TRACE(entry.path().string());
    fuzz::CheckCatalogue(text.str());  // aborts, failing the test, if an invariant breaks
    ++replayed;
  }
  EXPECT_GE(replayed, 4u);
}

}  // namespace
}  // namespace skybake
