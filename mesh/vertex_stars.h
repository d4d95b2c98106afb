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

/// The last face (in face order) of F holding the directed edge tail -> head, or -1: a scan of
/// tail's star. On a consistently oriented manifold, the face across an edge a -> b of one face
/// is face_with_directed_edge(stars, F, b, a).
/// \pre `stars` are F's vertex stars; tail is one of their vertices.
inline int face_with_directed_edge(const VertexStars& stars, const RowMatrixX3i& F, int tail, int head) {
  int face = -1;
  for (int i = stars.offset[tail]; i < stars.offset[tail + 1]; ++i) {
    const int f = stars.faces[i];
    for (int k = 0; k < 3; ++k)
      if (F(f, k) == tail && F(f, (k + 1) % 3) == head) face = f;
  }
  return face;
}

}  // namespace mrsnake
