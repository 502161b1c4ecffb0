#!/bin/sh
# help2roff.sh TOOL NAME VERSION OUT.1.gz SUMMARY: a man page for a host tool made from its own
# --help (help2man's idea, without its dependency): NAME - SUMMARY, then the --help text verbatim.
set -eu
tool=$1 name=$2 version=$3 out=$4 summary=$5
# Exit status 3: the tool has no working --help (no page is written; the packaging warns).
help=$("$tool" --help 2>&1) || { echo "help2roff.sh: '$tool --help' failed: no man page for $name" >&2; exit 3; }
[ -n "$help" ] || { echo "help2roff.sh: '$tool --help' printed nothing: no man page for $name" >&2; exit 3; }
mkdir -p "$(dirname "$out")"
{
  echo ".TH $(echo "$name" | tr a-z- A-Z-) 1 \"\" \"mmlfw $version\" \"mmlfw host tools\""
  echo ".SH NAME"
  echo "$name \\- $summary"
  echo ".SH DESCRIPTION"
  echo "The text of"
  echo ".B $name \\-\\-help"
  echo "(tools of the package mmlfw\\-tools; see also"
  echo ".BR mmlfw (1))."
  echo ".PP"
  echo ".nf"
  printf '%s\n' "$help" | sed 's/\\/\\\\/g; s/^\./\\\&./; s/^'"'"'/\\\&'"'"'/'
  echo ".fi"
} | gzip -9n > "$out"
