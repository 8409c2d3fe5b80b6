// The persistent pipeline cache (gpu/pipeline_cache.h): its file's envelope
// and the Vulkan header checked as the spec lays it out, a second context
// loading what the first saved, and damaged or foreign files ignored without
// a word from the validation layer. Hits are read from the cache's status
// and its file, never from a clock.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include "skybake/gpu/pipeline_cache.h"
#include "skybake/gpu/sky_renderer.h"
#include "skybake/gpu/vulkan_context.h"
#include "test_support.h"

namespace skybake {
namespace {

std::vector<uint8_t> ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void WriteBytes(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

// The Vulkan header of `device` (VkPipelineCacheHeaderVersionOne) and `extra` bytes after it.
std::vector<uint8_t> VulkanPayload(const VkPhysicalDeviceProperties& device, size_t extra = 8) {
  std::vector<uint8_t> p;
  auto put = [&](uint32_t v) {
    for (int i = 0; i < 4; ++i) p.push_back(uint8_t(v >> (8 * i)));
  };
  put(32);
  put(VK_PIPELINE_CACHE_HEADER_VERSION_ONE);
  put(device.vendorID);
  put(device.deviceID);
  p.insert(p.end(), device.pipelineCacheUUID, device.pipelineCacheUUID + VK_UUID_SIZE);
  for (size_t i = 0; i < extra; ++i) p.push_back(uint8_t(i));
  return p;
}

// A context with validation and the cache in `folder`, with the sky pipelines of the default style made.
struct CachedBake {
  explicit CachedBake(const std::string& folder) : context(Options(folder)) {
    SkyRenderer renderer(context, AtmosphereParams(), QualitySettings(), EffectSettings(), {1, 1, 1});
  }
  static VulkanOptions Options(const std::string& folder) {
    VulkanOptions options;
    options.validation = true;
    options.print_messages = false;
    options.pipeline_cache_folder = folder;
    return options;
  }
  VulkanContext context;
};

TEST(PipelineCacheTest, HeaderIsCheckedAsTheVulkanSpecLaysItOut) {
  const VkPhysicalDeviceProperties& device = testing::Vulkan().properties();
  std::string why;
  const std::vector<uint8_t> payload = VulkanPayload(device);
  EXPECT_EQ(DecodePipelineCacheFile(EncodePipelineCacheFile(payload), device, why), payload);
  EXPECT_EQ(why, "");
  // Each field of the header, and the envelope, wrong in turn.
  struct Case {
    size_t offset;  // into the payload; SIZE_MAX: the envelope's checksum
    const char* expect;
  };
  for (const Case& c : {Case{0, "headerSize"}, Case{4, "headerVersion"}, Case{8, "another device"},
                        Case{12, "another device"}, Case{16, "another driver"}, Case{31, "another driver"}}) {
    std::vector<uint8_t> bad = payload;
    bad[c.offset] ^= 0x40;
    EXPECT_TRUE(DecodePipelineCacheFile(EncodePipelineCacheFile(bad), device, why).empty()) << c.offset;
    EXPECT_NE(why.find(c.expect), std::string::npos) << c.offset << ": " << why;
  }
  std::vector<uint8_t> file = EncodePipelineCacheFile(payload);
  file.back() ^= 1;  // a bit flipped in the driver's data
  EXPECT_TRUE(DecodePipelineCacheFile(file, device, why).empty());
  EXPECT_NE(why.find("checksum"), std::string::npos) << why;
  file = EncodePipelineCacheFile(payload);
  file.resize(file.size() - 3);  // cut short
  EXPECT_TRUE(DecodePipelineCacheFile(file, device, why).empty());
  EXPECT_NE(why.find("cut short"), std::string::npos) << why;
  EXPECT_TRUE(DecodePipelineCacheFile({'x', 'y'}, device, why).empty());
  EXPECT_NE(why.find("envelope"), std::string::npos) << why;
  // A header shorter than version one's 32 bytes.
  EXPECT_TRUE(DecodePipelineCacheFile(EncodePipelineCacheFile(std::vector<uint8_t>(20, 0)), device, why).empty());
  EXPECT_NE(why.find("cut short"), std::string::npos) << why;
}

TEST(PipelineCacheTest, FileNameCarriesTheDriverAndTheShaders) {
  VkPhysicalDeviceProperties a = testing::Vulkan().properties(), b = a;
  b.pipelineCacheUUID[3] ^= 1;
  EXPECT_NE(PipelineCacheFileName(a, 1), PipelineCacheFileName(b, 1));
  EXPECT_NE(PipelineCacheFileName(a, 1), PipelineCacheFileName(a, 2));
  EXPECT_NE(BuildShaderDigest(), 0u);
}

TEST(PipelineCacheTest, SecondContextLoadsWhatTheFirstSaved) {
  const std::string folder = testing::FreshTempDir("pipeline_cache_hit") + "/made/by/the/cache";
  std::string path;
  {
    CachedBake first(folder);
    const PipelineCacheStatus s = first.context.pipeline_cache_status();
    EXPECT_TRUE(s.enabled);
    EXPECT_FALSE(s.loaded);
    EXPECT_EQ(s.ignored_because, "");
    path = s.path;
    first.context.SavePipelineCache();
    EXPECT_TRUE(first.context.pipeline_cache_status().saved) << first.context.pipeline_cache_status().save_error;
    EXPECT_EQ(first.context.validation_message_count(), 0);
  }
  ASSERT_TRUE(std::filesystem::exists(path)) << path;
  EXPECT_EQ(std::filesystem::path(path).parent_path(), std::filesystem::path(folder));
  // No temporary file is left beside it.
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(folder), std::filesystem::directory_iterator()), 1);
  std::string why;
  const std::vector<uint8_t> saved = DecodePipelineCacheFile(ReadBytes(path), testing::Vulkan().properties(), why);
  EXPECT_EQ(why, "");
  EXPECT_GE(saved.size(), 32u);

  CachedBake second(folder);
  const PipelineCacheStatus s = second.context.pipeline_cache_status();
  EXPECT_TRUE(s.loaded) << s.ignored_because;
  EXPECT_EQ(s.loaded_bytes, saved.size());
  second.context.SavePipelineCache();
  EXPECT_EQ(second.context.validation_message_count(), 0);
}

TEST(PipelineCacheTest, DamagedOrForeignFilesAreIgnoredSilentlyAndReplaced) {
  const VkPhysicalDeviceProperties& device = testing::Vulkan().properties();
  const std::string folder = testing::FreshTempDir("pipeline_cache_bad");
  const std::string path = folder + "/" + PipelineCacheFileName(device, BuildShaderDigest());
  VkPhysicalDeviceProperties other = device;
  other.pipelineCacheUUID[0] ^= 0xff;
  std::vector<uint8_t> flipped = EncodePipelineCacheFile(VulkanPayload(device, 64));
  flipped[40] ^= 0x10;
  const std::vector<std::vector<uint8_t>> files = {
      {},                                                 // empty
      std::vector<uint8_t>(4096, 0xa5),                   // garbage
      flipped,                                            // a bit flipped (checksum)
      EncodePipelineCacheFile(VulkanPayload(other, 64)),  // another driver's, well formed
  };
  for (size_t i = 0; i < files.size(); ++i) {
    WriteBytes(path, files[i]);
    CachedBake bake(folder);
    const PipelineCacheStatus s = bake.context.pipeline_cache_status();
    EXPECT_FALSE(s.loaded) << i;
    EXPECT_NE(s.ignored_because, "") << i;
    bake.context.SavePipelineCache();
    EXPECT_TRUE(bake.context.pipeline_cache_status().saved) << i;
    EXPECT_EQ(bake.context.validation_message_count(), 0) << i;
    for (const std::string& m : bake.context.validation_messages()) ADD_FAILURE() << m;
    std::string why;
    EXPECT_FALSE(DecodePipelineCacheFile(ReadBytes(path), device, why).empty()) << i << ": " << why;
  }
}

// A shared cache folder others can write: a FIFO or a link to a device at
// the cache's name is ignored with what it is (not waited on, not read
// without end, not followed) and replaced by the saved file; a link planted
// at the temporary's name is not written through.
TEST(PipelineCacheTest, HostileFilesInASharedFolderAreIgnoredNotFollowed) {
  const VkPhysicalDeviceProperties& device = testing::Vulkan().properties();
  const std::string folder = testing::FreshTempDir("pipeline_cache_hostile");
  const std::string path = folder + "/" + PipelineCacheFileName(device, BuildShaderDigest());
  struct Planted {
    std::function<void()> plant;
    std::string said;
  };
  const std::vector<Planted> cases = {
      {[&] { ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0); }, "it is a FIFO (named pipe), not a regular file"},
      {[&] { std::filesystem::create_symlink("/dev/zero", path); },
       "it is a symbolic link, which is not followed here"},
  };
  for (const Planted& c : cases) {
    std::filesystem::remove(path);
    c.plant();
    CachedBake bake(folder);
    EXPECT_FALSE(bake.context.pipeline_cache_status().loaded);
    EXPECT_EQ(bake.context.pipeline_cache_status().ignored_because, c.said);
    bake.context.SavePipelineCache();
    EXPECT_TRUE(bake.context.pipeline_cache_status().saved) << bake.context.pipeline_cache_status().save_error;
    EXPECT_TRUE(std::filesystem::is_regular_file(std::filesystem::symlink_status(path))) << c.said;
  }
  // The temporary's name (PATH.tmp.PID) is predictable: a link there to a
  // file of the user's is refused, the file left as it was.
  std::filesystem::remove(path);
  const std::string victim = testing::WriteFile(folder, "victim.txt", "keep me");
  std::filesystem::create_symlink(victim, path + ".tmp." + std::to_string(::getpid()));
  CachedBake bake(folder);
  bake.context.SavePipelineCache();
  EXPECT_FALSE(bake.context.pipeline_cache_status().saved);
  EXPECT_NE(bake.context.pipeline_cache_status().save_error, "");
  EXPECT_EQ(testing::ReadFileBytes(victim), "keep me");
  EXPECT_EQ(bake.context.validation_message_count(), 0);
}

TEST(PipelineCacheTest, NoFolderNoCache) {
  VulkanOptions options;
  options.validation = true;
  options.print_messages = false;
  VulkanContext context(options);
  EXPECT_EQ(context.pipeline_cache(), VkPipelineCache(VK_NULL_HANDLE));
  EXPECT_FALSE(context.pipeline_cache_status().enabled);
  context.SavePipelineCache();
  EXPECT_FALSE(context.pipeline_cache_status().saved);
}

}  // namespace
}  // namespace skybake
