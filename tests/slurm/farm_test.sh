#!/usr/bin/env bash
# The README's Slurm example ("Scale-out: shards on a farm"), run as written
# on a one-node Slurm cluster (tests/slurm/cluster.sh), as root:
#
#   bash tests/slurm/farm_test.sh BUILD_DIR      # ctest: slurm_farm
#
# The README's three code blocks (batch script, submission, retry) are
# extracted from README.md and run with only these replacements, each of
# which must match once: the shared folder /shared/day by a temporary one per
# case, --size 512 by --size $SIZE, the 59-frame day schedule by one of
# $FRAMES frames, the 8 tasks by $TASKS, --cpus-per-task=4 by 1 (the node may have 2
# CPUs) and the retried shard 5/8 by 2/$TASKS. Every bake runs under the
# Khronos validation layer (SKYBAKE_VULKAN_VALIDATION=1, passed to the jobs
# with the rest of the environment), so a validation message fails its job.
#
# Cases:
#   A  the array and the dependent merge: every task runs at the same time
#      into one folder; every EXR, PNG, manifest.json and the glTF scene are
#      byte-identical to an unsharded bake of the same command;
#   B  a task stopped part-way (it stops itself after its first frame,
#      SKYBAKE_STOP_AFTER_FRAME, then SIGKILL by scancel): the merge stays
#      pending with DependencyNeverSatisfied and never runs; the README's
#      retry (scancel the merge, srun the shard with --resume, srun the
#      merge) keeps the frames already written and ends byte-identical;
#   C  a task requeued by Slurm (scontrol requeue) part-way, stopped after
#      its first frame as in B: it resumes (its first frame's files are not
#      rewritten) and the original merge runs after it: byte-identical;
#   D  a merge run without the dependency while a task is held: exit code 8
#      naming the missing frames and the --frames that bakes them; released,
#      the task finishes and the merge is byte-identical;
#   E  task numbers 0 and above the count: exit code 2, the log says why, and
#      nothing is written.
#
# SKYBAKE_FARM_TASKS (default 3), SKYBAKE_FARM_FRAMES (default 12, 4 or more
# per task), SKYBAKE_FARM_SIZE (default 32),
# SKYBAKE_FARM_TIMEOUT (seconds per wait, default 300) and
# SKYBAKE_FARM_TOTAL_SECONDS (every wait ends by then, default 720) change the run.
# On failure the temporary folder (job logs, daemon logs) is kept and the
# daemons' logs are printed; the cluster is stopped in every case.
TEST_NAME=slurm_farm
source "$(dirname "$0")/farm_lib.sh"

# --- A: the README's array and merge ----------------------------------------
step "A: sbatch of the README's script, $TASKS tasks, $FRAMES frames at $SIZE, merge after them"
submit "$tmp/a"
# Every task must run at the same time as the others, into the one folder.
most=0
deadline=$(deadline_in)
while :; do
  running=$(job_field "$JOB" JobState | grep -c '^RUNNING$')
  [ "$running" -gt "$most" ] && most=$running
  all=1
  for s in $(job_field "$MERGE" JobState); do terminal "$s" || all=0; done
  [ "$all" = 1 ] && break
  [ "$(date +%s)" -lt "$deadline" ] || fail "A: the merge has not finished after $TIMEOUT s"
  sleep 0.1
done
expect_ok "$JOB"
expect_ok "$MERGE"
[ "$most" = "$TASKS" ] || fail "A: at most $most of the $TASKS tasks ran at once"
step "A: all $TASKS tasks ran at once"
expect_identical "$tmp/a"

# --- B: a task killed part-way, the merge held, the README's retry ----------
step "B: task 2 stopped after its first frame and killed"
submit_stopping_task_2 "$tmp/b"
part2=$tmp/b/manifest.shard-$(shard_first 2)-$(shard_last 2).json
shard2_frames=$((10#$(shard_last 2) - 10#$(shard_first 2) + 1))
wait_stopped_task 2
done_frames=$(frames_in "$part2")
[ "$done_frames" -ge 1 ] && [ "$done_frames" -lt "$shard2_frames" ] ||
  fail "B: task 2 was not stopped part-way: its manifest lists $done_frames of $shard2_frames frames"
first2=$tmp/b/sky_px.$(shard_first 2).exr
before=$(stat -c '%i %Y.%y' "$first2")
scancel --full --signal=KILL "${JOB}_2"
wait_done "$JOB"
state2=$(job_field "${JOB}_2" JobState)
[ "$state2" != COMPLETED ] || fail "B: task 2 completed although it was killed"
deadline=$(deadline_in)
until [ "$(job_field "$MERGE" Reason)" = DependencyNeverSatisfied ]; do
  [ "$(date +%s)" -lt "$deadline" ] || fail "B: the merge is $(job_field "$MERGE" JobState) ($(job_field "$MERGE" Reason)), not held by DependencyNeverSatisfied"
  sleep 0.2
done
[ "$(job_field "$MERGE" JobState)" = PENDING ] || fail "B: the merge is not pending"
[ ! -e "$tmp/b/manifest.json" ] && [ ! -e "$work/slurm-$MERGE.out" ] || fail "B: the merge ran although task 2 failed"
step "B: task 2 $state2 after $done_frames of $shard2_frames frames; the merge pending, DependencyNeverSatisfied"
retry=$(adapt "$tmp/b" "$retry_text") || exit 1
retry=$(replace_once "$retry" "--shard 5/8" "--shard 2/$TASKS") || exit 1
eval "$retry" > "$tmp/retry.log" 2>&1 || { cat "$tmp/retry.log"; fail "B: the README's retry failed"; }
[ -z "$(job_field "$MERGE" JobState)" ] || [ "$(job_field "$MERGE" JobState)" = CANCELLED ] || fail "B: the held merge was not cancelled"
[ "$(stat -c '%i %Y.%y' "$first2")" = "$before" ] || fail "B: the retry rewrote $first2 instead of keeping it"
step "B: the retry with --resume kept the frames done and baked the rest"
expect_identical "$tmp/b"

# --- C: a task requeued by Slurm part-way resumes ---------------------------
step "C: task 2 requeued by scontrol after its first frame"
submit_stopping_task_2 "$tmp/c"
part2=$tmp/c/manifest.shard-$(shard_first 2)-$(shard_last 2).json
wait_stopped_task 2
done_frames=$(frames_in "$part2")
[ "$done_frames" -ge 1 ] && [ "$done_frames" -lt "$shard2_frames" ] ||
  fail "C: task 2 was not stopped part-way: its manifest lists $done_frames of $shard2_frames frames"
first2=$tmp/c/sky_px.$(shard_first 2).exr
before=$(stat -c '%i %Y.%y' "$first2")
scontrol requeue "${JOB}_2" || fail "C: scontrol requeue failed"
# Slurm holds a requeued job for 2 minutes before it may start again; start it now.
deadline=$(deadline_in)
until [ "$(job_field "${JOB}_2" JobState)" = PENDING ] && scontrol update jobid="${JOB}_2" StartTime=now 2>/dev/null; do
  [ "$(date +%s)" -lt "$deadline" ] || fail "C: the requeued task is $(job_field "${JOB}_2" JobState), not pending again"
  sleep 0.2
done
wait_done "$MERGE"
wait_done "$JOB"
expect_ok "$JOB"
expect_ok "$MERGE"
restarts=$(job_field "${JOB}_2" Restarts)
[ "$restarts" = 1 ] || fail "C: task 2 restarted $restarts times, expected 1"
[ "$(stat -c '%i %Y.%y' "$first2")" = "$before" ] || fail "C: the requeued task rewrote $first2 instead of keeping it"
step "C: task 2 requeued after $done_frames of $shard2_frames frames, resumed, the merge ran after it"
expect_identical "$tmp/c"

# --- D: a merge before every task finished ----------------------------------
step "D: merge while task $TASKS is held"
batch_script "$tmp/d" > bake-shard.sbatch
JOB=$(sbatch --parsable --hold bake-shard.sbatch) || fail "D: sbatch --hold failed"
for i in $(seq 1 $((TASKS - 1))); do scontrol release "${JOB}_$i" || fail "D: could not release task $i"; done
deadline=$(deadline_in)
until [ "$(job_field "$JOB" JobState | grep -c '^COMPLETED$')" = $((TASKS - 1)) ]; do
  [ "$(date +%s)" -lt "$deadline" ] || fail "D: tasks 1 to $((TASKS - 1)) not completed after $TIMEOUT s"
  sleep 0.2
done
early=$(sbatch --parsable --wrap "skybake merge-manifest $tmp/d")
wait_done "$early"
[ "$(job_field "$early" ExitCode)" = 8:0 ] || fail "D: the early merge's exit code is $(job_field "$early" ExitCode), expected 8:0"
a=$((10#$(shard_first "$TASKS"))) b=$((10#$(shard_last "$TASKS")))
grep -q "frames $a-$b of 1-$FRAMES are missing" "slurm-$early.out" && grep -q -- "--frames $a:$b" "slurm-$early.out" ||
  fail "D: the early merge's log does not name frames $a-$b and --frames $a:$b: $(cat "slurm-$early.out")"
[ ! -e "$tmp/d/manifest.json" ] && [ ! -e "$tmp/d/sky.gltf" ] || fail "D: the early merge wrote files"
step "D: the early merge exited 8: $(grep -o 'frames [0-9-]* of [0-9-]* are missing' "slurm-$early.out")"
scontrol release "${JOB}_$TASKS" || fail "D: could not release task $TASKS"
wait_done "$JOB"
expect_ok "$JOB"
merge=$(sbatch --parsable --dependency=afterok:$JOB --wrap "skybake merge-manifest $tmp/d")
wait_done "$merge"
expect_ok "$merge"
expect_identical "$tmp/d"

# --- E: bad task numbers ----------------------------------------------------
# An array 0,7 has 2 tasks: shard 0/2 and 7/2, neither of which exists.
step "E: an array of the task numbers 0 and 7"
batch_script "$tmp/e" > bake-shard.sbatch
JOB=$(sbatch --parsable --array=0,7 bake-shard.sbatch) || fail "E: sbatch failed"
wait_done "$JOB"
for id in 0 7; do
  [ "$(job_field "${JOB}_$id" ExitCode)" = 2:0 ] || fail "E: task $id's exit code is $(job_field "${JOB}_$id" ExitCode), expected 2:0"
  [ "$(job_field "${JOB}_$id" JobState)" = FAILED ] || fail "E: task $id is $(job_field "${JOB}_$id" JobState), expected FAILED"
done
grep -q "error: --shard 0/2: shards are counted from 1" "slurm-${JOB}_0.out" ||
  fail "E: task 0's log does not say why: $(cat "slurm-${JOB}_0.out")"
grep -q "error: --shard 7/2: shard 7 does not exist among 2" "slurm-${JOB}_7.out" ||
  fail "E: task 7's log does not say why: $(cat "slurm-${JOB}_7.out")"
[ -z "$(ls -A "$tmp/e" 2>/dev/null)" ] || fail "E: the bad tasks wrote $(ls "$tmp/e" | head -n 3)"
step "E: task 0: $(head -n 1 "slurm-${JOB}_0.out")"
step "E: task 7: $(head -n 1 "slurm-${JOB}_7.out")"

failed=0
step "every case passed"
echo "$TEST_NAME: 1 passed, 0 failed"
