"""A small reader of attached-header gzip NRRD files, written from the format's specification
(teem's NRRD format), so that the tests check mrsnake's NRRD output with a reader not its own."""
import gzip

import numpy as np


def read_nrrd(path):
    """(fields, key/values, voxels) of an attached-header gzip NRRD, by the format's spec."""
    with open(path, "rb") as f:
        data = f.read()
    header, payload = data.split(b"\n\n", 1)
    lines = header.decode("ascii").split("\n")
    assert lines[0].startswith("NRRD000"), lines[0]
    fields, pairs = {}, {}
    for line in lines[1:]:
        if line.startswith("#") or not line:
            continue
        if ":=" in line:
            key, value = line.split(":=", 1)
            pairs[key] = value
        else:
            key, value = line.split(": ", 1)
            fields[key] = value
    assert fields["encoding"] == "gzip", fields["encoding"]
    dtype = {"unsigned char": np.uint8, "uchar": np.uint8, "short": np.int16}[fields["type"]]
    sizes = [int(s) for s in fields["sizes"].split()]
    voxels = np.frombuffer(gzip.decompress(payload), dtype=dtype).reshape(sizes, order="F")
    return fields, pairs, voxels


def nrrd_affine_ras(fields):
    """The NRRD's index-to-RAS matrix from its LPS space directions and origin."""
    assert fields["space"] == "left-posterior-superior", fields["space"]
    vectors = [[float(x) for x in v.strip("()").split(",")] for v in fields["space directions"].split()]
    origin = [float(x) for x in fields["space origin"].strip("()").split(",")]
    lps = np.eye(4)
    lps[:3, :3] = np.array(vectors).T
    lps[:3, 3] = origin
    return np.diag([-1.0, -1.0, 1.0, 1.0]) @ lps
