#pragma once
/// \file subdivision.h
/// The connectivity of a semi-regular hierarchy, kept apart from its geometry
/// (geometry-central style). Level j's vertices are the prefix [0, n_j) of level j+1's
/// (libigl style), and every vertex added at level j+1 records the edge of level j it splits.
#include <vector>

#include "mesh/trimesh.h"

namespace mrsnake {

/// Connectivity of levels 0..L of a 1:4 subdivision of a base mesh.
///
/// Numbering is deterministic: the new vertices of level j+1 are numbered n_j, n_j+1, ...
/// in the order their edges are first met when walking the faces of level j in order and,
/// in each face (a,b,c), the edges (a,b), (b,c), (c,a). Face f of level j has the four
/// children 4f..4f+3 at level j+1: (a,ab,ca), (ab,b,bc), (ca,bc,c), (ab,bc,ca).
struct SubdivisionConnectivity {
  std::vector<RowMatrixX3i> faces;  ///< faces[j]: the faces of level j
  std::vector<int> vertex_counts;   ///< vertex_counts[j] = n_j
  /// Row v - n_0 holds the two level-(j) vertices of the edge that vertex v (n_0 <= v < n_L)
  /// splits, where j+1 is the level that adds v.
  RowMatrixX2i parent_edges;

  int levels() const { return static_cast<int>(faces.size()) - 1; }
  int vertex_count(int level) const { return vertex_counts[level]; }
  /// The level that first has vertex v (0 for base vertices).
  int level_of_vertex(int v) const;
  /// The two parents of vertex v, which must not be a base vertex.
  Eigen::Vector2i parents(int v) const { return parent_edges.row(v - vertex_counts[0]).transpose(); }
};

/// Builds the connectivity of `levels` 1:4 splits of the base faces F0 on n0 vertices.
/// \pre F0 references only vertices in [0, n0); levels >= 0.
/// \throw TopologyError if an edge of F0 is shared by more than two faces.
SubdivisionConnectivity subdivide_connectivity(const RowMatrixX3i& F0, int n0, int levels);

/// Positions of level j+1's new vertices at the midpoints of their parent edges; the first
/// n_j rows are copied from V_j. This is the linear (unrelaxed) refinement.
/// \pre V_j has n_j rows.
RowMatrixX3d midpoint_refine(const SubdivisionConnectivity& conn, int level, const RowMatrixX3d& V_j);

}  // namespace mrsnake
