#pragma once
/// \file surface_moves.h
/// Small pieces shared by the steps that move the vertices of a level over the input surface in
/// 3D and carry each move back to the parameter domain D (shape_smoothing.h, triangle_repair.h,
/// base_levels.h): the vertex normal, the no-flip check of a vertex's star in D, the smallest
/// quality of a star and of a level, the mean edge length, the point-triangle distance, the
/// equilateral apex of an edge, the repair's surface error, targets, retries and sweep, and the
/// pull-back of a 3D move through the affine map of one input triangle.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include <Eigen/Dense>
#include <boost/container/small_vector.hpp>

#include "mesh/quality.h"
#include "mesh/trimesh.h"
#include "mesh/vertex_stars.h"
#include "remesh/domain.h"
#include "remesh/split_sweep.h"

namespace mrsnake {

/// The unit area-weighted normal of vertex v of (X, F), or nullopt where its faces cancel out.
inline std::optional<Eigen::Vector3d> vertex_normal(const RowMatrixX3d& X, const RowMatrixX3i& F,
                                                    const VertexStars& stars, int v) {
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (int i = stars.offset[v]; i < stars.offset[v + 1]; ++i) {
    const int f = stars.faces[i];
    normal += (X.row(F(f, 1)) - X.row(F(f, 0))).cross(X.row(F(f, 2)) - X.row(F(f, 0))).transpose();
  }
  if (!(normal.norm() > 0)) return std::nullopt;
  return normal.normalized();
}

/// Whether no face around v is flipped in D (U, F) when v is put at u.
inline bool star_unflipped_in_domain(const RowMatrixX3d& U, const RowMatrixX3i& F, const VertexStars& stars, int v,
                                     const Eigen::Vector3d& u) {
  for (int i = stars.offset[v]; i < stars.offset[v + 1]; ++i) {
    const int f = stars.faces[i];
    Eigen::Vector3d P[3] = {U.row(F(f, 0)), U.row(F(f, 1)), U.row(F(f, 2))};
    for (int k = 0; k < 3; ++k)
      if (F(f, k) == v) P[k] = u;
    if (!(domain_orientation(P[0], P[1], P[2]) > 0)) return false;
  }
  return true;
}

/// Smallest Frey–Borouchaki Q of v's triangles in (X, F) with v put at x; +infinity if v has
/// no triangle (nothing to make worse).
inline double star_quality(const RowMatrixX3d& X, const RowMatrixX3i& F, const VertexStars& stars, int v,
                           const Eigen::Vector3d& x) {
  double q = std::numeric_limits<double>::infinity();
  for (int i = stars.offset[v]; i < stars.offset[v + 1]; ++i) {
    const int f = stars.faces[i];
    Eigen::Vector3d P[3] = {X.row(F(f, 0)), X.row(F(f, 1)), X.row(F(f, 2))};
    for (int k = 0; k < 3; ++k)
      if (F(f, k) == v) P[k] = x;
    q = std::min(q, frey_borouchaki_quality(P[0], P[1], P[2]));
  }
  return q;
}

/// Distance from p to the triangle (a, b, c) (Ericson, Real-Time Collision Detection, 5.1.5).
inline double point_triangle_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                      const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return ap.norm();
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return bp.norm();
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return (p - (a + d1 / (d1 - d3) * ab)).norm();
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return cp.norm();
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return (p - (a + d2 / (d2 - d6) * ac)).norm();
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return (p - (b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b))).norm();
  const double denom = 1.0 / (va + vb + vc);
  return (p - (a + ab * (vb * denom) + ac * (vc * denom))).norm();
}

/// The apex of the equilateral triangle on edge a → b, on the side where a vertex with outward
/// normal `normal` lies when it is left of a → b seen from outside; nullopt if the edge is
/// parallel to the normal.
inline std::optional<Eigen::Vector3d> equilateral_apex(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                                       const Eigen::Vector3d& normal) {
  const Eigen::Vector3d e = b - a;
  const Eigen::Vector3d side = normal.cross(e);
  if (!(side.norm() > 0)) return std::nullopt;
  return Eigen::Vector3d(0.5 * (a + b) + (std::sqrt(3.0) / 2.0) * e.norm() * side.normalized());
}

/// The mean length of the edges of (X, F), each counted once per face around it; 0 without faces.
inline double mean_edge_length(const RowMatrixX3d& X, const RowMatrixX3i& F) {
  double sum = 0;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) sum += (X.row(F(f, k)) - X.row(F(f, (k + 1) % 3))).norm();
  return sum / std::max<Eigen::Index>(1, 3 * F.rows());
}

/// The smallest Frey–Borouchaki Q of the triangles of (X, F); 0 without faces.
inline double smallest_quality(const RowMatrixX3d& X, const RowMatrixX3i& F) {
  double q = std::numeric_limits<double>::infinity();
  for (int f = 0; f < F.rows(); ++f)
    q = std::min(
        q, frey_borouchaki_quality(X.row(F(f, 0)).transpose(), X.row(F(f, 1)).transpose(), X.row(F(f, 2)).transpose()));
  return F.rows() > 0 ? q : 0.0;
}

/// How far v's triangles, with v at x, leave the surface, for the repair's guard: the largest
/// distance between an edge's 3D midpoint and `lifted_midpoint(w)`, the lift of the midpoint of
/// the edge v–w in D (nullopt where there is none: the error is then infinite), and the distance
/// from `old` (v before the move, on the surface) to the triangles: a move off a ridge or a tip
/// leaves it away from them. The neighbours are visited in the order of v's star, each once.
template <class LiftedMidpoint>
double star_surface_error(const RowMatrixX3d& X, const RowMatrixX3i& F, const VertexStars& stars, int v,
                          const Eigen::Vector3d& x, const Eigen::Vector3d& old, LiftedMidpoint&& lifted_midpoint) {
  double error = 0, to_old = std::numeric_limits<double>::infinity();
  // A neighbour inside the star is in two of its faces; its midpoint's lift (a point location)
  // is the costly part, so it is done once.
  boost::container::small_vector<int, 16> measured;
  for (int i = stars.offset[v]; i < stars.offset[v + 1]; ++i) {
    const int f = stars.faces[i];
    int k = 0;
    while (F(f, k) != v) ++k;
    const int a = F(f, (k + 1) % 3), b = F(f, (k + 2) % 3);
    for (const int w : {a, b}) {
      if (std::find(measured.begin(), measured.end(), w) != measured.end()) continue;
      measured.push_back(w);
      const std::optional<Eigen::Vector3d> mid = lifted_midpoint(w);
      if (!mid) return std::numeric_limits<double>::infinity();
      error = std::max(error, (*mid - 0.5 * (x + X.row(w).transpose())).norm());
    }
    to_old = std::min(to_old, point_triangle_distance(old, x, X.row(a).transpose(), X.row(b).transpose()));
  }
  return std::max(error, to_old);
}

/// The best of the repair's candidates (each with a quality `q`) that `passes`, or null: they are
/// tried from the best down, equals in their order, so that the costly checks in `passes` run
/// only until one passes, and the one kept is the one a scan keeping the best passing
/// candidate so far would keep (but for qualities within 1e-9 of each other).
template <class Candidates, class Passes>
const typename Candidates::value_type* best_passing(Candidates& candidates, Passes&& passes) {
  std::stable_sort(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) { return a.q > b.q; });
  for (const auto& candidate : candidates)
    if (passes(candidate)) return &candidate;
  return nullptr;
}

/// Where the repair of the worst triangles (triangle_repair.h, base_levels.h) tries to move
/// vertex v of (X, F) with outward normal `normal`, best guess first: the apex that makes its
/// worst triangle equilateral, the mean such apex over its triangles, and its ring's centroid.
/// nullopt where no triangle has an apex (every edge parallel to the normal).
inline std::optional<std::array<Eigen::Vector3d, 3>> repair_targets(const RowMatrixX3d& X, const RowMatrixX3i& F,
                                                                    const VertexStars& stars, int v,
                                                                    const Eigen::Vector3d& normal) {
  const Eigen::Vector3d x = X.row(v);
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero(), mean_apex = Eigen::Vector3d::Zero(), worst_apex = x;
  double worst = std::numeric_limits<double>::infinity();
  int count = 0;
  for (int i = stars.offset[v]; i < stars.offset[v + 1]; ++i) {
    const int f = stars.faces[i];
    int k = 0;
    while (F(f, k) != v) ++k;
    const Eigen::Vector3d a = X.row(F(f, (k + 1) % 3)), b = X.row(F(f, (k + 2) % 3));
    const std::optional<Eigen::Vector3d> apex = equilateral_apex(a, b, normal);
    if (!apex) continue;
    mean_apex += *apex;
    centroid += 0.5 * (a + b);  // each neighbour twice around an interior vertex
    ++count;
    if (const double q = frey_borouchaki_quality(x, a, b); q < worst) {
      worst = q;
      worst_apex = *apex;
    }
  }
  if (count == 0) return std::nullopt;
  return std::array<Eigen::Vector3d, 3>{worst_apex, mean_apex / count, centroid / count};
}

/// Which vertices a repair sweep need not try again. A vertex's attempt depends only on the
/// positions of its star, so after a failed attempt it is tried again only once something in
/// its 1-ring has moved: the same result, fewer attempts.
class RepairRetries {
 public:
  RepairRetries(const RowMatrixX3i& F, const VertexStars& stars, int n)
      : F_(F), stars_(stars), moved_at_(n, -1), failed_at_(n, -1) {}

  /// Never tried, or something in its 1-ring moved since it last failed.
  bool worth_trying(int v) const {
    if (failed_at_[v] < 0) return true;
    for (int i = stars_.offset[v]; i < stars_.offset[v + 1]; ++i)
      for (int k = 0; k < 3; ++k)
        if (moved_at_[F_(stars_.faces[i], k)] > failed_at_[v]) return true;
    return false;
  }
  /// v failed or moved, stamped by the clock of `part` (split_sweep.h): parts that run side by
  /// side keep their own clocks, and never compare each other's stamps.
  void failed(int v, int part = 0) { failed_at_[v] = ++clock_[part]; }
  void moved(int v, int part = 0) {
    failed_at_[v] = -1;
    moved_at_[v] = ++clock_[part];
  }
  /// After parts ran side by side: every clock goes on from the latest stamp, so that later
  /// stamps are larger than all of theirs.
  void join_parts() { clock_.fill(*std::max_element(clock_.begin(), clock_.end())); }

 private:
  const RowMatrixX3i& F_;
  const VertexStars& stars_;
  std::array<long, 3> clock_{};
  std::vector<long> moved_at_, failed_at_;
};

/// The faces whose quality (one entry per face) is below `threshold`, worst first, with their
/// quality: what a repair sweep visits.
inline std::vector<std::pair<double, int>> faces_below(const std::vector<double>& quality, double threshold) {
  std::vector<std::pair<double, int>> poor;
  for (int f = 0; f < static_cast<int>(quality.size()); ++f)
    if (quality[f] < threshold) poor.emplace_back(quality[f], f);
  std::sort(poor.begin(), poor.end());
  return poor;
}

/// One repair sweep over the vertices of the `poor` faces (worst first), on the parts of
/// `split`: each part visits its own vertices in that order, each vertex once per sweep
/// (`visited` stamped with `sweep`), movable(v) and worth retrying, and repair(v) moves it or
/// not. \return the moves made.
/// \pre repair(v) reads only v's 1-ring and star and writes only v (SplitSweep::run).
template <class Movable, class RepairVertex>
int repair_sweep(const SplitSweep& split, const RowMatrixX3i& F, const std::vector<std::pair<double, int>>& poor,
                 int sweep, std::vector<int>& visited, RepairRetries& retries, Movable&& movable,
                 RepairVertex&& repair) {
  std::array<int, SplitSweep::kParts> moved{};
  split.run([&](int part) {
    if (part == SplitSweep::kBand) retries.join_parts();
    for (const auto& [q_face, face] : poor)
      for (int corner = 0; corner < 3; ++corner) {
        const int v = F(face, corner);
        if (split.part(v) != part || visited[v] == sweep || !movable(v)) continue;
        visited[v] = sweep;
        if (!retries.worth_trying(v)) continue;
        if (repair(v)) {
          retries.moved(v, part);
          ++moved[part];
        } else {
          retries.failed(v, part);
        }
      }
  });
  retries.join_parts();
  return moved[0] + moved[1] + moved[2];
}

/// The affine map of one input triangle from its plane in 3D to D. A 3D move is projected on
/// the triangle's plane (least squares) and mapped to the move in D that gives it, to first
/// order: the Jacobian of the lift's inverse on that triangle.
class TrianglePullback {
 public:
  /// \return nullopt if the triangle is degenerate in 3D (no plane to project on).
  /// \pre face is a row of F; surface_V and domain_V index the same vertices.
  static std::optional<TrianglePullback> of(const RowMatrixX3d& surface_V, const RowMatrixX3d& domain_V,
                                            const RowMatrixX3i& F, int face) {
    TrianglePullback map;
    const Eigen::Vector3d x0 = surface_V.row(F(face, 0)), d0 = domain_V.row(F(face, 0));
    map.edges_3d_.col(0) = surface_V.row(F(face, 1)).transpose() - x0;
    map.edges_3d_.col(1) = surface_V.row(F(face, 2)).transpose() - x0;
    map.edges_domain_.col(0) = domain_V.row(F(face, 1)).transpose() - d0;
    map.edges_domain_.col(1) = domain_V.row(F(face, 2)).transpose() - d0;
    const Eigen::Matrix2d gram = map.edges_3d_.transpose() * map.edges_3d_;
    if (!(std::abs(gram.determinant()) > 0)) return std::nullopt;
    map.gram_solver_.compute(gram);
    return map;
  }

  /// The move in D whose lift is `move_3d`'s part in the triangle's plane.
  Eigen::Vector3d to_domain(const Eigen::Vector3d& move_3d) const {
    return edges_domain_ * gram_solver_.solve(edges_3d_.transpose() * move_3d);
  }

 private:
  TrianglePullback() = default;
  Eigen::Matrix<double, 3, 2> edges_3d_, edges_domain_;
  Eigen::LDLT<Eigen::Matrix2d> gram_solver_;
};

}  // namespace mrsnake
