#include "remesh/shape_smoothing.h"

#include <cmath>
#include <optional>

#include <Eigen/Dense>

#include "remesh/surface_moves.h"

namespace mrsnake {

int smooth_shapes_in_domain(DomainKind kind, const RowMatrixX3i& F, const DomainMesh& param,
                            const RowMatrixX3d& surface_V, RowMatrixX3d& U, RowMatrixX3d& X,
                            std::vector<int>& hints, const ShapeSmoothingOptions& options) {
  const int n = static_cast<int>(U.rows());
  const std::vector<bool> boundary = kind == DomainKind::disk ? boundary_vertices(F, n) : std::vector<bool>(n, false);
  const VertexStars stars(F, n);
  const auto& PF = param.faces();
  const auto& PD = param.positions();
  int moves = 0;
  for (int it = 0; it < options.iterations; ++it) {
    for (int v = options.first_movable; v < n; ++v) {
      if (boundary[v]) continue;
      const Eigen::Vector3d x = X.row(v);
      const std::optional<Eigen::Vector3d> normal = vertex_normal(X, F, stars, v);
      if (!normal) continue;
      Eigen::Vector3d target = Eigen::Vector3d::Zero();
      int count = 0;
      for (int i = stars.offset[v]; i < stars.offset[v + 1]; ++i) {
        const int f = stars.faces[i];
        int k = 0;
        while (F(f, k) != v) ++k;
        if (const auto apex = equilateral_apex(X.row(F(f, (k + 1) % 3)), X.row(F(f, (k + 2) % 3)), *normal)) {
          target += *apex;
          ++count;
        }
      }
      if (count == 0) continue;
      Eigen::Vector3d move = target / count - x;
      move -= move.dot(*normal) * *normal;
      // Pull the 3D move back to D through the affine map of the input triangle under v.
      const std::optional<TrianglePullback> pullback = TrianglePullback::of(surface_V, PD, PF, hints[v]);
      if (!pullback) continue;
      const Eigen::Vector3d domain_move = pullback->to_domain(move);
      const Eigen::Vector3d current = U.row(v);
      double t = options.step;
      for (int attempt = 0; attempt < 8; ++attempt, t *= 0.5) {
        const Eigen::Vector3d candidate = project_to_domain(kind, current + t * domain_move, false);
        if (!star_unflipped_in_domain(U, F, stars, v, candidate)) continue;
        const DomainMesh::Location loc = param.locate(candidate, hints[v]);
        hints[v] = loc.face;
        U.row(v) = candidate.transpose();
        X.row(v) = loc.barycentric[0] * surface_V.row(PF(loc.face, 0)) + loc.barycentric[1] * surface_V.row(PF(loc.face, 1)) +
                   loc.barycentric[2] * surface_V.row(PF(loc.face, 2));
        ++moves;
        break;
      }
    }
  }
  return moves;
}

}  // namespace mrsnake
