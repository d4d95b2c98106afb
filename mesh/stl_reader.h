#pragma once
/// \file stl_reader.h
/// A strict STL reader (ASCII and binary). VTK 9.1's vtkSTLReader believes a binary file's
/// triangle count and allocates it before reading (gigabytes for a damaged file, found by
/// fuzzing), so mrsnake reads STL itself and checks the count against the file size.
#include <string>

#include "mesh/trimesh.h"

namespace mrsnake {

/// Reads an STL file; corners with identical coordinates are merged into one vertex, in
/// the order they are first met.
/// \throw InputError if the file is missing, malformed, truncated, or has no triangle.
TriMesh read_stl(const std::string& path);

}  // namespace mrsnake
