#!/usr/bin/env bash
# Regenerates the side-by-side images of the Tamura–Johan–Nishita technique shown in README.md
# (issue 4: "Images side by side (reference, tamura, sloan, difference) for the default scene"):
#
#   docs/tamura-reference.png  `kage reference` (Monte Carlo, full visibility), tonemapped
#   docs/tamura-tamura.png     `kage render --technique tamura` (q = 32, 3 bands, 2048 rays)
#   docs/tamura-sloan.png      `kage render --technique sloan` (self-shadowing PRT only)
#   docs/tamura-diff.png       `kage compare tamura.exr reference.exr --diff`: per-pixel
#                              |luminance(tamura) − luminance(reference)|, viridis, yellow at the
#                              99th percentile of those errors
#
# and prints the relative RMSE of tamura and sloan against the reference (`kage compare`);
# then adaptive shadow maps on the `asm` scene's grating close-up (walkthrough keyframe 1):
#
#   docs/asm-reference.png     `kage reference --light local` (hard shadows, exact)
#   docs/asm-asm.png           `kage render --technique asm --asm-budget-mb 16` after 20 frames
#   docs/asm-mismatch-asm.png  `kage compare --mismatch-image` of the ASM render: red lit in
#                              the render only, blue lit in the reference only
#   docs/asm-mismatch-map.png  the same for the conventional 2048² map (16 MiB too)
#
# and the light probes in probe-room, the bunny lit by 18 probes, the room by Sloan's PRT:
#
#   docs/probes-room.png       `kage render --technique probes --probe-statics sloan`
# Four separate PNGs, put side by side by a Markdown table in README.md: no image tool needed.
#
# Run by hand (not in CI), from anywhere: bash scripts/docs-images.sh
# Needs only the kage binary (built here with cargo) and a Vulkan device (lavapipe will do).
# Environment: SIZE (default 256, pixels per side), SPP (default 1024, reference samples per
# pixel), KAGE_DEVICE (device name substring). At 256×256 and 1024 spp the reference takes about
# a minute on a 2-core lavapipe machine, and it runs twice (see below).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

SIZE="${SIZE:-256}"
SPP="${SPP:-1024}"
cargo build --release -p kage-tools
kage=target/release/kage
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

common=(--scene teapot --width "$SIZE" --height "$SIZE")

# The reference: linear EXR for the metrics, and the same image again as a tonemapped PNG. The
# renderer is deterministic for a fixed --seed and --spp (no --time-budget, which would stop at
# a time-dependent batch), so the second run reproduces the first sample for sample.
"$kage" reference "${common[@]}" --spp "$SPP" --seed 0 --out "$work/reference.exr"
"$kage" reference "${common[@]}" --spp "$SPP" --seed 0 --out docs/tamura-reference.png

for technique in tamura sloan; do
    "$kage" render "${common[@]}" --technique "$technique" --out "$work/$technique.exr"
    "$kage" render "${common[@]}" --technique "$technique" --out "docs/tamura-$technique.png"
done

echo "== tamura vs reference"
"$kage" compare "$work/tamura.exr" "$work/reference.exr" --diff docs/tamura-diff.png
echo "== sloan vs reference"
"$kage" compare "$work/sloan.exr" "$work/reference.exr"
echo "wrote docs/tamura-reference.png docs/tamura-tamura.png docs/tamura-sloan.png docs/tamura-diff.png"

close=(--scene asm --keyframe 1 --width "$SIZE" --height "$SIZE")
"$kage" reference "${close[@]}" --light local --out "$work/asm-reference.exr"
"$kage" reference "${close[@]}" --light local --out docs/asm-reference.png
"$kage" render "${close[@]}" --technique asm --asm-budget-mb 16 --frames 20 --out "$work/asm.exr"
"$kage" render "${close[@]}" --technique asm --asm-budget-mb 16 --frames 20 --out docs/asm-asm.png
"$kage" render "${close[@]}" --technique shadowmap --shadowmap-size 2048 --out "$work/map.exr"
echo "== asm (16 MiB) vs reference"
"$kage" compare "$work/asm.exr" "$work/asm-reference.exr" --shadow-mismatch --mismatch-image docs/asm-mismatch-asm.png
echo "== shadowmap 2048² (16 MiB) vs reference"
"$kage" compare "$work/map.exr" "$work/asm-reference.exr" --shadow-mismatch --mismatch-image docs/asm-mismatch-map.png
echo "wrote docs/asm-reference.png docs/asm-asm.png docs/asm-mismatch-asm.png docs/asm-mismatch-map.png"

"$kage" render --scene probe-room --width "$SIZE" --height "$SIZE" --technique probes --probe-statics sloan --exposure 4 --out docs/probes-room.png
echo "wrote docs/probes-room.png"
