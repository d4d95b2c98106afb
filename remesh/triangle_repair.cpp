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
#include "remesh/split_sweep.h"
#include "remesh/surface_moves.h"

namespace mrsnake {
namespace {

// A move of the repair: v at u in D, lifted to x (found from `hint`), its star's smallest quality q.
struct Candidate {
  double q;
  Eigen::Vector3d u, x;
  int hint;
};

// The repair of one level: the level, its domain, and each face's quality kept current as
// vertices move (the sweeps' scans and the smallest quality before and after read it).
class Repair {
 public:
  Repair(DomainKind kind, const RowMatrixX3i& F, const DomainMesh& param, const RowMatrixX3d& surface_V,
         RowMatrixX3d& U, RowMatrixX3d& X, std::vector<int>& hints, const TriangleRepairOptions& options)
      : kind_(kind),
        F_(F),
        param_(param),
        surface_V_(surface_V),
        U_(U),
        X_(X),
        hints_(hints),
        options_(options),
        stars_(F, static_cast<int>(U.rows())),
        boundary_(kind == DomainKind::disk ? boundary_vertices(F, stars_)
                                           : std::vector<bool>(static_cast<std::size_t>(U.rows()), false)),
        mean_edge_(mean_edge_length(X, F)),
        face_quality_(static_cast<std::size_t>(F.rows())) {
    for (int f = 0; f < F.rows(); ++f) update_quality(f);
  }

  const VertexStars& stars() const { return stars_; }

  double smallest_quality() const {
    return face_quality_.empty() ? 0.0 : *std::min_element(face_quality_.begin(), face_quality_.end());
  }

  // The faces below the threshold, worst first.
  std::vector<std::pair<double, int>> poor_faces() const { return faces_below(face_quality_, options_.threshold); }

  // Whether v may move at all: not a fixed vertex, nor a rim vertex when the rim stays.
  bool movable(int v) const {
    return !(boundary_[v] && !options_.move_rim) && !(options_.fixed && (*options_.fixed)[v]);
  }

  // v to its best candidate, if one raises its star's smallest quality within the guard.
  // Writes only v and the qualities of its star's faces. Returns whether v moved.
  bool repair_vertex(int v) {
    const std::optional<Candidate> chosen = best_move(v);
    if (!chosen) return false;
    U_.row(v) = chosen->u.transpose();
    X_.row(v) = chosen->x.transpose();
    hints_[v] = chosen->hint;
    for (int i = stars_.offset[v]; i < stars_.offset[v + 1]; ++i) update_quality(stars_.faces[i]);
    return true;
  }

 private:
  void update_quality(int f) {
    face_quality_[f] = frey_borouchaki_quality(X_.row(F_(f, 0)).transpose(), X_.row(F_(f, 1)).transpose(),
                                               X_.row(F_(f, 2)).transpose());
  }

  Eigen::Vector3d lift(const Eigen::Vector3d& u, int& hint) const {
    const DomainMesh::Location loc = param_.locate(u, hint);
    hint = loc.face;
    const Eigen::Vector3d lifted = lift_location(surface_V_, param_.faces(), loc);
    return options_.project_onto ? Eigen::Vector3d(options_.project_onto->closest(lifted).point) : lifted;
  }

  // How far v's triangles (v at u in D, x in 3D) leave the surface (star_surface_error), the
  // midpoints lifted through D with one walking hint.
  double surface_error(int v, const Eigen::Vector3d& u, const Eigen::Vector3d& x, const Eigen::Vector3d& old) const {
    int hint = hints_[v];
    return star_surface_error(X_, F_, stars_, v, x, old, [&](int w) -> std::optional<Eigen::Vector3d> {
      return lift(project_to_domain(kind_, 0.5 * (u + U_.row(w).transpose()), false), hint);
    });
  }

  // The candidates (repair_targets() at full, half and quarter steps, pulled back to D through
  // the affine map of the input triangle under v) that keep v's star unflipped in D and raise
  // its smallest quality above `current`.
  boost::container::small_vector<Candidate, 9> better_candidates(int v, double current) const {
    boost::container::small_vector<Candidate, 9> better;
    const std::optional<Eigen::Vector3d> normal = vertex_normal(X_, F_, stars_, v);
    if (!normal) return better;
    const std::optional<std::array<Eigen::Vector3d, 3>> targets = repair_targets(X_, F_, stars_, v, *normal);
    const std::optional<TrianglePullback> pullback =
        TrianglePullback::of(surface_V_, param_.positions(), param_.faces(), hints_[v]);
    if (!targets || !pullback) return better;
    const Eigen::Vector3d x = X_.row(v), u = U_.row(v);
    for (const Eigen::Vector3d& target : *targets) {
      Eigen::Vector3d move = target - x;
      move -= move.dot(*normal) * *normal;
      const Eigen::Vector3d domain_move = pullback->to_domain(move);
      for (double t : {1.0, 0.5, 0.25}) {
        const Eigen::Vector3d candidate = project_to_domain(kind_, u + t * domain_move, boundary_[v]);
        if (!star_unflipped_in_domain(U_, F_, stars_, v, candidate)) continue;
        int hint = hints_[v];
        const Eigen::Vector3d lifted = lift(candidate, hint);
        const double q = star_quality(X_, F_, stars_, v, lifted);
        if (q > current + 1e-9) better.push_back({q, candidate, lifted, hint});
      }
    }
    return better;
  }

  // The best candidate within the guard, tried best first: the guard, the costly check, runs
  // only until one passes.
  std::optional<Candidate> best_move(int v) const {
    const Eigen::Vector3d x = X_.row(v), u = U_.row(v);
    const double current = star_quality(X_, F_, stars_, v, x);
    if (!(current < options_.threshold)) return std::nullopt;
    boost::container::small_vector<Candidate, 9> better = better_candidates(v, current);
    double allowed_error = -1;  // computed when a candidate first needs it
    const Candidate* chosen = best_passing(better, [&](const Candidate& c) {
      if (!options_.guard_surface_error) return true;
      if (allowed_error < 0) allowed_error = std::max(surface_error(v, u, x, x), options_.error_tolerance * mean_edge_);
      return !(surface_error(v, c.u, c.x, x) > allowed_error);
    });
    if (!chosen) return std::nullopt;
    return *chosen;
  }

  const DomainKind kind_;
  const RowMatrixX3i& F_;
  const DomainMesh& param_;
  const RowMatrixX3d& surface_V_;
  RowMatrixX3d& U_;
  RowMatrixX3d& X_;
  std::vector<int>& hints_;
  const TriangleRepairOptions& options_;
  const VertexStars stars_;
  const std::vector<bool> boundary_;
  const double mean_edge_;
  std::vector<double> face_quality_;
};

}  // namespace

TriangleRepairStats repair_worst_triangles(DomainKind kind, const RowMatrixX3i& F, const DomainMesh& param,
                                           const RowMatrixX3d& surface_V, RowMatrixX3d& U, RowMatrixX3d& X,
                                           std::vector<int>& hints, const TriangleRepairOptions& options) {
  const int n = static_cast<int>(U.rows());
  Repair repair(kind, F, param, surface_V, U, X, hints, options);
  const SplitSweep split(X, F, repair.stars());
  TriangleRepairStats stats;
  stats.q_min_before = repair.smallest_quality();
  std::vector<int> visited(n, -1);
  RepairRetries retries(F, repair.stars(), n);
  for (int sweep = 0; sweep < options.sweeps; ++sweep) {
    const std::vector<std::pair<double, int>> poor = repair.poor_faces();
    if (poor.empty()) break;
    const int moves = repair_sweep(
        split, F, poor, sweep, visited, retries, [&](int v) { return repair.movable(v); },
        [&](int v) { return repair.repair_vertex(v); });
    stats.moves += moves;
    if (moves == 0) break;
  }
  stats.q_min_after = repair.smallest_quality();
  return stats;
}

}  // namespace mrsnake
