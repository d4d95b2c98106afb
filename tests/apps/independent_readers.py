#!/usr/bin/python3
"""segment's outputs read by readers that are not mrsnake's own: nibabel for the label map,
VTK's Python reader for the surface, and a small NRRD reader written here for the Slicer
segmentation (Debian has no pynrrd). The case is built on an oblique grid (rotated, anisotropic,
offset), so that a mix-up of LPS and RAS, of axes or of the origin shows.

  independent_readers.py   (MRSNAKE_BIN names the mrsnake executable)
Exit 77 when nibabel or VTK's Python module is missing.
"""
import json
import os
import subprocess
import sys
import tempfile

try:
    import nibabel as nib
    import numpy as np
    from vtkmodules.vtkIOXML import vtkXMLPolyDataReader
    from nrrd_reader import nrrd_affine_ras, read_nrrd
except ImportError as e:
    print(f"SKIP: {e.name} is missing (scripts/setup installs python3-nibabel and python3-vtk9)")
    sys.exit(77)

MRSNAKE = os.environ["MRSNAKE_BIN"]
LPS_TO_RAS = np.diag([-1.0, -1.0, 1.0])
NAME = "Left kidney"


def mrsnake(*args):
    subprocess.run([MRSNAKE, "-q", *args], check=True)


def oblique(path_in, path_out, affine):
    """The same voxels on another grid: rotated 30° about z, anisotropic, offset."""
    img = nib.load(path_in)
    nib.save(nib.Nifti1Image(np.asanyarray(img.dataobj), affine), path_out)


def check_labels(out, affine, report):
    labels = nib.load(os.path.join(out, "labels.nii.gz"))
    assert np.allclose(labels.affine, affine, atol=1e-4), (labels.affine, affine)
    values = sorted(int(v) for v in np.unique(np.asanyarray(labels.dataobj)))
    assert values == [0] + [s["value"] for s in report["structures"]], values
    return np.asanyarray(labels.dataobj).astype(int)


def check_surface(out, affine, report, labels):
    reader = vtkXMLPolyDataReader()
    reader.SetFileName(os.path.join(out, "surface.vtp"))
    reader.Update()
    poly = reader.GetOutput()
    assert poly.GetNumberOfPoints() == report["vertices"], (poly.GetNumberOfPoints(), report["vertices"])
    assert poly.GetNumberOfPolys() == report["faces"], (poly.GetNumberOfPolys(), report["faces"])
    points = np.array([poly.GetPoint(i) for i in range(poly.GetNumberOfPoints())])
    centroid_ras = LPS_TO_RAS @ points.mean(axis=0)  # the file is in LPS, as ITK and Slicer keep it
    index = np.rint(np.linalg.solve(affine[:3, :3], centroid_ras - affine[:3, 3])).astype(int)
    assert labels[tuple(index)] == report["structures"][0]["value"], ("the centroid is not labelled", index)


def check_segmentation(out, affine, report, labels):
    fields, pairs, voxels = read_nrrd(os.path.join(out, "labels.seg.nrrd"))
    assert np.allclose(nrrd_affine_ras(fields), affine, atol=1e-4), (nrrd_affine_ras(fields), affine)
    assert np.array_equal(voxels.astype(int), labels), "the segmentation's voxels differ from labels.nii.gz"
    s = report["structures"][0]
    assert pairs["Segment0_Name"] == NAME and pairs["Segment0_LabelValue"] == str(s["value"]), pairs
    assert pairs["Segment0_ID"] == f"Segment_{s['value']}" and pairs["Segment0_Layer"] == "0", pairs
    color = [float(c) for c in pairs["Segment0_Color"].split()]
    assert np.allclose(color, np.array(s["color"]) / 255.0, atol=1e-5), (color, s["color"])
    nonzero = np.argwhere(labels == s["value"])
    extent = [int(e) for e in pairs["Segment0_Extent"].split()]
    assert extent == [v for a in range(3) for v in (nonzero[:, a].min(), nonzero[:, a].max())], extent
    assert pairs["Segmentation_MasterRepresentation"] == "Binary labelmap", pairs


def check_color_files(out, report):
    s = report["structures"][0]
    with open(os.path.join(out, "labels.ctbl")) as f:
        rows = [line.split() for line in f if line.strip() and not line.startswith("#")]
    assert rows[0] == ["0", "Background", "0", "0", "0", "0"], rows[0]
    assert rows[1] == [str(s["value"]), NAME.replace(" ", "_"), *map(str, s["color"]), "255"], rows[1]
    with open(os.path.join(out, "labels.itksnap.txt")) as f:
        rows = [line for line in f if line.strip() and not line.startswith("#")]
    assert rows[1].split('"')[1] == NAME and rows[1].split()[:4] == [str(s["value"]), *map(str, s["color"])], rows


def main():
    work = tempfile.mkdtemp(prefix="independent-readers-")
    c, s = np.cos(np.radians(30)), np.sin(np.radians(30))
    affine = np.array([[0.9 * c, -0.9 * s, 0, 12.5], [0.9 * s, 0.9 * c, 0, -7.0], [0, 0, 1.3, 30.0], [0, 0, 0, 1]])
    for name, seed in (("ref", 5), ("tgt", 6)):
        mrsnake("synth", "--shape", "ellipsoid", "--size", "48", "--snr", "6", "--seed", str(seed),
                "-o", os.path.join(work, name))
        for part in ("image", "truth"):
            oblique(os.path.join(work, name, f"{part}.nii.gz"), os.path.join(work, f"{name}-{part}.nii.gz"), affine)
    with open(os.path.join(work, "names.csv"), "w") as f:
        f.write(f"value,name\n1,{NAME}\n")
    mrsnake("build-model", "--labels", os.path.join(work, "ref-truth.nii.gz"), "--label", "1", "--label-names",
            os.path.join(work, "names.csv"), "--image", os.path.join(work, "ref-image.nii.gz"),
            "-o", os.path.join(work, "model"))
    out = os.path.join(work, "seg")
    mrsnake("segment", "--image", os.path.join(work, "tgt-image.nii.gz"), "--model", os.path.join(work, "model"),
            "--truth", os.path.join(work, "tgt-truth.nii.gz"), "-o", out)
    with open(os.path.join(out, "report.json")) as f:
        report = json.load(f)
    assert report["structures"][0]["scores"]["dice"] > 0.9, report["structures"][0]["scores"]
    labels = check_labels(out, affine, report)
    check_surface(out, affine, report, labels)
    check_segmentation(out, affine, report, labels)
    check_color_files(out, report)
    subprocess.run(["rm", "-rf", work], check=True)
    print("independent readers: labels.nii.gz (nibabel), surface.vtp (VTK), labels.seg.nrrd, labels.ctbl and "
          "labels.itksnap.txt agree with report.json and the image's grid")


if __name__ == "__main__":
    main()
