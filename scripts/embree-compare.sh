#!/usr/bin/env bash
# Kage's ray casting and PRT precomputation against Embree 4 on one CPU thread, on the same
# rays, in one run: `kage bench rays --export` (any and closest hits, coherent and incoherent
# rays), `kage precompute --force` (its rays per second and the split of its time), then
# scripts/embree-rays.py on the exported rays; prints each Kage rate over Embree's and the
# time Embree would take for the precomputation's rays (its rate on the PRT rays of every 16th
# vertex).
#
# Benchmark only, not part of CI: needs `pip install embreex numpy`.
# Run by hand: bash scripts/embree-compare.sh [SCENE]   (default: the full Stanford bunny)
# Environment: KAGE_DEVICE (device name substring), KAGE (the kage binary; default: build it),
# ROUNDS (default 1): rounds of the whole comparison, Kage's casts and precomputation each
# followed at once by Embree's, whose ratios are printed with their median: a machine whose
# speed drifts from minute to minute moves both sides of a round alike.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

scene="${1:-tests/assets/stanford-bunny/scene.json}"
if [ -z "${KAGE:-}" ]; then
  cargo build --release -p kage-tools
  KAGE=target/release/kage
fi
device=()
[ -n "${KAGE_DEVICE:-}" ] && device=(--device "$KAGE_DEVICE")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

for round in $(seq 1 "${ROUNDS:-1}"); do
  # The first round writes the rays every round casts (the same rays: the generator is seeded).
  export_to=()
  [ "$round" = 1 ] && export_to=(--export "$work")
  "$KAGE" bench rays --scene "$scene" "${export_to[@]}" "${device[@]}" | tee "$work/kage-$round.txt"
  python3 scripts/embree-rays.py "$work" 5 --rays-only | tee "$work/embree-rays-$round.txt"
  "$KAGE" precompute --scene "$scene" --force --cache "$work/cache" "${device[@]}" | tee "$work/precompute-$round.txt"
  python3 scripts/embree-rays.py "$work" 5 --prt-only | tee "$work/embree-$round.txt"
done

python3 - "$work" "${ROUNDS:-1}" <<'PY'
import re, sys
folder, rounds = sys.argv[1], int(sys.argv[2])
print("\nKage over Embree (one thread), Mrays/s, round by round:")
for query in ["closest hit", "any hit"]:
    for column, ray_set in [(1, "coherent"), (2, "incoherent")]:
        pairs = []
        for r in range(1, rounds + 1):
            kage = open(f"{folder}/kage-{r}.txt").read()
            embree = open(f"{folder}/embree-rays-{r}.txt").read()
            k = float(re.search(rf"^{query}\s+\S+\s+(\S+)\s+\S+\s+(\S+)", kage, re.M).group(column))
            e = float(re.search(rf"^{query}\s+{ray_set}\s+\S+\s+(\S+)", embree, re.M).group(1))
            pairs.append((k, e))
        shown = ", ".join(f"{k:.3f} / {e:.3f}" for k, e in pairs)
        ratios = sorted(k / e for k, e in pairs)
        print(f"  {query:<12} {ray_set:<11} {shown}: median {ratios[len(ratios) // 2]:.2f}x, "
              f"{ratios[0]:.2f}-{ratios[-1]:.2f}x")
ratios = []
for r in range(1, rounds + 1):
    precompute = open(f"{folder}/precompute-{r}.txt").read()
    seconds = float(re.search(r"^time: (\S+) s", precompute, re.M).group(1))
    vertices, per_vertex = re.search(r"(\d+) vertices; .* (\d+) rays per vertex", precompute).groups()
    rays = float(vertices) * float(per_vertex)
    prt = open(f"{folder}/embree-{r}.txt").read()
    e = float(re.search(r"^closest hit\s+prt\s+\S+\s+(\S+)", prt, re.M).group(1)) * 1e6
    ratios.append(seconds / (rays / e))
    print(f"  precompute, round {r}: Kage {seconds:.2f} s for {rays / 1e6:.1f} M rays; Embree at its PRT-ray "
          f"rate {e / 1e6:.2f} Mrays/s: {rays / e:.2f} s; Kage / Embree = {ratios[-1]:.2f}x")
ratios.sort()
print(f"  precompute, Kage / Embree over {rounds} round(s): median {ratios[len(ratios) // 2]:.2f}x, "
      f"{ratios[0]:.2f}-{ratios[-1]:.2f}x")
PY
