#pragma once
/// \file trimesh.h
/// The triangle mesh shared by every module: plain Eigen matrices (libigl style).
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace mrsnake {

using RowMatrixX3d = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using RowMatrixX3i = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;
using RowMatrixX2i = Eigen::Matrix<int, Eigen::Dynamic, 2, Eigen::RowMajor>;

/// A triangle mesh: vertex positions V (n×3, physical coordinates in mm) and faces F
/// (m×3, counter-clockwise seen from outside, 0-based vertex indices).
struct TriMesh {
  RowMatrixX3d V;
  RowMatrixX3i F;

  int num_vertices() const { return static_cast<int>(V.rows()); }
  int num_faces() const { return static_cast<int>(F.rows()); }
  bool empty() const { return F.rows() == 0; }
};

/// Length of the diagonal of the axis-aligned bounding box of V (0 for an empty mesh).
inline double bounding_box_diagonal(const RowMatrixX3d& V) {
  if (V.rows() == 0) return 0.0;
  return (V.colwise().maxCoeff() - V.colwise().minCoeff()).norm();
}

}  // namespace mrsnake
