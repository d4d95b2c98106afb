#pragma once
/// \file vertex_stars.h
/// The faces around each vertex of a triangle list, in compressed rows (one flat array and
/// offsets), for the loops over a vertex's star that remeshing and topology checks run.
#include <vector>

#include "mesh/trimesh.h"

namespace mrsnake {

/// The faces around each vertex, in compressed rows: faces offset[v] … offset[v + 1] − 1 of
/// `faces` hold vertex v, in increasing face order.
struct VertexStars {
  std::vector<int> offset, faces;

  /// \pre every entry of F is in [0, n).
  VertexStars(const RowMatrixX3i& F, int n) : offset(n + 1, 0) {
    for (int f = 0; f < F.rows(); ++f)
      for (int k = 0; k < 3; ++k) ++offset[F(f, k) + 1];
    for (int v = 0; v < n; ++v) offset[v + 1] += offset[v];
    faces.resize(offset[n]);
    std::vector<int> fill(offset.begin(), offset.end() - 1);
    for (int f = 0; f < F.rows(); ++f)
      for (int k = 0; k < 3; ++k) faces[fill[F(f, k)]++] = f;
  }
};

}  // namespace mrsnake
