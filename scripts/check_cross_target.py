#!/usr/bin/env python3
"""Cross-target check (scripts/test.sh, aarch64 stage): the robot's CPU computes what the host does.

Runs one test case of the host build and the same case of the aarch64 build (under qemu-user) and
compares the "trace" lines both print (`mml::testing::print_trace`: one line per published step of
the MML + tracker run; the ant colony's answer on the synthetic loop with its sampled edges). Integer
fields (status, mode, counts, reason) must be equal; floating-point fields (C99 hex, `%a`) equal to
within --tol (absolute): glibc's atan2f is not correctly rounded and differs in the last bit between
x86-64 and aarch64 (2026-11-28, 2 million random arguments: cosf, sinf, expf, logf, cos, atan2, exp
bit-identical, atan2f not; ≤ 1.2e-7 over the 266 steps), while a real
divergence — an unsequenced draw (scripts/check_draw_order.py), a contracted FMA, a different
decision — changes statuses or moves poses by far more.

Usage: check_cross_target.py --host BIN --cross BIN [--emulator "qemu-aarch64 -L PREFIX"]
                             --filter GTEST_FILTER [--tol 1e-4]
       check_cross_target.py --self-test      (planted traces: a last-bit difference passes; a
                                               changed status, a moved pose or a missing line fails)
"""

import argparse
import shlex
import subprocess
import sys


def traces(text):
    return [line.split() for line in text.splitlines() if line.startswith("trace ")]


def value(token):
    """A float printed with %a, or None for an integer / name field (compared exactly)."""
    if "0x" in token or token in ("inf", "-inf", "nan", "-nan"):
        try:
            return float.fromhex(token)
        except ValueError:
            return None
    return None


def compare(host, cross, tol):
    """(ok, message) for two lists of trace lines."""
    if not host:
        return False, "the host run printed no trace line"
    if len(host) != len(cross):
        return False, "host printed %d trace lines, aarch64 %d" % (len(host), len(cross))
    worst = 0.0
    for a, b in zip(host, cross):
        if len(a) != len(b):
            return False, "field count differs:\n  host    %s\n  aarch64 %s" % (" ".join(a), " ".join(b))
        for k, (x, y) in enumerate(zip(a, b)):
            vx, vy = value(x), value(y)
            if vx is None or vy is None:
                if x != y:
                    return False, "field %d differs:\n  host    %s\n  aarch64 %s" % (k, " ".join(a), " ".join(b))
                continue
            d = abs(vx - vy) if vx == vx and vy == vy else (0.0 if (vx != vx) == (vy != vy) else float("inf"))
            worst = max(worst, d)
            if d > tol:
                return False, "field %d differs by %.3g (tolerance %.3g):\n  host    %s\n  aarch64 %s" % (
                    k, d, tol, " ".join(a), " ".join(b))
    return True, "%d trace lines agree (largest difference %.3g, tolerance %.3g)" % (len(host), worst, tol)


def run(cmd):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if p.returncode != 0:
        sys.stdout.write(p.stdout[-4000:])
        raise SystemExit("check_cross_target: %s exited with %d" % (" ".join(cmd), p.returncode))
    return p.stdout


def self_test():
    base = ["trace mml-track 0 1 0 12 3 0 4 0x1.791206p+0 0x1.c1dep+0 0x1.8f43b6p+0 0x0p+0",
            "trace mml-track 1 0 1 0 0 0 0 0x1.8207fap+0 0x1.c4a896p+0 0x1.94952p+0 0x1.2p-3"]
    cases = {
        "identical": (base, True),
        "last_bit": ([base[0].replace("0x1.791206p+0", "0x1.791208p+0"), base[1]], True),
        "status_changed": ([base[0], base[1].replace("mml-track 1 0 1", "mml-track 1 1 1")], False),
        "pose_moved": ([base[0].replace("0x1.791206p+0", "0x1.7a1206p+0"), base[1]], False),
        "line_missing": ([base[0]], False),
    }
    ok_all = True
    for name, (cross, expect) in cases.items():
        ok, msg = compare(traces("\n".join(base)), traces("\n".join(cross)), 1e-4)
        good = ok == expect
        ok_all &= good
        print("self-test: %s: %s%s" % (name, "agree" if ok else "differ", ", as it must" if good else " — WRONG: " + msg))
    ok, _ = compare([], [], 1e-4)
    print("self-test: no trace at all: %s" % ("differ, as it must" if not ok else "agree — WRONG"))
    return 0 if ok_all and not ok else 1


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--host")
    ap.add_argument("--cross")
    ap.add_argument("--emulator", default="")
    ap.add_argument("--filter")
    ap.add_argument("--tol", type=float, default=1e-4)
    ap.add_argument("--self-test", action="store_true")
    a = ap.parse_args()
    if a.self_test:
        return self_test()
    if not (a.host and a.cross and a.filter):
        ap.error("--host, --cross and --filter are required")
    gtest = ["--gtest_filter=" + a.filter]
    host = traces(run([a.host] + gtest))
    cross = traces(run(shlex.split(a.emulator) + [a.cross] + gtest))
    ok, msg = compare(host, cross, a.tol)
    print("check_cross_target: %s (%s): %s" % (a.filter, a.cross.split("/")[-1], msg))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
