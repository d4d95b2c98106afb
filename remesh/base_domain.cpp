#include "remesh/base_domain.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/Geometry>

#include "mesh/errors.h"
#include "mesh/vertex_stars.h"

namespace mrsnake {
namespace {

// The corner of face f at vertex v, or -1.
int corner_of(const RowMatrixX3i& F, int f, int v) {
  for (int k = 0; k < 3; ++k)
    if (F(f, k) == v) return k;
  return -1;
}

// The vertex `steps` corners after v in face f (counter-clockwise).
int after(const RowMatrixX3i& F, int f, int v, int steps) { return F(f, (corner_of(F, f, v) + steps) % 3); }

double cross2(const Eigen::Vector2d& u, const Eigen::Vector2d& w) { return u.x() * w.y() - u.y() * w.x(); }

// q's barycentric coordinates in the 2D triangle with corners the columns of t.
Eigen::Vector3d barycentric_2d(const Eigen::Matrix<double, 2, 3>& t, const Eigen::Vector2d& q) {
  const Eigen::Vector2d a = t.col(0) - q, b = t.col(1) - q, c = t.col(2) - q;
  const Eigen::Vector3d w(cross2(b, c), cross2(c, a), cross2(a, b));
  return w / w.sum();
}

// The faces of v's star in counter-clockwise order seen from outside, from the face whose
// edge v -> a has no face across it on a boundary; `closed` when the fan closes.
std::vector<int> ordered_star(const VertexStars& stars, const RowMatrixX3i& F, int v, bool& closed) {
  const int count = stars.offset[v + 1] - stars.offset[v];
  if (count == 0) throw TopologyError("base mesh vertex " + std::to_string(v) + " is in no face");
  int start = stars.faces[stars.offset[v]], starts = 0;
  for (int i = stars.offset[v]; i < stars.offset[v + 1]; ++i) {
    const int f = stars.faces[i];
    if (face_with_directed_edge(stars, F, after(F, f, v, 1), v) >= 0) continue;
    start = f;
    ++starts;
  }
  closed = starts == 0;
  // The next face counter-clockwise holds the edge v -> b of the current face (v, a, b).
  const auto next = [&](int f) { return face_with_directed_edge(stars, F, v, after(F, f, v, 2)); };
  std::vector<int> fan{start};
  for (int f = next(start); f >= 0 && f != start && static_cast<int>(fan.size()) < count; f = next(f)) fan.push_back(f);
  const bool ends = closed ? next(fan.back()) == start : next(fan.back()) < 0;
  if (starts > 1 || !ends || static_cast<int>(fan.size()) != count)
    throw TopologyError("base mesh vertex " + std::to_string(v) + ": its faces are not one fan (non-manifold)");
  return fan;
}

// The chart positions of the ring of v's fan: flatten_star, or for a lone boundary face its
// own shape, which spanning π would flatten to a segment.
std::vector<Eigen::Vector2d> flatten_ring(const RowMatrixX3d& V, int v, const std::vector<int>& ring, bool closed) {
  const Eigen::Vector3d c = V.row(v);
  std::vector<Eigen::Vector3d> points;
  for (int r : ring) points.push_back(V.row(r));
  if (closed || ring.size() > 2) return flatten_star(c, points, closed);
  const Eigen::Vector3d a = points[0] - c, b = points[1] - c;
  const double angle = std::atan2(a.cross(b).norm(), a.dot(b));
  return {Eigen::Vector2d(a.norm(), 0), b.norm() * Eigen::Vector2d(std::cos(angle), std::sin(angle))};
}

}  // namespace

std::vector<Eigen::Vector2d> flatten_star(const Eigen::Vector3d& center, const std::vector<Eigen::Vector3d>& ring,
                                          bool closed) {
  const int k = static_cast<int>(ring.size());
  const int wedges = closed ? k : k - 1;
  std::vector<double> wedge(wedges);
  double total = 0, widest = 0;
  for (int i = 0; i < wedges; ++i) {
    const Eigen::Vector3d a = ring[i] - center, b = ring[(i + 1) % k] - center;
    // atan2 of |a×b| and a·b: accurate for angles near 0 and π, where acos is not.
    wedge[i] = std::atan2(a.cross(b).norm(), a.dot(b));
    total += wedge[i];
    widest = std::max(widest, wedge[i]);
  }
  const double span = closed ? 2 * M_PI : M_PI;
  const double a = span / total;
  // A wedge scaled past π would fold the chart (a sharp tip with one wide angle): blend the
  // scaled wedges toward equal ones just enough that none exceeds kWidestWedge.
  const double even = span / wedges, scaled_widest = a * widest;
  const double t = scaled_widest > kWidestWedge ? (scaled_widest - kWidestWedge) / (scaled_widest - even) : 0.0;
  // Radii relative to their mean before the power, so that the chart keeps the star's size
  // and a sharp tip (a large a) does not underflow: a scaling does not change the shapes.
  double mean_radius = 0;
  for (const Eigen::Vector3d& r : ring) mean_radius += (r - center).norm() / k;
  std::vector<Eigen::Vector2d> flat(k);
  double phi = 0;
  for (int i = 0; i < k; ++i) {
    const double r = mean_radius * std::pow((ring[i] - center).norm() / mean_radius, a);
    flat[i] = r * Eigen::Vector2d(std::cos(phi), std::sin(phi));
    if (i < wedges) phi += (1 - t) * a * wedge[i] + t * even;
  }
  return flat;
}

BaseDomain::BaseDomain(TriMesh base) : base_(std::move(base)), star_offset_{0}, slot_(base_.num_faces(), 3) {
  const RowMatrixX3i& F = base_.F;
  const VertexStars stars(F, base_.num_vertices());
  for (int v = 0; v < base_.num_vertices(); ++v) {
    bool closed = false;
    const std::vector<int> fan = ordered_star(stars, F, v, closed);
    std::vector<int> ring;
    for (int f : fan) ring.push_back(after(F, f, v, 1));
    if (!closed) ring.push_back(after(F, fan.back(), v, 2));
    const std::vector<Eigen::Vector2d> flat = flatten_ring(base_.V, v, ring, closed);
    for (std::size_t j = 0; j < fan.size(); ++j) {
      const int f = fan[j], k = corner_of(F, f, v);
      Eigen::Matrix<double, 2, 3> corners;
      corners.col(k).setZero();
      corners.col((k + 1) % 3) = flat[j];
      corners.col((k + 2) % 3) = flat[(j + 1) % flat.size()];
      slot_(f, k) = static_cast<int>(star_face_.size());
      star_face_.push_back(f);
      star_corners_.push_back(corners);
    }
    star_offset_.push_back(static_cast<int>(star_face_.size()));
  }
}

Eigen::Vector3d BaseDomain::position(const BasePoint& p) const {
  const RowMatrixX3i& F = base_.F;
  return p.bary[0] * base_.V.row(F(p.face, 0)).transpose() + p.bary[1] * base_.V.row(F(p.face, 1)).transpose() +
         p.bary[2] * base_.V.row(F(p.face, 2)).transpose();
}

BasePoint BaseDomain::vertex_point(int v) const {
  const int f = star_face_[star_offset_[v]];
  BasePoint p{f, Eigen::Vector3d::Zero()};
  p.bary[corner_of(base_.F, f, v)] = 1;
  return p;
}

int BaseDomain::star_slot(int v, const BasePoint& p, Eigen::Vector3d& bary) const {
  const RowMatrixX3i& F = base_.F;
  const int k = corner_of(F, p.face, v);
  if (k >= 0) {
    bary = p.bary;
    return slot_(p.face, k);
  }
  // The corners that carry weight span the smallest simplex of K holding p; a face of the star
  // holding all of them holds p.
  for (int i = star_offset_[v]; i < star_offset_[v + 1]; ++i) {
    const int g = star_face_[i];
    bary.setZero();
    bool holds = true;
    for (int j = 0; j < 3 && holds; ++j) {
      if (p.bary[j] <= kOnSimplex) continue;
      const int corner = corner_of(F, g, F(p.face, j));
      holds = corner >= 0;
      if (holds) bary[corner] = p.bary[j];
    }
    if (holds) {
      bary /= bary.sum();
      return i;
    }
  }
  return -1;
}

bool BaseDomain::in_star(int v, const BasePoint& p) const {
  Eigen::Vector3d bary;
  return star_slot(v, p, bary) >= 0;
}

BaseDomain::ChartList BaseDomain::charts_holding(const BasePoint& p) const {
  const RowMatrixX3i& F = base_.F;
  ChartList charts(F.row(p.face).data(), F.row(p.face).data() + 3);
  int heaviest = 0;
  p.bary.maxCoeff(&heaviest);
  if (p.bary.minCoeff() > kOnSimplex) return charts;
  // On an edge or a vertex: every face around it that holds all the weighted corners.
  const int a = F(p.face, heaviest);
  for (int i = star_offset_[a]; i < star_offset_[a + 1]; ++i) {
    const int g = star_face_[i];
    bool holds = true;
    for (int j = 0; j < 3; ++j) holds = holds && (p.bary[j] <= kOnSimplex || corner_of(F, g, F(p.face, j)) >= 0);
    for (int k = 0; k < 3 && holds; ++k)
      if (std::find(charts.begin(), charts.end(), F(g, k)) == charts.end()) charts.push_back(F(g, k));
  }
  return charts;
}

std::optional<Eigen::Vector2d> BaseDomain::chart_point(int v, const BasePoint& p) const {
  Eigen::Vector3d bary;
  const int slot = star_slot(v, p, bary);
  if (slot < 0) return std::nullopt;
  return Eigen::Vector2d(star_corners_[slot] * bary);
}

Eigen::Vector2d BaseDomain::to_chart(int v, const BasePoint& p) const {
  Eigen::Vector3d bary;
  const int slot = star_slot(v, p, bary);
  if (slot < 0) throw std::invalid_argument("to_chart: the point is not in vertex " + std::to_string(v) + "'s star");
  return star_corners_[slot] * bary;
}

std::optional<BasePoint> BaseDomain::from_chart(int v, const Eigen::Vector2d& q) const {
  int best = -1;
  Eigen::Vector3d best_bary;
  double best_min = -kChartSlack;  // a degenerate face's NaN never compares above it
  for (int i = star_offset_[v]; i < star_offset_[v + 1]; ++i) {
    const Eigen::Vector3d bary = barycentric_2d(star_corners_[i], q);
    if (!(bary.minCoeff() >= best_min)) continue;
    best = i;
    best_bary = bary;
    best_min = bary.minCoeff();
  }
  if (best < 0) return std::nullopt;
  best_bary = best_bary.cwiseMax(0.0);
  return BasePoint{star_face_[best], best_bary / best_bary.sum()};
}

double BaseDomain::depth(int v, const BasePoint& p) const {
  Eigen::Vector3d bary;
  const int slot = star_slot(v, p, bary);
  if (slot < 0) return -1;
  return bary[corner_of(base_.F, star_face_[slot], v)];
}

int BaseDomain::common_chart(const BasePoint* points, int count) const {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int i = 0; i < count; ++i) centroid += position(points[i]) / count;
  int best = -1;
  double best_depth = -1, best_distance = std::numeric_limits<double>::infinity();
  // A chart holding all the points holds the first. The deepest chart first: three points on
  // the rim of a star are held by it, but the straight triangle between them in that chart
  // cuts across the star, while the face of K they span is outside it.
  for (int v : charts_holding(points[0])) {
    double total_depth = 0;
    bool holds = true;
    for (int i = 0; i < count && holds; ++i) {
      const double d = depth(v, points[i]);
      holds = d >= 0;
      total_depth += d;
    }
    if (!holds) continue;
    const double distance = (base_.V.row(v).transpose() - centroid).squaredNorm();
    if (total_depth < best_depth || (total_depth == best_depth && distance >= best_distance)) continue;
    best = v;
    best_depth = total_depth;
    best_distance = distance;
  }
  return best;
}

double BaseDomain::orientation(const BasePoint& a, const BasePoint& b, const BasePoint& c) const {
  const BasePoint points[3] = {a, b, c};
  const int v = common_chart(points, 3);
  if (v < 0) return std::numeric_limits<double>::quiet_NaN();
  const Eigen::Vector2d qa = to_chart(v, a);
  return cross2(to_chart(v, b) - qa, to_chart(v, c) - qa);
}

bool BaseDomain::counter_clockwise(const BasePoint& a, const BasePoint& b, const BasePoint& c) const {
  for (int v : charts_holding(a)) {
    const std::optional<Eigen::Vector2d> qb = chart_point(v, b);
    if (!qb) continue;
    const std::optional<Eigen::Vector2d> qc = chart_point(v, c);
    if (!qc) continue;
    const Eigen::Vector2d qa = to_chart(v, a);
    if (cross2(*qb - qa, *qc - qa) > 0) return true;
  }
  return false;
}

}  // namespace mrsnake
