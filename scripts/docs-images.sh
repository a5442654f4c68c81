#!/usr/bin/env bash
# Regenerates the images shown in README.md and BENCHMARKS.md. First the soft shadows, on the
# default scene at rest under three maps (MAP: courtyard, the scene's own; sun, the synthetic 2°
# sun 45° up of tests/assets/sun/sun2-45.exr; studio, tests/assets/studio.exr), side by side:
#
#   docs/shadows-MAP-reference.png        `kage reference` (Monte Carlo, full visibility)
#   docs/shadows-MAP-tamura.png           `kage render --technique tamura` (Kage's default, q = 32)
#   docs/shadows-MAP-tamura-paper.png     `kage render --technique tamura-paper` (as published)
#   docs/shadows-MAP-parallel-lights.png  `kage render --technique parallel-lights` (q = 32)
#   docs/shadows-MAP-diff.png             `kage compare tamura.exr reference.exr --diff`:
#                                         |luminance(tamura) − luminance(reference)|, viridis,
#                                         yellow at the 99th percentile of those errors
#
# and prints each render's relative RMSE against the reference (`kage compare`) with the
# reference's own noise (`kage reference` prints it); then adaptive shadow maps on the `asm`
# scene's grating close-up (walkthrough keyframe 1):
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
# Separate PNGs, put side by side by Markdown tables in README.md: no image tool needed.
#
# Run by hand (not in CI), from anywhere: bash scripts/docs-images.sh
# Needs only the kage binary (built here with cargo) and a Vulkan device (lavapipe will do).
# Environment: SIZE (default 256, pixels per side), SPP (default 2048, reference samples per
# pixel), KAGE_DEVICE (device name substring). At 256×256 and 2048 spp each reference takes a
# few minutes on a 2-core lavapipe machine, and it runs twice (see below).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

SIZE="${SIZE:-256}"
SPP="${SPP:-2048}"
cargo build --release -p kage-tools
kage=target/release/kage
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

for map in courtyard sun studio; do
    case "$map" in
        courtyard) env=() ;;
        sun) env=(--env tests/assets/sun/sun2-45.exr) ;;
        studio) env=(--env tests/assets/studio.exr) ;;
    esac
    common=(--scene teapot "${env[@]}" --width "$SIZE" --height "$SIZE")
    # The reference: linear EXR for the metrics, and the same image again as a tonemapped PNG.
    # The renderer is deterministic for a fixed --seed and --spp (no --time-budget, which would
    # stop at a time-dependent batch), so the second run reproduces the first sample for sample.
    echo "== $map: reference"
    "$kage" reference "${common[@]}" --spp "$SPP" --seed 0 --out "$work/reference.exr"
    "$kage" reference "${common[@]}" --spp "$SPP" --seed 0 --out "docs/shadows-$map-reference.png"
    for technique in tamura tamura-paper parallel-lights; do
        "$kage" render "${common[@]}" --technique "$technique" --out "$work/$technique.exr"
        "$kage" render "${common[@]}" --technique "$technique" --out "docs/shadows-$map-$technique.png"
        echo "== $map: $technique vs reference"
        if [ "$technique" = tamura ]; then
            "$kage" compare "$work/$technique.exr" "$work/reference.exr" --diff "docs/shadows-$map-diff.png"
        else
            "$kage" compare "$work/$technique.exr" "$work/reference.exr"
        fi
    done
    echo "wrote docs/shadows-$map-*.png"
done

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

"$kage" render --scene probe-room --width "$SIZE" --height "$SIZE" --technique probes --probe-statics sloan --out docs/probes-room.png
echo "wrote docs/probes-room.png"
