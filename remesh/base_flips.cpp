#include "remesh/base_flips.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <Eigen/Geometry>

#include "remesh/base_mesh.h"

namespace mrsnake {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

double cross2(const Vector2d& u, const Vector2d& w) { return u.x() * w.y() - u.y() * w.x(); }

// The quad a, d, b, c of a flip unfolded into the plane along a-b: a at the origin, b on the
// x axis, c above it (f1 is counter-clockwise) and d below, every edge at its 3D length.
struct UnfoldedQuad {
  std::array<int, 4> vertex;  // a, b, c, d
  std::array<Vector2d, 4> at;

  const Vector2d& of(int v) const { return at[std::find(vertex.begin(), vertex.end(), v) - vertex.begin()]; }
};

Vector2d apex(double base, double to_a, double to_b, double side) {
  const double x = (to_a * to_a - to_b * to_b + base * base) / (2 * base);
  return {x, side * std::sqrt(std::max(0.0, to_a * to_a - x * x))};
}

UnfoldedQuad unfold(const RowMatrixX3d& X, const EdgeFlip& e) {
  const auto length = [&](int u, int v) { return (X.row(u) - X.row(v)).norm(); };
  const double ab = length(e.a, e.b);
  return {{e.a, e.b, e.c, e.d},
          {Vector2d(0, 0), Vector2d(ab, 0), apex(ab, length(e.c, e.a), length(e.c, e.b), 1.0),
           apex(ab, length(e.d, e.a), length(e.d, e.b), -1.0)}};
}

// The new faces (a, d, c) and (d, b, c) both counter-clockwise in the unfolding, with some
// area to spare: the quad is convex, so they cover exactly what the old two covered.
bool convex(const UnfoldedQuad& q) {
  const Vector2d &a = q.at[0], &b = q.at[1], &c = q.at[2], &d = q.at[3];
  const double scale = 1e-9 * (b - a).squaredNorm();
  return cross2(d - a, c - a) > scale && cross2(b - d, c - d) > scale;
}

Vector3d face_normal(const RowMatrixX3d& X, int u, int v, int w) {
  const Vector3d n = (X.row(v) - X.row(u)).transpose().cross((X.row(w) - X.row(u)).transpose());
  return n.normalized();
}

double fold_deg(const RowMatrixX3d& X, int u0, int u1, int u2, int w0, int w1, int w2) {
  const double c = std::clamp(face_normal(X, u0, u1, u2).dot(face_normal(X, w0, w1, w2)), -1.0, 1.0);
  return std::acos(c) * 180.0 / 3.14159265358979323846;
}

// The mean-ratio quality 4·sqrt(3)·area / (sum of squared edge lengths), 1 for equilateral:
// smooth in the vertices, so a small loss reads as a small loss (not mesh/quality.h's Q).
double mean_ratio(const RowMatrixX3d& X, int u, int v, int w) {
  const Vector3d p = X.row(u), q = X.row(v), r = X.row(w);
  const double squares = (q - p).squaredNorm() + (r - q).squaredNorm() + (p - r).squaredNorm();
  return squares > 0 ? 2 * std::sqrt(3.0) * (q - p).cross(r - p).norm() / squares : 0.0;
}

// Barycentric coordinates of p in the triangle (u, v, w) of the plane.
Vector3d barycentric(const Vector2d& p, const Vector2d& u, const Vector2d& v, const Vector2d& w) {
  const double area = cross2(v - u, w - u);
  const double bu = cross2(v - p, w - p) / area, bv = cross2(w - p, u - p) / area;
  return {bu, bv, 1.0 - bu - bv};
}

// The vertex of K that a point stands on (a unit barycentric vector), or -1.
int vertex_of_k(const BasePoint& at, const Eigen::RowVector3i& corners) {
  for (int k = 0; k < 3; ++k)
    if (at.bary[k] == 1.0) return corners[k];
  return -1;
}

// K's faces and the input points located in each, kept up to date by the flips.
class BaseFlipper {
 public:
  BaseFlipper(MapsParameterization& maps, const BaseFlipOptions& options)
      : maps_(maps), options_(options), points_(maps.base.num_faces()) {
    for (std::size_t p = 0; p < maps.location.size(); ++p)
      points_[maps.location[p].face].push_back(static_cast<int>(p));
  }

  BaseFlipStats run() {
    BaseFlipStats stats;
    const RowMatrixX3d& X = maps_.base.V;
    stats.delaunay_flips =
        flip_toward_surface_delaunay(X, maps_.base.F, [this](const EdgeFlip& e) { return flip(e, false); });
    stats.valence_flips =
        flip_toward_regular_valence(static_cast<int>(X.rows()), maps_.base.F, options_.rim_min_triangles,
                                    [this](const EdgeFlip& e) { return flip(e, true); });
    return stats;
  }

 private:
  // Whether the flip keeps K close to the shape (and, for a valence flip, its triangles round
  // enough); if so, the points of f1 and f2 are located in the new faces.
  bool flip(const EdgeFlip& e, bool for_valence) {
    const RowMatrixX3d& X = maps_.base.V;
    const UnfoldedQuad quad = unfold(X, e);
    if (!convex(quad)) return false;
    const double fold_before = fold_deg(X, e.a, e.b, e.c, e.b, e.a, e.d);
    const double fold_after = fold_deg(X, e.a, e.d, e.c, e.d, e.b, e.c);
    if (fold_after > options_.max_fold_deg && fold_after > fold_before) return false;
    if (for_valence) {
      const double before = std::min(mean_ratio(X, e.a, e.b, e.c), mean_ratio(X, e.b, e.a, e.d));
      const double after = std::min(mean_ratio(X, e.a, e.d, e.c), mean_ratio(X, e.d, e.b, e.c));
      if (after < options_.valence_quality_share * before) return false;
    }
    relocate(e, quad);
    return true;
  }

  // The points of f1 and f2, through their position in the unfolding, into (a, d, c) (f1)
  // or (d, b, c) (f2). A vertex of K keeps its exact corner.
  void relocate(const EdgeFlip& e, const UnfoldedQuad& quad) {
    const std::array<int, 3> first = {e.a, e.d, e.c}, second = {e.d, e.b, e.c};
    std::vector<int> moving = points_[e.f1];
    moving.insert(moving.end(), points_[e.f2].begin(), points_[e.f2].end());
    points_[e.f1].clear();
    points_[e.f2].clear();
    for (int p : moving) {
      BasePoint& at = maps_.location[p];
      const Eigen::RowVector3i corners = maps_.base.F.row(at.face);
      Vector2d where = Vector2d::Zero();
      for (int k = 0; k < 3; ++k) where += at.bary[k] * quad.of(corners[k]);
      const Vector3d in_first = barycentric(where, quad.of(first[0]), quad.of(first[1]), quad.of(first[2]));
      const Vector3d in_second = barycentric(where, quad.of(second[0]), quad.of(second[1]), quad.of(second[2]));
      const int vertex = vertex_of_k(at, corners);
      const bool first_holds = vertex >= 0 ? vertex != e.b : in_first.minCoeff() >= in_second.minCoeff();
      const std::array<int, 3>& face = first_holds ? first : second;
      at.face = first_holds ? e.f1 : e.f2;
      if (vertex >= 0) {
        at.bary = Vector3d::Unit(static_cast<int>(std::find(face.begin(), face.end(), vertex) - face.begin()));
      } else {
        const Vector3d b = (first_holds ? in_first : in_second).cwiseMax(0.0);
        at.bary = b / b.sum();
      }
      points_[at.face].push_back(p);
    }
  }

  MapsParameterization& maps_;
  const BaseFlipOptions& options_;
  std::vector<std::vector<int>> points_;
};

}  // namespace

BaseFlipStats flip_base_edges(MapsParameterization& maps, const BaseFlipOptions& options) {
  return BaseFlipper(maps, options).run();
}

}  // namespace mrsnake
