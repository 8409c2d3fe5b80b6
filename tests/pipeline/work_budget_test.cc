// Budgets from the plan (formation_budget.h): the cloud formation's host
// work is counted frame by frame in the order the bake runs them, and a
// frame over --max-frame-seconds is refused before any work (exit 7) by
// check, plan and bake alike, naming the frame, its steps and the fix.
#include <filesystem>
#include <fstream>
#include <regex>

#include <gtest/gtest.h>

#include "test_support.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;
using testing::CommandRun;
using testing::RunSkybake;

// configs/styles/afternoon_buildup.toml's formation made as large as its
// ranges allow (512 x 512 x 64 cells, 3,600 steps an hour) and without its
// mask (which fits 64 x 64 cells): each half hour of its schedule is then
// 1,800 steps of 16.8 M cells, about 390 s of CPU time; but a part that
// bakes only 18:00 steps from the lattice of the sequence's reference frame
// (the highest Sun, 13:00, 3,620 steps, rendered first for the shared
// exposure) to step 21,620: 18,000 steps, about 3,900 s.
std::string LargeFormationStyle(const std::string& dir) {
  std::ifstream in(testing::SourceDir() + "/configs/styles/afternoon_buildup.toml");
  std::string style((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  style = std::regex_replace(style, std::regex("cells = \\[64, 64, 8\\]"), "cells = [512, 512, 64]");
  style = std::regex_replace(style, std::regex("steps_per_hour = 20.0"), "steps_per_hour = 3600.0");
  style = std::regex_replace(style, std::regex("mask_image = .*\\n"), "");
  style = std::regex_replace(style, std::regex("mask_layers = .*\\n"), "");
  style = std::regex_replace(style, std::regex("velocity_cells_per_hour = .*\\n"), "");
  return testing::WriteFile(dir, "large_formation.toml", style);
}

std::string Schedule() { return testing::SourceDir() + "/configs/schedules/afternoon_buildup.toml"; }

TEST(WorkBudget, CheckReportsTheFormationsBusiestFrame) {
  CommandRun run = RunSkybake("check '" + testing::SourceDir() +
                              "/configs/styles/afternoon_buildup.toml' --schedule '" + Schedule() + "'");
  EXPECT_EQ(run.exit_code, 0) << run.output;
  // The first frame: 20 warm-up steps of 64 x 64 x 8 cells.
  EXPECT_NE(run.output.find("cloud formation: 6.55e+05 cell updates in its busiest frame (frame 1)"), std::string::npos)
      << run.output;
}

TEST(WorkBudget, APartThatStepsFromZeroIsRefusedBeforeAnyWork) {
  const std::string dir = testing::FreshTempDir("work_budget");
  const std::string style = LargeFormationStyle(dir);
  const std::string args = "'" + style + "' --schedule '" + Schedule() + "'";
  // The whole sequence steps half an hour a frame: within the default budget.
  CommandRun whole = RunSkybake("check " + args);
  EXPECT_EQ(whole.exit_code, 0) << whole.output;
  EXPECT_NE(whole.output.find("cell updates in its busiest frame (frame 2)"), std::string::npos) << whole.output;
  // The last frame alone: refused by a dry run and by the bake.
  for (const std::string command : {"bake --dry-run", "bake"}) {
    CommandRun part = RunSkybake(command + " " + args + " --frames 13:13 --out '" + dir + "/out'");
    EXPECT_EQ(part.exit_code, 7) << command << ": " << part.output;
    EXPECT_NE(part.output.find("frame 13: the cloud formation needs an estimated 3.02e+11 cell updates (18000 steps "
                               "of 512 x 512 x 64 cells at 1400 m), about 3926 s of CPU time"),
              std::string::npos)
        << command << ": " << part.output;
    EXPECT_NE(part.output.find("above the budget of 3600 s per frame: lower [cloud_layer.formation] steps_per_hour"),
              std::string::npos)
        << command << ": " << part.output;
  }
  EXPECT_FALSE(fs::exists(dir + "/out"));
  // A lower budget refuses the whole sequence's busiest frame too.
  CommandRun low = RunSkybake("check " + args + " --max-frame-seconds 300");
  EXPECT_EQ(low.exit_code, 7) << low.output;
  EXPECT_NE(low.output.find("frame 2: the cloud formation needs an estimated 3.02e+10 cell updates (1800 steps"),
            std::string::npos)
      << low.output;
  fs::remove_all(dir);
}

// testpattern: its images' directions are held at once (14 N^2 texels of 24
// bytes, more with a preset); a pattern over --max-memory-mib is refused
// before any file (exit 7).
TEST(WorkBudget, ATestPatternOverTheMemoryBudgetIsRefusedBeforeAnyFile) {
  const std::string dir = testing::FreshTempDir("work_budget_pattern");
  // 4096: 14 x 4096^2 x 24 bytes + 32 x 6 x 4096^2 bytes = 8448 MiB.
  CommandRun large = RunSkybake("testpattern --size 4096 --out '" + dir + "/large'");
  EXPECT_EQ(large.exit_code, 7) << large.output;
  EXPECT_NE(large.output.find("testpattern --size 4096 needs an estimated 8448 MiB of memory"), std::string::npos)
      << large.output;
  EXPECT_NE(large.output.find("above the budget of 4096 MiB: lower --size, or raise --max-memory-mib"),
            std::string::npos)
      << large.output;
  EXPECT_FALSE(fs::exists(dir + "/large"));
  // 64 within a budget of 1 MiB: 14 x 64^2 x 24 + 32 x 6 x 64^2 bytes = 2.06 MiB, refused; within 3, written.
  CommandRun small = RunSkybake("testpattern --size 64 --max-memory-mib 1 --out '" + dir + "/small'");
  EXPECT_EQ(small.exit_code, 7) << small.output;
  EXPECT_NE(small.output.find("needs an estimated 2 MiB of memory"), std::string::npos) << small.output;
  CommandRun fits = RunSkybake("testpattern --size 64 --max-memory-mib 3 --out '" + dir + "/small'");
  EXPECT_EQ(fits.exit_code, 0) << fits.output;
  EXPECT_TRUE(fs::is_regular_file(dir + "/small/sky_latlong.exr")) << fits.output;
  for (const char* bad : {"nan", "0", "-1", "inf"}) {
    CommandRun run =
        RunSkybake(std::string("testpattern --size 64 --max-memory-mib ") + bad + " --out '" + dir + "/bad'");
    EXPECT_EQ(run.exit_code, 2) << bad << ": " << run.output;
  }
  fs::remove_all(dir);
}

// gallery: every style against the budgets before the first is baked; the
// formation of b.toml (warm-up 100,000 steps of 512 x 512 x 64 cells, about
// 21,800 s) refuses the gallery whole, a.toml unbaked, nothing written.
TEST(WorkBudget, AGalleryWithAStyleOverBudgetIsRefusedBeforeAnyBake) {
  const std::string dir = testing::FreshTempDir("work_budget_gallery");
  fs::create_directory(dir + "/styles");
  fs::copy_file(testing::SourceDir() + "/configs/default.toml", dir + "/styles/a.toml");
  const std::string large = testing::ReadFileBytes(LargeFormationStyle(dir));
  testing::WriteFile(dir + "/styles", "b.toml",
                     std::regex_replace(large, std::regex("warmup_steps = 20"), "warmup_steps = 100000"));
  CommandRun run = RunSkybake("gallery '" + dir + "/styles' --size 16 --out '" + dir + "/out'");
  EXPECT_EQ(run.exit_code, 7) << run.output;
  EXPECT_NE(run.output.find("gallery style " + dir +
                            "/styles/b.toml: render: the cloud formation needs an estimated "
                            "1.68e+12 cell updates (100000 steps of 512 x 512 x 64 cells"),
            std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("; nothing was baked"), std::string::npos) << run.output;
  EXPECT_FALSE(fs::exists(dir + "/out"));
  // A 512 x 256 preview (about 3 MiB of host images) over a memory budget
  // of 1 MiB: a.toml, refused by name.
  CommandRun memory = RunSkybake("gallery '" + dir + "/styles' --size 256 --max-memory-mib 1 --out '" + dir + "/out'");
  EXPECT_EQ(memory.exit_code, 7) << memory.output;
  EXPECT_NE(memory.output.find("gallery style " + dir + "/styles/a.toml: the bake needs an estimated"),
            std::string::npos)
      << memory.output;
  EXPECT_FALSE(fs::exists(dir + "/out"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace skybake
