#include "skybake/output/sha256.h"

#include <cerrno>
#include <cstring>

#include <unistd.h>
#include <memory>
#include <vector>

#include <fmt/format.h>
#include <openssl/evp.h>

#include "skybake/base/errors.h"
#include "skybake/base/file_door.h"

namespace skybake {
namespace {

class Sha256 {
 public:
  Sha256() : ctx_(EVP_MD_CTX_new(), EVP_MD_CTX_free) {
    if (!ctx_ || EVP_DigestInit_ex(ctx_.get(), EVP_sha256(), nullptr) != 1)
      throw OutputError("OpenSSL: cannot start SHA-256");
  }
  void Update(const void* data, size_t size) { EVP_DigestUpdate(ctx_.get(), data, size); }
  std::string HexDigest() {
    unsigned char digest[EVP_MAX_MD_SIZE];
    unsigned int length = 0;
    EVP_DigestFinal_ex(ctx_.get(), digest, &length);
    std::string hex;
    for (unsigned int i = 0; i < length; ++i) hex += fmt::format("{:02x}", digest[i]);
    return hex;
  }

 private:
  std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> ctx_;
};

}  // namespace

std::string Sha256OfFile(const std::string& path) {
  // Through the door (file_door.h): a regular file, not a link (every file
  // checksummed is one of a bake's folder), read in chunks.
  int fd = -1;
  if (const std::string problem = OpenRegularFile(path, FileLinks::kRefuse, fd); !problem.empty())
    throw OutputError(fmt::format("cannot read {} to checksum it: it {}", path, problem));
  Sha256 sha;
  std::vector<char> chunk(1 << 16);
  for (;;) {
    const ssize_t n = ::read(fd, chunk.data(), chunk.size());
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int error = errno;
      ::close(fd);
      throw OutputError(fmt::format("cannot read {} to checksum it: {}", path, std::strerror(error)));
    }
    if (n == 0) break;
    sha.Update(chunk.data(), size_t(n));
  }
  ::close(fd);
  return sha.HexDigest();
}

std::string Sha256OfText(std::string_view text) {
  Sha256 sha;
  sha.Update(text.data(), text.size());
  return sha.HexDigest();
}

}  // namespace skybake
