#!/usr/bin/env bash
# A study write that runs out of room ends in one line on stderr and exit 1, leaves the
# previous file byte-identical and nothing temporary beside it, and no signal ends the
# process. The room runs out under a file-size limit (ulimit -f, RLIMIT_FSIZE): write(2)
# then fails as on a full disk or a spent quota, and no root-only mount is needed. The
# limit's signal, SIGXFSZ, is left at its default (death): stepbench must ignore it.
set -u
bin=${1:?usage: write_no_room_test.sh path/to/stepbench}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
bad() { echo "FAIL: $*"; fails=$((fails + 1)); }

# The sweep part alone: the writer is the same for every part (the whole quick study of the
# problem took 22 s under the sanitizers).
sweep=(sweep --quick --quiet --problem damped_spring --parts sweep)
"$bin" "${sweep[@]}" --out "$work/study.h5" >/dev/null || { echo "FAIL: the first sweep failed"; exit 1; }
cp "$work/study.h5" "$work/previous.h5"
size=$(stat -c %s "$work/study.h5")
# Room for half the study (ulimit -f counts 1024-byte blocks).
(
  ulimit -f $((size / 2048))
  exec "$bin" "${sweep[@]}" --out "$work/study.h5"
) >"$work/out" 2>"$work/err"
rc=$?
[ "$rc" -eq 1 ] || bad "exit $rc (above 128: a signal), not 1; stderr: $(cat "$work/err")"
[ "$(wc -l <"$work/err")" -eq 1 ] || bad "stderr is not one line: $(cat "$work/err")"
grep -q "cannot write results file '$work/study.h5'" "$work/err" || bad "stderr lacks the file: $(cat "$work/err")"
grep -qi "file too large" "$work/err" || bad "stderr lacks the reason: $(cat "$work/err")"
cmp -s "$work/study.h5" "$work/previous.h5" || bad "the previous study file changed"
left=$(ls "$work" | grep -v -x -e study.h5 -e previous.h5 -e out -e err)
[ -z "$left" ] || bad "left behind: $left"

[ "$fails" -eq 0 ] && echo "write_no_room: exit 1, one line, previous file kept, nothing left" || exit 1
