#!/usr/bin/env bash
# Runs that never lose anything: a real run interrupted by SIGINT or SIGTERM leaves the
# previous results file (and report folder) byte-identical, and no temporary file behind.
# The one exception is a signal after the atomic rename that puts the new results in
# place (the run's last milliseconds): the target then holds the new results, complete.
# Each command is first timed whole, then interrupted at fractions of that time, so that
# some interruptions land during the long work and some near the end: during the write
# of the study file, or the swap of the report folder into place.
set -u
set -m  # job control: background jobs keep SIGINT's default action (bash ignores it otherwise)
stepbench=${1:?usage: interrupt_test.sh path/to/stepbench path/to/stepbench_bench path/to/scripts/report}
bench=${2:?}
report=${3:?}
. "$(dirname "${BASH_SOURCE[0]}")/expect.sh"

snapshot() { (cd "$work" && find . -type f -not -name err -print0 | sort -z | xargs -0 sha256sum); }

# interrupt SIGNAL DELAY_S CMD...: starts CMD, sends SIGNAL after DELAY_S; when the run was
# interrupted, the folder must be exactly as before (a run that finished first is not a
# test), unless the signal came after the rename. That case passes only when the folder
# holds the same names as before (nothing temporary or stray), the target changed, and
# the command in `complete` (set per run below) confirms the new target is whole.
interrupted=0 finished=0 replaced=0
complete=(false)
names() { (cd "$work" && find . -not -name err | sort); }
interrupt() {
  local sig=$1 delay=$2; shift 2
  local before before_names; before=$(snapshot) before_names=$(names)
  "$@" >/dev/null 2>"$work/err" &
  local pid=$!
  sleep "$delay"
  kill -s "$sig" "$pid" 2>/dev/null
  wait "$pid" 2>/dev/null
  local rc=$?
  if [ "$rc" -eq 0 ]; then  # finished before the signal
    finished=$((finished + 1))
    return
  fi
  interrupted=$((interrupted + 1))
  [ "$before" = "$(snapshot)" ] && { ok; return; }
  if [ "$before_names" = "$(names)" ] && "${complete[@]}" >/dev/null 2>&1; then
    replaced=$((replaced + 1))
    ok
    return
  fi
  bad "$* interrupted by SIG$sig at ${delay}s (exit $rc) changed the folder: $(diff <(echo "$before") <(snapshot) | head -4)"
}

# duration CMD...: the seconds CMD takes, run to completion into a scratch target.
duration() {
  local t0 t1; t0=$(date +%s.%N); "$@" >/dev/null 2>&1; t1=$(date +%s.%N)
  awk -v a="$t0" -v b="$t1" 'BEGIN { print b - a }'
}

# interrupt_throughout SCRATCH TARGET CMD...: times CMD whole with __TARGET__ replaced by
# SCRATCH, then interrupts it at 10 % .. 99 % of that time, with both signals, writing to
# TARGET (the previous results, which must survive).
interrupt_throughout() {
  local scratch=$1 target=$2; shift 2
  local total; total=$(duration "${@//__TARGET__/$scratch}")
  for frac in 0.1 0.3 0.5 0.7 0.9 0.99; do
    for sig in INT TERM; do
      interrupt "$sig" "$(awk -v t="$total" -v f="$frac" 'BEGIN { print t * f }')" "${@//__TARGET__/$target}"
    done
  done
}

echo "previous results" >"$work/study.h5"
complete=("$stepbench" compare "$work/study.h5" "$work/study.h5")  # exit 0: a whole study file
# (the snapshot says study.h5 changed; the names say nothing else did)
interrupt_throughout "$work/scratch.h5" "$work/study.h5" "$stepbench" sweep --quick --parts sweep --quiet --problem pendulum --problem damped_spring --out __TARGET__
interrupt_throughout "$work/scratch.h5" "$work/study.h5" "$bench" --quick --parts=sweep --problem=pendulum --benchmark_filter=pendulum --study_out=__TARGET__
rm -f "$work/scratch.h5"
# Unless a run finished before its signal, or was signalled after its rename (and rightly
# replaced it), the file is the first one.
[ "$finished" -gt 0 ] || [ "$replaced" -gt 0 ] || { [ "$(cat "$work/study.h5")" = "previous results" ] && ok || bad "the previous study file was touched"; }

# The report: a previous report folder survives an interrupted run whole.
"$stepbench" sweep --quick --parts sweep,verdict --quiet --problem pendulum --out "$work/good.h5" 2>/dev/null || bad "quick sweep for the report failed"
/usr/bin/python3 "$report" "$work/good.h5" --out "$work/report" >/dev/null 2>&1 || bad "report failed"
# The report says so itself when the signal came after its swap (a whole new folder).
complete=(grep -q "after the new report was in place" "$work/err")
interrupt_throughout "$work/scratch_report" "$work/report" /usr/bin/python3 "$report" "$work/good.h5" --out __TARGET__
rm -rf "$work/scratch_report"
[ -f "$work/report/REPORT.md" ] && ok || bad "the previous report folder is gone"
[ "$interrupted" -ge 20 ] && ok || bad "only $interrupted runs were interrupted before they finished"

echo "interrupt: $passes passed, $fails failed ($interrupted runs interrupted, $replaced of them after the rename;" \
  "$finished finished first)"
[ "$fails" -eq 0 ]
