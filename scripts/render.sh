#!/usr/bin/env bash
# Set-up command 1: installs what is missing, builds Kage and renders the default scene with
# Tamura's soft shadows (the default technique) to kage.png (and kage.exr), printing the
# per-pass GPU timings.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
bash scripts/deps.sh
cargo build --release -p kage-tools
./target/release/kage render --validate --out kage.png "$@"
./target/release/kage render --validate --out kage.exr --timings kage-timings.json "$@"
