#include "mesh/normals.h"

namespace mrsnake {

void face_normals(const RowMatrixX3d& V, const RowMatrixX3i& F, RowMatrixX3d& N) {
  N.resize(F.rows(), 3);
  for (int f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    Eigen::Vector3d n = (b - a).cross(c - a);
    const double len = n.norm();
    N.row(f) = len > 0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d::Zero();
  }
}

void vertex_normals(const RowMatrixX3d& V, const RowMatrixX3i& F, RowMatrixX3d& N) {
  N.setZero(V.rows(), 3);
  for (int f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a);  // twice the area times the unit normal
    for (int k = 0; k < 3; ++k) N.row(F(f, k)) += n.transpose();
  }
  for (int v = 0; v < N.rows(); ++v) {
    const double len = N.row(v).norm();
    if (len > 0) N.row(v) /= len;
  }
}

}  // namespace mrsnake
