#pragma once
// Small analytic inputs shared by the remesher's tests: a closed genus-0 surface with uneven
// stretch, disks (a cap, a flat grid), a capsule, and a sheared layout of the sphere D.
#include <cmath>
#include <utility>
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

// A flat square grid of n x n cells in z = 0, vertex (i, j) at index j·(n+1) + i, faces
// counter-clockwise seen from +z. `nudge` moves the interior vertices in the plane by up to that
// much (deterministically), so that no four vertices are cocircular.
inline TriMesh flat_grid(int n, double nudge = 0.0) {
  TriMesh m;
  m.V.resize((n + 1) * (n + 1), 3);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double d = i == 0 || j == 0 || i == n || j == n ? 0.0 : nudge;
      m.V.row(j * (n + 1) + i) << i + d * std::sin(1.7 * i + 0.3 * j), j + d * std::cos(0.9 * i - 1.3 * j), 0.0;
    }
  m.F.resize(2 * n * n, 3);
  for (int j = 0, f = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int v00 = j * (n + 1) + i, v10 = v00 + 1, v01 = v00 + n + 1, v11 = v01 + 1;
      m.F.row(f++) << v00, v10, v11;
      m.F.row(f++) << v00, v11, v01;
    }
  return m;
}

// A capsule along z: a tube of radius 1 and the given length with hemispherical caps, `around`
// vertices per ring, the tube's rings `ring_spacing` apart (0: as far as the ring's vertices,
// so that its triangles are about isosceles right). From a length of about 15, a one-chart
// conformal map squeezes its far end by more than 12 orders of magnitude in area.
inline TriMesh capsule(double length, int around = 16, double ring_spacing = 0.0) {
  const double pi = 3.14159265358979323846;
  std::vector<std::pair<double, double>> rings;  // (z, radius), bottom to top
  const int cap_rings = around / 4;
  for (int i = 1; i <= cap_rings; ++i)
    rings.emplace_back(-std::cos(0.5 * pi * i / cap_rings), std::sin(0.5 * pi * i / cap_rings));
  const int tube = static_cast<int>(std::lround(length / (ring_spacing > 0 ? ring_spacing : 2 * pi / around)));
  for (int j = 1; j <= tube; ++j) rings.emplace_back(length * j / tube, 1.0);
  for (int i = 1; i < cap_rings; ++i)
    rings.emplace_back(length + std::sin(0.5 * pi * i / cap_rings), std::cos(0.5 * pi * i / cap_rings));
  const int r = static_cast<int>(rings.size());
  TriMesh m;
  m.V.resize(r * around + 2, 3);
  for (int i = 0; i < r; ++i)
    for (int k = 0; k < around; ++k) {
      const double a = 2 * pi * k / around;
      m.V.row(i * around + k) << rings[i].second * std::cos(a), rings[i].second * std::sin(a), rings[i].first;
    }
  const int south = r * around, north = south + 1;
  m.V.row(south) << 0, 0, -1;
  m.V.row(north) << 0, 0, length + 1;
  std::vector<Eigen::RowVector3i> faces;
  for (int k = 0; k < around; ++k) {
    const int k1 = (k + 1) % around;
    faces.emplace_back(south, k1, k);
    for (int i = 0; i + 1 < r; ++i) {
      faces.emplace_back(i * around + k, i * around + k1, (i + 1) * around + k1);
      faces.emplace_back(i * around + k, (i + 1) * around + k1, (i + 1) * around + k);
    }
    faces.emplace_back((r - 1) * around + k, (r - 1) * around + k1, north);
  }
  m.F.resize(static_cast<int>(faces.size()), 3);
  for (std::size_t f = 0; f < faces.size(); ++f) m.F.row(static_cast<int>(f)) = faces[f];
  return m;
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
        U(sheared ? sheared_layout(grid.V.rowwise().normalized(), grid.F)
                  : RowMatrixX3d(grid.V.rowwise().normalized())),
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
