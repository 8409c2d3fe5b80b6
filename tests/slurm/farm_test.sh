#!/usr/bin/env bash
# The README's Slurm example ("Scale-out: shards on a farm"), run as written
# on a one-node Slurm cluster (tests/slurm/cluster.sh), as root:
#
#   bash tests/slurm/farm_test.sh BUILD_DIR      # ctest: slurm_farm
#
# The README's three code blocks (batch script, submission, retry) are
# extracted from README.md and run with only these replacements, each of
# which must match once: the shared folder /shared/day by a temporary one per
# case, --size 512 by --size $SIZE, the 59-frame day schedule by a 12-frame
# one, the 8 tasks by $TASKS, --cpus-per-task=4 by 1 (the node may have 2
# CPUs) and the retried shard 5/8 by 2/$TASKS. Every bake runs under the
# Khronos validation layer (SKYBAKE_VULKAN_VALIDATION=1, passed to the jobs
# with the rest of the environment), so a validation message fails its job.
#
# Cases:
#   A  the array and the dependent merge: every task runs at the same time
#      into one folder; every EXR, PNG, manifest.json and the glTF scene are
#      byte-identical to an unsharded bake of the same command;
#   B  a task stopped part-way (SIGSTOP after its first frame, then SIGKILL
#      by scancel): the merge stays pending with DependencyNeverSatisfied and
#      never runs; the README's retry (scancel the merge, srun the shard with
#      --resume, srun the merge) keeps the frames already written and ends
#      byte-identical;
#   C  a task requeued by Slurm (scontrol requeue) part-way: it resumes (its
#      first frame's files are not rewritten) and the original merge runs
#      after it: byte-identical;
#   D  a merge run without the dependency while a task is held: exit code 8
#      naming the missing frames and the --frames that bakes them; released,
#      the task finishes and the merge is byte-identical;
#   E  task numbers 0 and above the count: exit code 2, the log says why, and
#      nothing is written.
#
# SKYBAKE_FARM_TASKS (default 3), SKYBAKE_FARM_SIZE (default 32) and
# SKYBAKE_FARM_TIMEOUT (seconds per wait, default 300) and
# SKYBAKE_FARM_TOTAL_SECONDS (every wait ends by then, default 720) change the run.
# On failure the temporary folder (job logs, daemon logs) is kept and the
# daemons' logs are printed; the cluster is stopped in every case.
set -uo pipefail

BUILD=${1:?usage: farm_test.sh BUILD_DIR}
BUILD=$(cd "$BUILD" && pwd)
SRC=$(cd "$(dirname "$0")/../.." && pwd)
TASKS=${SKYBAKE_FARM_TASKS:-3}
SIZE=${SKYBAKE_FARM_SIZE:-32}
TIMEOUT=${SKYBAKE_FARM_TIMEOUT:-300}
TOTAL=${SKYBAKE_FARM_TOTAL_SECONDS:-720}
FRAMES=12
CLUSTER=$SRC/tests/slurm/cluster.sh

tmp=$(mktemp -d /tmp/skybake-farm.XXXXXX)
chmod 755 "$tmp"    # munged wants every folder above its socket searchable by all
work=$tmp/work      # the submission folder: job logs land here
mkdir -p "$work"
failed=1
started=$(date +%s)

cleanup() {
  bash "$CLUSTER" stop "$tmp/slurm" >/dev/null 2>&1 || true
  if [ "$failed" = 0 ]; then
    rm -rf "$tmp"
  else
    echo "----- job logs in $work"
    for f in "$work"/slurm-*.out; do [ -f "$f" ] && { echo "== $f"; tail -n 20 "$f"; }; done
    bash "$CLUSTER" logs "$tmp/slurm" 2>/dev/null
    echo "farm test: kept $tmp"
    echo "slurm_farm: 0 passed, 1 failed"
  fi
}
trap cleanup EXIT
trap 'exit 1' INT TERM HUP

# The end of a wait: TIMEOUT from now, and never past TOTAL from the start
# (within ctest's 900 s, so the cluster is always stopped by this script).
deadline_in() {
  local per=$(($(date +%s) + TIMEOUT)) all=$((started + TOTAL))
  echo $((per < all ? per : all))
}

# Also inside $(...): the caller's "|| exit 1" passes it on.
fail() {
  echo "FAIL: $*" >&2
  exit 1
}
step() { echo "farm test: [$(($(date +%s) - started)) s] $*"; }

# --- The README's blocks -----------------------------------------------------
# The sh block that follows the first line containing $1.
readme_block() {
  awk -v mark="$1" 'index($0, mark) { found = 1; next }
    found && /^```sh$/ { inside = 1; next }
    inside && /^```$/ { exit }
    inside { print }' "$SRC/README.md"
}
# Replaces $2 by $3 in the text $1, which must hold $2 exactly once ($4 = all:
# every time, at least once).
replace_once() {
  local text=$1 from=$2 to=$3 count
  count=$(grep -oF -- "$from" <<<"$text" | wc -l)
  if [ "${4:-}" = all ]; then
    [ "$count" -ge 1 ] || fail "README.md's Slurm example has no '$from': update tests/slurm/farm_test.sh with the README"
    printf '%s\n' "${text//"$from"/"$to"}"
  else
    [ "$count" = 1 ] || fail "README.md's Slurm example holds '$from' $count times, not once: update tests/slurm/farm_test.sh with the README"
    printf '%s\n' "${text/"$from"/"$to"}"
  fi
}

script_text=$(readme_block '`bake-shard.sbatch`:')
submit_text=$(readme_block 'the merge as a job that waits for every task of the array:')
retry_text=$(readme_block 'shard again alone with `--resume`')
[ -n "$script_text" ] && [ -n "$submit_text" ] && [ -n "$retry_text" ] ||
  fail "README.md: the Slurm example's batch script, submission or retry block is missing"

# The text with the test's replacements; $1 = the case's shared folder.
adapt() {
  local text=$2
  text=$(replace_once "$text" /shared/day "$1" all) || exit 1
  case $text in *"--size 512"*) text=$(replace_once "$text" "--size 512" "--size $SIZE") ;; esac || exit 1
  case $text in *configs/schedules/day.toml*) text=$(replace_once "$text" configs/schedules/day.toml twelve.toml) ;; esac || exit 1
  printf '%s\n' "$text"
}
batch_script() {  # $1 folder: the batch script of that case
  local text
  text=$(adapt "$1" "$script_text") || exit 1
  text=$(replace_once "$text" "#SBATCH --array=1-8" "#SBATCH --array=1-$TASKS") || exit 1
  text=$(replace_once "$text" "#SBATCH --cpus-per-task=4" "#SBATCH --cpus-per-task=1") || exit 1
  printf '%s\n' "$text"
}

# --- Set-up ------------------------------------------------------------------
[ -x "$BUILD/skybake" ] || fail "$BUILD/skybake is missing: build first"
[ "$(id -u)" = 0 ] || fail "the Slurm daemons run as root here: run the test as root (as .ci/test does)"
export PATH=$BUILD:$PATH SKYBAKE_VULKAN_VALIDATION=1
ln -s "$SRC/configs" "$work/configs"
# 12 frames of the README's day, 06:00 to 19:45 every 75 minutes.
sed 's/times = { start = 06:00:00, end = 20:30:00, step_minutes = 15 }/times = { start = 06:00:00, end = 19:45:00, step_minutes = 75 }/' \
  "$SRC/configs/schedules/day.toml" > "$work/twelve.toml"
grep -q "step_minutes = 75" "$work/twelve.toml" || fail "configs/schedules/day.toml has no 'times = ...' line to shorten"

bash "$CLUSTER" start "$tmp/slurm" $$ || fail "the Slurm cluster did not start"
export SLURM_CONF=$tmp/slurm/slurm.conf
cd "$work" || fail "no $work"

# The reference: the batch script's own bake command, unsharded, in one go.
bake_cmd=$(batch_script "$tmp/ref" | grep -v '^#' | sed -e ':a' -e '/\\$/N; s/\\\n//; ta') || exit 1
bake_cmd=$(replace_once "$bake_cmd" ' --shard ${SLURM_ARRAY_TASK_ID}/${SLURM_ARRAY_TASK_COUNT}' '') || exit 1
step "reference bake: $bake_cmd"
eval "$bake_cmd" >/dev/null 2>"$tmp/ref.log" || { cat "$tmp/ref.log"; fail "the unsharded reference bake failed"; }
n_exr=$(ls "$tmp/ref" | grep -c '\.exr$')
n_png=$(ls "$tmp/ref" | grep -c '\.png$')
[ "$n_exr" -ge $((FRAMES * 8)) ] && [ "$n_png" = "$FRAMES" ] || fail "the reference has $n_exr EXRs and $n_png PNGs"

# --- Helpers on jobs ---------------------------------------------------------
# KEY of every record of job $1 (an array gives one line per task).
job_field() { scontrol show job -o "$1" 2>/dev/null | grep -o " $2=[^ ]*" | cut -d= -f2-; }
terminal() { case $1 in COMPLETED | FAILED | CANCELLED | TIMEOUT | NODE_FAIL | OUT_OF_MEMORY | PREEMPTED | BOOT_FAIL | DEADLINE) return 0 ;; *) return 1 ;; esac; }
# Waits until every record of job $1 is in a terminal state.
wait_done() {
  local deadline=$(deadline_in) s all
  while :; do
    all=1
    for s in $(job_field "$1" JobState); do terminal "$s" || all=0; done
    [ -n "$(job_field "$1" JobState)" ] && [ "$all" = 1 ] && return 0
    [ "$(date +%s)" -lt "$deadline" ] || fail "job $1 not finished after $TIMEOUT s: $(job_field "$1" JobState | tr '\n' ' ')"
    sleep 0.2
  done
}
# Job $1's records are all COMPLETED with exit code 0.
expect_ok() {
  local s
  for s in $(job_field "$1" JobState); do [ "$s" = COMPLETED ] || fail "job $1: state $s, expected COMPLETED"; done
  for s in $(job_field "$1" ExitCode); do [ "$s" = 0:0 ] || fail "job $1: exit code $s, expected 0:0"; done
}
# Frames listed in the shard manifest $1 (0 when it does not exist).
frames_in() { [ -f "$1" ] && grep -o '"frame": *[0-9]*' "$1" | wc -l || echo 0; }
# Shard I of TASKS: its first frame, padded like the file names.
shard_first() { printf '%04d' $(((($1 - 1) * FRAMES) / TASKS + 1)); }
shard_last() { printf '%04d' $((($1 * FRAMES) / TASKS)); }
# Waits until the shard manifest $1 lists at least one frame.
wait_first_frame() {
  local deadline=$(deadline_in)
  until [ "$(frames_in "$1")" -ge 1 ]; do
    [ "$(date +%s)" -lt "$deadline" ] || fail "$1 lists no frame after $TIMEOUT s"
    sleep 0.02
  done
}
# Folder $1 holds the reference's files byte for byte, plus the parts' manifests and timings.
expect_identical() {
  local f n=0
  for f in $(ls "$tmp/ref"); do
    case $f in timings.json) continue ;; esac
    cmp -s "$tmp/ref/$f" "$1/$f" || fail "$1/$f differs from the unsharded bake's (or is missing)"
    n=$((n + 1))
  done
  for f in $(ls "$1"); do
    case $f in manifest.shard-*.json | timings.shard-*.json) continue ;; esac
    [ -e "$tmp/ref/$f" ] || fail "$1/$f is not in the unsharded bake"
  done
  [ "$(ls "$1" | grep -c '^manifest\.shard-')" = "$TASKS" ] || fail "$1 does not hold $TASKS shard manifests"
  step "$1: $n files byte-identical to the unsharded bake ($n_exr EXRs, $n_png PNGs, manifest.json, glTF scene)"
}
# Submits the README's submission block for the case folder $1; sets JOB and MERGE.
submit() {
  batch_script "$1" > bake-shard.sbatch
  local text
  text=$(adapt "$1" "$submit_text") || exit 1
  JOB='' MERGE=''
  eval "$text" || fail "the README's submission failed"
  [ -n "$JOB" ] && [ -n "$MERGE" ] || fail "the README's submission set no JOB or MERGE"
}

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
submit "$tmp/b"
part2=$tmp/b/manifest.shard-$(shard_first 2)-$(shard_last 2).json
shard2_frames=$((10#$(shard_last 2) - 10#$(shard_first 2) + 1))
wait_first_frame "$part2"
scancel --full --signal=STOP "${JOB}_2"
sleep 0.5
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
submit "$tmp/c"
part2=$tmp/c/manifest.shard-$(shard_first 2)-$(shard_last 2).json
wait_first_frame "$part2"
scancel --full --signal=STOP "${JOB}_2"
sleep 0.5
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
echo "slurm_farm: 1 passed, 0 failed"
