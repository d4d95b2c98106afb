#include "remesh/lloyd.h"

#include <algorithm>
#include <cmath>

#include "mesh/parallel.h"
#include "remesh/surface_moves.h"

namespace mrsnake {
namespace {

// Centroid of corner v's quadrilateral in the flat triangle (v, a, b): the mean of the
// centroids of (v, mid(v,a), g) and (v, g, mid(v,b)), which have equal areas.
Eigen::Vector3d quad_centroid(const Eigen::Vector3d& v, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return (11.0 / 18.0) * v + (7.0 / 36.0) * (a + b);
}

}  // namespace

double DensityField::at(const Eigen::Vector3d& p, int& hint) const {
  const DomainMesh::Location loc = mesh->locate(p, hint);
  hint = loc.face;
  const auto& F = mesh->faces();
  return loc.barycentric[0] * vertex_density[F(loc.face, 0)] + loc.barycentric[1] * vertex_density[F(loc.face, 1)] +
         loc.barycentric[2] * vertex_density[F(loc.face, 2)];
}

std::vector<std::array<Eigen::Vector3d, 4>> lloyd_cell(const RowMatrixX3i& F, const RowMatrixX3d& U, int v) {
  std::vector<std::array<Eigen::Vector3d, 4>> cell;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      if (F(f, k) == v) {
        const Eigen::Vector3d p = U.row(v), a = U.row(F(f, (k + 1) % 3)), b = U.row(F(f, (k + 2) % 3));
        cell.push_back({p, 0.5 * (p + a), (p + a + b) / 3.0, 0.5 * (p + b)});
      }
  return cell;
}

Eigen::Vector3d lloyd_cell_centroid(const RowMatrixX3i& F, const RowMatrixX3d& U, int v) {
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  double mass = 0;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      if (F(f, k) == v) {
        const Eigen::Vector3d p = U.row(v), a = U.row(F(f, (k + 1) % 3)), b = U.row(F(f, (k + 2) % 3));
        const double area = 0.5 * (a - p).cross(b - p).norm() / 3.0;
        mass += area;
        moment += area * quad_centroid(p, a, b);
      }
  return moment / mass;
}

LloydStats constrained_lloyd(DomainKind kind, const RowMatrixX3i& F, const DensityField& density, RowMatrixX3d& U,
                             std::vector<int>& vertex_hints, const LloydOptions& options) {
  LloydStats stats;
  const int n = static_cast<int>(U.rows());
  const int m = static_cast<int>(F.rows());
  const VertexStars star(F, n);
  const std::vector<bool> boundary =
      kind == DomainKind::disk ? boundary_vertices(F, star) : std::vector<bool>(n, false);
  std::vector<int> face_hint(m);
  for (int f = 0; f < m; ++f) face_hint[f] = vertex_hints[F(f, 0)];
  const int r = std::min(
      48, static_cast<int>(std::floor(std::sqrt(static_cast<double>(options.sample_budget) / std::max(1, m)))));

  Eigen::VectorXd mass(n);
  RowMatrixX3d moment(n, 3);
  std::vector<std::array<double, 3>> weight(m);
  std::vector<std::array<Eigen::Vector3d, 3>> corner_centroid(m);
  for (int it = 0; it < options.iterations; ++it) {
    mass.setZero();
    moment.setZero();
    // The density integrals of the faces are independent (each face walks from its own
    // hint): computed in parallel, then summed in face order as before.
    parallel_ranges(
        static_cast<std::size_t>(m),
        [&](std::size_t begin, std::size_t end) {
          for (int f = static_cast<int>(begin); f < static_cast<int>(end); ++f) {
            const Eigen::Vector3d P[3] = {U.row(F(f, 0)), U.row(F(f, 1)), U.row(F(f, 2))};
            const double third = 0.5 * (P[1] - P[0]).cross(P[2] - P[0]).norm() / 3.0;
            Eigen::Vector3d centroid[3];
            double rho[3];
            for (int k = 0; k < 3; ++k) centroid[k] = quad_centroid(P[k], P[(k + 1) % 3], P[(k + 2) % 3]);
            if (r <= 2) {
              for (int k = 0; k < 3; ++k) rho[k] = density.at(centroid[k], face_hint[f]);
            } else {
              // Mean density over the grid samples falling in each corner's quadrilateral (the
              // region where that corner's barycentric coordinate is the largest).
              double sum[3] = {0, 0, 0}, count[3] = {0, 0, 0};
              auto sample = [&](double x, double y) {
                const Eigen::Vector3d l(1 - x - y, x, y);
                const double value = density.at(l[0] * P[0] + l[1] * P[1] + l[2] * P[2], face_hint[f]);
                const double top = l.maxCoeff();
                int ties = 0;
                for (int k = 0; k < 3; ++k) ties += l[k] >= top - 1e-12;
                for (int k = 0; k < 3; ++k)
                  if (l[k] >= top - 1e-12) {
                    sum[k] += value / ties;
                    count[k] += 1.0 / ties;
                  }
              };
              for (int i = 0; i < r; ++i)
                for (int j = 0; i + j < r; ++j) {
                  sample((i + 1.0 / 3) / r, (j + 1.0 / 3) / r);
                  if (i + j <= r - 2) sample((i + 2.0 / 3) / r, (j + 2.0 / 3) / r);
                }
              for (int k = 0; k < 3; ++k)
                rho[k] = count[k] > 0 ? sum[k] / count[k] : density.at(centroid[k], face_hint[f]);
            }
            for (int k = 0; k < 3; ++k) {
              weight[f][k] = rho[k] * third;
              corner_centroid[f][k] = centroid[k];
            }
          }
        },
        /*min_per_thread=*/16);
    for (int f = 0; f < m; ++f)
      for (int k = 0; k < 3; ++k) {
        const double w = weight[f][k];
        mass[F(f, k)] += w;
        moment.row(F(f, k)) += w * corner_centroid[f][k].transpose();
      }
    // Gauss-Seidel moves, each checked against the current positions of its neighbours.
    double shift = 0;
    int moved = 0;
    for (int v = options.first_movable; v < n; ++v) {
      if (!(mass[v] > 0)) continue;
      const Eigen::Vector3d current = U.row(v);
      const Eigen::Vector3d target = project_to_domain(kind, moment.row(v).transpose() / mass[v], boundary[v]);
      double t = options.step;
      bool accepted = false;
      for (int attempt = 0; attempt < 12 && !accepted; ++attempt, t *= 0.5) {
        const Eigen::Vector3d candidate = project_to_domain(kind, current + t * (target - current), boundary[v]);
        bool valid = true;
        for (int i = star.offset[v]; i < star.offset[v + 1] && valid; ++i) {
          const int f = star.faces[i];
          Eigen::Vector3d P[3] = {U.row(F(f, 0)), U.row(F(f, 1)), U.row(F(f, 2))};
          for (int k = 0; k < 3; ++k)
            if (F(f, k) == v) P[k] = candidate;
          valid = domain_orientation(P[0], P[1], P[2]) > 0;
        }
        if (valid) {
          U.row(v) = candidate.transpose();
          shift += (candidate - current).norm();
          ++moved;
          accepted = true;
          if (attempt > 0) ++stats.shortened_moves;
        }
      }
      if (!accepted) ++stats.rejected_moves;
    }
    stats.moves += moved;
    stats.mean_shift = moved > 0 ? shift / moved : 0;
  }
  for (int f = 0; f < m; ++f) vertex_hints[F(f, 0)] = face_hint[f];
  return stats;
}

}  // namespace mrsnake
