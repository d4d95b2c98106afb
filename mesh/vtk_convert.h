#pragma once
/// \file vtk_convert.h
/// Conversions between TriMesh / Volume and VTK data objects (for the VTK-based parts:
/// file I/O, marching cubes, rendering).
#include <vtkImageData.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>

#include "mesh/trimesh.h"
#include "mesh/volume.h"

namespace mrsnake {

/// Triangulates the polygons of a vtkPolyData (lines and vertices are dropped).
TriMesh from_polydata(vtkPolyData* poly);

/// A vtkPolyData with double points and triangle polys.
vtkSmartPointer<vtkPolyData> to_polydata(const TriMesh& mesh);

/// The volume as vtkImageData in *index* space (origin 0, spacing 1), padded by `pad`
/// voxels of `pad_value` on every side so that surfaces touching the border close.
/// Map the results to physical space with index_to_physical (pad subtracted).
vtkSmartPointer<vtkImageData> to_index_space_image(const Volume& volume, int pad, float pad_value);

}  // namespace mrsnake
