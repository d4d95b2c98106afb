#include "remesh/feature_snap.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "mesh/distance.h"
#include "mesh/parallel.h"
#include "remesh/surface_moves.h"

namespace mrsnake {

int snap_level_to_input_tips(const RowMatrixX3i& F, RowMatrixX3d& X, const RowMatrixX3d& surface_V,
                             const RowMatrixX3i& input_F, const std::vector<bool>& rim,
                             const std::vector<bool>& input_rim, const SnapInDomain& domain,
                             const FeatureSnapOptions& options, std::vector<bool>* snapped) {
  const int n = static_cast<int>(X.rows());
  const int m = static_cast<int>(F.rows());
  if (snapped) snapped->assign(n, false);
  if (m == 0 || options.max_snaps <= 0) return 0;
  const VertexStars stars(F, n);
  const int input_vertices = static_cast<int>(surface_V.rows());
  std::vector<int> face_of(input_vertices, -1);  // one face of the input around each of its vertices
  for (int f = 0; f < input_F.rows(); ++f)
    for (int k = 0; k < 3; ++k) face_of[input_F(f, k)] = f;
  const double threshold = options.min_distance * mean_edge_length(X, F);

  // The level face nearest to each input vertex, before any snap; the input vertices under
  // each level face (so that a snap can be judged on the input around it).
  const SurfaceLocator level(TriMesh{X, F});
  std::vector<int> nearest_face(input_vertices);
  std::vector<double> distance(input_vertices);
  // Every input vertex is queried (90k on a liver): both cores.
  parallel_ranges(static_cast<std::size_t>(input_vertices), [&](std::size_t begin, std::size_t end) {
    for (auto s = static_cast<int>(begin); s < static_cast<int>(end); ++s) {
      const SurfaceLocator::Hit hit = level.closest(surface_V.row(s).transpose());
      nearest_face[s] = hit.face;
      distance[s] = hit.distance;
    }
  });
  std::vector<int> under_offset(m + 1, 0), under;
  for (int s = 0; s < input_vertices; ++s) ++under_offset[nearest_face[s] + 1];
  for (int f = 0; f < m; ++f) under_offset[f + 1] += under_offset[f];
  under.resize(under_offset[m]);
  {
    std::vector<int> fill(under_offset.begin(), under_offset.end() - 1);
    for (int s = 0; s < input_vertices; ++s) under[fill[nearest_face[s]]++] = s;
  }
  const double largest = *std::max_element(distance.begin(), distance.end());
  const double far_threshold = std::max(threshold, options.min_share_of_largest * largest);
  std::vector<int> far;
  for (int s = 0; s < input_vertices; ++s)
    if (distance[s] > far_threshold && face_of[s] >= 0 && !input_rim[s]) far.push_back(s);
  std::sort(far.begin(), far.end(),
            [&](int a, int b) { return distance[a] > distance[b] || (distance[a] == distance[b] && a < b); });

  // The faces of v's star and of its neighbours' stars: the triangles a move of v can change
  // the nearest point on, for the input near v.
  std::vector<int> region, region_mark(m, -1);
  int stamp = 0;
  auto collect_region = [&](int v) {
    region.clear();
    ++stamp;
    for (int i = stars.offset[v]; i < stars.offset[v + 1]; ++i)
      for (int k = 0; k < 3; ++k) {
        const int w = F(stars.faces[i], k);
        for (int j = stars.offset[w]; j < stars.offset[w + 1]; ++j) {
          const int f = stars.faces[j];
          if (region_mark[f] == stamp) continue;
          region_mark[f] = stamp;
          region.push_back(f);
        }
      }
  };
  // Distance from p to the region's triangles with v at x.
  auto region_distance = [&](const Eigen::Vector3d& p, int v, const Eigen::Vector3d& x) {
    double d = std::numeric_limits<double>::infinity();
    for (int f : region) {
      Eigen::Vector3d P[3] = {X.row(F(f, 0)), X.row(F(f, 1)), X.row(F(f, 2))};
      for (int k = 0; k < 3; ++k)
        if (F(f, k) == v) P[k] = x;
      d = std::min(d, point_triangle_distance(p, P[0], P[1], P[2]));
    }
    return d;
  };
  // The largest distance from the input vertices under the region to its triangles, v at x.
  auto region_error = [&](int v, const Eigen::Vector3d& x) {
    double error = 0;
    for (int f : region)
      for (int i = under_offset[f]; i < under_offset[f + 1]; ++i)
        error = std::max(error, region_distance(surface_V.row(under[i]).transpose(), v, x));
    return error;
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
  const RowMatrixX3d X_before = X;
  int snaps = 0, judged = 0;
  const int max_judged = 8 * options.max_snaps;  // the region error is the costly part
  for (int s : far) {
    if (snaps >= options.max_snaps || judged >= max_judged) break;
    // The level vertex nearest the tip: the closest corner of the level face nearest to it.
    const int face = nearest_face[s];
    int v = -1;
    double best = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) {
      const int w = F(face, k);
      const double d = (X.row(w) - surface_V.row(s)).squaredNorm();
      if (d < best) {
        best = d;
        v = w;
      }
    }
    if (v < 0 || moved[v] || rim[v]) continue;
    const Eigen::Vector3d x = surface_V.row(s).transpose();
    const Eigen::Vector3d x_old = X.row(v).transpose();
    collect_region(v);
    // An earlier snap nearby may have fixed this tip already: its distance now, not before.
    if (!(region_distance(x, v, x_old) > threshold)) continue;
    if (!domain.allowed(v, s)) continue;
    if (star_quality(X, F, stars, v, x) < options.min_quality || star_angle(v, x) < options.min_angle_deg) continue;
    // Worth it only if the input around v ends up really closer to the level: moving v onto s
    // also moves its triangles away from the input v stood on.
    ++judged;
    const double before = region_error(v, x_old), after = region_error(v, x);
    if (!(after <= (1 - options.min_gain) * before)) continue;
    domain.apply(v, s);
    X.row(v) = x.transpose();
    moved[v] = true;
    ++snaps;
  }
  // The snaps cost triangle quality: keep them only if they really bring the input closer
  // overall (the largest distance drops), not only around each snapped vertex.
  if (snaps > 0) {
    // "The largest distance after <= limit" (the same decision as querying the whole input,
    // up to rounding), without querying the whole input again:
    // an input vertex whose nearest face did not change is at most as far as before (that
    // face is still there), so only those nearest to a changed face and those that were
    // already beyond the limit can be beyond it now.
    const double limit = (1 - options.min_gain) * largest;
    std::vector<bool> changed(m, false);
    for (int v = 0; v < n; ++v)
      if (moved[v])
        for (int i = stars.offset[v]; i < stars.offset[v + 1]; ++i) changed[stars.faces[i]] = true;
    std::vector<int> recheck;
    for (int s = 0; s < input_vertices; ++s)
      if (changed[nearest_face[s]] || distance[s] > limit) recheck.push_back(s);
    RowMatrixX3d points(static_cast<Eigen::Index>(recheck.size()), 3);
    for (std::size_t i = 0; i < recheck.size(); ++i)
      points.row(static_cast<Eigen::Index>(i)) = surface_V.row(recheck[i]);
    const double largest_after = recheck.empty() ? 0.0 : SurfaceLocator(TriMesh{X, F}).distances(points).maxCoeff();
    if (!(largest_after <= limit)) {
      X = X_before;
      domain.undo();
      if (snapped) snapped->assign(n, false);
      return 0;
    }
  }
  if (snapped) *snapped = moved;
  return snaps;
}

int snap_to_input_tips(DomainKind kind, const RowMatrixX3i& F, const DomainMesh& param, const RowMatrixX3d& surface_V,
                       RowMatrixX3d& U, RowMatrixX3d& X, std::vector<int>& hints, const FeatureSnapOptions& options,
                       std::vector<bool>* snapped) {
  const int n = static_cast<int>(U.rows());
  const VertexStars stars(F, n);
  const auto& PF = param.faces();
  const auto& PD = param.positions();
  const bool disk = kind == DomainKind::disk;
  std::vector<int> face_of(PD.rows(), -1);
  for (int f = 0; f < PF.rows(); ++f)
    for (int k = 0; k < 3; ++k) face_of[PF(f, k)] = f;
  const RowMatrixX3d U_before = U;
  const std::vector<int> hints_before = hints;
  const auto point_of = [&](int s) { return project_to_domain(kind, PD.row(s).transpose(), false); };
  const SnapInDomain domain{[&](int v, int s) { return star_unflipped_in_domain(U, F, stars, v, point_of(s)); },
                            [&](int v, int s) {
                              U.row(v) = point_of(s).transpose();
                              hints[v] = face_of[s];
                            },
                            [&] {
                              U = U_before;
                              hints = hints_before;
                            }};
  return snap_level_to_input_tips(
      F, X, surface_V, PF, disk ? boundary_vertices(F, stars) : std::vector<bool>(n, false),
      disk ? boundary_vertices(PF, static_cast<int>(PD.rows())) : std::vector<bool>(PD.rows(), false), domain, options,
      snapped);
}

}  // namespace mrsnake
