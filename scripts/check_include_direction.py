#!/usr/bin/env python3
"""Include direction check (CTest include_direction_test, label `rules`).

The layer rule (README "Layers"): every #include points one way, down.

    common       firmware/base       status/result, faults, fixed containers, CRC-32, clock interface
      ^
    hal_if       hal/include/hal     HAL interfaces and messages (hal/clock.h re-exports fw::Clock)
      ^
    runtime      firmware/runtime    Localizer interface, localization loop, threads (names no algorithm)
      ^
    algorithm    firmware/<other>    map, scan, rbsm, pransam, mml, track, mcl, icp (peers)
      ^
    app          firmware/app        start-up builder and the mmlfw binary (chooses the backend set)

  On the side:
    backend      hal/can, hal/linux, hal/socketcan, hal/serial, hal/sim: common + hal_if + other
                 backends; never firmware algorithms/runtime/app, never sim/. Only the app (and
                 tests) may include a backend.
    sim          sim/**: anything in firmware/, hal/, sim/ but never tests/; sim/eval/** never
                 includes sim/cli/** (the simulator CLI is the top), and the folders of sim/ form no
                 include cycle (e.g. sim/cli <-> sim/eval/mml_eval).
    Algorithm folders include each other freely but, outside test sources, form no cycle.
    tests        tests/**: anything. Test sources beside the code (*_test.cpp) follow their folder's
                 rule, plus the test support of tests/ (allocation counter) and hal/sim as a fake.

An #include is resolved to a file of the tree by its prefix: "firmware/..", "sim/..", "tests/.." as
written, "hal/.." -> hal/include/hal/.., "hal_X/.." -> hal/X/include/hal_X/..; anything else
(system, Eigen, gtest, a name relative to the including file) is outside the rule.

Usage: check_include_direction.py [--root DIR]   -> exit 1 and one line per violation
       check_include_direction.py --self-test [--root DIR]
           copies firmware/, hal/, sim/ of DIR into a temporary folder, checks the copy is clean,
           then plants one wrong include at a time and checks that each one fails with its message.
"""

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile

SCANNED = ("firmware", "hal", "sim")
SOURCE_EXT = (".h", ".hpp", ".cpp", ".cc", ".c", ".inc")
BACKENDS = ("can", "linux", "socketcan", "serial", "sim")
INCLUDE_RE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]')

RANK = {"common": 0, "hal_if": 1, "runtime": 2, "algorithm": 3, "app": 4}


def module_of(path):
    """(layer, module) of a repository-relative path, or None if it is outside the rule."""
    parts = path.split("/")
    if parts[0] == "firmware" and len(parts) >= 3:
        sub = parts[1]
        if sub == "base":
            return "common", "firmware/base"
        if sub == "runtime":
            return "runtime", "firmware/runtime"
        if sub == "app":
            return "app", "firmware/app"
        return "algorithm", "firmware/" + sub
    if parts[0] == "hal" and len(parts) >= 3:
        if parts[1] == "include":
            return "hal_if", "hal/include"
        if parts[1] in BACKENDS:
            return "backend", "hal/" + parts[1]
        return "backend", "hal/" + parts[1]
    if parts[0] == "sim" and len(parts) >= 2:
        if len(parts) >= 4 and parts[1] == "eval":
            return "sim", "sim/eval/" + parts[2]
        if len(parts) >= 3:
            return "sim", "sim/" + parts[1]
        return "sim", "sim"
    if parts[0] == "tests":
        return "tests", "tests"
    return None


def resolve(include):
    """Repository path an include names, or None when it is not one of ours."""
    if include.startswith(("firmware/", "sim/", "tests/")):
        return include
    if include.startswith("hal/"):
        return "hal/include/" + include
    m = re.match(r"hal_([a-z0-9]+)/", include)
    if m:
        return "hal/%s/include/%s" % (m.group(1), include)
    return None


def is_test_source(path):
    base = os.path.basename(path)
    return "_test." in base or base.endswith("_test_util.h")


def violation(src, dst):
    """Why src may not include dst, or None when it may."""
    s, d = module_of(src), module_of(dst)
    if s is None or d is None:
        return None
    (sl, sm), (dl, dm) = s, d
    if sl == "tests":
        return None
    if dl == "tests":
        if is_test_source(src):
            return None  # test sources beside the code use the test support (allocation counter)
        return "%s may not include tests/ (tests sit on top)" % sm
    if sl == "sim":
        if sm == "sim/cli" or not dm.startswith("sim/"):
            return None
        if sm.startswith("sim/eval") and dm == "sim/cli":
            return "%s may not include sim/cli (the simulator CLI is the top of sim/)" % sm
        return None
    # From here on the including file is in firmware/ or hal/.
    if dl == "sim":
        return "%s (%s) may not include sim/ (host tools sit beside the firmware, never below it)" % (sm, sl)
    if sl == "backend":
        if dl in ("common", "hal_if", "backend"):
            return None
        return "HAL backend %s may not include %s (%s): a backend never includes an algorithm" % (sm, dm, dl)
    if dl == "backend":
        if sl == "app":
            return None
        if is_test_source(src) and dm == "hal/sim":
            return None  # firmware tests use the simulation backend as their fake
        return "%s (%s) may not include HAL backend %s (only the app chooses backends)" % (sm, sl, dm)
    if RANK[dl] > RANK[sl]:
        return "%s (%s) may not include %s (%s): includes point down (common <- hal_if <- runtime <- algorithm <- app)" % (
            sm, sl, dm, dl)
    return None


def scan(root):
    """[(src, line_no, include, dst)] for every resolvable include of the scanned folders."""
    edges = []
    for top in SCANNED:
        for dirpath, dirnames, filenames in os.walk(os.path.join(root, top)):
            dirnames[:] = sorted(d for d in dirnames if not d.startswith("."))
            for fn in sorted(filenames):
                if not fn.endswith(SOURCE_EXT):
                    continue
                full = os.path.join(dirpath, fn)
                rel = os.path.relpath(full, root).replace(os.sep, "/")
                with open(full, encoding="utf-8", errors="replace") as f:
                    for no, line in enumerate(f, 1):
                        m = INCLUDE_RE.match(line)
                        if not m:
                            continue
                        dst = resolve(m.group(2))
                        if dst is not None:
                            edges.append((rel, no, m.group(2), dst))
    return edges


def folder_cycles(edges, layer, tests_too):
    """Include cycles between the folders of one layer (module graph): (a, b, witness a->b, witness b->a)."""
    graph = {}
    witness = {}
    for src, no, inc, dst in edges:
        s, d = module_of(src), module_of(dst)
        if not s or not d or s[0] != layer or d[0] != layer or s[1] == d[1]:
            continue
        if not tests_too and is_test_source(src):
            continue
        graph.setdefault(s[1], set()).add(d[1])
        witness.setdefault((s[1], d[1]), "%s:%d" % (src, no))
    cycles, seen = [], set()
    for a in sorted(graph):
        for b in sorted(graph[a]):
            if a in graph.get(b, ()) and (b, a) not in seen:
                seen.add((a, b))
                cycles.append((a, b, witness[(a, b)], witness[(b, a)]))
    # Longer cycles: a module reaching itself through others.
    def reach(start):
        stack, out = [start], set()
        while stack:
            n = stack.pop()
            for m in graph.get(n, ()):
                if m not in out:
                    out.add(m)
                    stack.append(m)
        return out
    for a in sorted(graph):
        if a in reach(a) and not any(a in (c[0], c[1]) for c in cycles):
            cycles.append((a, a, "(through other sim/ folders)", ""))
    return cycles


def check(root):
    edges = scan(root)
    problems = []
    for src, no, inc, dst in edges:
        why = violation(src, dst)
        if why:
            problems.append('%s:%d: #include "%s": %s' % (src, no, inc, why))
    for a, b, wa, wb in folder_cycles(edges, "sim", True):
        problems.append("include cycle between %s and %s (%s; %s)" % (a, b, wa, wb))
    # Algorithms are peers but their libraries form no cycle (a test may compare two: rbsm_test
    # runs the ICP baseline).
    for a, b, wa, wb in folder_cycles(edges, "algorithm", False):
        problems.append("include cycle between %s and %s (%s; %s)" % (a, b, wa, wb))
    return edges, problems


def report(root):
    edges, problems = check(root)
    for p in problems:
        print("include_direction: " + p)
    print("include_direction: %d includes checked in %s, %d violation(s)" % (len(edges), "/".join(SCANNED), len(problems)))
    return 1 if problems else 0


# Planted wrong includes: (file to create in the copy, include it gets, words the message must hold).
PLANTS = [
    ("firmware/base/planted.h", "hal/clock.h", "firmware/base (common) may not include hal/include (hal_if)"),
    ("hal/include/hal/planted.h", "firmware/runtime/localizer.h", "hal/include (hal_if) may not include firmware/runtime"),
    ("firmware/mml/planted.cpp", "sim/io/carmen_log.h", "firmware/mml (algorithm) may not include sim/"),
    ("firmware/pransam/planted_test.cpp", "sim/eval/pransam_scenes.h", "may not include sim/"),
    ("firmware/runtime/planted.cpp", "firmware/mml/mml_localizer.h", "firmware/runtime (runtime) may not include firmware/mml"),
    ("firmware/mml/planted.h", "firmware/app/system.h", "firmware/mml (algorithm) may not include firmware/app"),
    ("firmware/track/planted.cpp", "hal_linux/linux_clock.h", "may not include HAL backend hal/linux"),
    ("hal/can/planted.cpp", "firmware/mml/mml_localizer.h", "HAL backend hal/can may not include firmware/mml"),
    ("hal/sim/planted.cpp", "sim/io/carmen_log.h", "hal/sim (backend) may not include sim/"),
    ("sim/eval/mml_eval/planted.cpp", "sim/cli/sim_runner.h", "sim/eval/mml_eval may not include sim/cli"),
    ("sim/io/planted_cycle.cpp", "sim/cli/sim_runner.h", "include cycle between"),
    ("firmware/map/planted.cpp", "tests/alloc_counter.h", "may not include tests/"),
    ("firmware/map/planted.h", "firmware/pransam/matcher.h", "include cycle between firmware/map and firmware/pransam"),
]


def self_test(root):
    failures = 0
    with tempfile.TemporaryDirectory(prefix="include_direction_") as tmp:
        for top in SCANNED:
            shutil.copytree(os.path.join(root, top), os.path.join(tmp, top),
                            ignore=lambda d, names: [n for n in names
                                                     if not os.path.isdir(os.path.join(d, n))
                                                     and not n.endswith(SOURCE_EXT)])
        _, problems = check(tmp)
        if problems:
            print("self-test: the copy of the tree is not clean before planting:")
            for p in problems:
                print("  " + p)
            return 1
        for rel, inc, expect in PLANTS:
            path = os.path.join(tmp, rel)
            os.makedirs(os.path.dirname(path), exist_ok=True)
            with open(path, "w") as f:
                f.write('// planted by check_include_direction.py --self-test\n#include "%s"\n' % inc)
            # The checker itself, as CTest runs it: it must exit 1 and name the planted include.
            run = subprocess.run([sys.executable, os.path.abspath(__file__), "--root", tmp],
                                 stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
            os.remove(path)
            problems = [l for l in run.stdout.splitlines() if "violation(s)" not in l]
            hit = [p for p in problems if expect in p] if run.returncode == 1 else []
            if hit:
                print("self-test: planted %-36s -> #include \"%s\": FAILS as it must:\n    %s" % (rel, inc, hit[0]))
            else:
                failures += 1
                print("self-test: planted %s -> #include \"%s\": NOT caught (exit %d: %s)" % (rel, inc, run.returncode, problems))
        _, problems = check(tmp)
        if problems:
            failures += 1
            print("self-test: copy not clean after removing the plants: %s" % problems)
    print("self-test: %d plant(s) not caught" % failures)
    return 1 if failures else 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--root", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    ap.add_argument("--self-test", action="store_true")
    args = ap.parse_args()
    if args.self_test:
        return self_test(args.root)
    return report(args.root)


if __name__ == "__main__":
    sys.exit(main())
