#!/usr/bin/env bash
# End-to-end benchmark of `mrsnake build-model` on the liver labels (label 255): seconds per
# stage (from the command's own timings), wall time and peak memory of the whole process.
# Usage: bench/bench_build_model.sh [extra build-model options, e.g. --faces 131072]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="${MRSNAKE_BIN:-$root/build/apps/mrsnake}"
data="${MRSNAKE_DATA:-$root/../shared/data}"
labels="$data/volumes/liver-labels.nii.gz"
[ -f "$labels" ] || { echo "skipped: $labels not found (set MRSNAKE_DATA)"; exit 0; }
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
/usr/bin/time -f '%e %M' -o "$out/time" "$bin" -q build-model --labels "$labels" --label 255 -o "$out/liver.model" --json "$@" > "$out/summary.json"
python3 - "$out/summary.json" "$out/time" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
wall, kb = open(sys.argv[2]).read().split()
print(f"build-model liver-labels.nii.gz label 255: {s['faces']} faces, {s['levels']} levels, input surface {s['input_faces']} faces")
print(f"{'stage':<18}{'seconds':>10}")
for t in s['timings']:
    print(f"{t['stage']:<18}{t['seconds']:>10.3f}")
print(f"{'total (in process)':<18}{s['total_seconds']:>10.3f}")
print(f"{'wall (process)':<18}{float(wall):>10.3f}")
print(f"{'peak memory (MB)':<18}{int(kb)/1024:>10.0f}")
PY
