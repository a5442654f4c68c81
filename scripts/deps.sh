#!/usr/bin/env bash
# Installs the Debian/Ubuntu packages Kage needs: the Vulkan loader, lavapipe, the validation
# layers, the static shaderc/glslang/SPIRV-Tools libraries the engine's build script links
# (vendor-notes.md, "Building shaders"), and what the tests use. Idempotent.
set -euo pipefail

# gcc, g++, libvulkan-dev and valgrind: the C ABI tests compile C hosts (and kage.h as C++),
# link them with -lvulkan and run them under memcheck. fonts-dejavu-core: the text of the charts
# `kage sweep` draws.
packages=(mesa-vulkan-drivers libvulkan1 libvulkan-dev vulkan-tools vulkan-validationlayers
          libshaderc-dev glslang-dev spirv-tools valgrind gcc g++ fonts-dejavu-core)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "kage: installing ${missing[*]}"
  sudo=""; [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
