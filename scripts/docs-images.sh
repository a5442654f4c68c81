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
# and prints the relative RMSE of tamura and sloan against the reference (`kage compare`).
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
