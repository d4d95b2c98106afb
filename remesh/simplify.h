#pragma once
/// \file simplify.h
/// Edge-collapse simplification (CGAL: shortest edge first, midpoint placement) of a fine input before it is
/// parameterized: a marching-cubes organ surface has hundreds of thousands of faces, far
/// more than a 16k-face model needs, and the parameterization's sparse solve dominates the
/// run time. The remeshed vertices are projected back onto the original surface afterwards.
#include <optional>

#include "mesh/trimesh.h"

namespace mrsnake {

struct SimplifyOptions {
  /// A closed surface of this many faces or more is cut in two halves across its bounding
  /// box's longest axis; each is simplified to a little above its share on its own core, with
  /// the cut between them kept exactly (its vertices stay and no collapse joins two of them),
  /// then they are stitched along it and a last pass over the whole surface reaches the target,
  /// taking the cut's strip of short input edges first. 0 = never. Speed and quality on the
  /// 442k-face liver: docs/bench-remesh.md.
  int halves_from_faces = 100000;
};

/// A simplification of `mesh` to about `target_faces` faces (topology preserved).
/// \pre mesh is a manifold disk or closed genus-0 surface; target_faces >= 8.
/// \throw AlgorithmError if CGAL cannot build or simplify the surface.
TriMesh simplify_to_faces(const TriMesh& mesh, int target_faces, const SimplifyOptions& options = {});

namespace detail {
/// The two-halves path of simplify_to_faces, exposed for tests: its result, or nothing when
/// the halves do not stitch back into the same closed surface (repeated positions on the cut,
/// or a zero-length edge that CGAL collapses before asking the placement).
/// \pre mesh is a closed manifold surface with one component.
std::optional<TriMesh> simplify_in_halves(const TriMesh& mesh, int target_faces);
}  // namespace detail

}  // namespace mrsnake
