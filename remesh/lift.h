#pragma once
/// \file lift.h
/// Lifting from D to 3D (section 4.3 step 2c): each point takes the barycentric coordinates
/// of the input triangle of T that holds it in D.
#include <vector>

#include "mesh/trimesh.h"
#include "remesh/domain.h"

namespace mrsnake {

/// The 3D point at `loc` (a face of the domain mesh with faces param_faces and barycentric
/// coordinates in it), on the surface with vertex positions surface_V.
/// \pre loc.face is a row of param_faces, whose entries index surface_V.
inline Eigen::Vector3d lift_location(const RowMatrixX3d& surface_V, const RowMatrixX3i& param_faces,
                                     const DomainMesh::Location& loc) {
  return loc.barycentric[0] * surface_V.row(param_faces(loc.face, 0)).transpose() +
         loc.barycentric[1] * surface_V.row(param_faces(loc.face, 1)).transpose() +
         loc.barycentric[2] * surface_V.row(param_faces(loc.face, 2)).transpose();
}

/// 3D positions of the domain points U.
/// \pre surface_V holds the 3D positions of param's vertices; hints has one entry per row of
///      U (a face of param to start the walk; updated to the face found).
RowMatrixX3d lift_to_surface(const DomainMesh& param, const RowMatrixX3d& surface_V, const RowMatrixX3d& U,
                             std::vector<int>& hints);

}  // namespace mrsnake
