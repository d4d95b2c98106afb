#pragma once
/// \file legacy_vtk_reader.h
/// A strict reader of legacy VTK polydata files (.vtk), ASCII or BINARY, in both the
/// classic cell layout and the 5.1 OFFSETS/CONNECTIVITY layout. VTK 9.1's vtkPolyDataReader
/// dereferences null on malformed numbers (found by fuzzing), so mrsnake parses the format
/// itself and checks every count, type and index.
#include <string>

#include "mesh/trimesh.h"

namespace mrsnake {

/// Reads the points and the polygons (fanned into triangles) of a legacy VTK polydata file;
/// vertices, lines, strips and point/cell data are skipped.
/// \throw InputError if the file is missing, malformed, truncated or inconsistent.
TriMesh read_legacy_vtk(const std::string& path);

}  // namespace mrsnake
