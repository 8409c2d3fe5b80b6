// The bake's stage reports (private to the pipeline layer): each stage's
// wall time since the last, recorded in the BakeResult and passed to the
// progress callback as it finishes.
#pragma once

#include <algorithm>
#include <chrono>
#include <functional>
#include <string>

#include "skybake/output/bake_record.h"

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
    Clock::time_point end = std::min(Clock::now(), start_ + std::chrono::duration_cast<Clock::duration>(
                                                                 std::chrono::duration<double>(seconds)));
    Add({name, std::chrono::duration<double>(end - start_).count(), detail});
    start_ = end;
  }
  // A stage timed elsewhere (on the writer thread): reported, not counted
  // against the time since the last Finish.
  void Report(const std::string& name, double seconds, const std::string& detail = "") {
    Add({name, seconds, detail});
  }

 private:
  void Add(const StageReport& report) {
    result_.stages.push_back(report);
    if (progress_) progress_(report);
  }

  BakeResult& result_;
  const Callback& progress_;
  Clock::time_point start_;
};

}  // namespace skybake
