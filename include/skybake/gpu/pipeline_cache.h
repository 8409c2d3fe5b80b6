// A persistent Vulkan pipeline cache: the driver's VkPipelineCache, kept
// between processes in the user's cache folder, so that a farm's thousands
// of bakes do not each compile the same pipelines from nothing.
//
// One file per device and set of shaders:
//   <folder>/pipelines-<pipelineCacheUUID, hex>-<shader digest, hex>.bin
// The folder is $XDG_CACHE_HOME/skybake, or ~/.cache/skybake (main chooses
// it; SKYBAKE_PIPELINE_CACHE=0 switches the cache off). The shader digest is
// the build's SPIR-V (SKYBAKE_SHADER_DIGEST, cmake/shader_digest.cmake), so a
// build with other shaders writes a file of its own.
//
// The file is skybake's envelope around the driver's data:
//   8 bytes  magic "SKBKPC01"
//   8 bytes  payload size, little-endian
//   8 bytes  FNV-1a 64 of the payload, little-endian
//   payload  vkGetPipelineCacheData's bytes, which open with the Vulkan
//            header (VkPipelineCacheHeaderVersionOne, Vulkan spec
//            "Pipeline Cache Header"): headerSize (>= 32), headerVersion
//            (VK_PIPELINE_CACHE_HEADER_VERSION_ONE), vendorID, deviceID,
//            pipelineCacheUUID[16]
// A file whose envelope or Vulkan header does not match this device is
// ignored (the cache starts empty and the file is replaced when saved):
// corrupt data never reaches the driver. Saving writes a temporary file in
// the same folder and renames it over the old one (atomic on POSIX), and
// only when the driver's data differs from what was loaded.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

namespace skybake {

// What happened to the cache in this process (reported with the pipelines
// stage; the tests read it instead of timing anything).
struct PipelineCacheStatus {
  bool enabled = false;         // a folder was given
  std::string path;             // the file, when enabled
  bool loaded = false;          // a valid file's data was given to the driver (a hit)
  size_t loaded_bytes = 0;      // the driver's data in it
  std::string ignored_because;  // why a file that exists was not used ("" when loaded or absent)
  bool saved = false;           // written this process
  size_t saved_bytes = 0;
  std::string save_error;  // why saving failed ("" otherwise); the bake goes on
};

// The file's name for a device and shader digest (no folder).
std::string PipelineCacheFileName(const VkPhysicalDeviceProperties& device, uint64_t shader_digest);

// The envelope around `payload` (the driver's data), as written to disk.
std::vector<uint8_t> EncodePipelineCacheFile(const std::vector<uint8_t>& payload);

// The driver's data of a file's bytes, or empty with `why` set when the
// envelope is damaged or the Vulkan header is not this device's.
std::vector<uint8_t> DecodePipelineCacheFile(const std::vector<uint8_t>& file, const VkPhysicalDeviceProperties& device,
                                             std::string& why);

// The digest of the SPIR-V compiled into this build.
uint64_t BuildShaderDigest();

class PipelineCache {
 public:
  // `folder` empty: no cache (handle() is VK_NULL_HANDLE). The folder need
  // not exist; it is made when the cache is saved.
  PipelineCache(VkDevice device, const VkPhysicalDeviceProperties& properties, const std::string& folder,
                uint64_t shader_digest);
  ~PipelineCache();
  PipelineCache(const PipelineCache&) = delete;
  PipelineCache& operator=(const PipelineCache&) = delete;

  // Given to vkCreateComputePipelines (the driver synchronizes it: pipelines
  // are created on several threads at once).
  VkPipelineCache handle() const { return cache_; }
  const PipelineCacheStatus& status() const { return status_; }

  // Writes the driver's data when it differs from what was loaded; never
  // throws (a failure is recorded in status().save_error).
  void Save();

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  VkPhysicalDeviceProperties properties_{};
  VkPipelineCache cache_ = VK_NULL_HANDLE;
  std::vector<uint8_t> loaded_;  // the payload given to the driver
  PipelineCacheStatus status_;
};

}  // namespace skybake
