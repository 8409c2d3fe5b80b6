// A bake's progress as a person or a wrapping tool reads it. The bake itself
// never prints: it reports each stage as it finishes and each frame as it
// starts and is done (BakeOptions::progress, ::frame_progress); the CLI owns
// a ProgressReport and passes those on to it.
//
//   kLiveLine  a terminal: the stages before and after the frames one line
//              each; during the frames one line rewritten in place (carriage
//              return): frame N of M, the rate, the time left, the stage
//              ("rendering", then the last stage finished: "IBL done"); the
//              files a frame wrote print above it
//   kLines     not a terminal (a farm's log): every stage one line, and a
//              line per frame done with the same figures, no control
//              characters
//   kQuiet     nothing (--quiet: errors only)
//
// Beside any of them, JSON lines (--progress-json): one object per event,
// written and flushed as it happens:
//   {"event":"start","version":"0.1.0","commit":"...","elapsed_s":0}
//   {"event":"stage","stage":"LUTs","seconds":0.02,"detail":"...","elapsed_s":0.4}
//       (with "frame" and "of" when a frame is in progress)
//   {"event":"frame_start","frame":3,"of":96,"number":3,"elapsed_s":9.1}
//   {"event":"frame_end","frame":3,"of":96,"number":3,"frame_s":2.9,
//    "seconds_per_frame":3.0,"eta_s":279.0,"elapsed_s":12.0}
//   {"event":"end","exit_code":0,"elapsed_s":300.2}  (and "error" when it failed)
// "number" is the frame's number in file names, for sequences; "frame" runs
// 1 to "of" over the frames this run bakes.
//
// The rate is the frames done over the time from the first frame's start
// to the last one's end (the device, pipelines and exposure before them are
// not frames); the time left is the frames to go at that rate, less, on the
// live line, the time the frame under way has taken so far.
#pragma once

#include <chrono>
#include <cstdio>
#include <functional>
#include <optional>
#include <string>

#include "skybake/output/bake_record.h"
#include "skybake/pipeline/pipeline.h"

namespace skybake {

enum class ProgressStyle { kQuiet, kLines, kLiveLine };

// "42s", "6m05s", "2h07m": a time left or a frame's time, to the second.
// Text for a terminal or a log: control characters read from a file, a
// style or the command line (an escape sequence, a newline) shown as \xNN.
std::string Printable(const std::string& text);

std::string FormatDuration(double seconds);
// "4.2 s/frame" at a second or more a frame, else "14 frames/min".
std::string FormatRate(double seconds_per_frame);

class ProgressReport {
 public:
  using Clock = std::chrono::steady_clock;
  // `text`: where the lines go (stderr); `json`: the JSON lines' file, or
  // null; neither is closed here. `now` is the clock (tests give their own).
  ProgressReport(ProgressStyle style, std::FILE* text, std::FILE* json, std::string version, std::string commit,
                 std::function<Clock::time_point()> now = Clock::now);

  void Stage(const StageReport& stage);
  void Frame(const FrameProgress& frame);
  // Before lines of other output on the same terminal (the files a frame
  // wrote): the live line is cleared; Resume draws it again.
  void Suspend();
  void Resume();
  // The last event: the exit code and, when it failed, the error.
  void End(int exit_code, const std::string& error = "");

  // Callbacks for a bake that report here.
  void Attach(BakeOptions& options);

 private:
  double Elapsed() const;
  void WriteJson(const std::string& object_text);
  void DrawLiveLine();
  void ClearLiveLine();

  ProgressStyle style_;
  std::FILE* text_;
  std::FILE* json_;
  std::function<Clock::time_point()> now_;
  Clock::time_point start_;
  // The frames: the current one, how many are done, when the first started
  // and when the current one did.
  std::optional<FrameProgress> frame_;
  int done_ = 0;
  double seconds_per_frame_ = 0.0;  // as of the last frame done
  Clock::time_point first_frame_start_, frame_start_;
  std::string stage_;      // the live line's stage: "rendering", then "IBL done" (the last one finished)
  size_t live_width_ = 0;  // characters of the live line on the terminal (0: none shown)
};

}  // namespace skybake
