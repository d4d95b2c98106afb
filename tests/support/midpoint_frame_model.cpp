#include "tests/support/midpoint_frame_model.h"

#include <algorithm>
#include <memory>
#include <vector>

#include "mesh/normals.h"

namespace mrsnake {
namespace {

// Frame of the parent edge (a, b) from the coarse positions and vertex normals.
Eigen::Matrix3d edge_frame(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& na,
                           const Eigen::Vector3d& nb) {
  Eigen::Vector3d t = b - a;
  t.normalize();
  Eigen::Vector3d n = na + nb;
  n -= n.dot(t) * t;
  if (n.norm() < 1e-12) n = t.unitOrthogonal();
  n.normalize();
  Eigen::Matrix3d R;
  R.col(0) = t;
  R.col(1) = n.cross(t);
  R.col(2) = n;
  return R;
}
}  // namespace

SnakeModel midpoint_frame_model(const SubdivisionConnectivity& conn, const RowMatrixX3d& finest) {
  SnakeModel m;
  m.connectivity = conn;
  const int L = conn.levels();
  for (int j = 0; j <= L; ++j) m.levels.push_back(finest.topRows(conn.vertex_count(j)));
  // Details of level j+1 in the frames of level j.
  auto details = std::make_shared<std::vector<RowMatrixX3d>>();
  RowMatrixX3d N;
  for (int j = 0; j < L; ++j) {
    const RowMatrixX3d& C = m.levels[j];
    vertex_normals(C, conn.faces[j], N);
    const int n0 = conn.vertex_count(j), n1 = conn.vertex_count(j + 1);
    RowMatrixX3d D(n1 - n0, 3);
    for (int v = n0; v < n1; ++v) {
      const Eigen::Vector2i p = conn.parents(v);
      const Eigen::Vector3d a = C.row(p[0]), b = C.row(p[1]);
      const Eigen::Matrix3d R = edge_frame(a, b, N.row(p[0]), N.row(p[1]));
      const double len = std::max(1e-12, (b - a).norm());
      D.row(v - n0) = (R.transpose() * (finest.row(v).transpose() - 0.5 * (a + b)) / len).transpose();
    }
    details->push_back(std::move(D));
  }
  auto connectivity = std::make_shared<SubdivisionConnectivity>(conn);
  m.synthesize = [details, connectivity](int j, const RowMatrixX3d& C) {
    const SubdivisionConnectivity& cn = *connectivity;
    RowMatrixX3d Nc;
    vertex_normals(C, cn.faces[j], Nc);
    const int n0 = cn.vertex_count(j), n1 = cn.vertex_count(j + 1);
    RowMatrixX3d F(n1, 3);
    F.topRows(n0) = C;
    const RowMatrixX3d& D = (*details)[j];
    for (int v = n0; v < n1; ++v) {
      const Eigen::Vector2i p = cn.parents(v);
      const Eigen::Vector3d a = C.row(p[0]), b = C.row(p[1]);
      const Eigen::Matrix3d R = edge_frame(a, b, Nc.row(p[0]), Nc.row(p[1]));
      F.row(v) = (0.5 * (a + b) + (b - a).norm() * (R * D.row(v - n0).transpose())).transpose();
    }
    return F;
  };
  return m;
}

}  // namespace mrsnake
