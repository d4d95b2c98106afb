#include "remesh/base_lift.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "mesh/errors.h"

namespace mrsnake {
namespace {

using Corners2d = Eigen::Matrix<double, 2, 3>;

// How far below 0 a barycentric coordinate may be for a triangle to hold a point: rounding,
// which a point on a shared edge of two triangles meets in both.
constexpr double kInside = 1e-9;

// Below this ratio of |det| to the longer edge squared, a chart triangle is taken as
// degenerate: it holds no point and its inverse is not finite.
constexpr double kDegenerate = 1e-14;

// The cell index of coordinate x along an axis of n cells from `low`, clamped to the grid.
int cell_of(double x, double low, double inverse_cell, int n) {
  const double cell = std::floor((x - low) * inverse_cell);
  return static_cast<int>(std::clamp(cell, 0.0, static_cast<double>(n - 1)));
}

BaseLift::Hit clamped(BaseLift::Hit hit) {
  hit.bary = hit.bary.cwiseMax(0.0);
  hit.bary /= hit.bary.sum();
  return hit;
}

}  // namespace

BaseLift::BaseLift(const TriMesh& input, const BaseDomain& domain, std::vector<BasePoint> location)
    : V_(input.V), F_(input.F), domain_(&domain), location_(std::move(location)) {
  if (static_cast<int>(location_.size()) != input.num_vertices())
    throw std::invalid_argument("BaseLift: " + std::to_string(location_.size()) + " locations for " +
                                std::to_string(input.num_vertices()) + " vertices");
  const int charts = domain.base().num_vertices();
  std::vector<int> chart(F_.rows(), -1);
  std::vector<Corners2d> corners(F_.rows());
  for (int f = 0; f < F_.rows(); ++f) {
    const BasePoint points[3] = {location_[F_(f, 0)], location_[F_(f, 1)], location_[F_(f, 2)]};
    const int v = domain.common_chart(points, 3);
    if (v < 0) continue;
    for (int k = 0; k < 3; ++k) corners[f].col(k) = domain.to_chart(v, points[k]);
    const Eigen::Vector2d e1 = corners[f].col(1) - corners[f].col(0), e2 = corners[f].col(2) - corners[f].col(0);
    const double det = e1.x() * e2.y() - e1.y() * e2.x();
    if (std::abs(det) > kDegenerate * std::max(e1.squaredNorm(), e2.squaredNorm())) chart[f] = v;
  }
  // Counting sort by chart, so that each chart's triangles are one range.
  chart_offset_.assign(charts + 1, 0);
  for (int f = 0; f < F_.rows(); ++f) {
    if (chart[f] >= 0)
      ++chart_offset_[chart[f] + 1];
    else
      ++unmapped_;
  }
  for (int v = 0; v < charts; ++v) chart_offset_[v + 1] += chart_offset_[v];
  triangles_.resize(chart_offset_[charts]);
  std::vector<Corners2d> sorted(triangles_.size());
  std::vector<int> fill(chart_offset_.begin(), chart_offset_.end() - 1);
  for (int f = 0; f < F_.rows(); ++f) {
    if (chart[f] < 0) continue;
    const int t = fill[chart[f]]++;
    Eigen::Matrix2d edges;
    edges << corners[f].col(1) - corners[f].col(0), corners[f].col(2) - corners[f].col(0);
    triangles_[t] = {f, corners[f].col(0), edges.inverse()};
    sorted[t] = corners[f];
  }
  grid_.resize(charts);
  for (int v = 0; v < charts; ++v) build_grid(v, sorted);
}

void BaseLift::build_grid(int v, const std::vector<Corners2d>& corners) {
  const int begin = chart_offset_[v], end = chart_offset_[v + 1];
  if (begin == end) return;
  Grid& g = grid_[v];
  Eigen::Vector2d low = corners[begin].rowwise().minCoeff(), high = corners[begin].rowwise().maxCoeff();
  for (int t = begin; t < end; ++t) {
    low = low.cwiseMin(corners[t].rowwise().minCoeff());
    high = high.cwiseMax(corners[t].rowwise().maxCoeff());
  }
  // About one cell per triangle: a query tests a few triangles.
  g.nx = g.ny = std::max(1, static_cast<int>(std::ceil(std::sqrt(end - begin))));
  g.low = low;
  g.inverse_cell = Eigen::Vector2d(g.nx, g.ny).cwiseQuotient((high - low).cwiseMax(1e-300));
  const auto cells = [&](int t, auto&& visit) {
    const Eigen::Vector2d lo = corners[t].rowwise().minCoeff(), hi = corners[t].rowwise().maxCoeff();
    const int x0 = cell_of(lo.x(), g.low.x(), g.inverse_cell.x(), g.nx);
    const int x1 = cell_of(hi.x(), g.low.x(), g.inverse_cell.x(), g.nx);
    const int y0 = cell_of(lo.y(), g.low.y(), g.inverse_cell.y(), g.ny);
    const int y1 = cell_of(hi.y(), g.low.y(), g.inverse_cell.y(), g.ny);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) visit(y * g.nx + x);
  };
  g.offset.assign(g.nx * g.ny + 1, 0);
  for (int t = begin; t < end; ++t) cells(t, [&](int c) { ++g.offset[c + 1]; });
  for (int c = 0; c < g.nx * g.ny; ++c) g.offset[c + 1] += g.offset[c];
  g.items.resize(g.offset.back());
  std::vector<int> fill(g.offset.begin(), g.offset.end() - 1);
  for (int t = begin; t < end; ++t) cells(t, [&](int c) { g.items[fill[c]++] = t; });
}

void BaseLift::search_chart(int v, const Eigen::Vector2d& q, bool all, Hit& hit, double& best_min) const {
  const auto test = [&](int t) {
    const ChartTriangle& tri = triangles_[t];
    const Eigen::Vector2d b = tri.inverse * (q - tri.origin);
    const Eigen::Vector3d bary(1 - b.x() - b.y(), b.x(), b.y());
    const double smallest = bary.minCoeff();
    if (smallest > best_min) {
      best_min = smallest;
      hit = {tri.face, bary};
    }
  };
  if (all) {
    for (int t = chart_offset_[v]; t < chart_offset_[v + 1]; ++t) test(t);
    return;
  }
  const Grid& g = grid_[v];
  if (g.nx == 0) return;
  const int c =
      cell_of(q.y(), g.low.y(), g.inverse_cell.y(), g.ny) * g.nx + cell_of(q.x(), g.low.x(), g.inverse_cell.x(), g.nx);
  for (int i = g.offset[c]; i < g.offset[c + 1]; ++i) test(g.items[i]);
}

BaseLift::Hit BaseLift::locate(const BasePoint& p) const {
  Hit hit;
  double best_min = -std::numeric_limits<double>::infinity();
  const BaseDomain::ChartList charts = domain_->charts_holding(p);
  // The grid cell of p in each chart; only when those are all empty, every triangle of them.
  for (int pass = 0; pass < 2; ++pass) {
    for (int v : charts) {
      search_chart(v, domain_->to_chart(v, p), pass == 1, hit, best_min);
      if (best_min >= -kInside) return clamped(hit);
    }
    if (hit.face >= 0) return clamped(hit);
  }
  throw AlgorithmError("no input triangle is mapped in the charts around base face " + std::to_string(p.face));
}

Eigen::Vector3d BaseLift::lift(const BasePoint& p) const {
  const Hit hit = locate(p);
  return hit.bary[0] * V_.row(F_(hit.face, 0)).transpose() + hit.bary[1] * V_.row(F_(hit.face, 1)).transpose() +
         hit.bary[2] * V_.row(F_(hit.face, 2)).transpose();
}

}  // namespace mrsnake
