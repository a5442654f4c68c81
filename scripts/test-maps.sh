#!/usr/bin/env bash
# Writes the synthetic sun maps of tests/assets/sun/ with `kage env sun` (1024×512 EXR): a sun
# alone of 0.5° and 2° radius at 15°, 45° and 80° elevation, and a 2° sun over a dim sky. Each
# sun gives the same irradiance (radiance × radius² held), from azimuth 90° (+X).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
cargo build --release -p kage-tools
kage=target/release/kage
out=tests/assets/sun
mkdir -p "$out"
for elevation in 15 45 80; do
  "$kage" env sun --elevation "$elevation" --radius 2 --radiance 2000,2000,2000 --out "$out/sun2-$elevation.exr"
  "$kage" env sun --elevation "$elevation" --radius 0.5 --radiance 32000,32000,32000 --out "$out/sun05-$elevation.exr"
done
"$kage" env sun --elevation 45 --radius 2 --radiance 2000,2000,2000 --sky 0.4,0.5,0.6 --ground 0.1,0.1,0.1 \
  --out "$out/sun2-45-sky.exr"
