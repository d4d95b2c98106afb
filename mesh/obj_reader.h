#pragma once
/// \file obj_reader.h
/// A strict Wavefront OBJ reader (v and f lines). VTK 9.1's vtkOBJReader dereferences null
/// on faces that name missing texture coordinates (found by fuzzing), so mrsnake reads the
/// geometry itself: `f` corners may be i, i/t, i//n or i/t/n, with negative (relative) i.
#include <string>

#include "mesh/trimesh.h"

namespace mrsnake {

/// Reads vertex positions and faces (fanned into triangles); other statements are skipped.
/// \throw InputError if the file is missing or has a malformed v or f line.
TriMesh read_obj(const std::string& path);

}  // namespace mrsnake
