#!/usr/bin/env bash
# End-to-end benchmark of `mrsnake build-model` on the liver labels (label 255): seconds per
# stage (from the command's own timings), wall time, CPU time (user + system: less sensitive
# to other jobs on a shared machine than the wall time) and peak memory of the whole process, the
# face counts, and the model's fidelity: RMS and Hausdorff distance of its finest level to the
# full-resolution marching-cubes surfaces (`mrsnake mc`, the voxels' own surface, and
# `mrsnake mc --smooth 20`; 442,712 faces each) in % of their bounding-box diagonal, with its
# triangle quality.
# Usage: bench/bench_build_model.sh [extra build-model options, e.g. --faces 131072 --config FILE]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="${MRSNAKE_BIN:-$root/build/apps/mrsnake}"
data="${MRSNAKE_DATA:-$root/../shared/data}"
labels="$data/volumes/liver-labels.nii.gz"
[ -f "$labels" ] || { echo "skipped: $labels not found (set MRSNAKE_DATA)"; exit 0; }
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
/usr/bin/time -f '%e %M %U %S' -o "$out/time" "$bin" -q build-model --labels "$labels" --label 255 -o "$out/liver.model" --json "$@" > "$out/summary.json"
"$bin" -q mc --labels "$labels" --label 255 -o "$out/voxels.vtp" > /dev/null
"$bin" -q mc --labels "$labels" --label 255 --smooth 20 -o "$out/smoothed.vtp" > /dev/null
levels="$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['levels'])" "$out/summary.json")"
# The structure's folder in the model, as model.json names it.
structure="$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['structures'][0]['path'])" "$out/liver.model/model.json")"
finest="$out/liver.model/$structure/level_$levels.vtp"
"$bin" -q quality "$finest" --reference "$out/voxels.vtp" --json > "$out/quality.json"
"$bin" -q quality "$finest" --reference "$out/smoothed.vtp" --json > "$out/quality20.json"
python3 - "$out/summary.json" "$out/time" "$out/quality.json" "$out/quality20.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
wall, kb, user, system = open(sys.argv[2]).read().split()
q = json.load(open(sys.argv[3]))
d, d20 = q["distance"], json.load(open(sys.argv[4]))["distance"]
print(f"build-model liver-labels.nii.gz label 255: {s['faces']} faces, {s['levels']} levels, "
      f"input surface {s['input_faces']} faces (marching-cubes spacing {s.get('mc_spacing_mm', 0)} mm)")
print(f"{'stage':<20}{'seconds':>10}")
for t in s['timings']:
    print(f"{t['stage']:<20}{t['seconds']:>10.3f}")
print(f"{'total (in process)':<20}{s['total_seconds']:>10.3f}")
print(f"{'wall (process)':<20}{float(wall):>10.3f}")
print(f"{'CPU user+sys (s)':<20}{float(user) + float(system):>10.3f}")
print(f"{'peak memory (MB)':<20}{int(kb)/1024:>10.0f}")
print("finest level against the full-resolution marching-cubes surface:")
print(f"{'':<20}{'mrsnake mc':>22}{'mc --smooth 20':>22}")
print(f"{'RMS %':<20}{d['rms_pct']:>10.4f} ({d['rms_mm']:.3f} mm){d20['rms_pct']:>10.4f} ({d20['rms_mm']:.3f} mm)")
print(f"{'Hausdorff %':<20}{d['hausdorff_pct']:>10.4f} ({d['hausdorff_mm']:.3f} mm){d20['hausdorff_pct']:>10.4f} ({d20['hausdorff_mm']:.3f} mm)")
print(f"{'min angle (deg)':<20}{q['min_angle_deg']:>10.2f}")
print(f"{'Q min':<20}{q['q_min']:>10.3f}")
print(f"{'Q mean':<20}{q['q_mean']:>10.3f}")
print(f"{'valence 6 %':<20}{q['pct_valence6_interior']:>10.2f}")
PY
