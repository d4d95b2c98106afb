#include "snake/surface_geometry.h"

#include <algorithm>

namespace mrsnake {

VertexRings build_vertex_rings(const RowMatrixX3i& F, int n) {
  std::vector<std::vector<int>> adj(static_cast<std::size_t>(n));
  for (int f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      const int a = F(f, c), b = F(f, (c + 1) % 3);
      adj[a].push_back(b);
      adj[b].push_back(a);
    }
  VertexRings rings;
  rings.offsets.resize(static_cast<std::size_t>(n) + 1, 0);
  for (int v = 0; v < n; ++v) {
    auto& a = adj[v];
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
    rings.offsets[v + 1] = rings.offsets[v] + static_cast<int>(a.size());
  }
  rings.neighbors.reserve(static_cast<std::size_t>(rings.offsets[n]));
  for (int v = 0; v < n; ++v) rings.neighbors.insert(rings.neighbors.end(), adj[v].begin(), adj[v].end());
  return rings;
}

void umbrella(const VertexRings& rings, const RowMatrixX3d& V, RowMatrixX3d& U) {
  const int n = rings.num_vertices();
  U.resize(n, 3);
  for (int v = 0; v < n; ++v) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int k = rings.offsets[v]; k < rings.offsets[v + 1]; ++k) sum += V.row(rings.neighbors[k]).transpose();
    const int val = rings.valence(v);
    U.row(v) = val > 0 ? Eigen::Vector3d(sum / val - V.row(v).transpose()) : Eigen::Vector3d::Zero();
  }
}

void ring_edge_lengths(const VertexRings& rings, const RowMatrixX3d& V, Eigen::VectorXd& lengths) {
  const int n = rings.num_vertices();
  lengths.resize(n);
  for (int v = 0; v < n; ++v) {
    double sum = 0;
    for (int k = rings.offsets[v]; k < rings.offsets[v + 1]; ++k) sum += (V.row(rings.neighbors[k]) - V.row(v)).norm();
    const int val = rings.valence(v);
    lengths[v] = val > 0 ? sum / val : 0.0;
  }
}

void smooth_on_rings(const VertexRings& rings, Eigen::VectorXd& values, int passes) {
  Eigen::VectorXd tmp(values.size());
  for (int p = 0; p < passes; ++p) {
    for (int v = 0; v < rings.num_vertices(); ++v) {
      double sum = values[v];
      for (int k = rings.offsets[v]; k < rings.offsets[v + 1]; ++k) sum += values[rings.neighbors[k]];
      tmp[v] = sum / (rings.valence(v) + 1);
    }
    values.swap(tmp);
  }
}

void median_on_rings(const VertexRings& rings, Eigen::VectorXd& values, int passes) {
  Eigen::VectorXd tmp(values.size());
  std::vector<double> window;
  for (int p = 0; p < passes; ++p) {
    for (int v = 0; v < rings.num_vertices(); ++v) {
      window.assign(1, values[v]);
      for (int k = rings.offsets[v]; k < rings.offsets[v + 1]; ++k) {  // insertion sort: rings are small
        const double x = values[rings.neighbors[k]];
        window.push_back(x);
        std::size_t i = window.size() - 1;
        for (; i > 0 && window[i - 1] > x; --i) window[i] = window[i - 1];
        window[i] = x;
      }
      const std::size_t mid = window.size() / 2;
      // An even window takes the mean of its two middle values.
      tmp[v] = window.size() % 2 ? window[mid] : 0.5 * (window[mid - 1] + window[mid]);
    }
    values.swap(tmp);
  }
}

}  // namespace mrsnake
