#include "test_support.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>

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

}  // namespace skybake::testing
