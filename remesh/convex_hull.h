#pragma once
/// \file convex_hull.h
/// Convex hull of a point set in 3D (CGAL behind a small adapter). On points of the unit
/// sphere it is the spherical Delaunay triangulation; on points lifted onto the paraboloid
/// z = x² + y², its lower faces are the planar Delaunay triangulation.
#include "mesh/trimesh.h"

namespace mrsnake {

/// Faces of the convex hull, oriented outward, indexing rows of `points`. Points strictly
/// inside the hull are not referenced.
/// \pre at least four points, not all coplanar, no duplicates.
/// \throw AlgorithmError if the hull is degenerate (fewer than four faces).
RowMatrixX3i convex_hull_faces(const RowMatrixX3d& points);

}  // namespace mrsnake
