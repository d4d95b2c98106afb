#!/usr/bin/python3
"""Checks a study's table against each volume's own report.json, and that the page was made.

  check_study_table.py OUTPUT IDS [FAILED_ID]
IDS: the manifest's ids in order, comma-separated; FAILED_ID: the one volume expected to fail.
"""
import json
import sys
from pathlib import Path

import pandas as pd

out, ids = Path(sys.argv[1]), sys.argv[2].split(",")
failed = sys.argv[3] if len(sys.argv) > 3 else None
table = pd.read_csv(out / "study" / "volumes.csv", dtype={"id": str})
assert list(table["id"]) == ids, list(table["id"])
for _, row in table.iterrows():
    if row.id == failed:
        assert row.status == "failed" and row.exit_code == 3 and row.image in row.error, row.to_dict()
        continue
    report = json.loads((out / "segmentations" / row.id / "report.json").read_text())
    assert row.status == "ok", row.to_dict()
    for s in report["structures"]:
        volume = row[f"volume_mm3_{s['value']}"]
        assert abs(volume - s["volume_mm3"]) <= 1e-6 * s["volume_mm3"], (row.id, volume, s["volume_mm3"])
        assert str(row[f"suspect_{s['value']}"]).lower() == str(s["suspect"]).lower(), (row.id, s["suspect"])
    assert abs(row.compute_seconds - report["compute_seconds"]) < 1e-6, row.id
page = (out / "study" / "report.html").read_text()
needles = ["Volume of each structure by group", "data:image/png;base64,", "Timings"]
needles += [f"Failed volumes (1)", failed] if failed else ["Failed volumes (0)"]
for needle in needles:
    assert needle in page, f"the page lacks '{needle}'"
print(f"study table: {len(table)} rows checked against their reports; the page is made")
