#include "remesh/sizing.h"

#include <vector>

namespace mrsnake {

Eigen::VectorXd vertex_curvature(const TriMesh& mesh, int smoothing) {
  const int n = mesh.num_vertices();
  RowMatrixX3d normal = RowMatrixX3d::Zero(n, 3);
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::RowVector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    const Eigen::RowVector3d area_normal = (b - a).cross(c - a);
    for (int k = 0; k < 3; ++k) normal.row(mesh.F(f, k)) += area_normal;
  }
  for (int v = 0; v < n; ++v)
    if (normal.row(v).norm() > 0) normal.row(v).normalize();
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(n), count = Eigen::VectorXd::Zero(n);
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int u = mesh.F(f, k), v = mesh.F(f, (k + 1) % 3);
      const double length = (mesh.V.row(u) - mesh.V.row(v)).norm();
      if (!(length > 0)) continue;
      const double change = (normal.row(u) - normal.row(v)).norm() / length;
      sum[u] += change;
      sum[v] += change;
      count[u] += 1;
      count[v] += 1;
    }
  return smooth_vertex_field(mesh, sum.cwiseQuotient(count.cwiseMax(1.0)), smoothing);
}

Eigen::VectorXd smooth_vertex_field(const TriMesh& mesh, Eigen::VectorXd field, int passes) {
  const int n = mesh.num_vertices();
  for (int pass = 0; pass < passes; ++pass) {
    Eigen::VectorXd next = field, weight = Eigen::VectorXd::Ones(n);
    for (int f = 0; f < mesh.num_faces(); ++f)
      for (int k = 0; k < 3; ++k) {
        const int u = mesh.F(f, k), v = mesh.F(f, (k + 1) % 3);
        next[u] += field[v];
        next[v] += field[u];
        weight[u] += 1;
        weight[v] += 1;
      }
    field = next.cwiseQuotient(weight);
  }
  return field;
}

}  // namespace mrsnake
