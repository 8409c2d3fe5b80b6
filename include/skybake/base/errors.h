// The errors skybake reports to its user: one class per failure kind, each
// carrying the process exit code of that kind (README "Exit codes"). Every
// layer throws these, or one derived from them beside its concept
// (VulkanError in gpu/vulkan_context.h adds the VkResult, ConfigFailure in
// input/config.h the located errors, OutputLockedError in output/output_lock.h);
// the CLI maps any Error to its message and exit code in one place. A bug is
// any other exception (exit code 1).
#pragma once

#include <stdexcept>
#include <string>

namespace skybake {

// Process exit codes, one per failure kind (README "Exit codes").
enum ExitCode : int {
  kExitOk = 0,
  kExitInternal = 1,  // a bug: please report it
  kExitUsage = 2,     // bad command line
  kExitConfig = 3,    // the style or schedule is invalid
  kExitVulkan = 4,    // no usable Vulkan driver or device, or a Vulkan failure
  kExitOutput = 5,    // an output file could not be written (disk full, no permission)
  kExitExists = 6,    // the bake's files already exist: pass --force or --resume
  kExitBudget = 7,    // the bake would exceed the memory or time budget (README "Limits")
  kExitMerge = 8,     // merge-manifest: shard manifests missing frames, overlapping, of different bakes
};

// A failure the user can act on: the message names the cause and the fix.
class Error : public std::runtime_error {
 public:
  Error(const std::string& what, ExitCode code) : std::runtime_error(what), code_(code) {}
  ExitCode exit_code() const { return code_; }
  // The line the CLI prints after "skybake: error: ".
  virtual std::string message() const { return what(); }

 private:
  ExitCode code_;
};

// A bad command line (exit code 2), found before any GPU work; the message
// names the option, the value and the fix.
class UsageError : public Error {
 public:
  explicit UsageError(const std::string& what) : Error(what, kExitUsage) {}
};

// No usable Vulkan driver or device: the message names the package to install.
class VulkanUnavailable : public Error {
 public:
  explicit VulkanUnavailable(const std::string& what) : Error(what, kExitVulkan) {}
};

// A file could not be written, or a value cannot be represented.
class OutputError : public Error {
 public:
  explicit OutputError(const std::string& what) : Error(what, kExitOutput) {}

 protected:
  OutputError(const std::string& what, ExitCode code) : Error(what, code) {}
};

// The bake's files are already in the output folder and neither --force nor
// --resume was given. Thrown before any GPU work.
class OutputExistsError : public OutputError {
 public:
  explicit OutputExistsError(const std::string& what) : OutputError(what, kExitExists) {}
};

// The bake would need more memory or time than the budget. Thrown before any
// GPU work; the message gives the estimate.
class BudgetError : public Error {
 public:
  explicit BudgetError(const std::string& what) : Error(what, kExitBudget) {}
};

// Shard manifests that cannot be merged (a frame missing or in two parts,
// parts of different bakes, a listed file missing or changed), or a manifest
// that cannot be read. The message names the files and the fix.
class ManifestError : public Error {
 public:
  explicit ManifestError(const std::string& what) : Error(what, kExitMerge) {}
};

}  // namespace skybake
