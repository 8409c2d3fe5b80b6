// Splitting a sequence bake across machines: `--frames a:b` selects frames
// by their number (as in file names, counted from the schedule's
// first_frame), and `--shard i/n` takes the i-th of n contiguous blocks of
// nearly equal size (i from 1 to n, as Slurm's SLURM_ARRAY_TASK_ID) of the
// selection. Contiguous blocks keep each machine's frames adjacent, so its
// renderer and LUTs carry over from one frame to the next. The split depends
// only on the schedule and the two options: every machine computes the same
// partition, with no coordination.
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "skybake/base/errors.h"
#include "skybake/input/schedule.h"

namespace skybake {

// Frame numbers first..last, inclusive, as in file names (sky_px.0007.exr).
struct FrameRange {
  int first = 1;
  int last = 1;
  int count() const { return last - first + 1; }
  bool Contains(int number) const { return number >= first && number <= last; }
};

// Shard `index` of `count`, 1 <= index <= count.
struct ShardSpec {
  int index = 1;
  int count = 1;
};

// Parse `--frames FIRST:LAST` and `--shard I/N`. Throw UsageError.
FrameRange ParseFrameRange(std::string_view text);
ShardSpec ParseShard(std::string_view text);

// Every frame of `schedule`, by number.
FrameRange ScheduleFrameRange(const Schedule& schedule);

// The frames one run bakes: `frames` (every frame when unset), then the
// shard's block of them. Block i of n holds frames [floor((i-1) k / n),
// floor(i k / n)) of the k selected, so sizes differ by at most one. Throws
// UsageError when `frames` leaves the schedule or there are more shards than
// frames.
FrameRange SelectFrames(const Schedule& schedule, const std::optional<FrameRange>& frames,
                        const std::optional<ShardSpec>& shard);

}  // namespace skybake
