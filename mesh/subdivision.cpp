#include "mesh/subdivision.h"

#include <algorithm>
#include <unordered_map>

#include "mesh/errors.h"

namespace mrsnake {
namespace {

std::uint64_t edge_key(int a, int b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint32_t>(b);
}

}  // namespace

int SubdivisionConnectivity::level_of_vertex(int v) const {
  const auto it = std::upper_bound(vertex_counts.begin(), vertex_counts.end(), v);
  return static_cast<int>(it - vertex_counts.begin());
}

SubdivisionConnectivity subdivide_connectivity(const RowMatrixX3i& F0, int n0, int levels) {
  SubdivisionConnectivity conn;
  conn.faces.push_back(F0);
  conn.vertex_counts.push_back(n0);
  std::vector<Eigen::Vector2i> parents;
  for (int j = 0; j < levels; ++j) {
    const RowMatrixX3i& F = conn.faces.back();
    int next = conn.vertex_counts.back();
    std::unordered_map<std::uint64_t, int> midpoint;
    std::unordered_map<std::uint64_t, int> uses;
    midpoint.reserve(F.rows() * 2);
    RowMatrixX3i children(4 * F.rows(), 3);
    for (int f = 0; f < F.rows(); ++f) {
      int mid[3];
      for (int e = 0; e < 3; ++e) {
        const int a = F(f, e), b = F(f, (e + 1) % 3);
        const auto key = edge_key(a, b);
        if (++uses[key] > 2)
          throw TopologyError("edge (" + std::to_string(a) + ", " + std::to_string(b) +
                              ") of the base mesh is shared by more than two faces; repair the mesh first");
        const auto [it, inserted] = midpoint.try_emplace(key, next);
        if (inserted) {
          parents.emplace_back(a, b);
          ++next;
        }
        mid[e] = it->second;
      }
      const int a = F(f, 0), b = F(f, 1), c = F(f, 2);
      const int ab = mid[0], bc = mid[1], ca = mid[2];
      children.row(4 * f + 0) << a, ab, ca;
      children.row(4 * f + 1) << ab, b, bc;
      children.row(4 * f + 2) << ca, bc, c;
      children.row(4 * f + 3) << ab, bc, ca;
    }
    conn.faces.push_back(std::move(children));
    conn.vertex_counts.push_back(next);
  }
  conn.parent_edges.resize(static_cast<Eigen::Index>(parents.size()), 2);
  for (std::size_t i = 0; i < parents.size(); ++i)
    conn.parent_edges.row(static_cast<Eigen::Index>(i)) = parents[i].transpose();
  return conn;
}

RowMatrixX3d midpoint_refine(const SubdivisionConnectivity& conn, int level, const RowMatrixX3d& V_j) {
  const int n_j = conn.vertex_counts[level];
  const int n_next = conn.vertex_counts[level + 1];
  RowMatrixX3d V(n_next, 3);
  V.topRows(n_j) = V_j.topRows(n_j);
  for (int v = n_j; v < n_next; ++v) {
    const Eigen::Vector2i p = conn.parents(v);
    V.row(v) = 0.5 * (V_j.row(p[0]) + V_j.row(p[1]));
  }
  return V;
}

}  // namespace mrsnake
