#!/usr/bin/env python3
"""Draw order check (CTest draw_order_test, label `rules`): one seed, one answer, on every target.

C++ leaves the order in which a function's arguments (and the operands of + or *) are evaluated
unspecified. `Vec3(rng.gaussian(), rng.gaussian(), rng.gaussian())` therefore fills x, y, z from
different draws on different compilers: x86-64 GCC evaluated such arguments last first, aarch64 GCC
and clang first first (measured 2026-11-28, GCC 12 / clang 14). That broke the rule that the same
seed gives the same output on the robot's computer as on the host. Declarators
(`const double a = r.gaussian(), b = r.gaussian();`), the comma operator and braced lists are
sequenced left to right and are fine.

Reported: any expression (a statement cut at ';', '{', '}' and at its top-level commas) holding two
or more draws from the same stream: `S.M(` / `S->M(` with M one of RandomStream's draws
(firmware/base/rng.h), or `D(S)` where S is a <random> engine declared in the same file.
Comments and literals are blanked first (scripts/check_function_length.py's `blank`).

Usage: check_draw_order.py [--root DIR]        exit 1 and one line per expression found
       check_draw_order.py --self-test [--root DIR]
           plants draws that must be reported and sequenced ones that must not, in a tree of their own.
"""

import argparse
import os
import re
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from check_function_length import blank  # noqa: E402

SCANNED = ("firmware", "hal", "sim", "tests")
SOURCE_EXT = (".cpp", ".h", ".cc", ".hpp")
DRAWS = ("next_u32", "uniform_index", "uniform01f", "uniform01", "uniform", "gaussianf", "gaussian")
MEMBER_DRAW = re.compile(r"([A-Za-z_]\w*)\s*(?:\.|->)\s*(?:%s)\s*\(" % "|".join(DRAWS))
ENGINE_DECL = re.compile(r"\bstd::(?:mt19937(?:_64)?|default_random_engine|minstd_rand0?|ranlux\w+)\s*&?\s*([A-Za-z_]\w*)")


def expressions(code):
    """(offset, text) of every expression: statements cut at ; { } and at top-level commas."""
    out, start, depth = [], 0, 0
    for i, c in enumerate(code):
        if c in "([":
            depth += 1
        elif c in ")]":
            depth = max(0, depth - 1)
        if c in ";{}" or (c == "," and depth == 0):
            out.append((start, code[start:i]))
            start = i + 1
            if c in ";{}":
                depth = 0
    out.append((start, code[start:]))
    return out


def findings(text):
    code = blank(text)
    engines = set(ENGINE_DECL.findall(code))
    engine_draw = re.compile(r"\b[A-Za-z_]\w*\s*\(\s*(%s)\s*\)" % "|".join(map(re.escape, engines))) if engines else None
    found = []
    for offset, expr in expressions(code):
        streams = MEMBER_DRAW.findall(expr) + (engine_draw.findall(expr) if engine_draw else [])
        twice = sorted({s for s in streams if streams.count(s) > 1})
        if twice:
            line = code.count("\n", 0, offset + len(expr) - len(expr.lstrip())) + 1
            found.append((line, ", ".join(twice), " ".join(expr.split())[:110]))
    return found


def check(root):
    bad = 0
    for top in SCANNED:
        for d, _, names in sorted(os.walk(os.path.join(root, top))):
            for name in sorted(names):
                if not name.endswith(SOURCE_EXT):
                    continue
                path = os.path.join(d, name)
                with open(path, encoding="utf-8", errors="replace") as f:
                    text = f.read()
                for line, streams, expr in findings(text):
                    print("%s:%d: two draws from %s in one expression, order unspecified: %s"
                          % (os.path.relpath(path, root), line, streams, expr))
                    bad += 1
    if bad:
        print("%d expression(s): draw into named values, one per declarator, in a fixed order" % bad)
    return 1 if bad else 0


PLANTED = {
    # name: (source, must be reported)
    "ctor_args": ("void f(fw::RandomStream& rng) { const Eigen::Vector2f v(rng.gaussian(), rng.gaussian()); }\n", True),
    "operands": ("float f(fw::RandomStream* r) { return r->uniform01f() * 2.0f + r->uniform01f(); }\n", True),
    "engine": ("void f() { std::mt19937 gen(1); std::uniform_real_distribution<float> u(0, 1);\n"
               "  auto p = std::make_pair(u(gen), u(gen)); }\n", True),
    "declarators": ("void f(fw::RandomStream& rng) { const double a = rng.gaussian(), b = rng.gaussian(); }\n", False),
    "two_streams": ("void f(fw::RandomStream& a, fw::RandomStream& b) { g(a.gaussian(), b.gaussian()); }\n", False),
    "braced": ("void f(fw::RandomStream& rng) { const P3 p{rng.uniform(0, 1), rng.uniform(0, 1), 0.0f}; }\n", False),
    "comment": ("void f(fw::RandomStream& rng) { // g(rng.gaussian(), rng.gaussian())\n}\n", False),
}


def self_test(root):
    """The planted files alone, in one tree, one run of the check: each reported or not as marked."""
    del root  # the planted tree stands alone: the product's own findings are draw_order_test's
    with tempfile.TemporaryDirectory(prefix="draw_order_") as tmp:
        os.makedirs(os.path.join(tmp, "firmware"))
        for name, (source, _) in PLANTED.items():
            with open(os.path.join(tmp, "firmware", "planted_%s.cpp" % name), "w") as f:
                f.write(source)
        run = subprocess.run([sys.executable, os.path.abspath(__file__), "--root", tmp], stdout=subprocess.PIPE,
                             stderr=subprocess.STDOUT, text=True)
    results = [run.returncode == 1]
    for name, (_, expect) in PLANTED.items():
        reported = any(("planted_%s.cpp" % name) in l for l in run.stdout.splitlines())
        ok = reported == expect
        print("self-test: planted %s: %s" % (name, ("reported" if reported else "not reported")
                                               + (", as it must" if ok else " — WRONG")))
        results.append(ok)
    if not all(results):
        print(run.stdout)
    return 0 if all(results) else 1


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--root", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    ap.add_argument("--self-test", action="store_true")
    a = ap.parse_args()
    return self_test(a.root) if a.self_test else check(a.root)


if __name__ == "__main__":
    sys.exit(main())
