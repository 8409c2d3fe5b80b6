// Loading libskybake_oiio.so (oiio_module.h) on first use: from the folder
// main passes in ($SKYBAKE_MODULE_DIR), beside the executable, the build
// tree's top folder, an install's lib/skybake/, or the folder it was built in.
#include <dlfcn.h>

#include <filesystem>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "skybake/base/errors.h"
#include "skybake/base/oiio_module.h"

#include "skybake/base/file_door.h"

namespace skybake {

namespace {

std::mutex& LoaderMutex() {
  static std::mutex mutex;
  return mutex;
}

std::optional<std::string>& FirstModuleDir() {
  static std::optional<std::string> dir;  // SetOiioModuleDir
  return dir;
}

}  // namespace

void SetOiioModuleDir(const std::string& dir) {
  std::lock_guard<std::mutex> lock(LoaderMutex());
  FirstModuleDir() = dir;
}

const OiioModule& LoadOiioModule() {
  static const OiioModule* module = nullptr;
  std::lock_guard<std::mutex> lock(LoaderMutex());
  if (module) return *module;
  std::vector<std::filesystem::path> dirs;
  if (FirstModuleDir()) dirs.emplace_back(*FirstModuleDir());
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    dirs.push_back(exe.parent_path());
    dirs.push_back(exe.parent_path().parent_path());  // tests/ of the build tree
    // An installed skybake (`cmake --install`, the .deb): PREFIX/bin/skybake
    // and PREFIX/LIBDIR/skybake/libskybake_oiio.so, wherever PREFIX is.
    dirs.push_back(exe.parent_path().parent_path() / SKYBAKE_MODULE_INSTALL_SUBDIR);
  }
  dirs.emplace_back(SKYBAKE_MODULE_BUILD_DIR);
  std::string tried;
  for (const std::filesystem::path& dir : dirs) {
    const std::string path = (dir / "libskybake_oiio.so").string();
    void* handle = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      tried += fmt::format("\n  {}: {}", path, ::dlerror());
      continue;
    }
    auto entry = reinterpret_cast<const OiioModule* (*)()>(::dlsym(handle, "skybake_oiio_module_v3"));
    if (!entry) {
      tried += fmt::format("\n  {}: no skybake_oiio_module_v3 (a module of another skybake version)", path);
      continue;
    }
    module = entry();
    return *module;
  }
  throw OutputError(
      fmt::format("cannot load the OpenImageIO module libskybake_oiio.so (the gallery, cloud "
                  "weather and formation images): it is built when OpenImageIO is installed "
                  "(apt-get install libopenimageio-dev, then rebuild skybake), or set "
                  "SKYBAKE_MODULE_DIR to the folder holding it; tried:{}",
                  tried));
}

// The door's image read (file_door.h): the bytes kept by ReadKept, decoded by
// the module from memory.
std::string ReadImageFile(const std::string& path, int& width, int& height, int& channels, std::vector<float>& pixels) {
  std::shared_ptr<const std::string> bytes;
  if (std::string problem = ReadKept(path, kMaxImageFileBytes, bytes); !problem.empty()) return problem;
  std::string error;
  if (!LoadOiioModule().read_image(path, *bytes, kMaxImageSamples, width, height, channels, pixels, error))
    return "cannot read it as an image (" + error + ")";
  return "";
}

}  // namespace skybake
