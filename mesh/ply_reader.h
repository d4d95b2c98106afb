#pragma once
/// \file ply_reader.h
/// A strict PLY reader (ASCII, binary little- and big-endian). VTK 9.1's vtkPLYReader
/// double-frees on some malformed files (found by fuzzing, tests/fuzz), so mrsnake reads
/// PLY itself and validates every count, type and index before trusting it.
#include <string>

#include "mesh/trimesh.h"

namespace mrsnake {

/// Reads the vertex positions (x, y, z) and the faces (vertex_indices or vertex_index
/// lists; polygons are fanned into triangles) of a PLY file; other elements and
/// properties are skipped.
/// \throw InputError if the file is missing, malformed, truncated, or inconsistent.
TriMesh read_ply(const std::string& path);

}  // namespace mrsnake
