#include "tests/support/shrink_wrap.h"

#include "mesh/distance.h"
#include "mesh/errors.h"
#include "mesh/primitives.h"
#include "snake/surface_geometry.h"

namespace mrsnake {

ShrinkWrapResult shrink_wrap(const TriMesh& target, const ShrinkWrapOptions& options) {
  if (target.empty()) throw InputError("cannot shrink-wrap an empty surface");
  const SurfaceLocator locator(target);
  const Eigen::RowVector3d centre = target.V.colwise().mean();
  const double radius = (target.V.rowwise() - centre).rowwise().norm().maxCoeff();
  const TriMesh ico = icosahedron(1.1 * radius);
  ShrinkWrapResult r;
  r.connectivity = subdivide_connectivity(ico.F, ico.num_vertices(), options.levels);
  RowMatrixX3d V = ico.V.rowwise() + centre;
  RowMatrixX3d N, U;
  for (int j = 0; j <= options.levels; ++j) {
    if (j > 0) V = midpoint_refine(r.connectivity, j - 1, V);
    const RowMatrixX3i& F = r.connectivity.faces[j];
    const VertexRings rings = build_vertex_rings(F, static_cast<int>(V.rows()));
    const int iterations = options.iterations_per_level * (j == options.levels ? 2 : 1);
    for (int it = 0; it < iterations; ++it) {
      vertex_normals(V, F, N);
      umbrella(rings, V, U);
      for (int v = 0; v < V.rows(); ++v) {
        const Eigen::Vector3d x = V.row(v), n = N.row(v), u = U.row(v);
        const Eigen::Vector3d p = locator.closest(x).point;
        V.row(v) = (x + options.attraction * (p - x) + options.relaxation * (u - u.dot(n) * n)).transpose();
      }
    }
  }
  // End exactly on the surface.
  for (int v = 0; v < V.rows(); ++v) V.row(v) = locator.closest(V.row(v).transpose()).point.transpose();
  // How well the wrap covers the target: distances from the target's vertices to it.
  const SurfaceLocator wrapped(TriMesh{V, r.connectivity.faces.back()});
  const Eigen::VectorXd d = wrapped.distances(target.V);
  r.mean_distance_mm = d.mean();
  r.max_distance_mm = d.maxCoeff();
  r.finest = V;
  return r;
}

}  // namespace mrsnake
