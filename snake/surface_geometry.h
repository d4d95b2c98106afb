#pragma once
/// \file surface_geometry.h
/// Per-vertex geometry on a fixed connectivity: 1-rings built once per level (CSR),
/// umbrella vectors and local edge lengths. Plain loops, no allocation
/// in the per-iteration calls.
#include <vector>

#include "mesh/normals.h"  // face_normals, vertex_normals
#include "mesh/trimesh.h"

namespace mrsnake {

/// The 1-ring of every vertex of a fixed connectivity, in compressed rows.
struct VertexRings {
  std::vector<int> offsets;  ///< ring of v: neighbors[offsets[v] .. offsets[v+1])
  std::vector<int> neighbors;
  int num_vertices() const { return static_cast<int>(offsets.size()) - 1; }
  int valence(int v) const { return offsets[v + 1] - offsets[v]; }
};

/// Builds the rings of the n vertices of F (each neighbour listed once).
/// \pre F references only vertices in [0, n).
VertexRings build_vertex_rings(const RowMatrixX3i& F, int n);

/// Umbrella vectors U_v = mean of the ring − x_v.
void umbrella(const VertexRings& rings, const RowMatrixX3d& V, RowMatrixX3d& U);

/// Mean length of the edges from each vertex to its ring.
void ring_edge_lengths(const VertexRings& rings, const RowMatrixX3d& V, Eigen::VectorXd& lengths);

/// Replaces each value by the mean over the vertex and its ring, `passes` times.
void smooth_on_rings(const VertexRings& rings, Eigen::VectorXd& values, int passes);

/// Replaces each value by the median over the vertex and its ring, `passes` times (an
/// outlier among its neighbours, e.g. a false profile match, does not move a vertex).
/// \pre values has one entry per vertex of rings.
void median_on_rings(const VertexRings& rings, Eigen::VectorXd& values, int passes);

}  // namespace mrsnake
