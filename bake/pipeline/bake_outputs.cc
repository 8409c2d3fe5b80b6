#include "bake_outputs.h"

#include <filesystem>

#include <fmt/format.h>

#include "skybake/base/errors.h"
#include "skybake/pipeline/formation_budget.h"

namespace skybake {

std::string OutputPath(const BakeOptions& options, const std::string& name) {
  return (std::filesystem::path(options.out_dir) / name).string();
}

OutputLock ClaimOutputs(const RenderPlan& plan, const BakeOptions& options) {
  for (const FramePlan& frame : plan.frames) CheckBudget(*frame.style, options);
  CheckSequenceBudget(plan, options);
  CheckFormationBudget(plan, options);
  std::error_code ec;
  const std::filesystem::file_status out = std::filesystem::status(options.out_dir, ec);
  if (std::filesystem::exists(out) && !std::filesystem::is_directory(out))
    throw OutputError(
        fmt::format("--out {} is not a folder: give a folder (it is created when missing)", options.out_dir));
  std::filesystem::create_directories(options.out_dir, ec);
  if (ec)
    throw OutputError(fmt::format("cannot create the output folder {}: {}: choose a writable --out folder",
                                  options.out_dir, ec.message()));
  return OutputLock::Claim(options.out_dir, plan.files);
}

namespace {

// A directory (or a pipe, a socket) under an output's name, which the
// renames at the end could not replace.
void CheckNothingInTheWay(const RenderPlan& plan, const BakeOptions& options) {
  for (const std::string& name : plan.files) {
    if (options.resume && name == plan.manifest_name) continue;  // read first: ReadPreviousManifest says what is wrong
    std::error_code ec;
    const std::filesystem::file_status st = std::filesystem::symlink_status(OutputPath(options, name), ec);
    if (std::filesystem::exists(st) && !std::filesystem::is_regular_file(st) && !std::filesystem::is_symlink(st))
      throw OutputError(fmt::format("{} is {}: an output file cannot replace it; move it away, or choose another --out",
                                    OutputPath(options, name),
                                    std::filesystem::is_directory(st) ? "a directory" : "not a regular file"));
  }
}

// A previous bake's file, unless it is to be overwritten (--force) or finished (--resume).
void CheckNoPreviousBake(const RenderPlan& plan, const BakeOptions& options) {
  if (options.force || options.resume) return;
  for (const std::string& name : plan.files) {
    std::error_code ec;
    // A link (dangling or not) at the name is a file in the way too.
    if (std::filesystem::exists(std::filesystem::symlink_status(OutputPath(options, name), ec)))
      throw OutputExistsError(
          fmt::format("{} already exists: pass --force to overwrite the bake's files{}, or choose another --out",
                      OutputPath(options, name), plan.sequence ? ", --resume to finish an interrupted sequence" : ""));
  }
}

}  // namespace

PreviousBake PrepareOutputs(const RenderPlan& plan, const BakeOptions& options, StageTimer& timer, BakeResult& result) {
  CheckNothingInTheWay(plan, options);
  CheckNoPreviousBake(plan, options);
  PreviousBake previous;
  if (options.resume) previous = ReadPreviousManifest(OutputPath(options, plan.manifest_name));
  result.removed_temporaries = RemoveStaleTemporaries(options.out_dir, plan.files);
  timer.Finish("outputs",
               fmt::format("{} files planned{}{}", plan.files.size(),
                           result.removed_temporaries.empty()
                               ? ""
                               : fmt::format(", {} stale temporary file(s) removed", result.removed_temporaries.size()),
                           previous.loaded ? fmt::format(", resuming from {} frame(s) in {}", previous.frames.size(),
                                                         plan.manifest_name)
                                           : ""));
  return previous;
}

}  // namespace skybake
