#include "test_support.h"

#include <cmath>

#include <cstdio>
#include <cstdlib>
#include <array>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <sys/wait.h>
#include <unistd.h>

#include <OpenImageIO/imageio.h>

namespace skybake::testing {
namespace {
std::unique_ptr<VulkanContext> g_context;
int g_seen_messages = 0;
}  // namespace

VulkanContext& Vulkan() {
  if (!g_context) {
    VulkanOptions options;
    options.validation = true;
    try {
      g_context = std::make_unique<VulkanContext>(options);
    } catch (const std::exception& e) {
      std::fprintf(stderr,
                   "FAILED: Vulkan is required for this test and is not usable: %s\n"
                   "Install it with: apt-get install libvulkan1 mesa-vulkan-drivers "
                   "vulkan-validationlayers\n",
                   e.what());
      std::exit(1);
    }
  }
  return *g_context;
}

void ExpectNoValidationMessages() {
  if (!g_context) return;
  const auto& messages = g_context->validation_messages();
  for (size_t i = size_t(g_seen_messages); i < messages.size(); ++i)
    ADD_FAILURE() << "validation message: " << messages[i];
  g_seen_messages = int(messages.size());
}

std::string SourceDir() { return SKYBAKE_SOURCE_DIR; }

std::string SharedDir() {
  if (const char* env = std::getenv("SKYBAKE_SHARED_DIR")) return env;
  return (std::filesystem::path(SKYBAKE_SOURCE_DIR).parent_path() / "shared").string();
}

CommandRun RunSkybake(const std::string& args, const std::string& shell_prefix) {
  std::string script = shell_prefix + " '" + SKYBAKE_BINARY + "' " + args + " 2>&1";
  std::string command = "bash -c \"";
  for (char c : script) {
    if (c == '"' || c == '\\' || c == '$' || c == '`') command += '\\';
    command += c;
  }
  command += "\"";
  CommandRun run;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return run;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) run.output.append(buffer.data(), n);
  int status = pclose(pipe);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

std::pair<int, std::string> RunCommand(const std::string& command) {
  std::string output;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return {-1, "popen failed"};
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) output.append(buffer.data(), n);
  int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
}

nlohmann::json RunViewerPage(const std::string& page, const std::string& dir, const std::string& png,
                             const std::string& query) {
  const std::string command = "cd '" + SourceDir() + "/tests/viewer' && node run_page.mjs " + page + " '" + dir +
                              "' '" + png + "' '" + query + "'";
  auto [code, output] = RunCommand(command);
  EXPECT_EQ(code, 0) << command << "\n" << output;
  const size_t at = output.find("{\"chromium_exit\"");
  if (at == std::string::npos) {
    ADD_FAILURE() << "no report from " << page << ":\n" << output;
    return {};
  }
  nlohmann::json line = nlohmann::json::parse(output.substr(at, output.find('\n', at) - at), nullptr, false);
  EXPECT_FALSE(line.is_discarded()) << output;
  return line.is_discarded() ? nlohmann::json() : line;
}

std::string FreshTempDir(const std::string& name) {
  auto dir = std::filesystem::temp_directory_path() / ("skybake_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

std::string WriteFile(const std::string& dir, const std::string& name, const std::string& text) {
  const std::string path = dir + "/" + name;
  std::ofstream out(path, std::ios::binary);
  out << text;
  EXPECT_TRUE(out.good()) << "could not write " << path;
  return path;
}

std::string ReadFileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::set<std::string> FileNames(const std::string& dir) {
  std::set<std::string> names;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) names.insert(e.path().filename().string());
  return names;
}

void BakeSequence16(const std::string& style, const std::string& schedule, const std::string& out,
                    const std::string& extra) {
  CommandRun run = RunSkybake("bake '" + style + "' --schedule '" + schedule +
                              "' --size 16 -q --vulkan-validation --out '" + out + "' " + extra);
  EXPECT_EQ(run.exit_code, 0) << run.output;
}

int BakeWholeAndTwoShards(const std::string& style, const std::string& schedule, const std::string& root,
                          const std::string& shards) {
  BakeSequence16(style, schedule, root + "/whole");
  BakeSequence16(style, schedule, root + "/" + shards, "--shard 1/2");
  BakeSequence16(style, schedule, root + "/" + shards, "--shard 2/2");
  return RunSkybake("merge-manifest '" + root + "/" + shards + "'").exit_code;
}

void ExpectSameBytes(const std::string& dir, const std::string& reference_dir, const std::set<std::string>& names) {
  for (const std::string& name : names)
    EXPECT_TRUE(ReadFileBytes(dir + "/" + name) == ReadFileBytes(reference_dir + "/" + name)) << dir << "/" << name;
}

void WriteTestImage(const std::string& path, int w, int h, int channels,
                    const std::function<float(int, int, int)>& value) {
  std::vector<float> pixels(size_t(w) * h * channels);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < channels; ++c) pixels[(size_t(y) * w + x) * channels + c] = value(x, y, c);
  auto out = OIIO::ImageOutput::create(path);
  ASSERT_TRUE(out) << path;
  OIIO::ImageSpec spec(w, h, channels, path.ends_with(".png") ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT);
  ASSERT_TRUE(out->open(path, spec));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()));
  out->close();
}

namespace {
template <class T>
bool ReadRgbAs(const std::string& path, OIIO::TypeDesc type, int& width, int& height, std::vector<T>& rgb,
               std::map<std::string, std::string>* string_attributes) {
  auto in = OIIO::ImageInput::open(path);
  EXPECT_TRUE(in) << path;
  if (!in) return false;
  width = in->spec().width;
  height = in->spec().height;
  rgb.resize(size_t(width) * height * 3);
  in->read_image(0, 0, 0, 3, type, rgb.data());
  if (string_attributes)
    for (const OIIO::ParamValue& p : in->spec().extra_attribs)
      if (p.type() == OIIO::TypeDesc::STRING) (*string_attributes)[p.name().string()] = p.get_string();
  return true;
}
}  // namespace

bool ReadRgb(const std::string& path, int& width, int& height, std::vector<float>& rgb,
             std::map<std::string, std::string>* string_attributes) {
  return ReadRgbAs(path, OIIO::TypeDesc::FLOAT, width, height, rgb, string_attributes);
}

bool ReadRgb(const std::string& path, int& width, int& height, std::vector<unsigned char>& rgb) {
  return ReadRgbAs(path, OIIO::TypeDesc::UINT8, width, height, rgb, nullptr);
}

CubeFaceHit SpecCubeFace(const glm::dvec3& r) {
  const double ax = std::abs(r.x), ay = std::abs(r.y), az = std::abs(r.z);
  int face;
  double sc, tc, ma;
  if (ax >= ay && ax >= az) {
    face = r.x > 0 ? 0 : 1;
    sc = r.x > 0 ? -r.z : r.z;
    tc = -r.y;
    ma = ax;
  } else if (ay >= az) {
    face = r.y > 0 ? 2 : 3;
    sc = r.x;
    tc = r.y > 0 ? r.z : -r.z;
    ma = ay;
  } else {
    face = r.z > 0 ? 4 : 5;
    sc = r.z > 0 ? r.x : -r.x;
    tc = -r.y;
    ma = az;
  }
  return {face, 0.5 * (sc / ma + 1.0), 0.5 * (tc / ma + 1.0)};
}

}  // namespace skybake::testing
