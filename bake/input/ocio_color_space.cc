#include "skybake/input/ocio_color_space.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include <sys/stat.h>
#include <unistd.h>

#include <OpenColorIO/OpenColorIO.h>
#include <fmt/format.h>

#include "skybake/base/file_door.h"

namespace skybake {
namespace {

namespace OCIO = OCIO_NAMESPACE;

constexpr uintmax_t kMaxConfigBytes = uintmax_t(16) << 20;

// A CPU processor's action on a colour, in float as OpenColorIO computes.
std::array<double, 3> ApplyProcessor(const OCIO::ConstCPUProcessorRcPtr& cpu, const std::array<double, 3>& rgb) {
  float pixel[3] = {float(rgb[0]), float(rgb[1]), float(rgb[2])};
  cpu->applyRGB(pixel);
  return {pixel[0], pixel[1], pixel[2]};
}

// The 3x3 matrix a processor applies, from the images of the unit vectors.
Matrix3 SampledMatrix(const OCIO::ConstCPUProcessorRcPtr& cpu) {
  Matrix3 m{};
  for (int j = 0; j < 3; ++j) {
    std::array<double, 3> e{};
    e[j] = 1.0;
    const std::array<double, 3> column = ApplyProcessor(cpu, e);
    for (int i = 0; i < 3; ++i) m[i][j] = column[i];
  }
  return m;
}

// Whether the processor is the matrix on colours from dark to bright and
// out of gamut (to float precision).
bool IsLinear(const OCIO::ConstCPUProcessorRcPtr& cpu, const Matrix3& m) {
  for (const std::array<double, 3>& v : std::vector<std::array<double, 3>>{{0.18, 0.18, 0.18},
                                                                           {0.001, 0.002, 0.0005},
                                                                           {40.0, 25.0, 10.0},
                                                                           {1000.0, 3000.0, 2000.0},
                                                                           {-0.05, 0.3, 0.9}}) {
    const std::array<double, 3> got = ApplyProcessor(cpu, v), want = Apply(m, v);
    const double scale = std::max({std::abs(v[0]), std::abs(v[1]), std::abs(v[2])});
    for (int i = 0; i < 3; ++i)
      if (!(std::abs(got[i] - want[i]) <= 1e-4 * scale)) return false;
  }
  return true;
}

std::string ConfigSpaceNames(const OCIO::ConstConfigRcPtr& config) {
  std::string names;
  for (int i = 0; i < config->getNumColorSpaces(); ++i)
    names += fmt::format("{}'{}'", names.empty() ? "" : ", ", config->getColorSpaceNameByIndex(i));
  return names;
}

// 64 MiB: a 65^3 .cube LUT, the largest OpenColorIO configs ship, is about
// 8 MiB of text.
constexpr uint64_t kMaxLutBytes = uint64_t(64) << 20;

// The LUT files of a transform and of the transforms it groups.
void CollectLutFiles(const OCIO::ConstTransformRcPtr& t, std::vector<std::string>& files) {
  if (!t) return;
  if (auto file = OCIO::DynamicPtrCast<const OCIO::FileTransform>(t)) {
    if (file->getSrc() && *file->getSrc()) files.push_back(file->getSrc());
  } else if (auto group = OCIO::DynamicPtrCast<const OCIO::GroupTransform>(t)) {
    for (int i = 0; i < group->getNumTransforms(); ++i) CollectLutFiles(group->getTransform(i), files);
  }
}

// The LUT files a config names (colour spaces, looks, view and named
// transforms) are files OpenColorIO opens by name when a processor needs
// them: each one found is checked through the door (file_door.h) first, so
// that a FIFO, a device, a folder or a huge file at a LUT's name is refused
// with its name instead of hanging the bake or filling its memory. A LUT not
// found is left to OpenColorIO, which says so if the conversion needs it.
// "" or the problem.
std::string LutFilesProblem(const OCIO::ConstConfigRcPtr& config) {
  std::vector<std::string> files;
  for (int i = 0; i < config->getNumColorSpaces(OCIO::SEARCH_REFERENCE_SPACE_ALL, OCIO::COLORSPACE_ALL); ++i) {
    auto space = config->getColorSpace(
        config->getColorSpaceNameByIndex(OCIO::SEARCH_REFERENCE_SPACE_ALL, OCIO::COLORSPACE_ALL, i));
    if (!space) continue;
    CollectLutFiles(space->getTransform(OCIO::COLORSPACE_DIR_TO_REFERENCE), files);
    CollectLutFiles(space->getTransform(OCIO::COLORSPACE_DIR_FROM_REFERENCE), files);
  }
  for (int i = 0; i < config->getNumLooks(); ++i)
    if (auto look = config->getLook(config->getLookNameByIndex(i))) {
      CollectLutFiles(look->getTransform(), files);
      CollectLutFiles(look->getInverseTransform(), files);
    }
  for (int i = 0; i < config->getNumViewTransforms(); ++i)
    if (auto view = config->getViewTransform(config->getViewTransformNameByIndex(i))) {
      CollectLutFiles(view->getTransform(OCIO::VIEWTRANSFORM_DIR_TO_REFERENCE), files);
      CollectLutFiles(view->getTransform(OCIO::VIEWTRANSFORM_DIR_FROM_REFERENCE), files);
    }
  for (int i = 0; i < config->getNumNamedTransforms(OCIO::NAMEDTRANSFORM_ALL); ++i)
    if (auto named = config->getNamedTransform(config->getNamedTransformNameByIndex(OCIO::NAMEDTRANSFORM_ALL, i))) {
      CollectLutFiles(named->getTransform(OCIO::TRANSFORM_DIR_FORWARD), files);
      CollectLutFiles(named->getTransform(OCIO::TRANSFORM_DIR_INVERSE), files);
    }
  for (const std::string& src : files) {
    std::string resolved;
    try {
      resolved = config->getCurrentContext()->resolveFileLocation(src.c_str());
    } catch (const OCIO::Exception&) {
      continue;  // not found: OpenColorIO's own message if it is needed
    }
    int fd = -1;
    std::string problem = OpenRegularFile(resolved, FileLinks::kFollow, fd);
    if (problem.empty()) {
      struct stat st {};
      if (::fstat(fd, &st) == 0 && uint64_t(st.st_size) > kMaxLutBytes)
        problem =
            fmt::format("is {} bytes, more than the {} MiB a LUT may have", uint64_t(st.st_size), kMaxLutBytes >> 20);
      ::close(fd);
    }
    if (!problem.empty()) return fmt::format("its LUT file '{}' ({}) {}", src, resolved, problem);
  }
  return "";
}

ColorSpaceLookup FromConfig(const std::string& name, const std::string& path) {
  ColorSpaceLookup r;
  // A config is a small text file: not a FIFO, a device or a folder that
  // OpenColorIO would block on or read without end.
  // Through the door (file_door.h): a regular file, capped, read once.
  std::shared_ptr<const std::string> bytes;
  if (const std::string problem = ReadKept(path, kMaxConfigBytes, bytes); !problem.empty()) {
    r.error = fmt::format(
        "'{}' is not a built-in space ({}), and the OpenColorIO config {} that would name it "
        "cannot be read: it {}",
        name, BuiltinColorSpaceNames(), path, problem);
    return r;
  }
  OCIO::ConstConfigRcPtr config;
  try {
    std::istringstream stream(*bytes);
    OCIO::ConfigRcPtr read = OCIO::Config::CreateFromStream(stream)->createEditableCopy();
    // Its LUTs' search paths are relative to the config's folder, as
    // CreateFromFile would set.
    read->setWorkingDir(std::filesystem::absolute(path).parent_path().string().c_str());
    config = read;
  } catch (const OCIO::Exception& e) {
    r.error = fmt::format(
        "'{}' is not a built-in space ({}), and the OpenColorIO config {} that would name it "
        "cannot be read: {}",
        name, BuiltinColorSpaceNames(), path, e.what());
    return r;
  }
  std::string lut_problem;
  try {
    lut_problem = LutFilesProblem(config);
  } catch (const OCIO::Exception& e) {
    lut_problem = fmt::format("its transforms cannot be listed ({})", e.what());
  }
  if (const std::string& problem = lut_problem; !problem.empty()) {
    r.error = fmt::format(
        "the OpenColorIO config {} cannot be used: {}; give the LUT as a regular file of at "
        "most {} MiB, or a config that does not name it",
        path, problem, kMaxLutBytes >> 20);
    return r;
  }
  if (!config->getColorSpace(name.c_str())) {
    r.error = fmt::format(
        "'{}' is neither a built-in space ({}) nor a colour space of the OpenColorIO config {} "
        "(its spaces: {})",
        name, BuiltinColorSpaceNames(), path, ConfigSpaceNames(config));
    return r;
  }
  if (!config->hasRole("aces_interchange")) {
    r.error = fmt::format(
        "the OpenColorIO config {} has no 'aces_interchange' role, the ACES2065-1 space through "
        "which skybake enters a config: add the role (OpenColorIO 2 configs have it)",
        path);
    return r;
  }
  try {
    const OCIO::ConstCPUProcessorRcPtr to_space =
        config->getProcessor("aces_interchange", name.c_str())->getDefaultCPUProcessor();
    const Matrix3 from_aces = SampledMatrix(to_space);
    if (!IsLinear(to_space, from_aces)) {
      r.error = fmt::format(
          "'{}' of the OpenColorIO config {} is not a linear space: skybake writes scene-linear "
          "light (cd/m^2); name a linear space of the config",
          name, path);
      return r;
    }
    // The space's primaries and white as light, through OpenColorIO's ACES AP0 to D65 XYZ.
    OCIO::BuiltinTransformRcPtr to_xyz = OCIO::BuiltinTransform::Create();
    to_xyz->setStyle("UTILITY - ACES-AP0_to_CIE-XYZ-D65_BFD");
    const Matrix3 aces_to_xyz =
        SampledMatrix(OCIO::Config::CreateRaw()->getProcessor(to_xyz)->getDefaultCPUProcessor());
    const Matrix3 space_to_xyz = Multiply(aces_to_xyz, Inverse(from_aces));
    OutputColorSpace space;
    space.name = name;
    space.description = fmt::format("the OpenColorIO config's '{}' ({})", name, path);
    space.from_rec709 = Multiply(from_aces, Rec709To(ColorSpace::kAces2065));
    for (int j = 0; j < 4; ++j) {
      std::array<double, 3> rgb = {j == 0 || j == 3 ? 1.0 : 0.0, j == 1 || j == 3 ? 1.0 : 0.0,
                                   j == 2 || j == 3 ? 1.0 : 0.0};
      space.chromaticities[size_t(j)] = ChromaticityOf(Apply(space_to_xyz, rgb));
    }
    for (const auto& xy : space.chromaticities)
      if (!std::isfinite(xy[0]) || !std::isfinite(xy[1])) {
        r.error =
            fmt::format("'{}' of the OpenColorIO config {} has no chromaticities (a primary of no light)", name, path);
        return r;
      }
    r.space = space;
  } catch (const OCIO::Exception& e) {
    r.error = fmt::format("OpenColorIO cannot convert to '{}' of {}: {}", name, path, e.what());
  }
  return r;
}

}  // namespace

std::string BuiltinColorSpaceNames() {
  std::string names;
  for (const NamedColorSpace& n : BuiltinColorSpaces())
    names += fmt::format("{}'{}'", names.empty() ? "" : ", ", n.name);
  return names;
}

ColorSpaceLookup ResolveOutputColorSpace(const std::string& name, const std::string& config_path) {
  for (const NamedColorSpace& n : BuiltinColorSpaces())
    if (name == n.name) return {BuiltinOutputColorSpace(n.space), ""};
  std::string path = config_path;
  if (path.empty())
    if (const char* env = std::getenv("OCIO")) path = env;
  if (path.empty())
    return {std::nullopt, fmt::format("'{}' is not one of {}; a colour space of an OpenColorIO config is named with "
                                      "output.ocio_config = \"config.ocio\" (or $OCIO)",
                                      name, BuiltinColorSpaceNames())};
  return FromConfig(name, path);
}

}  // namespace skybake
