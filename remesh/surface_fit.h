#pragma once
/// \file surface_fit.h
/// Least-squares fit of a remeshed level to its input along the vertex normals. A level lifted
/// onto the input has every vertex on the surface, so every triangle is a chord: on a convex
/// patch the whole triangle lies inside, and its distance to the surface, h²κ/8 at the worst,
/// is one-signed. Moving each vertex a little along its normal (by much less than an edge)
/// centres the triangles on the surface instead, as the vertex placement of mesh optimization
/// and quadric simplification does: the connectivity and the triangle shapes stay as they are,
/// and the distance to the input falls.
#include <vector>

#include "mesh/distance.h"
#include "mesh/trimesh.h"

namespace mrsnake {

struct SurfaceFitOptions {
  /// Rounds of closest points then a linear solve; each round starts from the previous fit.
  /// 1: a second round changed the RMS by under 1 % on heart, retinal and bear.
  int rounds = 1;
  /// Tikhonov weight on the offsets, relative to the quadrature mass: keeps the solve well posed
  /// where the samples say little (a tiny value barely biases the fit).
  double regularization = 1e-3;
  /// No vertex moves by more than this x the mean length of its edges (the fit corrects chord
  /// errors, which are a small fraction of an edge on a surface the level resolves; a larger
  /// offset means a crease or a voxel step the level cannot follow).
  double max_offset = 0.15;
  /// A sample whose closest point lies more than this x the local edge length away is left out
  /// (it sees another part of the surface, across a thin gap).
  double max_sample_distance = 0.5;
  /// A triangle may not end with a Frey-Borouchaki quality below min(its own before, this):
  /// the offsets around it are undone (on a marching-cubes staircase the fit follows voxel steps).
  double quality_floor = 0.75;
};

/// What fit_to_surface() did.
struct SurfaceFitStats {
  /// Quadrature estimates of the RMS normal distance from the level to the surface (mm): before
  /// the fit, and after the last round's solve as linearized, before the triangle guard.
  /// The rule weighs the corners more than the exact integral of the squared distance would:
  /// on a sphere these say 1/2 where the integral says about 1/4.
  double rms_before = 0;
  double rms_after = 0;
  double mean_offset = 0;    ///< mean |offset| over the vertices, in mm
  double max_offset = 0;     ///< largest |offset|, in mm
  int clamped_vertices = 0;  ///< vertices whose offset hit options.max_offset in the last round
  int held_vertices = 0;     ///< vertices pulled back because a triangle around them turned or lost quality
};

/// Moves every vertex of (X, F) along its vertex normal to minimize the squared normal
/// distance from the level to `surface`, integrated over the level's triangles (a quadrature on
/// the corners and centroids, exact for quadratic integrands), plus a small penalty on the
/// offsets. Each round takes the closest points of the quadrature points, then solves the
/// normal equations by conjugate gradients. The first round takes the vertices' own distance as
/// 0 (they start on the surface); later rounds query them too.
/// \pre surface_locator was built on the input surface and every vertex of X lies on it (as
///      lifted or projected: the first round takes their distance as 0); F is a manifold
///      triangle mesh on the rows of X; fixed is empty or has one entry per row of X.
/// \post vertices with fixed[v] do not move; no vertex moves by more than max_offset x the mean
///       length of its edges; no triangle's normal turns by 30° or more, and none ends with a
///       quality below min(before, quality_floor) (the offsets around one that would are undone).
/// \throw std::invalid_argument on bad options or a `fixed` of the wrong size.
SurfaceFitStats fit_to_surface(const RowMatrixX3i& F, RowMatrixX3d& X, const SurfaceLocator& surface_locator,
                               const SurfaceFitOptions& options = {}, const std::vector<bool>& fixed = {});

}  // namespace mrsnake
