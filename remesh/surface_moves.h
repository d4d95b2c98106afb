#pragma once
/// \file surface_moves.h
/// Small pieces shared by the steps that move the vertices of a level over the input surface in
/// 3D and carry each move back to the parameter domain D (shape_smoothing.h, triangle_repair.h):
/// the vertex normal, the no-flip check of a vertex's star in D, the equilateral apex of an edge, and the
/// pull-back of a 3D move through the affine map of one input triangle.
#include <cmath>
#include <optional>

#include <Eigen/Dense>

#include "mesh/trimesh.h"
#include "mesh/vertex_stars.h"
#include "remesh/domain.h"

namespace mrsnake {

/// The unit area-weighted normal of vertex v of (X, F), or nullopt where its faces cancel out.
inline std::optional<Eigen::Vector3d> vertex_normal(const RowMatrixX3d& X, const RowMatrixX3i& F, const VertexStars& stars,
                                                    int v) {
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
