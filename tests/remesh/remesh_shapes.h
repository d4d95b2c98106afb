#pragma once
// Small analytic inputs shared by the remesher's tests: a closed genus-0 surface with uneven
// stretch, a disk, and a sheared layout of the sphere D.
#include <vector>

#include "mesh/primitives.h"
#include "mesh/topology.h"
#include "mesh/trimesh.h"
#include "remesh/domain.h"
#include "remesh/lift.h"
#include "remesh/parameterization.h"

namespace mrsnake::test {

// An ellipsoid with semi-axes 3, 1.5, 1 (stretches the sphere unevenly).
inline TriMesh ellipsoid(int levels) {
  TriMesh m = icosphere(levels);
  m.V.col(0) *= 3.0;
  m.V.col(1) *= 1.5;
  return m;
}

// A disk: the part of an icosphere with z < 0.3, slightly flattened.
inline TriMesh spherical_cap(int levels) {
  const TriMesh s = icosphere(levels);
  std::vector<int> faces;
  for (int f = 0; f < s.num_faces(); ++f) {
    const double z = (s.V(s.F(f, 0), 2) + s.V(s.F(f, 1), 2) + s.V(s.F(f, 2), 2)) / 3;
    if (z < 0.3) faces.push_back(f);
  }
  TriMesh cap = extract_faces(s, faces);
  cap.V.col(0) *= 2.0;
  return cap;
}

// U with 10 vertices pushed 80% of the way toward a neighbour in (U, F) (sliver triangles);
// only pushes that flip nothing in D are kept.
inline RowMatrixX3d sheared_layout(RowMatrixX3d U, const RowMatrixX3i& F) {
  for (int f = 0; f < 300 && f < F.rows(); f += 30) {
    const int v = F(f, 0), w = F(f, 1);
    const Eigen::RowVector3d before = U.row(v);
    U.row(v) = (0.2 * U.row(v) + 0.8 * U.row(w)).normalized();
    if (count_flipped(U, F) > 0) U.row(v) = before;
  }
  return U;
}

// The ellipsoid(4) parameterized onto the sphere D, and a level laid out on it: the vertices
// of icosphere(grid_levels) on the unit sphere (sheared: see sheared_layout), lifted.
struct EllipsoidLayout {
  explicit EllipsoidLayout(int grid_levels = 3, bool sheared = false)
      : grid(icosphere(grid_levels)),
        U(sheared ? sheared_layout(grid.V.rowwise().normalized(), grid.F) : RowMatrixX3d(grid.V.rowwise().normalized())),
        hints(U.rows(), 0),
        X(lift_to_surface(domain, param.surface.V, U, hints)) {}
  TriMesh input = ellipsoid(4);
  Parameterization param = parameterize(input);
  DomainMesh domain{param.domain, param.surface.F};
  TriMesh grid;
  RowMatrixX3d U;
  std::vector<int> hints;
  RowMatrixX3d X;
};

}  // namespace mrsnake::test
