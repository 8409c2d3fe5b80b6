// Nothing is lost: existing outputs need --force, a killed sequence resumes
// to the same bytes, a full disk is reported and leaves no partial file,
// names cannot leave the output folder, and bakes over the budget or the
// device's limits are refused with the estimate. Runs the binary.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "skybake/output/output_lock.h"
#include "test_support.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;
using testing::CommandRun;
using testing::FileNames;
using testing::FreshTempDir;
using testing::ReadFileBytes;
using testing::RunSkybake;
using testing::WriteFile;

std::string Style() { return testing::SourceDir() + "/configs/default.toml"; }

// Twenty frames, the Sun rising from the horizon to 38 degrees.
constexpr const char* kTwentyFrames = R"([schedule]
sun = { elevation_deg = { start = 0, end = 38, step = 2 }, azimuth_deg = 135 }
)";

// What differs between any two runs of a bake: its wall-clock timings, kept
// out of manifest.json.
bool IsTimings(const std::string& name) { return name == "timings.json"; }

TEST(SafeOutputs, ExistingOutputsNeedForce) {
  std::string out = FreshTempDir("exists") + "/out";
  const std::string bake = "bake '" + Style() + "' --size 8 -q --out '" + out + "'";
  CommandRun first = RunSkybake(bake);
  ASSERT_EQ(first.exit_code, 0) << first.output;
  std::string before = ReadFileBytes(out + "/sky_px.exr");
  CommandRun again = RunSkybake(bake);
  EXPECT_EQ(again.exit_code, 6) << again.output;
  EXPECT_EQ(again.output, "skybake: error: " + out +
                              "/sky_px.exr already exists: pass --force to overwrite the bake's files, or choose "
                              "another --out\n");
  EXPECT_EQ(ReadFileBytes(out + "/sky_px.exr"), before);
  CommandRun forced = RunSkybake(bake + " --force");
  EXPECT_EQ(forced.exit_code, 0) << forced.output;
  EXPECT_EQ(ReadFileBytes(out + "/sky_px.exr"), before) << "the same bake gives the same bytes";
  CommandRun resume_single = RunSkybake(bake + " --resume");
  EXPECT_EQ(resume_single.exit_code, 2) << resume_single.output;
  EXPECT_NE(resume_single.output.find("--resume continues a sequence bake"), std::string::npos);
  CommandRun both = RunSkybake(bake + " --resume --force");
  EXPECT_EQ(both.exit_code, 2) << both.output;
  fs::remove_all(fs::path(out).parent_path());
}

// kill -9 in the middle of a 20-frame bake, then --resume: every file is
// byte-identical to an uninterrupted bake's, manifest.json included (the
// wall-clock timings are in timings.json).
TEST(SafeOutputs, KilledSequenceResumesToIdenticalBytes) {
  const std::string root = FreshTempDir("resume");
  const std::string schedule = WriteFile(root, "twenty.toml", kTwentyFrames);
  fs::create_directories(root + "/whole");
  fs::create_directories(root + "/killed");
  // The same relative --out for both, as a user resuming would type it.
  const std::string bake = "bake '" + Style() + "' --schedule '" + schedule + "' --size 16 -q --out out";
  CommandRun whole = RunSkybake(bake, "cd '" + root + "/whole' &&");
  ASSERT_EQ(whole.exit_code, 0) << whole.output;

  const std::string killed = root + "/killed/out";
  pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    if (chdir((root + "/killed").c_str()) != 0) _exit(127);
    execl(SKYBAKE_BINARY, "skybake", "bake", Style().c_str(), "--schedule", schedule.c_str(), "--size", "16", "-q",
          "--out", "out", static_cast<char*>(nullptr));
    _exit(127);
  }
  // Kill once the fifth frame's first file is in place (frames 1-4 done).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (!fs::exists(killed + "/sky_px.0005.exr") && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_EQ(kill(pid, SIGKILL), 0);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the bake finished before the kill: it was not interrupted";

  // After the kill: every file under a real output name is complete (the
  // manifest lists the frames done; any other output file has the bytes of
  // the uninterrupted bake, since it was renamed into place only once whole).
  const std::set<std::string> after_kill = FileNames(killed);
  nlohmann::json partial = nlohmann::json::parse(std::ifstream(killed + "/manifest.json"));
  EXPECT_FALSE(partial["complete"].get<bool>());
  EXPECT_GE(partial["frames"].size(), 4u);
  EXPECT_LT(partial["frames"].size(), 20u);
  size_t temporaries = 0;
  for (const std::string& name : after_kill) {
    if (name.rfind(".skybake.lock.", 0) == 0) continue;  // the killed bake's lock claim, no longer held
    if (name[0] == '.') {
      ++temporaries;  // a hidden temporary of the killed process: never a real output name
      EXPECT_NE(name.find(".tmp"), std::string::npos) << name;
      continue;
    }
    if (name == "manifest.json" || IsTimings(name)) continue;
    EXPECT_EQ(ReadFileBytes(killed + "/" + name), ReadFileBytes(root + "/whole/out/" + name)) << name << " is partial";
  }

  CommandRun resumed = RunSkybake(bake + " --resume", "cd '" + root + "/killed' &&");
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  const std::set<std::string> whole_names = FileNames(root + "/whole/out");
  EXPECT_EQ(FileNames(killed), whole_names) << "no temporary left, no file missing";
  EXPECT_TRUE(whole_names.count("manifest.json") && whole_names.count("timings.json"));
  for (const std::string& name : whole_names) {
    if (IsTimings(name)) continue;
    EXPECT_EQ(ReadFileBytes(killed + "/" + name), ReadFileBytes(root + "/whole/out/" + name)) << name;
  }
  nlohmann::json timings = nlohmann::json::parse(std::ifstream(killed + "/timings.json"));
  EXPECT_GT(timings["total_s"].get<double>(), 0.0);
  std::printf("killed after %zu of 20 frames, %zu temporary file(s) left by the kill and removed by --resume\n",
              partial["frames"].size(), temporaries);

  // Resuming a finished bake renders nothing and changes no file.
  CommandRun again = RunSkybake("bake '" + Style() + "' --schedule '" + schedule + "' --size 16 --out out --resume",
                                "cd '" + root + "/killed' &&");
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_EQ(again.output.find(" 8 views"), std::string::npos) << again.output;

  // Another style: no frame matches its recorded style_sha256, so --resume
  // bakes all twenty again.
  CommandRun changed = RunSkybake(
      "bake '" + Style() + "' --schedule '" + schedule + "' --size 16 --out out --resume --set atmosphere.mie.g=0.7",
      "cd '" + root + "/killed' &&");
  ASSERT_EQ(changed.exit_code, 0) << changed.output;
  size_t rendered = 0;
  for (size_t at = changed.output.find(" 8 views"); at != std::string::npos;
       at = changed.output.find(" 8 views", at + 1))
    ++rendered;
  EXPECT_EQ(rendered, 20u) << changed.output;
  EXPECT_NE(ReadFileBytes(killed + "/sky_px.0001.exr"), ReadFileBytes(root + "/whole/out/sky_px.0001.exr"));
  fs::remove_all(root);
}

// A hostile folder: links planted at every temporary name a bake used to
// pick (`.NAME.tmpPID`, the pid known once the process starts: here the
// child plants them before it execs skybake, keeping its pid), pointing at
// files elsewhere. Temporaries are created with O_EXCL | O_NOFOLLOW under
// unguessable names, so every victim keeps its bytes and every output is
// the bake's own.
TEST(SafeOutputs, PlantedTemporaryLinksAreNeverFollowed) {
  const std::string root = FreshTempDir("planted");
  const std::string out = root + "/out";
  const std::string victims = root + "/victims";
  fs::create_directories(out);
  fs::create_directories(victims);
  const std::string schedule =
      WriteFile(root, "two.toml", "[schedule]\nsun = { elevation_deg = [10, 20], azimuth_deg = 135 }\n");
  std::vector<std::string> names = {"manifest.json", "timings.json", "sky.gltf", "sky.bin", "sky.glb"};
  for (const char* frame : {"0001", "0002"}) {
    for (const char* face : {"px", "nx", "py", "ny", "pz", "nz", "cube", "latlong"})
      names.push_back(std::string("sky_") + face + "." + frame + ".exr");
    names.push_back(std::string("sky_latlong.") + frame + ".png");
  }
  pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    for (const std::string& name : names) {
      const std::string victim = victims + "/" + name;
      std::ofstream(victim) << "victim " << name;
      if (symlink(victim.c_str(), (out + "/." + name + ".tmp" + std::to_string(getpid())).c_str()) != 0) _exit(126);
    }
    execl(SKYBAKE_BINARY, "skybake", "bake", Style().c_str(), "--schedule", schedule.c_str(), "--size", "8", "-q",
          "--out", out.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status)) << "the bake crashed";
  ASSERT_EQ(WEXITSTATUS(status), 0) << "planting failed (126) or the bake failed";
  for (const std::string& name : names) {
    EXPECT_EQ(ReadFileBytes(victims + "/" + name), "victim " + name) << name << " was written through a link";
    EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(out + "/" + name))) << name;
  }
  nlohmann::json manifest = nlohmann::json::parse(std::ifstream(out + "/manifest.json"));
  EXPECT_TRUE(manifest["complete"].get<bool>());
  for (const auto& frame : manifest["frames"])
    for (const auto& file : frame["files"])
      EXPECT_EQ(ReadFileBytes(out + "/" + file["file"].get<std::string>()).size(), file["bytes"].get<uint64_t>());
  fs::remove_all(root);
}

// A link at an output's own name is replaced (the rename), never written
// through.
TEST(SafeOutputs, LinkAtAnOutputNameIsReplacedNotFollowed) {
  const std::string root = FreshTempDir("finallink");
  const std::string out = root + "/out";
  fs::create_directories(out);
  std::ofstream(root + "/victim") << "victim";
  fs::create_symlink(root + "/victim", out + "/sky_px.exr");
  CommandRun run = RunSkybake("bake '" + Style() + "' --size 8 -q --force --out '" + out + "'");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(ReadFileBytes(root + "/victim"), "victim");
  EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(out + "/sky_px.exr")));
  fs::remove_all(root);
}

// The output lock (skybake/output_lock.h): claims that share a file name
// exclude each other while held; disjoint claims coexist; a released or
// dead claim frees its names.
TEST(OutputLockTest, OverlappingClaimsAreRefusedDisjointOnesCoexist) {
  const std::string dir = FreshTempDir("lockunit");
  {
    OutputLock a = OutputLock::Claim(dir, {"sky_px.0001.exr", "manifest.shard-0001-0002.json"});
    OutputLock b = OutputLock::Claim(dir, {"sky_px.0003.exr", "manifest.shard-0003-0004.json"});
    try {
      OutputLock c = OutputLock::Claim(dir, {"sky_px.0004.exr", "sky_px.0001.exr"});
      ADD_FAILURE() << "an overlapping claim was granted";
    } catch (const OutputLockedError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(fmt::format("(pid {} on ", getpid())), std::string::npos) << what;
      EXPECT_NE(what.find("which writes " + dir + "/sky_px.0001.exr too"), std::string::npos) << what;
    }
  }
  // Both released: the names are free, and no lock file is left.
  OutputLock again = OutputLock::Claim(dir, {"sky_px.0001.exr"});
  EXPECT_EQ(FileNames(dir).size(), 1u) << "only the one live claim";
  again = OutputLock();
  EXPECT_TRUE(FileNames(dir).empty());
  fs::remove_all(dir);
}

// The folder's mutex held by a stopped process (here: this test, holding
// its flock): a claimer waits a bounded time, then exit 6 naming the
// holder's pid and host as the mutex file gives them; the wait is set by
// SKYBAKE_LOCK_WAIT_SECONDS, a bad value being a usage error.
TEST(OutputLockTest, AHeldMutexIsWaitedForABoundedTimeThenNamed) {
  const std::string dir = FreshTempDir("lockwait");
  const int held = ::open((dir + "/.skybake.lock").c_str(), O_RDWR | O_CREAT, 0644);
  ASSERT_GE(held, 0);
  ASSERT_EQ(::flock(held, LOCK_EX), 0);
  const std::string holder = "pid 4242\nhost farm-node-7\x1b[2J\n";
  ASSERT_EQ(::write(held, holder.data(), holder.size()), ssize_t(holder.size()));
  try {
    OutputLock never = OutputLock::Claim(dir, {"sky_px.exr"}, 0.05);
    ADD_FAILURE() << "the mutex was taken while held";
  } catch (const OutputLockedError& e) {
    EXPECT_EQ(e.exit_code(), 6);
    EXPECT_NE(std::string(e.what()).find("/.skybake.lock has been held for more than 0.05 s by pid 4242 on "
                                         "farm-node-7\\x1b[2J: that skybake is stopped or hung"),
              std::string::npos)
        << e.what();
  }
  CommandRun bake = RunSkybake("bake '" + Style() + "' --size 8 -q --out '" + dir + "'", "SKYBAKE_LOCK_WAIT_SECONDS=0");
  EXPECT_EQ(bake.exit_code, 6) << bake.output;
  EXPECT_NE(bake.output.find("held for more than 0 s by pid 4242 on farm-node-7"), std::string::npos) << bake.output;
  for (const char* bad : {"nan", "-1", "1e9", "soon"}) {
    CommandRun refused = RunSkybake("bake '" + Style() + "' --size 8 -q --out '" + dir + "'",
                                    std::string("SKYBAKE_LOCK_WAIT_SECONDS=") + bad);
    EXPECT_EQ(refused.exit_code, 2) << bad << ": " << refused.output;
  }
  // Released: the next claim proceeds and leaves the holder's name behind.
  ::close(held);
  OutputLock taken = OutputLock::Claim(dir, {"sky_px.exr"}, 0.05);
  EXPECT_FALSE(fs::exists(dir + "/sky_px.exr"));
  taken = OutputLock();
  fs::remove_all(dir);
}

// Twenty frames of 64^3 take a few seconds: long enough to meet them.
std::string SlowSequenceBake(const std::string& schedule, const std::string& out, const std::string& extra = "") {
  return "bake '" + Style() + "' --schedule '" + schedule + "' --size 48 -q --out '" + out + "' " + extra;
}

// A fresh ROOT for a lock test, the twenty frames' schedule in it, and an
// empty ROOT/out for the bakes.
struct LockTest {
  std::string root, schedule, out;
};
LockTest FreshLockTest(const std::string& name) {
  LockTest t;
  t.root = FreshTempDir(name);
  t.schedule = WriteFile(t.root, "twenty.toml", kTwentyFrames);
  t.out = t.root + "/out";
  fs::create_directories(t.out);
  return t;
}

// Waits until `dir` holds a lock claim (a bake got past its start).
bool WaitForClaim(const std::string& dir, pid_t child) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline) {
    for (const std::string& name : FileNames(dir))
      if (name.rfind(".skybake.lock.", 0) == 0) return true;
    if (waitpid(child, nullptr, WNOHANG) == child) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return false;
}

pid_t Spawn(const std::string& args) {
  pid_t pid = fork();
  if (pid == 0) {
    execl("/bin/bash", "bash", "-c",
          (std::string("exec '") + SKYBAKE_BINARY + "' " + args + " >/dev/null 2>&1").c_str(),
          static_cast<char*>(nullptr));
    _exit(127);
  }
  return pid;
}

int WaitExit(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// --out swapped for a link while a sequence runs (the folder renamed away,
// a link to another folder put at its name, between frames 1 and 2 at the
// frame boundary the product stops at): the later frames land in the folder
// the bake locked and holds open, never in the link's target.
TEST(SafeOutputs, OutSwappedForALinkMidSequenceDoesNotRedirectLaterFrames) {
  const std::string root = FreshTempDir("outswap");
  const std::string schedule =
      WriteFile(root, "three.toml", "[schedule]\nsun = { elevation_deg = [10, 20, 30], azimuth_deg = 135 }\n");
  const std::string out = root + "/out";
  ::setenv("SKYBAKE_STOP_AFTER_FRAME", "1", 1);
  const pid_t child = Spawn("bake '" + Style() + "' --schedule '" + schedule + "' --size 8 -q --out '" + out + "'");
  ::unsetenv("SKYBAKE_STOP_AFTER_FRAME");
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, WUNTRACED), child);
  ASSERT_TRUE(WIFSTOPPED(status)) << "the bake stops itself after frame 1";
  fs::rename(out, root + "/locked");
  fs::create_directories(root + "/elsewhere");
  fs::create_directory_symlink(root + "/elsewhere", out);
  ::kill(child, SIGCONT);
  ASSERT_EQ(waitpid(child, &status, 0), child);
  EXPECT_TRUE(FileNames(root + "/elsewhere").empty()) << "nothing lands in the link's target";
  const std::set<std::string> locked = FileNames(root + "/locked");
  for (const char* name : {"sky_px.0001.exr", "sky_px.0002.exr", "sky_px.0003.exr"})
    EXPECT_TRUE(locked.count(name)) << name << " is in the folder the bake locked";
  fs::remove_all(root);
}

// Two bakes of the same files into one folder: the second, even with
// --force, stops before any GPU work with exit 6 naming the first; the first
// completes with every file matching its manifest.
TEST(SafeOutputs, SecondBakeIntoTheSameFilesIsRefusedWhileTheFirstRuns) {
  const auto [root, schedule, out] = FreshLockTest("lockbake");
  // A holder the test controls: this process claims one frame's file.
  {
    OutputLock held = OutputLock::Claim(out, {"sky_px.0007.exr"});
    CommandRun refused = RunSkybake(SlowSequenceBake(schedule, out, "--force"));
    EXPECT_EQ(refused.exit_code, 6) << refused.output;
    EXPECT_EQ(refused.output.rfind(
                  fmt::format("skybake: error: {} is being written by another skybake (pid {} on ", out, getpid()), 0),
              0u)
        << refused.output;
    EXPECT_NE(refused.output.find("which writes " + out +
                                  "/sky_px.0007.exr too: wait for it to end, or choose "
                                  "another --out"),
              std::string::npos)
        << refused.output;
    EXPECT_EQ(refused.output.find("skybake: device"), std::string::npos) << "no GPU work";
    EXPECT_EQ(FileNames(out).size(), 1u) << "nothing written but the holder's claim";
  }
  // Two real bakes: the second overlaps the running first.
  pid_t first = Spawn(SlowSequenceBake(schedule, out, "--force"));
  ASSERT_TRUE(WaitForClaim(out, first)) << "the first bake never claimed its files";
  CommandRun second = RunSkybake(SlowSequenceBake(schedule, out, "--force"));
  EXPECT_EQ(second.exit_code, 6) << second.output;
  EXPECT_NE(second.output.find(fmt::format("(pid {} on ", first)), std::string::npos) << second.output;
  // The other's command and part, not its paths (a claim is read by all
  // who share the folder).
  EXPECT_NE(second.output.find(": skybake bake), which writes"), std::string::npos)
      << "names the other's command: " << second.output;
  EXPECT_EQ(second.output.find("--schedule"), std::string::npos) << "no arguments but the part: " << second.output;
  ASSERT_EQ(WaitExit(first), 0);
  nlohmann::json manifest = nlohmann::json::parse(std::ifstream(out + "/manifest.json"));
  EXPECT_TRUE(manifest["complete"].get<bool>());
  for (const auto& frame : manifest["frames"])
    for (const auto& file : frame["files"])
      EXPECT_EQ(ReadFileBytes(out + "/" + file["file"].get<std::string>()).size(), file["bytes"].get<uint64_t>());
  for (const std::string& name : FileNames(out)) EXPECT_NE(name[0], '.') << name << " left behind";
  fs::remove_all(root);
}

// Shards of one sequence write into one folder at the same time; a part that
// overlaps a running one is refused; the merge gives the unsharded bake.
TEST(SafeOutputs, DisjointShardsShareAFolderOverlappingPartsAreRefused) {
  const auto [root, schedule, out] = FreshLockTest("lockshards");
  pid_t one = Spawn(SlowSequenceBake(schedule, out, "--shard 1/2"));
  pid_t two = Spawn(SlowSequenceBake(schedule, out, "--shard 2/2"));
  ASSERT_TRUE(WaitForClaim(out, one));
  CommandRun overlapping = RunSkybake(SlowSequenceBake(schedule, out, "--frames 10:11 --force"));
  EXPECT_EQ(overlapping.exit_code, 6) << overlapping.output;
  EXPECT_NE(overlapping.output.find("is being written by another skybake (pid "), std::string::npos)
      << overlapping.output;
  EXPECT_EQ(WaitExit(one), 0);
  EXPECT_EQ(WaitExit(two), 0);
  CommandRun merged = RunSkybake("merge-manifest '" + out + "'");
  EXPECT_EQ(merged.exit_code, 0) << merged.output;
  fs::remove_all(root);
}

// kill -9 of a bake releases its lock (the kernel drops the flock): the
// next bake into the folder proceeds and removes the dead claim.
TEST(SafeOutputs, KilledBakesLockIsReleased) {
  const auto [root, schedule, out] = FreshLockTest("lockkill");
  pid_t first = Spawn(SlowSequenceBake(schedule, out));
  ASSERT_TRUE(WaitForClaim(out, first));
  ASSERT_EQ(kill(first, SIGKILL), 0);
  EXPECT_EQ(WaitExit(first), -1);
  CommandRun resumed = RunSkybake(SlowSequenceBake(schedule, out, "--resume"));
  EXPECT_EQ(resumed.exit_code, 0) << resumed.output;
  for (const std::string& name : FileNames(out)) EXPECT_NE(name[0], '.') << name << " left behind";
  fs::remove_all(root);
}

// merge-manifest takes the lock for what it writes: a live claim on
// manifest.json (a whole bake running) refuses it, and it writes nothing.
TEST(SafeOutputs, MergeTakesTheLockOnWhatItWrites) {
  const std::string root = FreshTempDir("lockmerge");
  const std::string schedule =
      WriteFile(root, "two.toml", "[schedule]\nsun = { elevation_deg = [10, 20], azimuth_deg = 135 }\n");
  const std::string out = root + "/out";
  for (const char* shard : {"1/2", "2/2"}) {
    CommandRun part = RunSkybake("bake '" + Style() + "' --schedule '" + schedule + "' --size 8 -q --out '" + out +
                                 "' --shard " + shard);
    ASSERT_EQ(part.exit_code, 0) << part.output;
  }
  {
    OutputLock held = OutputLock::Claim(out, {"sky.glb"});
    CommandRun refused = RunSkybake("merge-manifest '" + out + "'");
    EXPECT_EQ(refused.exit_code, 6) << refused.output;
    EXPECT_NE(refused.output.find("which writes " + out + "/sky.glb too"), std::string::npos) << refused.output;
    EXPECT_FALSE(fs::exists(out + "/manifest.json"));
  }
  CommandRun merged = RunSkybake("merge-manifest '" + out + "'");
  EXPECT_EQ(merged.exit_code, 0) << merged.output;
  fs::remove_all(root);
}

// --resume reads manifest.json as input: a directory or non-JSON there is
// the folder's problem (exit 6, with the fix), a value of the wrong type
// only makes its frames bake again, and a name that is not the one this
// bake gives the frame (same style) stops it (exit 8) before it is opened.
TEST(SafeOutputs, ResumeRefusesManifestsItCannotTrust) {
  const std::string root = FreshTempDir("resumein");
  const std::string schedule =
      WriteFile(root, "two.toml", "[schedule]\nsun = { elevation_deg = [10, 20], azimuth_deg = 135 }\n");
  const std::string out = root + "/out";
  const std::string bake = "bake '" + Style() + "' --schedule '" + schedule + "' --size 8 -q --out '" + out + "'";
  ASSERT_EQ(RunSkybake(bake).exit_code, 0);
  const std::string manifest_path = out + "/manifest.json";
  const std::string good = ReadFileBytes(manifest_path);

  fs::remove(manifest_path);
  fs::create_directory(manifest_path);
  CommandRun directory = RunSkybake(bake + " --resume");
  EXPECT_EQ(directory.exit_code, 6) << directory.output;
  EXPECT_EQ(directory.output,
            "skybake: error: " + manifest_path +
                " is a directory, not a manifest, so --resume "
                "cannot tell which frames are done: move it away, or pass --force instead to bake every "
                "frame again\n");
  fs::remove(manifest_path);

  std::ofstream(manifest_path) << "not json";
  CommandRun garbage = RunSkybake(bake + " --resume");
  EXPECT_EQ(garbage.exit_code, 6) << garbage.output;
  EXPECT_EQ(garbage.output, "skybake: error: " + manifest_path +
                                " is not valid JSON, so --resume cannot tell which "
                                "frames are done: pass --force instead to bake every frame again\n");

  // `command` --resume after the good manifest's value at `pointer` is
  // changed to `value`.
  auto resume_edited = [&](const std::string& pointer, const nlohmann::json& value, const std::string& command) {
    nlohmann::json m = nlohmann::json::parse(good);
    m[nlohmann::json::json_pointer(pointer)] = value;
    std::ofstream(manifest_path) << m.dump(2);
    return RunSkybake(command + " --resume");
  };
  CommandRun typed = resume_edited("/half_scale", "one", bake);
  EXPECT_EQ(typed.exit_code, 0) << typed.output;
  EXPECT_EQ(ReadFileBytes(manifest_path), good) << "every frame baked again, to the same bytes";

  // --resume reads through merge-manifest's reader (ReadManifest), which
  // type-checks sizes: a size that is not a byte count proves no frame.
  CommandRun sized = resume_edited("/frames/0/files/0/bytes", -1,
                                   "bake '" + Style() + "' --schedule '" + schedule + "' --size 8 --out '" + out + "'");
  EXPECT_EQ(sized.exit_code, 0) << sized.output;
  EXPECT_NE(sized.output.find("resuming from 0 frame(s) in manifest.json"), std::string::npos) << sized.output;
  EXPECT_EQ(sized.output.find("files verified by checksum"), std::string::npos) << sized.output;
  EXPECT_EQ(ReadFileBytes(manifest_path), good) << "every frame baked again, to the same bytes";

  // A name or face that is not the one this bake gives the file stops it:
  // exit 8, saying so.
  auto expect_stopped = [&](const std::string& pointer, const nlohmann::json& value, const std::string& message) {
    CommandRun run = resume_edited(pointer, value, bake);
    EXPECT_EQ(run.exit_code, 8) << run.output;
    EXPECT_NE(run.output.find(message), std::string::npos) << run.output;
  };
  // A face listed as another face (its name kept) is refused too.
  expect_stopped("/frames/0/files/1/face", "+X",
                 "lists 'sky_nx.0001.exr' as face '+X' for frame 1, where this bake of the same style writes face -X "
                 "under that name");
  expect_stopped("/frames/1/files/7/file", "../../../etc/passwd",
                 "lists '../../../etc/passwd' ('latlong') for frame 2, where this bake of the same style writes "
                 "'sky_latlong.0002.exr': the manifest was edited");
  fs::remove_all(root);
}

// gallery: a second run stops at the existing sheet with a fix gallery
// accepts (--force; it advised --force and then rejected it), a link at
// gallery.png counts as a file and is replaced, never followed.
TEST(SafeOutputs, GalleryNeedsForceAndNeverWritesThroughALink) {
  const std::string root = FreshTempDir("gallery");
  const std::string styles = root + "/styles";
  fs::create_directories(styles);
  for (const char* name : {"a", "b"})
    fs::copy_file(testing::SourceDir() + "/configs/styles/" +
                      (std::string(name) == "a" ? "ambiguous_yellow.toml" : "crystal_blue.toml"),
                  styles + "/" + name + ".toml");
  const std::string out = root + "/out";
  const std::string gallery = "gallery '" + styles + "' --size 8 -q --out '" + out + "'";
  CommandRun first = RunSkybake(gallery);
  ASSERT_EQ(first.exit_code, 0) << first.output;
  const std::string sheet = ReadFileBytes(out + "/gallery.png");
  CommandRun again = RunSkybake(gallery);
  EXPECT_EQ(again.exit_code, 6) << again.output;
  EXPECT_EQ(again.output, "skybake: error: " + out +
                              "/gallery.png already exists: pass --force to replace the "
                              "gallery, or choose another --out\n");
  fs::remove(out + "/gallery.png");
  std::ofstream(root + "/victim") << "victim";
  fs::create_symlink(root + "/victim", out + "/gallery.png");
  CommandRun linked = RunSkybake(gallery);
  EXPECT_EQ(linked.exit_code, 6) << "a link is a file in the way: " << linked.output;
  CommandRun forced = RunSkybake(gallery + " --force");
  ASSERT_EQ(forced.exit_code, 0) << forced.output;
  EXPECT_EQ(ReadFileBytes(root + "/victim"), "victim");
  EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(out + "/gallery.png")));
  EXPECT_EQ(ReadFileBytes(out + "/gallery.png"), sheet);

  // A link planted at a style's folder (out/b -> a folder outside --out) is
  // refused, not followed, even with --force: nothing lands in its target;
  // a file there is refused alike.
  fs::remove_all(out + "/b");
  fs::create_directories(root + "/elsewhere");
  fs::create_directory_symlink(root + "/elsewhere", out + "/b");
  CommandRun planted = RunSkybake(gallery + " --force");
  EXPECT_EQ(planted.exit_code, 6) << planted.output;
  EXPECT_NE(planted.output.find("'" + out + "/b' is a symbolic link, not a folder"), std::string::npos)
      << planted.output;
  EXPECT_TRUE(FileNames(root + "/elsewhere").empty()) << "nothing written through the link";
  fs::remove(out + "/b");
  std::ofstream(out + "/b") << "a file";
  CommandRun file = RunSkybake(gallery + " --force");
  EXPECT_EQ(file.exit_code, 6) << file.output;
  EXPECT_NE(file.output.find("'" + out + "/b' is a file, not a folder"), std::string::npos) << file.output;
  fs::remove_all(root);
}

// What would fail only at the end is found before any GPU work: an output
// name that is a directory (even with --force: 7 files were replaced, then
// exit 5), --out naming a regular file; a dangling link at an output name
// is a file in the way (exists() followed it).
TEST(SafeOutputs, OutputsThatCannotBeWrittenAreFoundBeforeRendering) {
  const std::string root = FreshTempDir("beforegpu");
  const std::string out = root + "/out";
  const std::string bake = "bake '" + Style() + "' --size 8 --out '" + out + "'";
  ASSERT_EQ(RunSkybake(bake + " -q").exit_code, 0);
  const std::string px = ReadFileBytes(out + "/sky_px.exr");
  fs::remove(out + "/sky.glb");
  fs::create_directory(out + "/sky.glb");
  CommandRun directory = RunSkybake(bake + " --force");
  EXPECT_EQ(directory.exit_code, 5) << directory.output;
  EXPECT_EQ(directory.output, "skybake: error: " + out +
                                  "/sky.glb is a directory: an output file cannot replace "
                                  "it; move it away, or choose another --out\n");
  EXPECT_EQ(ReadFileBytes(out + "/sky_px.exr"), px);
  fs::remove(out + "/sky.glb");

  fs::remove_all(out);
  fs::create_directories(out);
  fs::create_symlink(root + "/nowhere", out + "/sky_nz.exr");
  CommandRun dangling = RunSkybake(bake + " -q");
  EXPECT_EQ(dangling.exit_code, 6) << dangling.output;
  EXPECT_NE(dangling.output.find(out + "/sky_nz.exr already exists"), std::string::npos) << dangling.output;

  std::ofstream(root + "/file") << "x";
  CommandRun file = RunSkybake("bake '" + Style() + "' --size 8 --out '" + root + "/file'");
  EXPECT_EQ(file.exit_code, 5) << file.output;
  EXPECT_EQ(file.output, "skybake: error: --out " + root +
                             "/file is not a folder: give a folder (it is created when "
                             "missing)\n");
  fs::remove_all(root);
}

// A file-size limit (ulimit -f, in KiB) stands in for a full disk: write()
// fails with EFBIG, as with ENOSPC.
TEST(SafeOutputs, FullDiskIsReportedAndLeavesNoPartialFile) {
  const std::string root = FreshTempDir("full");
  const std::string out = root + "/out";
  CommandRun run = RunSkybake("bake '" + Style() + "' --size 64 -q --set output.compression=none --out '" + out + "'",
                              "ulimit -f 16;");
  EXPECT_EQ(run.exit_code, 5) << run.output;
  EXPECT_EQ(run.output, "skybake: error: cannot write " + out + "/sky_px.exr (writing " + out + "/.sky_px.exr.tmp" +
                            run.output.substr(run.output.find(".tmp") + 4,
                                              run.output.find(": File") - run.output.find(".tmp") - 4) +
                            ": File too large): the file is larger than the file-size limit (ulimit -f) or the "
                            "file system allows\n");
  EXPECT_TRUE(FileNames(out).empty()) << "left: " << *FileNames(out).begin();
  fs::remove_all(root);
}

// `skybake check` of the default style with `sets` refuses before any GPU
// work: exit 7 and exactly "skybake: error: MESSAGE".
void ExpectCheckRefuses(const std::string& sets, const std::string& message) {
  CommandRun run = RunSkybake("check '" + Style() + "' " + sets);
  EXPECT_EQ(run.exit_code, 7) << run.output;
  EXPECT_EQ(run.output, "skybake: error: " + message + "\n");
}

// Cube 4096 with latlong 8192x4096: 235 Mtexels x 32 bytes (device buffer
// and host copy), the 101 Mtexel cube strip's RGB half copy and encoding
// (x 12 bytes), the preview (34 Mtexels x 22 bytes), the LUTs (the
// production preset's 256 x 144 sky-view LUT among them): 9025 MiB.
TEST(SafeOutputs, MemoryBudgetRefusesWithTheEstimate) {
  ExpectCheckRefuses("--set render.cube_size=4096 --set render.latlong_height=4096",
                     "the bake needs an estimated 9025 MiB of memory per frame (cube 4096, latlong 8192x4096), above "
                     "the budget of 4096 MiB: lower render.cube_size or render.latlong_height, turn off outputs, or "
                     "raise --max-memory-mib (README \"Limits\")");
  CommandRun small_budget = RunSkybake("bake '" + Style() + "' --size 64 --max-memory-mib 1 --out /nonexistent/x");
  EXPECT_EQ(small_budget.exit_code, 7) << small_budget.output;
  EXPECT_NE(small_budget.output.find("estimated 3 MiB of memory per frame"), std::string::npos) << small_budget.output;
  EXPECT_EQ(small_budget.output.find("skybake: device"), std::string::npos) << "no GPU work";
}

// A sequence counts what it keeps of each frame (the CLI: what the glTF
// scene needs of it, its manifest entry and timings on disk; and every
// frame's style): 1,000 frames at --size 1 need about 34 MiB beyond their
// tiny frames, above a 10 MiB budget, before any GPU work; ten of them
// (--frames) fit.
TEST(SafeOutputs, MemoryBudgetCountsTheSequence) {
  const std::string root = FreshTempDir("seqbudget");
  const std::string schedule = root + "/long.toml";
  std::ofstream(schedule) << "[schedule]\nsun = { elevation_deg = { start = 0, end = 89, step = "
                          << fmt::format("{:.17g}", 89.0 / 999) << " }, azimuth_deg = 135 }\n";
  const std::string out = root + "/out";
  const std::string bake = "bake '" + Style() + "' --schedule '" + schedule + "' --size 1 -q --max-memory-mib 10 ";
  CommandRun run = RunSkybake(bake + "--out '" + out + "'");
  EXPECT_EQ(run.exit_code, 7) << run.output;
  EXPECT_NE(run.output.find("the sequence needs an estimated "), std::string::npos) << run.output;
  EXPECT_NE(
      run.output.find("for what it keeps of its 1000 frames (their styles and the scene's per-frame data), above the "
                      "budget of 10 MiB: bake it in parts"),
      std::string::npos)
      << run.output;
  EXPECT_EQ(run.output.find("skybake: device"), std::string::npos) << "no GPU work";
  EXPECT_TRUE(FileNames(out).empty());
  CommandRun part = RunSkybake(bake + "--frames 1:10 --out '" + out + "'");
  EXPECT_EQ(part.exit_code, 0) << part.output;
  fs::remove_all(root);
}

// Cube 2048 and latlong 4096x2048 (58.7 Mtexels) ray-marched with 4096
// steps = 2.41e11 samples, at lavapipe's measured 1.2e7 samples/s. (The
// default sky-view LUT reads each texel once: 1.1 s for the default style.)
TEST(SafeOutputs, TimeBudgetRefusesWithTheEstimate) {
  ExpectCheckRefuses(
      "--set render.cube_size=2048 --set render.latlong_height=2048 --set quality.view_steps=4096 "
      "--set quality.sky_view_lut=false",
      "the bake needs an estimated 2.41e+11 ray-march samples per frame, about 20044 s of lavapipe "
      "time, above the budget of 3600 s per frame: lower quality.view_steps, quality.light_steps or "
      "the sizes, or raise --max-frame-seconds (README \"Limits\")");
  CommandRun ok = RunSkybake("check '" + Style() + "'");
  EXPECT_EQ(ok.exit_code, 0) << ok.output;
  EXPECT_NE(ok.output.find("estimate per frame: 142 MiB of memory (budget 4096), 0.9 s of lavapipe time"),
            std::string::npos)
      << ok.output;
}

// A view larger than the device can bind as one storage buffer (lavapipe:
// 128 MiB) is refused with the sizes, not a crash or a validation error.
TEST(SafeOutputs, ViewBeyondTheDeviceLimitIsAClearVulkanError) {
  const std::string root = FreshTempDir("devicelimit");
  CommandRun run = RunSkybake("bake '" + Style() +
                              "' --size 2048 --set output.faces=false --set output.latlong=false "
                              "--set output.preview=false --set gltf.enabled=false --out '" +
                              root + "/out'");
  EXPECT_EQ(run.exit_code, 4) << run.output;
  EXPECT_NE(run.output.find("skybake: error: Vulkan: a 2048x12288 view needs 384 MiB in one storage buffer; "),
            std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("allows 128 MiB (maxStorageBufferRange): lower render.cube_size or "
                            "render.latlong_height\n"),
            std::string::npos)
      << run.output;
  EXPECT_TRUE(FileNames(root + "/out").empty());
  fs::remove_all(root);
}

// Views that fit one by one but not together are rendered in groups: 1024
// faces and cube strip (192 MiB of views, above lavapipe's 128 MiB) under
// the validation layer.
TEST(SafeOutputs, ViewsAboveTheDeviceLimitTogetherAreRenderedInGroups) {
  const std::string root = FreshTempDir("groups");
  CommandRun run = RunSkybake("bake '" + Style() +
                              "' --size 1024 --set quality.view_steps=4 --set output.latlong=false "
                              "--set gltf.enabled=false --set output.preview=false --vulkan-validation -q --out '" +
                              root + "/out'");
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_TRUE(fs::exists(root + "/out/sky_cube.exr"));
  fs::remove_all(root);
}

}  // namespace
}  // namespace skybake
