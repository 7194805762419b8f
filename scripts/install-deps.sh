#!/usr/bin/env bash
# Installs what shine needs from Debian when it is missing: the Vulkan loader, lavapipe
# (Mesa's CPU Vulkan driver) and the Khronos validation layer. Runs apt-get only when a
# package is absent, as root or through sudo.
set -euo pipefail

packages=(libvulkan1 mesa-vulkan-drivers vulkan-validationlayers)
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
