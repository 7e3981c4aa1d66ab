# The shell tests' shared preamble (sourced by the tests/*_test.sh scripts after they set
# `bin`, the stepbench under test, where they check refusals): a scratch folder
# `work` removed on exit, the pass and failure counts, and the check every script makes of
# a refusal. `finish NAME` prints the counts and ends the script with its status.
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0 passes=0
ok() { passes=$((passes + 1)); }
bad() { echo "FAIL: $*"; fails=$((fails + 1)); }

# expect_error "<what the one line must contain>" args...: bad usage as docs/commands.md's
# exit codes have it: exit 2, one line on stderr containing the text, and no study written
# ($work/never.h5). expect_error_re takes a grep pattern (basic, any case) for the text;
# expect_file_error (a pattern too) wants exit 1, a file that cannot be read or written.
expect_refusal() {
  local code=$1 grep_flags=$2 want=$3; shift 3
  "$bin" "$@" >"$work/out" 2>"$work/err"
  local rc=$?
  local lines; lines=$(wc -l <"$work/err")
  if [ "$rc" -ne "$code" ]; then bad "exit $rc (want $code) for: $* :: $(cat "$work/err")"; return; fi
  if [ "$lines" -ne 1 ]; then bad "$lines lines on stderr for: $* :: $(cat "$work/err")"; return; fi
  grep "$grep_flags" -- "$want" "$work/err" || { bad "message lacks '$want' for: $* :: $(cat "$work/err")"; return; }
  [ ! -e "$work/never.h5" ] || { bad "a study was written for: $*"; return; }
  ok
}
expect_error() { expect_refusal 2 -qF "$@"; }
expect_error_re() { expect_refusal 2 -qi "$@"; }
expect_file_error() { expect_refusal 1 -qi "$@"; }

finish() {
  echo "$1: $passes passed, $fails failed"
  [ "$fails" -eq 0 ]
  exit
}
