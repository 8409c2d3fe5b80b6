// Helpers shared by the tests: one Vulkan context per test binary, always
// with the Khronos validation layer, and never skipped: lavapipe is always
// installable, so a missing device fails with the command that fixes it.
#pragma once

#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "skybake/vulkan_context.h"

namespace skybake::testing {

// The context, created on first use. Fails the test (fatal) when Vulkan or
// the validation layer is missing.
VulkanContext& Vulkan();

// Asserts that the validation layer has said nothing since the last call.
void ExpectNoValidationMessages();

// Path of the repository's configs/ and of shared/ beside the checkout.
std::string SourceDir();
std::string SharedDir();

}  // namespace skybake::testing
