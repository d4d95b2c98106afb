#include "remesh/stretch_map.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <queue>
#include <vector>

#include "mesh/errors.h"
#include "mesh/vertex_stars.h"
#include "remesh/split_sweep.h"

namespace mrsnake {
namespace {

using Vec3 = Eigen::Vector3d;
using FaceLists = std::vector<std::vector<int>>;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = 3.14159265358979323846;

// The surface side of a face's map: the squared lengths |l_k|² of its edges, l_k opposite
// corner k, and twice its area. Constant while D moves: StarRelaxer keeps them per face.
struct SurfaceTriangle {
  std::array<double, 3> squared_lengths;
  double double_area;
};

SurfaceTriangle surface_triangle(const Vec3& q0, const Vec3& q1, const Vec3& q2) {
  return {{(q2 - q1).squaredNorm(), (q0 - q2).squaredNorm(), (q1 - q0).squaredNorm()}, (q1 - q0).cross(q2 - q0).norm()};
}

// ‖J‖²_F of the affine map from the domain triangle to the surface triangle, and its
// determinant (the area ratio), or NaN when the triangle is flat or flipped in D. With a_k, b_k
// the domain edges at corner k and l_k the surface edge opposite it, the Dirichlet energy gives
// ‖J‖² = Σ_k (a_k·b_k)|l_k|² / (2 A_D)². On the sphere, orientation = 2 A_D x the chord plane's
// distance from the centre: using it for 2 A_D keeps a coarse triangle from growing to a
// hemisphere, where its chord plane reaches the centre and the triangle turns over.
inline std::pair<double, double> jacobian_norm_and_det(const Vec3& d0, const Vec3& d1, const Vec3& d2,
                                                       const SurfaceTriangle& q) {
  const double orientation = domain_orientation(d0, d1, d2);
  if (!(orientation > 0)) return {std::nan(""), std::nan("")};
  const double s = (d1 - d0).dot(d2 - d0) * q.squared_lengths[0] + (d2 - d1).dot(d0 - d1) * q.squared_lengths[1] +
                   (d0 - d2).dot(d1 - d2) * q.squared_lengths[2];
  return {s / (orientation * orientation), q.double_area / orientation};
}

// A3D (‖J‖²/det + λ (det + 1/det)) of a face whose surface was scaled to the domain's area:
// the MIPS energy (Hormann and Greiner) keeps the map near conformal, so that round cells in D
// stay round on the surface, and the area term (λ = area_weight) bounds the squeeze that a
// conformal map puts on a protrusion. Both grow without bound as a face goes flat in D.
// Infinite when the face is flat or flipped in D.
double face_energy(const Vec3& d0, const Vec3& d1, const Vec3& d2, const SurfaceTriangle& q, double area_weight) {
  const auto [norm2, det] = jacobian_norm_and_det(d0, d1, d2, q);
  if (!(det > 0)) return std::isnan(det) ? kInf : 0.0;
  return 0.5 * q.double_area * (norm2 / det + area_weight * (det + 1 / det));
}

// The surface scaled to the area of the unit sphere: the area term's minimum is then an
// area-preserving map.
RowMatrixX3d scaled_to_sphere_area(const TriMesh& mesh) {
  double area = 0;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Vec3 a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  return mesh.V * std::sqrt(4 * kPi / area);
}

FaceLists faces_of_vertices(const RowMatrixX3i& F, int n) {
  FaceLists lists(n);
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) lists[F(f, k)].push_back(f);
  return lists;
}

void erase_value(std::vector<int>& list, int value) { list.erase(std::find(list.begin(), list.end(), value)); }

/// Moves single vertices on the sphere downhill in map_energy, never through a flip. The faces
/// and their lists may change between calls (the hierarchical map's splits).
class StarRelaxer {
 public:
  StarRelaxer(const RowMatrixX3d& surface, const RowMatrixX3i& F, const FaceLists& faces_of, RowMatrixX3d& D,
              double area_weight)
      : X_(surface), F_(F), faces_of_(faces_of), D_(D), area_weight_(area_weight), surface_(F.rows()) {}

  /// The energy of v's star with v at p (infinite if a face flips or goes flat).
  double star_energy(int v, const Vec3& p) const {
    double e = 0;
    for (int f : faces_of_[v]) {
      Vec3 d[3];
      for (int k = 0; k < 3; ++k) d[k] = F_(f, k) == v ? p : Vec3(D_.row(F_(f, k)));
      e += face_energy(d[0], d[1], d[2], surface_of(f), area_weight_);
      if (!std::isfinite(e)) return kInf;
    }
    return e;
  }

  /// One downhill step of v along the finite-difference gradient, with a backtracking line
  /// search from half the star's mean radius. \return whether v moved.
  bool relax(int v) {
    const Vec3 p = D_.row(v);
    const double e0 = star_energy(v, p);
    const auto [height, radius] = star_extent(v, p);
    if (!std::isfinite(e0) || !(height > 0)) return false;
    const Frame frame = tangent_frame(p);
    // Probes well inside the star: a vertex of a sliver sits very close to its opposite edge.
    const double h = 1e-3 * height;
    const auto energy_at = [&](double x, double y) { return star_energy(v, frame.at(x, y)); };
    const Eigen::Vector2d g((energy_at(h, 0) - energy_at(-h, 0)) / (2 * h),
                            (energy_at(0, h) - energy_at(0, -h)) / (2 * h));
    if (!std::isfinite(g.squaredNorm()) || g.squaredNorm() == 0) return false;
    const Eigen::Vector2d direction = -g.normalized();
    double step = 0.5 * radius;
    for (int attempt = 0; attempt < 40 && step > 0.1 * h; ++attempt, step *= 0.5) {
      const double e = energy_at(step * direction.x(), step * direction.y());
      if (e < e0) {
        // Half the step is often better still: the first lower point overshoots the minimum.
        const double e_half = energy_at(0.5 * step * direction.x(), 0.5 * step * direction.y());
        const double s = e_half < e ? 0.5 * step : step;
        D_.row(v) = frame.at(s * direction.x(), s * direction.y()).transpose();
        return true;
      }
    }
    return false;
  }

 private:
  /// Where the tangent offset (x, y) of p lands on the sphere.
  struct Frame {
    Vec3 p, t1, t2;
    Vec3 at(double x, double y) const { return (p + x * t1 + y * t2).normalized(); }
  };

  static Frame tangent_frame(const Vec3& p) {
    const Vec3 t1 = p.unitOrthogonal();
    return {p, t1, p.cross(t1).normalized()};
  }

  /// The smallest height over its opposite edge, and the mean distance to its neighbours, of
  /// p in v's star (in D).
  std::pair<double, double> star_extent(int v, const Vec3& p) const {
    double sum = 0, height = kInf;
    int count = 0;
    for (int f : faces_of_[v]) {
      int k = 0;
      while (F_(f, k) != v) ++k;
      const Vec3 a = D_.row(F_(f, (k + 1) % 3)), b = D_.row(F_(f, (k + 2) % 3));
      height = std::min(height, (a - p).cross(b - p).norm() / std::max((b - a).norm(), 1e-300));
      sum += (a - p).norm() + (b - p).norm();
      count += 2;
    }
    return {height, count > 0 ? sum / count : 0.0};
  }

  /// Face f's surface triangle, computed again only when its corners changed (a split or a
  /// collapse rewrites faces in place; F keeps its rows): each relaxation step evaluates its star's energy five times
  /// or more, and the hierarchical map spends most of its time there.
  const SurfaceTriangle& surface_of(int f) const {
    Cached& c = surface_[f];
    const int a = F_(f, 0), b = F_(f, 1), d = F_(f, 2);
    if (c.corners[0] != a || c.corners[1] != b || c.corners[2] != d) {  // (std::array's != calls memcmp)
      c.corners = {a, b, d};
      c.triangle = surface_triangle(X_.row(a), X_.row(b), X_.row(d));
    }
    return c.triangle;
  }

  struct Cached {
    std::array<int, 3> corners{-1, -1, -1};
    SurfaceTriangle triangle{};
  };

  const RowMatrixX3d& X_;
  const RowMatrixX3i& F_;
  const FaceLists& faces_of_;
  RowMatrixX3d& D_;
  double area_weight_;
  mutable std::vector<Cached> surface_;  // a cache: star_energy stays const
};

/// Sweeps (sweep_once()) until one lowers the energy by less than `tolerance` (relative) or
/// `max_sweeps` are done. \return the sweeps made.
template <class SweepFn, class EnergyFn>
int sweep_until_converged(SweepFn&& sweep_once, int max_sweeps, double tolerance, EnergyFn&& total_energy) {
  double before = total_energy();
  int sweeps = 0;
  while (sweeps < max_sweeps) {
    sweep_once();
    ++sweeps;
    const double after = total_energy();
    if (!(before - after > tolerance * before)) break;
    before = after;
  }
  return sweeps;
}

/// A closed manifold that half-edge collapses shrink and the recorded collapses restore.
class CollapsibleMesh {
 public:
  struct Collapse {
    int removed = -1, kept = -1;
    std::vector<int> changed;            ///< faces that had `removed` and now have `kept` in its place
    std::array<int, 2> deleted{-1, -1};  ///< the two faces of the collapsed edge
  };

  explicit CollapsibleMesh(const TriMesh& mesh)
      : X(mesh.V),
        F(mesh.F),
        faces_of(faces_of_vertices(mesh.F, mesh.num_vertices())),
        alive_vertices_(mesh.num_vertices()) {}

  std::vector<int> neighbors(int v) const {
    std::vector<int> ring;
    for (int f : faces_of[v])
      for (int k = 0; k < 3; ++k)
        if (F(f, k) != v) ring.push_back(F(f, k));
    std::sort(ring.begin(), ring.end());
    ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
    return ring;
  }

  bool adjacent(int a, int b) const {
    for (int f : faces_of[a])
      if (F(f, 0) == b || F(f, 1) == b || F(f, 2) == b) return true;
    return false;
  }

  /// The link condition: the edge's two ends share exactly its two opposite vertices.
  bool link_condition(int a, int b) const {
    const std::vector<int> ra = neighbors(a), rb = neighbors(b);
    std::vector<int> common;
    std::set_intersection(ra.begin(), ra.end(), rb.begin(), rb.end(), std::back_inserter(common));
    return common.size() == 2;
  }

  /// The smallest cosine between a face's normal before and after collapsing v into u
  /// (1 when no face tilts; -1 or less when one turns over or goes flat).
  double normal_agreement(int v, int u) const {
    double worst = 1;
    const Vec3 pu = X.row(u);
    for (int f : faces_of[v]) {
      if (F(f, 0) == u || F(f, 1) == u || F(f, 2) == u) continue;
      Vec3 before[3], after[3];
      for (int k = 0; k < 3; ++k) before[k] = after[k] = X.row(F(f, k));
      for (int k = 0; k < 3; ++k)
        if (F(f, k) == v) after[k] = pu;
      const Vec3 n0 = (before[1] - before[0]).cross(before[2] - before[0]);
      const Vec3 n1 = (after[1] - after[0]).cross(after[2] - after[0]);
      const double norms = n0.norm() * n1.norm();
      worst = std::min(worst, norms > 0 ? n0.dot(n1) / norms : -2.0);
    }
    return worst;
  }

  Collapse collapse(int v, int u) {
    Collapse c;
    c.removed = v;
    c.kept = u;
    int deleted = 0;
    for (int f : std::vector<int>(faces_of[v])) {
      if (F(f, 0) == u || F(f, 1) == u || F(f, 2) == u) {
        c.deleted[deleted++] = f;
        for (int k = 0; k < 3; ++k)
          if (F(f, k) != v) erase_value(faces_of[F(f, k)], f);
      } else {
        for (int k = 0; k < 3; ++k)
          if (F(f, k) == v) F(f, k) = u;
        faces_of[u].push_back(f);
        c.changed.push_back(f);
      }
    }
    faces_of[v].clear();
    --alive_vertices_;
    return c;
  }

  void undo(const Collapse& c) {
    for (int f : c.changed) {
      for (int k = 0; k < 3; ++k)
        if (F(f, k) == c.kept) F(f, k) = c.removed;
      erase_value(faces_of[c.kept], f);
      faces_of[c.removed].push_back(f);
    }
    for (int f : c.deleted)
      for (int k = 0; k < 3; ++k) faces_of[F(f, k)].push_back(f);
    ++alive_vertices_;
  }

  int alive_vertices() const { return alive_vertices_; }

  const RowMatrixX3d& X;
  RowMatrixX3i F;
  FaceLists faces_of;

 private:
  int alive_vertices_;
};

/// Shortest edges first, each collapsed into the end whose faces tilt least; edges whose faces
/// would tilt more than the current limit wait until nothing else can go, and the limit is then
/// relaxed, down to the link condition alone, until four vertices are left.
std::vector<CollapsibleMesh::Collapse> collapse_to_tetrahedron(CollapsibleMesh& mesh) {
  using Entry = std::pair<double, std::pair<int, int>>;
  std::vector<CollapsibleMesh::Collapse> history;
  const auto length2 = [&](int a, int b) { return (mesh.X.row(a) - mesh.X.row(b)).squaredNorm(); };
  for (const double limit : {0.5, 0.0, -0.9, -3.0}) {
    std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
    for (int f = 0; f < mesh.F.rows(); ++f)
      for (int k = 0; k < 3; ++k) {
        const int a = mesh.F(f, k), b = mesh.F(f, (k + 1) % 3);
        if (a < b && !mesh.faces_of[a].empty()) queue.push({length2(a, b), {a, b}});
      }
    while (!queue.empty() && mesh.alive_vertices() > 4) {
      const auto [a, b] = queue.top().second;
      queue.pop();
      if (mesh.faces_of[a].empty() || mesh.faces_of[b].empty() || !mesh.adjacent(a, b)) continue;
      if (!mesh.link_condition(a, b)) continue;
      const double ab = mesh.normal_agreement(a, b), ba = mesh.normal_agreement(b, a);
      if (std::max(ab, ba) < limit) continue;
      const int removed = ab >= ba ? a : b, kept = ab >= ba ? b : a;
      history.push_back(mesh.collapse(removed, kept));
      for (int w : mesh.neighbors(kept)) queue.push({length2(kept, w), {std::min(kept, w), std::max(kept, w)}});
    }
    if (mesh.alive_vertices() <= 4) return history;
  }
  throw AlgorithmError(
      "the surface cannot be simplified to a tetrahedron by edge collapses; it is not a clean closed "
      "genus-0 manifold: repair it first");
}

/// The four vertices left on a regular tetrahedron inscribed in the sphere, mirrored if needed
/// so that the four faces are counter-clockwise seen from outside.
void place_tetrahedron(const CollapsibleMesh& mesh, RowMatrixX3d& D) {
  std::vector<int> corners;
  for (int v = 0; v < static_cast<int>(mesh.faces_of.size()); ++v)
    if (!mesh.faces_of[v].empty()) corners.push_back(v);
  const double s = 1 / std::sqrt(3.0);
  const Vec3 regular[4] = {{s, s, s}, {s, -s, -s}, {-s, s, -s}, {-s, -s, s}};
  for (std::size_t i = 0; i < corners.size(); ++i) D.row(corners[i]) = regular[i].transpose();
  const int f = mesh.faces_of[corners[0]].front();
  if (domain_orientation(D.row(mesh.F(f, 0)), D.row(mesh.F(f, 1)), D.row(mesh.F(f, 2))) < 0)
    D.row(corners[0]).swap(D.row(corners[1]));
}

/// The split's vertex placed just off the kept one, on the bisector of the angle between the
/// two faces it regains: there every one of its faces is counter-clockwise, for a small enough
/// offset (each of its other faces was one of the kept vertex's, and those were).
void place_split(const CollapsibleMesh::Collapse& c, const CollapsibleMesh& mesh, const StarRelaxer& relaxer,
                 RowMatrixX3d& D) {
  const int v = c.removed, u = c.kept;
  int left = -1, right = -1;  // (u, v, left) and (v, u, right) are the regained faces
  for (int f : c.deleted)
    for (int k = 0; k < 3; ++k)
      if (mesh.F(f, k) == u) {
        const int next = mesh.F(f, (k + 1) % 3), third = mesh.F(f, (k + 2) % 3);
        if (next == v)
          left = third;
        else
          right = next;
      }
  const Vec3 pu = D.row(u);
  const Vec3 normal = pu.normalized();
  const Vec3 t1 = normal.unitOrthogonal(), t2 = normal.cross(t1);
  const auto angle_of = [&](int w) {
    const Vec3 d = Vec3(D.row(w)) - pu;
    return std::atan2(d.dot(t2), d.dot(t1));
  };
  double sector = angle_of(left) - angle_of(right);
  while (sector <= 0) sector += 2 * kPi;
  const double bisector = angle_of(right) + 0.5 * sector;
  const Vec3 direction = std::cos(bisector) * t1 + std::sin(bisector) * t2;
  double offset = 0.25 * std::min((Vec3(D.row(left)) - pu).norm(), (Vec3(D.row(right)) - pu).norm());
  for (int attempt = 0; attempt < 80; ++attempt, offset *= 0.5) {
    const Vec3 p = (pu + offset * direction).normalized();
    if (std::isfinite(relaxer.star_energy(v, p))) {
      D.row(v) = p.transpose();
      return;
    }
  }
  throw AlgorithmError(
      "a vertex split of the hierarchical sphere map found no place without a flipped triangle; "
      "the surface has degenerate triangles: repair them first");
}

}  // namespace

double map_energy(const TriMesh& mesh, const RowMatrixX3d& domain, double area_weight) {
  double e = 0;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const int a = mesh.F(f, 0), b = mesh.F(f, 1), c = mesh.F(f, 2);
    e += face_energy(domain.row(a), domain.row(b), domain.row(c),
                     surface_triangle(mesh.V.row(a), mesh.V.row(b), mesh.V.row(c)), area_weight);
  }
  return e;
}

double normalized_stretch(const TriMesh& mesh, const RowMatrixX3d& domain) {
  double area3 = 0, aread = 0, weighted = 0;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Vec3 a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    const Vec3 p = domain.row(mesh.F(f, 0)), q = domain.row(mesh.F(f, 1)), r = domain.row(mesh.F(f, 2));
    const double a3 = 0.5 * (b - a).cross(c - a).norm();
    area3 += a3;
    aread += 0.5 * (q - p).cross(r - p).norm();
    weighted += a3 * 0.5 * jacobian_norm_and_det(p, q, r, surface_triangle(a, b, c)).first;
  }
  return std::sqrt(weighted / area3 * aread / area3);
}

RowMatrixX3d hierarchical_sphere_map(const TriMesh& mesh, const HierarchicalMapOptions& options) {
  const int n = mesh.num_vertices();
  CollapsibleMesh collapsible(mesh);
  const std::vector<CollapsibleMesh::Collapse> history = collapse_to_tetrahedron(collapsible);
  RowMatrixX3d D = RowMatrixX3d::Zero(n, 3);
  place_tetrahedron(collapsible, D);
  const RowMatrixX3d scaled = scaled_to_sphere_area(mesh);
  StarRelaxer relaxer(scaled, collapsible.F, collapsible.faces_of, D, options.area_weight);

  std::vector<int> present;
  for (int v = 0; v < n; ++v)
    if (!collapsible.faces_of[v].empty()) present.push_back(v);
  // The energy of the faces present: those of the vertices present, each counted three times.
  const auto present_energy = [&] {
    double e = 0;
    for (int v : present) e += relaxer.star_energy(v, D.row(v));
    return e;
  };
  double next_round = present.size() * options.growth;
  for (auto c = history.rbegin(); c != history.rend(); ++c) {
    collapsible.undo(*c);
    place_split(*c, collapsible, relaxer, D);
    for (int i = 0; i < 3; ++i) relaxer.relax(c->removed);
    for (int w : collapsible.neighbors(c->removed)) relaxer.relax(w);
    relaxer.relax(c->removed);
    present.push_back(c->removed);
    if (present.size() >= next_round) {
      const auto sweep_present = [&] {
        for (int v : present) relaxer.relax(v);
      };
      sweep_until_converged(sweep_present, options.level_sweeps, options.tolerance, present_energy);
      next_round = present.size() * options.growth;
    }
  }
  // The final sweeps, over the whole mesh, relax the two halves side by side (split_sweep.h):
  // a relaxation reads v's star and writes v and its star's cached surface triangles only.
  const VertexStars stars(collapsible.F, n);
  const SplitSweep split(mesh.V, collapsible.F, stars);
  const auto sweep_halves = [&] {
    split.run([&](int part) {
      for (int v : present)
        if (split.part(v) == part) relaxer.relax(v);
    });
  };
  sweep_until_converged(sweep_halves, options.final_sweeps, options.tolerance, present_energy);
  return D;
}

}  // namespace mrsnake
