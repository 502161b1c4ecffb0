#!/usr/bin/env python3
"""Function length check (CTest function_length_test, label `rules`; issue "The house").

No function body of the product's sources (firmware/, hal/, sim/; *_test.cpp and tests/ excluded)
may span more than --max lines (default 150), counted from the first line of its signature to its
closing brace: a longer function is split into named steps. Lambdas count with their enclosing
function; a function inside a class body counts on its own.

How a body is found: comments, string and character literals are blanked, then every '{' is
classified by the code before it: after ')' (optionally followed by const, noexcept, override,
final, a trailing return type or a constructor's member-initialiser list) it opens a function
unless it is a control statement (if/for/while/switch/catch) or a lambda inside another function;
namespace / class / struct / union / enum / extern / initialiser braces are scopes, not functions.

Usage: check_function_length.py [--root DIR] [--max N] [--list K]
           exit 1 and one line per function over N lines; --list K prints the K longest.
       check_function_length.py --self-test [--root DIR]
           plants a function of N + 1 lines (must be reported) and one of N lines (must not) in a copy.
"""

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile

SCANNED = ("firmware", "hal", "sim")
SOURCE_EXT = (".cpp", ".h", ".cc", ".hpp")
CONTROL = re.compile(r"\b(if|for|while|switch|catch)\s*$")
# What may follow a function's parameter list before its body.
QUALIFIERS = re.compile(r"^(\s|const\b|noexcept\b|override\b|final\b|mutable\b|&)*(->[^=;]*)?$")
SCOPE = re.compile(r"\b(namespace|class|struct|union|enum|extern)\b[^;{}()]*$")


def blank(text):
    """Comments and literals replaced by spaces (newlines kept, so line numbers stay)."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == 'R' and text.startswith('R"', i):
            m = re.match(r'R"([^(\s]*)\(', text[i:])
            end = text.find(")" + (m.group(1) if m else "") + '"', i)
            j = n if end < 0 else end + len(m.group(1) if m else "") + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            out.append(" " * (min(j + 1, n) - i))
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def functions(text):
    """(first line, last line, signature) of every function body in `text`."""
    code = blank(text)
    found, stack = [], []  # stack of (kind, start line, signature)
    stmt_start = 0          # index where the current statement / declaration began
    for i, c in enumerate(code):
        if c in ";":
            stmt_start = i + 1
        elif c == "{":
            head = code[stmt_start:i]
            stripped = head.strip()
            kind = "block"
            if not any(k == "function" for k, _, _ in stack):
                close = stripped.rfind(")")
                tail = stripped[close + 1:] if close >= 0 else None
                if tail is not None and QUALIFIERS.match(tail) and not CONTROL.search(stripped[:stripped.find("(")]):
                    kind = "function"
                elif SCOPE.search(stripped):
                    kind = "scope"
            first = code.count("\n", 0, stmt_start + len(head) - len(head.lstrip())) + 1
            stack.append((kind, first, " ".join(stripped.split())[:90]))
            stmt_start = i + 1
        elif c == "}":
            if stack:
                kind, first, sig = stack.pop()
                if kind == "function":
                    found.append((first, code.count("\n", 0, i) + 1, sig))
            stmt_start = i + 1
    return found


def scan(root):
    rows = []
    for top in SCANNED:
        for d, _, names in os.walk(os.path.join(root, top)):
            for name in sorted(names):
                if not name.endswith(SOURCE_EXT) or name.endswith("_test.cpp"):
                    continue
                path = os.path.join(d, name)
                with open(path, encoding="utf-8", errors="replace") as f:
                    text = f.read()
                for first, last, sig in functions(text):
                    rows.append((last - first + 1, os.path.relpath(path, root), first, sig))
    rows.sort(key=lambda r: (-r[0], r[1], r[2]))
    return rows


def check(root, limit, show):
    rows = scan(root)
    for length, path, line, sig in rows[:show]:
        print("%4d lines  %s:%d  %s" % (length, path, line, sig))
    over = [r for r in rows if r[0] > limit]
    for length, path, line, sig in over:
        print("%s:%d: function of %d lines (limit %d): %s" % (path, line, length, limit, sig))
    if over:
        print("%d function(s) over %d lines: split them into named steps" % (len(over), limit))
    return 1 if over else 0


def planted(name, body_lines):
    # A signature line, body_lines - 2 statements, the closing brace: body_lines lines in all.
    stmts = "".join("  x += %d;  // {\n" % k for k in range(body_lines - 2))
    return "int %s(int x) {\n%s}\n" % (name, stmts)


def self_test(root, limit):
    with tempfile.TemporaryDirectory(prefix="function_length_") as tmp:
        for top in SCANNED:
            shutil.copytree(os.path.join(root, top), os.path.join(tmp, top),
                            ignore=lambda d, names: [n for n in names if not os.path.isdir(os.path.join(d, n))
                                                     and not n.endswith(SOURCE_EXT)])
        me = os.path.abspath(__file__)
        runs = []
        for name, lines, expect_fail in (("planted_too_long", limit + 1, True), ("planted_at_limit", limit, False)):
            path = os.path.join(tmp, "firmware", "planted_function_length.cpp")
            with open(path, "w") as f:
                f.write("namespace fw {\n" + planted(name, lines) + "}  // namespace fw\n")
            run = subprocess.run([sys.executable, me, "--root", tmp, "--max", str(limit)],
                                 stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
            os.remove(path)
            caught = run.returncode == 1 and any(name in l and "function of %d lines" % lines in l
                                                 for l in run.stdout.splitlines())
            ok = caught == expect_fail  # at the limit: not reported (whatever else the tree holds)
            print("self-test: planted %s (%d lines): %s" % (name, lines, "as it must" if ok else "WRONG:\n" + run.stdout))
            runs.append(ok)
    return 0 if all(runs) else 1


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--root", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    ap.add_argument("--max", type=int, default=150)
    ap.add_argument("--list", type=int, default=0)
    ap.add_argument("--self-test", action="store_true")
    a = ap.parse_args()
    if a.self_test:
        return self_test(a.root, a.max)
    return check(a.root, a.max, a.list)


if __name__ == "__main__":
    sys.exit(main())
