#!/bin/sh
# mml-mapc against hostile inputs (issue 13), each generated here: every case must end with exit
# status 1 (not an abort: 134) and a message naming the input, within a timeout (no hang), and a
# failed compile must leave no output file (and an older one untouched).
#   mml_mapc_cli_test.sh PATH/TO/mml-mapc
set -u
mapc="$1"
t=$(mktemp -d)
trap 'rm -rf "$t"' EXIT
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }

# expect_error NAME PATTERN ARGS...: exit 1 within 20 s and PATTERN in stderr.
expect_error() {
  name=$1 pattern=$2
  shift 2
  timeout 20 "$mapc" "$@" >"$t/out" 2>"$t/err" </dev/null
  rc=$?
  if [ $rc -ne 1 ]; then fail "$name: exit status $rc (expected 1): $(cat "$t/err")"; return; fi
  grep -qF -- "$pattern" "$t/err" || fail "$name: stderr lacks '$pattern': $(cat "$t/err")"
}

tail="negate: 0
occupied_thresh: 0.65
free_thresh: 0.196"
# A valid 8x6 map: a dark border (occupied) around free cells.
{
  printf 'P2\n8 6\n255\n'
  for y in 0 1 2 3 4 5; do
    for x in 0 1 2 3 4 5 6 7; do
      if [ $x -eq 0 ] || [ $y -eq 0 ] || [ $x -eq 7 ] || [ $y -eq 5 ]; then printf '0 '; else printf '254 '; fi
    done
    printf '\n'
  done
} >"$t/ok.pgm"
printf 'image: ok.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n%s\n' "$tail" >"$t/ok.yaml"

# --info on a directory aborted on an uncaught std::ios_base::failure.
expect_error "info directory" "$t: not a regular file (a directory)" --info "$t"
# --info on a FIFO blocked forever in open().
mkfifo "$t/fifo.mmap"
expect_error "info FIFO" "fifo.mmap: not a regular file (a FIFO)" --info "$t/fifo.mmap"
expect_error "info /dev/zero" "/dev/zero: not a regular file (a character device)" --info /dev/zero
expect_error "info missing" "$t/missing.mmap: cannot open" --info "$t/missing.mmap"

# `image: /dev/zero` read forever; a FIFO as image or as the YAML blocked forever.
printf 'image: /dev/zero\nresolution: 0.05\norigin: [0, 0, 0]\n%s\n' "$tail" >"$t/zero.yaml"
expect_error "image /dev/zero" "zero.yaml: field 'image': /dev/zero: not a regular file (a character device)" \
  "$t/zero.yaml" "$t/zero.mmap"
mkfifo "$t/fifo.pgm"
printf 'image: fifo.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n%s\n' "$tail" >"$t/fifoimg.yaml"
expect_error "image FIFO" "not a regular file (a FIFO)" "$t/fifoimg.yaml" "$t/fifoimg.mmap"
mkfifo "$t/fifo.yaml"
expect_error "yaml FIFO" "fifo.yaml: not a regular file (a FIFO)" "$t/fifo.yaml" "$t/x.mmap"

# A 100000x100000 (and a 16000x16000) PGM header over 1 KB of data: refused before allocating.
{ printf 'P5\n100000 100000\n255\n'; head -c 1024 /dev/zero; } >"$t/bomb.pgm"
printf 'image: bomb.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n%s\n' "$tail" >"$t/bomb.yaml"
expect_error "PGM bomb" "bomb.pgm: PGM header: size 100000x100000" "$t/bomb.yaml" "$t/bomb.mmap"
{ printf 'P5\n16000 16000\n255\n'; head -c 1024 /dev/zero; } >"$t/bomb.pgm"
expect_error "PGM bomb 2" "bomb.pgm: truncated P5 data: 1024 of 256000000" "$t/bomb.yaml" "$t/bomb.mmap"

# origin -1e38 compiled into a map whose points all collapse; a failed compile left its output.
printf 'image: ok.pgm\nresolution: 0.05\norigin: [-1e38, -1e38, 0]\n%s\n' "$tail" >"$t/far.yaml"
printf 'old image\n' >"$t/far.mmap"
expect_error "origin -1e38" "far.yaml: field 'origin'" "$t/far.yaml" "$t/far.mmap"
[ "$(cat "$t/far.mmap")" = "old image" ] || fail "origin -1e38: the existing output was replaced"
expect_error "origin -1e38 (new)" "field 'origin'" "$t/far.yaml" "$t/far-new.mmap"
[ -e "$t/far-new.mmap" ] && fail "origin -1e38: an output file was left behind"
expect_error "output dir missing" "$t/no/such/dir/o.mmap" "$t/ok.yaml" "$t/no/such/dir/o.mmap"

# The good map compiles, --info accepts it, and no temporary is left next to it.
timeout 60 "$mapc" "$t/ok.yaml" "$t/ok.mmap" >"$t/out" 2>"$t/err" || fail "good map: $(cat "$t/err")"
grep -q "verified and loaded by the firmware loader" "$t/out" || fail "good map: no summary: $(cat "$t/out")"
timeout 60 "$mapc" --info "$t/ok.mmap" >"$t/out" 2>"$t/err" || fail "good --info: $(cat "$t/err")"
ls "$t" | grep -q '\.tmp\.' && fail "temporary files left: $(ls "$t")"

if [ $fails -ne 0 ]; then
  echo "$fails failure(s)"
  exit 1
fi
echo "mml-mapc hostile inputs: all cases passed"
