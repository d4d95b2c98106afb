#pragma once
/// \file triangle_repair.h
/// A final per-level repair of the worst triangles, in 3D, with the vertices kept on the input.
///
/// Lloyd and shape smoothing work on averages, so a few triangles stay poor where the
/// parameterization's stretch changes fast or around extraordinary base vertices. This step
/// looks only at the vertices of triangles whose Frey–Borouchaki quality Q is below a
/// threshold and, worst first, tries a few tangential 3D moves (toward the apex that makes its
/// worst triangle equilateral, toward the mean such apex, toward the 1-ring centroid; full,
/// half and quarter steps). Each move is pulled back to D through the Jacobian of the input
/// triangle under the vertex and re-lifted exactly (so the vertex stays on the input surface);
/// the candidate that raises the smallest Q of the vertex's triangles the most is kept, and
/// only if it raises it. Connectivity is untouched (the hierarchy stays nested) and a move that
/// would flip a triangle in D is never taken. Disk rim vertices slide along the circle. The two
/// halves of the level are swept side by side, each worst first, then the vertices along the cut
/// (split_sweep.h).
#include <vector>

#include "mesh/distance.h"
#include "mesh/trimesh.h"
#include "remesh/domain.h"

namespace mrsnake {

struct TriangleRepairOptions {
  int sweeps = 6;          ///< passes over the poor triangles (each recomputes which are poor)
  double threshold = 0.8;  ///< triangles with Q below this are repaired
  bool move_rim = true;    ///< disk rim vertices may slide along the boundary
  /// Refuse moves that take the vertex's triangles further from the surface than before, or
  /// than error_tolerance x the mean edge length if that is more (largest distance between an
  /// edge's 3D midpoint and the lift of its midpoint in D, and from the vertex's old position
  /// to its new triangles): better shapes must not cut across ridges or tips.
  bool guard_surface_error = false;
  double error_tolerance = 0.03;
  /// If set, every lifted position is then moved to its closest point on this surface (the
  /// original input when the parameterized surface is a simplification of it): the repair
  /// then judges and keeps the triangles as they will finally be. X must already be on it.
  const SurfaceLocator* project_onto = nullptr;
  /// If set (one entry per vertex), vertices marked true never move: the tips that
  /// snap_to_input_tips put exactly on the input.
  const std::vector<bool>* fixed = nullptr;
};

struct TriangleRepairStats {
  int moves = 0;            ///< vertex moves made
  double q_min_before = 0;  ///< smallest Q in 3D before the repair
  double q_min_after = 0;   ///< and after
};

/// Repairs the worst triangles of (X, F) by moving vertices tangentially; updates U, X and hints.
/// \pre X = lift of U onto the surface whose domain mesh is `param` (3D positions surface_V),
///      then projected onto options.project_onto if set;
///      no triangle of (U, F) flipped in D; hints has one face of `param` per vertex; a fixed
///      mask has one entry per vertex.
/// \post no triangle of (U, F) is flipped in D; vertices marked in options.fixed keep U, X and
///       hints; the smallest Q of every moved vertex's
///       triangles went up, so the mesh's smallest Q never goes down; with
///       guard_surface_error and error_tolerance 0 the largest edge-midpoint distance to the
///       surface never goes up either.
/// \throw nothing (a vertex whose move cannot be computed stays put).
TriangleRepairStats repair_worst_triangles(DomainKind kind, const RowMatrixX3i& F, const DomainMesh& param,
                                           const RowMatrixX3d& surface_V, RowMatrixX3d& U, RowMatrixX3d& X,
                                           std::vector<int>& hints, const TriangleRepairOptions& options);

}  // namespace mrsnake
