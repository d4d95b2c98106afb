#pragma once
/// \file untangle.h
/// Opening the folds of a level that passes through itself. Where a protrusion is thinner than
/// the level's edges (an octopus's tentacle tips), the triangles lifted around it fold into one
/// another: nearby points of the domain lift onto opposite sides of the tube. Moving each vertex
/// of an intersecting face pair to the mean of its neighbours (the umbrella step) opens such a
/// fold, and leaves the input there, by up to about an edge. Where the input itself passes
/// through itself, the level may keep crossings that no such move removes.
///
/// The pairs are crossing_face_pairs (mesh/distance.h): faces that share no vertex. Neighbours
/// that overlap in a fold have crossing faces beside them, and open with them (on the octopus and
/// the human figure of bench/remesh, count_self_intersections after the stage is the same as with
/// it run on every pair, in half to two thirds of the time).
#include <vector>

#include "mesh/trimesh.h"

namespace mrsnake {

struct UntangleOptions {
  /// Rounds at most; the rounds stop as soon as one would not lower the count of crossing face
  /// pairs. 0 = off.
  int max_rounds = 10;
};

/// What untangle_self_intersections() did.
struct UntangleStats {
  int pairs_before = 0;    ///< crossing face pairs before (crossing_face_pairs); 0 when off
  int pairs_after = 0;     ///< and after
  int rounds = 0;          ///< rounds kept
  int moved_vertices = 0;  ///< distinct vertices the kept rounds moved
};

/// Moves every vertex of the crossing face pairs of (X, F) to the mean of its neighbours, all at
/// once, round after round while the count of such pairs falls; the first round that would not
/// lower it is undone and ends the stage.
/// Only the count decides: a round may thin triangles or fold neighbours that share a vertex
/// (which crossing_face_pairs does not see), as long as fewer faces cross.
/// \pre every index in F is a row of X.
/// \post vertices with fixed[v] do not move; pairs_after <= pairs_before, and pairs_after is
///       the size of crossing_face_pairs of the result.
/// \throw std::invalid_argument if fixed is neither empty nor one entry per row of X.
UntangleStats untangle_self_intersections(const RowMatrixX3i& F, RowMatrixX3d& X, const std::vector<bool>& fixed,
                                          const UntangleOptions& options = {});

}  // namespace mrsnake
