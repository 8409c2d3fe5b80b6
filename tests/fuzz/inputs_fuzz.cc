// libFuzzer target for the inputs a key names that are not TOML: any bytes
// are read as a d3-celestial star catalogue (night.star_catalogue;
// ParseStarCatalogue, astronomy.h); tests/fuzz/input_invariants.h says what
// must hold. .ci/fuzz runs it after parsers_fuzz, seeded from
// tests/fuzz/catalogues/:
//
//   build-fuzz/tests/fuzz/inputs_fuzz -max_total_time=60 build-fuzz/corpus-inputs tests/fuzz/catalogues
//
// A crash writes crash-<sha1> in the working folder: copy it into
// tests/fuzz/catalogues/ (tests/e2e/fuzz_regression_test.cc replays it in every
// build) and fix the reader.
#include <cstddef>
#include <cstdint>
#include <string>

#include "input_invariants.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  skybake::fuzz::CheckCatalogue(std::string(reinterpret_cast<const char*>(data), size));
  return 0;
}
