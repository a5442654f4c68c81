#!/usr/bin/env bash
# Installs what Kage needs on a Debian/Ubuntu machine and prepares the static glslang/shaderc
# archive that the engine links (see vendor-notes.md, "Building shaders"). Idempotent.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

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

# Debian's libshaderc_combined.a lacks glslang and SPIRV-Tools: merge them into one archive so
# that the shaderc crate links it instead of spending ~10 minutes building glslang from source.
libdir=/usr/lib/$(gcc -print-multiarch)
out="$root/.deps/shaderc"
if [ ! -f "$out/libshaderc_combined.a" ]; then
  mkdir -p "$out"
  {
    echo "create $out/libshaderc_combined.a"
    for a in shaderc_combined glslang MachineIndependent GenericCodeGen OSDependent OGLCompiler \
             HLSL SPIRV SPIRV-Tools-opt SPIRV-Tools glslang-default-resource-limits; do
      echo "addlib $libdir/lib$a.a"
    done
    echo save
    echo end
  } | ar -M
fi
