#!/usr/bin/env python3
"""Closed genus-0 shapes as a decimated mesh leaves them: a few thousand faces, long slivers along
their limbs and tubes. None is in ../shared/data; they try `mrsnake remesh` on inputs unlike its
benchmark's (docs/remesh.md, "Large slivers").

    bench/decimated_shapes.py OUT_DIR

writes cow.ply, hand.ply, kidney.ply and caudate.ply (an implicit shape, marching cubes on a 160^3
grid, the largest component, VTK's quadric decimation to 5 % of the faces) and capsule-3.off and
capsule-4.off (a tube of radius 1 and length 20 with hemispherical caps, 16 vertices per ring,
the tube's rings 20/7 or 4 apart: tube triangles of Q 0.22 and 0.16).
"""
import math
import os
import sys

import numpy as np
import vtk
from vtk.util.numpy_support import numpy_to_vtk


def capsule_distance(P, a, b, r):
    ab = b - a
    t = np.clip(((P - a) @ ab) / (ab @ ab), 0, 1)
    return np.linalg.norm(P - (a + t[..., None] * ab), axis=-1) - r


def ellipsoid_distance(P, centre, axes):
    return (np.linalg.norm((P - centre) / axes, axis=-1) - 1) * min(axes)


def smooth_union(a, b, k=0.05):
    h = np.clip(0.5 + 0.5 * (b - a) / k, 0, 1)
    return b * (1 - h) + a * h - k * h * (1 - h)


def v(*xyz):
    return np.array(xyz, dtype=float)


def hand(P):
    d = ellipsoid_distance(P, v(0, 0, 0), v(0.45, 0.55, 0.15))
    for i, x in enumerate([-0.33, -0.11, 0.11, 0.33]):
        d = smooth_union(d, capsule_distance(P, v(x, 0.4, 0), v(x * 1.3, 1.1 + 0.1 * (i in (1, 2)), 0), 0.085))
    return smooth_union(d, capsule_distance(P, v(-0.35, -0.1, 0), v(-0.85, 0.35, 0.05), 0.095))


def cow(P):
    d = ellipsoid_distance(P, v(0, 0, 0), v(0.8, 0.35, 0.35))
    for x in (-0.55, 0.55):
        for z in (-0.2, 0.2):
            d = smooth_union(d, capsule_distance(P, v(x, -0.2, z), v(x, -0.95, z), 0.07))
    d = smooth_union(d, ellipsoid_distance(P, v(1.0, 0.25, 0), v(0.25, 0.18, 0.16)))
    for z in (-0.12, 0.12):
        d = smooth_union(d, capsule_distance(P, v(1.05, 0.38, z), v(1.05, 0.6, z * 2.6), 0.03), 0.02)
    return smooth_union(d, capsule_distance(P, v(-0.8, 0.1, 0), v(-1.1, -0.45, 0), 0.025), 0.02)


def kidney(P):
    d = ellipsoid_distance(P, v(0, 0, 0), v(0.35, 0.6, 0.25))
    d = np.maximum(d, -ellipsoid_distance(P, v(0.42, 0, 0), v(0.2, 0.25, 0.3)))
    d = smooth_union(d, capsule_distance(P, v(0.15, 0, 0), v(0.5, -0.05, 0), 0.08))
    return smooth_union(d, capsule_distance(P, v(0.5, -0.05, 0), v(0.6, -0.9, 0.05), 0.035), 0.03)


def caudate(P):
    d = ellipsoid_distance(P, v(0, 0, 0), v(0.3, 0.4, 0.3))
    th = np.linspace(0, np.pi * 1.1, 12)
    tail = np.stack([0.1 + 0.42 * (1 - np.cos(th)), -0.3 - 0.6 * np.sin(th), 0.1 * th], 1)
    for i in range(len(tail) - 1):
        d = smooth_union(d, capsule_distance(P, tail[i], tail[i + 1], 0.15 * (1 - i / len(tail)) + 0.03), 0.03)
    return d


def decimated_surface(distance, path, n=160, extent=1.3):
    g = np.linspace(-extent, extent, n)
    P = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1)
    image = vtk.vtkImageData()
    image.SetDimensions(n, n, n)
    step = 2 * extent / (n - 1)
    image.SetSpacing(step, step, step)
    image.SetOrigin(-extent, -extent, -extent)
    image.GetPointData().SetScalars(numpy_to_vtk(distance(P).transpose(2, 1, 0).ravel().copy(), deep=1))
    surface = vtk.vtkMarchingCubes()
    surface.SetInputData(image)
    surface.SetValue(0, 0.0)
    largest = vtk.vtkPolyDataConnectivityFilter()
    largest.SetInputConnection(surface.GetOutputPort())
    largest.SetExtractionModeToLargestRegion()
    clean = vtk.vtkCleanPolyData()
    clean.SetInputConnection(largest.GetOutputPort())
    decimate = vtk.vtkQuadricDecimation()
    decimate.SetInputConnection(clean.GetOutputPort())
    decimate.SetTargetReduction(0.95)
    writer = vtk.vtkPLYWriter()
    writer.SetInputConnection(decimate.GetOutputPort())
    writer.SetFileName(path)
    writer.Write()


def write_capsule(path, length=20.0, around=16, ring_spacing=4.0):
    cap = around // 4
    rings = [(-math.cos(0.5 * math.pi * i / cap), math.sin(0.5 * math.pi * i / cap)) for i in range(1, cap + 1)]
    tube = round(length / ring_spacing)
    rings += [(length * j / tube, 1.0) for j in range(1, tube + 1)]
    rings += [(length + math.sin(0.5 * math.pi * i / cap), math.cos(0.5 * math.pi * i / cap)) for i in range(1, cap)]
    V = [(r * math.cos(2 * math.pi * k / around), r * math.sin(2 * math.pi * k / around), z)
         for z, r in rings for k in range(around)]
    south, north = len(V), len(V) + 1
    V += [(0.0, 0.0, -1.0), (0.0, 0.0, length + 1)]
    F = []
    last = len(rings) - 1
    for k in range(around):
        k1 = (k + 1) % around
        F.append((south, k1, k))
        for i in range(last):
            F += [(i * around + k, i * around + k1, (i + 1) * around + k1),
                  (i * around + k, (i + 1) * around + k1, (i + 1) * around + k)]
        F.append((last * around + k, last * around + k1, north))
    with open(path, "w") as out:
        out.write("OFF\n%d %d 0\n" % (len(V), len(F)))
        out.writelines("%.17g %.17g %.17g\n" % p for p in V)
        out.writelines("3 %d %d %d\n" % f for f in F)


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: bench/decimated_shapes.py OUT_DIR")
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    for name, distance in (("cow", cow), ("hand", hand), ("kidney", kidney), ("caudate", caudate)):
        decimated_surface(distance, os.path.join(out, name + ".ply"))
    for spacing in (3, 4):
        write_capsule(os.path.join(out, "capsule-%d.off" % spacing), ring_spacing=float(spacing))
    print("wrote cow.ply, hand.ply, kidney.ply, caudate.ply, capsule-3.off and capsule-4.off to " + out)


if __name__ == "__main__":
    main()
