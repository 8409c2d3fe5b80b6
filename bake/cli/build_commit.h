// The git commit the skybake binary was built from: 40 hexadecimal digits,
// or "unknown" when it was not built from a git checkout. Captured at build
// time (cmake/build_commit.cmake), shown by `skybake --version` and recorded
// in every manifest (BakeOptions::build_commit).
#pragma once

namespace skybake {

extern const char* const kBuildCommit;

}  // namespace skybake
