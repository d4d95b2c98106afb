#!/usr/bin/env bash
# The study workflow (workflow/Snakefile through scripts/study), run locally for real on 6
# synthetic volumes in two groups, one of pure noise and one corrupt file:
#   1. the table against every volume's report.json, the failed volume listed, the noise image
#      flagged with its thumbnail in the page;
#   2. a second run does nothing;
#   3. a new reference (so a new model) reruns every segmentation; that run is killed mid-way
#      and resumed, and the volumes finished before the kill are not segmented again;
#   4. two rows added to the manifest run two segmentations and nothing else.
# Exit 77 (ctest: skipped) when Snakemake is not installed.
set -euo pipefail
: "${MRSNAKE_BIN:?MRSNAKE_BIN is not set; run through ctest}"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
python=/usr/bin/python3
if ! command -v snakemake >/dev/null || ! "$python" -c "import pandas, seaborn, yaml" 2>/dev/null; then
  echo "SKIP: Snakemake, pandas, seaborn or PyYAML is missing (scripts/setup installs them)"
  exit 77
fi
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
export MRSNAKE_BIN
fail() { echo "FAIL: $*" >&2; exit 1; }

# The reference and the volumes: group A and group B, whose blobs are deformed more.
"$MRSNAKE_BIN" -q synth --shape ellipsoid --size 48 --snr 6 --seed 5 -o "$work/reference"
echo "id,image,group" >"$work/manifest.csv"
for i in 1 2 3; do
  "$MRSNAKE_BIN" -q synth --shape ellipsoid --size 48 --snr 6 --pose random --seed $((20 + i)) -o "$work/a$i"
  "$MRSNAKE_BIN" -q synth --shape ellipsoid --size 48 --snr 6 --pose random --deform 2 --seed $((30 + i)) -o "$work/b$i"
  echo "a$i,a$i/image.nii.gz,A" >>"$work/manifest.csv"
  echo "b$i,b$i/image.nii.gz,B" >>"$work/manifest.csv"
done
echo "not an image" >"$work/bad.nii.gz"
echo "bad,bad.nii.gz,B" >>"$work/manifest.csv"
# Pure noise: segmented, and flagged as matching the image hardly better than chance.
"$MRSNAKE_BIN" -q synth --shape ellipsoid --size 48 --contrast 100,99 --snr 0.05 --seed 7 -o "$work/noise"
echo "noise,noise/image.nii.gz,A" >>"$work/manifest.csv"
cat >"$work/study.yaml" <<YAML
reference: {labels: reference/truth.nii.gz, image: reference/image.nii.gz, structures: [1]}
manifest: manifest.csv
output: out
YAML
out="$work/out"
study() {
  local code=0
  "$root/scripts/study" "$work/study.yaml" "$@" >"$work/run.log" 2>&1 || code=$?
  echo "$code"
}
newer_than() { find "$out/status" -name '*.json' -newer "$1" | sort | xargs -r -n1 basename | tr '\n' ' '; }

echo "== 1. the first run"
code=$(study)
[ "$code" = 6 ] || { cat "$work/run.log"; fail "the first run exited $code, expected 6 (one volume failed)"; }
"$python" "$root/tests/workflow/check_study_table.py" "$out" a1,b1,a2,b2,a3,b3,bad,noise bad
grep -q 'alt="slices of noise"' "$out/study/report.html" || fail "the page does not show the doubtful noise image"
grep -q '^noise,.*,ok,True,' "$out/study/volumes.csv" || fail "volumes.csv does not flag the noise image"

echo "== 2. a second run does nothing"
touch "$work/mark2"
sleep 1
code=$(study)
[ "$code" = 6 ] || fail "the second run exited $code"
grep -q "Nothing to be done" "$work/run.log" || { cat "$work/run.log"; fail "the second run ran jobs"; }
[ -z "$(newer_than "$work/mark2")" ] || fail "the second run rewrote $(newer_than "$work/mark2")"

echo "== 3. a new reference reruns every segmentation; killed mid-way, then resumed"
touch "$work/mark3"
sleep 1
# Another reference, not merely a touched one (Snakemake compares the content of inputs under 100 kB).
"$MRSNAKE_BIN" -q synth --shape ellipsoid --size 48 --snr 6 --seed 6 -o "$work/reference"
# One job at a time and at most one started per second: a segmentation takes well under a
# second here, and the whole run would otherwise end before the kill below.
set -m  # the run in a process group of its own, whose id is its pid: killed whole, waited for
"$root/scripts/study" "$work/study.yaml" --cores 1 --max-jobs-per-second 1 >"$work/killed.log" 2>&1 &
run=$!
set +m
for _ in $(seq 1 1200); do  # at most 120 s for the model and two segmentations (not the corrupt file's)
  [ "$(newer_than "$work/mark3" | tr ' ' '\n' | grep -c '[ab][0-9]')" -ge 2 ] && break
  sleep 0.1
done
sleep 1  # Snakemake records a finished job a moment after its files are written
kill -TERM -- "-$run" 2>/dev/null || true
wait "$run" || true
before=$(newer_than "$work/mark3")
[ "$(echo "$before" | wc -w)" -lt 8 ] || { cat "$work/killed.log"; fail "the kill came after every volume was done"; }
echo "killed after: $before"
touch "$work/mark3b"
sleep 1
code=$(study)
[ "$code" = 6 ] || { cat "$work/run.log"; fail "the resumed run exited $code"; }
redone=$(newer_than "$work/mark3b")
# Every volume not done before the kill is done now; some done before it are kept (a job cut
# off between its files and Snakemake's record of it is rightly done again).
for id in $(cd "$out/status" && ls); do
  case " $before " in *" $id "*) ;; *) case " $redone " in *" $id "*) ;; *) fail "$id was not done after the kill" ;; esac ;; esac
done
[ "$(echo "$redone" | wc -w)" -lt 8 ] || fail "the resumed run did every volume again: $redone"
echo "resumed: did $redone"
[ "$(newer_than "$work/mark3" | wc -w)" = 8 ] || fail "not every volume was redone with the new model"

echo "== 4. two rows added run two segmentations"
touch "$work/mark4"
sleep 1
"$MRSNAKE_BIN" -q synth --shape ellipsoid --size 48 --snr 6 --pose random --seed 41 -o "$work/c1"
"$MRSNAKE_BIN" -q synth --shape ellipsoid --size 48 --snr 6 --pose random --seed 42 -o "$work/c2"
printf 'c1,c1/image.nii.gz,A\nc2,c2/image.nii.gz,B\n' >>"$work/manifest.csv"
code=$(study)
[ "$code" = 6 ] || { cat "$work/run.log"; fail "the run with two more rows exited $code"; }
[ "$(newer_than "$work/mark4")" = "c1.json c2.json " ] || fail "the new rows ran $(newer_than "$work/mark4")"
"$python" "$root/tests/workflow/check_study_table.py" "$out" a1,b1,a2,b2,a3,b3,bad,noise,c1,c2 bad
echo "PASS: the local study workflow"
