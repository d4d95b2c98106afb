#pragma once
/// \file base_flips.h
/// Edge flips on the base mesh K of the MAPS map. The simplification leaves K with the valences
/// its removals happened to make (about a third of them 6), and every irregular vertex of K is
/// an irregular vertex of every level. Flipping K's edges toward the surface's Delaunay
/// triangulation, then toward valence 6, gives rounder and more regular base triangles; the
/// input points located in the two faces of a flip are located again in the new two, through
/// the quad unfolded into the plane, so the map stays a bijection onto K.
#include "remesh/maps.h"

namespace mrsnake {

struct BaseFlipOptions {
  int rim_min_triangles = 3;  ///< a disk's rim vertex keeps at least this many triangles
  /// Degrees: a flip may not fold K more than this between the two new faces, unless it folds
  /// it less than before (a flip across a ridge would cut the shape).
  double max_fold_deg = 40.0;
  /// A valence flip may not lower the smaller mean-ratio quality (4·sqrt(3)·area / the sum of
  /// squared edge lengths) of the two faces below this share of what it was.
  double valence_quality_share = 0.9;
};

struct BaseFlipStats {
  int delaunay_flips = 0;  ///< flips toward the surface's Delaunay triangulation
  int valence_flips = 0;   ///< flips toward valence 6 (4 on a rim)
};

/// Flips K's edges (the surface's Delaunay condition first, then valence 6) where the quad of
/// the two faces is convex once unfolded into the plane and the guards of `options` hold, and
/// locates every input point of the two faces again. A vertex of K stays at a corner (a unit
/// barycentric vector) of a face holding it.
/// \pre maps comes from maps_parameterize.
BaseFlipStats flip_base_edges(MapsParameterization& maps, const BaseFlipOptions& options = {});

}  // namespace mrsnake
