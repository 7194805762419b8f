#!/usr/bin/env bash
# Fixed benchmark configurations of shine, each measured beside its peer or peak in the same run
# (docs/performance.md, "Benchmarks"):
#   - the device's fp32 FMA peak and memory bandwidth (shine profile --roofline; cached per device)
#     and the HVL gather at builtin:cornell-box 256x256 against them;
#   - the path tracer's samples per second at builtin:cornell-box 256x256, one bounce, against
#     Mitsuba 3's Cornell box at the same size and depth (scalar_rgb and llvm_ad_rgb), only when
#     the `mitsuba` Python package is installed.
# Prints a table and writes OUT_DIR/bench.json. Usage: scripts/bench.sh [OUT_DIR] (out/bench).
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-out/bench}"
mkdir -p "$out"
cargo build --release --quiet
shine=target/release/shine

echo "[1/3] shine profile --roofline (cornell-box 256x256, 20 frames)" >&2
"$shine" profile builtin:cornell-box --width 256 --height 256 --frames 20 --warmup 3 \
    --roofline --format json > "$out/profile.json"

echo "[2/3] shine reference (cornell-box 256x256, 64 spp, 1 bounce)" >&2
"$shine" reference builtin:cornell-box --width 256 --height 256 --spp 64 --bounces 1 \
    -o "$out/reference.exr" > "$out/reference.log" 2>&1

echo "[3/3] Mitsuba 3 (if installed)" >&2
: > "$out/mitsuba.jsonl"
if python3 -c "import mitsuba" 2> /dev/null; then
    for variant in scalar_rgb llvm_ad_rgb; do
        # max_depth 3: the emitter seen, direct light, one bounce (shine's --bounces 1).
        # An inner shell that does not exec python (`; exit $?`): a variant that aborts
        # (llvm_ad_rgb against an old system LLVM) has the shell's "Aborted" go to its log,
        # and is reported below.
        if ! bash -c 'python3 scripts/mitsuba_cbox.py "$@"; exit $?' _ "$variant" 256 256 64 3 \
            >> "$out/mitsuba.jsonl" 2> "$out/mitsuba-$variant.log"; then
            echo "  mitsuba $variant failed: see $out/mitsuba-$variant.log" >&2
        fi
    done
else
    echo "  mitsuba is not installed (pip install mitsuba): its peers are left out" >&2
fi

python3 - "$out" <<'PY'
import json, re, sys, pathlib
out = pathlib.Path(sys.argv[1])
profile = json.loads((out / "profile.json").read_text())
roof = profile["roofline"]
gather = next(p for p in roof["passes"] if p["name"] == "hvl_gather")
median = next(p for p in profile["passes"] if p["name"] == "hvl_gather")["time"]["median_ms"]
log = (out / "reference.log").read_text()
ns = float(re.search(r"([0-9.]+) ns per sample per pixel", log).group(1))
shine_sps = 1e9 / ns
peers = [json.loads(l) for l in (out / "mitsuba.jsonl").read_text().splitlines() if l.strip()]
rows = [
    ("fp32 FMA peak (micro-kernel)", f"{roof['peaks']['gflops']:.1f} GFLOP/s", ""),
    ("memory bandwidth (micro-kernel)", f"{roof['peaks']['gbps']:.2f} GB/s", ""),
    ("hvl_gather median", f"{median:.1f} ms", ""),
    ("hvl_gather achieved", f"{gather['gflops']:.2f} GFLOP/s",
     f"{100 * gather['flop_share']:.1f}% of the FMA peak"),
    ("path tracer", f"{shine_sps / 1e6:.3f} M samples/s", ""),
]
for p in peers:
    rows.append((f"Mitsuba {p['version']} {p['variant']}",
                 f"{p['samples_per_second'] / 1e6:.3f} M samples/s",
                 f"shine / Mitsuba = {shine_sps / p['samples_per_second']:.2f}"))
width = max(len(r[0]) for r in rows)
print(f"device: {profile['run']['device']}, revision {profile['run']['revision']}")
for name, value, ratio in rows:
    print(f"{name:<{width}}  {value:>22}  {ratio}")
(out / "bench.json").write_text(json.dumps({
    "run": profile["run"], "peaks": roof["peaks"],
    "hvl_gather": {"median_ms": median, **gather},
    "path_tracer_samples_per_second": shine_sps, "mitsuba": peers}, indent=2))
PY
