#!/usr/bin/env bash
# Renders every built-in scene in every GI mode (and a few non-default settings of each
# technique) with the engine built from BASE and with the working tree, and checks that the
# images are identical to the bit. It is the proof a behaviour-preserving refactor gives.
#
#   scripts/same-images.sh [BASE]     BASE: a git revision (default: HEAD)
#
# EXR (the linear HDR frame, f32) and PNG (tonemapped) are both compared; a case that fails
# must fail with the same message on both sides. BASE is checked out in a worktree under
# target/same-images/ and built into a target directory of its own (cargo keys the workspace's
# own crates by their path inside the workspace, so two trees sharing one target directory
# would take each other's builds for fresh): the first run builds every dependency there once
# (several minutes on two cores), later runs against any BASE rebuild only shine's crates.
# Exit status 0 when every case matches, 1 otherwise (the differing cases are listed).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
base=$(git rev-parse --verify "${1:-HEAD}^{commit}")
work="$root/target/same-images"
mkdir -p "$work"

size=(--width 64 --height 64)
scenes=(cornell-box room spheres)
# label|flags: every GI mode, then settings that take other branches of each technique.
cases=(
  "none|--gi none"
  "hvl|--gi hvl"
  "igi|--gi igi"
  "proxy|--gi proxy"
  "hvl-proxy|--gi hvl,proxy"
  "igi-proxy|--gi igi,proxy"
  "hvl-r1-zonal|--gi hvl --set hvl.radius=r1 --set hvl.gather=zonal --set hvl.count=100"
  "hvl-visibility|--gi hvl --set hvl.visibility=true --set hvl.count=64"
  "hvl-indirect|--gi hvl --set output.component=indirect --set receiver_scale=4"
  "igi-irradiance|--gi igi --set igi.filter=irradiance --set igi.n=2 --set igi.m=2"
  "igi-phong|--gi igi --set igi.glossy=phong --set igi.sh_order=2"
  "proxy-brute|--gi proxy --set proxy.brute_force=true --set proxy.sh_order=3"
  "proxy-ol-fit|--gi proxy --set proxy.exp=ol --set proxy.fit_count=2 --set proxy.indirect=false"
  "direct-aces|--gi none --set output.component=direct --tonemap aces --exposure 2"
)

# build TREE TARGET-DIR OUT-BIN: release build of TREE into TARGET-DIR, binary copied to OUT-BIN.
build() {
  echo "building $1" >&2
  CARGO_TARGET_DIR="$2" cargo build --release --quiet --manifest-path "$1/Cargo.toml" --bin shine
  cp "$2/release/shine" "$3"
}

# render BIN DIR: every scene × case into DIR (images, or the error text of a refused case).
render() {
  local bin=$1 dir=$2
  rm -rf "$dir"
  mkdir -p "$dir"
  for scene in "${scenes[@]}"; do
    for case in "${cases[@]}"; do
      local label=${case%%|*} flags=${case#*|}
      local stem="$dir/$scene-$label"
      # shellcheck disable=SC2086 # flags are words on purpose
      if ! "$bin" render "builtin:$scene" "${size[@]}" $flags -o "$stem.exr" \
        >/dev/null 2>"$stem.err"; then
        echo "refused" >>"$stem.err"
        continue
      fi
      # shellcheck disable=SC2086
      "$bin" render "builtin:$scene" "${size[@]}" $flags -o "$stem.png" >/dev/null 2>&1
      rm -f "$stem.err"
    done
  done
}

tree="$work/$base"
if [ ! -d "$tree" ]; then
  git worktree add --detach "$tree" "$base" >/dev/null
fi
base_target="$work/target"
# The working tree first: once its binary is copied, it may change while BASE builds.
build "$root" "$root/target" "$work/shine-head"
build "$tree" "$base_target" "$work/shine-base"
echo "rendering ${#scenes[@]} scenes × ${#cases[@]} cases with each build" >&2
render "$work/shine-base" "$work/out-base"
render "$work/shine-head" "$work/out-head"

status=0
compared=0
for f in "$work/out-base"/*; do
  name=$(basename "$f")
  compared=$((compared + 1))
  if ! cmp -s "$f" "$work/out-head/$name"; then
    echo "differs: $name"
    status=1
  fi
done
for f in "$work/out-head"/*; do
  [ -e "$work/out-base/$(basename "$f")" ] || { echo "only in the working tree: $(basename "$f")"; status=1; }
done
refused=$(find "$work/out-base" -name '*.err' | wc -l)
echo "$compared files compared ($refused refused cases compared by message) against $(git rev-parse --short "$base"): $([ $status = 0 ] && echo identical || echo DIFFERENT)"
exit $status
