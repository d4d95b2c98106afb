#pragma once
/// \file sizing.h
/// Where the remesh should be denser than even: a per-vertex curvature estimate. Even 3D
/// spacing leaves the largest chord errors (the Hausdorff distance) where the surface bends
/// most; a point density growing with curvature spreads that error.
#include "mesh/trimesh.h"

namespace mrsnake {

/// Curvature magnitude per vertex (1/length): the mean over v's edges of the change in unit
/// vertex normal per unit length, then averaged `smoothing` times over the 1-ring (marching
/// cubes surfaces are noisy at the voxel scale).
/// \pre mesh is a manifold triangle mesh without unreferenced vertices.
Eigen::VectorXd vertex_curvature(const TriMesh& mesh, int smoothing = 3);

/// `field` (one value per vertex) averaged `passes` times over each vertex's 1-ring (itself
/// included, each neighbour once per incident edge side).
/// \pre field has one entry per vertex of mesh; passes >= 0.
/// \throw nothing beyond std::bad_alloc (passes <= 0 returns field unchanged).
Eigen::VectorXd smooth_vertex_field(const TriMesh& mesh, Eigen::VectorXd field, int passes);

}  // namespace mrsnake
