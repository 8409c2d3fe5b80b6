// libFuzzer target for the style and schedule parsers: any bytes are read as
// a style and as a schedule (tests/fuzz/parser_invariants.h says what must hold).
// .ci/fuzz builds and runs it:
//
//   CC=clang CXX=clang++ cmake -S . -B build-fuzz -DSKYBAKE_FUZZ=ON && cmake --build build-fuzz -j2
//   build-fuzz/tests/fuzz/parsers_fuzz -max_total_time=60 build-fuzz/corpus configs configs/schedules
//   tests/fuzz/regressions
//
// A crash writes crash-<sha1> in the working folder: copy it into
// tests/fuzz/regressions/ (tests/e2e/fuzz_regression_test.cc replays it in every build)
// and fix the parser.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "parser_invariants.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  skybake::fuzz::CheckParsers(std::string_view(reinterpret_cast<const char*>(data), size));
  return 0;
}
