#include "remesh/shape_smoothing.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include <Eigen/Dense>

#include "remesh/lift.h"
#include "remesh/split_sweep.h"
#include "remesh/surface_moves.h"

namespace mrsnake {

std::optional<Eigen::Vector3d> tangential_move(const RowMatrixX3d& X, const RowMatrixX3i& F, const VertexStars& stars,
                                               int v, SmoothingTarget target, const Eigen::VectorXd& vertex_density) {
  const std::optional<Eigen::Vector3d> normal = vertex_normal(X, F, stars, v);
  if (!normal) return std::nullopt;
  const Eigen::Vector3d x = X.row(v);
  Eigen::Vector3d aim = Eigen::Vector3d::Zero();
  double total = 0;
  for (int i = stars.offset[v]; i < stars.offset[v + 1]; ++i) {
    const int f = stars.faces[i];
    int k = 0;
    while (F(f, k) != v) ++k;
    const int ia = F(f, (k + 1) % 3), ib = F(f, (k + 2) % 3);
    const Eigen::Vector3d a = X.row(ia), b = X.row(ib);
    if (target == SmoothingTarget::equilateral_apexes) {
      if (const auto apex = equilateral_apex(a, b, *normal)) {
        aim += *apex;
        total += 1;
      }
    } else {
      const double rho = (vertex_density[v] + vertex_density[ia] + vertex_density[ib]) / 3.0;
      const double weight = 0.5 * (a - x).cross(b - x).norm() * rho * rho;
      aim += weight * (x + a + b) / 3.0;
      total += weight;
    }
  }
  if (!(total > 0)) return std::nullopt;
  Eigen::Vector3d move = aim / total - x;
  move -= move.dot(*normal) * *normal;
  return move;
}

namespace {

// What a smoothing move of one vertex reads: the level's connectivity, its domain and the options.
struct SmoothingContext {
  DomainKind kind;
  const RowMatrixX3i& F;
  const VertexStars& stars;
  const DomainMesh& param;
  const RowMatrixX3d& surface_V;
  const std::vector<bool>& boundary;
  const std::vector<Eigen::Vector2i>& rim;  // a rim vertex's two rim neighbours, when the rim moves
  const ShapeSmoothingOptions& options;
};

// The 3D move of v: along the rim toward the midpoint of its rim neighbours, or tangentially
// toward its target; nullopt where it has none.
std::optional<Eigen::Vector3d> wanted_move(const SmoothingContext& c, const RowMatrixX3d& X,
                                           const Eigen::VectorXd& vertex_density, int v) {
  if (!c.boundary[v]) return tangential_move(X, c.F, c.stars, v, c.options.target, vertex_density);
  const int prev = c.rim[v][0], next = c.rim[v][1];
  if (prev < 0 || next < 0) return std::nullopt;
  const Eigen::Vector3d a = X.row(prev), b = X.row(next), x = X.row(v);
  if (!((b - a).norm() > 0)) return std::nullopt;
  const Eigen::Vector3d tangent = (b - a).normalized();
  return Eigen::Vector3d((0.5 * (a + b) - x).dot(tangent) * tangent);
}

// Vertex v by the first of step, step/2, ... of its wanted move (pulled back to D through the
// affine map of the input triangle under it) that keeps its star unflipped in D and, with a
// floor, its smallest Q. Writes only v. Returns whether it moved.
bool smooth_vertex(const SmoothingContext& c, const Eigen::VectorXd& vertex_density, int v, RowMatrixX3d& U,
                   RowMatrixX3d& X, std::vector<int>& hints) {
  const bool on_rim = c.boundary[v];
  if (on_rim && !c.options.move_rim) return false;
  const std::optional<Eigen::Vector3d> move = wanted_move(c, X, vertex_density, v);
  if (!move) return false;
  const std::optional<TrianglePullback> pullback =
      TrianglePullback::of(c.surface_V, c.param.positions(), c.param.faces(), hints[v]);
  if (!pullback) return false;
  const Eigen::Vector3d domain_move = pullback->to_domain(*move);
  const Eigen::Vector3d current = U.row(v), x = X.row(v);
  const double floor =
      c.options.quality_floor > 0 ? std::min(star_quality(X, c.F, c.stars, v, x), c.options.quality_floor) : 0.0;
  double t = c.options.step;
  for (int attempt = 0; attempt < 8; ++attempt, t *= 0.5) {
    const Eigen::Vector3d candidate = project_to_domain(c.kind, current + t * domain_move, on_rim);
    if (!star_unflipped_in_domain(U, c.F, c.stars, v, candidate)) continue;
    const DomainMesh::Location loc = c.param.locate(candidate, hints[v]);
    const Eigen::Vector3d lifted = lift_location(c.surface_V, c.param.faces(), loc);
    if (c.options.quality_floor > 0 && star_quality(X, c.F, c.stars, v, lifted) < floor) continue;
    hints[v] = loc.face;
    U.row(v) = candidate.transpose();
    X.row(v) = lifted.transpose();
    return true;
  }
  return false;
}

}  // namespace

int smooth_shapes_in_domain(DomainKind kind, const RowMatrixX3i& F, const DomainMesh& param,
                            const RowMatrixX3d& surface_V, RowMatrixX3d& U, RowMatrixX3d& X, std::vector<int>& hints,
                            const ShapeSmoothingOptions& options) {
  const int n = static_cast<int>(U.rows());
  const VertexStars stars(F, n);
  const std::vector<std::pair<int, int>> rim_edges =
      kind == DomainKind::disk ? boundary_edges(F, stars) : std::vector<std::pair<int, int>>();
  std::vector<bool> boundary(n, false);
  for (const auto& [a, b] : rim_edges) boundary[a] = boundary[b] = true;
  const std::vector<Eigen::Vector2i> rim =
      kind == DomainKind::disk && options.move_rim ? rim_neighbours(rim_edges, n) : std::vector<Eigen::Vector2i>();
  const SmoothingContext context{kind, F, stars, param, surface_V, boundary, rim, options};
  const bool weighted = options.target == SmoothingTarget::area_centroid && options.surface_density != nullptr;
  // Wanted density under vertex v (its hint face holds it).
  auto density_at = [&](int v) {
    const DomainMesh::Location loc = param.locate(U.row(v).transpose(), hints[v]);
    const Eigen::VectorXd& w = *options.surface_density;
    const RowMatrixX3i& PF = param.faces();
    return loc.barycentric[0] * w[PF(loc.face, 0)] + loc.barycentric[1] * w[PF(loc.face, 1)] +
           loc.barycentric[2] * w[PF(loc.face, 2)];
  };
  const SplitSweep split(X, F, stars);
  Eigen::VectorXd vertex_density = Eigen::VectorXd::Ones(n);
  int moves = 0;
  for (int it = 0; it < options.iterations; ++it) {
    if (weighted)
      for (int v = 0; v < n; ++v) vertex_density[v] = density_at(v);
    std::array<int, SplitSweep::kParts> moved{};
    split.run([&](int part) {
      for (int v = options.first_movable; v < n; ++v)
        if (split.part(v) == part && smooth_vertex(context, vertex_density, v, U, X, hints)) ++moved[part];
    });
    moves += moved[0] + moved[1] + moved[2];
  }
  return moves;
}

}  // namespace mrsnake
