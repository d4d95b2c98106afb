#include "remesh/maps.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>

#include <Eigen/Geometry>

#include "mesh/errors.h"
#include "mesh/topology.h"

namespace mrsnake {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using Triangle = std::array<int, 3>;

int corner_of(const Triangle& t, int v) { return t[0] == v ? 0 : t[1] == v ? 1 : 2; }

// K while it is simplified. Faces are appended and marked dead, never erased, so that face
// ids stay valid; each face lists the input vertices located in it, so that a removal
// re-locates only the points of its own star.
struct WorkingMesh {
  const RowMatrixX3d* V = nullptr;  // the input positions, which K's vertices keep
  std::vector<Triangle> faces;
  std::vector<char> face_alive;
  std::vector<std::vector<int>> points;        // per face: the input vertices located in it
  std::vector<std::vector<int>> vertex_faces;  // per vertex: its live faces
  std::vector<char> vertex_alive, boundary, feature;
  std::vector<BasePoint> location;
  int live_vertices = 0;
  double rim_spacing = 0;  // the mean length of the input's rim edges

  Vector3d position(int v) const { return V->row(v).transpose(); }

  int add_face(const Triangle& t) {
    const int f = static_cast<int>(faces.size());
    faces.push_back(t);
    face_alive.push_back(1);
    points.emplace_back();
    for (int c : t) vertex_faces[c].push_back(f);
    return f;
  }

  bool has_edge_directed(int tail, int head) const {
    for (int f : vertex_faces[tail])
      if (faces[f][(corner_of(faces[f], tail) + 1) % 3] == head) return true;
    return false;
  }

  bool has_edge(int a, int b) const {
    for (int f : vertex_faces[a])
      if (faces[f][0] == b || faces[f][1] == b || faces[f][2] == b) return true;
    return false;
  }
};

double cross2(const Vector2d& a, const Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

// A vertex's star in K: faces[i] is (center, ring[i], ring[i+1]), the ring counter-clockwise
// seen from outside; `closed` unless the centre is on the boundary, where the ring runs from
// one boundary neighbour to the other (one vertex more than faces).
struct Star {
  int center = -1;
  std::vector<int> ring, faces;
  bool closed = true;
};

// The star of v, or nothing if its faces are not one fan (cannot happen on a manifold K).
std::optional<Star> vertex_star(const WorkingMesh& K, int v) {
  const std::vector<int>& around = K.vertex_faces[v];
  const int m = static_cast<int>(around.size());
  std::vector<int> first(m), second(m);
  for (int i = 0; i < m; ++i) {
    const Triangle& t = K.faces[around[i]];
    const int c = corner_of(t, v);
    first[i] = t[(c + 1) % 3];
    second[i] = t[(c + 2) % 3];
  }
  auto face_from = [&](int a) { return static_cast<int>(std::find(first.begin(), first.end(), a) - first.begin()); };
  // On a boundary the fan starts at the one neighbour that no face of it enters.
  int start = 0, open_ends = 0;
  for (int i = 0; i < m; ++i)
    if (std::find(second.begin(), second.end(), first[i]) == second.end()) start = i, ++open_ends;
  if (m == 0 || open_ends > 1) return std::nullopt;
  Star star;
  star.center = v;
  star.closed = open_ends == 0;
  for (int i = start, step = 0; step < m; ++step) {
    star.ring.push_back(first[i]);
    star.faces.push_back(around[i]);
    const int next = face_from(second[i]);
    if (step + 1 < m) {
      if (next == m) return std::nullopt;
      i = next;
    } else if (star.closed ? second[i] != star.ring[0] : next != m) {
      return std::nullopt;
    } else if (!star.closed) {
      star.ring.push_back(second[i]);
    }
  }
  std::vector<int> sorted = star.ring;
  std::sort(sorted.begin(), sorted.end());
  if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) return std::nullopt;
  return star;
}

// ---- the retriangulation of a flattened hole ----

// The triangulation of the counter-clockwise polygon p (no inner vertices) of least total
// cost(i, m, j), among those made of triangles (i, m, j), i < m < j, that are
// counter-clockwise and `triangle_ok` accepts, with chords (i, j) that `chord_ok` accepts: a
// dynamic programme over the sub-polygons i … j. Triangles that are all counter-clockwise
// cover the polygon once (the winding number of its boundary), so none needs testing for
// other vertices inside. Nothing if no such triangulation exists.
template <class Cost, class TriangleOk, class ChordOk>
std::optional<std::vector<Triangle>> best_triangulation(const std::vector<Vector2d>& p, Cost cost,
                                                        TriangleOk triangle_ok, ChordOk chord_ok) {
  const int k = static_cast<int>(p.size());
  const double none = std::numeric_limits<double>::infinity();
  std::vector<double> best(k * k, none);  // best[i·k + j]: the least cost of the sub-polygon i … j
  std::vector<int> split(k * k, -1);
  for (int i = 0; i + 1 < k; ++i) best[i * k + i + 1] = 0;
  for (int length = 2; length < k; ++length)
    for (int i = 0, j = length; j < k; ++i, ++j) {
      if (!(i == 0 && j == k - 1) && !chord_ok(i, j)) continue;
      for (int m = i + 1; m < j; ++m) {
        if (best[i * k + m] == none || best[m * k + j] == none || cross2(p[m] - p[i], p[j] - p[i]) <= 0) continue;
        const double total = best[i * k + m] + best[m * k + j] + cost(i, m, j);
        if (total < best[i * k + j] && triangle_ok(i, m, j)) best[i * k + j] = total, split[i * k + j] = m;
      }
    }
  if (best[k - 1] == none) return std::nullopt;
  std::vector<Triangle> triangles;
  std::vector<std::pair<int, int>> todo = {{0, k - 1}};
  while (!todo.empty()) {
    const auto [i, j] = todo.back();
    todo.pop_back();
    if (j - i < 2) continue;
    const int m = split[i * k + j];
    triangles.push_back({i, m, j});
    todo.push_back({i, m});
    todo.push_back({m, j});
  }
  return triangles;
}

// How poor the chart triangle (a, b, c) is: the sum of its squared edges over its area, 4√3
// when equilateral, without bound as it flattens. Summed over a triangulation, unlike the
// smallest angle, it weighs every triangle, not only the worst: K's faces come out even.
double shape_cost(const Vector2d& a, const Vector2d& b, const Vector2d& c) {
  const double area = 0.5 * cross2(b - a, c - a);
  const double edges = (b - a).squaredNorm() + (c - b).squaredNorm() + (a - c).squaredNorm();
  return area > 0 ? edges / area : std::numeric_limits<double>::infinity();
}

// ---- one vertex removal ----

enum class Refusal { none, valence, edge, fold, rim, drift };

// Whether every old face is a counter-clockwise triangle of the chart (a wedge scaled past π
// by z^a would fold it).
bool chart_is_fan(const std::vector<Vector2d>& flat, bool closed) {
  const int k = static_cast<int>(flat.size());
  for (int i = 0; i < (closed ? k : k - 1); ++i)
    if (cross2(flat[i], flat[(i + 1) % k]) <= 0) return false;
  return true;
}

// The distance from p to the segment [a, b].
double segment_distance(const Vector3d& p, const Vector3d& a, const Vector3d& b) {
  const Vector3d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / std::max(ab.squaredNorm(), 1e-300), 0.0, 1.0);
  return (p - a - t * ab).norm();
}

// Whether the rim keeps its shape when the rim vertex star.center goes: the input's rim
// vertices on its two rim edges (it included) stay within tan(turn/2)/2 of the closing chord's
// length from the chord (what a corner turning by max_rim_turn would leave), plus a part of
// the input's rim spacing, so that a jagged input rim (zig-zags of 60°) is smoothed, not kept.
bool rim_keeps_shape(const WorkingMesh& K, const Star& star, double max_rim_turn) {
  const Vector3d a = K.position(star.ring.front()), b = K.position(star.ring.back());
  const double tolerance = 0.5 * std::tan(0.5 * max_rim_turn * M_PI / 180) * (b - a).norm() + 0.6 * K.rim_spacing;
  if (segment_distance(K.position(star.center), a, b) > tolerance) return false;
  for (int f : star.faces)
    for (int p : K.points[f])
      if (K.boundary[p] && segment_distance(K.position(p), a, b) > tolerance) return false;
  return true;
}

// Whether every ring vertex keeps enough faces once the star is replaced by `triangles`: 3
// inside, 2 on the boundary (a rim vertex with one face could never go).
bool ring_keeps_valence(const WorkingMesh& K, const Star& star, const std::vector<Triangle>& triangles) {
  const int k = static_cast<int>(star.ring.size());
  for (int i = 0; i < k; ++i) {
    const int old_faces = star.closed || (i > 0 && i < k - 1) ? 2 : 1;
    int new_faces = 0;
    for (const Triangle& t : triangles) new_faces += (t[0] == i) + (t[1] == i) + (t[2] == i);
    const int faces = static_cast<int>(K.vertex_faces[star.ring[i]].size()) - old_faces + new_faces;
    if (faces < (K.boundary[star.ring[i]] ? 2 : 3)) return false;
  }
  return true;
}

// The barycentric coordinates of q in the triangle (a, b, c).
Vector3d barycentric(const Vector2d& q, const Vector2d& a, const Vector2d& b, const Vector2d& c) {
  const double area = cross2(b - a, c - a);
  return Vector3d(cross2(b - q, c - q), cross2(c - q, a - q), cross2(a - q, b - q)) / area;
}

// The hole's triangle holding q and q's coordinates in it: the triangle where q's smallest
// coordinate is largest, negatives clamped (q is inside up to rounding, or the nearest).
std::pair<int, Vector3d> locate_in_hole(const Vector2d& q, const std::vector<Vector2d>& flat,
                                        const std::vector<Triangle>& triangles) {
  int best = 0;
  Vector3d best_bary(1, 0, 0);
  double best_min = -std::numeric_limits<double>::infinity();
  for (int t = 0; t < static_cast<int>(triangles.size()); ++t) {
    const Triangle& tri = triangles[t];
    const Vector3d bary = barycentric(q, flat[tri[0]], flat[tri[1]], flat[tri[2]]);
    if (bary.minCoeff() > best_min) best = t, best_bary = bary, best_min = bary.minCoeff();
  }
  best_bary = best_bary.cwiseMax(0.0);
  return {best, best_bary / best_bary.sum()};
}

// A point of the old star in the hole: the input vertex, its triangle (an index into the
// hole's triangles) and its coordinates there.
struct Move {
  int point, triangle;
  Vector3d bary;
};

// Where the points of the star's faces go among `triangles` (ring indices, counter-clockwise
// in the chart `flat`): their chart positions, located. A vertex of K stays exactly at its corner.
std::vector<Move> relocate(const WorkingMesh& K, const Star& star, const std::vector<Vector2d>& flat,
                           const std::vector<Triangle>& triangles) {
  auto ring_index = [&](int w) {
    return static_cast<int>(std::find(star.ring.begin(), star.ring.end(), w) - star.ring.begin());
  };
  std::vector<Move> moves;
  for (int f : star.faces) {
    std::array<Vector2d, 3> corner;
    for (int j = 0; j < 3; ++j)
      corner[j] = K.faces[f][j] == star.center ? Vector2d(0, 0) : flat[ring_index(K.faces[f][j])];
    for (int p : K.points[f]) {
      const BasePoint& where = K.location[p];
      if (K.vertex_alive[p] && p != star.center) {
        const int i = ring_index(p);
        int t = 0;
        while (triangles[t][0] != i && triangles[t][1] != i && triangles[t][2] != i) ++t;
        moves.push_back({p, t, Vector3d::Unit(corner_of(triangles[t], i))});
      } else {
        const Vector2d q = where.bary[0] * corner[0] + where.bary[1] * corner[1] + where.bary[2] * corner[2];
        const auto [t, bary] = locate_in_hole(q, flat, triangles);
        moves.push_back({p, t, bary});
      }
    }
  }
  return moves;
}

// The largest distance in 3D between a moved point's input position and its new point on
// the hole's triangles, over that triangle's longest edge.
double largest_drift(const WorkingMesh& K, const Star& star, const std::vector<Triangle>& triangles,
                     const std::vector<Move>& moves) {
  auto corner = [&](int t, int j) { return K.position(star.ring[triangles[t][j % 3]]); };
  std::vector<double> longest(triangles.size(), 0);
  for (int t = 0; t < static_cast<int>(triangles.size()); ++t)
    for (int j = 0; j < 3; ++j) longest[t] = std::max(longest[t], (corner(t, j) - corner(t, j + 1)).norm());
  double drift = 0;
  for (const Move& m : moves) {
    Vector3d x = Vector3d::Zero();
    for (int j = 0; j < 3; ++j) x += m.bary[j] * corner(m.triangle, j);
    drift = std::max(drift, (x - K.position(m.point)).norm() / longest[m.triangle]);
  }
  return drift;
}

// Replaces the star by `triangles` (ring indices) and moves its points there.
void fill_hole(WorkingMesh& K, const Star& star, const std::vector<Triangle>& triangles,
               const std::vector<Move>& moves) {
  std::vector<int> new_faces;
  for (const Triangle& t : triangles)
    new_faces.push_back(K.add_face({star.ring[t[0]], star.ring[t[1]], star.ring[t[2]]}));
  for (const Move& m : moves) {
    K.location[m.point] = {new_faces[m.triangle], m.bary};
    K.points[new_faces[m.triangle]].push_back(m.point);
  }
  for (int f : star.faces) {
    K.points[f] = {};
    K.face_alive[f] = 0;
  }
  for (int r : star.ring) {
    std::vector<int>& around = K.vertex_faces[r];
    around.erase(std::remove_if(around.begin(), around.end(), [&](int f) { return !K.face_alive[f]; }), around.end());
  }
  K.vertex_faces[star.center].clear();
  K.vertex_alive[star.center] = 0;
  --K.live_vertices;
}

// Whether a new triangle (i, m, j) of the hole, i < m < j, faces the way of the old faces it
// covers in the chart: a positive dot product of its 3D normal with theirs (area-weighted),
// those being the wedges i … j-1 it spans seen from the centre, or all of them if it holds the
// centre. A triangle turned against them would fold the map in 3D; the star's mean normal
// alone is no guide where the star wraps round a thin tube.
class NormalCheck {
 public:
  NormalCheck(const WorkingMesh& K, const Star& star, const std::vector<Vector2d>& flat) : flat_(flat) {
    const Vector3d c = K.position(star.center);
    const int k = static_cast<int>(star.ring.size());
    prefix_.assign(star.faces.size() + 1, Vector3d::Zero());
    for (std::size_t l = 0; l < star.faces.size(); ++l)
      prefix_[l + 1] = prefix_[l] + (K.position(star.ring[l]) - c).cross(K.position(star.ring[(l + 1) % k]) - c);
  }

  bool agrees(const std::vector<Vector3d>& ring, int i, int m, int j) const {
    const bool holds_centre = cross2(flat_[m] - flat_[i], -flat_[i]) > 0 &&
                              cross2(flat_[j] - flat_[m], -flat_[m]) > 0 && cross2(flat_[i] - flat_[j], -flat_[j]) > 0;
    const Vector3d covered = holds_centre ? prefix_.back() : Vector3d(prefix_[j] - prefix_[i]);
    return (ring[m] - ring[i]).cross(ring[j] - ring[i]).dot(covered) > 0;
  }

 private:
  const std::vector<Vector2d>& flat_;
  std::vector<Vector3d> prefix_;  // prefix_[l]: the sum of the wedges' normals before wedge l
};

// Removes star.center from K unless that would break the map: too many neighbours, a rim
// corner, a folded chart, no retriangulation without a repeated edge or a new triangle turned
// against the old star (the 3D normals), or a neighbour left with too few faces.
Refusal remove_vertex(WorkingMesh& K, const Star& star, const MapsOptions& options) {
  const int k = static_cast<int>(star.ring.size());
  if (k > options.max_valence || k < 3) return Refusal::valence;
  if (!star.closed && !rim_keeps_shape(K, star, options.max_rim_turn)) return Refusal::rim;
  std::vector<Vector3d> ring(k);
  for (int i = 0; i < k; ++i) ring[i] = K.position(star.ring[i]);
  const std::vector<Vector2d> flat = flatten_star(K.position(star.center), ring, star.closed);
  if (!chart_is_fan(flat, star.closed)) return Refusal::fold;
  // The closing edge of a rim hole is new too.
  if (!star.closed && K.has_edge(star.ring.back(), star.ring.front())) return Refusal::edge;
  const NormalCheck normals(K, star, flat);
  auto triangle_ok = [&](int i, int m, int j) { return normals.agrees(ring, i, m, j); };
  auto chord_ok = [&](int i, int j) { return !K.has_edge(star.ring[i], star.ring[j]); };
  auto cost = [&](int i, int m, int j) { return shape_cost(flat[i], flat[m], flat[j]); };
  const std::optional<std::vector<Triangle>> triangles = best_triangulation(flat, cost, triangle_ok, chord_ok);
  if (!triangles) {
    // Which condition was in the way: the repeated edges if the hole can be filled without them.
    const bool fillable = best_triangulation(flat, cost, triangle_ok, [](int, int) { return true; }).has_value();
    return fillable ? Refusal::edge : Refusal::fold;
  }
  if (!ring_keeps_valence(K, star, *triangles)) return Refusal::valence;
  const std::vector<Move> moves = relocate(K, star, flat, *triangles);
  if (largest_drift(K, star, *triangles, moves) > options.max_drift) return Refusal::drift;
  fill_hole(K, star, *triangles, moves);
  return Refusal::none;
}

// ---- the rounds ----

// The live vertices that may be removed, by MAPS' priority, low first: λ·(star area)/(largest)
// + (1-λ)·(curvature)/(largest), the curvature being the angle defect |2π - angle sum|
// (|π - angle sum| on the boundary).
std::vector<int> removal_order(const WorkingMesh& K, double lambda) {
  std::vector<int> candidates;
  std::vector<double> area, curvature;
  for (int v = 0; v < static_cast<int>(K.vertex_alive.size()); ++v) {
    if (!K.vertex_alive[v] || K.feature[v]) continue;
    double a = 0, angles = 0;
    for (int f : K.vertex_faces[v]) {
      const Triangle& t = K.faces[f];
      const int c = corner_of(t, v);
      const Vector3d e1 = K.position(t[(c + 1) % 3]) - K.position(v), e2 = K.position(t[(c + 2) % 3]) - K.position(v);
      a += 0.5 * e1.cross(e2).norm();
      angles += std::atan2(e1.cross(e2).norm(), e1.dot(e2));
    }
    candidates.push_back(v);
    area.push_back(a);
    curvature.push_back(std::abs((K.boundary[v] ? M_PI : 2 * M_PI) - angles));
  }
  if (candidates.empty()) return candidates;
  const double max_area = std::max(*std::max_element(area.begin(), area.end()), 1e-300);
  const double max_curvature = std::max(*std::max_element(curvature.begin(), curvature.end()), 1e-300);
  std::vector<std::pair<double, int>> keyed(candidates.size());
  for (std::size_t i = 0; i < candidates.size(); ++i)
    keyed[i] = {lambda * area[i] / max_area + (1 - lambda) * curvature[i] / max_curvature, candidates[i]};
  std::sort(keyed.begin(), keyed.end());
  for (std::size_t i = 0; i < keyed.size(); ++i) candidates[i] = keyed[i].second;
  return candidates;
}

// One round: removes an independent set of vertices in priority order (a removed vertex's
// neighbours wait for the next round), stopping at the target. Returns how many it removed.
int remove_independent_set(WorkingMesh& K, int target, const MapsOptions& options, MapsParameterization& result) {
  std::vector<char> blocked(K.vertex_alive.size(), 0);
  int removed = 0;
  for (int v : removal_order(K, options.curvature_weight)) {
    if (K.live_vertices <= target) break;
    if (blocked[v]) continue;
    const std::optional<Star> star = vertex_star(K, v);
    const Refusal refusal = star ? remove_vertex(K, *star, options) : Refusal::fold;
    if (refusal == Refusal::none) {
      for (int r : star->ring) blocked[r] = 1;
      ++removed;
      continue;
    }
    ++result.refused_removals;
    ++(refusal == Refusal::valence ? result.refused_valence
       : refusal == Refusal::edge  ? result.refused_edge
       : refusal == Refusal::rim   ? result.refused_rim
       : refusal == Refusal::drift ? result.refused_drift
                                   : result.refused_fold);
  }
  result.removed_vertices += removed;
  return removed;
}

// ---- set-up and result ----

void require_input(const TriMesh& input) {
  const TopologyReport report = topology_report(input);
  require_disk_or_sphere(report, "the mesh to simplify (MAPS)");
  if (report.referenced_vertices < report.vertices)
    throw TopologyError("the mesh to simplify (MAPS) has " +
                        std::to_string(report.vertices - report.referenced_vertices) +
                        " unreferenced vertices; drop them first");
}

// K = the input, every input vertex at its own corner of its first face.
WorkingMesh working_mesh(const TriMesh& input, const std::vector<int>& feature_vertices) {
  const int n = input.num_vertices();
  WorkingMesh K;
  K.V = &input.V;
  K.vertex_faces.resize(n);
  K.vertex_alive.assign(n, 1);
  K.boundary.assign(n, 0);
  K.feature.assign(n, 0);
  K.location.resize(n);
  K.live_vertices = n;
  for (int f = 0; f < input.num_faces(); ++f) K.add_face({input.F(f, 0), input.F(f, 1), input.F(f, 2)});
  for (int v = 0; v < n; ++v) {
    const int f = K.vertex_faces[v].front();
    K.location[v].face = f;
    K.location[v].bary = Vector3d::Unit(corner_of(K.faces[f], v));
    K.points[f].push_back(v);
    const std::optional<Star> star = vertex_star(K, v);
    K.boundary[v] = star && !star->closed;
  }
  int rim_edges = 0;
  for (int v = 0; v < n; ++v)
    for (int f : K.vertex_faces[v]) {
      const int w = K.faces[f][(corner_of(K.faces[f], v) + 1) % 3];
      if (K.boundary[v] && K.boundary[w] && !K.has_edge_directed(w, v)) {
        K.rim_spacing += (K.position(w) - K.position(v)).norm();
        ++rim_edges;
      }
    }
  if (rim_edges > 0) K.rim_spacing /= rim_edges;
  for (int v : feature_vertices)
    if (v >= 0 && v < n) K.feature[v] = 1;
  return K;
}

// K compacted: live vertices and faces renumbered in order, locations following.
void compact(const WorkingMesh& K, const TriMesh& input, MapsParameterization& result) {
  const int n = static_cast<int>(K.vertex_alive.size());
  std::vector<int> vertex_id(n, -1), face_id(K.faces.size(), -1);
  for (int v = 0; v < n; ++v)
    if (K.vertex_alive[v]) vertex_id[v] = static_cast<int>(result.base_vertex.size()), result.base_vertex.push_back(v);
  int m = 0;
  for (std::size_t f = 0; f < K.faces.size(); ++f)
    if (K.face_alive[f]) face_id[f] = m++;
  result.base.V.resize(static_cast<int>(result.base_vertex.size()), 3);
  for (int i = 0; i < result.base.V.rows(); ++i) result.base.V.row(i) = input.V.row(result.base_vertex[i]);
  result.base.F.resize(m, 3);
  for (std::size_t f = 0; f < K.faces.size(); ++f)
    if (K.face_alive[f])
      for (int j = 0; j < 3; ++j) result.base.F(face_id[f], j) = vertex_id[K.faces[f][j]];
  result.location = K.location;
  for (BasePoint& p : result.location) p.face = face_id[p.face];
}

}  // namespace

MapsParameterization maps_parameterize(const TriMesh& input, const MapsOptions& options) {
  require_input(input);
  WorkingMesh K = working_mesh(input, options.feature_vertices);
  const int target = std::max(options.base_vertices, 4);
  MapsParameterization result;
  while (K.live_vertices > target) {
    ++result.rounds;
    if (remove_independent_set(K, target, options, result) == 0) break;
  }
  if (K.live_vertices > 2 * target)
    throw AlgorithmError("the MAPS simplification stalled at " + std::to_string(K.live_vertices) +
                         " base vertices (target " + std::to_string(target) +
                         "): no further vertex can be removed without breaking the map");
  compact(K, input, result);
  return result;
}

}  // namespace mrsnake
