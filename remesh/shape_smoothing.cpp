#include "remesh/shape_smoothing.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include <Eigen/Dense>

#include "remesh/lift.h"
#include "remesh/surface_moves.h"

namespace mrsnake {

std::optional<Eigen::Vector3d> tangential_move(const RowMatrixX3d& X, const RowMatrixX3i& F, const VertexStars& stars,
                                               int v, SmoothingTarget target, const Eigen::VectorXd& vertex_density) {
  const std::optional<Eigen::Vector3d> normal = vertex_normal(X, F, stars, v);
  if (!normal) return std::nullopt;
  const Eigen::Vector3d x = X.row(v);
  Eigen::Vector3d aim = Eigen::Vector3d::Zero();
  double total = 0;
  for (int i = stars.offset[v]; i < stars.offset[v + 1]; ++i) {
    const int f = stars.faces[i];
    int k = 0;
    while (F(f, k) != v) ++k;
    const int ia = F(f, (k + 1) % 3), ib = F(f, (k + 2) % 3);
    const Eigen::Vector3d a = X.row(ia), b = X.row(ib);
    if (target == SmoothingTarget::equilateral_apexes) {
      if (const auto apex = equilateral_apex(a, b, *normal)) {
        aim += *apex;
        total += 1;
      }
    } else {
      const double rho = (vertex_density[v] + vertex_density[ia] + vertex_density[ib]) / 3.0;
      const double weight = 0.5 * (a - x).cross(b - x).norm() * rho * rho;
      aim += weight * (x + a + b) / 3.0;
      total += weight;
    }
  }
  if (!(total > 0)) return std::nullopt;
  Eigen::Vector3d move = aim / total - x;
  move -= move.dot(*normal) * *normal;
  return move;
}

int smooth_shapes_in_domain(DomainKind kind, const RowMatrixX3i& F, const DomainMesh& param,
                            const RowMatrixX3d& surface_V, RowMatrixX3d& U, RowMatrixX3d& X, std::vector<int>& hints,
                            const ShapeSmoothingOptions& options) {
  const int n = static_cast<int>(U.rows());
  const VertexStars stars(F, n);
  const std::vector<std::pair<int, int>> rim_edges =
      kind == DomainKind::disk ? boundary_edges(F, stars) : std::vector<std::pair<int, int>>();
  std::vector<bool> boundary(n, false);
  for (const auto& [a, b] : rim_edges) boundary[a] = boundary[b] = true;
  const std::vector<Eigen::Vector2i> rim =
      kind == DomainKind::disk && options.move_rim ? rim_neighbours(rim_edges, n) : std::vector<Eigen::Vector2i>();
  const auto& PF = param.faces();
  const auto& PD = param.positions();
  const bool weighted = options.target == SmoothingTarget::area_centroid && options.surface_density != nullptr;
  // Wanted density under vertex v (its hint face holds it).
  auto density_at = [&](int v) {
    const DomainMesh::Location loc = param.locate(U.row(v).transpose(), hints[v]);
    const Eigen::VectorXd& w = *options.surface_density;
    return loc.barycentric[0] * w[PF(loc.face, 0)] + loc.barycentric[1] * w[PF(loc.face, 1)] +
           loc.barycentric[2] * w[PF(loc.face, 2)];
  };
  Eigen::VectorXd vertex_density = Eigen::VectorXd::Ones(n);
  int moves = 0;
  for (int it = 0; it < options.iterations; ++it) {
    if (weighted)
      for (int v = 0; v < n; ++v) vertex_density[v] = density_at(v);
    for (int v = options.first_movable; v < n; ++v) {
      const bool on_rim = boundary[v];
      if (on_rim && !options.move_rim) continue;
      const Eigen::Vector3d x = X.row(v);
      Eigen::Vector3d move = Eigen::Vector3d::Zero();
      if (on_rim) {
        const int prev = rim[v][0], next = rim[v][1];
        if (prev < 0 || next < 0) continue;
        const Eigen::Vector3d a = X.row(prev), b = X.row(next);
        if (!((b - a).norm() > 0)) continue;
        const Eigen::Vector3d tangent = (b - a).normalized();
        move = (0.5 * (a + b) - x).dot(tangent) * tangent;
      } else {
        const std::optional<Eigen::Vector3d> interior = tangential_move(X, F, stars, v, options.target, vertex_density);
        if (!interior) continue;
        move = *interior;
      }
      // Pull the 3D move back to D through the affine map of the input triangle under v.
      const std::optional<TrianglePullback> pullback = TrianglePullback::of(surface_V, PD, PF, hints[v]);
      if (!pullback) continue;
      const Eigen::Vector3d domain_move = pullback->to_domain(move);
      const Eigen::Vector3d current = U.row(v);
      const double floor =
          options.quality_floor > 0 ? std::min(star_quality(X, F, stars, v, x), options.quality_floor) : 0.0;
      double t = options.step;
      for (int attempt = 0; attempt < 8; ++attempt, t *= 0.5) {
        const Eigen::Vector3d candidate = project_to_domain(kind, current + t * domain_move, on_rim);
        if (!star_unflipped_in_domain(U, F, stars, v, candidate)) continue;
        const DomainMesh::Location loc = param.locate(candidate, hints[v]);
        const Eigen::Vector3d lifted = lift_location(surface_V, PF, loc);
        if (options.quality_floor > 0 && star_quality(X, F, stars, v, lifted) < floor) continue;
        hints[v] = loc.face;
        U.row(v) = candidate.transpose();
        X.row(v) = lifted.transpose();
        ++moves;
        break;
      }
    }
  }
  return moves;
}

}  // namespace mrsnake
