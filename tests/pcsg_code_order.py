#!/usr/bin/env python3
"""A release pcsg is linked with its code in the order of tools/pcsg_code_order.txt.

    python3 tests/pcsg_code_order.py PCSG ORDER

lld's --symbol-ordering-file (tools/CMakeLists.txt; the file is made by
tools/dev/code_order.py) lays out the functions a render runs next to each other, so a
process maps fewer pages of code (docs/benchmarks.md, branch floor). Checked on pcsg's own
functions that the file lists (_ZN4pcsg...): in the binary they follow the file's order,
and at least 3/4 of the bytes between the first and the last of them are functions the
file lists (the rest: functions that share an object file's section with listed ones,
and alignment). Linked without the order they follow the object files' order, spread over the
whole text among functions a render never runs.
"""
import subprocess
import sys


def functions(binary):
    """The binary's functions: name -> (address, size)."""
    nm = subprocess.run(["nm", "-S", "--defined-only", binary], check=True,
                        capture_output=True, text=True).stdout
    found = {}
    for line in nm.splitlines():
        parts = line.split()
        if len(parts) == 4 and parts[2] in "tTwWiI":
            found[parts[3]] = (int(parts[0], 16), int(parts[1], 16))
    return found


def main():
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    found = functions(sys.argv[1])
    with open(sys.argv[2]) as f:
        listed = [name for name in f.read().split() if name in found]
    own = []  # addresses of pcsg's listed functions, in the file's order, once each
    for name in listed:
        if name.startswith("_ZN4pcsg") and found[name][0] not in own:
            own.append(found[name][0])
    if len(own) < 100:
        print(f"FAIL: only {len(own)} of pcsg's functions in the order are in the binary")
        return 1
    rising = sum(b > a for a, b in zip(own, own[1:]))
    lo = min(own)
    hi = max(found[name][0] + found[name][1] for name in listed if found[name][0] in own)
    in_span = {found[name] for name in listed if lo <= found[name][0] < hi}
    listed_bytes = sum(size for _, size in in_span)
    print(f"{len(own)} of pcsg's functions in the order; {rising} of {len(own) - 1} steps "
          f"rise; {hi - lo} bytes from the first to the last, {listed_bytes} of them listed")
    if rising < 0.98 * (len(own) - 1):
        print("FAIL: pcsg's functions do not follow the order file")
        return 1
    if listed_bytes < 0.75 * (hi - lo):
        print("FAIL: functions the order does not list lie among those it does")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
