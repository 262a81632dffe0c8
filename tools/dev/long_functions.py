#!/usr/bin/env python3
"""Lists the functions of pcsg's production C++ code that are longer than a limit.

    python3 tools/dev/long_functions.py [--limit 80] [--check] [--self-test]

A function starts at a line that ends with '{' after a signature (a ')' before it, not a
control statement, lambda or initialiser) and runs to its matching '}'; lambdas and nested
blocks count as part of their function. Test files (names containing 'test') are left out.
With --check the exit status is 1 when any function is longer than the limit.
--self-test checks the finder itself on made-up files (a long function is found, a short
one, a lambda and a long initialiser are not).
"""
import argparse
import os
import re
import sys

ROOTS = ("compiler", "tracer", "povexport", "tools")
CONTROL = re.compile(r"^\s*(if|for|while|switch|else|do|case|try|catch|return|namespace|"
                     r"class|struct|enum|union|template)\b")


def sources(top):
    for root in ROOTS:
        for dirpath, _, files in os.walk(os.path.join(top, root)):
            for f in sorted(files):
                if f.endswith((".cpp", ".h")) and "test" not in f:
                    yield os.path.join(dirpath, f)


def code_of(line):
    line = re.sub(r'"(\\.|[^"\\])*"', '""', line)
    line = re.sub(r"'(\\.|[^'\\])*'", "''", line)
    return line.split("//")[0]


def starts_function(line):
    s = line.rstrip()
    if not s.endswith("{") or CONTROL.match(s) or ")" not in s:
        return False
    head = s.split("(")[0]
    return "=" not in head and "[" not in head and not s.lstrip().startswith(("}", "//", ":", ","))


def long_functions(path, limit):
    lines = open(path, encoding="utf-8", errors="replace").read().split("\n")
    i = 0
    while i < len(lines):
        if not starts_function(lines[i]):
            i += 1
            continue
        depth, j = 0, i
        for j in range(i, len(lines)):
            c = code_of(lines[j])
            depth += c.count("{") - c.count("}")
            if depth <= 0:
                break
        length = j - i + 1
        if length > limit:
            name = re.search(r"([~\w:]+)\s*\(", lines[i])
            yield length, i + 1, name.group(1) if name else lines[i].strip()[:40]
            i = j + 1
        else:
            i += 1


def self_test():
    import tempfile
    body = "    x += 1;\n"
    long_fn = "int longOne(int x) {\n" + body * 85 + "    return x;\n}\n"
    short_fn = "int shortOne(int x) {\n" + body * 70 + "    return x;\n}\n"
    table = "const int kTable[] = {\n" + "    1,\n" * 100 + "};\n"
    lam = "auto f = [](int x) {\n" + body * 90 + "    return x;\n};\n"
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "sample.cpp")
        with open(path, "w") as f:
            f.write(short_fn + table + long_fn + lam)
        found = [name for _, _, name in long_functions(path, 80)]
    ok = found == ["longOne"]
    print("self-test:", "ok" if ok else f"FAILED (found {found}, expected ['longOne'])")
    return 0 if ok else 1


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--limit", type=int, default=80)
    ap.add_argument("--check", action="store_true")
    ap.add_argument("--self-test", action="store_true")
    args = ap.parse_args()
    if args.self_test:
        return self_test()
    top = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    found = []
    for path in sources(top):
        for length, line, name in long_functions(path, args.limit):
            found.append((length, os.path.relpath(path, top), line, name))
    for length, path, line, name in sorted(found, reverse=True):
        print(f"{path}:{line}: {name} is {length} lines (limit {args.limit})")
    if not found:
        print(f"no production function is over {args.limit} lines")
    return 1 if args.check and found else 0


if __name__ == "__main__":
    sys.exit(main())
