#include "snake/surface_geometry.h"

#include <algorithm>

namespace mrsnake {

VertexRings build_vertex_rings(const RowMatrixX3i& F, int n) {
  // Each face lists its other two corners at each corner (an interior edge twice), in one
  // flat array bucketed by vertex; each bucket is then sorted, deduplicated and compacted.
  std::vector<int> start(static_cast<std::size_t>(n) + 1, 0);
  for (int f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c) start[F(f, c) + 1] += 2;
  for (int v = 0; v < n; ++v) start[v + 1] += start[v];
  std::vector<int> listed(static_cast<std::size_t>(start[n])), fill(start.begin(), start.end() - 1);
  for (int f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      const int v = F(f, c);
      listed[fill[v]++] = F(f, (c + 1) % 3);
      listed[fill[v]++] = F(f, (c + 2) % 3);
    }
  VertexRings rings;
  rings.offsets.resize(static_cast<std::size_t>(n) + 1, 0);
  rings.neighbors.reserve(listed.size() / 2);
  for (int v = 0; v < n; ++v) {
    const auto begin = listed.begin() + start[v], end = listed.begin() + start[v + 1];
    std::sort(begin, end);
    rings.neighbors.insert(rings.neighbors.end(), begin, std::unique(begin, end));
    rings.offsets[v + 1] = static_cast<int>(rings.neighbors.size());
  }
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

namespace {
// The m-th smallest of w[0..n−1] (0-based) by counting ranks: the counting has no branch on
// the values, whose comparisons a sort of a 7-value ring mispredicts at almost every step.
double order_statistic(const double* w, int n, int m) {
  for (int i = 0; i < n; ++i) {
    int less = 0, less_or_equal = 0;
    for (int j = 0; j < n; ++j) {
      less += w[j] < w[i];
      less_or_equal += w[j] <= w[i];
    }
    if (less <= m && m < less_or_equal) return w[i];
  }
  return w[0];  // only with a NaN among the values: keep the vertex's own
}
}  // namespace

void median_on_rings(const VertexRings& rings, Eigen::VectorXd& values, int passes) {
  Eigen::VectorXd tmp(values.size());
  std::vector<double> window;
  for (int p = 0; p < passes; ++p) {
    for (int v = 0; v < rings.num_vertices(); ++v) {
      window.assign(1, values[v]);
      for (int k = rings.offsets[v]; k < rings.offsets[v + 1]; ++k) window.push_back(values[rings.neighbors[k]]);
      const int n = static_cast<int>(window.size()), mid = n / 2;
      // An even window takes the mean of its two middle values.
      tmp[v] = n % 2 ? order_statistic(window.data(), n, mid)
                     : 0.5 * (order_statistic(window.data(), n, mid - 1) + order_statistic(window.data(), n, mid));
    }
    values.swap(tmp);
  }
}

}  // namespace mrsnake
