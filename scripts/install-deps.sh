#!/usr/bin/env bash
# Installs what shine needs from Debian when it is missing: the Vulkan loader, lavapipe
# (Mesa's CPU Vulkan driver) and the Khronos validation layer. Runs apt-get only when a
# package is absent, as root or through sudo.
set -euo pipefail

packages=(libvulkan1 mesa-vulkan-drivers vulkan-validationlayers)
# Chromium, headless: the lab page test (tests/lab_page.rs) drives it.
packages+=(chromium)
# A single-node Slurm cluster (scripts/slurm/local-cluster.sh): tests/slurm.rs runs the sbatch
# templates on it.
packages+=(slurm-wlm munge)
# The C API's C++ host example (examples/capi_host, built and run by crates/capi/tests):
# Vulkan headers, and glslangValidator for its G-buffer shaders.
packages+=(libvulkan-dev glslang-tools g++ make)
# Node.js runs the Khronos glTF validator over the built-in scenes (crates/scene/tests).
if ! command -v npm >/dev/null 2>&1; then
    packages+=(nodejs npm)
fi
missing=()
for p in "${packages[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
        missing+=("$p")
    fi
done

if [ ${#missing[@]} -gt 0 ]; then
    echo "installing: ${missing[*]}"
    sudo=""
    if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
    $sudo apt-get update
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y "${missing[@]}"
fi

# The validator itself, pinned by crates/scene/tests/validator/package-lock.json.
validator="$(dirname "$0")/../crates/scene/tests/validator"
if [ ! -d "$validator/node_modules/gltf-validator" ]; then
    npm ci --prefix "$validator" --no-audit --no-fund
fi
