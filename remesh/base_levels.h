#pragma once
/// \file base_levels.h
/// The levels of the hierarchy built in the base-mesh domain (remesh/base_domain.h): the 1:4
/// split of a level, its relaxation, and its flip test, all in the charts of K's vertices.
///
/// Without relaxation, every vertex of level j sits at dyadic barycentric coordinates of one
/// face of K, and the hierarchy is the MAPS remesh. The relaxation moves vertices across K's
/// edges and vertices freely: a move is computed in a chart that holds the vertex and its whole
/// star, so K's edges are no seams. Each vertex aims at a 3D target (shape_smoothing.h), the
/// 3D move is pulled back into the chart through the affine map of the input triangle under
/// the vertex, and moves that would flip a triangle in the chart are halved until they do not.
#include <vector>

#include "mesh/subdivision.h"
#include "mesh/trimesh.h"
#include "remesh/base_domain.h"
#include "remesh/base_lift.h"
#include "remesh/feature_snap.h"
#include "remesh/shape_smoothing.h"

namespace mrsnake {

/// One level in the base domain: its points of D and their lifts onto the input.
struct BaseLayout {
  std::vector<BasePoint> points;
  RowMatrixX3d X;
};

/// Level 0: K's vertices, lifted (onto the input vertices they are).
BaseLayout base_vertices_layout(const BaseDomain& domain, const BaseLift& lift);

/// Level j > 0 from level j − 1: each new vertex at the midpoint of its parents in a chart
/// that holds both, lifted.
/// \pre layout holds level j − 1 of `connectivity`.
/// \return false, with `layout` partly split, if two parents share no chart: a relaxed sliver
/// can stretch an edge across more than one star of K. The dyadic split never does, as each
/// of its edges lies in one face of K.
[[nodiscard]] bool split_on_base(const SubdivisionConnectivity& connectivity, int j, const BaseDomain& domain,
                                 const BaseLift& lift, BaseLayout& layout);

struct BaseSmoothingOptions {
  int iterations = 6;
  double step = 0.5;  ///< fraction of the way to the target per iteration
  SmoothingTarget target = SmoothingTarget::equilateral_apexes;
  /// area_centroid: the wanted 3D point density per vertex of the input the lift maps onto
  /// (interpolated under each vertex). nullptr = even.
  const Eigen::VectorXd* surface_density = nullptr;
  /// A move is refused if it lowers the smallest Q of the vertex's triangles below
  /// min(its value before, quality_floor). 0 = no check.
  double quality_floor = 0;
  /// Disk rim vertices slide along the rim (evening the 3D rim lengths) instead of staying.
  bool slide_rim = true;
};

/// Moves the interior vertices of (layout, F) toward `options.target`, and slides disk rim
/// vertices along the rim (options.slide_rim).
/// \pre no triangle of F is flipped in D (count_flipped_on_base == 0).
/// \post the same.
/// \return the number of moves made.
int smooth_on_base(const RowMatrixX3i& F, const BaseDomain& domain, const BaseLift& lift, BaseLayout& layout,
                   const BaseSmoothingOptions& options);

/// The sphere route's snap of the finest level onto the input's tips (feature_snap.h) in the
/// base domain: a vertex moves to an input vertex's own point of D where no triangle of its
/// star is flipped there. Rim vertices stay; input rim vertices are no tips.
/// \pre layout holds a level of F; no triangle flipped in D.
/// \post as snap_level_to_input_tips(): each moved vertex is exactly its input vertex (X) at that
///       vertex's point of D; no triangle flipped in D; `snapped`, if given, marks the moved.
/// \return the number of vertices moved.
int snap_on_base(const RowMatrixX3i& F, const BaseDomain& domain, const BaseLift& lift, BaseLayout& layout,
                 const FeatureSnapOptions& options, std::vector<bool>* snapped = nullptr);

struct BaseRepairOptions {
  int sweeps = 6;           ///< passes over the poor triangles (each recomputes which are poor)
  double threshold = 0.85;  ///< triangles with Q below this are repaired
  /// If >= 0: refuse moves that take the vertex's triangles further from the surface than
  /// before, or than this x the mean edge length if that is more (the largest distance between
  /// an edge's 3D midpoint and the lift of its chart midpoint, and from the vertex's old
  /// position to its new triangles): better shapes must not cut across ridges or tips.
  double error_tolerance = -1;
  /// If set (one entry per vertex), vertices marked true never move: the tips snap_on_base put
  /// exactly on the input.
  const std::vector<bool>* fixed = nullptr;
};

/// What repair_on_base() did.
struct BaseRepairStats {
  int moves = 0;
  double q_min_before = 0;  ///< smallest Q of the level's triangles before the repair
  double q_min_after = 0;   ///< and after
};

/// The sphere route's repair of the worst triangles (triangle_repair.h) in the charts of K:
/// worst first, each interior vertex of a triangle with Q < threshold tries the moves toward
/// repair_targets() (full, half and quarter steps), pulled back into a chart that holds its
/// star, and keeps the one that raises the smallest Q of its triangles the most, if any does
/// without adding a flipped triangle in D (and, with a tolerance, within the surface guard).
/// Rim vertices stay. Every vertex stays on the input (the lift of its point of D).
/// \pre layout holds a level of F; no triangle flipped in D.
/// \post no triangle flipped in D; the smallest Q of every moved vertex's triangles went up,
///       so the level's smallest Q never goes down.
BaseRepairStats repair_on_base(const RowMatrixX3i& F, const BaseDomain& domain, const BaseLift& lift,
                               BaseLayout& layout, const BaseRepairOptions& options);

/// Up to `sweeps` sweeps over the interior vertices of flipped triangles, each moved to the
/// mean of its ring in the chart of its star where that leaves fewer flips around it: charts
/// disagree a little across K's edges, so a split can fold a sliver that the chart its parent
/// was tested in held unfolded.
/// \return the number of moves made.
int untangle_on_base(const RowMatrixX3i& F, const BaseDomain& domain, const BaseLift& lift, BaseLayout& layout,
                     int sweeps = 10);

/// Triangles of F that no chart holding their corners sees counter-clockwise
/// (BaseDomain::counter_clockwise): the flipped triangles in D.
int count_flipped_on_base(const BaseDomain& domain, const RowMatrixX3i& F, const std::vector<BasePoint>& points);

}  // namespace mrsnake
