// The persistent pipeline cache (gpu/pipeline_cache.h): its file's envelope
// and the Vulkan header checked as the spec lays it out, a second context
// loading what the first saved, and damaged or foreign files ignored without
// a word from the validation layer. Hits are read from the cache's status
// and its file, never from a clock.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

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
      {},                                                   // empty
      std::vector<uint8_t>(4096, 0xa5),                     // garbage
      flipped,                                              // a bit flipped (checksum)
      EncodePipelineCacheFile(VulkanPayload(other, 64)),   // another driver's, well formed
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
