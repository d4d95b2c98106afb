#pragma once
/// \file normals.h
/// Face and vertex normals of a triangle mesh (plain loops over Eigen matrices).
#include "mesh/trimesh.h"

namespace mrsnake {

/// Unit face normals (zero for a degenerate face).
void face_normals(const RowMatrixX3d& V, const RowMatrixX3i& F, RowMatrixX3d& N);

/// Unit vertex normals: the normalized sum of the area-weighted normals of the faces around
/// each vertex (outward for an outward-oriented mesh; zero for a vertex in no face).
void vertex_normals(const RowMatrixX3d& V, const RowMatrixX3i& F, RowMatrixX3d& N);

}  // namespace mrsnake
