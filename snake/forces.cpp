#include "snake/forces.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace mrsnake {

Eigen::MatrixXf sample_profiles(const VolumeSampler& image, const RowMatrixX3d& V, const RowMatrixX3d& N, int half,
                                double spacing_mm) {
  const int K = 2 * half + 1;
  Eigen::MatrixXf P(V.rows(), K);
  for (int v = 0; v < V.rows(); ++v) {
    const Eigen::Vector3d x = V.row(v), n = N.row(v);
    for (int k = 0; k < K; ++k) P(v, k) = image.value(x + ((k - half) * spacing_mm) * n);
  }
  return P;
}

namespace {
// Parabolic refinement of the minimum at index i of costs c (uniform spacing h).
double refine(const std::vector<double>& c, int i, double h) {
  if (i <= 0 || i + 1 >= static_cast<int>(c.size())) return 0.0;
  const double a = c[i - 1], b = c[i], d = c[i + 1];
  const double denom = a - 2 * b + d;
  if (!(denom > 0)) return 0.0;
  return std::clamp(0.5 * (a - d) / denom, -0.5, 0.5) * h;
}

// The candidate of least cost among costs[0..2·nc] (all computed for this vertex), ties
// resolved towards the centre nc; a move wins over staying (nc) only if it is cheaper by
// more than min_gain, on either side alike.
int best_candidate(const std::vector<double>& cost, int nc, double min_gain) {
  int best = nc;
  for (int c = 0; c <= 2 * nc; ++c)
    if (cost[c] < cost[best] || (cost[c] == cost[best] && std::abs(c - nc) < std::abs(best - nc))) best = c;
  return cost[best] < cost[nc] - min_gain ? best : nc;
}

// Row v: vertex v's costs of the candidates −nc..nc (row-major: the ring mixing reads whole rows).
using CostMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Per vertex, the best candidate of its cost curve (row v of `cost`, candidates −nc..nc at
// spacing h), refined by a parabola; see NormalSearchOptions::ring_weight for the mixing with
// the ring's curves first.
SearchResult pick_offsets(const CostMatrix& cost, int nc, double h, const NormalSearchOptions& options) {
  const int n = static_cast<int>(cost.rows());
  const int C = static_cast<int>(cost.cols());
  const VertexRings* rings = options.rings;
  const bool mix = rings != nullptr && options.ring_weight > 0 && rings->num_vertices() == n && C > 0;
  SearchResult r;
  r.offsets.setZero(n);
  r.costs.setZero(n);
  std::vector<double> curve(static_cast<std::size_t>(C));
  for (int v = 0; v < n; ++v) {
    for (int c = 0; c < C; ++c) curve[c] = cost(v, c);
    const int valence = mix ? rings->valence(v) : 0;
    if (valence > 0) {
      // A sharp match of its own (low cost) keeps the vertex on its own evidence.
      const double own_best = *std::min_element(curve.begin(), curve.end());
      const double scale =
          options.ring_full_weight_cost > 0 ? std::min(1.0, own_best / options.ring_full_weight_cost) : 1.0;
      const double w = std::clamp(options.ring_weight * scale, 0.0, 1.0);
      if (w > 0) {
        for (double& c : curve) c *= 1.0 - w;
        for (int k = rings->offsets[v]; k < rings->offsets[v + 1]; ++k)
          for (int c = 0; c < C; ++c) curve[c] += (w / valence) * cost(rings->neighbors[k], c);
      }
    }
    const int best = best_candidate(curve, nc, options.min_gain);
    r.offsets[v] = curve[best] <= options.max_cost ? (best - nc) * h + refine(curve, best, h) : 0.0;
    r.costs[v] = curve[best];
  }
  return r;
}
}  // namespace

SearchResult search_step_edges(const VolumeSampler& image, const RowMatrixX3d& V, const RowMatrixX3d& N,
                               const RegionStats& stats, const NormalSearchOptions& options) {
  const double h = options.step_mm;
  const int nc = std::max(0, static_cast<int>(std::floor(options.range_mm / h)));   // candidates −nc..nc
  const int w = std::max(1, static_cast<int>(std::lround(options.window_mm / h)));  // samples per side
  const int ns = 2 * (nc + w);  // samples at offsets (s − nc − w + 0.5)·h, s = 0..ns−1
  const double contrast2 = std::max(1e-12, (stats.inside - stats.outside) * (stats.inside - stats.outside));
  const double norm = 1.0 / (2.0 * w * contrast2);
  CostMatrix cost(V.rows(), 2 * nc + 1);
  std::vector<double> in_prefix(ns + 1), out_prefix(ns + 1), samples(ns);
  for (int v = 0; v < V.rows(); ++v) {
    const Eigen::Vector3d x = V.row(v), n = N.row(v);
    image.values_along(x, n, (-nc - w + 0.5) * h, h, ns, samples.data());
    in_prefix[0] = out_prefix[0] = 0;
    for (int s = 0; s < ns; ++s) {
      const double I = samples[s];
      in_prefix[s + 1] = in_prefix[s] + (I - stats.inside) * (I - stats.inside);
      out_prefix[s + 1] = out_prefix[s] + (I - stats.outside) * (I - stats.outside);
    }
    for (int c = 0; c <= 2 * nc; ++c) {
      // Candidate boundary at offset (c − nc)·h lies between samples c + w − 1 and c + w.
      const int mid = c + w;
      const double misfit = (in_prefix[mid] - in_prefix[mid - w]) + (out_prefix[mid + w] - out_prefix[mid]);
      const double t = (c - nc) * h;
      const double rel = options.range_mm > 0 ? t / options.range_mm : 0.0;
      cost(v, c) = misfit * norm + options.distance_penalty * rel * rel;
    }
  }
  return pick_offsets(cost, nc, h, options);
}

SearchResult search_profiles(const VolumeSampler& image, const RowMatrixX3d& V, const RowMatrixX3d& N,
                             const Eigen::MatrixXf& profiles, double profile_spacing_mm,
                             const NormalSearchOptions& options) {
  const int K = static_cast<int>(profiles.cols());
  const int half = K / 2;
  // Samples and candidates on a grid `sub` times finer than the profile spacing: the
  // profile's k-th sample of candidate c is sample c + sub·k.
  const int sub = std::max(1, static_cast<int>(std::lround(profile_spacing_mm / options.step_mm)));
  const double h = profile_spacing_mm / sub;
  const int nc = std::max(0, static_cast<int>(std::floor(options.range_mm / h)));
  const int ns = 2 * nc + sub * (K - 1) + 1;  // samples at offsets (s − nc − sub·half)·h
  // A flat learned profile carries no information: no boundary seen (cost 1, above the
  // usual max_cost, so it stays put unless its ring's evidence says where to go).
  CostMatrix cost = CostMatrix::Ones(V.rows(), 2 * nc + 1);
  std::vector<double> samples(ns), model(K);
  for (int v = 0; v < V.rows(); ++v) {
    // The learned profile, centred and scaled to unit norm.
    double mean = 0;
    for (int k = 0; k < K; ++k) mean += profiles(v, k);
    mean /= K;
    double norm2 = 0;
    for (int k = 0; k < K; ++k) {
      model[k] = profiles(v, k) - mean;
      norm2 += model[k] * model[k];
    }
    if (!(norm2 > 1e-12)) continue;
    const double inv = 1.0 / std::sqrt(norm2);
    for (double& m : model) m *= inv;
    const Eigen::Vector3d x = V.row(v), n = N.row(v);
    image.values_along(x, n, (-nc - sub * half) * h, h, ns, samples.data());
    for (int c = 0; c <= 2 * nc; ++c) {
      double sum = 0, sum2 = 0, dot = 0;
      for (int k = 0; k < K; ++k) {
        const double y = samples[c + sub * k];
        sum += y;
        sum2 += y * y;
        dot += y * model[k];  // model is centred, so the mean of y drops out
      }
      const double var = sum2 - sum * sum / K;
      const double ncc = var > 1e-12 ? dot / std::sqrt(var) : 0.0;
      const double t = (c - nc) * h;
      const double rel = options.range_mm > 0 ? t / options.range_mm : 0.0;
      cost(v, c) = (1.0 - ncc) + options.distance_penalty * rel * rel;
    }
  }
  return pick_offsets(cost, nc, h, options);
}

RegionStats estimate_region_stats(const VolumeSampler& image, const RowMatrixX3d& V, const RowMatrixX3d& N,
                                  double depth_mm, double step_mm) {
  std::vector<float> in, out;
  const int steps = std::max(1, static_cast<int>(std::floor(depth_mm / step_mm)));
  in.reserve(static_cast<std::size_t>(V.rows()) * steps);
  out.reserve(static_cast<std::size_t>(V.rows()) * steps);
  for (int v = 0; v < V.rows(); ++v) {
    const Eigen::Vector3d x = V.row(v), n = N.row(v);
    for (int s = 1; s <= steps; ++s) {
      in.push_back(image.value(x - (s * step_mm) * n));
      out.push_back(image.value(x + (s * step_mm) * n));
    }
  }
  const auto median = [](std::vector<float>& a) {
    if (a.empty()) return 0.0;
    std::nth_element(a.begin(), a.begin() + static_cast<long>(a.size() / 2), a.end());
    return static_cast<double>(a[a.size() / 2]);
  };
  RegionStats s;
  s.inside = median(in);
  s.outside = median(out);
  return s;
}

}  // namespace mrsnake
