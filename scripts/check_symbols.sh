#!/usr/bin/env bash
# Symbol check: fails if a firmware/hal library references the heap or exceptions or carries RTTI.
# usage: check_symbols.sh NM LIB.a [LIB.a ...]
# Forbidden (mangled): operator new/new[] (all overloads: _Znwm, _Znam, _Znwj/_Znaj on 32-bit),
# malloc/calloc/realloc/aligned_alloc/posix_memalign, __cxa_throw, __cxa_allocate_exception,
# __cxa_begin_catch, and typeinfo (_ZTI*) — the last appears only when RTTI is on.
set -uo pipefail
NM=${1:?usage: check_symbols.sh NM LIB...}
shift
pattern='^(_Zn[wa][mj].*|malloc|calloc|realloc|aligned_alloc|posix_memalign|memalign|valloc|__cxa_throw|__cxa_allocate_exception|__cxa_begin_catch|_ZTI.*)$'
bad=0
for lib in "$@"; do
  if [ ! -f "$lib" ]; then echo "check_symbols: $lib: no such library" >&2; bad=1; continue; fi
  # Undefined references (what the library would pull in) and defined typeinfo objects.
  hits=$("$NM" -A "$lib" 2>/dev/null | awk '{ s=$NF; t=$(NF-1); if (t=="U" || s ~ /^_ZTI/) print $1, s }' \
         | awk -v pat="$pattern" '{ if ($2 ~ pat) print }' | sort -u)
  if [ -n "$hits" ]; then
    echo "check_symbols: FORBIDDEN symbols in $(basename "$lib"):"
    while read -r where sym; do
      echo "  $where $sym  ($(echo "$sym" | c++filt))"
    done <<< "$hits"
    bad=1
  else
    echo "check_symbols: $(basename "$lib"): clean"
  fi
done
if [ $bad -ne 0 ]; then echo "check_symbols: FAILED"; exit 1; fi
echo "check_symbols: $# libraries clean"
