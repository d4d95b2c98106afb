#pragma once
// Semi-regular test hierarchies with positions from smooth analytic surfaces.
#include <cmath>
#include <random>

#include "mesh/primitives.h"
#include "mesh/subdivision.h"

namespace mrsnake::test {

struct Hierarchy {
  SubdivisionConnectivity conn;
  RowMatrixX3d finest;  ///< S_L
  std::string name;
};

/// Unit directions of the subdivided icosahedron (every level projected on the sphere).
inline RowMatrixX3d sphere_directions(const SubdivisionConnectivity& conn, const RowMatrixX3d& base) {
  RowMatrixX3d V = base;
  V.rowwise().normalize();
  for (int j = 0; j < conn.levels(); ++j) {
    V = midpoint_refine(conn, j, V);
    V.rowwise().normalize();
  }
  return V;
}

/// A star-shaped closed surface r(u)·u, smooth bumps on a sphere of radius 10 mm.
inline Eigen::RowVector3d bumpy(const Eigen::RowVector3d& u) {
  const double r = 10.0 * (1.0 + 0.12 * u.x() * u.y() + 0.08 * std::sin(2.0 * u.z()) + 0.05 * u.x() * u.x());
  return r * u + Eigen::RowVector3d(3.0, -2.0, 5.0);
}

inline Hierarchy bumpy_sphere(int levels) {
  const TriMesh ico = icosahedron();
  Hierarchy h{subdivide_connectivity(ico.F, 12, levels), {}, "bumpy sphere"};
  const RowMatrixX3d U = sphere_directions(h.conn, ico.V);
  h.finest.resize(U.rows(), 3);
  for (int v = 0; v < U.rows(); ++v) h.finest.row(v) = bumpy(U.row(v));
  return h;
}

inline Hierarchy ellipsoid(int levels) {
  const TriMesh ico = icosahedron();
  Hierarchy h{subdivide_connectivity(ico.F, 12, levels), {}, "ellipsoid"};
  h.finest = sphere_directions(h.conn, ico.V) * Eigen::Vector3d(40.0, 25.0, 15.0).asDiagonal();
  return h;
}

/// A disk: the icosahedron without the five faces around vertex 3 (a cap with five
/// valence-5 interior vertices and a boundary loop of five vertices), on the bumpy surface.
inline Hierarchy bumpy_cap(int levels) {
  const TriMesh ico = icosahedron();
  std::vector<int> keep;
  for (int f = 0; f < ico.num_faces(); ++f)
    if (ico.F(f, 0) != 3 && ico.F(f, 1) != 3 && ico.F(f, 2) != 3) keep.push_back(f);
  // Renumber vertices 0..10 (vertex 3 dropped).
  RowMatrixX3i F(static_cast<int>(keep.size()), 3);
  for (std::size_t i = 0; i < keep.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const int v = ico.F(keep[i], k);
      F(static_cast<int>(i), k) = v > 3 ? v - 1 : v;
    }
  RowMatrixX3d V0(11, 3);
  for (int v = 0, r = 0; v < 12; ++v)
    if (v != 3) V0.row(r++) = ico.V.row(v);
  Hierarchy h{subdivide_connectivity(F, 11, levels), {}, "bumpy cap (disk)"};
  const RowMatrixX3d U = sphere_directions(h.conn, V0);
  h.finest.resize(U.rows(), 3);
  for (int v = 0; v < U.rows(); ++v) h.finest.row(v) = bumpy(U.row(v));
  return h;
}

/// A disk: a fan of k triangles around a center, refined in the plane and lifted to a
/// smooth height field z = f(x, y).
inline Hierarchy height_field_fan(int k, int levels) {
  RowMatrixX3d V0(k + 1, 3);
  V0.row(0).setZero();
  RowMatrixX3i F(k, 3);
  for (int i = 0; i < k; ++i) {
    const double t = 2.0 * M_PI * i / k;
    V0.row(i + 1) << 20.0 * std::cos(t), 20.0 * std::sin(t), 0.0;
    F.row(i) << 0, i + 1, (i + 1) % k + 1;
  }
  Hierarchy h{subdivide_connectivity(F, k + 1, levels), {}, "height-field fan (disk)"};
  RowMatrixX3d V = V0;
  for (int j = 0; j < levels; ++j) V = midpoint_refine(h.conn, j, V);
  for (int v = 0; v < V.rows(); ++v) {
    const double x = V(v, 0) / 20.0, y = V(v, 1) / 20.0;
    V(v, 2) = 6.0 * std::cos(1.3 * x + 0.4) * std::sin(0.9 * y + 0.2) + 2.0 * x * x;
  }
  h.finest = V;
  return h;
}

/// Every test hierarchy above.
inline std::vector<Hierarchy> all_hierarchies(int levels) {
  return {bumpy_sphere(levels), ellipsoid(levels), bumpy_cap(levels), height_field_fan(6, levels),
          height_field_fan(5, levels)};
}

inline double max_row_distance(const RowMatrixX3d& A, const RowMatrixX3d& B) {
  return (A - B).rowwise().norm().maxCoeff();
}

}  // namespace mrsnake::test
