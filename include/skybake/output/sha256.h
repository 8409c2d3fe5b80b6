// SHA-256 checksums of output files (OpenSSL), lowercase hex: the manifest
// lists one for every file a bake writes.
#pragma once

#include <string>
#include <string_view>

namespace skybake {

// SHA-256 of a file, lowercase hex. Throws OutputError.
std::string Sha256OfFile(const std::string& path);
std::string Sha256OfText(std::string_view text);

}  // namespace skybake
