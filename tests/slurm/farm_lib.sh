#!/usr/bin/env bash
# Sourced by the Slurm farm tests (farm_test.sh, farm_lock_test.sh) with the
# build folder as $1 and TEST_NAME set: starts a one-node cluster
# (cluster.sh) in a temporary folder, stopped on exit, extracts the README's
# Slurm blocks, bakes the unsharded reference, and gives the helpers the cases
# use. See farm_test.sh for what is replaced in the README's text.
set -uo pipefail

BUILD=${1:?usage: $0 BUILD_DIR}
BUILD=$(cd "$BUILD" && pwd)
SRC=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
TASKS=${SKYBAKE_FARM_TASKS:-3}
SIZE=${SKYBAKE_FARM_SIZE:-32}
TIMEOUT=${SKYBAKE_FARM_TIMEOUT:-300}
TOTAL=${SKYBAKE_FARM_TOTAL_SECONDS:-720}
FRAMES=${SKYBAKE_FARM_FRAMES:-12}
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
    echo "$TEST_NAME: 0 passed, 1 failed"
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
  case $text in *configs/schedules/day.toml*) text=$(replace_once "$text" configs/schedules/day.toml frames.toml) ;; esac || exit 1
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
# skybake as a farm node has it: from its Debian packages (cpack in the build
# folder, unpacked with dpkg -x; the machine's own packages are not touched),
# on the PATH of the submission and of the jobs.
(cd "$tmp" && cpack --config "$BUILD/CPackConfig.cmake" -B "$tmp/debs" >"$tmp/cpack.log" 2>&1) ||
  { cat "$tmp/cpack.log"; fail "cpack could not build the packages"; }
for deb in "$tmp"/debs/*.deb; do dpkg -x "$deb" "$tmp/package" || fail "dpkg -x $deb"; done
export PATH=$tmp/package/usr/bin:$PATH SKYBAKE_VULKAN_VALIDATION=1
[ "$(command -v skybake)" = "$tmp/package/usr/bin/skybake" ] || fail "the packaged skybake is not the one on the PATH"
ln -s "$SRC/configs" "$work/configs"
# FRAMES frames of the README's day from 06:00, evenly spread over its 14.5 hours.
step_min=$((870 / FRAMES))
end_min=$((360 + (FRAMES - 1) * step_min))
end=$(printf '%02d:%02d:00' $((end_min / 60)) $((end_min % 60)))
sed "s/times = { start = 06:00:00, end = 20:30:00, step_minutes = 15 }/times = { start = 06:00:00, end = $end, step_minutes = $step_min }/" \
  "$SRC/configs/schedules/day.toml" > "$work/frames.toml"
grep -q "step_minutes = $step_min }" "$work/frames.toml" || fail "configs/schedules/day.toml has no 'times = ...' line to shorten"

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
# Waits until the task baking shard $1 has stopped itself at its frame
# boundary (SKYBAKE_STOP_AFTER_FRAME, set at submission: the product stops
# once that frame's files and the manifest listing them are written), so
# the fault lands at a known frame, not where a poll happens to catch it.
wait_stopped_task() {
  local deadline=$(deadline_in) pid
  while :; do
    for pid in $(pgrep -x skybake); do
      tr '\0' ' ' < "/proc/$pid/cmdline" 2>/dev/null | grep -q -- "--shard $1/$TASKS" || continue
      [ "$(ps -o stat= -p "$pid" | cut -c1)" = T ] && return 0
    done
    [ "$(date +%s)" -lt "$deadline" ] || fail "task $1 did not stop itself at its frame boundary in $TIMEOUT s"
    sleep 0.1
  done
}
# Submits the README's array ($1) with task 2 set to stop itself after its first frame.
submit_stopping_task_2() {
  export SKYBAKE_STOP_AFTER_FRAME=$((10#$(shard_first 2)))
  submit "$1"
  unset SKYBAKE_STOP_AFTER_FRAME
}
# Folder $1 holds the reference's files byte for byte, plus the parts' manifests and timings, and nothing else.
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
  # Nor hidden files: the lock's claims are gone once every writer ended.
  [ -z "$(ls -A "$1" | grep '^\.')" ] || fail "$1 holds hidden files after the merge: $(ls -A "$1" | grep '^\.' | tr '\n' ' ')"
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

