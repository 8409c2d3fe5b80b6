// The bake's stage reports (private to the pipeline layer): each stage's
// wall time since the last, recorded in the BakeResult and passed to the
// progress callback as it finishes.
#pragma once

#include <algorithm>
#include <chrono>
#include <functional>
#include <memory>
#include <string>

#include "skybake/output/bake_record.h"
#include "skybake/output/manifest.h"

namespace skybake {

using Clock = std::chrono::steady_clock;

inline double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

class StageTimer {
 public:
  using Callback = std::function<void(const StageReport&)>;
  StageTimer(BakeResult& result, const Callback& progress)
      : result_(result), progress_(progress), start_(Clock::now()) {}
  void Finish(const std::string& name, const std::string& detail = "") {
    Clock::time_point now = Clock::now();
    Add({name, std::chrono::duration<double>(now - start_).count(), detail});
    start_ = now;
  }
  // The first `seconds` of the time since the last Finish, timed elsewhere
  // (on the writer thread), as a stage of its own; the next Finish times the
  // rest.
  void Split(const std::string& name, double seconds, const std::string& detail = "") {
    Clock::time_point end = std::min(
        Clock::now(), start_ + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds)));
    Add({name, std::chrono::duration<double>(end - start_).count(), detail});
    start_ = end;
  }
  // A stage timed elsewhere (on the writer thread): reported, not counted
  // against the time since the last Finish.
  void Report(const std::string& name, double seconds, const std::string& detail = "") { Add({name, seconds, detail}); }
  // From now on, stages go to timings.json's record on disk, not into
  // result.stages, and so do the frames' timings (FrameWriter): a bake that
  // keeps no frame records (BakeOptions::keep_frame_records).
  void SpoolRecords(const std::string& dir) { spools_ = std::make_unique<TimingsSpools>(dir); }
  TimingsSpools* spools() const { return spools_.get(); }

 private:
  void Add(const StageReport& report) {
    if (spools_) spools_->stages.Add(TimingsStageText(report));
    else result_.stages.push_back(report);
    if (progress_) progress_(report);
  }

  BakeResult& result_;
  const Callback& progress_;
  Clock::time_point start_;
  std::unique_ptr<TimingsSpools> spools_;
};

}  // namespace skybake
