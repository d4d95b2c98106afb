#pragma once
/// \file shape_smoothing.h
/// Tangential smoothing of a level's vertices in 3D, carried out in D.
///
/// The paper's constrained Lloyd cell N(v) is made of barycenters and midpoints, so its
/// iteration is invariant under affine maps: it evens out sizes but cannot repair a sheared
/// triangle. This step does: each vertex aims at a 3D target (the mean of the apexes that would
/// make each of its triangles equilateral on its opposite edge, or the density-weighted mean of
/// its triangles' centroids: a Lloyd step on the surface itself, as in CGAL's tangential
/// relaxation), the tangential part of that 3D move is pulled back to D through the Jacobian of
/// the input triangle under the vertex, and the vertex is re-lifted. Moves that would flip a
/// triangle in D are halved until they do not. The two halves of the level are swept side by
/// side, then the vertices along the cut (split_sweep.h).
#include <optional>
#include <vector>

#include "mesh/trimesh.h"
#include "mesh/vertex_stars.h"
#include "remesh/domain.h"

namespace mrsnake {

/// Where a vertex aims in 3D.
enum class SmoothingTarget {
  equilateral_apexes,  ///< mean apex making each star triangle equilateral (shapes)
  area_centroid,       ///< density x area weighted mean of the star triangles' centroids (sizes and shapes)
};

struct ShapeSmoothingOptions {
  int iterations = 3;
  int first_movable = 0;  ///< vertices [0, first_movable) stay fixed
  double step = 0.5;      ///< fraction of the way to the target per iteration
  SmoothingTarget target = SmoothingTarget::equilateral_apexes;
  /// area_centroid: the wanted 3D point density per vertex of the parameterized surface
  /// (interpolated under each vertex; the weight of a triangle is its area x the square of its
  /// mean wanted density, as the 2D Lloyd density). nullptr = even.
  const Eigen::VectorXd* surface_density = nullptr;
  /// Disk rim vertices slide along the rim toward the midpoint of their two rim neighbours
  /// (staying on the circle in D); false = they stay put.
  bool move_rim = false;
  /// A move is refused if it lowers the smallest Frey–Borouchaki Q of the vertex's triangles
  /// below min(its value before the move, quality_floor): sizes even out without making the
  /// worst triangles worse. 0 = no check.
  double quality_floor = 0;
};

/// The 3D move of vertex v of (X, F) toward `target`, in the tangent plane of its normal;
/// nullopt where its normal or its target is undefined. `vertex_density` (one entry per vertex of
/// X) weighs the area_centroid target.
/// \pre `stars` are F's vertex stars.
std::optional<Eigen::Vector3d> tangential_move(const RowMatrixX3d& X, const RowMatrixX3i& F, const VertexStars& stars,
                                               int v, SmoothingTarget target, const Eigen::VectorXd& vertex_density);

/// Smooths the domain positions U of (U, F) and updates their lifts X.
/// \pre X = lift of U onto the surface whose domain mesh is `param` (3D positions surface_V);
///      no triangle flipped in D; hints has one face of `param` per vertex; a surface_density
///      has one entry per vertex of `param`.
/// \post no triangle of (U, F) is flipped in D; disk rim vertices stay on the unit circle.
/// \return the number of moves made.
int smooth_shapes_in_domain(DomainKind kind, const RowMatrixX3i& F, const DomainMesh& param,
                            const RowMatrixX3d& surface_V, RowMatrixX3d& U, RowMatrixX3d& X, std::vector<int>& hints,
                            const ShapeSmoothingOptions& options);

}  // namespace mrsnake
