#!/usr/bin/python3
"""bench/remesh runs to its end on a small ellipsoid, and its verdicts follow from its own figures.

The benchmark decides which remeshing targets are met; this checks that decision against the
targets' values, recomputed here from each row's figures in bench_remesh.json (valence 6 on
>= 99 % of the interior vertices, min angle >= 30 deg, Q min >= 0.6, Q mean >= 0.9, RMS <= CGAL's,
Hausdorff <= 0.5 % of the diagonal, faster than CGAL), the speed ratios, the summary line, and
that the Markdown page shows the same verdicts. It also reads report.json through the benchmark,
so a renamed key of mrsnake's report breaks it here, not in the next benchmark run.

  bench_remesh_smoke.py   (BENCH_REMESH_BIN and MRSNAKE_BIN name the executables)
No data folder is needed: the input is mrsnake synth's.
"""
import json
import math
import os
import subprocess
import sys
import tempfile

BENCH = os.environ["BENCH_REMESH_BIN"]
MRSNAKE = os.environ["MRSNAKE_BIN"]
TARGET = 2048
METHODS = {"mrsnake", "mrsnake-norelax", "cgal-isotropic"}


def write_ellipsoid(folder):
    """mrsnake synth's ellipsoid surface (a closed genus-0 surface of 2412 faces): uneven
    stretch, and one chart holds it. Returns its path."""
    subprocess.run([MRSNAKE, "-q", "synth", "--shape", "ellipsoid", "--size", "32", "--noise", "none", "-o", folder],
                   check=True)
    return os.path.join(folder, "truth.vtp")


def expected_missed(row, cgal):
    """The targets `row` misses, by the benchmark's stated values, in the table's order."""
    q, d = row["quality"], row["distance"]
    checks = [("val6", q["pct_valence6_interior"] >= 99.0), ("angle", q["min_angle_deg"] >= 30.0),
              ("Qmin", q["q_min"] >= 0.6), ("Qmean", q["q_mean"] >= 0.9),
              ("RMS", d["rms_pct"] <= cgal["distance"]["rms_pct"]), ("Haus", d["hausdorff_pct"] <= 0.5),
              ("time", row["algorithm_seconds"] < cgal["algorithm_seconds"])]
    return [name for name, met in checks if not met]


def fail(message):
    print(f"FAIL: {message}")
    sys.exit(1)


def check_rows(rows):
    """Every method has a row with figures; the verdicts and speed ratios follow from them."""
    by_method = {r["method"]: r for r in rows if r["target_faces"] == TARGET}
    if set(by_method) != METHODS:
        fail(f"methods {sorted(by_method)}, expected {sorted(METHODS)}")
    cgal = by_method["cgal-isotropic"]
    for method, row in by_method.items():
        if row["status"] != "ok":
            fail(f"{method}: status {row['status']}")
        if not TARGET / 2 <= row["faces"] <= TARGET * 2:
            fail(f"{method}: {row['faces']} faces for a target of {TARGET}")
        if method == "cgal-isotropic":
            if "targets" in row:
                fail("CGAL's row, the reference, has targets")
            continue
        missed = expected_missed(row, cgal)
        if row["targets"]["missed"] != missed or row["targets"]["all_met"] != (not missed):
            fail(f"{method}: the benchmark says {row['targets']}, its figures say missed {missed}")
        ratio = cgal["algorithm_seconds"] / row["algorithm_seconds"]
        if not math.isclose(row["speed_ratio_vs_cgal"], ratio, rel_tol=1e-9):
            fail(f"{method}: speed ratio {row['speed_ratio_vs_cgal']}, expected {ratio}")
    return by_method


def check_page(page, by_method, summary):
    """The Markdown page names the commit and shows each row's verdict."""
    if "Commit " not in page or "## Results" not in page:
        fail("the Markdown page has no commit line or no results")
    for method in ("mrsnake", "mrsnake-norelax"):
        missed = by_method[method]["targets"]["missed"]
        verdict = "all met" if not missed else ",".join(missed)
        if not any(f"| {TARGET} | {method} |" in line and line.rstrip().endswith(f"| {verdict} |")
                   for line in page.splitlines()):
            fail(f"the page has no {method} row ending with '{verdict}'")
    met = 0 if by_method["mrsnake"]["targets"]["missed"] else 1
    if f"mrsnake {met} of 1" not in summary:
        fail(f"the summary '{summary}' does not count {met} of 1 mrsnake rows meeting every target")


def main():
    with tempfile.TemporaryDirectory() as tmp:
        mesh = write_ellipsoid(os.path.join(tmp, "synth"))
        out, page = os.path.join(tmp, "out"), os.path.join(tmp, "page.md")
        run = subprocess.run([BENCH, "--inputs", mesh, "--targets", str(TARGET), "--repeat", "1", "--samples", "4",
                              "--out", out, "--markdown", page], capture_output=True, text=True)
        if run.returncode != 0:
            fail(f"bench_remesh exited {run.returncode}:\n{run.stdout}\n{run.stderr}")
        with open(os.path.join(out, "bench_remesh.json")) as f:
            result = json.load(f)
        by_method = check_rows(result["rows"])
        with open(page) as f:
            check_page(f.read(), by_method, result["targets_summary"])
        bad = subprocess.run([BENCH, "--inputs", mesh, "--targets", "0", "--out", out], capture_output=True, text=True)
        if bad.returncode == 0 or "--targets" not in bad.stderr:
            fail(f"--targets 0 was not refused with a message naming it: exit {bad.returncode}, {bad.stderr!r}")
    print("bench_remesh: every verdict follows from its figures")


if __name__ == "__main__":
    main()
