#!/usr/bin/env bash
# Regenerates the speed-against-accuracy charts shown in BENCHMARKS.md (docs/sweep-*.png) with
# `kage sweep`, and keeps each sweep's CSV beside its chart. Run by hand, not in CI: the PRT
# sweep takes about 15 minutes on a 2-core lavapipe machine once its references are cached
# (run to 0.5 % noise, they take about 10 more the first time), the ASM sweep about 2 (references cached; 5 more to ray-cast them) and the
# probe sweeps (probe-room and atrium) about 5 each. Frame times are only as good as the
# machine is quiet: run it with nothing else busy.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
cargo build --release -p kage-tools
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
# NAME, then the sweep's arguments: runs it and keeps its chart and CSV as docs/sweep-NAME.*.
sweep() {
  local name=$1
  shift
  target/release/kage sweep "$@" --out "$work/$name"
  cp "$work/$name/pareto.png" "docs/sweep-$name.png"
  cp "$work/$name/sweep.csv" "docs/sweep-$name.csv"
  echo "wrote docs/sweep-$name.png docs/sweep-$name.csv"
}
sweep prt --technique prt
sweep asm --technique asm --size 256 --frames 200
sweep probes-room --technique probes --scene probe-room --spp 8192
sweep probes-atrium --technique probes --scene atrium --spp 8192
