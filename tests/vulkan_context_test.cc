// The headless Vulkan context: device choice, and proof that the validation
// layer the other tests rely on is really listening.
#include <gtest/gtest.h>

#include "skybake/vulkan_context.h"
#include "test_support.h"

namespace skybake {
namespace {

TEST(VulkanContextTest, ChoosesAUsableComputeDevice) {
  VulkanContext& vulkan = testing::Vulkan();
  EXPECT_TRUE(vulkan.device_info().usable);
  EXPECT_NE(vulkan.device(), VK_NULL_HANDLE);
  std::vector<DeviceInfo> devices = VulkanContext::ListDevices();
  ASSERT_FALSE(devices.empty());
  // The chosen device is the best-ranked usable one.
  auto rank = [](const std::string& type) {
    return type == "discrete GPU" ? 0 : type == "integrated GPU" ? 1 : type == "virtual GPU" ? 2
           : type == "CPU" ? 3 : 4;
  };
  for (const DeviceInfo& d : devices) {
    if (d.usable) {
      EXPECT_LE(rank(vulkan.device_info().type), rank(d.type)) << d.name;
    }
  }
  testing::ExpectNoValidationMessages();
}

TEST(VulkanContextTest, ValidationLayerReportsMisuse) {
  VulkanOptions options;
  options.validation = true;
  options.print_messages = false;
  VulkanContext context(options);
  ASSERT_EQ(context.validation_message_count(), 0);
  // A zero-sized buffer is invalid usage (VUID-VkBufferCreateInfo-size-00912).
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = 0;
  info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  VkBuffer buffer = VK_NULL_HANDLE;
  VkResult result = vkCreateBuffer(context.device(), &info, nullptr, &buffer);
  if (result == VK_SUCCESS && buffer) vkDestroyBuffer(context.device(), buffer, nullptr);
  EXPECT_GT(context.validation_message_count(), 0);
}

TEST(VulkanContextTest, BadDeviceIndexIsAClearError) {
  VulkanOptions options;
  options.device_index = 99;
  try {
    VulkanContext context(options);
    FAIL() << "expected VulkanUnavailable";
  } catch (const VulkanUnavailable& e) {
    EXPECT_NE(std::string(e.what()).find("skybake devices"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace skybake
