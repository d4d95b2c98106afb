#!/usr/bin/env bash
# bench/bench_build_model.sh runs to its end on the liver and prints every row of its table:
# the benchmark reads the model's folder layout, which a change of the model format would break.
# Skips (77) without the liver labels in $MRSNAKE_DATA.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
data="${MRSNAKE_DATA:-$root/../shared/data}"
[ -f "$data/volumes/liver-labels.nii.gz" ] || { echo "skipped: $data/volumes/liver-labels.nii.gz not found (set MRSNAKE_DATA)"; exit 77; }
out="$(MRSNAKE_DATA="$data" bash "$root/bench/bench_build_model.sh")"
echo "$out"
for row in "total (in process)" "wall (process)" "peak memory (MB)" "RMS %" "Hausdorff %" "Q mean" "valence 6 %"; do
  grep -q "^$row " <<<"$out" || { echo "bench_build_model.sh printed no '$row' row"; exit 1; }
done
