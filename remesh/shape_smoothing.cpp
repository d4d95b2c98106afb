#include "remesh/shape_smoothing.h"

#include <cmath>

#include <Eigen/Dense>

namespace mrsnake {

int smooth_shapes_in_domain(DomainKind kind, const RowMatrixX3i& F, const DomainMesh& param,
                            const RowMatrixX3d& surface_V, RowMatrixX3d& U, RowMatrixX3d& X,
                            std::vector<int>& hints, const ShapeSmoothingOptions& options) {
  const int n = static_cast<int>(U.rows());
  const std::vector<bool> boundary = kind == DomainKind::disk ? boundary_vertices(F, n) : std::vector<bool>(n, false);
  // Vertex -> incident faces.
  std::vector<int> offset(n + 1, 0), star;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) ++offset[F(f, k) + 1];
  for (int v = 0; v < n; ++v) offset[v + 1] += offset[v];
  star.resize(offset[n]);
  {
    std::vector<int> fill(offset.begin(), offset.end() - 1);
    for (int f = 0; f < F.rows(); ++f)
      for (int k = 0; k < 3; ++k) star[fill[F(f, k)]++] = f;
  }
  const auto& PF = param.faces();
  const auto& PD = param.positions();
  int moves = 0;
  for (int it = 0; it < options.iterations; ++it) {
    for (int v = options.first_movable; v < n; ++v) {
      if (boundary[v]) continue;
      const Eigen::Vector3d x = X.row(v);
      Eigen::Vector3d normal = Eigen::Vector3d::Zero();
      for (int i = offset[v]; i < offset[v + 1]; ++i) {
        const int f = star[i];
        normal += (X.row(F(f, 1)) - X.row(F(f, 0))).cross(X.row(F(f, 2)) - X.row(F(f, 0))).transpose();
      }
      if (!(normal.norm() > 0)) continue;
      normal.normalize();
      Eigen::Vector3d target = Eigen::Vector3d::Zero();
      int count = 0;
      for (int i = offset[v]; i < offset[v + 1]; ++i) {
        const int f = star[i];
        int k = 0;
        while (F(f, k) != v) ++k;
        const Eigen::Vector3d a = X.row(F(f, (k + 1) % 3)), b = X.row(F(f, (k + 2) % 3));
        const Eigen::Vector3d e = b - a;
        const Eigen::Vector3d side = normal.cross(e);  // v lies left of a -> b, seen from outside
        if (!(side.norm() > 0)) continue;
        target += 0.5 * (a + b) + (std::sqrt(3.0) / 2.0) * e.norm() * side.normalized();
        ++count;
      }
      if (count == 0) continue;
      Eigen::Vector3d move = target / count - x;
      move -= move.dot(normal) * normal;
      // Pull the 3D move back to D through the affine map of the input triangle under v.
      const int pf = hints[v];
      const Eigen::Vector3d x0 = surface_V.row(PF(pf, 0)), d0 = PD.row(PF(pf, 0));
      Eigen::Matrix<double, 3, 2> XE, DE;
      XE.col(0) = surface_V.row(PF(pf, 1)).transpose() - x0;
      XE.col(1) = surface_V.row(PF(pf, 2)).transpose() - x0;
      DE.col(0) = PD.row(PF(pf, 1)).transpose() - d0;
      DE.col(1) = PD.row(PF(pf, 2)).transpose() - d0;
      const Eigen::Matrix2d gram = XE.transpose() * XE;
      if (!(std::abs(gram.determinant()) > 0)) continue;
      const Eigen::Vector2d alpha = gram.ldlt().solve(XE.transpose() * move);
      const Eigen::Vector3d domain_move = DE * alpha;
      const Eigen::Vector3d current = U.row(v);
      double t = options.step;
      for (int attempt = 0; attempt < 8; ++attempt, t *= 0.5) {
        const Eigen::Vector3d candidate = project_to_domain(kind, current + t * domain_move, false);
        bool valid = true;
        for (int i = offset[v]; i < offset[v + 1] && valid; ++i) {
          const int f = star[i];
          Eigen::Vector3d P[3] = {U.row(F(f, 0)), U.row(F(f, 1)), U.row(F(f, 2))};
          for (int k = 0; k < 3; ++k)
            if (F(f, k) == v) P[k] = candidate;
          valid = domain_orientation(P[0], P[1], P[2]) > 0;
        }
        if (!valid) continue;
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
