// The headless Vulkan context: device choice, and proof that the validation
// layer the other tests rely on is really listening.
#include <filesystem>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "skybake/gpu/vulkan_context.h"
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
    return type == "discrete GPU"     ? 0
           : type == "integrated GPU" ? 1
           : type == "virtual GPU"    ? 2
           : type == "CPU"            ? 3
                                      : 4;
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

TEST(VulkanDriversTest, OnlyLavapipeWithoutAGpuDeviceNodeUnlessTheUserChose) {
  DriverEnvironment e;
  e.manifests = {"intel_icd.x86_64.json", "lvp_icd.x86_64.json", "radeon_icd.x86_64.json"};
  EXPECT_EQ(SoftwareDriverSelection(e), "*lvp_icd*");
  DriverEnvironment gpu = e;
  gpu.gpu_device_node = "/dev/dri/renderD128";
  EXPECT_EQ(SoftwareDriverSelection(gpu), "");
  DriverEnvironment chosen = e;
  chosen.drivers_chosen_by_user = true;
  EXPECT_EQ(SoftwareDriverSelection(chosen), "");
  DriverEnvironment no_lavapipe = e;
  no_lavapipe.manifests = {"intel_icd.x86_64.json", "radeon_icd.x86_64.json"};
  EXPECT_EQ(SoftwareDriverSelection(no_lavapipe), "");  // leave the loader to find whatever exists
  EXPECT_EQ(SoftwareDriverSelection(DriverEnvironment{}), "");
}

TEST(VulkanDriversTest, LavapipeGetsTwiceTheHardwareThreadsUnlessTheUserSetACount) {
  EXPECT_EQ(LavapipeThreadCount({}, 2), "4");
  EXPECT_EQ(LavapipeThreadCount({}, 16), "32");
  EXPECT_EQ(LavapipeThreadCount({{"LP_NUM_THREADS", ""}}, 2), "4");  // empty: as if unset
  EXPECT_EQ(LavapipeThreadCount({{"LP_NUM_THREADS", "3"}}, 2), "");  // the user's count stays
  EXPECT_EQ(LavapipeThreadCount({{"LP_NUM_THREADS", "0"}}, 8), "");
  EXPECT_EQ(LavapipeThreadCount({}, 0), "");  // hardware threads unknown
  DeviceInfo device;
  device.name = "llvmpipe (LLVM 15.0.6, 256 bits)";
  EXPECT_TRUE(IsLavapipe(device));  // the count is reported only with lavapipe's device
  device.name = "AMD Radeon RX 6600 (RADV NAVI23)";
  EXPECT_FALSE(IsLavapipe(device));
}

// The CLI sets lavapipe's thread count when the user set none and keeps
// the user's, and a cloudy bake is the same bytes with 1 thread, the
// count the CLI chose and 5: a thread count changes only the time.
TEST(VulkanDriversTest, LavapipeThreadCountChangesNoByte) {
  const unsigned hardware = std::thread::hardware_concurrency();
  ASSERT_GT(hardware, 0u);
  const std::string chosen = "(lavapipe: " + std::to_string(2 * hardware) + " threads";
  testing::CommandRun devices = testing::RunSkybake("devices", "LP_NUM_THREADS=");
  ASSERT_EQ(devices.exit_code, 0) << devices.output;
  const bool lavapipe = devices.output.find("llvmpipe") != std::string::npos;
  EXPECT_EQ(devices.output.find(chosen) != std::string::npos, lavapipe) << devices.output;
  testing::CommandRun users = testing::RunSkybake("devices", "LP_NUM_THREADS=3");
  ASSERT_EQ(users.exit_code, 0) << users.output;
  EXPECT_EQ(users.output.find("(lavapipe:"), std::string::npos) << users.output;

  const std::string dir = testing::FreshTempDir("lavapipe_threads");
  const std::string style =
      testing::SourceDir() +
      "/configs/styles/cumulus_sunset.toml --size 48 --vulkan-validation --set output.preview=false";
  const std::vector<std::pair<std::string, std::string>> runs = {
      {"one", "LP_NUM_THREADS=1"}, {"chosen", "LP_NUM_THREADS="}, {"five", "LP_NUM_THREADS=5"}};
  for (const auto& [name, environment] : runs) {
    testing::CommandRun run = testing::RunSkybake("bake " + style + " --out " + dir + "/" + name, environment);
    ASSERT_EQ(run.exit_code, 0) << name << ": " << run.output;
    const bool reported = run.output.find("lavapipe threads " + std::to_string(2 * hardware)) != std::string::npos;
    EXPECT_EQ(reported, lavapipe && name == "chosen") << name << ": " << run.output;
  }
  for (const char* file : {"sky_latlong.exr", "sky_cube.exr", "sky_px.exr", "sky_ny.exr"}) {
    const std::string one = testing::ReadFileBytes(dir + "/one/" + file);
    ASSERT_FALSE(one.empty()) << file;
    EXPECT_EQ(one, testing::ReadFileBytes(dir + "/chosen/" + file)) << file;
    EXPECT_EQ(one, testing::ReadFileBytes(dir + "/five/" + file)) << file;
  }
  std::filesystem::remove_all(dir);
}

// The CLI asks the loader for lavapipe alone exactly when this machine
// calls for it, the loader then skips every other driver, and the bake's
// files are the same bytes as with every driver loaded.
TEST(VulkanDriversTest, CliLoadsOnlyTheSoftwareDriverWhenTheMachineHasNoGpu) {
  EnvironmentVariables environment;  // this process's, as main reads them
  for (const std::string& name : DriverEnvironmentVariableNames())
    if (const char* value = std::getenv(name.c_str())) environment[name] = value;
  const bool expected = !SoftwareDriverSelection(ProbeDriverEnvironment(environment)).empty();
  testing::CommandRun selected = testing::RunSkybake("devices", "VK_LOADER_DEBUG=driver");
  ASSERT_EQ(selected.exit_code, 0) << selected.output;
  EXPECT_EQ(selected.output.find("software driver only") != std::string::npos, expected) << selected.output;
  EXPECT_EQ(selected.output.find("not selected by env var") != std::string::npos, expected) << selected.output;
  testing::CommandRun all = testing::RunSkybake("devices", "VK_LOADER_DEBUG=driver SKYBAKE_ALL_VULKAN_DRIVERS=1");
  ASSERT_EQ(all.exit_code, 0) << all.output;
  EXPECT_EQ(all.output.find("software driver only"), std::string::npos) << all.output;
  EXPECT_EQ(all.output.find("not selected by env var"), std::string::npos) << all.output;

  const std::string dir = testing::FreshTempDir("drivers");
  const std::string style = testing::SourceDir() + "/configs/default.toml --size 32 --set output.preview=false";
  testing::CommandRun a = testing::RunSkybake("bake " + style + " --out " + dir + "/a");
  testing::CommandRun b = testing::RunSkybake("bake " + style + " --out " + dir + "/b", "SKYBAKE_ALL_VULKAN_DRIVERS=1");
  ASSERT_EQ(a.exit_code, 0) << a.output;
  ASSERT_EQ(b.exit_code, 0) << b.output;
  EXPECT_EQ(a.output.find("software driver only") != std::string::npos, expected) << a.output;
  for (const char* name : {"sky_latlong.exr", "sky_cube.exr", "sky_px.exr"})
    EXPECT_EQ(testing::ReadFileBytes(dir + "/a/" + name), testing::ReadFileBytes(dir + "/b/" + name)) << name;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace skybake
