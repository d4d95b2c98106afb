#pragma once
/// \file simplify.h
/// Edge-collapse simplification (CGAL: shortest edge first, midpoint placement) of a fine input before it is
/// parameterized: a marching-cubes organ surface has hundreds of thousands of faces, far
/// more than a 16k-face model needs, and the parameterization's sparse solve dominates the
/// run time. The remeshed vertices are projected back onto the original surface afterwards.
#include "mesh/trimesh.h"

namespace mrsnake {

struct SimplifyOptions {
  /// From this many faces on, the surface is cut in two halves across its bounding box's
  /// longest axis, each simplified on its own core with the cut between them kept exactly (its
  /// vertices and edges stay), then stitched: about twice as fast on two cores (442k-face liver:
  /// docs/bench-remesh.md). 0 = never.
  int halves_from_faces = 100000;
};

/// A simplification of `mesh` to about `target_faces` faces (topology preserved).
/// \pre mesh is a manifold disk or closed genus-0 surface; target_faces >= 8.
/// \throw AlgorithmError if CGAL cannot build or simplify the surface.
TriMesh simplify_to_faces(const TriMesh& mesh, int target_faces, const SimplifyOptions& options = {});

}  // namespace mrsnake
