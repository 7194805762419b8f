#!/usr/bin/env bash
# Where a shader's time goes on lavapipe, instruction by instruction (docs/pitfalls.md, "Reading
# llvmpipe's machine code"). lavapipe compiles each pipeline to x86 code in anonymous executable
# memory that perf cannot name. This script runs a command, samples it with perf after a
# warm-up, dumps the executable region holding the most samples (the hottest pipeline) with gdb,
# disassembles it and prints its loops (back-edges) with their share of the samples.
#
# Usage: scripts/jit-profile.sh NAME [--delay S] [--seconds S] -- COMMAND...
#   e.g. scripts/jit-profile.sh gather -- target/release/shine profile builtin:cornell-box \
#            --width 256 --height 256 --frames 300 --warmup 2
# Writes out/jit-profile/NAME.{s,annotated,ips}: the disassembly, the same with each
# instruction's sample count in front, and the raw sample addresses. Needs perf, gdb, objdump
# and permission to attach to the process (ptrace). The command must run longer than
# delay + seconds (defaults 4 + 5).
set -euo pipefail
cd "$(dirname "$0")/.."
name="${1:?usage: scripts/jit-profile.sh NAME [--delay S] [--seconds S] -- COMMAND...}"
shift
delay=4
seconds=5
while [ $# -gt 0 ] && [ "$1" != "--" ]; do
    case "$1" in
        --delay) delay="$2"; shift 2 ;;
        --seconds) seconds="$2"; shift 2 ;;
        *) echo "unknown option $1" >&2; exit 2 ;;
    esac
done
[ "${1:-}" = "--" ] || { echo "missing -- COMMAND" >&2; exit 2; }
shift
for tool in perf gdb objdump python3; do
    command -v "$tool" > /dev/null || { echo "jit-profile needs $tool" >&2; exit 1; }
done
out=out/jit-profile
mkdir -p "$out"
"$@" > "$out/$name.log" 2>&1 &
pid=$!
trap 'kill "$pid" 2> /dev/null || true' EXIT
sleep "$delay"
kill -0 "$pid" 2> /dev/null || { echo "the command ended before the sampling began" >&2; exit 1; }
echo "sampling pid $pid for $seconds s" >&2
perf record -q -o "$out/$name.perf" -p "$pid" -- sleep "$seconds" > /dev/null 2>&1
perf script -i "$out/$name.perf" -F ip 2> /dev/null | sort | uniq -c | awk '{print $2, $1}' \
    > "$out/$name.ips"
python3 - "$pid" "$out" "$name" <<'PY'
import re, subprocess, sys

pid, out, name = sys.argv[1:]
ips = {int(a, 16): int(c) for a, c in (l.split() for l in open(f"{out}/{name}.ips"))}
total = sum(ips.values())
best = None
for line in open(f"/proc/{pid}/maps"):
    f = line.split()
    # Anonymous executable mappings: lavapipe's compiled shaders.
    if f[1] == "r-xp" and len(f) == 5:
        lo, hi = (int(x, 16) for x in f[0].split("-"))
        s = sum(c for a, c in ips.items() if lo <= a < hi)
        if best is None or s > best[2]:
            best = (lo, hi, s)
if best is None or best[2] == 0:
    sys.exit("no samples in anonymous executable memory: is the command running shaders?")
lo, hi, s = best
print(f"hottest region {lo:#x}-{hi:#x}: {s} of {total} samples ({100 * s / total:.1f}%)")
subprocess.run(["gdb", "-p", pid, "-batch", "-ex", f"dump memory {out}/{name}.bin {lo:#x} {hi:#x}"],
               capture_output=True, check=True)
asm = subprocess.run(["objdump", "-D", "-b", "binary", "-m", "i386:x86-64", f"--adjust-vma={lo:#x}",
                      f"{out}/{name}.bin"], capture_output=True, text=True, check=True).stdout
open(f"{out}/{name}.s", "w").write(asm)
rows = []
for line in asm.splitlines():
    p = line.split("\t")
    if len(p) >= 3 and p[0].strip().endswith(":"):
        a = int(p[0].strip()[:-1], 16)
        rows.append((a, ips.get(a, 0), p[2]))
open(f"{out}/{name}.annotated", "w").write(
    "\n".join(f"{c:6d} {a:x} {i}" for a, c, i in rows) + "\n")
index = {a: k for k, (a, _, _) in enumerate(rows)}
print(f"{len(rows)} instructions; loops with at least 1% of the region's samples:")
for k, (a, _, ins) in enumerate(rows):
    m = re.match(r"j\w+\s+0x([0-9a-f]+)", ins)
    if m and int(m.group(1), 16) < a and int(m.group(1), 16) in index:
        first = index[int(m.group(1), 16)]
        share = sum(c for _, c, _ in rows[first:k + 1]) / s
        if share >= 0.01:
            print(f"  lines {first + 1}-{k + 1} of {name}.annotated: {k - first + 1} instructions,"
                  f" {100 * share:.1f}%")
PY
