#!/usr/bin/python3
"""study/volumes.csv: one row per volume of the manifest, in its order, with the manifest's own
columns, how its job went, its verdict, and per structure (in increasing label value) its
volume in mm3 and its verdict; and study/structures.csv: each structure's value, name and colour.

  collect_volumes.py --manifest MANIFEST --study OUTPUT_FOLDER --out OUTPUT_FOLDER/study/volumes.csv
"""
import argparse
import json
import os
import sys
from pathlib import Path

import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent))
from study_config import StudyError, read_manifest  # noqa: E402


def read_json(path: Path):
    with open(path, encoding="utf-8") as f:
        return json.load(f)


def case_row(study: Path, case, extra_columns):
    """The row of one volume: the manifest's columns, its job's status, and its report's volumes."""
    row = {"id": case.id, "image": case.image}
    row.update({c: case.columns.get(c, "") for c in extra_columns})
    status = read_json(study / "status" / f"{case.id}.json")
    row.update(status=status["status"], exit_code=status["exit_code"], error=status["error"],
               job_seconds=status["seconds"])
    structures = {}
    if status["status"] == "ok":
        report = read_json(study / "segmentations" / case.id / "report.json")
        row.update(suspect=report["suspect"], reason=report["reason"], compute_seconds=report["compute_seconds"])
        for s in report["structures"]:
            structures[s["value"]] = s
    return row, structures


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--manifest", required=True)
    parser.add_argument("--study", required=True, help="the study's output folder")
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    try:
        cases, extra = read_manifest(args.manifest)
    except StudyError as e:
        sys.exit(f"collect_volumes: {e}")
    study = Path(args.study)
    rows, per_case, names = [], [], {}
    for case in cases:
        row, structures = case_row(study, case, extra)
        rows.append(row)
        per_case.append(structures)
        for value, s in structures.items():
            names.setdefault(value, (s["name"], s["color"]))
    for row, structures in zip(rows, per_case):
        for value in sorted(names):
            s = structures.get(value)
            row[f"volume_mm3_{value}"] = s["volume_mm3"] if s else None
            row[f"suspect_{value}"] = s["suspect"] if s else None
    table = pd.DataFrame(rows)
    for column in ("suspect", "reason", "compute_seconds"):
        if column not in table:
            table[column] = None
    first = ["id", "image", *extra, "status", "suspect", "reason", "error", "exit_code", "compute_seconds",
             "job_seconds"]
    table = table[first + [c for c in table.columns if c not in first]]
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    table.to_csv(f"{out}.tmp", index=False)
    os.replace(f"{out}.tmp", out)
    structures = pd.DataFrame([{"value": v, "name": n, "color": " ".join(str(c) for c in color)}
                               for v, (n, color) in sorted(names.items())], columns=["value", "name", "color"])
    structures.to_csv(out.parent / "structures.csv", index=False)


if __name__ == "__main__":
    main()
