#!/usr/bin/env bash
# The output lock under Slurm: a second, overlapping submission of the
# README's array into the folder the first one is writing is refused, and the
# first one's files stay intact:
#
#   bash tests/slurm/farm_lock_test.sh BUILD_DIR      # ctest: slurm_farm_lock
#
# F  the README's array (3 tasks) into one folder; every task stops itself
#    (SKYBAKE_STOP_AFTER_FRAME=0) as soon as it holds its part's lock,
#    before its first frame;
#    the same array and merge are submitted again into the same folder:
#    every task of the second exits with code 6 before any GPU work, its log
#    naming the first array's task of the same part (pid, command) as the
#    folder's writer; no file
#    of the first changed; the second's merge is held
#    (DependencyNeverSatisfied) and cancelled; the first, resumed (SIGCONT),
#    completes, and its merge is byte-identical to an unsharded bake.
# That the tasks of one array write into one folder at once (parts that do
# not overlap share it) is case A of farm_test.sh.
TEST_NAME=slurm_farm_lock
source "$(dirname "$0")/farm_lib.sh"

step "F: the README's array, every task stopped once it holds its part's lock"
# Every task stops itself as soon as it holds its part's lock
# (SKYBAKE_STOP_AFTER_FRAME=0): before its device, pipelines and first frame,
# so no task can finish first, however fast or loaded the machine.
export SKYBAKE_STOP_AFTER_FRAME=0
submit "$tmp/f"
unset SKYBAKE_STOP_AFTER_FRAME
FIRST_JOB=$JOB FIRST_MERGE=$MERGE
for i in $(seq 1 "$TASKS"); do
  wait_stopped_task "$i"
  grep -qsF "manifest.shard-$(shard_first "$i")-$(shard_last "$i").json" "$tmp/f"/.skybake.lock.* ||
    fail "F: task $i stopped without its part's claim in the folder"
  n=$(frames_in "$tmp/f/manifest.shard-$(shard_first "$i")-$(shard_last "$i").json")
  [ "$n" = 0 ] || fail "F: task $i wrote $n frames before it stopped"
done
first_pids=$(pgrep -f "skybake bake .*--out $tmp/f " | tr '\n' ' ')
[ -n "$first_pids" ] || fail "F: no skybake process of the first array"
before=$(cd "$tmp/f" && sha256sum $(ls) | sort)

step "F: the same array and merge submitted again into the same folder"
submit "$tmp/f"
SECOND_JOB=$JOB SECOND_MERGE=$MERGE
wait_done "$SECOND_JOB"
for i in $(seq 1 "$TASKS"); do
  log=slurm-${SECOND_JOB}_$i.out
  [ "$(job_field "${SECOND_JOB}_$i" ExitCode)" = 6:0 ] ||
    fail "F: the second array's task $i exit code is $(job_field "${SECOND_JOB}_$i" ExitCode), expected 6:0: $(cat "$log")"
  grep -qF "error: $tmp/f is being written by another skybake (pid " "$log" && grep -qF -- "--shard $i/$TASKS), which writes" "$log" ||
    fail "F: the second array's task $i log does not name the first array's task $i as the folder's writer: $(cat "$log")"
  named=0
  for pid in $first_pids; do grep -qw "$pid" "$log" && named=1; done
  [ "$named" = 1 ] || fail "F: the second array's task $i log names no process of the first ($first_pids): $(cat "$log")"
done
step "F: task 1 of the second array: $(grep -i 'error:' "slurm-${SECOND_JOB}_1.out" | head -n 1)"
after=$(cd "$tmp/f" && sha256sum $(ls) | sort)
[ "$after" = "$before" ] || fail "F: the refused submission changed the first one's files: $(diff <(echo "$before") <(echo "$after") | head -n 5)"
deadline=$(deadline_in)
until [ "$(job_field "$SECOND_MERGE" Reason)" = DependencyNeverSatisfied ]; do
  [ "$(date +%s)" -lt "$deadline" ] || fail "F: the second merge is $(job_field "$SECOND_MERGE" JobState) ($(job_field "$SECOND_MERGE" Reason))"
  sleep 0.2
done
scancel "$SECOND_MERGE"

step "F: the first array resumed"
for i in $(seq 1 "$TASKS"); do scancel --full --signal=CONT "${FIRST_JOB}_$i"; done
wait_done "$FIRST_MERGE"
wait_done "$FIRST_JOB"
expect_ok "$FIRST_JOB"
expect_ok "$FIRST_MERGE"
expect_identical "$tmp/f"

failed=0
step "every case passed"
echo "$TEST_NAME: 1 passed, 0 failed"
