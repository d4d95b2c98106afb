#pragma once
/// \file feature_snap.h
/// Snapping level vertices onto the input's tips. Lloyd steps pull every vertex toward the
/// centroid of its cell, so no vertex stays on a sharp tip of the input and the level cuts it
/// off: the Hausdorff distance is then that tip's height. This step finds the input vertices
/// farthest from the level (worst first) and moves the nearest level vertex onto each, in D
/// (exact lift: the vertex is the input vertex), when that flips nothing in D, leaves the
/// vertex's triangles with Q >= min_quality and angles >= min_angle_deg, and really brings the
/// input around the vertex closer to the level (moving a vertex onto a tip also moves its
/// triangles off the input it stood on). Where the nearest vertex cannot take the tip, the
/// other corners of the tip's level face are tried; where none can, the nearest corner that
/// can go part of the way (from 1/4, in D) goes as far as the bounds allow, which still lowers
/// the tip's distance. A tip is judged by its distance to the level as it is
/// when its turn comes, after the snaps before it. Snaps cost triangle quality, so only tips
/// that set the Hausdorff distance are tried, and all snaps are undone unless together they
/// lower the largest input-to-level distance.
///
/// Where the domain says which level face holds each input vertex in D, the tips are found
/// by their distance to that face: the triangle that stands for the input there, and an
/// upper bound of the distance to the level. That needs no closest-point tree over the whole
/// level, the larger part of the snap's time. How far a tip must be, and whether the snaps are
/// kept, are still decided on the exact largest distance, measured for the few input vertices
/// whose bound exceeds it.
#include <functional>
#include <optional>
#include <vector>

#include "mesh/trimesh.h"
#include "remesh/domain.h"

namespace mrsnake {

struct FeatureSnapOptions {
  int max_snaps = 32;         ///< at most this many vertices move
  double min_distance = 0.1;  ///< only input vertices farther than this x the mean edge length
  double min_quality = 0.65;  ///< the moved vertex's triangles keep Q >= this
  double min_angle_deg = 32;  ///< and angles >= this (the repair after it keeps snapped tips fixed)
  /// A snap of v must lower the largest distance from the input vertices near v (those whose
  /// level face is around v or its neighbours) to the level by at least this fraction,
  /// and all snaps together the largest distance from the whole input.
  double min_gain = 0.25;
  /// Only tips at least this fraction of the largest input-to-level distance away: the ones
  /// that make the Hausdorff distance (a snap costs triangle quality).
  double min_share_of_largest = 0.5;
};

/// What the snap asks of the parameter domain, which holds a point of D per level vertex.
struct SnapInDomain {
  /// v moved the fraction t (in (0, 1]) of the way to input vertex s's point of D: its 3D
  /// position there on the input (at t = 1 exactly s's vertex), or nullopt where that point is
  /// not in D or flips one of v's triangles.
  std::function<std::optional<Eigen::Vector3d>(int v, int s, double t)> toward;
  std::function<void(int v, int s, double t)> apply;  ///< puts v there in D
  std::function<void()> undo;                         ///< puts every vertex back where it was before the snap
  /// Each input vertex's level face in D: the face whose triangle in D holds the input
  /// vertex's point (on a disk, outside the level's rim chords, the rim face nearest it), one
  /// entry per input vertex. Where this is empty, or gives anything but one face of the level
  /// per input vertex, the input is measured against the level by closest point in 3D
  /// instead: each input vertex's level face is then its nearest.
  std::function<std::vector<int>()> input_faces;
};

/// The snap in any parameter domain: level (X, F), input vertices surface_V with faces input_F;
/// level vertices on `rim` stay, input vertices on `input_rim` are no tips.
/// \pre as snap_to_input_tips(), in `domain`; rim has one entry per row of X, input_rim one per
///      row of surface_V.
/// \post as snap_to_input_tips(): every moved vertex is at domain.toward()'s position in X and
///       was applied in D; if the snaps are not kept, X and the domain are as they were.
/// \throw nothing beyond std::bad_alloc and what `domain`'s functions throw.
int snap_level_to_input_tips(const RowMatrixX3i& F, RowMatrixX3d& X, const RowMatrixX3d& surface_V,
                             const RowMatrixX3i& input_F, const std::vector<bool>& rim,
                             const std::vector<bool>& input_rim, const SnapInDomain& domain,
                             const FeatureSnapOptions& options, std::vector<bool>* snapped = nullptr);

/// Snaps vertices of (U, F) (lifted X) onto the input vertices farthest from (X, F).
/// \pre X = lift of U onto the surface whose domain mesh is `param` (3D positions surface_V);
///      no triangle of (U, F) flipped in D; hints has one face of `param` per vertex.
/// \post no triangle flipped in D; every moved vertex is on the input (X is the lift of U),
///       exactly at an input vertex where it went the whole way;
///       if any moved, the largest distance from the input vertices to the level went down
///       by at least min_gain (else nothing moved: U, X and hints are as they were);
///       disk rim vertices do not move; if `snapped` is given it has one entry per vertex, true
///       for the vertices moved (to keep them fixed in the repair after).
/// \return the number of vertices moved.
/// \throw nothing beyond std::bad_alloc (a tip whose snap is not worth it is left alone).
int snap_to_input_tips(DomainKind kind, const RowMatrixX3i& F, const DomainMesh& param, const RowMatrixX3d& surface_V,
                       RowMatrixX3d& U, RowMatrixX3d& X, std::vector<int>& hints, const FeatureSnapOptions& options,
                       std::vector<bool>* snapped = nullptr);

}  // namespace mrsnake
