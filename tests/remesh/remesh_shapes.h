#pragma once
// Small analytic inputs shared by the remesher's tests: a closed genus-0 surface with uneven
// stretch, and a disk.
#include <vector>

#include "mesh/primitives.h"
#include "mesh/topology.h"
#include "mesh/trimesh.h"

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

}  // namespace mrsnake::test
