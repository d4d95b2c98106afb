#!/usr/bin/python3
"""mrsnake as 3D Slicer CLI modules, checked the way Slicer uses them:
  1. each module's `--xml` validates against the Slicer Execution Model's schema (xmllint);
  2. each module runs with the arguments Slicer builds from that XML: every parameter that has
     a value by its flag, then the indexed ones (images, surfaces) in index order; the label
     map and the surfaces it writes are read back (a NRRD reader of the test's own, VTK), and no
     temporary result folder is left. segment also gets --returnparameterfile, which Slicer
     passes to modules that declare scalar outputs (the schema gives these descriptions none),
     and its file is read back.

  slicer_module.py   (MRSNAKE_BIN: the executable; MRSNAKE_SLICER_DIR: the module wrappers;
                      MRSNAKE_SCHEMAS: the folder of ModuleDescription.xsd, default ../shared/schemas)
Exit 77 when the schema, xmllint, nibabel or VTK is absent.

The schema as published does not compile in libxml2: enumerationType declares an attribute
after its complexContent. The test drops that one attribute in a temporary copy and validates
against the rest, unchanged.
"""
import glob
import os
import re
import shutil
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def skip(why):
    print(f"SKIP: {why}")
    sys.exit(77)


try:
    import nibabel as nib
    import numpy as np
    from vtkmodules.vtkIOLegacy import vtkPolyDataReader
    from nrrd_reader import nrrd_affine_ras, read_nrrd
except ImportError as e:
    skip(f"{e.name} is missing (scripts/setup installs python3-nibabel and python3-vtk9)")

MRSNAKE = os.environ["MRSNAKE_BIN"]
SLICER_DIR = os.environ["MRSNAKE_SLICER_DIR"]
DATA = os.environ.get("MRSNAKE_DATA", os.path.join(ROOT, "..", "shared", "data"))
SCHEMAS = os.environ.get("MRSNAKE_SCHEMAS", os.path.join(os.path.dirname(os.path.abspath(DATA)), "schemas"))


def compiled_schema(work):
    """A copy of the schema without the one attribute libxml2 refuses."""
    source = os.path.join(SCHEMAS, "ModuleDescription.xsd")
    if not os.path.isfile(source):
        skip(f"the schema {source} is absent (it is read from the shared folder, as the data is)")
    if shutil.which("xmllint") is None:
        skip("xmllint is missing (scripts/setup installs libxml2-utils)")
    with open(source) as f:
        text = f.read()
    fixed = re.sub(r'(</xsd:complexContent>\s*)<xsd:attribute name="hidden" type="xsd:boolean"/>', r"\1", text)
    assert fixed != text, "the schema changed: check what libxml2 refuses in it"
    path = os.path.join(work, "ModuleDescription.xsd")
    with open(path, "w") as f:
        f.write(fixed)
    return path


def module_xml(module, schema, work):
    exe = os.path.join(SLICER_DIR, f"mrsnake-{module}")
    xml = subprocess.run([exe, "--xml"], check=True, capture_output=True, text=True).stdout
    path = os.path.join(work, f"{module}.xml")
    with open(path, "w") as f:
        f.write(xml)
    result = subprocess.run(["xmllint", "--noout", "--schema", schema, path], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    return exe, ET.fromstring(xml)


def slicer_arguments(root, values):
    """The command line Slicer builds: flagged parameters with a value (given, else the default),
    then the indexed ones by index."""
    flagged, indexed = [], {}
    for group in root.iter("parameters"):
        for p in group:
            if p.tag in ("label", "description"):
                continue
            name = p.findtext("name")
            value = values.get(name, p.findtext("default") or "")
            if p.find("index") is not None:
                assert value, f"Slicer always passes the indexed parameter {name}"
                indexed[int(p.findtext("index"))] = value
            elif value:
                flagged += ["--" + p.findtext("longflag"), value]
    return flagged + [indexed[i] for i in sorted(indexed)]


def run_module(exe, root, values, return_file=None):
    """Runs the module; with return_file, also passes --returnparameterfile and reads it back."""
    command = [exe] + slicer_arguments(root, values) + (["--returnparameterfile", return_file] if return_file else [])
    subprocess.run(command, check=True)
    if not return_file:
        return {}
    with open(return_file) as f:
        return dict(line.rstrip("\n").split(" = ", 1) for line in f if " = " in line)


def main():
    work = tempfile.mkdtemp(prefix="slicer-module-")
    schema = compiled_schema(work)
    for name, seed in (("ref", 5), ("tgt", 6)):
        subprocess.run([MRSNAKE, "-q", "synth", "--shape", "ellipsoid", "--size", "48", "--snr", "6", "--seed",
                        str(seed), "-o", os.path.join(work, name)], check=True)
    build_exe, build_xml = module_xml("build-model", schema, work)
    segment_exe, segment_xml = module_xml("segment", schema, work)

    model = os.path.join(work, "model")
    run_module(build_exe, build_xml, {"referenceLabels": os.path.join(work, "ref", "truth.nii.gz"),
                                      "referenceImage": os.path.join(work, "ref", "image.nii.gz"),
                                      "output": model})
    assert os.path.isfile(os.path.join(model, "model.json")), "build-model made no model"

    before = set(glob.glob(os.path.join(tempfile.gettempdir(), "mrsnake-segment-*")))
    labels_path, surfaces_path = os.path.join(work, "labels.nrrd"), os.path.join(work, "surfaces.vtk")
    returned = run_module(segment_exe, segment_xml, {"inputVolume": os.path.join(work, "tgt", "image.nii.gz"),
                                                     "outputLabels": labels_path, "outputSurfaces": surfaces_path,
                                                     "model": model}, os.path.join(work, "segment.params"))
    assert set(glob.glob(os.path.join(tempfile.gettempdir(), "mrsnake-segment-*"))) == before, "a result folder is left"

    fields, _, voxels = read_nrrd(labels_path)
    truth = nib.load(os.path.join(work, "tgt", "truth.nii.gz"))
    assert np.allclose(nrrd_affine_ras(fields), truth.affine, atol=1e-4), "the label map is off the image's grid"
    seg, ref = voxels == 1, np.asanyarray(truth.dataobj) == 1
    dice = 2 * np.count_nonzero(seg & ref) / (np.count_nonzero(seg) + np.count_nonzero(ref))
    assert dice > 0.9, dice
    reader = vtkPolyDataReader()
    reader.SetFileName(surfaces_path)
    reader.Update()
    assert reader.GetOutput().GetNumberOfPolys() > 1000, reader.GetOutput().GetNumberOfPolys()
    assert returned["suspect"] == "false" and float(returned["volume_mm3"]) > 0, returned
    shutil.rmtree(work)
    print(f"Slicer modules: both descriptions validate; run as Slicer runs them, the label map has Dice {dice:.3f}, "
          f"the surfaces {reader.GetOutput().GetNumberOfPolys()} triangles, the return parameters {returned}")


if __name__ == "__main__":
    main()
