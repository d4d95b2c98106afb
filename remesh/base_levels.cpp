#include "remesh/base_levels.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>

#include <Eigen/Dense>
#include <boost/container/small_vector.hpp>

#include "mesh/errors.h"
#include "mesh/quality.h"
#include "mesh/vertex_stars.h"
#include "remesh/domain.h"
#include "remesh/split_sweep.h"
#include "remesh/surface_moves.h"

namespace mrsnake {
namespace {

double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  const Eigen::Vector2d u = b - a, w = c - a;
  return u.x() * w.y() - u.y() * w.x();
}

// The midpoint of the edge a -> b, whose faces are (a, b, left) and (b, a, right) (null on a
// disk's rim), in the chart holding all four that sees both faces counter-clockwise, deepest
// first: there the four halves of each face are counter-clockwise too. Else in any chart
// holding a and b whose star holds the midpoint (a star is star-shaped, not convex).
std::optional<BasePoint> edge_midpoint(const BaseDomain& domain, const BasePoint& a, const BasePoint& b,
                                       const BasePoint* left, const BasePoint* right) {
  std::optional<BasePoint> best, fallback;
  double best_depth = -1;
  for (const int c : domain.charts_holding(a)) {
    const std::optional<Eigen::Vector2d> chart_b = domain.chart_point(c, b);
    if (!chart_b) continue;
    const Eigen::Vector2d qa = domain.to_chart(c, a), qb = *chart_b;
    const std::optional<BasePoint> mid = domain.from_chart(c, 0.5 * (qa + qb));
    if (!mid) continue;
    if (!fallback) fallback = mid;
    // Whether the apex, if any, is in the chart on the side a -> b -> apex is counter-clockwise.
    const auto apex_ok = [&](const BasePoint* apex, const Eigen::Vector2d& from, const Eigen::Vector2d& to) {
      if (!apex) return true;
      const std::optional<Eigen::Vector2d> q = domain.chart_point(c, *apex);
      return q && cross2(from, to, *q) > 0;
    };
    const bool left_ok = apex_ok(left, qa, qb), right_ok = apex_ok(right, qb, qa);
    if (!left_ok || !right_ok) continue;
    const double depth = domain.depth(c, a) + domain.depth(c, b) + (left ? domain.depth(c, *left) : 0.0) +
                         (right ? domain.depth(c, *right) : 0.0);
    if (depth > best_depth) {
      best = mid;
      best_depth = depth;
    }
  }
  return best ? best : fallback;
}

// For each directed edge a -> b of F (key a·n + b), the vertex opposite it in its face.
std::unordered_map<long long, int> edge_apexes(const RowMatrixX3i& F, int n) {
  std::unordered_map<long long, int> apex;
  apex.reserve(3 * F.rows());
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) apex[static_cast<long long>(F(f, k)) * n + F(f, (k + 1) % 3)] = F(f, (k + 2) % 3);
  return apex;
}

// Vertex v's point and every corner of its star, for the chart that must hold them all.
std::vector<BasePoint> star_points(const RowMatrixX3i& F, const VertexStars& stars, const BaseLayout& layout, int v) {
  std::vector<BasePoint> points{layout.points[v]};
  for (int i = stars.offset[v]; i < stars.offset[v + 1]; ++i)
    for (int k = 0; k < 3; ++k)
      if (F(stars.faces[i], k) != v) points.push_back(layout.points[F(stars.faces[i], k)]);
  return points;
}

// The move in chart c whose lift is move_3d's part in the plane of the input triangle under p,
// to first order; nullopt where that triangle is degenerate or not all in the chart.
std::optional<Eigen::Vector2d> pull_back(const BaseDomain& domain, const BaseLift& lift, int c, const BasePoint& p,
                                         const Eigen::Vector3d& move_3d) {
  const BaseLift::Hit hit = lift.locate(p);
  const RowMatrixX3i& F = lift.input_faces();
  const RowMatrixX3d& V = lift.input_vertices();
  Eigen::Matrix<double, 3, 2> edges_3d;
  Eigen::Matrix2d edges_chart;
  std::array<Eigen::Vector2d, 3> corner;
  for (int k = 0; k < 3; ++k) {
    const BasePoint& q = lift.location(F(hit.face, k));
    const std::optional<Eigen::Vector2d> in_chart = domain.chart_point(c, q);
    if (!in_chart) return std::nullopt;
    corner[k] = *in_chart;
  }
  for (int k = 0; k < 2; ++k) {
    edges_3d.col(k) = (V.row(F(hit.face, k + 1)) - V.row(F(hit.face, 0))).transpose();
    edges_chart.col(k) = corner[k + 1] - corner[0];
  }
  const Eigen::Matrix2d gram = edges_3d.transpose() * edges_3d;
  if (!(std::abs(gram.determinant()) > 0)) return std::nullopt;
  return Eigen::Vector2d(edges_chart * gram.ldlt().solve(edges_3d.transpose() * move_3d));
}

// The move in chart c whose lift is move_3d's tangential part, to first order, from the
// level's own star: the linear map that best takes the 3D edges from v (in the tangent plane
// of `normal`) to the same edges in the chart. For a vertex whose input triangle reaches out of
// the chart. nullopt where the star is degenerate in 3D.
std::optional<Eigen::Vector2d> pull_back_by_star(const BaseDomain& domain, const RowMatrixX3i& F,
                                                 const VertexStars& stars, const BaseLayout& layout, int c, int v,
                                                 const Eigen::Vector3d& normal, const Eigen::Vector3d& move_3d) {
  const Eigen::Vector3d t1 = normal.unitOrthogonal(), t2 = normal.cross(t1);
  const Eigen::Vector3d x = layout.X.row(v);
  const Eigen::Vector2d q = domain.to_chart(c, layout.points[v]);
  Eigen::Matrix2d edges_edges = Eigen::Matrix2d::Zero(), chart_edges = Eigen::Matrix2d::Zero();
  for (int i = stars.offset[v]; i < stars.offset[v + 1]; ++i)
    for (int k = 0; k < 3; ++k) {
      const int w = F(stars.faces[i], k);
      if (w == v) continue;
      const Eigen::Vector3d e = layout.X.row(w).transpose() - x;
      const Eigen::Vector2d d(t1.dot(e), t2.dot(e));
      edges_edges += d * d.transpose();
      chart_edges += (domain.to_chart(c, layout.points[w]) - q) * d.transpose();
    }
  if (!(std::abs(edges_edges.determinant()) > 0)) return std::nullopt;
  return Eigen::Vector2d(chart_edges * edges_edges.inverse() * Eigen::Vector2d(t1.dot(move_3d), t2.dot(move_3d)));
}

// The triangles of v's star, with v at p, that are not counter-clockwise in the chart that
// count_flipped_on_base tests them in: the measure of the invariant itself.
int star_flips(const BaseDomain& domain, const RowMatrixX3i& F, const VertexStars& stars, const BaseLayout& layout,
               int v, const BasePoint& p) {
  int flips = 0;
  for (int i = stars.offset[v]; i < stars.offset[v + 1]; ++i) {
    const int f = stars.faces[i];
    BasePoint corner[3];
    for (int k = 0; k < 3; ++k) corner[k] = F(f, k) == v ? p : layout.points[F(f, k)];
    if (!domain.counter_clockwise(corner[0], corner[1], corner[2])) ++flips;
  }
  return flips;
}

// Vertex v to the first of at(step), at(step/2), … (positions in chart c; six tries) that adds
// no flipped triangle to its star and, with a floor, keeps its smallest Q above
// min(its value before, the floor). Charts disagree a little across K's edges, so a split can
// leave a triangle flipped in its own chart: a move may keep such flips but never add one, and
// smoothing undoes them. Returns whether v moved.
template <class At>
bool move_by_halving(const RowMatrixX3i& F, const VertexStars& stars, const BaseDomain& domain, const BaseLift& lift,
                     const BaseSmoothingOptions& options, int c, int v, BaseLayout& layout, At&& at) {
  const Eigen::Vector3d x = layout.X.row(v);
  const double floor =
      options.quality_floor > 0 ? std::min(star_quality(layout.X, F, stars, v, x), options.quality_floor) : 0.0;
  const int flips = star_flips(domain, F, stars, layout, v, layout.points[v]);
  double t = options.step;
  for (int attempt = 0; attempt < 6; ++attempt, t *= 0.5) {
    const std::optional<BasePoint> p = domain.from_chart(c, at(t));
    if (!p || star_flips(domain, F, stars, layout, v, *p) > flips) continue;
    const Eigen::Vector3d lifted = lift.lift(*p);
    if (flips == 0 && options.quality_floor > 0 && star_quality(layout.X, F, stars, v, lifted) < floor) continue;
    layout.points[v] = *p;
    layout.X.row(v) = lifted.transpose();
    return true;
  }
  return false;
}

// One vertex toward its target, by the largest of step, step/2, ... that keeps its star
// unflipped and, with a floor, its smallest Q. Returns whether it moved.
bool move_vertex(const RowMatrixX3i& F, const VertexStars& stars, const BaseDomain& domain, const BaseLift& lift,
                 const BaseSmoothingOptions& options, const Eigen::VectorXd& density, int v, BaseLayout& layout) {
  const std::vector<BasePoint> points = star_points(F, stars, layout, v);
  const int c = domain.common_chart(points.data(), static_cast<int>(points.size()));
  if (c < 0) return false;
  const std::optional<Eigen::Vector3d> move = tangential_move(layout.X, F, stars, v, options.target, density);
  if (!move) return false;
  std::optional<Eigen::Vector2d> chart_move = pull_back(domain, lift, c, layout.points[v], *move);
  if (!chart_move)
    if (const std::optional<Eigen::Vector3d> normal = vertex_normal(layout.X, F, stars, v))
      chart_move = pull_back_by_star(domain, F, stars, layout, c, v, *normal, *move);
  if (!chart_move) return false;
  const Eigen::Vector2d start = domain.to_chart(c, layout.points[v]);
  return move_by_halving(F, stars, domain, lift, options, c, v, layout,
                         [&](double t) -> Eigen::Vector2d { return start + t * *chart_move; });
}

// Rim vertex v slid along the rim, between its rim neighbours a and b, toward the point that
// splits the 3D lengths a–v and v–b evenly. It moves on the chart segment a–b, which is the rim
// where the chart straightens it (a rim vertex of K flattens its rim to a line); where a, v and
// b are not collinear in the chart (a corner of K with one face), v stays. Returns whether it
// moved.
bool slide_rim_vertex(const RowMatrixX3i& F, const VertexStars& stars, const BaseDomain& domain, const BaseLift& lift,
                      const BaseSmoothingOptions& options, const Eigen::Vector2i& rim, int v, BaseLayout& layout) {
  if (rim[0] < 0 || rim[1] < 0) return false;
  const std::vector<BasePoint> points = star_points(F, stars, layout, v);
  const int c = domain.common_chart(points.data(), static_cast<int>(points.size()));
  if (c < 0 || !domain.in_star(c, layout.points[rim[0]]) || !domain.in_star(c, layout.points[rim[1]])) return false;
  const Eigen::Vector2d qa = domain.to_chart(c, layout.points[rim[0]]), qb = domain.to_chart(c, layout.points[rim[1]]);
  const Eigen::Vector2d qv = domain.to_chart(c, layout.points[v]), chord = qb - qa;
  const double length2 = chord.squaredNorm();
  const double s = (qv - qa).dot(chord) / length2;
  if (!(length2 > 0) || !(s > 0 && s < 1) || std::abs(cross2(qa, qv, qb)) > 1e-9 * length2) return false;
  // The 3D rim length as linear in s on each side: the s that evens the two.
  const Eigen::Vector3d x = layout.X.row(v);
  const double per_s_before = (x - layout.X.row(rim[0]).transpose()).norm() / s;
  const double per_s_after = (x - layout.X.row(rim[1]).transpose()).norm() / (1 - s);
  if (!(per_s_before + per_s_after > 0)) return false;
  const double even = per_s_after / (per_s_before + per_s_after);
  return move_by_halving(F, stars, domain, lift, options, c, v, layout,
                         [&](double t) -> Eigen::Vector2d { return qa + (s + t * (even - s)) * chord; });
}

// The wanted density under each vertex of the layout: even without a surface density.
Eigen::VectorXd density_under(const BaseLift& lift, const BaseLayout& layout, const Eigen::VectorXd* surface_density) {
  const int n = static_cast<int>(layout.points.size());
  Eigen::VectorXd density = Eigen::VectorXd::Ones(n);
  if (!surface_density) return density;
  const RowMatrixX3i& F = lift.input_faces();
  for (int v = 0; v < n; ++v) {
    const BaseLift::Hit hit = lift.locate(layout.points[v]);
    density[v] = hit.bary[0] * (*surface_density)[F(hit.face, 0)] + hit.bary[1] * (*surface_density)[F(hit.face, 1)] +
                 hit.bary[2] * (*surface_density)[F(hit.face, 2)];
  }
  return density;
}

// Vertex v to the mean of its ring in the chart that holds its star (Tutte's step: inside a
// star-shaped ring it unfolds the star), if that leaves fewer flipped triangles around it.
bool untangle_vertex(const RowMatrixX3i& F, const VertexStars& stars, const BaseDomain& domain, const BaseLift& lift,
                     int v, BaseLayout& layout) {
  const std::vector<BasePoint> points = star_points(F, stars, layout, v);
  const int c = domain.common_chart(points.data(), static_cast<int>(points.size()));
  if (c < 0) return false;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (std::size_t i = 1; i < points.size(); ++i) mean += domain.to_chart(c, points[i]) / (points.size() - 1.0);
  const std::optional<BasePoint> p = domain.from_chart(c, mean);
  if (!p || star_flips(domain, F, stars, layout, v, *p) >= star_flips(domain, F, stars, layout, v, layout.points[v]))
    return false;
  layout.points[v] = *p;
  layout.X.row(v) = lift.lift(*p).transpose();
  return true;
}

// How far v's triangles, with v at chart point q of chart c (lifted to x), leave the surface
// (star_surface_error), the midpoints taken in chart c.
double surface_error_on_base(const RowMatrixX3i& F, const VertexStars& stars, const BaseDomain& domain,
                             const BaseLift& lift, const BaseLayout& layout, int c, int v, const Eigen::Vector2d& q,
                             const Eigen::Vector3d& x, const Eigen::Vector3d& old) {
  return star_surface_error(layout.X, F, stars, v, x, old, [&](int w) -> std::optional<Eigen::Vector3d> {
    const std::optional<BasePoint> mid = domain.from_chart(c, 0.5 * (q + domain.to_chart(c, layout.points[w])));
    if (!mid) return std::nullopt;
    return lift.lift(*mid);
  });
}

// A move of the repair: v at chart point `chart` (the base point `point`), lifted to x; q is its
// star's smallest quality.
struct RepairCandidate {
  double q;
  Eigen::Vector2d chart;
  BasePoint point;
  Eigen::Vector3d x;
};

// The triangles of (X, F) with Q below `threshold`, worst first, with their Q.
std::vector<std::pair<double, int>> poor_faces(const RowMatrixX3d& X, const RowMatrixX3i& F, double threshold) {
  std::vector<double> quality(static_cast<std::size_t>(F.rows()));
  for (int f = 0; f < F.rows(); ++f)
    quality[f] =
        frey_borouchaki_quality(X.row(F(f, 0)).transpose(), X.row(F(f, 1)).transpose(), X.row(F(f, 2)).transpose());
  return faces_below(quality, threshold);
}

// Vertex v of a poor triangle to the candidate (repair_targets() at full, half and quarter
// steps) that raises the smallest Q of its triangles the most, if one does without adding a
// flip in D and within the guard. Returns whether it moved.
bool repair_vertex(const RowMatrixX3i& F, const VertexStars& stars, const BaseDomain& domain, const BaseLift& lift,
                   const BaseRepairOptions& options, double mean_edge, int v, BaseLayout& layout) {
  const Eigen::Vector3d x = layout.X.row(v);
  const double current = star_quality(layout.X, F, stars, v, x);
  if (!(current < options.threshold)) return false;
  const std::optional<Eigen::Vector3d> normal = vertex_normal(layout.X, F, stars, v);
  if (!normal) return false;
  const std::optional<std::array<Eigen::Vector3d, 3>> targets = repair_targets(layout.X, F, stars, v, *normal);
  const std::vector<BasePoint> points = star_points(F, stars, layout, v);
  const int c = domain.common_chart(points.data(), static_cast<int>(points.size()));
  if (!targets || c < 0) return false;
  const Eigen::Vector2d start = domain.to_chart(c, layout.points[v]);
  // The candidates that raise the star's smallest quality, best first: the flip count and the
  // guard, the costly checks, then run only until one passes.
  boost::container::small_vector<RepairCandidate, 9> better;
  for (const Eigen::Vector3d& target : *targets) {
    Eigen::Vector3d move = target - x;
    move -= move.dot(*normal) * *normal;
    std::optional<Eigen::Vector2d> chart_move = pull_back(domain, lift, c, layout.points[v], move);
    if (!chart_move) chart_move = pull_back_by_star(domain, F, stars, layout, c, v, *normal, move);
    if (!chart_move) continue;
    for (const double t : {1.0, 0.5, 0.25}) {
      const Eigen::Vector2d q = start + t * *chart_move;
      const std::optional<BasePoint> p = domain.from_chart(c, q);
      if (!p) continue;
      const Eigen::Vector3d lifted = lift.lift(*p);
      const double quality = star_quality(layout.X, F, stars, v, lifted);
      if (quality > current + 1e-9) better.push_back({quality, q, *p, lifted});
    }
  }
  if (better.empty()) return false;
  const int flips = star_flips(domain, F, stars, layout, v, layout.points[v]);
  double allowed_error = -1;  // the guard's allowance, computed when a candidate first needs it
  const RepairCandidate* chosen = best_passing(better, [&](const RepairCandidate& candidate) {
    if (star_flips(domain, F, stars, layout, v, candidate.point) > flips) return false;
    if (options.error_tolerance < 0) return true;
    if (allowed_error < 0)
      allowed_error = std::max(surface_error_on_base(F, stars, domain, lift, layout, c, v, start, x, x),
                               options.error_tolerance * mean_edge);
    return !(surface_error_on_base(F, stars, domain, lift, layout, c, v, candidate.chart, candidate.x, x) >
             allowed_error);
  });
  if (!chosen) return false;
  layout.points[v] = chosen->point;
  layout.X.row(v) = chosen->x.transpose();
  return true;
}

}  // namespace

BaseRepairStats repair_on_base(const RowMatrixX3i& F, const BaseDomain& domain, const BaseLift& lift,
                               BaseLayout& layout, const BaseRepairOptions& options) {
  const int n = static_cast<int>(layout.points.size());
  const VertexStars stars(F, n);
  const std::vector<bool> rim = boundary_vertices(F, stars);
  const double mean_edge = mean_edge_length(layout.X, F);
  const auto movable = [&](int v) { return !rim[v] && !(options.fixed && (*options.fixed)[v]); };
  const SplitSweep split(layout.X, F, stars);
  BaseRepairStats stats;
  stats.q_min_before = smallest_quality(layout.X, F);
  std::vector<int> visited(n, -1);
  RepairRetries retries(F, stars, n);
  for (int sweep = 0; sweep < options.sweeps; ++sweep) {
    const std::vector<std::pair<double, int>> poor = poor_faces(layout.X, F, options.threshold);
    if (poor.empty()) break;
    const int moves = repair_sweep(split, F, poor, sweep, visited, retries, movable, [&](int v) {
      return repair_vertex(F, stars, domain, lift, options, mean_edge, v, layout);
    });
    stats.moves += moves;
    if (moves == 0) break;
  }
  stats.q_min_after = smallest_quality(layout.X, F);
  return stats;
}

int snap_on_base(const RowMatrixX3i& F, const BaseDomain& domain, const BaseLift& lift, BaseLayout& layout,
                 const FeatureSnapOptions& options, std::vector<bool>* snapped) {
  const VertexStars stars(F, static_cast<int>(layout.points.size()));
  const std::vector<BasePoint> before = layout.points;
  const RowMatrixX3d& input_V = lift.input_vertices();
  // v the fraction t of the way to input vertex s's point, in a chart holding both (exactly
  // that point at t = 1).
  const auto point_toward = [&](int v, int s, double t) -> std::optional<BasePoint> {
    const BasePoint ends[2] = {layout.points[v], lift.location(s)};
    if (t == 1) return ends[1];
    const int c = domain.common_chart(ends, 2);
    if (c < 0) return std::nullopt;
    return domain.from_chart(c, (1 - t) * domain.to_chart(c, ends[0]) + t * domain.to_chart(c, ends[1]));
  };
  const auto toward = [&](int v, int s, double t) -> std::optional<Eigen::Vector3d> {
    const std::optional<BasePoint> p = point_toward(v, s, t);
    if (!p || star_flips(domain, F, stars, layout, v, *p) != 0) return std::nullopt;
    return t == 1 ? Eigen::Vector3d(input_V.row(s).transpose()) : lift.lift(*p);
  };
  const SnapInDomain moves{toward,
                           [&](int v, int s, double t) { layout.points[v] = *point_toward(v, s, t); },
                           [&] { layout.points = before; },
                           {}};  // no faces in D: the tips are measured against the level in 3D
  const RowMatrixX3i& input_F = lift.input_faces();
  return snap_level_to_input_tips(F, layout.X, input_V, input_F, boundary_vertices(F, stars),
                                  boundary_vertices(input_F, static_cast<int>(input_V.rows())), moves, options,
                                  snapped);
}

int untangle_on_base(const RowMatrixX3i& F, const BaseDomain& domain, const BaseLift& lift, BaseLayout& layout,
                     int sweeps) {
  const int n = static_cast<int>(layout.points.size());
  const VertexStars stars(F, n);
  const std::vector<bool> rim = boundary_vertices(F, stars);
  int moves = 0;
  for (int sweep = 0; sweep < sweeps; ++sweep) {
    std::vector<bool> tangled(n, false);
    bool any = false;
    for (int f = 0; f < F.rows(); ++f)
      if (!domain.counter_clockwise(layout.points[F(f, 0)], layout.points[F(f, 1)], layout.points[F(f, 2)]))
        for (int k = 0; k < 3; ++k) any = tangled[F(f, k)] = true;
    if (!any) break;
    for (int v = 0; v < n; ++v)
      if (tangled[v] && !rim[v] && untangle_vertex(F, stars, domain, lift, v, layout)) ++moves;
  }
  return moves;
}

BaseLayout base_vertices_layout(const BaseDomain& domain, const BaseLift& lift) {
  const int n0 = domain.base().num_vertices();
  BaseLayout layout{std::vector<BasePoint>(n0), RowMatrixX3d(n0, 3)};
  for (int v = 0; v < n0; ++v) {
    layout.points[v] = domain.vertex_point(v);
    layout.X.row(v) = lift.lift(layout.points[v]).transpose();
  }
  return layout;
}

bool split_on_base(const SubdivisionConnectivity& connectivity, int j, const BaseDomain& domain, const BaseLift& lift,
                   BaseLayout& layout) {
  const int previous = connectivity.vertex_count(j - 1), n = connectivity.vertex_count(j);
  layout.points.resize(n);
  layout.X.conservativeResize(n, 3);
  const std::unordered_map<long long, int> apex_of = edge_apexes(connectivity.faces[j - 1], previous);
  for (int v = previous; v < n; ++v) {
    const Eigen::Vector2i parents = connectivity.parents(v);
    const auto apex = [&](int tail, int head) -> const BasePoint* {
      const auto it = apex_of.find(static_cast<long long>(tail) * previous + head);
      return it == apex_of.end() ? nullptr : &layout.points[it->second];
    };
    const std::optional<BasePoint> mid = edge_midpoint(domain, layout.points[parents[0]], layout.points[parents[1]],
                                                       apex(parents[0], parents[1]), apex(parents[1], parents[0]));
    if (!mid) return false;
    layout.points[v] = *mid;
    layout.X.row(v) = lift.lift(*mid).transpose();
  }
  return true;
}

int smooth_on_base(const RowMatrixX3i& F, const BaseDomain& domain, const BaseLift& lift, BaseLayout& layout,
                   const BaseSmoothingOptions& options) {
  if (options.iterations <= 0) return 0;  // before building the stars and the sweep's split
  const int n = static_cast<int>(layout.points.size());
  const VertexStars stars(F, n);
  const std::vector<Eigen::Vector2i> rim = rim_neighbours(boundary_edges(F, stars), n);
  const bool weighted = options.target == SmoothingTarget::area_centroid && options.surface_density;
  // Each move reads v's 1-ring and star and writes v only, as SplitSweep::run asks.
  const auto smooth_vertex = [&](const Eigen::VectorXd& density, int v) {
    const bool on_rim = rim[v][0] >= 0 || rim[v][1] >= 0;
    return on_rim ? options.slide_rim && slide_rim_vertex(F, stars, domain, lift, options, rim[v], v, layout)
                  : move_vertex(F, stars, domain, lift, options, density, v, layout);
  };
  const SplitSweep split(layout.X, F, stars);
  int moves = 0;
  for (int it = 0; it < options.iterations; ++it) {
    const Eigen::VectorXd density = density_under(lift, layout, weighted ? options.surface_density : nullptr);
    std::array<int, SplitSweep::kParts> moved{};
    split.run([&](int part) {
      for (int v = 0; v < n; ++v)
        if (split.part(v) == part && smooth_vertex(density, v)) ++moved[part];
    });
    moves += moved[0] + moved[1] + moved[2];
  }
  return moves;
}

int count_flipped_on_base(const BaseDomain& domain, const RowMatrixX3i& F, const std::vector<BasePoint>& points) {
  int flipped = 0;
  for (int f = 0; f < F.rows(); ++f)
    if (!domain.counter_clockwise(points[F(f, 0)], points[F(f, 1)], points[F(f, 2)])) ++flipped;
  return flipped;
}

}  // namespace mrsnake
