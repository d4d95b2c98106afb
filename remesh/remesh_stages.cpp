#include "remesh/remesh_stages.h"

#include <algorithm>
#include <cmath>

#include "mesh/parallel.h"
#include "mesh/quality.h"
#include "mesh/topology.h"
#include "remesh/domain.h"
#include "remesh/simplify.h"
#include "remesh/sizing.h"
#include "remesh/untangle.h"

namespace mrsnake::remesh_stages {

/// Points measured per surface for the per-level distance statistics.
constexpr long long kMaxStatsSamples = 50000;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// Levels L and base size n0 so that F0·4^L is near the target, with F0 in [128, 512): a base
// of ~65-260 vertices spread over the shape absorbs its curvature, and since about half of
// them are irregular, they stay under 1% of the finest level's vertices.
void choose_resolution(int target_faces, int& levels, int& n0) {
  levels = 1;
  double f0 = target_faces / 4.0;
  while (f0 >= 512) {
    f0 /= 4;
    ++levels;
  }
  n0 = std::max(8, static_cast<int>(std::lround(f0 / 2 + 2)));
}

// The levels L and the base size n0 asked for (the bend bound may still grow the base).
Resolution initial_resolution(const RemeshOptions& options) {
  Resolution r{options.levels, options.base_vertices};
  if (r.levels == 0) choose_resolution(options.target_faces, r.levels, r.base_vertices);
  return r;
}

namespace {

// Edge rings in about one base spacing: sqrt(input vertices / base vertices).
int base_spacing_rings(const TriMesh& surface, int n0) {
  return static_cast<int>(std::lround(std::sqrt(surface.num_vertices() / static_cast<double>(n0))));
}

}  // namespace

// Curvature sizing. Where the bend bound (remesh/sizing.h) asks for more than half of the base
// vertices (thin tubes, many tips), the base grows 4x and the hierarchy loses a level, unless
// the levels were given or there is only one. The grown base is spread by the bound, and the
// relaxation's density raised by the same factor, so that the levels keep the base's grading.
SizingFields sizing_fields(const TriMesh& surface, const SizingOptions& sizing, const BaseMeshOptions& base,
                           bool levels_given, Resolution& resolution) {
  int& levels = resolution.levels;
  int& n0 = resolution.base_vertices;
  const int n = surface.num_vertices();
  const Eigen::VectorXd kappa = vertex_curvature(surface, 8);
  SizingFields s{curvature_density(kappa, sizing.curvature_weight, sizing.curvature_exponent),
                 Eigen::VectorXd::Ones(n)};
  // Averaged over about a base spacing (sqrt(n / n0) edge rings): the base follows where the
  // surface bends at its own scale, not voxel steps.
  if (base.density_exponent > 0) {
    const int passes = base.density_smoothing < 0 ? base_spacing_rings(surface, n0) : base.density_smoothing;
    s.base_density = smooth_vertex_field(surface, s.wanted, passes).array().pow(base.density_exponent).matrix();
  }
  const double max_bend = base.max_bend;
  if (!(max_bend > 0)) return s;
  const Eigen::VectorXd bend_kappa = smooth_vertex_field(surface, kappa, base_spacing_rings(surface, n0));
  const double bound_points = bend_bound_points(surface, bend_kappa, max_bend);
  // Below that, the curvature sizing alone spreads the base: the bound moved base vertices
  // onto small bent features such as a bear's ears (Q mean -0.013 at 16k faces).
  if (levels_given || levels == 1 || bound_points <= 0.5 * n0) return s;
  // Once: a base 16x larger leaves a hierarchy of two levels with 10 % irregular vertices (the
  // octopus at 16k faces), and a marching-cubes staircase's voxel steps, which the curvature
  // measure sees as bends, ask for it too (the liver).
  n0 = 4 * n0 - 6;
  --levels;
  const Eigen::VectorXd grown_kappa = smooth_vertex_field(surface, kappa, base_spacing_rings(surface, n0));
  const Eigen::VectorXd bounded = bend_bounded_density(surface, s.base_density, grown_kappa, n0, max_bend);
  s.wanted = s.wanted.cwiseProduct(bounded.cwiseQuotient(s.base_density));
  s.base_density = bounded;
  return s;
}

// Moves every row of X to its closest point on the locator's surface.
void reproject_onto(const SurfaceLocator& surface, RowMatrixX3d& X) {
  parallel_ranges(static_cast<std::size_t>(X.rows()), [&](std::size_t begin, std::size_t end) {
    for (auto v = static_cast<Eigen::Index>(begin); v < static_cast<Eigen::Index>(end); ++v)
      X.row(v) = surface.closest(X.row(v).transpose()).point.transpose();
  });
}

namespace {

// The share of the triangles of Q < 0.3 with an edge longer than `edge`: slivers larger than
// the finest level's triangles, such as decimation leaves along a limb.
double sliver_share(const TriMesh& mesh, double edge) {
  int slivers = 0;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    slivers += longest > edge && frey_borouchaki_quality(a, b, c) < 0.3;
  }
  return mesh.num_faces() > 0 ? static_cast<double>(slivers) / mesh.num_faces() : 0.0;
}

// The edge length of `faces` equilateral triangles that cover the mesh's area.
double equilateral_edge(const TriMesh& mesh, double faces) {
  double area = 0;
  for (int f = 0; f < mesh.num_faces(); ++f)
    area += 0.5 * (mesh.V.row(mesh.F(f, 1)) - mesh.V.row(mesh.F(f, 0)))
                      .cross(mesh.V.row(mesh.F(f, 2)) - mesh.V.row(mesh.F(f, 0)))
                      .norm();
  return std::sqrt(4.0 * area / (std::sqrt(3.0) * faces));
}

// Puts `mesh` in for the original if it has the original's topology. \return whether it did.
bool stand_in(const TopologyReport& topology, TriMesh mesh, PreparedInput& p) {
  const TopologyReport after = topology_report(mesh);
  if (after.is_disk() != topology.is_disk() || after.is_closed_genus0() != topology.is_closed_genus0()) return false;
  p.work = std::move(mesh);
  p.simplified = true;
  return true;
}

// An input of large slivers, remeshed isotropically to stand in for it (SimplifyOptions::
// sliver_share). simplify_info gets the share, whether the remeshing stood in (it must keep the
// topology), and sliver_remesh_seconds, the time since the run's start.
void remesh_large_slivers(const TopologyReport& topology, const SimplifyOptions& options, double finest_faces,
                          const ProgressFn& progress, Clock::time_point start, PreparedInput& p) {
  const double finest_edge = equilateral_edge(p.original, finest_faces);
  if (!(finest_edge > 0)) return;  // no area: the parameterization refuses it
  const double share = sliver_share(p.original, finest_edge);
  if (share <= options.sliver_share) return;
  report(progress, "remesh the slivers", 0);
  p.simplify_info["sliver_share"] = share;
  p.simplify_info["sliver_remeshed"] = stand_in(topology, remesh_isotropically(p.original, finest_edge, 3), p);
  p.simplify_info["sliver_remesh_seconds"] = seconds_since(start);
}

}  // namespace

// The input as it is parameterized: the original without unreferenced vertices, or a
// simplification of it when it is much finer than the finest level (the parameterization is
// the costly part), or an isotropic remeshing of it when it is made of large slivers.

PreparedInput prepare_input(const TriMesh& input, const RemeshOptions& options, Clock::time_point start) {
  const SimplifyOptions& simplify = options.simplify;
  const Resolution resolution = initial_resolution(options);
  const ProgressFn& progress = options.progress;
  PreparedInput p;
  p.original = remove_unreferenced_vertices(input);
  const TopologyReport topology = topology_report(p.original);
  require_disk_or_sphere(topology, "the input surface");
  p.work = p.original;
  const double finest_faces = 2.0 * resolution.base_vertices * std::pow(4.0, resolution.levels);
  const double limit = std::max<double>(simplify.above_faces, 8 * finest_faces);
  if (simplify.above_faces > 0 && p.original.num_faces() > limit) {
    report(progress, "simplify", 0);
    stand_in(topology, simplify_to_faces(p.original, static_cast<int>(limit)), p);
    p.simplify_info["simplify_seconds"] = seconds_since(start);
    return p;
  }
  remesh_large_slivers(topology, simplify, finest_faces, progress, start, p);
  return p;
}

std::vector<bool> held_vertices(const RowMatrixX3i& F, int num_vertices, const std::vector<bool>& snapped) {
  std::vector<bool> held = boundary_vertices(F, num_vertices);
  for (std::size_t v = 0; v < snapped.size(); ++v) held[v] = held[v] || snapped[v];
  return held;
}

nlohmann::json untangle_finest(const RowMatrixX3i& F, RowMatrixX3d& X, const UntangleOptions& options,
                               const std::vector<bool>& snapped) {
  const UntangleStats s =
      untangle_self_intersections(F, X, held_vertices(F, static_cast<int>(X.rows()), snapped), options);
  if (s.pairs_before == 0) return nullptr;
  return {{"pairs_before", s.pairs_before},
          {"pairs_after", s.pairs_after},
          {"rounds", s.rounds},
          {"moved_vertices", s.moved_vertices}};
}

// Quality, distance to the input and crossing face pairs, into the level's stats. Metro-style
// sampling of both surfaces, then a uniform random subset of at most 50k points per surface:
// a marching-cubes input has hundreds of thousands of faces, and 50k points estimate the RMS
// to well under 1 % (the Hausdorff distance is the largest over the subset).
void measure_level(const TriMesh& original, const SurfaceLocator& locator, const RowMatrixX3i& F, RemeshLevel& level) {
  nlohmann::json& s = level.stats;
  const TriMesh mesh{level.positions, F};
  s["quality"] = mesh_quality(mesh);
  // Every vertex lies on the input, yet the level's triangles can pass through one another (a
  // tip thinner than an edge, a fold of the base mesh): a fault the quality figures do not show.
  s["self_intersections"] = count_self_intersections(mesh);
  DistanceOptions sampling;
  sampling.samples_per_face =
      std::clamp(static_cast<int>(5e5 / std::max(original.num_faces(), mesh.num_faces())), 1, 10);
  sampling.max_samples_per_mesh = kMaxStatsSamples;
  s["distance"] = surface_distance(mesh, original, locator, sampling);
  s["distance"]["samples_per_face"] = sampling.samples_per_face;
  s["distance"]["max_samples_per_mesh"] = sampling.max_samples_per_mesh;
}

}  // namespace mrsnake::remesh_stages
