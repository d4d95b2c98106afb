#include "remesh/domain.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

namespace mrsnake {
namespace {

// Nearest point of triangle (a, b, c) to p, as barycentric coordinates (Ericson's method).
Eigen::Vector3d closest_barycentric(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                    const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return {1, 0, 0};
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return {0, 1, 0};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return {1 - v, v, 0};
  }
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return {0, 0, 1};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 / (d2 - d6);
    return {1 - w, 0, w};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {0, 1 - w, w};
  }
  const double denom = 1.0 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  return {1 - v - w, v, w};
}

}  // namespace

Eigen::Vector3d project_to_domain(DomainKind kind, const Eigen::Vector3d& p, bool on_boundary) {
  if (kind == DomainKind::sphere) return p.normalized();
  Eigen::Vector3d q(p.x(), p.y(), 1.0);
  if (on_boundary) {
    const double r = std::hypot(q.x(), q.y());
    if (r > 0) q.head<2>() /= r;
  }
  return q;
}

int count_flipped(const RowMatrixX3d& D, const RowMatrixX3i& F) {
  int flipped = 0;
  for (int f = 0; f < F.rows(); ++f)
    if (!(domain_orientation(D.row(F(f, 0)), D.row(F(f, 1)), D.row(F(f, 2))) > 0)) ++flipped;
  return flipped;
}

std::vector<std::pair<int, int>> boundary_edges(const RowMatrixX3i& F, const VertexStars& stars) {
  std::vector<std::pair<int, int>> edges;
  for (int f = 0; f < F.rows(); ++f)
    for (int e = 0; e < 3; ++e) {
      const int a = F(f, e), b = F(f, (e + 1) % 3);
      if (face_with_directed_edge(stars, F, b, a) < 0) edges.emplace_back(a, b);
    }
  return edges;
}

std::vector<Eigen::Vector2i> rim_neighbours(const std::vector<std::pair<int, int>>& rim_edges, int n) {
  std::vector<Eigen::Vector2i> rim(n, Eigen::Vector2i(-1, -1));
  for (const auto& [a, b] : rim_edges) {
    rim[a][1] = b;  // a -> b runs along the boundary
    rim[b][0] = a;
  }
  return rim;
}

std::vector<bool> boundary_vertices(const RowMatrixX3i& F, const VertexStars& stars) {
  std::vector<bool> boundary(stars.offset.size() - 1, false);
  for (const auto& [a, b] : boundary_edges(F, stars)) boundary[a] = boundary[b] = true;
  return boundary;
}

std::vector<bool> boundary_vertices(const RowMatrixX3i& F, int num_vertices) {
  return boundary_vertices(F, VertexStars(F, num_vertices));
}

DomainMesh::DomainMesh(RowMatrixX3d D, RowMatrixX3i F) : D_(std::move(D)), F_(std::move(F)) {
  // The face holding the directed edge tail -> head: in tail's star (5x faster than sorting
  // 64-bit edge keys on a 179k-face liver). A repeated directed edge resolves to its last
  // face, as a map filled in face order would.
  const int m = static_cast<int>(F_.rows());
  const VertexStars stars(F_, static_cast<int>(std::max<Eigen::Index>(D_.rows(), m > 0 ? F_.maxCoeff() + 1 : 0)));
  edge_normal_.resize(F_.rows(), 9);
  for (int f = 0; f < F_.rows(); ++f) {
    const Eigen::Vector3d a = D_.row(F_(f, 0)), b = D_.row(F_(f, 1)), c = D_.row(F_(f, 2));
    edge_normal_.row(f).segment<3>(0) = b.cross(c).transpose();
    edge_normal_.row(f).segment<3>(3) = c.cross(a).transpose();
    edge_normal_.row(f).segment<3>(6) = a.cross(b).transpose();
  }
  neighbor_.resize(F_.rows(), 3);
  for (int f = 0; f < F_.rows(); ++f)
    for (int corner = 0; corner < 3; ++corner) {
      // The edge opposite `corner` runs from corner+1 to corner+2.
      const int a = F_(f, (corner + 1) % 3), b = F_(f, (corner + 2) % 3);
      neighbor_(f, corner) = face_with_directed_edge(stars, F_, b, a);
    }
}

DomainMesh::Location DomainMesh::locate(const Eigen::Vector3d& p, int hint) const {
  int f = (hint >= 0 && hint < F_.rows()) ? hint : 0;
  const int max_steps = static_cast<int>(F_.rows()) + 16;
  for (int step = 0; step < max_steps; ++step) {
    // det(p, b, c) = p·(b×c), det(a, p, c) = p·(c×a), det(a, b, p) = p·(a×b).
    const double* n = edge_normal_.row(f).data();
    const Eigen::Vector3d lambda(p.x() * n[0] + p.y() * n[1] + p.z() * n[2], p.x() * n[3] + p.y() * n[4] + p.z() * n[5],
                                 p.x() * n[6] + p.y() * n[7] + p.z() * n[8]);
    int cross = -1;
    bool outside_only = true;  // every violated edge is a boundary edge
    for (int k = 0; k < 3; ++k) {
      const int e = (k + step) % 3;  // rotate the start so that walks cannot cycle
      if (lambda[e] < 0) {
        if (neighbor_(f, e) >= 0) {
          cross = e;
          outside_only = false;
          break;
        }
      }
    }
    if (cross < 0) {
      Location loc;
      loc.face = f;
      if (lambda.minCoeff() >= 0 && lambda.sum() > 0) {
        loc.barycentric = lambda / lambda.sum();
      } else if (outside_only) {
        loc.barycentric = closest_barycentric(p, D_.row(F_(f, 0)), D_.row(F_(f, 1)), D_.row(F_(f, 2)));
      } else {
        return brute_force(p);
      }
      return loc;
    }
    f = neighbor_(f, cross);
  }
  return brute_force(p);
}

DomainMesh::Location DomainMesh::brute_force(const Eigen::Vector3d& p) const {
  Location best;
  double best_score = -std::numeric_limits<double>::infinity();
  for (int f = 0; f < F_.rows(); ++f) {
    const Eigen::Vector3d a = D_.row(F_(f, 0)), b = D_.row(F_(f, 1)), c = D_.row(F_(f, 2));
    const Eigen::Vector3d lambda(domain_orientation(p, b, c), domain_orientation(a, p, c), domain_orientation(a, b, p));
    const double sum = lambda.sum();
    if (!(sum > 0)) continue;
    const double score = lambda.minCoeff() / sum;
    if (score > best_score) {
      best_score = score;
      best.face = f;
      best.barycentric = lambda / sum;
    }
  }
  if (best.face < 0) best.face = 0;
  if (best_score < 0) {
    const Eigen::Vector3d a = D_.row(F_(best.face, 0)), b = D_.row(F_(best.face, 1)), c = D_.row(F_(best.face, 2));
    best.barycentric = closest_barycentric(p, a, b, c);
  }
  return best;
}

}  // namespace mrsnake
