#include "remesh/feature_snap.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "mesh/distance.h"
#include "mesh/quality.h"
#include "remesh/surface_moves.h"

namespace mrsnake {

int snap_to_input_tips(DomainKind kind, const RowMatrixX3i& F, const DomainMesh& param, const RowMatrixX3d& surface_V,
                       RowMatrixX3d& U, RowMatrixX3d& X, std::vector<int>& hints, const FeatureSnapOptions& options) {
  const int n = static_cast<int>(U.rows());
  const int m = static_cast<int>(F.rows());
  if (m == 0 || options.max_snaps <= 0) return 0;
  const std::vector<bool> rim = kind == DomainKind::disk ? boundary_vertices(F, n) : std::vector<bool>(n, false);
  const VertexStars stars(F, n);
  const auto& PF = param.faces();
  const auto& PD = param.positions();
  const std::vector<bool> input_rim =
      kind == DomainKind::disk ? boundary_vertices(PF, static_cast<int>(PD.rows())) : std::vector<bool>(PD.rows(), false);
  std::vector<int> face_of(PD.rows(), -1);  // one face of the input around each of its vertices
  for (int f = 0; f < PF.rows(); ++f)
    for (int k = 0; k < 3; ++k) face_of[PF(f, k)] = f;
  double mean_edge = 0;
  for (int f = 0; f < m; ++f)
    for (int k = 0; k < 3; ++k) mean_edge += (X.row(F(f, k)) - X.row(F(f, (k + 1) % 3))).norm();
  mean_edge /= 3.0 * m;

  const SurfaceLocator level(TriMesh{X, F});
  const Eigen::VectorXd distance = level.distances(surface_V);
  std::vector<int> far;
  for (int s = 0; s < distance.size(); ++s)
    if (distance[s] > options.min_distance * mean_edge && face_of[s] >= 0 && !input_rim[s]) far.push_back(s);
  std::sort(far.begin(), far.end(), [&](int a, int b) { return distance[a] > distance[b] || (distance[a] == distance[b] && a < b); });

  auto star_quality = [&](int v, const Eigen::Vector3d& x) {
    double q = 1;
    for (int i = stars.offset[v]; i < stars.offset[v + 1]; ++i) {
      const int f = stars.faces[i];
      Eigen::Vector3d P[3] = {X.row(F(f, 0)), X.row(F(f, 1)), X.row(F(f, 2))};
      for (int k = 0; k < 3; ++k)
        if (F(f, k) == v) P[k] = x;
      q = std::min(q, frey_borouchaki_quality(P[0], P[1], P[2]));
    }
    return q;
  };
  // Smallest angle (degrees) of v's triangles with v at x.
  auto star_angle = [&](int v, const Eigen::Vector3d& x) {
    double smallest = 180;
    for (int i = stars.offset[v]; i < stars.offset[v + 1]; ++i) {
      const int f = stars.faces[i];
      Eigen::Vector3d P[3] = {X.row(F(f, 0)), X.row(F(f, 1)), X.row(F(f, 2))};
      for (int k = 0; k < 3; ++k)
        if (F(f, k) == v) P[k] = x;
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d a = P[(k + 1) % 3] - P[k], b = P[(k + 2) % 3] - P[k];
        smallest = std::min(smallest, std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / M_PI);
      }
    }
    return smallest;
  };
  std::vector<bool> moved(n, false);
  int snaps = 0;
  for (int s : far) {
    if (snaps >= options.max_snaps) break;
    // The level vertex nearest the tip: the closest corner of the level face nearest to it.
    const SurfaceLocator::Hit hit = level.closest(surface_V.row(s).transpose());
    int v = -1;
    double best = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) {
      const int w = F(hit.face, k);
      const double d = (X.row(w) - surface_V.row(s)).squaredNorm();
      if (d < best) {
        best = d;
        v = w;
      }
    }
    if (v < 0 || moved[v] || rim[v]) continue;
    const Eigen::Vector3d u = project_to_domain(kind, PD.row(s).transpose(), false);
    const Eigen::Vector3d x = surface_V.row(s).transpose();
    if (!star_unflipped_in_domain(U, F, stars, v, u)) continue;
    if (star_quality(v, x) < options.min_quality || star_angle(v, x) < options.min_angle_deg) continue;
    U.row(v) = u.transpose();
    X.row(v) = x.transpose();
    hints[v] = face_of[s];
    moved[v] = true;
    ++snaps;
  }
  return snaps;
}

}  // namespace mrsnake
