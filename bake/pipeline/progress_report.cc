// A bake's progress as lines, a live line and JSON lines (progress_report.h).
#include "skybake/pipeline/progress_report.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <sys/ioctl.h>
#include <unistd.h>

namespace skybake {
namespace {

using Json = nlohmann::ordered_json;

// One line of JSON; bytes of a path that are not UTF-8 become U+FFFD.
std::string Dump(const Json& j) { return j.dump(-1, ' ', false, Json::error_handler_t::replace); }

// The terminal's width in characters (80 when it cannot be told): a live
// line longer than it would wrap, and the carriage return would then not
// bring the cursor back to its start.
size_t TerminalWidth(std::FILE* file) {
  winsize size{};
  if (ioctl(fileno(file), TIOCGWINSZ, &size) == 0 && size.ws_col > 0) return size.ws_col;
  return 80;
}

}  // namespace

std::string Printable(const std::string& text) {
  std::string out;
  for (char ch : text) {
    const unsigned char c = static_cast<unsigned char>(ch);
    if (c < 0x20 || c == 0x7f) out += fmt::format("\\x{:02x}", c);
    else out += ch;
  }
  return out;
}

std::string FormatDuration(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  if (s < 60) return fmt::format("{}s", s);
  if (s < 3600) return fmt::format("{}m{:02}s", s / 60, s % 60);
  return fmt::format("{}h{:02}m", s / 3600, (s % 3600) / 60);
}

std::string FormatRate(double seconds_per_frame) {
  if (!(seconds_per_frame > 0.0)) return "-";
  if (seconds_per_frame >= 1.0) return fmt::format("{:.1f} s/frame", seconds_per_frame);
  return fmt::format("{:.0f} frames/min", 60.0 / seconds_per_frame);
}

ProgressReport::ProgressReport(ProgressStyle style, std::FILE* text, std::FILE* json, std::string version,
                               std::string commit, std::function<Clock::time_point()> now)
    : style_(style), text_(text), json_(json), now_(std::move(now)), start_(now_()) {
  WriteJson(Dump(Json{{"event", "start"}, {"version", version}, {"commit", commit}, {"elapsed_s", 0.0}}));
}

double ProgressReport::Elapsed() const { return std::chrono::duration<double>(now_() - start_).count(); }

void ProgressReport::WriteJson(const std::string& object_text) {
  if (!json_) return;
  std::fputs(object_text.c_str(), json_);
  std::fputc('\n', json_);
  std::fflush(json_);  // a wrapping tool reads each event as it happens
}

void ProgressReport::Stage(const StageReport& stage) {
  Json j = {{"event", "stage"}, {"stage", stage.name}, {"seconds", stage.seconds}, {"detail", stage.detail}};
  if (frame_) {
    j["frame"] = frame_->index;
    j["of"] = frame_->count;
  }
  j["elapsed_s"] = Elapsed();
  WriteJson(Dump(j));
  if (style_ == ProgressStyle::kQuiet) return;
  if (style_ == ProgressStyle::kLiveLine && frame_) {
    // What is known is the stage just finished; a frame's render stage is
    // named after the frame ("frame 12"), shown as "render".
    stage_ = (stage.name.rfind("frame ", 0) == 0 ? "render" : Printable(stage.name)) + " done";
    DrawLiveLine();
    return;
  }
  std::fprintf(text_, "skybake: %-10s %8.3f s  %s\n", Printable(stage.name).c_str(), stage.seconds,
               Printable(stage.detail).c_str());
}

void ProgressReport::Frame(const FrameProgress& frame) {
  const Clock::time_point now = now_();
  Json j = {{"event", frame.event == FrameProgress::Event::kStart ? "frame_start" : "frame_end"},
            {"frame", frame.index},
            {"of", frame.count}};
  if (frame.sequence) j["number"] = frame.number;
  if (frame.event == FrameProgress::Event::kStart) {
    if (frame.index == 1 || done_ == 0) first_frame_start_ = now;
    frame_start_ = now;
    frame_ = frame;
    stage_ = "rendering";
    j["elapsed_s"] = Elapsed();
    WriteJson(Dump(j));
    if (style_ == ProgressStyle::kLiveLine) DrawLiveLine();
    return;
  }
  ++done_;
  const double frame_s = std::chrono::duration<double>(now - frame_start_).count();
  const double seconds_per_frame = std::chrono::duration<double>(now - first_frame_start_).count() / done_;
  seconds_per_frame_ = seconds_per_frame;
  const double eta_s = seconds_per_frame * (frame.count - frame.index);
  j["frame_s"] = frame_s;
  j["seconds_per_frame"] = seconds_per_frame;
  j["eta_s"] = eta_s;
  j["elapsed_s"] = Elapsed();
  WriteJson(Dump(j));
  frame_ = frame;
  if (style_ == ProgressStyle::kLiveLine) {
    DrawLiveLine();
    if (frame.index == frame.count) {  // the frames are over: the line stays, later stages go below it
      std::fputc('\n', text_);
      live_width_ = 0;
    }
  } else if (style_ == ProgressStyle::kLines && frame.sequence) {
    std::fprintf(text_, "skybake: frame %d of %d (#%d) done in %.2f s, %s, %s left\n", frame.index, frame.count,
                 frame.number, frame_s, FormatRate(seconds_per_frame).c_str(), FormatDuration(eta_s).c_str());
  }
  if (frame.index == frame.count) frame_.reset();
}

void ProgressReport::DrawLiveLine() {
  if (!frame_) return;
  const int to_go = frame_->count - done_;
  // The time left counts down through a frame: the frames to go at the
  // rate, less what the one under way has taken.
  const double in_frame = frame_->event == FrameProgress::Event::kStart
                              ? std::chrono::duration<double>(now_() - frame_start_).count()
                              : 0.0;
  std::string line = fmt::format("skybake: frame {} of {}", frame_->index, frame_->count);
  if (frame_->sequence) line += fmt::format(" (#{})", frame_->number);
  if (done_ > 0) line += ", " + FormatRate(seconds_per_frame_);
  if (to_go == 0) line += ", done in " + FormatDuration(Elapsed());
  else if (done_ > 0) line += ", " + FormatDuration(seconds_per_frame_ * to_go - in_frame) + " left, " + stage_;
  else line += ", " + stage_;
  const size_t width = TerminalWidth(text_) - 1;
  if (line.size() > width) line.resize(width);
  // Over the previous line: back to its start, the new text, blanks over
  // what is left of the old.
  std::fprintf(text_, "\r%s%*s", line.c_str(), int(live_width_ > line.size() ? live_width_ - line.size() : 0), "");
  std::fflush(text_);
  live_width_ = line.size();
}

void ProgressReport::ClearLiveLine() {
  if (live_width_ == 0) return;
  std::fprintf(text_, "\r%*s\r", int(live_width_), "");
  std::fflush(text_);
  live_width_ = 0;
}

void ProgressReport::Suspend() {
  if (style_ == ProgressStyle::kLiveLine) ClearLiveLine();
}

void ProgressReport::Resume() {
  if (style_ == ProgressStyle::kLiveLine && frame_) DrawLiveLine();
}

void ProgressReport::End(int exit_code, const std::string& error) {
  if (style_ == ProgressStyle::kLiveLine && live_width_ > 0) {  // a bake that stopped mid-frame
    std::fputc('\n', text_);
    live_width_ = 0;
  }
  Json j = {{"event", "end"}, {"exit_code", exit_code}};
  if (!error.empty()) j["error"] = error;
  j["elapsed_s"] = Elapsed();
  WriteJson(Dump(j));
}

void ProgressReport::Attach(BakeOptions& options) {
  options.progress = [this](const StageReport& stage) { Stage(stage); };
  options.frame_progress = [this](const FrameProgress& frame) { Frame(frame); };
}

}  // namespace skybake
