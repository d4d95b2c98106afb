#include "mesh/primitives.h"

#include <cmath>

namespace mrsnake {

TriMesh icosahedron(double radius) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  TriMesh m;
  m.V.resize(12, 3);
  m.V << -1, t, 0, 1, t, 0, -1, -t, 0, 1, -t, 0,  //
      0, -1, t, 0, 1, t, 0, -1, -t, 0, 1, -t,     //
      t, 0, -1, t, 0, 1, -t, 0, -1, -t, 0, 1;
  m.V *= radius / std::sqrt(1.0 + t * t);
  m.F.resize(20, 3);
  m.F << 0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11,  //
      1, 5, 9, 5, 11, 4, 11, 10, 2, 10, 7, 6, 7, 1, 8,     //
      3, 9, 4, 3, 4, 2, 3, 2, 6, 3, 6, 8, 3, 8, 9,         //
      4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6, 7, 9, 8, 1;
  return m;
}

TriMesh icosphere(int levels, double radius) {
  const TriMesh base = icosahedron(radius);
  const SubdivisionConnectivity conn = subdivide_connectivity(base.F, base.num_vertices(), levels);
  RowMatrixX3d V = base.V;
  for (int j = 0; j < levels; ++j) {
    V = midpoint_refine(conn, j, V);
    V.rowwise().normalize();
    V *= radius;
  }
  return TriMesh{V, conn.faces.back()};
}

}  // namespace mrsnake
