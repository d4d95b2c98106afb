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

/// The wanted relative point density 1 + weight·min((κ/mean κ)^exponent, 3) per vertex, κ the
/// `curvature`: smaller triangles where the surface bends, whose chord error grows as κh².
/// Capped, so that a few sharp spots (voxel steps of a marching-cubes surface) cannot pull the
/// spacing down so fast that triangle shapes suffer. weight 0 (or a flat surface) = even.
/// \pre weight >= 0, exponent > 0.
Eigen::VectorXd curvature_density(const Eigen::VectorXd& curvature, double weight, double exponent);

/// `field` (one value per vertex) averaged `passes` times over each vertex's 1-ring (itself
/// included, each neighbour once per incident edge side).
/// \pre field has one entry per vertex of mesh; passes >= 0.
/// \throw nothing beyond std::bad_alloc (passes <= 0 returns field unchanged).
Eigen::VectorXd smooth_vertex_field(const TriMesh& mesh, Eigen::VectorXd field, int passes);

/// The area of each vertex's share of the surface: a third of each incident triangle's.
/// \pre mesh has no unreferenced vertices.
Eigen::VectorXd vertex_areas(const TriMesh& mesh);

/// A relative point density (one entry > 0 per vertex) raised where `points` points spread by it
/// would be spaced wider than max_bend / curvature, so that no edge between them turns the
/// surface's normal by more than about max_bend radians: a tube of radius r then gets at least
/// about 2π·0.64 / max_bend points around (curvature() of a tube is ~0.64 / r). The result is
/// the density where the bound is slack and the bound where it is not, in the same units.
/// Where the bound alone would take more than half of the points, it is scaled down to half
/// (a wider bend than max_bend), so that the rest still follow the density.
/// \pre density (> 0), curvature have one entry per vertex; points > 0; max_bend > 0.
Eigen::VectorXd bend_bounded_density(const TriMesh& mesh, const Eigen::VectorXd& density,
                                     const Eigen::VectorXd& curvature, double points, double max_bend);

/// The points that bend_bounded_density()'s bound alone asks for, Σ area·2κ²/(√3·max_bend²):
/// where that nears the points available, the density can no longer follow its own sizing.
/// \pre curvature has one entry per vertex; max_bend > 0.
double bend_bound_points(const TriMesh& mesh, const Eigen::VectorXd& curvature, double max_bend);

}  // namespace mrsnake
