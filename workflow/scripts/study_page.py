#!/usr/bin/python3
"""study/report.html: a self-contained page of the study. The volume of each structure by group
(box and strip plots), the doubtful and the failed volumes with thumbnails of their slices, and
the run's timings and peak memory per job.

  study_page.py --study OUTPUT_FOLDER --model MODEL --out OUTPUT_FOLDER/study/report.html
"""
import argparse
import base64
import glob
import html
import io
import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only: no display on a cluster node
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402
import seaborn as sns  # noqa: E402

STYLE = """body{font-family:sans-serif;margin:2em;max-width:1200px}table{border-collapse:collapse;margin:1em 0}
td,th{border:1px solid #ccc;padding:3px 8px;text-align:left;vertical-align:top}th{background:#eee}
img{max-width:100%}.note{color:#555}"""


def png_uri(data: bytes) -> str:
    return "data:image/png;base64," + base64.b64encode(data).decode("ascii")


def table_html(frame: pd.DataFrame, raw=()) -> str:
    """An HTML table; every cell escaped but those of the columns in `raw` (pictures)."""
    head = "".join(f"<th>{html.escape(str(c))}</th>" for c in frame.columns)
    rows = "".join("<tr>" + "".join(f"<td>{cell if column in raw else html.escape(cell)}</td>"
                                     for column, cell in zip(frame.columns, row)) + "</tr>"
                   for row in frame.astype(str).values)
    return f"<table><tr>{head}</tr>{rows}</table>"


def volumes_long(volumes: pd.DataFrame, structures: pd.DataFrame, group: str) -> pd.DataFrame:
    """One row per volume and structure, for seaborn."""
    names = {int(v): f"{n} ({v})" for v, n in zip(structures["value"], structures["name"])}
    ok = volumes[volumes["status"] == "ok"]
    columns = [f"volume_mm3_{v}" for v in names]
    long = ok.melt(id_vars=["id", group], value_vars=columns, var_name="structure", value_name="volume (mm³)")
    long["structure"] = long["structure"].map(lambda c: names[int(c.rsplit("_", 1)[1])])
    return long.dropna(subset=["volume (mm³)"])


def volume_plot(volumes: pd.DataFrame, structures: pd.DataFrame, group: str) -> bytes:
    """Box plots of every structure's volume by group, each volume a point over them."""
    long = volumes_long(volumes, structures, group)
    order = sorted(long[group].unique())
    grid = sns.catplot(data=long, x=group, y="volume (mm³)", col="structure", kind="box", order=order,
                       col_wrap=min(4, long["structure"].nunique()), sharey=False, height=3, aspect=1.0,
                       color="#cfe0f3", showfliers=False)
    grid.map_dataframe(sns.stripplot, x=group, y="volume (mm³)", order=order, color="#1f4e79", size=4, jitter=0.15)
    grid.set_titles("{col_name}")
    buffer = io.BytesIO()
    grid.savefig(buffer, format="png", dpi=90)
    plt.close("all")
    return buffer.getvalue()


def thumbnail(study: Path, case_id: str) -> str:
    path = study / "segmentations" / case_id / "slices.png"
    if not path.is_file():
        return "<span class=note>no slices</span>"
    return f'<img src="{png_uri(path.read_bytes())}" width="480" alt="slices of {html.escape(case_id)}">'


def benchmark_rows(study: Path) -> pd.DataFrame:
    """Each job's wall seconds and peak resident memory, as Snakemake's benchmark files give them."""
    frames = []
    for path in glob.glob(str(study / "benchmarks" / "**" / "*.tsv"), recursive=True):
        frame = pd.read_csv(path, sep="\t")
        frame["rule"] = "build_model" if Path(path).name == "build_model.tsv" else Path(path).parent.name
        frames.append(frame)
    return pd.concat(frames) if frames else pd.DataFrame(columns=["rule", "s", "max_rss"])


def timings_html(study: Path, volumes: pd.DataFrame) -> str:
    bench = benchmark_rows(study)
    rows = []
    for rule, jobs in bench.groupby("rule"):
        rss = pd.to_numeric(jobs["max_rss"], errors="coerce")
        rows.append({"job": rule, "jobs": len(jobs), "median s": f"{jobs['s'].median():.2f}",
                     "max s": f"{jobs['s'].max():.2f}", "total s": f"{jobs['s'].sum():.1f}",
                     "peak memory MiB": f"{rss.max():.0f}" if rss.notna().any() else "–"})
    compute = pd.to_numeric(volumes.get("compute_seconds"), errors="coerce").dropna()
    text = table_html(pd.DataFrame(rows)) if rows else "<p class=note>No job timings were recorded.</p>"
    if len(compute):
        text += (f"<p>mrsnake's own compute per volume (report.json): median {compute.median():.3f} s, "
                 f"max {compute.max():.3f} s, over {len(compute)} volumes.</p>")
    return text


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--study", required=True)
    parser.add_argument("--model", required=True)
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    study = Path(args.study)
    volumes = pd.read_csv(study / "study" / "volumes.csv", dtype={"id": str})
    structures = pd.read_csv(study / "study" / "structures.csv")
    group = "group" if "group" in volumes.columns else None
    if group is None:
        volumes["group"], group = "all", "group"
    volumes[group] = volumes[group].fillna("").astype(str)

    ok = volumes[volumes["status"] == "ok"]
    flagged = ok[ok["suspect"].astype(str).str.lower() == "true"]
    failed = volumes[volumes["status"] != "ok"]
    parts = [f"<h1>mrsnake study: {len(volumes)} volumes</h1>",
             f"<p>Model <code>{html.escape(args.model)}</code>; {len(ok)} segmented, {len(flagged)} doubtful, "
             f"{len(failed)} failed. The table: <code>study/volumes.csv</code>.</p>"]
    parts.append("<h2>Volume of each structure by group</h2>")
    if len(ok) and len(structures):
        parts.append(f'<img src="{png_uri(volume_plot(volumes, structures, group))}" alt="volumes by group">')
        summary = volumes_long(volumes, structures, group).groupby(["structure", group])["volume (mm³)"]
        parts.append(table_html(summary.agg(["count", "mean", "std", "median"]).round(3).reset_index()))
    else:
        parts.append("<p class=note>No volume was segmented.</p>")
    parts.append(f"<h2>Doubtful results ({len(flagged)})</h2>")
    if len(flagged):
        rows = [[r.id, str(r[group]), str(r.reason), thumbnail(study, r.id)] for _, r in flagged.iterrows()]
        parts.append(table_html(pd.DataFrame(rows, columns=["id", group, "reason", "slices"]), raw=("slices",)))
    else:
        parts.append("<p class=note>No result was flagged.</p>")
    parts.append(f"<h2>Failed volumes ({len(failed)})</h2>")
    if len(failed):
        rows = [[r.id, str(r.image), r.exit_code, str(r.error)] for _, r in failed.iterrows()]
        parts.append(table_html(pd.DataFrame(rows, columns=["id", "image", "exit code", "error"])))
    else:
        parts.append("<p class=note>Every volume was segmented.</p>")
    parts.append("<h2>Timings</h2>" + timings_html(study, volumes))
    page = f"<!DOCTYPE html><html><head><meta charset=utf-8><title>mrsnake study</title><style>{STYLE}</style>" \
           f"</head><body>{''.join(parts)}</body></html>\n"
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    Path(f"{out}.tmp").write_text(page, encoding="utf-8")
    os.replace(f"{out}.tmp", out)


if __name__ == "__main__":
    main()
