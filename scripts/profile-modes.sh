#!/usr/bin/env bash
# Every GI mode on several scenes at one resolution, timed per pass with GPU timestamps
# (docs/performance.md, "A real GPU"): one `shine profile --format json` per scene and mode into
# OUT_DIR, then a table of each frame split into its raster passes (G-buffer, shadow maps, RSMs)
# and the rest. Meant for real GPUs (lavapipe's timestamps miss compute work: there, pass
# `--clock host` through CLOCK=host).
# Usage: scripts/profile-modes.sh [OUT_DIR] [WIDTH] [HEIGHT]   (out/modes 1920 1080)
# Environment: SHINE (binary; default: build target/release/shine), FRAMES (60), CLOCK (gpu).
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-out/modes}"
width="${2:-1920}"
height="${3:-1080}"
mkdir -p "$out"
if [ -z "${SHINE:-}" ]; then
    cargo build --release --quiet
    SHINE=target/release/shine
fi
# The proxies need an environment light: only the scenes with one get them.
runs="cornell-box:hvl cornell-box:igi cornell-box:aaf cornell-box:none
room:hvl room:igi room:aaf room:none
marbles:hvl marbles:igi marbles:proxy marbles:aaf marbles:none marbles:hvl,proxy
spheres:hvl spheres:proxy"
total=$(echo $runs | wc -w)
k=0
failed=0
for run in $runs; do
    k=$((k + 1))
    scene=${run%%:*}
    gi=${run#*:}
    name="${scene}_${gi/,/+}"
    echo "[$k/$total] $scene --gi $gi" >&2
    if ! "$SHINE" profile "builtin:$scene" --width "$width" --height "$height" --gi "$gi" \
        --frames "${FRAMES:-60}" --warmup 5 --clock "${CLOCK:-gpu}" --format json \
        > "$out/$name.json" 2> "$out/$name.log"; then
        echo "  failed: see $out/$name.log" >&2
        rm -f "$out/$name.json"
        failed=$((failed + 1))
    fi
done
python3 - "$out" <<'PY'
import glob, json, os, sys

def raster(name):
    return name == "gbuffer" or name.startswith("shadow light") or name.startswith("rsm")

print("| scene, mode | frame ms | raster ms | the rest ms | largest other passes (ms) |")
print("|---|---|---|---|---|")
for path in sorted(glob.glob(os.path.join(sys.argv[1], "*.json"))):
    d = json.load(open(path))
    passes = d["passes"]
    frame = d["frame"]["median_ms"]
    r = sum(p["time"]["median_ms"] for p in passes if raster(p["name"]))
    top = sorted((p for p in passes if not raster(p["name"])), key=lambda p: -p["time"]["median_ms"])[:3]
    name = os.path.basename(path)[:-5].replace("_", ", ")
    print(f"| {name} | {frame:.2f} | {r:.2f} | {frame - r:.2f} | "
          + ", ".join(f"{p['name']} {p['time']['median_ms']:.2f}" for p in top) + " |")
if passes:
    print(f"\n{d['run']['device']}, {d['run']['driver']}, {d['run']['width']}x{d['run']['height']}, "
          f"revision {d['run']['revision']}, clock {d['clock']}")
PY
exit $((failed > 0))
