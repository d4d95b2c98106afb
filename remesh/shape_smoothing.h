#pragma once
/// \file shape_smoothing.h
/// Tangential smoothing toward equilateral triangles in 3D, carried out in D.
///
/// The paper's constrained Lloyd cell N(v) is made of barycenters and midpoints, so its
/// iteration is invariant under affine maps: it evens out sizes but cannot repair a sheared
/// triangle. This step does: each vertex aims at the mean of the apexes that would make each
/// of its 3D triangles equilateral on its opposite edge, the tangential part of that 3D move is
/// pulled back to D through the Jacobian of the input triangle under the vertex, and the
/// vertex is re-lifted. Moves that would flip a triangle in D are halved until they do not.
#include <vector>

#include "mesh/trimesh.h"
#include "remesh/domain.h"

namespace mrsnake {

struct ShapeSmoothingOptions {
  int iterations = 3;
  int first_movable = 0;  ///< vertices [0, first_movable) stay fixed
  double step = 0.5;      ///< fraction of the way to the target per iteration
};

/// Smooths the domain positions U of (U, F) and updates their lifts X.
/// \pre X = lift of U onto the surface whose domain mesh is `param` (3D positions surface_V);
///      no triangle flipped in D; hints has one face of `param` per vertex.
/// \return the number of moves made.
int smooth_shapes_in_domain(DomainKind kind, const RowMatrixX3i& F, const DomainMesh& param,
                            const RowMatrixX3d& surface_V, RowMatrixX3d& U, RowMatrixX3d& X,
                            std::vector<int>& hints, const ShapeSmoothingOptions& options);

}  // namespace mrsnake
