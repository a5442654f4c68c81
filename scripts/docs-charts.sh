#!/usr/bin/env bash
# Regenerates the speed-against-accuracy charts shown in README.md (docs/sweep-*.png) with
# `kage sweep`, and keeps each sweep's CSV beside its chart. Run by hand, not in CI: the PRT
# sweep takes about 15 minutes on a 2-core lavapipe machine. Frame times are only as good as the
# machine is quiet: run it with nothing else busy.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
cargo build --release -p kage-tools
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
target/release/kage sweep --technique prt --out "$work/prt"
cp "$work/prt/pareto.png" docs/sweep-prt.png
cp "$work/prt/sweep.csv" docs/sweep-prt.csv
echo "wrote docs/sweep-prt.png docs/sweep-prt.csv"
