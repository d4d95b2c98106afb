#pragma once
/// \file mesh_io.h
/// Reading and writing triangle meshes: .vtp .vtk .stl .ply .obj .off.
#include <string>

#include "mesh/trimesh.h"

namespace mrsnake {

/// Reads a triangle mesh; polygons are triangulated, and STL's duplicated corners merged.
/// \throw InputError if the file is missing, of an unknown extension, unreadable, empty,
///        or holds non-finite coordinates or out-of-range indices.
TriMesh read_mesh(const std::string& path);

/// Writes a mesh; the format follows the extension. VTK XML .vtp is the default output
/// format (ParaView, 3D Slicer). Written to a temporary name and renamed into place.
/// \throw OutputError if the extension is unknown or the file cannot be written.
void write_mesh(const std::string& path, const TriMesh& mesh);

/// Lower-case extension of a path, including ".gz" compound forms such as ".nii.gz".
std::string file_extension(const std::string& path);

}  // namespace mrsnake
