#include "remesh/base_mesh.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <set>

#include "mesh/errors.h"
#include "remesh/convex_hull.h"

namespace mrsnake {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The valence flips never leave an interior vertex with fewer edges. One with three keeps three
// triangles at every level of the 1:4 split, whose angles there sum to 360° on a flat patch:
// each has an angle near 120° (Q <= 0.6, a smallest angle <= 30°) whatever the relaxation does.
// (The surface-Delaunay flips may, and the valence flips then raise such a vertex where they
// can: holding the Delaunay flips to four as well measured worse on the hierarchical map's
// inputs, e.g. cheburashka at 16k faces, smallest angle 17.6° -> 11.9°.)
constexpr int kMinInteriorValence = 4;

// Farthest point sampling in 3D over the candidates, continuing from the distances already
// in `dist` (0 for chosen vertices). With `density` (wanted point density per vertex) the
// squared distances are scaled by it: spacing ∝ density^(-1/2).
void farthest_points(const RowMatrixX3d& X, const std::vector<int>& candidates, int count, std::vector<double>& dist,
                     std::vector<int>& chosen, const Eigen::VectorXd* density = nullptr) {
  for (int k = 0; k < count; ++k) {
    int best = -1;
    double best_d = -1;
    for (int v : candidates)
      if (const double d = density ? dist[v] * (*density)[v] : dist[v]; d > best_d) {
        best_d = d;
        best = v;
      }
    if (best < 0 || best_d <= 0) break;
    chosen.push_back(best);
    for (int v = 0; v < X.rows(); ++v) dist[v] = std::min(dist[v], (X.row(v) - X.row(best)).squaredNorm());
  }
}

// Which edges of a closed base are flipped toward the surface's Delaunay triangulation, if any.
// The hierarchical map's: every edge past 180°, as far as each end keeps three edges (a margin
// there measured worse: cheburashka at 16k faces, smallest angle 17.4° -> 11.3°). A one-chart
// map's: those past 180° + one_chart_margin_deg, as far as each end keeps five edges; a base
// vertex left with four has a right angle in its triangles at every level, which the repair
// cannot raise (an ellipsoid with 24 base vertices: Q min 0.69 at the finest level against
// 0.71 with the floor of five).
std::optional<SurfaceFlipOptions> closed_base_flips(const Parameterization& param, double one_chart_margin_deg) {
  if (param.kind != DomainKind::sphere) return std::nullopt;
  if (param.sphere_map == SphereMap::hierarchical) return SurfaceFlipOptions{};
  if (one_chart_margin_deg >= 180.0) return std::nullopt;
  return SurfaceFlipOptions{one_chart_margin_deg * kPi / 180.0, 5};
}

void triangulate_samples(const Parameterization& param, const std::vector<bool>& boundary, int rim_min_triangles,
                         double one_chart_margin_deg, BaseMesh& base) {
  const int m = static_cast<int>(base.samples.size());
  base.domain.resize(m, 3);
  for (int i = 0; i < m; ++i) base.domain.row(i) = param.domain.row(base.samples[i]);

  if (param.kind == DomainKind::sphere) {
    base.faces = convex_hull_faces(base.domain);
  } else {
    RowMatrixX3d lifted(m, 3);
    for (int i = 0; i < m; ++i) {
      if (boundary[base.samples[i]]) base.domain.row(i) = project_to_domain(DomainKind::disk, base.domain.row(i), true);
      lifted.row(i) << base.domain(i, 0), base.domain(i, 1),
          base.domain(i, 0) * base.domain(i, 0) + base.domain(i, 1) * base.domain(i, 1);
    }
    const RowMatrixX3i hull = convex_hull_faces(lifted);
    std::vector<Eigen::RowVector3i> lower;
    for (int f = 0; f < hull.rows(); ++f) {
      const Eigen::Vector3d a = lifted.row(hull(f, 0)), b = lifted.row(hull(f, 1)), c = lifted.row(hull(f, 2));
      if ((b - a).cross(c - a).z() < 0) lower.emplace_back(hull(f, 0), hull(f, 2), hull(f, 1));
    }
    base.faces.resize(static_cast<int>(lower.size()), 3);
    for (std::size_t i = 0; i < lower.size(); ++i) base.faces.row(static_cast<int>(i)) = lower[i];
  }
  std::set<int> used(base.faces.data(), base.faces.data() + base.faces.size());
  if (static_cast<int>(used.size()) != m)
    throw AlgorithmError("the base mesh does not use all of its " + std::to_string(m) +
                             " vertices; the parameterization is too distorted for this base size",
                         Remedy::other_resolution);
  if (const int flipped = count_flipped(base.domain, base.faces); flipped > 0)
    throw AlgorithmError("the base mesh has " + std::to_string(flipped) + " flipped triangles in the domain");
  if (const std::optional<SurfaceFlipOptions> flips = closed_base_flips(param, one_chart_margin_deg)) {
    RowMatrixX3d X(m, 3);
    for (int i = 0; i < m; ++i) X.row(i) = param.surface.V.row(base.samples[i]);
    base.surface_flips += flip_toward_surface_delaunay(base.domain, X, base.faces, *flips);
  }
  base.valence_flips += flip_toward_regular_valence(base.domain, base.faces, rim_min_triangles);
}

// The quad a, d, b, c convex in D, so that neither new face flips there.
FlipGuard convex_in_domain(const RowMatrixX3d& D) {
  return [&D](const EdgeFlip& e) {
    return domain_orientation(D.row(e.a), D.row(e.d), D.row(e.c)) > 0 &&
           domain_orientation(D.row(e.d), D.row(e.b), D.row(e.c)) > 0;
  };
}

// Makes the flip if `allowed` lets it, updating the valences. \return whether it flipped.
bool flip_if_allowed(const EdgeFlip& e, const FlipGuard& allowed, RowMatrixX3i& F, std::vector<int>& valence) {
  if (!allowed(e)) return false;
  F.row(e.f1) << e.a, e.d, e.c;
  F.row(e.f2) << e.d, e.b, e.c;
  --valence[e.a];
  --valence[e.b];
  ++valence[e.c];
  ++valence[e.d];
  return true;
}

}  // namespace

int flip_toward_surface_delaunay(const RowMatrixX3d& D, const RowMatrixX3d& X, RowMatrixX3i& F,
                                 const SurfaceFlipOptions& options) {
  return flip_toward_surface_delaunay(X, F, convex_in_domain(D), options);
}

int flip_toward_regular_valence(const RowMatrixX3d& D, RowMatrixX3i& F, int rim_min_triangles) {
  return flip_toward_regular_valence(static_cast<int>(D.rows()), F, rim_min_triangles, convex_in_domain(D));
}

int flip_toward_surface_delaunay(const RowMatrixX3d& X, RowMatrixX3i& F, const FlipGuard& allowed,
                                 const SurfaceFlipOptions& options) {
  const auto angle_at = [&](int apex, int a, int b) {
    const Eigen::Vector3d u = X.row(a) - X.row(apex), w = X.row(b) - X.row(apex);
    return std::atan2(u.cross(w).norm(), u.dot(w));
  };
  int flips = 0;
  for (int pass = 0; pass < 100; ++pass) {
    std::map<std::pair<int, int>, std::pair<int, int>> edge_faces;  // directed edge -> (face, corner opposite)
    for (int f = 0; f < F.rows(); ++f)
      for (int k = 0; k < 3; ++k) edge_faces[{F(f, k), F(f, (k + 1) % 3)}] = {f, (k + 2) % 3};
    std::vector<int> valence(X.rows(), 0);
    for (const auto& [e, fc] : edge_faces) ++valence[e.first];
    bool changed = false;
    std::vector<bool> touched(F.rows(), false);
    std::set<std::pair<int, int>> created;  // edge_faces is this pass's: two flips may make one edge
    for (const auto& [e, fc] : edge_faces) {
      const int a = e.first, b = e.second;
      const auto twin = edge_faces.find({b, a});
      if (a > b || twin == edge_faces.end()) continue;
      const int f1 = fc.first, f2 = twin->second.first;
      if (touched[f1] || touched[f2]) continue;
      const int c = F(f1, fc.second), d = F(f2, twin->second.second);
      if (c == d || edge_faces.count({c, d}) || edge_faces.count({d, c}) ||
          created.count({std::min(c, d), std::max(c, d)}) || valence[a] <= options.min_end_edges ||
          valence[b] <= options.min_end_edges)
        continue;
      // The surface's Delaunay condition: the two angles facing the edge sum to at most pi.
      if (!(angle_at(c, a, b) + angle_at(d, b, a) > kPi + options.margin + 1e-9)) continue;
      if (!flip_if_allowed({f1, f2, a, b, c, d}, allowed, F, valence)) continue;
      touched[f1] = touched[f2] = true;
      created.insert({std::min(c, d), std::max(c, d)});
      ++flips;
      changed = true;
    }
    if (!changed) break;
  }
  return flips;
}

int flip_toward_regular_valence(int n, RowMatrixX3i& F, int rim_min_triangles, const FlipGuard& allowed) {
  int flips = 0;
  for (int pass = 0; pass < 50; ++pass) {
    std::map<std::pair<int, int>, std::pair<int, int>> edge_faces;  // directed edge -> (face, corner opposite)
    std::vector<int> valence(n, 0);
    for (int f = 0; f < F.rows(); ++f)
      for (int k = 0; k < 3; ++k) edge_faces[{F(f, k), F(f, (k + 1) % 3)}] = {f, (k + 2) % 3};
    std::vector<bool> boundary(n, false);
    for (const auto& [e, fc] : edge_faces) {
      ++valence[e.first];
      if (!edge_faces.count({e.second, e.first})) boundary[e.first] = boundary[e.second] = true;
    }
    // valence[] counted outgoing half-edges; add the incoming boundary ones.
    for (const auto& [e, fc] : edge_faces)
      if (!edge_faces.count({e.second, e.first})) ++valence[e.second];
    auto target = [&](int v) { return boundary[v] ? 4 : 6; };
    bool changed = false;
    std::vector<bool> touched(F.rows(), false);
    std::set<std::pair<int, int>> created;
    for (const auto& [e, fc] : edge_faces) {
      const int a = e.first, b = e.second;
      if (a > b) continue;
      const auto twin = edge_faces.find({b, a});
      if (twin == edge_faces.end()) continue;
      const int f1 = fc.first, f2 = twin->second.first;
      if (touched[f1] || touched[f2]) continue;
      const int c = F(f1, fc.second), d = F(f2, twin->second.second);
      if (c == d || edge_faces.count({c, d}) || edge_faces.count({d, c}) ||
          created.count({std::min(c, d), std::max(c, d)}))
        continue;
      // Never below kMinInteriorValence edges inside, or rim_min_triangles + 1 on the rim: a rim
      // vertex with 2 triangles splits a ~180-240 degree rim angle into two obtuse corners at
      // every level.
      const int rim_floor = std::max(3, rim_min_triangles + 1);
      if (valence[a] <= (boundary[a] ? rim_floor : kMinInteriorValence) ||
          valence[b] <= (boundary[b] ? rim_floor : kMinInteriorValence))
        continue;
      // A rim vertex with too few triangles forces a near-flat angle into them: weigh the
      // rim three times.
      auto dev = [&](int v, int delta) {
        const double x = valence[v] + delta - target(v);
        return (boundary[v] ? 3.0 : 1.0) * x * x;
      };
      const double before = dev(a, 0) + dev(b, 0) + dev(c, 0) + dev(d, 0);
      const double after = dev(a, -1) + dev(b, -1) + dev(c, 1) + dev(d, 1);
      if (!(after < before)) continue;
      if (!flip_if_allowed({f1, f2, a, b, c, d}, allowed, F, valence)) continue;
      touched[f1] = touched[f2] = true;
      created.insert({std::min(c, d), std::max(c, d)});
      ++flips;
      changed = true;
    }
    if (!changed) break;
  }
  return flips;
}

namespace {

// Starts farthest point sampling at the candidate farthest from the centroid (the first such
// candidate on ties): the first sample, and every vertex's squared distance to it in `dist`.
void start_at_farthest_from_centroid(const RowMatrixX3d& X, const std::vector<int>& candidates,
                                     std::vector<double>& dist, std::vector<int>& samples) {
  const Eigen::RowVector3d centroid = X.colwise().mean();
  int first = candidates.front();
  for (int v : candidates)
    if ((X.row(v) - centroid).squaredNorm() > (X.row(first) - centroid).squaredNorm()) first = v;
  samples.push_back(first);
  for (int v = 0; v < X.rows(); ++v) dist[v] = (X.row(v) - X.row(first)).squaredNorm();
}

// Farthest point samples of a disk: nb on its rim first, evenly spaced, then the interior.
// `rim_edges` are the input's boundary edges (each appears once: their lengths sum to the
// perimeter).
void sample_disk(const TriMesh& mesh, int n0, const std::vector<std::pair<int, int>>& rim_edges,
                 const std::vector<bool>& boundary, const Eigen::VectorXd* density, std::vector<double>& dist,
                 std::vector<int>& samples) {
  const int n = mesh.num_vertices();
  std::vector<int> rim;
  for (int v = 0; v < n; ++v)
    if (boundary[v]) rim.push_back(v);
  double area = 0, perimeter = 0;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  for (const auto& [a, b] : rim_edges) perimeter += (mesh.V.row(a) - mesh.V.row(b)).norm();
  // Even spacing h over the whole disk: area ~ (n0 - nb/2)·(√3/2)·h², nb ~ perimeter / h.
  double h = std::sqrt(2 * area / (std::sqrt(3.0) * n0));
  for (int it = 0; it < 20; ++it) {
    const double nb = perimeter / h;
    h = std::sqrt(2 * area / (std::sqrt(3.0) * std::max(1.0, n0 - nb / 2)));
  }
  const int nb = std::clamp(static_cast<int>(std::lround(perimeter / h)), 3, std::max(3, n0 - 1));
  start_at_farthest_from_centroid(mesh.V, rim, dist, samples);
  farthest_points(mesh.V, rim, nb - 1, dist, samples);
  std::vector<int> inner;
  for (int v = 0; v < n; ++v)
    if (!boundary[v]) inner.push_back(v);
  farthest_points(mesh.V, inner, n0 - static_cast<int>(samples.size()), dist, samples, density);
}

// Farthest point samples of a closed surface, from the vertex farthest from the centroid.
void sample_closed(const TriMesh& mesh, int n0, const Eigen::VectorXd* density, std::vector<double>& dist,
                   std::vector<int>& samples) {
  std::vector<int> all(mesh.num_vertices());
  std::iota(all.begin(), all.end(), 0);
  start_at_farthest_from_centroid(mesh.V, all, dist, samples);
  farthest_points(mesh.V, all, n0 - 1, dist, samples, density);
}

}  // namespace

BaseMesh build_base_mesh(const Parameterization& param, int n0, int rim_min_triangles, const Eigen::VectorXd* density,
                         double one_chart_flip_margin_deg) {
  const TriMesh& mesh = param.surface;
  const int n = mesh.num_vertices();
  n0 = std::min(n0, n);
  BaseMesh base;
  std::vector<double> dist(n, std::numeric_limits<double>::infinity());
  std::vector<bool> input_boundary(n, false);
  if (param.kind == DomainKind::disk) {
    // One pass over the input's stars gives the rim, its length and the boundary flags.
    const std::vector<std::pair<int, int>> rim_edges = boundary_edges(mesh.F, VertexStars(mesh.F, n));
    for (const auto& [a, b] : rim_edges) input_boundary[a] = input_boundary[b] = true;
    sample_disk(mesh, n0, rim_edges, input_boundary, density, dist, base.samples);
  } else {
    sample_closed(mesh, n0, density, dist, base.samples);
  }

  // Triangulates the samples in D, then flips toward regular valences. With a disk, a rim
  // sample left with fewer than rim_min_triangles triangles is dropped and the rest
  // triangulated again: with 2, its corners stay obtuse (~120 degrees in 3D) at every level.
  for (int attempt = 0;; ++attempt) {
    triangulate_samples(param, input_boundary, rim_min_triangles, one_chart_flip_margin_deg, base);
    if (param.kind != DomainKind::disk || attempt == 4) break;
    const int m = static_cast<int>(base.samples.size());
    std::vector<int> triangles(m, 0);
    for (int f = 0; f < base.faces.rows(); ++f)
      for (int k = 0; k < 3; ++k) ++triangles[base.faces(f, k)];
    const std::vector<bool> rim = boundary_vertices(base.faces, m);
    std::vector<int> kept;
    for (int i = 0; i < m; ++i)
      if (!(rim[i] && triangles[i] < rim_min_triangles)) kept.push_back(base.samples[i]);
    const int rim_count = static_cast<int>(std::count(rim.begin(), rim.end(), true));
    const int dropped = m - static_cast<int>(kept.size());
    if (dropped == 0 || rim_count - dropped < 3) break;
    base.samples = kept;
    base.dropped_rim_samples += dropped;
  }
  return base;
}

}  // namespace mrsnake
