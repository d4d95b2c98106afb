#include "remesh/sizing.h"

#include <cmath>
#include <vector>

namespace mrsnake {

Eigen::VectorXd vertex_curvature(const TriMesh& mesh, int smoothing) {
  const int n = mesh.num_vertices();
  RowMatrixX3d normal = RowMatrixX3d::Zero(n, 3);
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::RowVector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    const Eigen::RowVector3d area_normal = (b - a).cross(c - a);
    for (int k = 0; k < 3; ++k) normal.row(mesh.F(f, k)) += area_normal;
  }
  for (int v = 0; v < n; ++v)
    if (normal.row(v).norm() > 0) normal.row(v).normalize();
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(n), count = Eigen::VectorXd::Zero(n);
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int u = mesh.F(f, k), v = mesh.F(f, (k + 1) % 3);
      const double length = (mesh.V.row(u) - mesh.V.row(v)).norm();
      if (!(length > 0)) continue;
      const double change = (normal.row(u) - normal.row(v)).norm() / length;
      sum[u] += change;
      sum[v] += change;
      count[u] += 1;
      count[v] += 1;
    }
  return smooth_vertex_field(mesh, sum.cwiseQuotient(count.cwiseMax(1.0)), smoothing);
}

Eigen::VectorXd smooth_vertex_field(const TriMesh& mesh, Eigen::VectorXd field, int passes) {
  const int n = mesh.num_vertices();
  for (int pass = 0; pass < passes; ++pass) {
    Eigen::VectorXd next = field, weight = Eigen::VectorXd::Ones(n);
    for (int f = 0; f < mesh.num_faces(); ++f)
      for (int k = 0; k < 3; ++k) {
        const int u = mesh.F(f, k), v = mesh.F(f, (k + 1) % 3);
        next[u] += field[v];
        next[v] += field[u];
        weight[u] += 1;
        weight[v] += 1;
      }
    field = next.cwiseQuotient(weight);
  }
  return field;
}

Eigen::VectorXd vertex_areas(const TriMesh& mesh) {
  Eigen::VectorXd area = Eigen::VectorXd::Zero(mesh.num_vertices());
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::RowVector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    const double third = (b - a).cross(c - a).norm() / 6.0;
    for (int k = 0; k < 3; ++k) area[mesh.F(f, k)] += third;
  }
  return area;
}

namespace {

// Points per unit area of an equilateral grid of spacing h = max_bend / κ: 2 / (sqrt(3) h²).
Eigen::VectorXd bend_bound(const Eigen::VectorXd& curvature, double max_bend) {
  return (2.0 / std::sqrt(3.0)) * (curvature / max_bend).array().square().matrix();
}

}  // namespace

double bend_bound_points(const TriMesh& mesh, const Eigen::VectorXd& curvature, double max_bend) {
  return vertex_areas(mesh).dot(bend_bound(curvature, max_bend));
}

Eigen::VectorXd bend_bounded_density(const TriMesh& mesh, const Eigen::VectorXd& density,
                                     const Eigen::VectorXd& curvature, double points, double max_bend) {
  const Eigen::VectorXd area = vertex_areas(mesh);
  Eigen::VectorXd floor = bend_bound(curvature, max_bend);
  if (const double floor_points = area.dot(floor); floor_points > 0.5 * points) floor *= 0.5 * points / floor_points;
  // Scale t of the density (points per area = t·density where the bound is slack) such that
  // Σ area·max(t·density, floor) = points; the count grows with t, so bisect.
  const auto count = [&](double t) { return area.dot((t * density).cwiseMax(floor)); };
  double lo = 0, hi = points / area.dot(density);
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    (count(mid) < points ? lo : hi) = mid;
  }
  // t >= points / (2 Σ area·density) > 0: the bound takes at most half of the points.
  return density.cwiseMax(floor / hi);
}

Eigen::VectorXd curvature_density(const Eigen::VectorXd& curvature, double weight, double exponent) {
  Eigen::VectorXd wanted = Eigen::VectorXd::Ones(curvature.size());
  if (const double mean = curvature.mean(); weight > 0 && mean > 0)
    wanted.array() += weight * (curvature.array() / mean).pow(exponent).min(3.0);
  return wanted;
}

}  // namespace mrsnake
