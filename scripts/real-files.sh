#!/usr/bin/env bash
# Scenes users bring, measured: files nobody here wrote by hand (Khronos glTF samples, Blender
# exports, scanned and classic meshes), each read alone as `--scene FILE` (the default sky, the
# file's camera or a view of the whole). Prints one Markdown row per file for BENCHMARKS.md:
# triangles and read time (`kage scene info`), the PRT precomputation (`kage precompute
# --force`, default 3 bands and 2048 rays), and the median GPU frame at SIZE² over FRAMES frames
# of every technique (`kage render`; "—" where the file has what a technique needs not: a light
# for shadowmap and asm, a static group beside the moving one for probes); and writes a picture
# of each with Kage's default technique (tamura, --exposure auto) to docs/real-files/NAME.png.
#
# The eighth file is a Blender export made here: tests/assets/gltf/blender-suzanne/make.py with
# Suzanne subdivided three times (63k triangles); it needs Blender (Debian: blender
# python3-numpy), and the row is left out without it.
#
# Run by hand (not in CI): bash scripts/real-files.sh
# Environment: SIZE (default 512), FRAMES (default 20), KAGE_DEVICE (device name substring).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

SIZE="${SIZE:-512}"
FRAMES="${FRAMES:-20}"
cargo build --release -p kage-tools
kage=target/release/kage
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p docs/real-files

files=(
  tests/assets/gltf/khronos-box/Box.gltf
  tests/assets/gltf/khronos-box-animated/BoxAnimated.gltf
  tests/assets/gltf/khronos-box-textured/BoxTextured.gltf
  tests/assets/gltf/blender-teapot/teapot.glb
  tests/assets/gltf/blender-suzanne/scene.glb
  tests/assets/bunny/bunny.obj
  engine/assets/teapot.obj
)
if command -v blender > /dev/null; then
  OUT="$work/blender-suzanne-subdivided.glb" SUBDIVISIONS=3 \
    blender --background --factory-startup --python tests/assets/gltf/blender-suzanne/make.py > /dev/null
  files+=("$work/blender-suzanne-subdivided.glb")
fi

techniques=(unshadowed sloan-self sloan-scene tamura tamura-paper parallel-lights probes shadowmap asm)
device=()
[ -n "${KAGE_DEVICE:-}" ] && device=(--device "$KAGE_DEVICE")

printf '| file | triangles | read ms | precompute s |'
printf ' %s |' "${techniques[@]}"
printf '\n|---|---:|---:|---:|'
printf -- '---:|%.0s' "${techniques[@]}"
printf '\n'
for file in "${files[@]}"; do
  name=$(basename "$(dirname "$file")")-$(basename "${file%.*}")
  [[ "$file" == "$work"/* ]] && name=$(basename "${file%.*}")
  cache="$work/cache-$name"
  info=$("$kage" scene info --scene "$file" --json 2> /dev/null)
  triangles=$(python3 -c 'import json, sys; print(json.load(sys.stdin)["triangles"])' <<< "$info")
  read_ms=$(python3 -c 'import json, sys; print("%.1f" % json.load(sys.stdin)["read_ms"])' <<< "$info")
  precompute=$("$kage" precompute --scene "$file" --force --cache "$cache" "${device[@]}" 2> /dev/null \
    | sed -n 's/^time: \([0-9.]*\) s.*/\1/p')
  printf '| %s | %s | %s | %s |' "$name" "$triangles" "$read_ms" "$precompute"
  for technique in "${techniques[@]}"; do
    frame=$("$kage" render --scene "$file" --technique "$technique" --width "$SIZE" --height "$SIZE" \
      --frames "$FRAMES" --cache "$cache" "${device[@]}" --out "$work/out.exr" 2> /dev/null \
      | sed -n 's/^frame *\([0-9.]*\).*/\1/p' || true)
    printf ' %s |' "${frame:-—}"
  done
  printf '\n'
  "$kage" render --scene "$file" --width 256 --height 256 --exposure auto --cache "$cache" "${device[@]}" \
    --out "docs/real-files/$name.png" > /dev/null 2>&1
done
