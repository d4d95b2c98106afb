#pragma once
/// \file shrink_wrap.h
/// A semi-regular hierarchy fitted to a closed surface by shrink wrapping (Kobbelt et al.
/// 1999, the paper's ref. [8]): an icosahedron around the surface is pulled onto it level by
/// level, subdividing 1:4 between levels, with tangential relaxation keeping the sampling
/// even. Suited to roundish (star-like) organs; the remesh module is the general route. A test
/// and benchmark helper: hierarchies without a parameterization.
#include "mesh/subdivision.h"
#include "mesh/trimesh.h"

namespace mrsnake {

struct ShrinkWrapOptions {
  int levels = 4;  ///< 1:4 splits of the icosahedron
  int iterations_per_level = 30;
  double attraction = 0.5;  ///< fraction of the way to the closest point per iteration
  double relaxation = 0.5;  ///< tangential umbrella weight per iteration
};

struct ShrinkWrapResult {
  SubdivisionConnectivity connectivity;
  RowMatrixX3d finest;          ///< positions of the finest level (prefixes are the coarser ones)
  double mean_distance_mm = 0;  ///< mean distance from the target's vertices to the finest level
  double max_distance_mm = 0;   ///< largest such distance
};

/// \pre target is a closed, outward-oriented surface.
/// \throw InputError if target is empty.
ShrinkWrapResult shrink_wrap(const TriMesh& target, const ShrinkWrapOptions& options = {});

}  // namespace mrsnake
