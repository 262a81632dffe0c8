#!/usr/bin/env python3
"""Writes the order of pcsg's code in its static release binary, from a profile.

    python3 tools/dev/code_order.py BUILD/tools/pcsg [-o tools/pcsg_code_order.txt]

The release pcsg is linked by lld with `--symbol-ordering-file tools/pcsg_code_order.txt`
(tools/CMakeLists.txt): the functions a render runs are laid out next to each other, so a
process maps fewer pages of code. The kernel maps 64 KB of the file around each page of
code that faults, so a function that is never run still costs memory when it sits between
two that are (docs/benchmarks.md, branch floor). lld moves the section that holds each
listed symbol: pcsg's and libstdc++'s functions have a section each (-ffunction-sections),
most of glibc's a file each, so glibc's are ordered too (gold's --section-ordering-file
goes by section names and cannot order them: tried).

The profile: each command of COMMANDS (start-up, renders of several scenes, a frame
sequence, export-pov) runs under callgrind with the given binary; every function that ran
is listed, those run by more of the commands first (start-up, then the render's core,
then what only some scenes or commands use), each under every name the binary has at its
address. glibc picks its string functions' variants by the CPU (memcpy's avx2, evex, ...)
and valgrind's CPU is not the machine's, so each variant that ran brings its siblings.
Functions that never ran are not listed: lld puts them after the listed ones.

Refresh it after changes to the code a render runs (new or renamed functions): build, run
this script on build/tools/pcsg (about 7 minutes on a loaded machine), commit the file,
rebuild. A stale order is harmless: names the binary no longer has are ignored
(--no-warn-symbol-ordering), and a function missing from the order only costs pages, never
correctness. The release ctest `pcsg_code_order` checks that the binary follows the file.
"""
import argparse
import collections
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
# glibc's variants of one function for different instruction sets: __memmove_avx_unaligned,
# __memmove_evex_unaligned_erms, __strlen_sse2, __ieee754_pow_fma ...
VARIANT = re.compile(r"(__\w+?)_(sse2|ssse3|sse4_1|sse4_2|sse42|avx|avx2|evex|avx512|fma|fma4)"
                     r"(_\w+)?")

# What the profile runs: (name, arguments after the binary). Images are small: callgrind
# runs ~50 times slower, and the code a render runs does not depend on the image's size.
RENDER = ["--width", "48", "--height", "36", "--adaptive", "0.3", "--threads", "2"]
COMMANDS = [
    ("version", ["--version"]),
    ("render_1x1", ["render", "scenes/sierpinski.pcsg", "-o", "{out}/a.png", "--width", "1",
                    "--height", "1"]),
    ("order8", ["render", "tools/bench/sierpinski_8.pcsg", "-o", "{out}/b.png"] + RENDER),
    ("sympodial", ["render", "scenes/sympodial_tree.pcsg", "-o", "{out}/c.png"] + RENDER),
    ("terrain", ["render", "scenes/terrain.pcsg", "-o", "{out}/d.png", "--width", "16",
                 "--height", "12", "--threads", "2"]),
    ("terrain_sea", ["render", "scenes/terrain_sea.pcsg", "-o", "{out}/e.png", "--width", "16",
                     "--height", "12", "--threads", "2"]),
    ("textured", ["render", "scenes/textured_tree.pcsg", "-o", "{out}/f.png"] + RENDER),
    ("glass", ["render", "scenes/glass_sierpinski.pcsg", "-o", "{out}/g.png"] + RENDER),
    ("menger", ["render", "scenes/menger_marble.pcsg", "-o", "{out}/h.png"] + RENDER),
    ("metals", ["render", "scenes/sphereflake_metals.pcsg", "-o", "{out}/i.png"] + RENDER),
    ("frames", ["render", "scenes/growing_tree.pcsg", "-o", "{out}/j.png", "--frames", "48",
                "--subset", "20,22", "--frame-bounds", "on", "--width", "32", "--height",
                "24", "--adaptive", "0.3", "--threads", "2"]),
    ("export", ["export-pov", "scenes/sierpinski.pcsg", "-o", "{out}/k.pov"]),
]


def functions_run(binary, args, workdir):
    """The names of the functions callgrind saw run in one command."""
    out = os.path.join(workdir, "callgrind.out")
    cmd = ["valgrind", "--tool=callgrind", "--demangle=no", "--compress-strings=no",
           "--callgrind-out-file=" + out, binary] + [a.format(out=workdir) for a in args]
    subprocess.run(cmd, cwd=ROOT, check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    names = set()
    with open(out) as f:
        for line in f:
            # fn=NAME, or NAME'2 for a recursion's deeper levels; (below main) and bare
            # addresses are not functions of the binary's symbol table
            name = re.sub(r"'[0-9]+$", "", line[3:].strip())
            if line.startswith("fn=") and re.fullmatch(r"[A-Za-z_.$][\w.$]*", name):
                names.add(name)
    os.remove(out)
    return names


def function_names(binary):
    """The binary's function names, in address order: [(address, name)]."""
    nm = subprocess.run(["nm", "-n", "--defined-only", binary], check=True,
                        capture_output=True, text=True).stdout
    return [(parts[0], parts[2]) for parts in (line.split() for line in nm.splitlines())
            if len(parts) == 3 and parts[1] in "tTwWiI"]


def names_to_write(binary):
    """For each function name: all names at its address, then its variants' names."""
    by_address = collections.defaultdict(list)
    family = collections.defaultdict(list)
    for address, name in function_names(binary):
        by_address[address].append(name)
        variant = VARIANT.fullmatch(name)
        if variant:
            family[variant.group(1)].append(name)
    expand = {}
    for names in by_address.values():
        for name in names:
            variant = VARIANT.fullmatch(name)
            expand[name] = names + (family[variant.group(1)] if variant else [])
    return expand


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("binary", help="the pcsg to profile (build/tools/pcsg)")
    parser.add_argument("-o", "--output", default=os.path.join(ROOT, "tools",
                                                               "pcsg_code_order.txt"))
    opts = parser.parse_args()
    binary = os.path.abspath(opts.binary)
    runs = collections.Counter()
    first_seen = {}
    with tempfile.TemporaryDirectory() as workdir:
        for name, args in COMMANDS:
            ran = functions_run(binary, args, workdir)
            print(f"{name}: {len(ran)} functions", file=sys.stderr)
            for fn in sorted(ran):
                runs[fn] += 1
                first_seen.setdefault(fn, len(first_seen))
    expand = names_to_write(binary)
    order = sorted(runs, key=lambda fn: (-runs[fn], first_seen[fn]))
    lines, written = [], set()
    for fn in order:
        for name in expand.get(fn, [fn]):
            if name not in written:
                written.add(name)
                lines.append(name)
    with open(opts.output, "w") as f:
        f.write("\n".join(lines) + "\n")
    print(f"{len(order)} functions, {len(lines)} names -> {opts.output}",
          file=sys.stderr)


if __name__ == "__main__":
    main()
