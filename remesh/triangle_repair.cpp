#include "remesh/triangle_repair.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include <Eigen/Dense>
#include <boost/container/small_vector.hpp>

#include "mesh/quality.h"
#include "remesh/lift.h"
#include "remesh/surface_moves.h"

namespace mrsnake {
namespace {

// A move of the repair: v at u in D, lifted to x (found from `hint`), its star's smallest quality q.
struct Candidate {
  double q;
  Eigen::Vector3d u, x;
  int hint;
};

}  // namespace

TriangleRepairStats repair_worst_triangles(DomainKind kind, const RowMatrixX3i& F, const DomainMesh& param,
                                           const RowMatrixX3d& surface_V, RowMatrixX3d& U, RowMatrixX3d& X,
                                           std::vector<int>& hints, const TriangleRepairOptions& options) {
  const int n = static_cast<int>(U.rows());
  const int m = static_cast<int>(F.rows());
  const VertexStars stars(F, n);
  const std::vector<bool> boundary =
      kind == DomainKind::disk ? boundary_vertices(F, stars) : std::vector<bool>(n, false);
  const auto& PF = param.faces();
  const auto& PD = param.positions();
  auto quality = [&](int f, int v, const Eigen::Vector3d& x) {
    Eigen::Vector3d P[3] = {X.row(F(f, 0)), X.row(F(f, 1)), X.row(F(f, 2))};
    for (int k = 0; k < 3; ++k)
      if (F(f, k) == v) P[k] = x;
    return frey_borouchaki_quality(P[0], P[1], P[2]);
  };
  auto lift = [&](const Eigen::Vector3d& u, int& hint) {
    const DomainMesh::Location loc = param.locate(u, hint);
    hint = loc.face;
    const Eigen::Vector3d lifted = lift_location(surface_V, PF, loc);
    return options.project_onto ? Eigen::Vector3d(options.project_onto->closest(lifted).point) : lifted;
  };
  // How far v's triangles (v at u in D, x in 3D) leave the surface (star_surface_error), the
  // midpoints lifted through D with one walking hint.
  auto surface_error = [&](int v, const Eigen::Vector3d& u, const Eigen::Vector3d& x, const Eigen::Vector3d& old) {
    int hint = hints[v];
    return star_surface_error(X, F, stars, v, x, old, [&](int w) -> std::optional<Eigen::Vector3d> {
      return lift(project_to_domain(kind, 0.5 * (u + U.row(w).transpose()), false), hint);
    });
  };
  const double mean_edge = mean_edge_length(X, F);

  // Each face's quality, kept current as vertices move: the sweeps' scans and the smallest
  // quality before and after read it.
  std::vector<double> face_quality(m);
  auto update_quality = [&](int f) { face_quality[f] = quality(f, -1, Eigen::Vector3d::Zero()); };
  auto smallest = [&] { return m > 0 ? *std::min_element(face_quality.begin(), face_quality.end()) : 0.0; };
  for (int f = 0; f < m; ++f) update_quality(f);

  TriangleRepairStats stats;
  stats.q_min_before = smallest();
  std::vector<std::pair<double, int>> poor;
  std::vector<int> visited(n, -1);
  RepairRetries retries(F, stars, n);
  for (int sweep = 0; sweep < options.sweeps; ++sweep) {
    poor.clear();
    for (int f = 0; f < m; ++f)
      if (face_quality[f] < options.threshold) poor.emplace_back(face_quality[f], f);
    if (poor.empty()) break;
    std::sort(poor.begin(), poor.end());
    int moved = 0;
    for (const auto& [q_face, face] : poor)
      for (int corner = 0; corner < 3; ++corner) {
        const int v = F(face, corner);
        if (visited[v] == sweep || (boundary[v] && !options.move_rim)) continue;
        if (options.fixed && (*options.fixed)[v]) continue;
        visited[v] = sweep;
        if (!retries.worth_trying(v)) continue;
        retries.failed(v);  // undone below if v moves
        const Eigen::Vector3d x = X.row(v);
        const double current = star_quality(X, F, stars, v, x);
        if (!(current < options.threshold)) continue;
        const std::optional<Eigen::Vector3d> normal = vertex_normal(X, F, stars, v);
        if (!normal) continue;
        const std::optional<std::array<Eigen::Vector3d, 3>> targets = repair_targets(X, F, stars, v, *normal);
        if (!targets) continue;
        // The affine map of the input triangle under v pulls a 3D move back to D.
        const std::optional<TrianglePullback> pullback = TrianglePullback::of(surface_V, PD, PF, hints[v]);
        if (!pullback) continue;
        const Eigen::Vector3d u = U.row(v);
        // The candidates that raise the star's smallest quality, best first: the guard, the
        // costly check, then runs only until one passes.
        boost::container::small_vector<Candidate, 9> better;
        for (const Eigen::Vector3d& target : *targets) {
          Eigen::Vector3d move = target - x;
          move -= move.dot(*normal) * *normal;
          const Eigen::Vector3d domain_move = pullback->to_domain(move);
          for (double t : {1.0, 0.5, 0.25}) {
            const Eigen::Vector3d candidate = project_to_domain(kind, u + t * domain_move, boundary[v]);
            if (!star_unflipped_in_domain(U, F, stars, v, candidate)) continue;
            int hint = hints[v];
            const Eigen::Vector3d lifted = lift(candidate, hint);
            const double q = star_quality(X, F, stars, v, lifted);
            if (q > current + 1e-9) better.push_back({q, candidate, lifted, hint});
          }
        }
        double allowed_error = -1;  // computed when a candidate first needs it
        const Candidate* chosen = best_passing(better, [&](const Candidate& c) {
          if (!options.guard_surface_error) return true;
          if (allowed_error < 0)
            allowed_error = std::max(surface_error(v, u, x, x), options.error_tolerance * mean_edge);
          return !(surface_error(v, c.u, c.x, x) > allowed_error);
        });
        if (!chosen) continue;
        U.row(v) = chosen->u.transpose();
        X.row(v) = chosen->x.transpose();
        hints[v] = chosen->hint;
        for (int i = stars.offset[v]; i < stars.offset[v + 1]; ++i) update_quality(stars.faces[i]);
        retries.moved(v);
        ++moved;
      }
    stats.moves += moved;
    if (moved == 0) break;
  }
  stats.q_min_after = smallest();
  return stats;
}

}  // namespace mrsnake
