#!/bin/sh
# Integrity after a kidnap into a building of twins (issue 11). The large office has two blocks of
# identical cells and corridors that look the same turned 180°. Before the rival memory
# (firmware/mml/rival_memory.h), this run published 12 `localized` steps 80–83 m and 180° off
# (steps 503–514): the true cluster dropped out of pRANSAM's hypotheses for 20 steps and MML took
# the mirror as isolated. The run must have no `localized` step beyond 0.5 m / 5°, must fix before
# the kidnap and must re-fix (correctly) after it.
# Usage: kidnap_twin_test.sh MML_SIM
set -eu
sim=$1
t=$(mktemp -d)
trap 'rm -rf "$t"' EXIT
"$sim" --world large-office --seed 1 --kidnap-at 400 --transport sick --timing none --quiet --no-pictures \
  --out "$t/run" > "$t/out.txt"
cat "$t/out.txt"
python3 - "$t/run/summary.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
bad = []
if s["integrity_failures"] != 0: bad.append("integrity failures %d (want 0)" % s["integrity_failures"])
if not (0 <= s["first_localized_step"] < 400): bad.append("no fix before the kidnap (first fix %s)" % s["first_localized_step"])
if s.get("relocalized_step", -1) < 400: bad.append("no re-fix after the kidnap")
elif s["refix_err_m"] > 0.5: bad.append("re-fix %.2f m off" % s["refix_err_m"])
print("kidnap_twin_test: integrity failures %d, first fix %d, re-fix at step %d (%.2f m off)" %
      (s["integrity_failures"], s["first_localized_step"], s.get("relocalized_step", -1), s.get("refix_err_m", -1)))
if bad:
    print("FAIL: " + "; ".join(bad)); sys.exit(1)
PY
