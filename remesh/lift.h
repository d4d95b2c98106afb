#pragma once
/// \file lift.h
/// Lifting from D to 3D (section 4.3 step 2c): each point takes the barycentric coordinates
/// of the input triangle of T that holds it in D.
#include <vector>

#include "mesh/trimesh.h"
#include "remesh/domain.h"

namespace mrsnake {

/// 3D positions of the domain points U.
/// \pre surface_V holds the 3D positions of param's vertices; hints has one entry per row of
///      U (a face of param to start the walk; updated to the face found).
RowMatrixX3d lift_to_surface(const DomainMesh& param, const RowMatrixX3d& surface_V, const RowMatrixX3d& U,
                             std::vector<int>& hints);

}  // namespace mrsnake
