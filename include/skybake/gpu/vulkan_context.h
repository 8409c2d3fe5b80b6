// Headless Vulkan compute context: instance, one physical device, one compute
// queue. No window, no surface.
//
// Device choice: a discrete GPU, else an integrated GPU, else a virtual GPU,
// else the CPU implementation (Mesa lavapipe). Every rejected device is
// listed with the reason. With validation on, the Khronos validation layer is
// loaded and every message it emits is counted and printed.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <map>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "skybake/base/errors.h"
#include "skybake/gpu/pipeline_cache.h"

namespace skybake {

// A Vulkan call failed (out of memory, device lost, ...).
class VulkanError : public Error {
 public:
  VulkanError(const std::string& what, VkResult result) : Error(what, kExitVulkan), result(result) {}
  std::string message() const override { return std::string("Vulkan: ") + what(); }
  VkResult result;
};

const char* VkResultName(VkResult result);

#define VK_CHECK(call)                                                                                                \
  do {                                                                                                                \
    VkResult vk_check_result_ = (call);                                                                               \
    if (vk_check_result_ != VK_SUCCESS)                                                                               \
      throw ::skybake::VulkanError(std::string(#call) + " failed with " + ::skybake::VkResultName(vk_check_result_) + \
                                       " at " + __FILE__ + ":" + std::to_string(__LINE__),                            \
                                   vk_check_result_);                                                                 \
  } while (0)

struct DeviceInfo {
  int index = 0;
  std::string name;
  std::string type;  // "discrete GPU", "integrated GPU", "virtual GPU", "CPU", "other"
  std::string api_version;
  std::string driver;
  bool usable = false;
  std::string rejected_because;  // empty when usable
};

// Mesa's lavapipe, the software driver LP_NUM_THREADS speaks to (its device
// is named "llvmpipe (LLVM ...)").
bool IsLavapipe(const DeviceInfo& device);

// Loading a Vulkan driver costs start-up whether or not it finds a device:
// the loader opens every installed driver, and Mesa's hardware drivers each
// link LLVM, whose relocation is most of lavapipe's 0.07-0.09 s device
// creation on the benchmark machine (docs/performance.md). A hardware driver
// offers a device only through a GPU's device node, so on a machine with
// none skybake asks the loader for the software driver alone.
struct DriverEnvironment {
  bool drivers_chosen_by_user = false;  // VK_ICD_FILENAMES, VK_DRIVER_FILES, VK_ADD_DRIVER_FILES,
                                        // VK_LOADER_DRIVERS_SELECT/_DISABLE or SKYBAKE_ALL_VULKAN_DRIVERS=1
  std::string gpu_device_node;          // the first of /dev/dri/renderD*, /dev/dri/card*, /dev/nvidia*,
                                        // /dev/dxg, /dev/kgsl*, /dev/mali*; empty when none exists
  std::vector<std::string> manifests;   // file names of the installed driver manifests (vulkan/icd.d)
};

// The environment variables the driver choice reads (VK_ICD_FILENAMES,
// VK_DRIVER_FILES, VK_ADD_DRIVER_FILES, VK_LOADER_DRIVERS_SELECT/_DISABLE,
// SKYBAKE_ALL_VULKAN_DRIVERS, HOME and XDG_* for the manifest folders, and
// LP_NUM_THREADS for lavapipe's thread count), by name; a name that is not
// set is absent. main reads them (the library reads no environment).
using EnvironmentVariables = std::map<std::string, std::string>;
const std::vector<std::string>& DriverEnvironmentVariableNames();

// This machine's, with `environment`: /dev and the loader's manifest folders.
DriverEnvironment ProbeDriverEnvironment(const EnvironmentVariables& environment);

// The loader's VK_LOADER_DRIVERS_SELECT that loads only lavapipe, or "" to
// load every driver: when the user chose none, no GPU device node exists
// and lavapipe's manifest is installed. The loader reads it from the
// environment when the first Vulkan instance is made, so main sets it
// before any Vulkan call and any thread starts, and passes it in as
// VulkanOptions::software_driver_selection.
std::string SoftwareDriverSelection(const DriverEnvironment& environment);

// The LP_NUM_THREADS main sets for lavapipe when the user set none (absent
// or empty in `environment`): twice `hardware_threads`, or "" to leave it.
// Lavapipe's own default, one thread per core, leaves cores idle between
// its work items; twice as many keep them busy, with the same user CPU time
// and the same bytes in every file (docs/performance_history.md, "Lavapipe
// threads"). Lavapipe caps the count at its own maximum. "" also when
// `hardware_threads` is 0 (unknown) or the user's value is set.
std::string LavapipeThreadCount(const EnvironmentVariables& environment, unsigned hardware_threads);

// The layouts of a compute pipeline with one descriptor set of `bindings`
// and one push-constant block of `push_bytes` bytes; the caller destroys both.
struct ComputeLayouts {
  VkDescriptorSetLayout set = VK_NULL_HANDLE;
  VkPipelineLayout pipeline = VK_NULL_HANDLE;
};
ComputeLayouts CreateComputeLayouts(VkDevice device, const VkDescriptorSetLayoutBinding* bindings,
                                    uint32_t binding_count, uint32_t push_bytes);

// A compute pipeline of SPIR-V `code` (`bytes` long, entry point "main")
// with `layout` and optional specialization constants, through `cache` when
// given (VulkanContext::pipeline_cache()); the caller destroys it.
VkPipeline CreateComputePipeline(VkDevice device, const uint32_t* code, size_t bytes, VkPipelineLayout layout,
                                 const VkSpecializationInfo* specialization = nullptr,
                                 VkPipelineCache cache = VK_NULL_HANDLE);

struct VulkanOptions {
  int device_index = -1;       // -1: choose the best usable device
  bool validation = false;     // load VK_LAYER_KHRONOS_validation
  bool print_messages = true;  // print validation messages to stderr
  // The VK_LOADER_DRIVERS_SELECT main set (SoftwareDriverSelection), or ""
  // when every driver is loaded; reported with the device.
  std::string software_driver_selection;
  // The LP_NUM_THREADS main set (LavapipeThreadCount), or "" when it set
  // none; reported with the device when the device is lavapipe.
  std::string lavapipe_threads;
  // The folder of the persistent pipeline cache (pipeline_cache.h), or ""
  // for none: main gives $XDG_CACHE_HOME/skybake or ~/.cache/skybake unless
  // SKYBAKE_PIPELINE_CACHE=0; tests and the library's other users give none.
  std::string pipeline_cache_folder;
};

class VulkanContext {
 public:
  explicit VulkanContext(const VulkanOptions& options);
  ~VulkanContext();
  VulkanContext(const VulkanContext&) = delete;
  VulkanContext& operator=(const VulkanContext&) = delete;

  // Lists every physical device and whether it can run skybake.
  static std::vector<DeviceInfo> ListDevices();

  VkDevice device() const { return device_; }
  VkPhysicalDevice physical_device() const { return physical_device_; }
  VkQueue queue() const { return queue_; }
  uint32_t queue_family() const { return queue_family_; }
  const DeviceInfo& device_info() const { return device_info_; }
  const VkPhysicalDeviceProperties& properties() const { return properties_; }

  // Whether the queue's commands can be timed (timestamp queries with a
  // known period): GPU pass times are reported only then.
  bool SupportsTimestamps() const;

  // The pipeline cache every pipeline is created through (VK_NULL_HANDLE
  // without a folder), what it did, and saving it (also done by the
  // destructor; never throws).
  VkPipelineCache pipeline_cache() const { return pipeline_cache_ ? pipeline_cache_->handle() : VK_NULL_HANDLE; }
  PipelineCacheStatus pipeline_cache_status() const {
    return pipeline_cache_ ? pipeline_cache_->status() : PipelineCacheStatus();
  }
  void SavePipelineCache() {
    if (pipeline_cache_) pipeline_cache_->Save();
  }

  // Number of validation messages (warnings and errors) seen so far.
  int validation_message_count() const { return validation_messages_; }
  const std::vector<std::string>& validation_messages() const { return messages_; }

  // Memory type with all `required` flags among `type_bits`; prefers `preferred` too.
  uint32_t FindMemoryType(uint32_t type_bits, VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred) const;

 private:
  static VKAPI_ATTR VkBool32 VKAPI_CALL DebugCallback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                      VkDebugUtilsMessageTypeFlagsEXT types,
                                                      const VkDebugUtilsMessengerCallbackDataEXT* data, void* user);

  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_device_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  std::unique_ptr<PipelineCache> pipeline_cache_;  // destroyed before the device
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t queue_family_ = 0;
  VkPhysicalDeviceProperties properties_{};
  VkPhysicalDeviceMemoryProperties memory_properties_{};
  DeviceInfo device_info_;
  bool print_messages_ = true;
  int validation_messages_ = 0;
  std::vector<std::string> messages_;
};

}  // namespace skybake
