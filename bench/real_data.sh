#!/usr/bin/env bash
# Real-data procedure: for the liver (label 5) of abdomen-ct-small and the genus-0
# brain structures of MRIcrop (labels 3, 4, 5, 8; the two parts of 6 and of 7 one at a time), build the model from the labels (tunnels of
# the liver closed), make a new case with `mrsnake synth --from-image` (a known random pose
# and deformation), segment it and score it against the synth truth; ITK's level sets run
# from the same initial surface for comparison, and single-atlas elastix (bench/elastix_atlas:
# the original image registered to the case, its truth warped onto the case) beside the snake,
# skipped when elastix is not on PATH. Prints Dice, ASSD, HD95 and seconds per structure.
# Usage: bench/real_data.sh [--keep] [--work DIR] [--json OUT]   (data: MRSNAKE_DATA)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${MRSNAKE_BUILD_DIR:-$root/build}"
data="${MRSNAKE_DATA:-$root/../shared/data}"
[ -d "$data/volumes" ] || { echo "skipped: $data/volumes not found (set MRSNAKE_DATA)"; exit 0; }
MRSNAKE_JOBS="${MRSNAKE_JOBS:-1}" "$root/scripts/build" mrsnake bench_segment >&2
exec "$build/bench/bench_segment" --mrsnake "$build/apps/mrsnake" --elastix-atlas "$root/bench/elastix_atlas" \
  --real "$data" --json bench_segment_real.json "$@"
