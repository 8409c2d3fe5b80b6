#include "skybake/gpu/vulkan_context.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <sstream>

#include <fmt/format.h>

namespace skybake {
namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
constexpr const char* kInstallDriver =
    "install a Vulkan driver: on Debian 'apt-get install libvulkan1 mesa-vulkan-drivers' "
    "(lavapipe runs on the CPU and needs no GPU)";

std::string DeviceTypeName(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return "discrete GPU";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return "integrated GPU";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return "virtual GPU";
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return "CPU";
    default:
      return "other";
  }
}

// Lower is better.
int DeviceRank(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return 3;
    default:
      return 4;
  }
}

std::string VersionString(uint32_t v) {
  return fmt::format("{}.{}.{}", VK_API_VERSION_MAJOR(v), VK_API_VERSION_MINOR(v), VK_API_VERSION_PATCH(v));
}

bool HasLayer(const char* name) {
  uint32_t count = 0;
  vkEnumerateInstanceLayerProperties(&count, nullptr);
  std::vector<VkLayerProperties> layers(count);
  vkEnumerateInstanceLayerProperties(&count, layers.data());
  for (const auto& l : layers)
    if (std::strcmp(l.layerName, name) == 0) return true;
  return false;
}

VkInstance CreateInstance(bool validation, bool debug_utils) {
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "skybake";
  app.apiVersion = VK_API_VERSION_1_1;
  std::vector<const char*> layers;
  std::vector<const char*> extensions;
  if (validation) layers.push_back(kValidationLayer);
  if (debug_utils) extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  info.pApplicationInfo = &app;
  info.enabledLayerCount = uint32_t(layers.size());
  info.ppEnabledLayerNames = layers.data();
  info.enabledExtensionCount = uint32_t(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  VkInstance instance = VK_NULL_HANDLE;
  VkResult result = vkCreateInstance(&info, nullptr, &instance);
  if (result == VK_ERROR_INCOMPATIBLE_DRIVER)
    throw VulkanUnavailable(fmt::format("no Vulkan driver found; {}", kInstallDriver));
  if (result == VK_ERROR_LAYER_NOT_PRESENT)
    throw VulkanUnavailable(
        "the Khronos validation layer is missing; on Debian 'apt-get install "
        "vulkan-validationlayers'");
  VK_CHECK(result);
  return instance;
}

// The first queue family with compute support, or -1.
int ComputeQueueFamily(VkPhysicalDevice device) {
  uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, families.data());
  for (uint32_t i = 0; i < count; ++i)
    if (families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) return int(i);
  return -1;
}

bool SupportsShaderInt64(VkPhysicalDevice device) {
  VkPhysicalDeviceFeatures features;
  vkGetPhysicalDeviceFeatures(device, &features);
  return features.shaderInt64 == VK_TRUE;
}

DeviceInfo Describe(VkPhysicalDevice device, int index) {
  VkPhysicalDeviceProperties p;
  vkGetPhysicalDeviceProperties(device, &p);
  DeviceInfo info;
  info.index = index;
  info.name = p.deviceName;
  info.type = DeviceTypeName(p.deviceType);
  info.api_version = VersionString(p.apiVersion);
  info.driver = fmt::format("{:#x}", p.driverVersion);
  if (p.apiVersion < VK_API_VERSION_1_1) {
    info.rejected_because = "supports Vulkan " + info.api_version + ", skybake needs 1.1";
  } else if (ComputeQueueFamily(device) < 0) {
    info.rejected_because = "has no compute queue";
  } else if (!SupportsShaderInt64(device)) {
    info.rejected_because = "has no 64-bit integers in shaders (shaderInt64), which the sky-view LUT is packed in";
  } else {
    info.usable = true;
  }
  return info;
}

std::vector<VkPhysicalDevice> EnumerateDevices(VkInstance instance) {
  uint32_t count = 0;
  VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, nullptr));
  std::vector<VkPhysicalDevice> devices(count);
  VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, devices.data()));
  return devices;
}

}  // namespace

namespace {

bool StartsWith(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

// The folders the Vulkan loader searches for driver manifests on Linux
// (its LoaderInterfaceArchitecture.md, "Driver Discovery on Linux").
std::vector<std::filesystem::path> ManifestFolders(const EnvironmentVariables& environment) {
  auto env = [&](const char* name, const char* fallback) {
    auto it = environment.find(name);
    return it != environment.end() && !it->second.empty() ? it->second : std::string(fallback);
  };
  const std::string home = env("HOME", "");
  std::vector<std::filesystem::path> folders;
  auto add_list = [&](const std::string& list) {
    std::stringstream in(list);
    for (std::string dir; std::getline(in, dir, ':');)
      if (!dir.empty()) folders.push_back(std::filesystem::path(dir) / "vulkan" / "icd.d");
  };
  add_list(env("XDG_CONFIG_HOME", home.empty() ? "" : (home + "/.config").c_str()));
  add_list(env("XDG_CONFIG_DIRS", "/etc/xdg"));
  folders.push_back("/etc/vulkan/icd.d");
  add_list(env("XDG_DATA_HOME", home.empty() ? "" : (home + "/.local/share").c_str()));
  add_list(env("XDG_DATA_DIRS", "/usr/local/share:/usr/share"));
  return folders;
}
}  // namespace

const std::vector<std::string>& DriverEnvironmentVariableNames() {
  static const std::vector<std::string> names = {"VK_ICD_FILENAMES",
                                                 "VK_DRIVER_FILES",
                                                 "VK_ADD_DRIVER_FILES",
                                                 "VK_LOADER_DRIVERS_SELECT",
                                                 "VK_LOADER_DRIVERS_DISABLE",
                                                 "SKYBAKE_ALL_VULKAN_DRIVERS",
                                                 "HOME",
                                                 "XDG_CONFIG_HOME",
                                                 "XDG_CONFIG_DIRS",
                                                 "XDG_DATA_HOME",
                                                 "XDG_DATA_DIRS",
                                                 "LP_NUM_THREADS"};
  return names;
}

DriverEnvironment ProbeDriverEnvironment(const EnvironmentVariables& environment) {
  DriverEnvironment e;
  for (const char* name : {"VK_ICD_FILENAMES", "VK_DRIVER_FILES", "VK_ADD_DRIVER_FILES", "VK_LOADER_DRIVERS_SELECT",
                           "VK_LOADER_DRIVERS_DISABLE"}) {
    auto it = environment.find(name);
    if (it != environment.end() && !it->second.empty()) e.drivers_chosen_by_user = true;
  }
  auto all = environment.find("SKYBAKE_ALL_VULKAN_DRIVERS");
  if (all != environment.end() && all->second == "1") e.drivers_chosen_by_user = true;
  auto gpu_node = [](const std::string& folder, const std::string& name) {
    if (folder == "/dev/dri") return StartsWith(name, "renderD") || StartsWith(name, "card");
    return StartsWith(name, "nvidia") || name == "dxg" || StartsWith(name, "kgsl") || StartsWith(name, "mali");
  };
  std::error_code ec;  // a folder that does not exist lists nothing
  try {
    for (const char* folder : {"/dev/dri", "/dev"})
      for (const auto& entry : std::filesystem::directory_iterator(folder, ec))
        if (e.gpu_device_node.empty() && gpu_node(folder, entry.path().filename().string()))
          e.gpu_device_node = entry.path().string();
    for (const std::filesystem::path& folder : ManifestFolders(environment))
      for (const auto& entry : std::filesystem::directory_iterator(folder, ec))
        if (entry.path().extension() == ".json") e.manifests.push_back(entry.path().filename().string());
  } catch (const std::filesystem::filesystem_error&) {
    e.gpu_device_node = "(unknown: a folder could not be listed)";  // keep every driver
  }
  return e;
}

std::string SoftwareDriverSelection(const DriverEnvironment& environment) {
  if (environment.drivers_chosen_by_user || !environment.gpu_device_node.empty()) return "";
  for (const std::string& manifest : environment.manifests)
    if (StartsWith(manifest, "lvp_icd")) return "*lvp_icd*";
  return "";
}

bool IsLavapipe(const DeviceInfo& device) { return device.name.find("llvmpipe") != std::string::npos; }

std::string LavapipeThreadCount(const EnvironmentVariables& environment, unsigned hardware_threads) {
  auto it = environment.find("LP_NUM_THREADS");
  if ((it != environment.end() && !it->second.empty()) || hardware_threads == 0) return "";
  return std::to_string(2 * hardware_threads);
}

const char* VkResultName(VkResult result) {
  switch (result) {
    case VK_SUCCESS:
      return "VK_SUCCESS";
    case VK_NOT_READY:
      return "VK_NOT_READY";
    case VK_TIMEOUT:
      return "VK_TIMEOUT";
    case VK_ERROR_OUT_OF_HOST_MEMORY:
      return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY:
      return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED:
      return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST:
      return "VK_ERROR_DEVICE_LOST";
    case VK_ERROR_MEMORY_MAP_FAILED:
      return "VK_ERROR_MEMORY_MAP_FAILED";
    case VK_ERROR_LAYER_NOT_PRESENT:
      return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT:
      return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT:
      return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER:
      return "VK_ERROR_INCOMPATIBLE_DRIVER";
    case VK_ERROR_TOO_MANY_OBJECTS:
      return "VK_ERROR_TOO_MANY_OBJECTS";
    default:
      return "VkResult(other)";
  }
}

std::vector<DeviceInfo> VulkanContext::ListDevices() {
  VkInstance instance = CreateInstance(false, false);
  std::vector<DeviceInfo> infos;
  try {
    std::vector<VkPhysicalDevice> devices = EnumerateDevices(instance);
    for (size_t i = 0; i < devices.size(); ++i) infos.push_back(Describe(devices[i], int(i)));
  } catch (...) {
    vkDestroyInstance(instance, nullptr);
    throw;
  }
  vkDestroyInstance(instance, nullptr);
  return infos;
}

VkBool32 VulkanContext::DebugCallback(VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT,
                                      const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  auto* self = static_cast<VulkanContext*>(user);
  const char* level = (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) ? "error" : "warning";
  std::string text =
      fmt::format("vulkan validation {}: {}", level, data && data->pMessage ? data->pMessage : "(no message)");
  ++self->validation_messages_;
  self->messages_.push_back(text);
  if (self->print_messages_) std::fprintf(stderr, "%s\n", text.c_str());
  return VK_FALSE;
}

VulkanContext::VulkanContext(const VulkanOptions& options) : print_messages_(options.print_messages) {
  if (options.validation && !HasLayer(kValidationLayer))
    throw VulkanUnavailable(
        "the Khronos validation layer is missing; on Debian 'apt-get install "
        "vulkan-validationlayers'");
  instance_ = CreateInstance(options.validation, options.validation);
  try {
    if (options.validation) {
      VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
      info.messageSeverity =
          VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
      info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                         VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
      info.pfnUserCallback = &VulkanContext::DebugCallback;
      info.pUserData = this;
      auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
      if (!create) throw VulkanUnavailable("VK_EXT_debug_utils is not available for validation");
      VK_CHECK(create(instance_, &info, nullptr, &messenger_));
    }

    std::vector<VkPhysicalDevice> devices = EnumerateDevices(instance_);
    if (devices.empty()) throw VulkanUnavailable(fmt::format("no Vulkan device found; {}", kInstallDriver));
    int chosen = -1;
    if (options.device_index >= 0) {
      if (options.device_index >= int(devices.size()))
        throw VulkanUnavailable(fmt::format("device {} does not exist: there are {} devices (run 'skybake devices')",
                                            options.device_index, devices.size()));
      DeviceInfo info = Describe(devices[options.device_index], options.device_index);
      if (!info.usable)
        throw VulkanUnavailable(
            fmt::format("device {} ({}) cannot be used: it {}", info.index, info.name, info.rejected_because));
      chosen = options.device_index;
    } else {
      int best_rank = 1 << 20;
      for (size_t i = 0; i < devices.size(); ++i) {
        DeviceInfo info = Describe(devices[i], int(i));
        if (!info.usable) continue;
        VkPhysicalDeviceProperties p;
        vkGetPhysicalDeviceProperties(devices[i], &p);
        if (DeviceRank(p.deviceType) < best_rank) {
          best_rank = DeviceRank(p.deviceType);
          chosen = int(i);
        }
      }
      if (chosen < 0) throw VulkanUnavailable(fmt::format("no usable Vulkan device; {}", kInstallDriver));
    }
    physical_device_ = devices[chosen];
    device_info_ = Describe(physical_device_, chosen);
    vkGetPhysicalDeviceProperties(physical_device_, &properties_);
    vkGetPhysicalDeviceMemoryProperties(physical_device_, &memory_properties_);
    queue_family_ = uint32_t(ComputeQueueFamily(physical_device_));

    float priority = 1.0f;
    VkDeviceQueueCreateInfo queue_info{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    queue_info.queueFamilyIndex = queue_family_;
    queue_info.queueCount = 1;
    queue_info.pQueuePriorities = &priority;
    VkDeviceCreateInfo device_info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    device_info.queueCreateInfoCount = 1;
    device_info.pQueueCreateInfos = &queue_info;
    VkPhysicalDeviceFeatures features{};
    features.shaderInt64 = VK_TRUE;  // the packed sky-view LUT (shaders/common.glsl)
    device_info.pEnabledFeatures = &features;
    VK_CHECK(vkCreateDevice(physical_device_, &device_info, nullptr, &device_));
    vkGetDeviceQueue(device_, queue_family_, 0, &queue_);
    pipeline_cache_ =
        std::make_unique<PipelineCache>(device_, properties_, options.pipeline_cache_folder, BuildShaderDigest());
  } catch (...) {
    if (device_) vkDestroyDevice(device_, nullptr);
    if (messenger_) {
      auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
      if (destroy) destroy(instance_, messenger_, nullptr);
    }
    vkDestroyInstance(instance_, nullptr);
    throw;
  }
}

VulkanContext::~VulkanContext() {
  if (pipeline_cache_) pipeline_cache_->Save();
  pipeline_cache_.reset();
  if (device_) vkDestroyDevice(device_, nullptr);
  if (messenger_) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(instance_, messenger_, nullptr);
  }
  if (instance_) vkDestroyInstance(instance_, nullptr);
}

uint32_t VulkanContext::FindMemoryType(uint32_t type_bits, VkMemoryPropertyFlags required,
                                       VkMemoryPropertyFlags preferred) const {
  int fallback = -1;
  for (uint32_t i = 0; i < memory_properties_.memoryTypeCount; ++i) {
    if (!(type_bits & (1u << i))) continue;
    VkMemoryPropertyFlags flags = memory_properties_.memoryTypes[i].propertyFlags;
    if ((flags & required) != required) continue;
    if ((flags & preferred) == preferred) return i;
    if (fallback < 0) fallback = int(i);
  }
  if (fallback < 0)
    throw VulkanError("no Vulkan memory type with the required properties", VK_ERROR_OUT_OF_DEVICE_MEMORY);
  return uint32_t(fallback);
}

bool VulkanContext::SupportsTimestamps() const {
  uint32_t family_count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physical_device_, &family_count, nullptr);
  std::vector<VkQueueFamilyProperties> families(family_count);
  vkGetPhysicalDeviceQueueFamilyProperties(physical_device_, &family_count, families.data());
  return families[queue_family_].timestampValidBits > 0 && properties_.limits.timestampPeriod > 0.0f;
}

ComputeLayouts CreateComputeLayouts(VkDevice device, const VkDescriptorSetLayoutBinding* bindings,
                                    uint32_t binding_count, uint32_t push_bytes) {
  ComputeLayouts layouts;
  VkDescriptorSetLayoutCreateInfo set_info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  set_info.bindingCount = binding_count;
  set_info.pBindings = bindings;
  VK_CHECK(vkCreateDescriptorSetLayout(device, &set_info, nullptr, &layouts.set));
  VkPushConstantRange push_range{VK_SHADER_STAGE_COMPUTE_BIT, 0, push_bytes};
  VkPipelineLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layout_info.setLayoutCount = 1;
  layout_info.pSetLayouts = &layouts.set;
  layout_info.pushConstantRangeCount = 1;
  layout_info.pPushConstantRanges = &push_range;
  VK_CHECK(vkCreatePipelineLayout(device, &layout_info, nullptr, &layouts.pipeline));
  return layouts;
}

VkPipeline CreateComputePipeline(VkDevice device, const uint32_t* code, size_t bytes, VkPipelineLayout layout,
                                 const VkSpecializationInfo* specialization, VkPipelineCache cache) {
  VkShaderModuleCreateInfo module_info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  module_info.codeSize = bytes;
  module_info.pCode = code;
  VkShaderModule module;
  VK_CHECK(vkCreateShaderModule(device, &module_info, nullptr, &module));
  VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  info.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  info.stage.module = module;
  info.stage.pName = "main";
  info.stage.pSpecializationInfo = specialization;
  info.layout = layout;
  VkPipeline pipeline;
  VkResult result = vkCreateComputePipelines(device, cache, 1, &info, nullptr, &pipeline);
  vkDestroyShaderModule(device, module, nullptr);
  VK_CHECK(result);
  return pipeline;
}

}  // namespace skybake
