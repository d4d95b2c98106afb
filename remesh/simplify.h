#pragma once
/// \file simplify.h
/// Edge-collapse simplification (CGAL: shortest edge first, midpoint placement) of a fine input before it is
/// parameterized: a marching-cubes organ surface has hundreds of thousands of faces, far
/// more than a 16k-face model needs, and the parameterization's sparse solve dominates the
/// run time. Also CGAL's isotropic remeshing of an input made of slivers (a decimated mesh),
/// whose long triangles no chart of the base-mesh domain holds. The remeshed vertices are
/// projected back onto the original surface afterwards.
#include "mesh/trimesh.h"

namespace mrsnake {

/// A simplification of `mesh` to about `target_faces` faces (topology preserved), on two cores:
/// each simplifies one half, and the halves are stitched (one core's way if they do not fit).
/// \pre mesh is a manifold disk or closed genus-0 surface; target_faces >= 8.
/// \throw AlgorithmError if CGAL cannot build or simplify the surface.
TriMesh simplify_to_faces(const TriMesh& mesh, int target_faces);

/// CGAL's isotropic remeshing of `mesh` toward `edge_length` (splits, collapses, flips toward
/// valence 6, tangential relaxation), `iterations` rounds; a disk's rim is remeshed too.
/// \pre mesh is a manifold disk or closed genus-0 surface; edge_length > 0.
/// \throw AlgorithmError if CGAL cannot build the surface.
TriMesh remesh_isotropically(const TriMesh& mesh, double edge_length, int iterations);

namespace detail {
/// The two-halves way alone, exposed for tests.
/// \throw AlgorithmError if the surface cannot be built or the halves do not fit together.
TriMesh simplify_in_two_halves(const TriMesh& mesh, int target_faces);
}  // namespace detail

}  // namespace mrsnake
