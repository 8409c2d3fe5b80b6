#include "skybake/input/shard.h"

#include <charconv>
#include <cstdint>

#include <fmt/format.h>

namespace skybake {
namespace {

// A whole decimal number filling `text`, or nothing.
std::optional<int> ParseInt(std::string_view text) {
  int value = 0;
  const char* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (text.empty() || ec != std::errc() || ptr != end) return std::nullopt;
  return value;
}

// Two numbers around `separator`, e.g. "3:7" or "2/8".
std::optional<std::pair<int, int>> ParsePair(std::string_view text, char separator) {
  size_t at = text.find(separator);
  if (at == std::string_view::npos) return std::nullopt;
  std::optional<int> a = ParseInt(text.substr(0, at)), b = ParseInt(text.substr(at + 1));
  if (!a || !b) return std::nullopt;
  return std::pair{*a, *b};
}

}  // namespace

FrameRange ParseFrameRange(std::string_view text) {
  std::optional<std::pair<int, int>> pair = ParsePair(text, ':');
  if (!pair)
    throw UsageError(
        fmt::format("--frames {}: expected FIRST:LAST, frame numbers as in file names (inclusive), "
                    "e.g. --frames 1:24",
                    text));
  auto [first, last] = *pair;
  if (last < first)
    throw UsageError(
        fmt::format("--frames {}: the last frame comes before the first: use --frames {}:{}", text, last, first));
  return {first, last};
}

ShardSpec ParseShard(std::string_view text) {
  std::optional<std::pair<int, int>> pair = ParsePair(text, '/');
  if (!pair)
    throw UsageError(
        fmt::format("--shard {}: expected I/N, shard I of N counted from 1, e.g. --shard 2/8 "
                    "(the second of 8 shards)",
                    text));
  auto [index, count] = *pair;
  if (count < 1)
    throw UsageError(
        fmt::format("--shard {}: the number of shards must be at least 1: use I/N with 1 <= I <= N, "
                    "e.g. --shard 1/4",
                    text));
  if (index == 0)
    throw UsageError(
        fmt::format("--shard {}: shards are counted from 1: use 1/{} to {}/{} (add 1 to a 0-based "
                    "index such as Kubernetes' JOB_COMPLETION_INDEX)",
                    text, count, count, count));
  if (index < 0 || index > count)
    throw UsageError(fmt::format("--shard {}: shard {} does not exist among {}: use 1/{} to {}/{}", text, index, count,
                                 count, count, count));
  return {index, count};
}

FrameRange ScheduleFrameRange(const Schedule& schedule) {
  // Frames are numbered first_frame, first_frame + 1, ... (schedule.cc).
  return {schedule.frames.front().number, schedule.frames.back().number};
}

FrameRange SelectFrames(const Schedule& schedule, const std::optional<FrameRange>& frames,
                        const std::optional<ShardSpec>& shard) {
  const FrameRange all = ScheduleFrameRange(schedule);
  FrameRange selected = all;
  if (frames) {
    if (!all.Contains(frames->first) || !all.Contains(frames->last))
      throw UsageError(
          fmt::format("--frames {}:{}: {} has frames {} to {} (numbered from schedule.first_frame): "
                      "choose frames in that range, e.g. --frames {}:{}",
                      frames->first, frames->last, schedule.source_path, all.first, all.last,
                      std::max(all.first, std::min(frames->first, all.last)), all.last));
    selected = *frames;
  }
  if (shard) {
    const int64_t k = selected.count();
    if (shard->count > k)
      throw UsageError(fmt::format(
          "--shard {}/{}: {} frame{} ({} to {}) cannot make {} shards: use at most {} "
          "shards",
          shard->index, shard->count, k, k == 1 ? "" : "s", selected.first, selected.last, shard->count, k));
    // 64-bit products: a million frames times a thousand shards stays exact.
    const int begin = int(int64_t(shard->index - 1) * k / shard->count);
    const int end = int(int64_t(shard->index) * k / shard->count);
    selected = {selected.first + begin, selected.first + end - 1};
  }
  return selected;
}

}  // namespace skybake
