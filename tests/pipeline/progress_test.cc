// A bake's progress (progress_report.h): the figures' formats; the report
// on a clock of the test's own, as lines, as a live line and as JSON lines;
// and the binary on a five-frame sequence off a terminal (a line per frame,
// no control characters), on a terminal (script(1) gives it one: one line
// rewritten in place), with --quiet (nothing on stderr) and with
// --progress-json (events parsed: frames in order, figures consistent), and
// a --progress-json path that cannot be written (exit 5 before anything is
// touched).
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "skybake/pipeline/progress_report.h"
#include "test_support.h"

namespace skybake {
namespace {

using nlohmann::json;
using Clock = ProgressReport::Clock;

std::string FiveFrames() {
  return "bake " + testing::SourceDir() + "/configs/default.toml --schedule " + testing::SourceDir() +
         "/tests/golden/five_frames.toml --size 16 --set gltf.enabled=false";
}

// The lines of a text.
std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  size_t start = 0;
  for (size_t end; (end = text.find('\n', start)) != std::string::npos; start = end + 1)
    lines.push_back(text.substr(start, end - start));
  if (start < text.size()) lines.push_back(text.substr(start));
  return lines;
}

// Everything written to a temporary file, read back.
std::string Contents(std::FILE* file) {
  std::fflush(file);
  std::rewind(file);
  std::string text;
  for (int c; (c = std::fgetc(file)) != EOF;) text += char(c);
  return text;
}

TEST(ProgressTest, DurationsAndRates) {
  EXPECT_EQ(FormatDuration(0.0), "0s");
  EXPECT_EQ(FormatDuration(42.4), "42s");
  EXPECT_EQ(FormatDuration(59.6), "1m00s");
  EXPECT_EQ(FormatDuration(365.0), "6m05s");
  EXPECT_EQ(FormatDuration(7620.0), "2h07m");
  EXPECT_EQ(FormatDuration(-3.0), "0s");
  EXPECT_EQ(FormatRate(4.24), "4.2 s/frame");
  EXPECT_EQ(FormatRate(1.0), "1.0 s/frame");
  EXPECT_EQ(FormatRate(0.25), "240 frames/min");
  EXPECT_EQ(FormatRate(0.0), "-");
}

// Three frames of 10 s each after 5 s of set-up, on the test's clock.
struct FakeBake {
  Clock::time_point t{};
  std::FILE* text = std::tmpfile();
  std::FILE* json = std::tmpfile();
  ~FakeBake() {
    std::fclose(text);
    std::fclose(json);
  }
  void Run(ProgressStyle style) {
    ProgressReport report(style, text, json, "1.2.3", "abc", [this] { return t; });
    t += std::chrono::seconds(5);
    report.Stage({"LUTs", 5.0, "transmittance 256x64"});
    for (int k = 1; k <= 3; ++k) {
      report.Frame({FrameProgress::Event::kStart, k, 3, 10 + k, true});
      t += std::chrono::seconds(8);
      report.Stage({"frame " + std::to_string(10 + k), 8.0, "8 views"});
      t += std::chrono::seconds(2);
      report.Stage({"IBL", 2.0, "specular"});
      report.Suspend();
      std::fputs("face  out/sky_px.exr  100 bytes\n", text);
      report.Resume();
      report.Frame({FrameProgress::Event::kDone, k, 3, 10 + k, true});
    }
    report.Stage({"manifest", 0.0, "out/manifest.json"});
    report.End(0);
  }
};

TEST(ProgressTest, LinesOffATerminal) {
  FakeBake bake;
  bake.Run(ProgressStyle::kLines);
  const std::string text = Contents(bake.text);
  EXPECT_EQ(text.find('\r'), std::string::npos);
  const std::vector<std::string> lines = Lines(text);
  const std::vector<std::string> frames = {"skybake: frame 1 of 3 (#11) done in 10.00 s, 10.0 s/frame, 20s left",
                                           "skybake: frame 2 of 3 (#12) done in 10.00 s, 10.0 s/frame, 10s left",
                                           "skybake: frame 3 of 3 (#13) done in 10.00 s, 10.0 s/frame, 0s left"};
  std::vector<std::string> seen;
  for (const std::string& line : lines)
    if (line.rfind("skybake: frame ", 0) == 0 && line.find(" of 3 ") != std::string::npos) seen.push_back(line);
  EXPECT_EQ(seen, frames) << text;
  EXPECT_NE(text.find("skybake: LUTs          5.000 s  transmittance 256x64\n"), std::string::npos) << text;
  EXPECT_NE(text.find("skybake: IBL           2.000 s  specular\n"), std::string::npos) << text;
}

TEST(ProgressTest, LiveLineOnATerminal) {
  FakeBake bake;
  bake.Run(ProgressStyle::kLiveLine);
  const std::string text = Contents(bake.text);
  // Set-up and closing stages on lines of their own; the frames on one line
  // rewritten after a carriage return, the files printed above it.
  EXPECT_EQ(text.rfind("skybake: LUTs          5.000 s  transmittance 256x64\n\r", 0), 0u) << text;
  EXPECT_NE(text.find("\rskybake: frame 2 of 3 (#12), 10.0 s/frame, 20s left, rendering"), std::string::npos) << text;
  EXPECT_NE(text.find("\rskybake: frame 2 of 3 (#12), 10.0 s/frame, 12s left, render done"), std::string::npos)
      << "the rate of the frames done, the time left counting down: " << text;
  EXPECT_NE(text.find("face  out/sky_px.exr  100 bytes\n"), std::string::npos) << text;
  EXPECT_EQ(text.find("skybake: IBL  "), std::string::npos) << "no stage line during the frames: " << text;
  const size_t last = text.rfind("\rskybake: frame 3 of 3 (#13), 10.0 s/frame, done in 35s");
  ASSERT_NE(last, std::string::npos) << text;
  EXPECT_EQ(text.substr(text.find('\n', last)), "\nskybake: manifest      0.000 s  out/manifest.json\n") << text;
}

TEST(ProgressTest, JsonLines) {
  FakeBake bake;
  bake.Run(ProgressStyle::kQuiet);
  EXPECT_EQ(Contents(bake.text).find("skybake:"), std::string::npos) << "only the files FakeBake prints itself";
  std::vector<json> events;
  for (const std::string& line : Lines(Contents(bake.json))) events.push_back(json::parse(line));
  ASSERT_EQ(events.size(), 1u + 1 + 3 * 4 + 1 + 1);
  EXPECT_EQ(events.front(), json::parse(R"({"event":"start","version":"1.2.3","commit":"abc","elapsed_s":0.0})"));
  EXPECT_EQ(events[2], json::parse(R"({"event":"frame_start","frame":1,"of":3,"number":11,"elapsed_s":5.0})"));
  EXPECT_EQ(events[3], json::parse(R"({"event":"stage","stage":"frame 11","seconds":8.0,"detail":"8 views",
                                       "frame":1,"of":3,"elapsed_s":13.0})"));
  EXPECT_EQ(events[5], json::parse(R"({"event":"frame_end","frame":1,"of":3,"number":11,"frame_s":10.0,
                                       "seconds_per_frame":10.0,"eta_s":20.0,"elapsed_s":15.0})"));
  EXPECT_EQ(events.back(), json::parse(R"({"event":"end","exit_code":0,"elapsed_s":35.0})"));
}

// The binary, off a terminal: every stage a line, a line per frame with
// the same figures, no control character; the JSON lines beside.
TEST(ProgressCliTest, FiveFramesOffATerminalAndAsJson) {
  const std::string dir = testing::FreshTempDir("progress_lines");
  const std::string events_path = dir + "/progress.jsonl";
  testing::CommandRun run = testing::RunSkybake(FiveFrames() + " --out " + dir + "/out --progress-json " + events_path);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  for (char c : run.output)
    EXPECT_TRUE(c == '\n' || (static_cast<unsigned char>(c) >= 0x20 && c != 0x7f)) << "control character " << int(c);
  const std::regex frame_line(R"(skybake: frame (\d) of 5 \(#(\d)\) done in (\d+\.\d\d) s, )"
                              R"((\d+(\.\d)? s/frame|\d+ frames/min), (\d+s|\d+m\d\ds|\d+h\d\dm) left)");
  int frames = 0;
  for (const std::string& line : Lines(run.output)) {
    std::smatch m;
    if (line.rfind("skybake: frame ", 0) == 0 && line.find(" done in ") != std::string::npos) {
      ASSERT_TRUE(std::regex_match(line, m, frame_line)) << line;
      ++frames;
      EXPECT_EQ(std::stoi(m[1]), frames) << line;
      EXPECT_EQ(std::stoi(m[2]), frames) << "five_frames.toml numbers from 1: " << line;
    }
  }
  EXPECT_EQ(frames, 5) << run.output;
  EXPECT_NE(run.output.find("skybake: device"), std::string::npos) << "stage lines too: " << run.output;

  // The JSON lines: start, stages, frames 1..5 each started then ended in
  // order, end with exit code 0; times never go back; the figures agree.
  std::vector<json> events;
  for (const std::string& line : Lines(testing::ReadFileBytes(events_path))) {
    json event = json::parse(line, nullptr, false);
    ASSERT_FALSE(event.is_discarded()) << line;
    events.push_back(event);
  }
  ASSERT_GE(events.size(), 12u);
  EXPECT_EQ(events.front()["event"], "start");
  EXPECT_EQ(events.front()["version"], SKYBAKE_VERSION);
  EXPECT_EQ(events.back()["event"], "end");
  EXPECT_EQ(events.back()["exit_code"], 0);
  double elapsed = 0.0;
  int started = 0, ended = 0;
  for (const json& e : events) {
    EXPECT_GE(e["elapsed_s"].get<double>(), elapsed) << e.dump();
    elapsed = e["elapsed_s"].get<double>();
    if (e["event"] == "frame_start") {
      EXPECT_EQ(e["frame"], ended + 1) << e.dump();
      EXPECT_EQ(started, ended) << "a frame starts after the one before ended: " << e.dump();
      started = e["frame"];
    } else if (e["event"] == "frame_end") {
      EXPECT_EQ(e["frame"], started) << e.dump();
      ended = e["frame"];
      EXPECT_EQ(e["of"], 5);
      EXPECT_EQ(e["number"], ended);
      EXPECT_NEAR(e["eta_s"].get<double>(), e["seconds_per_frame"].get<double>() * (5 - ended), 1e-9);
      EXPECT_GT(e["frame_s"].get<double>(), 0.0);
    } else if (e["event"] == "stage" && started > ended) {
      EXPECT_EQ(e["frame"], started) << "a stage during a frame names it: " << e.dump();
    }
  }
  EXPECT_EQ(ended, 5);
  std::filesystem::remove_all(dir);
}

// On a terminal (script(1) runs it on a pseudo-terminal): the frames on one
// line rewritten after carriage returns, ending "done in".
TEST(ProgressCliTest, FiveFramesOnATerminal) {
  const std::string dir = testing::FreshTempDir("progress_tty");
  const std::string command = std::string(SKYBAKE_BINARY) + " " + FiveFrames() + " --out " + dir + "/out";
  auto [status, output] = testing::RunCommand("script -qec '" + command + " > " + dir + "/stdout.txt' /dev/null");
  ASSERT_EQ(status, 0) << output;
  EXPECT_NE(output.find("\rskybake: frame 1 of 5 (#1), rendering"), std::string::npos) << output;
  EXPECT_NE(output.find("\rskybake: frame 5 of 5 (#5), "), std::string::npos) << output;
  EXPECT_TRUE(std::regex_search(output, std::regex(R"(\rskybake: frame 5 of 5 \(#5\), [^\r\n]*, done in \d+s)")))
      << output;
  EXPECT_EQ(output.find("done in 0."), std::string::npos) << "no per-frame lines on a terminal: " << output;
  std::filesystem::remove_all(dir);
}

// --quiet: errors only. Nothing on stderr for a bake that works (the files
// written still go to stdout); a failed bake says why.
TEST(ProgressCliTest, QuietKeepsErrorsOnly) {
  const std::string dir = testing::FreshTempDir("progress_quiet");
  testing::CommandRun run = testing::RunSkybake(FiveFrames() + " -q --out " + dir + "/out");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  for (const std::string& line : Lines(run.output))
    EXPECT_NE(line.rfind("skybake:", 0), 0u) << "not even the half-range warning: " << line;
  EXPECT_NE(run.output.find("manifest  " + dir + "/out/manifest.json"), std::string::npos) << run.output;
  testing::CommandRun again = testing::RunSkybake(FiveFrames() + " -q --out " + dir + "/out");
  EXPECT_EQ(again.exit_code, 6) << again.output;
  EXPECT_EQ(again.output.rfind("skybake: error: ", 0), 0u) << again.output;
  std::filesystem::remove_all(dir);
}

// A --progress-json path that cannot be written: exit 5 and the reason,
// before anything else (no output folder, no device); a bake that fails
// later ends its stream with its exit code and error.
TEST(ProgressCliTest, UnwritableProgressPathStopsBeforeAnything) {
  const std::string dir = testing::FreshTempDir("progress_unwritable");
  for (const std::string& path : {dir + "/no/such/folder/progress.jsonl", dir}) {
    testing::CommandRun run = testing::RunSkybake(FiveFrames() + " --out " + dir + "/out --progress-json " + path);
    EXPECT_EQ(run.exit_code, 5) << run.output;
    EXPECT_EQ(run.output.rfind("skybake: error: --progress-json " + path + " cannot be written: ", 0), 0u)
        << run.output;
    EXPECT_NE(run.output.find("; nothing was baked\n"), std::string::npos) << run.output;
    EXPECT_EQ(run.output.find("skybake: device"), std::string::npos) << run.output;
    EXPECT_FALSE(std::filesystem::exists(dir + "/out")) << "the output folder was touched";
  }
  EXPECT_EQ(testing::FileNames(dir), std::set<std::string>{}) << "nothing written";

  // A bake refused later (its outputs exist): the stream's last event says so.
  testing::CommandRun first = testing::RunSkybake(FiveFrames() + " -q --out " + dir + "/out");
  ASSERT_EQ(first.exit_code, 0) << first.output;
  testing::CommandRun refused =
      testing::RunSkybake(FiveFrames() + " -q --out " + dir + "/out --progress-json " + dir + "/p.jsonl");
  EXPECT_EQ(refused.exit_code, 6) << refused.output;
  const std::vector<std::string> lines = Lines(testing::ReadFileBytes(dir + "/p.jsonl"));
  ASSERT_FALSE(lines.empty());
  const json end = json::parse(lines.back());
  EXPECT_EQ(end["event"], "end");
  EXPECT_EQ(end["exit_code"], 6);
  EXPECT_NE(end.value("error", "").find("already exists"), std::string::npos) << end.dump();
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace skybake
