"""The study's configuration (YAML) and manifest (CSV), read and checked before any job runs.

Relative paths in the configuration are relative to its folder; relative image paths in the
manifest are relative to the manifest's folder. Every defect is a StudyError whose message says
what is wrong and what to do, in one line.
"""
import csv
import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Dict, List, Optional

# Ids name files and folders: no separators, no leading dot.
ID_PATTERN = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9._-]*$")
# Columns of study/volumes.csv that a manifest column may not take.
RESERVED_COLUMNS = {"status", "suspect", "reason", "error", "exit_code", "compute_seconds", "job_seconds"}
KNOWN_KEYS = {"reference", "model", "manifest", "output", "mrsnake", "segment_options", "build_options"}
REFERENCE_KEYS = {"labels", "image", "structures", "label_names"}


class StudyError(Exception):
    """A configuration or manifest that cannot be run, with what to do about it."""


@dataclass
class Reference:
    labels: str
    image: Optional[str]
    structures: str  # build-model's --label: "1,3,7" or "all"
    label_names: Optional[str] = None


@dataclass
class Case:
    id: str
    image: str
    columns: Dict[str, str]  # the manifest's other columns (group, timepoint, ...)


@dataclass
class Study:
    output: str
    manifest: str
    cases: List[Case]
    extra_columns: List[str]
    reference: Optional[Reference] = None
    model: Optional[str] = None
    mrsnake: str = "mrsnake"
    segment_options: Optional[str] = None
    build_options: Optional[str] = None
    ids: List[str] = field(default_factory=list)
    by_id: Dict[str, Case] = field(default_factory=dict)

    def case(self, case_id: str) -> Case:
        return self.by_id[case_id]


def _path(base: Path, value, key: str) -> str:
    if not isinstance(value, str) or not value:
        raise StudyError(f"the study's '{key}' must be a path; give it in the configuration file")
    path = Path(os.path.expanduser(value))
    return str(path if path.is_absolute() else (base / path).resolve())


def _structures(value) -> str:
    if value is None or value == "all":
        return "all"
    values = value if isinstance(value, list) else [value]
    if not values or not all(isinstance(v, int) and not isinstance(v, bool) and v > 0 for v in values):
        raise StudyError("reference.structures must be 'all' or a list of positive label values, e.g. [1, 3]")
    return ",".join(str(v) for v in values)


def _reference(base: Path, ref) -> Reference:
    if not isinstance(ref, dict):
        raise StudyError("'reference' must be a mapping: {labels: LABELS, image: IMAGE, structures: [1, 3]}")
    unknown = set(ref) - REFERENCE_KEYS
    if unknown:
        raise StudyError(f"unknown key reference.{sorted(unknown)[0]}; the keys are {', '.join(sorted(REFERENCE_KEYS))}")
    if "labels" not in ref:
        raise StudyError("reference.labels is missing: the reference label volume the model is built from")
    return Reference(
        labels=_path(base, ref["labels"], "reference.labels"),
        image=_path(base, ref["image"], "reference.image") if ref.get("image") else None,
        structures=_structures(ref.get("structures")),
        label_names=_path(base, ref["label_names"], "reference.label_names") if ref.get("label_names") else None,
    )


def read_manifest(path: str):
    """The cases of a manifest CSV: columns id and image, then any others (group, timepoint, ...)."""
    try:
        with open(path, newline="", encoding="utf-8-sig") as f:
            reader = csv.DictReader(f)
            header = [name.strip() for name in reader.fieldnames or []]
            reader.fieldnames = header
            rows = list(reader)
    except OSError as e:
        raise StudyError(f"cannot read the manifest '{path}' ({e.strerror}); check the path in the configuration")
    for needed in ("id", "image"):
        if needed not in header:
            raise StudyError(f"the manifest '{path}' has no '{needed}' column; its first line must name id,image[,group,...]")
    for name in header:
        if name in RESERVED_COLUMNS or name.startswith(("volume_mm3_", "suspect_")):
            raise StudyError(f"the manifest '{path}' has a column '{name}', which the study's table uses itself; "
                             "rename it")
    base = Path(path).parent
    cases, seen = [], set()
    for line, row in enumerate(rows, start=2):
        case_id, image = (row.get("id") or "").strip(), (row.get("image") or "").strip()
        if not case_id and not image:
            continue  # a blank line
        if not ID_PATTERN.match(case_id):
            raise StudyError(f"manifest line {line}: the id '{case_id}' must be letters, digits, '.', '_' or '-', "
                             "not starting with '.' or '-'")
        if case_id in seen:
            raise StudyError(f"manifest line {line}: the id '{case_id}' is given twice; ids must be unique")
        if not image:
            raise StudyError(f"manifest line {line}: the case '{case_id}' has no image")
        seen.add(case_id)
        image_path = Path(os.path.expanduser(image))
        cases.append(Case(case_id, str(image_path if image_path.is_absolute() else (base / image_path).resolve()),
                          {k: (v or "").strip() for k, v in row.items() if k not in ("id", "image") and k is not None}))
    if not cases:
        raise StudyError(f"the manifest '{path}' lists no volume; add rows of id,image")
    return cases, [c for c in header if c not in ("id", "image")]


def load_study(config: dict, config_dir: Path) -> Study:
    """The study that `config` (the parsed YAML) describes, its paths resolved from config_dir."""
    if not isinstance(config, dict) or not config:
        raise StudyError("the study configuration is empty; it needs manifest, output, and reference or model")
    unknown = set(config) - KNOWN_KEYS
    if unknown:
        raise StudyError(f"unknown key '{sorted(unknown)[0]}' in the study configuration; "
                         f"the keys are {', '.join(sorted(KNOWN_KEYS))}")
    if ("reference" in config) == ("model" in config):
        raise StudyError("give either 'reference' (to build the model) or 'model' (a prebuilt model folder), not both")
    for key in ("manifest", "output"):
        if key not in config:
            raise StudyError(f"the study configuration has no '{key}'")
    manifest = _path(config_dir, config["manifest"], "manifest")
    cases, extra = read_manifest(manifest)
    study = Study(output=_path(config_dir, config["output"], "output"), manifest=manifest, cases=cases,
                  extra_columns=extra, ids=[c.id for c in cases], by_id={c.id: c for c in cases})
    if "reference" in config:
        study.reference = _reference(config_dir, config["reference"])
    else:
        study.model = _path(config_dir, config["model"], "model")
        if not os.path.isfile(os.path.join(study.model, "model.json")):
            raise StudyError(f"'{study.model}' is not a model folder (no model.json); build it with mrsnake build-model")
    for key in ("segment_options", "build_options"):
        if config.get(key):
            setattr(study, key, _path(config_dir, config[key], key))
    study.mrsnake = str(config.get("mrsnake") or "mrsnake")
    return study


def main():
    """`study_config.py CONFIG`: checks the study and prints its output folder (for scripts/study)."""
    import sys

    import yaml

    if len(sys.argv) != 2:
        sys.exit("usage: study_config.py CONFIG")
    path = Path(sys.argv[1])
    try:
        with open(path, encoding="utf-8") as f:
            config = yaml.safe_load(f)
        print(load_study(config, path.resolve().parent).output)
    except OSError as e:
        sys.exit(f"study: cannot read the configuration '{path}' ({e.strerror}); check the path")
    except yaml.YAMLError as e:
        sys.exit(f"study: the configuration '{path}' is not valid YAML ({str(e).splitlines()[0]})")
    except StudyError as e:
        sys.exit(f"study: {e}")


if __name__ == "__main__":
    main()
