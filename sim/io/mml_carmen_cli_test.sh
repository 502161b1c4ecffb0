#!/bin/sh
# mml-carmen (and mml-sim --log) against hostile logs (issue 13), generated here: a gzip bomb stopped
# at --max-log-mib, trailing garbage after the gzip stream, a FIFO, a directory, a 1e300 maximum range.
# Every case must exit 1 with a message naming the file, within a timeout.
#   mml_carmen_cli_test.sh PATH/TO/mml-carmen [PATH/TO/mml-sim]
set -u
carmen="$1"
sim="${2:-}"
t=$(mktemp -d)
trap 'rm -rf "$t"' EXIT
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
expect_error() {  # NAME PATTERN COMMAND...
  name=$1 pattern=$2
  shift 2
  timeout 60 "$@" >"$t/out" 2>"$t/err" </dev/null
  rc=$?
  if [ $rc -ne 1 ]; then fail "$name: exit status $rc (expected 1): $(cat "$t/err")"; return; fi
  grep -qF -- "$pattern" "$t/err" || fail "$name: stderr lacks '$pattern': $(cat "$t/err")"
}

# 64 MiB of newlines, about 64 KB of gzip (the reported bomb: 3 GB in 13 MB).
head -c 67108864 /dev/zero | tr '\0' '\n' | gzip -1 >"$t/bomb.clf.gz"
expect_error "gzip bomb" "bomb.clf.gz: inflates to more than 8 MiB" "$carmen" info --max-log-mib 8 "$t/bomb.clf.gz"
timeout 60 "$carmen" info --max-log-mib 0 "$t/bomb.clf.gz" >/dev/null 2>"$t/err"
[ $? -eq 2 ] && grep -q -- "--max-log-mib '0' is not a size" "$t/err" || fail "bad --max-log-mib: $(cat "$t/err")"
line='FLASER 3 1.0 2.0 3.0 0 0 0 0 0 0 1.0 host 1.0'
printf '%s\n' "$line" | gzip >"$t/tail.clf.gz"
"$carmen" info "$t/tail.clf.gz" >/dev/null 2>"$t/err" || fail "clean gzip log: $(cat "$t/err")"
printf 'junk\n' >>"$t/tail.clf.gz"
expect_error "trailing garbage" "tail.clf.gz: 5 bytes of trailing garbage after the gzip stream" \
  "$carmen" info "$t/tail.clf.gz"
mkfifo "$t/fifo.clf"
expect_error "FIFO" "fifo.clf: not a regular file (a FIFO)" "$carmen" info "$t/fifo.clf"
expect_error "directory" "not a regular file (a directory)" "$carmen" info "$t"
printf 'ROBOTLASER1 0 -1.5 3.1 1.0 1e300 0.01 0 3 1 2 3 0 0 0 0 0 0 0 0 0 0 0 0 1.0 h 1.0\n' >"$t/range.clf"
expect_error "max range 1e300" "range.clf:1: field 6 (maximum_range) is '1e300'" "$carmen" info "$t/range.clf"
if [ -n "$sim" ]; then
  expect_error "mml-sim gzip bomb" "bomb.clf.gz: inflates to more than 8 MiB" \
    "$sim" --log "$t/bomb.clf.gz" --max-log-mib 8 --out "$t/run" --quiet --no-pictures
  expect_error "mml-sim FIFO log" "fifo.clf: not a regular file (a FIFO)" \
    "$sim" --log "$t/fifo.clf" --out "$t/run" --quiet --no-pictures
fi

if [ $fails -ne 0 ]; then
  echo "$fails failure(s)"
  exit 1
fi
echo "mml-carmen hostile logs: all cases passed"
